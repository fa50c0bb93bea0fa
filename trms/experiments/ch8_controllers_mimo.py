"""The 2-DOF comparison: MIMO LQG, decentralised PID, constrained MPC and H-infinity on pitch and yaw together.

Every controller is designed once on the 2-DOF design model (:func:`~trms.worlds.design_model` ``("2dof")``, the
twin's linearisation at hover reduced to its rigid-body and motor states, 0.1 s) and flown through
:func:`~trms.control.loop.closed_loop` in both scenarios of :mod:`~trms.experiments.ch8_mimo_lqg` (a pitch square
wave with the yaw held at 0, and a yaw square wave with the pitch held at 0) on the linear 2-DOF model and on the
twin in moving air, at the same seeds.

The designs:

* **MIMO LQG**: chapter 8's autopilot (:func:`~trms.experiments.ch8_mimo_lqg.controllers`, its ``R`` the margin-based
  choice of :func:`~trms.experiments.ch8_mimo_lqg.design_r_weight`).
* **MIMO PID**: pitch from the main rotor (u1), yaw from the tail rotor (u2), each PID tuned by
  :func:`~trms.control.pid.tune_pid` on its own channel of the model (:func:`~trms.control.pid.decentralised_pid`),
  with the +-10 V limits and back-calculation.
* **MIMO MPC**: :func:`~trms.control.mpc.mpc_for_plant` on the whole 2 x 2 model, horizon 30, both inputs' +-10 V,
  a rate limit of 1 V per sample and both end stops (soft), both outputs tracked (offset-free through the input
  disturbance estimate); ``Q = C' C``, ``R = I`` and a disturbance random walk ``Qd = 1e-5`` V^2 (:data:`MPC_OPTIONS`).
* **MIMO H-infinity**: mixed sensitivity on the 2 x 2 plant with diagonal weights (:data:`HINF_WEIGHTS`,
  :func:`~trms.control.hinf.diagonal_weights`), Tustin-discretised at 0.1 s. ``mixsyn`` needs a continuous plant; the
  design model's own continuous form is used: the same reduced linearisation before its zero-order hold, with the
  rotors' transport delay as a second-order Pade approximation per input (:func:`continuous_design_model`).

Measured per controller, scenario and world, over the seeds (:func:`~trms.control.metrics.square_wave_metrics` on the
tracked axis): overshoot, settling time (2 % band; steps that never settle counted apart), RMS control, the share of
the time commanded beyond the limits, and the cross-coupling: the largest excursion of the untracked axis.

MPC needs ``osqp`` and H-infinity ``slycot`` (the ``control`` extra); without them those rows say so.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import control
import numpy as np

from trms.control.hinf import HinfController, HinfDesign, design_mixsyn, diagonal_weights, pitch_weights
from trms.control.loop import Controller, closed_loop, deviation_limits
from trms.control.lqg import LQGController, LQGDesign
from trms.control.margins import DiskMargin, input_disk_margins
from trms.control.metrics import square_wave_metrics
from trms.control.mpc import mpc_for_plant
from trms.control.pid import PIDGains, decentralised_pid
from trms.control.realization import residualise
from trms.errors import ConfigurationError, DivergenceError, InputError, SimulationError, check_choice, check_in_range
from trms.experiments.ch8_controllers import feedback_compensator, summarise_steps
from trms.experiments.ch8_mimo_lqg import DURATION, SCENARIOS, controllers
from trms.plant import Plant
from trms.present.sections import finite_or
from trms.present.tables import ComparisonTable
from trms.reference import SAMPLE_TIME_2DOF
from trms.signals import square_wave
from trms.worlds import design_model, make_plant, rigid_states

__all__ = [
    "CONTROLLERS",
    "WORLDS",
    "HINF_WEIGHTS",
    "MPC_OPTIONS",
    "PADE_ORDER",
    "MimoCase",
    "MimoComparison",
    "MimoDesigns",
    "design_controllers_mimo",
    "controllers_for_mimo",
    "continuous_design_model",
    "compare_controllers_mimo",
    "table_controllers_mimo",
]

#: The controllers compared, in the table's order.
CONTROLLERS = ("MIMO LQG", "MIMO PID", "MIMO MPC", "MIMO H-infinity")
#: The worlds: name -> (world of :func:`~trms.worlds.make_plant`, still air).
WORLDS = {"linear model": "linear", "twin, moving air": "twin"}
#: Per channel (pitch, yaw), the :func:`~trms.control.hinf.pitch_weights` of the H-infinity design. Pitch: the 1-DOF
#: comparison's robust weight (0.3 rad/s crossover, peak 2, control weight 0.2), which keeps the loop off the delay
#: and bending modes the design model lacks. Yaw: a lower crossover (0.2 rad/s), since the yaw's disturbance from u1
#: (its largest gain, 12 rad/V at DC against 3.3 rad/V from u2) must be rejected by the weaker tail rotor, with the
#: same peak and control weight. Both keep ``|S(0)| <= 1e-3``.
HINF_WEIGHTS = ({"bandwidth": 0.3, "peak": 2.0, "effort": 0.2}, {"bandwidth": 0.2, "peak": 2.0, "effort": 0.2})
#: The MPC's options beyond the plant's limits and end stops: the 1-DOF comparison's horizon and rate limit, and a
#: slower disturbance estimate than the default ``Qd = 1e-3``, which on the twin (seed 0 only, the one seed looked
#: at) let the pitch square wave drive the yaw to its end stop; ``Qd = 1e-5`` settles both scenarios there.
MPC_OPTIONS = {"horizon": 30, "rate_limit": 1.0, "Qd": 1e-5}
#: Order of the Pade approximation of the rotors' transport delay in the H-infinity design plant.
PADE_ORDER = 2


@dataclass(frozen=True)
class MimoCase:
    """One controller in one scenario on one world, over the seeds.

    Attributes
    ----------
    controller, scenario, world : str
    overshoot : float
        Mean overshoot of the tracked axis's steps (%).
    settling : float
        Median settling time of the settled steps (s; NaN if none settled).
    unsettled : int
        Steps that never settled within the 2 % band.
    steps : int
    rms_control : float
        Mean RMS of both commanded inputs (V, deviation).
    saturated : float
        Mean share of the time commanded beyond a limit (fraction).
    cross : float
        Mean over the seeds of the untracked axis's largest excursion (rad, deviation).
    status : str
        ``"flown"``, or why not (a missing extra, a diverged run).
    """

    controller: str
    scenario: str
    world: str
    overshoot: float
    settling: float
    unsettled: int
    steps: int
    rms_control: float
    saturated: float
    cross: float
    status: str = "flown"


@dataclass(frozen=True)
class MimoComparison:
    """Every controller in every scenario on every world.

    Attributes
    ----------
    cases : tuple of MimoCase
    gamma : float
        The H-infinity design's achieved ``gamma`` (NaN without slycot).
    seeds : tuple of int
    sample_time, duration : float
        Seconds.
    margins : dict
        Per controller: the loop-at-a-time disk margins at u1 and u2 on the design model
        (:func:`~trms.control.margins.input_disk_margins`), or None (MPC: no linear compensator while a constraint
        can act).
    """

    cases: tuple[MimoCase, ...]
    gamma: float
    seeds: tuple[int, ...]
    sample_time: float
    duration: float
    margins: dict[str, tuple[DiskMargin, ...] | None] = field(default_factory=dict)


@dataclass(frozen=True)
class MimoDesigns:
    """Every design of the comparison, made once from the design model (they do not depend on the plant)."""

    model: control.StateSpace
    lqg: LQGDesign
    pid: tuple[PIDGains, ...]
    hinf: HinfDesign | None
    missing_hinf: str | None


def continuous_design_model(sample_time: float = SAMPLE_TIME_2DOF, pade_order: int = PADE_ORDER) -> control.StateSpace:
    """The continuous form of :func:`~trms.worlds.design_model` ``("2dof")``: the twin's linearisation at hover reduced
    to its rigid-body and motor states, each input delayed by the rotors' transport delay (Pade approximation).

    Parameters
    ----------
    sample_time : float
        Sample time (s) of the linearisation.
    pade_order : int
        Order of the Pade approximation of the delay, 1 to 6.

    Returns
    -------
    control.StateSpace
        Continuous, inputs u1, u2 (deviation V), outputs pitch, yaw (deviation rad).

    Examples
    --------
    Six rigid-body and motor states and two per input for the delay; the DC gain is the design model's:

    >>> g = continuous_design_model()
    >>> d = design_model("2dof")
    >>> g.nstates, bool(np.allclose(control.dcgain(g), control.dcgain(d), rtol=1e-6))
    (10, True)
    """
    from trms.twin import Twin

    order = int(check_in_range("pade_order", pade_order, 1, 6))
    lin = Twin("2dof", sample_time).linearise()
    reduced = residualise(lin.continuous, rigid_states(lin.state_names))
    delay = control.ss(control.tf(*control.pade(float(lin.input_delay), order)))
    plant = control.series(control.append(delay, delay), reduced)
    return control.ss(
        plant.A, plant.B, plant.C, plant.D, inputs=["u1", "u2"], outputs=list(lin.continuous.output_labels)
    )


@functools.lru_cache(maxsize=4)
def design_controllers_mimo(sample_time: float, r_weight: float | None) -> MimoDesigns:
    """Every design on ``design_model("2dof", sample_time)``, made once per process (they depend on the model only).

    Parameters
    ----------
    sample_time : float
        Sample time of the design model (s).
    r_weight : float or None
        The MIMO LQG's ``R = r I`` (None: chapter 8's design choice).

    Returns
    -------
    MimoDesigns

    Examples
    --------
    >>> d = design_controllers_mimo(0.1, 1000.0)
    >>> len(d.pid), d.model.ninputs
    (2, 2)
    """
    model = design_model("2dof", sample_time)
    lqg = controllers(model, r_weight)["MIMO LQG"]
    assert isinstance(lqg, LQGController)
    pid = decentralised_pid(model)
    hinf, missing = None, None
    try:
        weights = diagonal_weights(*(pitch_weights(**w) for w in HINF_WEIGHTS))
        hinf = design_mixsyn(continuous_design_model(float(model.dt)), *weights, sample_time=float(model.dt))
    except ConfigurationError as exc:
        missing = str(exc)
    return MimoDesigns(model, lqg.design, tuple(c.gains for c in pid.loops), hinf, missing)


def controllers_for_mimo(designs: MimoDesigns, plant: Plant) -> tuple[dict[str, Controller], dict[str, str]]:
    """A fresh controller of each kind of :data:`CONTROLLERS` for ``plant`` (its actuator limits and stops), and the
    reason for each kind that cannot be built (a missing extra).

    Examples
    --------
    >>> from trms.worlds import make_plant
    >>> ctrls, missing = controllers_for_mimo(design_controllers_mimo(0.1, 1000.0), make_plant("linear", "2dof"))
    >>> sorted(ctrls) == sorted(set(CONTROLLERS) - set(missing))
    True
    """
    limits = deviation_limits(plant)
    out: dict[str, Controller] = {
        "MIMO LQG": LQGController(designs.lqg, limits),
        "MIMO PID": decentralised_pid(designs.model, limits, gains=designs.pid),
    }
    missing = {}
    try:
        out["MIMO MPC"] = mpc_for_plant(designs.model, plant, **MPC_OPTIONS)
    except ConfigurationError as exc:
        missing["MIMO MPC"] = str(exc)
    if designs.hinf is not None:
        out["MIMO H-infinity"] = HinfController(designs.hinf, limits)
    else:
        missing["MIMO H-infinity"] = str(designs.missing_hinf)
    return out, missing


def _reference(scenario: str, sample_time: float, duration: float) -> np.ndarray:
    """The scenario's ``(N, 2)`` reference (deviation rad): one square-wave period of ``duration`` on its axis."""
    tracked, amplitude = SCENARIOS[scenario]
    ref = np.zeros((int(round(duration / sample_time)), 2))
    ref[:, tracked] = square_wave(duration, sample_time, duration, amplitude)
    return ref


def _case(name: str, scenario: str, world: str, runs: list, crosses: list[float], half: float, why: str) -> MimoCase:
    """Aggregate the steps and cross-coupling peaks of every seed's run into one row."""
    if not runs:
        nan = math.nan
        return MimoCase(name, scenario, world, nan, nan, 0, 0, nan, nan, nan, why)
    return MimoCase(
        name,
        scenario,
        world,
        *summarise_steps(runs, half),
        float(np.mean(crosses)),
        "flown" if not why else f"flown; {why}",
    )


def compare_controllers_mimo(
    seeds: Sequence[int] = (0, 1, 2),
    worlds: Sequence[str] = tuple(WORLDS),
    duration: float = DURATION,
    r_weight: float | None = None,
) -> MimoComparison:
    """Fly every controller in both scenarios on every world at ``seeds`` (see the module docstring).

    Parameters
    ----------
    seeds : sequence of int
        Plant seeds (noise, turbulence), the same for every controller.
    worlds : sequence of str
        Keys of :data:`WORLDS` (both by default).
    duration : float
        Length of each run, one square-wave period (s): 80 s by default (steps at 0 and ``duration / 2``).
    r_weight : float, optional
        The MIMO LQG's ``R = r I``; default chapter 8's choice
        (:func:`~trms.experiments.ch8_mimo_lqg.design_r_weight`).

    Returns
    -------
    MimoComparison

    Raises
    ------
    InputError
        No seed, an unknown world, a duration out of [4, 600] s.

    Examples
    --------
    >>> c = compare_controllers_mimo(seeds=(0,), worlds=["linear model"], duration=20.0, r_weight=1000.0)
    >>> [(k.controller, k.scenario, k.steps) for k in c.cases][:2]
    [('MIMO LQG', 'pitch square wave', 2), ('MIMO LQG', 'yaw square wave', 2)]
    >>> c.gamma > 0, all(k.cross >= 0 for k in c.cases)
    (True, True)
    """
    seeds = tuple(int(s) for s in seeds)
    if not seeds:
        raise InputError("seeds must name at least one seed")
    for world in worlds:
        check_choice("world", world, tuple(WORLDS), error=InputError)
    duration = check_in_range("duration", duration, 4.0, 600.0, unit=" s")
    ts = SAMPLE_TIME_2DOF
    designs = design_controllers_mimo(ts, None if r_weight is None else float(r_weight))
    refs = {scen: _reference(scen, ts, duration) for scen in SCENARIOS}
    rows = []
    for world in worlds:
        steps: dict[tuple[str, str], list] = {(n, s): [] for n in CONTROLLERS for s in SCENARIOS}
        cross: dict[tuple[str, str], list[float]] = {key: [] for key in steps}
        why: dict[tuple[str, str], str] = {}
        for seed in seeds:
            plant = make_plant(WORLDS[world], "2dof", ts, seed=seed)
            ctrls, missing = controllers_for_mimo(designs, plant)
            for name, reason in missing.items():
                why.update({(name, s): f"not flown: {reason}" for s in SCENARIOS})
            for name, ctrl in ctrls.items():
                for scen, (tracked, _) in SCENARIOS.items():
                    try:
                        rec = closed_loop(plant, ctrl, refs[scen], seed=seed)
                    except (DivergenceError, SimulationError) as exc:
                        why[(name, scen)] = f"seed {seed} failed: {type(exc).__name__}"
                        continue
                    steps[(name, scen)] += square_wave_metrics(rec, output=tracked)
                    cross[(name, scen)].append(float(np.max(np.abs(rec.deviations()[1][:, 1 - tracked]))))
        for name in CONTROLLERS:
            for scen in SCENARIOS:
                key = (name, scen)
                rows.append(_case(name, scen, world, steps[key], cross[key], duration / 2.0, why.get(key, "")))
    gamma = designs.hinf.gamma if designs.hinf is not None else math.nan
    ctrls, _ = controllers_for_mimo(designs, make_plant("linear", "2dof", ts))
    margins: dict[str, tuple[DiskMargin, ...] | None] = {}
    for name, ctrl in ctrls.items():
        feedback = feedback_compensator(ctrl, designs.model.noutputs)
        margins[name] = None if feedback is None else input_disk_margins(designs.model, feedback)
    return MimoComparison(tuple(rows), gamma, seeds, ts, duration, margins)


def table_controllers_mimo(comparison: MimoComparison) -> ComparisonTable:
    """The comparison as a table: one row per controller, scenario and world.

    Examples
    --------
    >>> case = MimoCase("MIMO PID", "pitch square wave", "linear model", 4.1, 9.7, 0, 2, 0.3, 0.0, 0.05)
    >>> t = table_controllers_mimo(MimoComparison((case,), 1.2, (0,), 0.1, 80.0))
    >>> t.rows[0][:5], t.rows[0][-2:]
    (['MIMO PID', 'pitch square wave', 'linear model', 4.1, 9.7], [0.05, '-'])
    """
    table = ComparisonTable(
        f"Ch. 8 future work: MIMO LQG, PID, MPC and H-infinity on the 2-DOF rig (Ts = {comparison.sample_time:g} s)",
        [
            "controller",
            "scenario",
            "world",
            "overshoot (%)",
            "settling (s)",
            "steps unsettled",
            "RMS control (V)",
            "time saturated (%)",
            "untracked axis' peak (rad)",
            "disk margin u1; u2 (dB, deg)",
        ],
    )

    def margin_cell(name: str) -> str:
        margins = comparison.margins.get(name)
        if margins is None:
            return "-"
        return "; ".join(
            f"{m.gain_margin_db:.1f} dB, {m.phase_margin_deg:.1f} deg" if m.stable else "closed loop unstable"
            for m in margins
        )

    for c in comparison.cases:
        table.rows.append(
            [
                c.controller,
                c.scenario,
                c.world,
                finite_or(c.overshoot, "not flown"),
                finite_or(c.settling, "none settled" if c.steps else "not flown"),  # no step flown: none to settle
                f"{c.unsettled}/{c.steps}" if c.status == "flown" else f"{c.unsettled}/{c.steps} ({c.status})",
                finite_or(c.rms_control, "not flown"),
                finite_or(100.0 * c.saturated, "not flown"),
                finite_or(c.cross, "not flown"),
                margin_cell(c.controller) if c.world == "linear model" and c.scenario == next(iter(SCENARIOS)) else "-",
            ]
        )
    amplitudes = ", ".join(f"{s} +-{a:g} rad" for s, (_, a) in SCENARIOS.items())
    table.notes += [
        f"One square-wave period of {comparison.duration:g} s per scenario ({amplitudes}), the other axis held at 0; "
        f"seeds {', '.join(map(str, comparison.seeds))}, the same for every controller; means over the steps and "
        "seeds, settling the median of the settled steps (2 % band).",
        "Designs on the 2-DOF design model: the chapter 8 MIMO LQG; two PIDs (u1 -> pitch, u2 -> yaw) tuned on their "
        f"own channels; MPC {MPC_OPTIONS} with +-10 V and both end stops; H-infinity mixed sensitivity with diagonal "
        f"weights {list(HINF_WEIGHTS)} (gamma = {comparison.gamma:.3g}).",
        "Disk margins at each plant input with the other loop closed, on the design model (MPC: no linear "
        "compensator while a constraint can act); 'closed loop unstable': the nominal MIMO loop itself is (loops "
        "designed one channel at a time can be, where an input drives both axes).",
    ]
    return table
