"""The ch. 8 controllers on the 1-DOF pitch: their designs on eq. (3.11), their damping, and the loops they fly.

One builder for every user of the comparison (the report's chapter 8, ``trms compare-controllers``, the spread study,
the tests): :func:`designs_at` makes the designs once per process, :func:`controllers_for` builds a fresh set of
controllers for a plant, each as it flies: the feedback law, behind the thrust-curve inversion when that is on
(:data:`INVERSION`), with the reference prefilter of :func:`reference_prefilter`.

The designs (each on eq. 3.11 at ``Ts``, deviation V in, deviation rad out):

* **LQG**: the thesis's integral LQG, ``R = 75`` (:func:`~trms.experiments.ch67_lqg.design`).
* **PID**: :func:`~trms.control.pid.tune_pid` with its measurement filter and the damping constraint
  :data:`~trms.control.damping.MIN_DAMPING`: a PID alone cannot damp the 0.34 Hz mode on eq. (3.11) (its best,
  a pure integrator, reaches 0.09; the mode needs a controller phase near -150 deg there), a filtered one can.
* **MPC**: :func:`~trms.control.mpc.mpc_for_plant`, horizon 30, a rate limit of 1 V per sample, the end stops.
* **H-infinity**: mixed sensitivity (:func:`~trms.control.hinf.pitch_weights`) with the default weights, with
  :data:`HINF_ROBUST`, and with the default weights plus the twin's input uncertainty on ``T``
  (:data:`SPREAD_WEIGHT`), each with an input-disturbance channel ``Wd`` (:func:`damped_hinf`): the lightest weight
  of :data:`DISTURBANCE_GRID` whose design damps the mode to :data:`DESIGN_DAMPING`. Without it every one of them
  cancels the mode (closed-loop damping 0.044-0.048, the plant's 0.041).

The two-degree-of-freedom structure: every controller follows the reference through the thesis's CSAS low-pass
(:data:`PREFILTER`, Table 6.1's Butterworth at 0.2 Hz), so a reference step does not jump the voltage (the feedback
laws' direct error gains, 1.4-9 V/rad, would jump it by volts on a 0.4 rad step).

The thrust-curve inversion (:class:`~trms.control.inversion.InvertedInputs`, the twin's calibrated curve from
:func:`~trms.worlds.input_maps`) is on by default on the twin (:data:`INVERSION`): measured in the comparison with
and without (:mod:`trms.experiments.ch8_sweep`). The linear model has no thrust curve; nothing is inverted there.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import control
import numpy as np

from trms.control.damping import MIN_DAMPING, ModeDamping, mode_damping
from trms.control.hinf import HinfController, HinfDesign, continuous_model, design_mixsyn, pitch_weights
from trms.control.inversion import InvertedInputs
from trms.control.loop import Controller, DiagonalController
from trms.control.lqg import LQGController, LQGDesign
from trms.control.mpc import MPCController, mpc_for_plant
from trms.control.pid import PIDController, PIDGains
from trms.control.pid_tuning import tune_pid
from trms.control.shaping import CommandFilter
from trms.errors import ConfigurationError, check_in_range
from trms.experiments.ch67_lqg import design, prefilters
from trms.plant import Plant
from trms.worlds import design_model, input_layer, make_plant

__all__ = [
    "CONTROLLERS",
    "HINF_ROBUST",
    "SPREAD_WEIGHT",
    "DISTURBANCE_GRID",
    "DESIGN_DAMPING",
    "PREFILTER",
    "INVERSION",
    "MPC_OPTIONS",
    "Designs",
    "input_uncertainty_weight",
    "damped_hinf",
    "design_controllers",
    "designs_at",
    "controllers_for",
    "design_damping",
    "feedback_compensator",
    "reference_prefilter",
]

#: The controllers compared.
CONTROLLERS = ("LQG", "PID", "MPC", "H-infinity", "H-infinity, robust weight", "H-infinity, from the spread")

#: The weights of the second H-infinity design (:func:`~trms.control.hinf.pitch_weights`): a 0.3 rad/s crossover and
#: four times the control weight (the first: the defaults, 0.5 rad/s and 0.05).
HINF_ROBUST = {"bandwidth": 0.3, "peak": 2.0, "effort": 0.2}
#: The twin's multiplicative input uncertainty weight ``W_I(s) = (tau s + r0) / ((tau / r_inf) s + 1)`` against
#: eq. (3.11) at 0.2 s: ``r0`` (-), ``tau`` (s), ``r_inf`` (-). Fitted (:func:`~trms.experiments.ch8_robustness.
#: fit_weight`) above ``l_I(w) = max_i |(G_i - G0) / G0|`` of the linearised twins of the Monte Carlo spread
#: (24 samples, seed 0, +-20 %): 0.21 at low frequency (the gain spread), 2.2 at the shifted pitch resonance
#: (2 rad/s), 3.7 at Nyquist (delay, bending); the fit gave ``r0 = 0.210, tau = 1.32 s, r_inf = 3.87`` (5 % above
#: the largest), rounded up here, so the weight still lies above every sample (``|W_I|`` grows with each of the three).
SPREAD_WEIGHT = {"r0": 0.22, "tau": 1.35, "r_inf": 3.9}
#: The H-infinity designs: name -> keyword arguments of :func:`~trms.control.hinf.pitch_weights`, and whether
#: :func:`input_uncertainty_weight` (:data:`SPREAD_WEIGHT`) bounds ``T``.
_HINF: dict[str, tuple[dict[str, float], bool]] = {
    "H-infinity": ({}, False),
    "H-infinity, robust weight": (HINF_ROBUST, False),
    "H-infinity, from the spread": ({}, True),
}
#: Constant input-disturbance weights ``Wd`` (V) tried, lightest first (:func:`damped_hinf`).
DISTURBANCE_GRID = (0.1, 0.2, 0.3, 0.4, 0.5, 0.7, 1.0)
#: The pitch mode's closed-loop damping (-) an H-infinity design is asked for: the rule
#: :data:`~trms.control.damping.MIN_DAMPING` with a margin, so that the design meets the rule with room.
DESIGN_DAMPING = 0.12
#: The comparison's reference prefilter: a case of :func:`~trms.experiments.ch67_lqg.prefilters`.
PREFILTER = "CSAS LPF 0.2 Hz"
#: Whether the comparison's controllers fly the twin behind the thrust-curve inversion (the measured default:
#: :mod:`trms.experiments.ch8_sweep` flies both).
INVERSION = True
#: The MPC's options beyond the plant's limits and end stops.
MPC_OPTIONS = {"horizon": 30, "rate_limit": 1.0}


@dataclass(frozen=True)
class Designs:
    """Every design of the comparison, made once from the design model (they do not depend on the plant).

    Attributes
    ----------
    model : control.StateSpace
        The design model (eq. 3.11 at the sample time).
    lqg : LQGDesign
    pid : PIDGains
    hinf : dict
        Name -> HinfDesign (empty without slycot).
    missing_hinf : str or None
        Why there is no H-infinity design.
    disturbance : dict
        Name -> the H-infinity design's ``Wd`` (V).
    """

    model: control.StateSpace
    lqg: LQGDesign
    pid: PIDGains
    hinf: dict[str, HinfDesign]
    missing_hinf: str | None
    disturbance: dict[str, float]


def input_uncertainty_weight(r0: float, tau: float, r_inf: float) -> control.TransferFunction:
    """The first-order multiplicative uncertainty weight ``W_I(s) = (tau s + r0) / ((tau / r_inf) s + 1)``.

    Parameters
    ----------
    r0 : float
        Relative uncertainty at low frequency (-), ``> 0``.
    tau : float
        Time constant (s): ``|W_I|`` reaches 1 near ``1 / tau`` rad/s, ``> 0``.
    r_inf : float
        Relative uncertainty at high frequency (-), ``> r0``.

    Examples
    --------
    >>> w = input_uncertainty_weight(**SPREAD_WEIGHT)
    >>> round(float(abs(w(0))), 2), round(float(abs(w(1e6j))), 2)
    (0.22, 3.9)
    """
    r0 = check_in_range("r0", r0, 0.0, 1e3, low_open=True)
    tau = check_in_range("tau", tau, 0.0, 1e6, unit=" s", low_open=True)
    r_inf = check_in_range("r_inf", r_inf, r0, 1e3, low_open=True)
    return control.tf([tau, r0], [tau / r_inf, 1.0])


def damped_hinf(
    model: control.StateSpace, W1: object, W2: object, W3: object = None, damping: float = DESIGN_DAMPING
) -> tuple[HinfDesign, float]:
    """The mixed-sensitivity design with the lightest input-disturbance weight of :data:`DISTURBANCE_GRID` whose
    closed loop damps ``model``'s least damped mode to ``damping`` (-), and that weight (V).

    Raises
    ------
    DesignError
        No weight of the grid damps the mode so much.

    Examples
    --------
    >>> d, wd = damped_hinf(design_model("1dof"), *pitch_weights())
    >>> wd, bool(mode_damping(design_model("1dof"), d.discrete_controller).closed.damping >= DESIGN_DAMPING)
    (0.4, True)
    """
    from trms.errors import DesignError

    best = 0.0
    plant = continuous_model(model)  # the matrix logarithm once, not per weight
    for wd in DISTURBANCE_GRID:
        d = design_mixsyn(plant, W1, W2, W3, sample_time=float(model.dt), Wd=control.tf([wd], [1.0]))
        zeta = mode_damping(model, d.discrete_controller).closed.damping
        if zeta >= damping:
            return d, wd
        best = max(best, zeta)
    raise DesignError(
        f"no input-disturbance weight of {DISTURBANCE_GRID} V damps the mode to {damping:g}; the best gave {best:.3g}"
    )


@functools.cache
def designs_at(sample_time: float) -> Designs:
    """:func:`design_controllers` on eq. (3.11) at ``sample_time`` (s), made once per process (the designs are
    deterministic and read-only: every run builds its controllers from them with :func:`controllers_for`).

    Examples
    --------
    >>> designs_at(0.2) is designs_at(0.2), float(designs_at(0.2).model.dt)
    (True, 0.2)
    """
    return design_controllers(design_model("1dof", sample_time))


def design_controllers(model: control.StateSpace) -> Designs:
    """Every controller's design on ``model`` (module docstring).

    Examples
    --------
    >>> d = design_controllers(design_model("1dof"))
    >>> sorted(d.hinf) == sorted(n for n in CONTROLLERS if n.startswith("H-inf")) or d.missing_hinf is not None
    True
    """
    hinf: dict[str, HinfDesign] = {}
    weights: dict[str, float] = {}
    missing = None
    try:
        for name, (kw, spread) in _HINF.items():
            w3 = input_uncertainty_weight(**SPREAD_WEIGHT) if spread else None
            hinf[name], weights[name] = damped_hinf(model, *pitch_weights(**kw), w3)
    except ConfigurationError as exc:
        missing = str(exc)
    return Designs(model, design(model, 75.0), tune_pid(model, min_damping=MIN_DAMPING), hinf, missing, weights)


def reference_prefilter(sample_time: float) -> CommandFilter:
    """The comparison's reference prefilter (:data:`PREFILTER`) at ``sample_time`` (s).

    Examples
    --------
    >>> reference_prefilter(0.2).name
    'Butterworth LPF order 2, 0.2 Hz'
    """
    pf = prefilters(sample_time)[PREFILTER]
    assert pf is not None
    return pf


def controllers_for(
    designs: Designs, plant: Plant, inversion: bool = INVERSION
) -> tuple[dict[str, Controller], dict[str, str]]:
    """A fresh controller of each kind for ``plant`` (its actuator limits), and why each missing kind is missing.

    Parameters
    ----------
    designs : Designs
    plant : Plant
        The linear model or the twin.
    inversion : bool
        Fly behind the plant's thrust-curve inversion (:class:`~trms.control.inversion.InvertedInputs`; a plant
        without a thrust curve, the linear model, has none to invert).

    Examples
    --------
    >>> plant = make_plant("linear", "1dof")
    >>> ctrls, missing = controllers_for(designs_at(0.2), plant)
    >>> sorted(ctrls) + sorted(missing) == sorted(CONTROLLERS)
    True
    """
    limits, wrap = input_layer(plant, inversion)
    pair = (float(limits[0][0]), float(limits[1][0]))
    out: dict[str, Controller] = {
        "LQG": LQGController(designs.lqg, limits),
        "PID": PIDController(designs.pid, plant.sample_time, pair),
    }
    missing = {}
    try:
        out["MPC"] = mpc_for_plant(designs.model, plant, input_limits=limits, **MPC_OPTIONS)
    except ConfigurationError as exc:
        missing["MPC"] = str(exc)
    for name, hinf in designs.hinf.items():
        out[name] = HinfController(hinf, pair)
    if designs.missing_hinf is not None:
        missing.update(dict.fromkeys(_HINF, designs.missing_hinf))
    return {n: wrap(c) for n, c in out.items()}, missing


def feedback_compensator(controller: Controller, n_outputs: int = 1) -> control.StateSpace | None:
    """The controller's feedback part ``K_y`` (``u = ... - K_y y``, so the loop is ``L = K_y G``), or None (no linear
    compensator). MPC's is its law while no constraint is active (:meth:`~trms.control.mpc.MPCController.
    compensator`); an inverted controller's is the wrapped one's (the inversion is the identity at trim).

    Parameters
    ----------
    controller : Controller
        An LQG, PID, MPC, H-infinity or decentralised controller (SISO or MIMO), possibly inverted.
    n_outputs : int
        Plant outputs the controller measures (a decentralised controller's loops may read some of them only).

    Examples
    --------
    >>> float(feedback_compensator(PIDController(PIDGains(kp=2.0, ki=0.0, kd=0.0), 0.2)).D[0, 0])
    2.0
    >>> P = [PIDController(PIDGains(kp=k, ki=0.0, kd=0.0), 0.2) for k in (2.0, 3.0)]
    >>> feedback_compensator(DiagonalController(P, (1, 0), (0, 1), 2), 2).D.tolist()  # u0 from y1, u1 from y0
    [[0.0, 2.0], [3.0, 0.0]]
    """
    if isinstance(controller, InvertedInputs):
        return feedback_compensator(controller.controller, n_outputs)
    if isinstance(controller, HinfController):
        return controller.design.discrete_controller
    if isinstance(controller, (LQGController, MPCController)):
        comp = controller.compensator()
        return -comp[:, controller.n_references :]  # from y to u (inputs r, y)
    if isinstance(controller, PIDController):
        return -controller.compensator()[0, 1]
    if isinstance(controller, DiagonalController):
        parts = [feedback_compensator(c) for c in controller.loops]
        if any(p is None for p in parts):
            return None
        pick = np.zeros((len(parts), n_outputs))
        place = np.zeros((controller.n_inputs, len(parts)))
        for j, (o, i) in enumerate(zip(controller.outputs, controller.inputs)):
            pick[j, o], place[i, j] = 1.0, 1.0
        blocks = control.append(*parts)
        return control.ss(blocks.A, blocks.B @ pick, place @ blocks.C, place @ blocks.D @ pick, blocks.dt)
    return None


def design_damping(designs: Designs, plant: Plant | None = None) -> dict[str, ModeDamping]:
    """Each design's closed-loop damping of the pitch mode on its design model (:func:`~trms.control.damping.
    mode_damping`).

    Examples
    --------
    >>> d = design_damping(designs_at(0.2))
    >>> all(m.meets() for m in d.values()), round(d["LQG"].closed.damping, 3)
    (True, 0.127)
    """
    plant = make_plant("linear", "1dof", float(designs.model.dt)) if plant is None else plant
    controllers, _ = controllers_for(designs, plant, inversion=False)
    out = {}
    for name, c in controllers.items():
        k = feedback_compensator(c)
        if k is not None:
            out[name] = mode_damping(designs.model, k)
    return out
