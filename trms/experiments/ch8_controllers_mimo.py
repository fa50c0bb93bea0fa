"""The 2-DOF comparison: MIMO LQG, decentralised PID, constrained MPC and H-infinity on pitch and yaw together.

Every controller is designed once on the 2-DOF design model (:func:`~trms.worlds.design_model` ``("2dof")``, the
twin's linearisation at hover reduced to its rigid-body and motor states, 0.1 s) and flown as chapter 8's
controllers fly (the reference prefilter; the thrust-curve inversion of both rotors on the twin) in both scenarios
of :mod:`~trms.experiments.ch8_mimo_lqg` (a 0.2 rad pitch step with the yaw held at 0, a 0.5 rad yaw step with the
pitch held at 0) on the linear 2-DOF model and on the twin in moving air, at the same seeds.

The designs:

* **MIMO LQG**: chapter 8's autopilot (:func:`~trms.experiments.ch8_mimo_lqg.controllers`, its per-channel weights).
* **MIMO PID**: pitch from the main rotor (u1), yaw from the tail rotor (u2), each PID tuned by
  :func:`~trms.control.pid.tune_pid` on its own channel of the model (:data:`PID_TUNING`: the pitch loop with its
  measurement filter and the damping constraint on the pitch mode, the yaw loop gentle, ``Ms = 1.3``), run side by
  side (:func:`~trms.control.pid.decentralised_pid`) with the +-10 V limits and back-calculation. Offered only with
  a disk gain margin of at least :data:`PID_GAIN_MARGIN_DB` at each plant input, the other loop closed, on the design
  model and on the twin's full linearisation (:func:`pid_refusal`); loops tuned one channel at a time can be
  unstable together, where an input drives both axes.
* **MIMO MPC**: :func:`~trms.control.mpc.mpc_for_plant` on the whole 2 x 2 model, horizon 30, both inputs' +-10 V,
  a rate limit of 1 V per sample and both end stops (soft), both outputs tracked (offset-free through the input
  disturbance estimate); ``Q = C' C``, ``R = I`` and a disturbance random walk ``Qd = 1e-5`` V^2 (:data:`MPC_OPTIONS`).
* **MIMO H-infinity**: mixed sensitivity on the 2 x 2 plant with diagonal weights (:data:`HINF_WEIGHTS`,
  :func:`~trms.control.hinf.diagonal_weights`) and an input-disturbance channel ``Wd = 0.4 I`` V
  (:data:`DISTURBANCE_WEIGHT`: 0.1, 0.2, 0.3 leave the pitch mode at 0.05, 0.07, 0.10), Tustin-discretised at 0.1 s.
  The synthesis needs a continuous plant; the design model's own continuous form is used: the same reduced
  linearisation before its zero-order hold, with the rotors' transport delay as a second-order Pade approximation
  per input (:func:`continuous_design_model`).

Measured per controller, scenario and world, over the seeds (:func:`~trms.experiments.ch8_mimo_lqg.measures`):
overshoot, settling time (the noise band at each target, :func:`~trms.experiments.ch8_mimo_lqg.rest_levels`; steps
that never settle counted apart) and the 5 % figure, RMS control, the share of the time commanded beyond the limits,
and the cross-coupling: the largest excursion of the untracked axis. On the design model: each feedback law's disk
margins at each input and its closed-loop damping of the pitch mode (:func:`~trms.control.damping.mode_damping`).

MPC needs ``osqp`` and H-infinity ``slycot`` (the ``control`` extra); without them those rows say so.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import control
import numpy as np

from trms.control.damping import MIN_DAMPING, ModeDamping, mode_damping
from trms.control.hinf import HinfController, HinfDesign, design_mixsyn, diagonal_weights, pitch_weights
from trms.control.loop import Controller, closed_loop
from trms.control.lqg import LQGController, LQGDesign
from trms.control.margins import DiskMargin, input_disk_margins
from trms.control.mpc import mpc_for_plant
from trms.control.pid import PIDGains
from trms.control.pid_tuning import channel_model, decentralised_pid, tune_pid
from trms.control.realization import residualise
from trms.errors import ConfigurationError, DivergenceError, InputError, SimulationError, check_choice, check_in_range
from trms.experiments.ch8_designs import INVERSION, feedback_compensator, reference_prefilter
from trms.experiments.ch8_mimo_lqg import (
    DURATION,
    SCENARIOS,
    AutopilotRun,
    controllers,
    measures,
    rest_levels,
    scenario_reference,
)
from trms.plant import Plant
from trms.present.sections import finite_or
from trms.present.tables import ComparisonTable
from trms.reference import END_STOPS, SAMPLE_TIME_2DOF
from trms.worlds import design_model, input_layer, make_plant, rigid_states

__all__ = [
    "CONTROLLERS",
    "WORLDS",
    "HINF_WEIGHTS",
    "DISTURBANCE_WEIGHT",
    "MPC_OPTIONS",
    "PID_TUNING",
    "PID_GAIN_MARGIN_DB",
    "PADE_ORDER",
    "MimoCase",
    "MimoComparison",
    "MimoDesigns",
    "design_controllers_mimo",
    "controllers_for_mimo",
    "continuous_design_model",
    "compare_controllers_mimo",
    "pid_refusal",
    "table_controllers_mimo",
]

#: The controllers compared, in the table's order.
CONTROLLERS = ("MIMO LQG", "MIMO PID", "MIMO MPC", "MIMO H-infinity")
#: The worlds: name -> world of :func:`~trms.worlds.make_plant`.
WORLDS = {"linear model": "linear", "twin, moving air": "twin"}
#: Per channel (pitch, yaw), the :func:`~trms.control.hinf.pitch_weights` of the H-infinity design. Pitch: the 1-DOF
#: comparison's robust weight (0.3 rad/s crossover, peak 2, control weight 0.2). Yaw: a lower crossover (0.2 rad/s),
#: since the yaw's disturbance from u1 (its largest gain, 16 rad/V at DC against 3.6 rad/V from u2) must be rejected
#: by the weaker tail rotor, with the same peak and control weight. Both keep ``|S(0)| <= 1e-3``.
HINF_WEIGHTS = ({"bandwidth": 0.3, "peak": 2.0, "effort": 0.2}, {"bandwidth": 0.2, "peak": 2.0, "effort": 0.2})
#: The H-infinity design's input-disturbance weight (V, times the identity).
DISTURBANCE_WEIGHT = 0.4
#: The MPC's options beyond the plant's limits and end stops: the 1-DOF comparison's horizon and rate limit, and a
#: slower disturbance estimate than the default ``Qd = 1e-3``.
MPC_OPTIONS = {"horizon": 30, "rate_limit": 1.0, "Qd": 1e-5}
#: The PIDs' :func:`~trms.control.pid.tune_pid` options, pitch loop then yaw loop.
PID_TUNING: tuple[dict[str, object], dict[str, object]] = (
    {"Ms": 1.6, "effort": 0.1, "min_damping": MIN_DAMPING, "damping_band": (0.2, 0.6)},
    {"Ms": 1.3},
)
#: The disk gain margin (dB) the decentralised PID needs at each input to be offered.
PID_GAIN_MARGIN_DB = 4.0
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
    settling_wide : float
        Median settling time of the steps settled within 5 % (s).
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
    settling_wide: float = math.nan


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
        (:func:`~trms.control.margins.input_disk_margins`; MPC's law while no constraint acts), or None.
    damping : dict
        Per controller: the pitch mode's closed-loop damping on the design model.
    refused : dict
        Controller -> why it is not offered (measured).
    """

    cases: tuple[MimoCase, ...]
    gamma: float
    seeds: tuple[int, ...]
    sample_time: float
    duration: float
    margins: dict[str, tuple[DiskMargin, ...] | None] = field(default_factory=dict)
    damping: dict[str, ModeDamping] = field(default_factory=dict)
    refused: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class MimoDesigns:
    """Every design of the comparison, made once from the design model (they do not depend on the plant);
    ``pid_refused`` says why the decentralised PID is not offered (None: it is, :func:`pid_refusal`)."""

    model: control.StateSpace
    lqg: LQGDesign
    pid: tuple[PIDGains, ...]
    hinf: HinfDesign | None
    missing_hinf: str | None
    pid_refused: str | None = None


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


def pid_refusal(model: control.StateSpace, gains: Sequence[PIDGains]) -> str | None:
    """Why the decentralised PID of ``gains`` is not offered as a baseline, or None: it needs a stable loop with a
    disk gain margin of at least :data:`PID_GAIN_MARGIN_DB` at each plant input (the other loop closed), on the
    design model and on the twin's full linearisation at hover.

    Examples
    --------
    >>> d = design_controllers_mimo(0.1)
    >>> pid_refusal(d.model, d.pid) is None
    True
    """
    from trms.twin import Twin

    feedback = feedback_compensator(decentralised_pid(model, gains=gains), model.noutputs)
    assert feedback is not None
    for label, plant in (
        ("design model", model),
        ("twin's linearisation", Twin("2dof", float(model.dt)).linearise().discrete),
    ):
        margins = input_disk_margins(plant, feedback)
        if not all(m.stable for m in margins):
            return f"the decentralised loops are unstable together on the {label}"
        low = min(m.gain_margin_db for m in margins)
        if low < PID_GAIN_MARGIN_DB:
            return f"disk gain margin {low:.1f} dB < {PID_GAIN_MARGIN_DB:g} dB at an input on the {label}"
    return None


@functools.lru_cache(maxsize=4)
def design_controllers_mimo(sample_time: float = SAMPLE_TIME_2DOF) -> MimoDesigns:
    """Every design on ``design_model("2dof", sample_time)``, made once per process (they depend on the model only).

    Parameters
    ----------
    sample_time : float
        Sample time of the design model (s).

    Returns
    -------
    MimoDesigns

    Examples
    --------
    >>> d = design_controllers_mimo(0.1)
    >>> len(d.pid), d.model.ninputs, d.pid[0].tm > 0
    (2, 2, True)
    """
    model = design_model("2dof", sample_time)
    lqg = controllers(model)["MIMO LQG"]
    assert isinstance(lqg, LQGController)
    pid = tuple(tune_pid(channel_model(model, k, k), **PID_TUNING[k]) for k in range(2))  # type: ignore[arg-type]
    hinf, missing = None, None
    try:
        weights = diagonal_weights(*(pitch_weights(**w) for w in HINF_WEIGHTS))
        disturbance = control.ss([], [], [], DISTURBANCE_WEIGHT * np.eye(2))
        hinf = design_mixsyn(
            continuous_design_model(float(model.dt)), *weights, sample_time=float(model.dt), Wd=disturbance
        )
    except ConfigurationError as exc:
        missing = str(exc)
    return MimoDesigns(model, lqg.design, pid, hinf, missing, pid_refusal(model, pid))


def controllers_for_mimo(
    designs: MimoDesigns, plant: Plant, inversion: bool = INVERSION
) -> tuple[dict[str, Controller], dict[str, str]]:
    """A fresh controller of each kind of :data:`CONTROLLERS` for ``plant`` (its actuator limits and stops, behind
    its thrust-curve inversion when ``inversion``), and the reason for each kind that is not built (a missing extra,
    a PID refused).

    Examples
    --------
    >>> ctrls, missing = controllers_for_mimo(design_controllers_mimo(0.1), make_plant("linear", "2dof"))
    >>> sorted(ctrls) == sorted(set(CONTROLLERS) - set(missing))
    True
    """
    limits, wrap = input_layer(plant, inversion)
    out: dict[str, Controller] = {"MIMO LQG": LQGController(designs.lqg, limits)}
    missing = {}
    if designs.pid_refused is None:
        out["MIMO PID"] = decentralised_pid(designs.model, limits, gains=designs.pid)
    else:
        missing["MIMO PID"] = f"not offered: {designs.pid_refused}"
    try:
        out["MIMO MPC"] = mpc_for_plant(designs.model, plant, input_limits=limits, **MPC_OPTIONS)
    except ConfigurationError as exc:
        missing["MIMO MPC"] = str(exc)
    if designs.hinf is not None:
        out["MIMO H-infinity"] = HinfController(designs.hinf, limits)
    else:
        missing["MIMO H-infinity"] = str(designs.missing_hinf)
    return {n: wrap(c) for n, c in out.items()}, missing


def _case(name: str, scenario: str, world: str, runs: list[AutopilotRun], half: float, why: str) -> MimoCase:
    """Aggregate every seed's run of one controller in one scenario into one row."""
    flown = [r for r in runs if r.measures]
    if not flown:
        nan = math.nan
        return MimoCase(name, scenario, world, nan, nan, 0, 0, nan, nan, nan, why or "not flown")
    records = [r.record for r in flown if r.record is not None]
    settle = np.array([v for r in flown for k, v in r.measures.items() if k.startswith("TS ") and k[3:].isdigit()])
    wide = np.array([r.measures["TS 5 %"] for r in flown])
    sat = [float(np.mean(np.any(np.asarray(rec.extras.get("saturated", np.zeros((1, 1)))), axis=1))) for rec in records]
    return MimoCase(
        name,
        scenario,
        world,
        float(np.mean([r.measures["overshoot"] for r in flown])),
        float(np.median(settle[np.isfinite(settle)])) if np.isfinite(settle).any() else math.nan,
        int(np.isnan(settle).sum()),
        int(settle.size),
        float(np.mean([0.5 * (r.measures["rms u1"] + r.measures["rms u2"]) for r in flown])),
        float(np.mean(sat)) if sat else math.nan,
        float(np.mean([r.measures["cross"] for r in flown])),
        "flown" if not why else f"flown; {why}",
        float(np.median(wide[np.isfinite(wide)])) if np.isfinite(wide).any() else math.nan,
    )


def compare_controllers_mimo(
    seeds: Sequence[int] = (0, 1, 2),
    worlds: Sequence[str] = tuple(WORLDS),
    duration: float = DURATION,
    inversion: bool = INVERSION,
) -> MimoComparison:
    """Fly every controller in both scenarios on every world at ``seeds`` (see the module docstring).

    Parameters
    ----------
    seeds : sequence of int
        Plant seeds (noise, turbulence), the same for every controller.
    worlds : sequence of str
        Keys of :data:`WORLDS` (both by default).
    duration : float
        Length of each run (s): the step is held for its first half; 80 s by default.
    inversion : bool
        Fly the twin behind its thrust-curve inversion.

    Returns
    -------
    MimoComparison

    Raises
    ------
    InputError
        No seed, an unknown world, a duration out of [4, 600] s.

    Examples
    --------
    >>> c = compare_controllers_mimo(seeds=(0,), worlds=["linear model"], duration=20.0)
    >>> [(k.controller, k.scenario, k.steps) for k in c.cases][:2]
    [('MIMO LQG', 'pitch step', 2), ('MIMO LQG', 'yaw step', 2)]
    >>> c.gamma > 0, all(k.cross >= 0 for k in c.cases if k.steps)
    (True, True)
    """
    seeds = tuple(int(s) for s in seeds)
    if not seeds:
        raise InputError("seeds must name at least one seed")
    for world in worlds:
        check_choice("world", world, tuple(WORLDS), error=InputError)
    duration = check_in_range("duration", duration, 4.0, 600.0, unit=" s")
    ts = SAMPLE_TIME_2DOF
    designs = design_controllers_mimo(ts)
    prefilter = reference_prefilter(ts)
    rows = []
    for world in worlds:
        runs: dict[tuple[str, str], list[AutopilotRun]] = {(n, s): [] for n in CONTROLLERS for s in SCENARIOS}
        why: dict[tuple[str, str], str] = {}
        for seed in seeds:
            plant = make_plant(WORLDS[world], "2dof", ts, seed=seed)
            ctrls, missing = controllers_for_mimo(designs, plant, inversion)
            for name, reason in missing.items():
                why.update({(name, s): f"not flown: {reason}" for s in SCENARIOS})
            for name, ctrl in ctrls.items():  # each loop resets the controller
                for scen, (tracked, _) in SCENARIOS.items():
                    try:
                        rest = rest_levels(plant, ctrl, scen, seed)
                        ref = scenario_reference(scen, ts, duration)
                        rec = closed_loop(plant, ctrl, ref, prefilter, seed=seed)
                    except (DivergenceError, SimulationError) as exc:
                        why[(name, scen)] = f"seed {seed} failed: {type(exc).__name__}"
                        continue
                    runs[(name, scen)].append(AutopilotRun("ran", measures(rec, tracked, rest), rec))
        for name in CONTROLLERS:
            for scen in SCENARIOS:
                key = (name, scen)
                rows.append(_case(name, scen, world, runs[key], duration / 2.0, why.get(key, "")))
    gamma = designs.hinf.gamma if designs.hinf is not None else math.nan
    ctrls, _ = controllers_for_mimo(designs, make_plant("linear", "2dof", ts), inversion=False)
    margins: dict[str, tuple[DiskMargin, ...] | None] = {}
    damping: dict[str, ModeDamping] = {}
    for name, ctrl in ctrls.items():
        feedback = feedback_compensator(ctrl, designs.model.noutputs)
        margins[name] = None if feedback is None else input_disk_margins(designs.model, feedback)
        if feedback is not None:
            damping[name] = mode_damping(designs.model, feedback, frequency_hz=0.34)
    refused = {} if designs.pid_refused is None else {"MIMO PID": designs.pid_refused}
    return MimoComparison(tuple(rows), gamma, seeds, ts, duration, margins, damping, refused)


def table_controllers_mimo(comparison: MimoComparison) -> ComparisonTable:
    """The comparison as a table: one row per controller, scenario and world, the design-model margins and pitch-mode
    damping in each controller's first row.

    Examples
    --------
    >>> case = MimoCase("MIMO LQG", "pitch step", "linear model", 4.1, 9.7, 0, 2, 0.3, 0.0, 0.05)
    >>> t = table_controllers_mimo(MimoComparison((case,), 1.2, (0,), 0.1, 80.0))
    >>> t.rows[0][:5], t.rows[0][-3:]
    (['MIMO LQG', 'pitch step', 'linear model', 4.1, 9.7], [0.05, '-', '-'])
    """
    table = ComparisonTable(
        f"Ch. 8 future work: MIMO LQG, PID, MPC and H-infinity on the 2-DOF rig (Ts = {comparison.sample_time:g} s)",
        [
            "controller",
            "scenario",
            "world",
            "overshoot (%)",
            "settling, noise band (s)",
            "steps unsettled, noise band",
            "settling, 5 % (s)",
            "RMS control (V)",
            "time saturated (%)",
            "untracked axis' peak (rad)",
            "disk margin u1; u2 (dB, deg)",
            "pitch mode's closed-loop damping",
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

    first = next(iter(SCENARIOS))
    for c in comparison.cases:
        design_row = c.world == "linear model" and c.scenario == first
        d = comparison.damping.get(c.controller)
        table.rows.append(
            [
                c.controller,
                c.scenario,
                c.world,
                finite_or(c.overshoot, "not flown"),
                finite_or(c.settling, "none settled" if c.steps else "not flown"),  # no step flown: none to settle
                f"{c.unsettled}/{c.steps}" if c.status == "flown" else f"{c.unsettled}/{c.steps} ({c.status})",
                finite_or(c.settling_wide, "none settled") if c.steps else "-",
                finite_or(c.rms_control, "not flown"),
                finite_or(100.0 * c.saturated, "not flown"),
                finite_or(c.cross, "not flown"),
                margin_cell(c.controller) if design_row else "-",
                (f"{d.closed.damping:.3g} ({d.closed.frequency_hz:.3g} Hz)" if d is not None else "-")
                if design_row
                else "-",
            ]
        )
    sizes = ", ".join(f"{s} {a:g} rad" for s, (_, a) in SCENARIOS.items())
    table.notes += [
        f"Each scenario a step ({sizes}) held for {comparison.duration / 2:g} s and back to hover, the other axis held "
        f"at 0; seeds {', '.join(map(str, comparison.seeds))}, the same for every controller; means over the steps "
        "and seeds, settling the median of the settled steps, in the noise band (max(2 % of the step, 3 standard "
        "deviations of the loop's angle at rest at the target)) and in 5 %.",
        "Designs on the 2-DOF design model: the chapter 8 MIMO LQG (per-channel weights); two PIDs (u1 -> pitch with "
        f"its measurement filter and the pitch mode damped to {MIN_DAMPING:g}, u2 -> yaw) tuned on their own "
        f"channels; MPC {MPC_OPTIONS} with +-10 V and both end stops; H-infinity mixed sensitivity with diagonal "
        f"weights {list(HINF_WEIGHTS)} and Wd = {DISTURBANCE_WEIGHT:g} I (gamma = {comparison.gamma:.3g}). Every "
        "controller follows the reference through the CSAS prefilter and flies the twin behind the thrust-curve "
        "inversion of both rotors.",
        "Disk margins at each plant input with the other loop closed, on the design model (MPC: its law while no "
        "constraint acts); 'closed loop unstable': the nominal MIMO loop itself is.",
    ]
    table.notes += [f"{name} is not offered as a baseline: {why}." for name, why in comparison.refused.items()]
    yaw = [c for c in comparison.cases if c.scenario == "pitch step" and np.isfinite(c.cross)]
    if yaw:
        worst = max(yaw, key=lambda c: c.cross)
        table.notes.append(
            f"The yaw's largest excursion under a pitch step: {worst.cross:.3g} rad ({worst.controller}, "
            f"{worst.world}), against the yaw stops at +-{END_STOPS['yaw']:g} rad"
            + (": every controller kept the yaw off them." if worst.cross < END_STOPS["yaw"] else ".")
        )
    return table
