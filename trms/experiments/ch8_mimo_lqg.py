"""Chapter 8's future work on a plant: a 2-DOF LQG autopilot for pitch and yaw against two SISO loops.

Design model: the twin's linearisation at hover reduced to its rigid-body and motor states (six:
pitch, yaw, their rates and the two rotor activations; the beam's bending states residualised,
which keeps the DC gain), discretised at 0.1 s (:func:`trms.worlds.design_model`).

* MIMO LQG: integral LQG on both outputs, one current estimator on both measurements: u2 is free to
  cancel what u1 does to the yaw (the "decoupling objective" of ch. 8). Weights (this project's
  choice, in the spirit of the thesis's eq. 6.36, ``q_i = 1 / z_max^2``): :data:`STATE_WEIGHTS` on
  the pitch and yaw angles and integrators (pitch held ten times tighter, since it is the axis
  near its stops), 1 on the rates and rotor states, ``R = r I``. With ``Q = I`` the optimum moves
  the pitch by most of a radian to help the yaw with u1's reaction torque.
* The control weight ``r`` is chosen by a measured criterion (:func:`design_r_weight`): the smallest
  ``r`` of :data:`R_SCAN` whose MIMO loop, closed around the twin's full linearisation at hover
  (bending states and transport delay included), is stable with adequate margins at each plant
  input -- the loop broken at that input with the other loop closed, a gain margin of at least
  :data:`GAIN_MARGIN_DB` (up or down) and a phase margin of at least :data:`PHASE_MARGIN_DEG`, the
  classical requirements (:func:`input_margins`). The report, the CLI, the robustness batch and the
  Gymnasium tasks' LQG baseline all use this one choice.
* Two SISO loops: the same design on the ``u1 -> pitch`` and the ``u2 -> yaw`` columns of the model
  alone (:class:`trms.control.loop.DiagonalController`), the way a per-channel design ignores the
  coupling.

Scenarios (references in deviation rad, 80 s at 0.1 s): a pitch square wave of +-0.2 rad with the
yaw held at 0, and a yaw square wave of +-0.3 rad with the pitch held at 0 (one period of 80 s, so
one step up at 0 s and one down at 40 s). Measures: the tracked channel's rise and settling times
(2 % band) and overshoot, the other channel's largest excursion (cross-coupling), and the control
effort (RMS and total variation of both commanded inputs). The section that shows them:
:mod:`trms.experiments.ch8_mimo_section`.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import control
import numpy as np

from trms.control.loop import Controller, DiagonalController, closed_loop, deviation_limits
from trms.control.lqg import LQGController, design_lqg
from trms.control.metrics import square_wave_metrics, total_variation
from trms.errors import DesignError, DivergenceError
from trms.experiments.ch67_lqg import full_swing, worst
from trms.plant import Plant
from trms.record import Record
from trms.signals import square_wave

__all__ = [
    "R_SCAN",
    "GAIN_MARGIN_DB",
    "PHASE_MARGIN_DEG",
    "InputMargins",
    "input_margins",
    "margin_scan",
    "choose_r_weight",
    "design_r_weight",
    "shipped_margin_scan",
    "scan_runs",
    "STATE_WEIGHTS",
    "INTEGRATOR_WEIGHTS",
    "weights",
    "SCENARIOS",
    "CONTROLLERS",
    "AutopilotRun",
    "controllers",
    "scenario_reference",
    "autopilot_runs",
    "measures",
]

#: The control weights ``R = r I`` scanned for the design choice (half decades).
R_SCAN = (10.0, 30.0, 100.0, 300.0, 1000.0, 3000.0, 10000.0, 30000.0, 100000.0)
#: Adequate margins at each plant input: the classical gain margin (dB, a factor 2 up or down) and
#: phase margin (deg).
GAIN_MARGIN_DB = 6.0
PHASE_MARGIN_DEG = 30.0
#: Diagonal state weights by state name (angles) and integrator weights by tracked output; 1 elsewhere.
STATE_WEIGHTS = {"pitch": 100.0, "yaw": 10.0}
INTEGRATOR_WEIGHTS = {"pitch": 10.0, "yaw": 1.0}
#: Scenario name -> (tracked output index, amplitude rad).
SCENARIOS = {"pitch square wave": (0, 0.2), "yaw square wave": (1, 0.3)}
#: Controller names, in the report's order.
CONTROLLERS = ("MIMO LQG", "two SISO loops")
#: Scenario length and square-wave period (s).
DURATION = 80.0


def weights(model: control.StateSpace) -> np.ndarray:
    """Diagonal ``Q`` on ``[x; xi]`` of an integral LQG on ``model`` (all outputs tracked), by state and output name."""
    q = [STATE_WEIGHTS.get(n, 1.0) for n in model.state_labels]
    q += [INTEGRATOR_WEIGHTS.get(n, 1.0) for n in model.output_labels]
    return np.diag(q)


def controllers(
    model: control.StateSpace, r_weight: float | None = None, limits: tuple[np.ndarray, np.ndarray] | None = None
) -> dict[str, Controller]:
    """The MIMO LQG and the two SISO loops designed on the 2-DOF model (inputs u1, u2; outputs pitch, yaw),
    both with the weights of :func:`weights`.

    Parameters
    ----------
    model : control.StateSpace
        Discrete, ``D = 0``.
    r_weight : float, optional
        ``R = r_weight I``; default :func:`design_r_weight` at the model's sample time.
    limits : tuple of numpy.ndarray, optional
        Deviation limits (V) of both inputs.
    """
    if r_weight is None:
        r_weight = design_r_weight(float(model.dt))
    mimo = LQGController(design_lqg(model, Q=weights(model), R=r_weight), limits)
    A, B, C = (np.asarray(m, float) for m in (model.A, model.B, model.C))
    loops = []
    for i in range(2):
        sub = control.ss(
            A,
            B[:, [i]],
            C[[i]],
            np.zeros((1, 1)),
            model.dt,
            states=list(model.state_labels),
            inputs=[model.input_labels[i]],
            outputs=[model.output_labels[i]],
        )
        lim = None if limits is None else (limits[0][i], limits[1][i])
        loops.append(LQGController(design_lqg(sub, Q=weights(sub), R=r_weight), lim))
    return {"MIMO LQG": mimo, "two SISO loops": DiagonalController(loops, (0, 1), (0, 1), 2)}


# ------------------------------------------------------------------------------ the design choice of R
@dataclass(frozen=True)
class InputMargins:
    """Margins of the MIMO LQG loop at each plant input for one ``R = r I``.

    Attributes
    ----------
    r_weight : float
        ``r``.
    gain_margin_db, phase_margin_deg : tuple of float
        Per input (u1, u2), the loop broken there with the other loop closed: the smallest factor (dB),
        up or down, that takes the loop to -1 where it crosses the negative real axis, and the
        smallest distance (deg) of its phase from -180 deg where its gain crosses 1 (``inf`` where
        it never does).
    stable : bool
        The nominal closed loop is stable.
    """

    r_weight: float
    gain_margin_db: tuple[float, float]
    phase_margin_deg: tuple[float, float]
    stable: bool

    @property
    def adequate(self) -> bool:
        """Stable, with :data:`GAIN_MARGIN_DB` and :data:`PHASE_MARGIN_DEG` at both inputs."""
        return (
            self.stable
            and min(self.gain_margin_db) >= GAIN_MARGIN_DB
            and min(self.phase_margin_deg) >= PHASE_MARGIN_DEG
        )


def _siso_margins(loop: control.StateSpace) -> tuple[float, float]:
    """Gain margin (dB, up or down) and phase margin (deg) of a discrete SISO loop.

    The loop is evaluated on a log grid up to the Nyquist frequency; each crossing (of ``|L| = 1``, or
    of the real axis) is located by linear interpolation between the two grid points around it.
    """
    w = np.geomspace(1e-4, np.pi / loop.dt, 4000)
    h = np.asarray(loop(np.exp(1j * w * loop.dt))).ravel()

    def at(k: int, x: np.ndarray) -> complex:  # the loop where x crosses zero between k and k + 1
        t = x[k] / (x[k] - x[k + 1])
        return complex(h[k] + t * (h[k + 1] - h[k]))

    log_mag = np.log(np.abs(h))
    gain_cross = [at(int(k), log_mag) for k in np.flatnonzero(np.diff(np.sign(log_mag)) != 0)]
    real_axis = [at(int(k), h.imag) for k in np.flatnonzero(np.diff(np.sign(h.imag)) != 0)]
    if h.imag[-1] == 0.0 or abs(h.imag[-1]) < 1e-12 * abs(h[-1]):  # at Nyquist a discrete loop is real
        real_axis.append(complex(h[-1]))
    pm = min((180.0 - abs(np.degrees(np.angle(c))) for c in gain_cross), default=float("inf"))
    gm = min((abs(20.0 * np.log10(abs(c.real))) for c in real_axis if c.real < 0), default=float("inf"))
    return float(gm), float(pm)


def input_margins(plant_model: control.StateSpace, design_model: control.StateSpace, r_weight: float) -> InputMargins:
    """Break the MIMO LQG loop at each plant input in turn (the other loop closed) and read its margins.

    The compensator (:meth:`trms.control.lqg.LQGController.compensator`) maps both measurements to
    both inputs; the loop at the plant inputs is ``L = -C_y(z) G(z)`` (2 x 2).

    Parameters
    ----------
    plant_model : control.StateSpace
        Discrete 2-DOF plant the loop is closed around (the twin's linearisation), same sample time.
    design_model : control.StateSpace
        The model the LQG is designed on (:func:`trms.worlds.design_model`).
    r_weight : float
        ``R = r_weight I``.

    Examples
    --------
    >>> from trms.worlds import design_model
    >>> m = design_model("2dof")
    >>> input_margins(m, m, 1000.0).stable
    True
    """
    ctrl = controllers(design_model, r_weight)["MIMO LQG"]
    assert isinstance(ctrl, LQGController)
    comp = ctrl.compensator()
    n_ref = comp.ninputs - plant_model.noutputs
    c_y = control.ss(comp.A, comp.B[:, n_ref:], comp.C, comp.D[:, n_ref:], comp.dt)
    plant = control.ss(plant_model.A, plant_model.B, plant_model.C, plant_model.D, plant_model.dt)
    loop = control.series(plant, -c_y)
    closed = control.feedback(loop, np.eye(2), sign=-1)
    stable = bool(np.all(np.abs(control.poles(closed)) < 1.0))
    gms, pms = [], []
    for i in range(2):
        other = np.zeros((2, 2))
        other[1 - i, 1 - i] = 1.0
        half = control.feedback(loop, other, sign=-1)
        gm, pm = _siso_margins(control.ss(half.A, half.B[:, [i]], half.C[[i]], half.D[[i]][:, [i]], half.dt))
        gms.append(gm)
        pms.append(pm)
    return InputMargins(float(r_weight), (gms[0], gms[1]), (pms[0], pms[1]), stable)


def margin_scan(
    plant_model: control.StateSpace, design_model: control.StateSpace, weights: Sequence[float] = R_SCAN
) -> list[InputMargins]:
    """:func:`input_margins` for every ``r`` of ``weights``."""
    return [input_margins(plant_model, design_model, r) for r in weights]


def choose_r_weight(scan: Sequence[InputMargins]) -> float:
    """The smallest ``r`` of a scan whose loop has adequate margins (:attr:`InputMargins.adequate`).

    Raises
    ------
    DesignError
        No ``r`` of the scan does.

    Examples
    --------
    >>> choose_r_weight([InputMargins(1.0, (3.0, 9.0), (40.0, 60.0), True),
    ...                  InputMargins(10.0, (7.0, 9.0), (35.0, 60.0), True)])
    10.0
    """
    for m in sorted(scan, key=lambda m: m.r_weight):
        if m.adequate:
            return m.r_weight
    raise DesignError(
        f"no R = r I of {', '.join(f'{m.r_weight:g}' for m in scan)} gives the MIMO LQG a stable loop with "
        f"{GAIN_MARGIN_DB:g} dB and {PHASE_MARGIN_DEG:g} deg at each plant input"
    )


@functools.lru_cache(maxsize=4)
def shipped_margin_scan(sample_time: float = 0.1) -> tuple[InputMargins, ...]:
    """:func:`margin_scan` over :data:`R_SCAN` of the loop designed on ``design_model("2dof", sample_time)`` and
    closed around the shipped twin's ``Twin("2dof", sample_time).linearise().discrete`` (computed once per process
    and sample time: the design choice and the report's margin table read the same scan)."""
    from trms.twin import Twin
    from trms.worlds import design_model

    plant = Twin("2dof", sample_time).linearise().discrete
    return tuple(margin_scan(plant, design_model("2dof", sample_time)))


def design_r_weight(sample_time: float = 0.1) -> float:
    """The chapter 8 design choice: :func:`choose_r_weight` over :data:`R_SCAN` on the shipped twin
    (:func:`shipped_margin_scan`).

    Examples
    --------
    >>> design_r_weight() in R_SCAN
    True
    """
    return choose_r_weight(shipped_margin_scan(sample_time))


def scenario_reference(name: str, sample_time: float) -> np.ndarray:
    """The ``(N, 2)`` reference (deviation rad) of a scenario."""
    tracked, amplitude = SCENARIOS[name]
    ref = np.zeros((int(round(DURATION / sample_time)), 2))
    ref[:, tracked] = square_wave(DURATION, sample_time, DURATION, amplitude)
    return ref


@dataclass
class AutopilotRun:
    """One controller in one scenario on one plant.

    Attributes
    ----------
    status : str
        ``"ran"`` or ``"diverged"``.
    measures : dict
        ``TR``, ``TS`` (s, tracked channel, worst step), ``overshoot`` (%), ``cross`` (rad, largest
        excursion of the other channel), ``rms u1``, ``rms u2`` (V), ``TV`` (V, both inputs).
    record : Record or None
    """

    status: str
    measures: dict[str, float]
    record: Record | None


def measures(record: Record, tracked: int) -> dict[str, float]:
    """The autopilot's measures of one closed-loop run (the columns of the chapter 8 tables).

    Parameters
    ----------
    record : Record
        A 2-DOF closed loop from :func:`trms.control.loop.closed_loop` (``reference`` and ``control`` extras).
    tracked : int
        The output that follows the square wave (0 pitch, 1 yaw); the other is the cross-coupled one.

    Returns
    -------
    dict
        ``TR``, ``TS`` (s, 2 % band, the worst full-swing step; nan when it never rose or settled),
        ``overshoot`` (%), ``cross`` (rad, largest excursion of the other output), ``rms u1``, ``rms u2`` (V),
        ``TV`` (V, total variation of both inputs).

    Examples
    --------
    >>> t = np.arange(200) * 0.1
    >>> ref = np.column_stack([np.where(t < 10, 0.2, -0.2), np.zeros(200)])
    >>> y = np.column_stack([ref[:, 0], np.full(200, 0.01)])
    >>> rec = Record(t, np.zeros((200, 2)), y, ("u1", "u2"), ("pitch", "yaw"), {"reference": ref,
    ...              "control": np.ones((200, 2))})
    >>> m = measures(rec, 0)
    >>> m["overshoot"], m["cross"], m["rms u1"]
    (0.0, 0.01, 1.0)
    """
    steps = full_swing(square_wave_metrics(record, output=tracked))
    other = 1 - tracked
    u = record.extras["control"]
    return {
        "TR": worst([m.rise_time for m in steps]),
        "TS": worst([m.settling_time for m in steps]),
        "overshoot": float(max(m.overshoot for m in steps)),
        "cross": float(np.max(np.abs(record.deviations()[1][:, other]))),
        "rms u1": float(np.sqrt(np.mean(u[:, 0] ** 2))),
        "rms u2": float(np.sqrt(np.mean(u[:, 1] ** 2))),
        "TV": total_variation(u),
    }


def autopilot_runs(
    plant: Plant, model: control.StateSpace, seed: int = 0, r_weight: float | None = None
) -> dict[tuple[str, str], AutopilotRun]:
    """Both controllers in both scenarios on a 2-DOF plant.

    Parameters
    ----------
    plant : Plant
        The linear model or the twin (2-DOF, 0.1 s).
    model : control.StateSpace
        Design model (:func:`trms.worlds.design_model` ``("2dof")``).
    seed : int
        Plant seed.
    r_weight : float, optional
        ``R = r_weight I``; default :func:`design_r_weight`.

    Returns
    -------
    dict keyed ``(controller, scenario)``
    """
    out = {}
    for name, ctrl in controllers(model, r_weight, deviation_limits(plant)).items():
        for scen, (tracked, _) in SCENARIOS.items():
            ref = scenario_reference(scen, plant.sample_time)
            try:
                rec = closed_loop(plant, ctrl, ref, seed=seed, metadata={"controller_design": name, "scenario": scen})
            except DivergenceError:
                out[(name, scen)] = AutopilotRun("diverged", {}, None)
                continue
            out[(name, scen)] = AutopilotRun("ran", measures(rec, tracked), rec)
    return out


def scan_runs(
    plant: Plant,
    model: control.StateSpace,
    weights: Sequence[float] = R_SCAN,
    seed: int = 0,
    flown: Mapping[float, Mapping[str, AutopilotRun]] | None = None,
) -> dict[float, dict[str, AutopilotRun]]:
    """The MIMO LQG in both scenarios on ``plant`` for every ``r`` of ``weights`` (the scan's runs).

    Parameters
    ----------
    plant : Plant
        The 2-DOF plant.
    model : control.StateSpace
        Design model (:func:`trms.worlds.design_model` ``("2dof")``).
    weights : sequence of float
        The ``r`` of ``R = r I`` to fly.
    seed : int
        Plant seed.
    flown : mapping, optional
        Runs already flown on this plant at this seed, by ``r`` then scenario (the MIMO LQG of
        :func:`autopilot_runs` at its weight): taken as they are, not flown again.

    Returns
    -------
    dict
        ``{r: {scenario: AutopilotRun}}``.

    Examples
    --------
    >>> from trms.worlds import design_model, make_plant
    >>> done = {10.0: {s: AutopilotRun("ran", {}, None) for s in SCENARIOS}}
    >>> scan_runs(make_plant("linear", "2dof"), design_model("2dof"), [10.0], flown=done) == done
    True
    """
    out: dict[float, dict[str, AutopilotRun]] = {}
    for r in weights:
        if flown is not None and float(r) in flown:
            out[float(r)] = dict(flown[float(r)])
            continue
        ctrl = controllers(model, r, deviation_limits(plant))["MIMO LQG"]
        out[float(r)] = {}
        for scen, (tracked, _) in SCENARIOS.items():
            ref = scenario_reference(scen, plant.sample_time)
            try:
                rec = closed_loop(plant, ctrl, ref, seed=seed, metadata={"R": float(r), "scenario": scen})
            except DivergenceError:
                out[float(r)][scen] = AutopilotRun("diverged", {}, None)
                continue
            out[float(r)][scen] = AutopilotRun("ran", measures(rec, tracked), rec)
    return out
