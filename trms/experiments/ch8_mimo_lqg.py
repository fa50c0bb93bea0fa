"""Chapter 8's future work on a plant: a 2-DOF LQG autopilot for pitch and yaw against two SISO loops.

Design model: the twin's linearisation at hover reduced to its rigid-body and motor states (six:
pitch, yaw, their rates and the two rotor activations; the beam's bending states residualised,
which keeps the DC gain), discretised at 0.1 s with the rotors' transport delay
(:func:`trms.worlds.design_model`).

* MIMO LQG: integral LQG on both outputs, one current estimator on both measurements: u2 is free to
  cancel what u1 does to the yaw (the "decoupling objective" of ch. 8). Weights per channel
  (:data:`STATE_WEIGHTS` on the pitch and yaw angles, :data:`INTEGRATOR_WEIGHTS` on their integrators, 1 on the
  rates and rotor states, 0 on the delay line's past inputs, :data:`CONTROL_WEIGHTS` on u1 and u2): tuned by
  :func:`trms.experiments.ch8_autopilot_tuning.tune_autopilot` against :data:`TARGETS` on the twin in moving air,
  with classical margins at each plant input (:mod:`trms.experiments.ch8_autopilot_margins`) and the pitch mode
  damped, and verified on the twin at seeds the tuning never saw.
* Two SISO loops: the same weights on the ``u1 -> pitch`` and the ``u2 -> yaw`` columns of the model
  alone (:class:`trms.control.loop.DiagonalController`), the way a per-channel design ignores the coupling.

Both fly as chapter 8's controllers do (:mod:`trms.experiments.ch8_designs`): through the reference prefilter and,
on the twin, behind the thrust-curve inversion. Margins: :mod:`trms.experiments.ch8_autopilot_margins`; the scan
(:func:`scan_runs`) flies the design beside loops with its control weights scaled by :data:`R_SCALES`.

Scenarios (references in deviation rad, 80 s at 0.1 s): a 0.2 rad pitch step with the yaw held at 0, and a 0.5 rad
yaw step with the pitch held at 0, each held for half the run and then back to hover (two steps of the same size).
Measures (:func:`measures`): the tracked channel's rise time and settling time, in the noise band
(:func:`~trms.control.metrics.noise_band`, the loop's wobble at rest at each target measured on a run holding it)
and in 5 %, and overshoot, the other channel's largest excursion (cross-coupling), and the control effort (RMS and
total variation of both commanded inputs). The section that shows them: :mod:`trms.experiments.ch8_mimo_section`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import control
import numpy as np

from trms.control.loop import Controller, DiagonalController, closed_loop
from trms.control.lqg import LQGController, design_lqg
from trms.control.metrics import WIDE_BAND, square_wave_metrics, total_variation
from trms.errors import DivergenceError, InputError
from trms.experiments.ch8_designs import INVERSION, reference_prefilter
from trms.experiments.ch67_lqg import worst
from trms.plant import Plant
from trms.record import Record
from trms.worlds import input_layer

__all__ = [
    "R_SCALES",
    "AutopilotWeights",
    "scan_runs",
    "STATE_WEIGHTS",
    "INTEGRATOR_WEIGHTS",
    "CONTROL_WEIGHTS",
    "TARGETS",
    "weights",
    "control_weights",
    "SCENARIOS",
    "CONTROLLERS",
    "AutopilotRun",
    "controllers",
    "autopilot_controllers",
    "scenario_reference",
    "autopilot_runs",
    "measures",
    "meets_targets",
    "rest_levels",
]

#: Scales of the control weights (``R = s diag(CONTROL_WEIGHTS)``) shown beside the design (``s = 1``).
R_SCALES = (0.3, 1.0, 3.0)
#: Diagonal state weights by state name (angles, rad^-2); the rates and rotor states get 1, the delay line's past
#: inputs 0 (:func:`weights`).
STATE_WEIGHTS = {"pitch": 2.497e5, "yaw": 7.200}
#: Integrator weights by tracked output.
INTEGRATOR_WEIGHTS = {"pitch": 478.6, "yaw": 3.706}
#: Control weights of u1 and u2 (V^-2).
CONTROL_WEIGHTS = (3.927e4, 2317.0)
#: Scenario name -> (tracked output index, step size rad).
SCENARIOS = {"pitch step": (0, 0.2), "yaw step": (1, 0.5)}
#: What the autopilot must do on the twin in moving air, per scenario: rise time and settling time of the tracked
#: axis (s, worst step; settling in the noise band) and the other axis' largest excursion (rad).
TARGETS: dict[str, dict[str, float]] = {
    "pitch step": {"TR": 6.0, "TS": 20.0, "cross": 0.25},
    "yaw step": {"TS": 30.0, "cross": 0.05},
}
#: Controller names, in the report's order.
CONTROLLERS = ("MIMO LQG", "two SISO loops")
#: Scenario length (s): the step is held for half of it.
DURATION = 80.0
#: The run at rest that measures the loop's wobble at a target (:func:`rest_levels`): its length and the start left
#: out, the way there (s).
REST_HOLD = (80.0, 20.0)


def weights(
    model: control.StateSpace,
    state: Mapping[str, float] = STATE_WEIGHTS,
    integrator: Mapping[str, float] = INTEGRATOR_WEIGHTS,
) -> np.ndarray:
    """Diagonal ``Q`` on ``[x; xi]`` of an integral LQG on ``model`` (all outputs tracked), by state and output name
    (module docstring): ``state`` weights by state name, 0 on the delay line's past inputs, 1 elsewhere;
    ``integrator`` weights by tracked output.

    Examples
    --------
    >>> from trms.worlds import design_model
    >>> q = np.diag(weights(design_model("2dof")))
    >>> q[:6].tolist(), q[-2:].tolist()
    ([7.2, 249700.0, 1.0, 1.0, 1.0, 1.0], [478.6, 3.706])
    """
    q = [state.get(n, 0.0 if "[k-" in n else 1.0) for n in model.state_labels]
    q += [integrator.get(n, 1.0) for n in model.output_labels]
    return np.diag(q)


def control_weights(scale: float = 1.0, control: Sequence[float] = CONTROL_WEIGHTS) -> np.ndarray:
    """``R = scale diag(control)`` (V^-2).

    Examples
    --------
    >>> control_weights(2.0).tolist()
    [[78540.0, 0.0], [0.0, 4634.0]]
    """
    return float(scale) * np.diag(np.asarray(control, float))


@dataclass(frozen=True)
class AutopilotWeights:
    """The autopilot's weights (module docstring): by state name, by tracked output, per input.

    Examples
    --------
    >>> AutopilotWeights().control == CONTROL_WEIGHTS
    True
    """

    state: Mapping[str, float] = field(default_factory=lambda: dict(STATE_WEIGHTS))
    integrator: Mapping[str, float] = field(default_factory=lambda: dict(INTEGRATOR_WEIGHTS))
    control: tuple[float, float] = CONTROL_WEIGHTS


def controllers(
    model: control.StateSpace,
    scale: float = 1.0,
    limits: tuple[np.ndarray, np.ndarray] | None = None,
    gains: AutopilotWeights | None = None,
) -> dict[str, Controller]:
    """The MIMO LQG and the two SISO loops designed on the 2-DOF model (inputs u1, u2; outputs pitch, yaw),
    both with the weights of :func:`weights` and :func:`control_weights` ``(scale)``.

    Parameters
    ----------
    model : control.StateSpace
        Discrete, ``D = 0``.
    scale : float
        Scale of the control weights (1: the design).
    limits : tuple of numpy.ndarray, optional
        Deviation limits (V) of both inputs.
    gains : AutopilotWeights, optional
        Other weights than the shipped ones (their tuning, :mod:`trms.experiments.ch8_autopilot_tuning`).

    Examples
    --------
    >>> from trms.worlds import design_model
    >>> sorted(controllers(design_model("2dof")))
    ['MIMO LQG', 'two SISO loops']
    """
    g = AutopilotWeights() if gains is None else gains
    R = control_weights(scale, g.control)
    mimo = LQGController(design_lqg(model, Q=weights(model, g.state, g.integrator), R=R), limits)
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
        loops.append(LQGController(design_lqg(sub, Q=weights(sub, g.state, g.integrator), R=R[i, i]), lim))
    return {"MIMO LQG": mimo, "two SISO loops": DiagonalController(loops, (0, 1), (0, 1), 2)}


def autopilot_controllers(
    model: control.StateSpace,
    plant: Plant,
    scale: float = 1.0,
    inversion: bool = INVERSION,
    gains: AutopilotWeights | None = None,
) -> dict[str, Controller]:
    """:func:`controllers` for ``plant`` as they fly it: its input limits, behind its thrust-curve inversion
    when ``inversion`` (:func:`~trms.worlds.input_layer`).

    Examples
    --------
    >>> from trms.worlds import design_model, make_plant
    >>> c = autopilot_controllers(design_model("2dof"), make_plant("twin", "2dof"))
    >>> type(c["MIMO LQG"]).__name__
    'InvertedInputs'
    """
    limits, wrap = input_layer(plant, inversion)
    return {name: wrap(c) for name, c in controllers(model, scale, limits, gains).items()}


def scenario_reference(name: str, sample_time: float, duration: float = DURATION) -> np.ndarray:
    """The ``(N, 2)`` reference (deviation rad) of a scenario: its step on the tracked axis for the first half of
    ``duration`` (s), then back to 0; the other axis at 0.

    Raises
    ------
    InputError
        An unknown scenario.

    Examples
    --------
    >>> r = scenario_reference("yaw step", 0.1)
    >>> r.shape, float(r[0, 1]), float(r[-1, 1]), float(np.abs(r[:, 0]).max())
    ((800, 2), 0.5, 0.0, 0.0)
    """
    if name not in SCENARIOS:
        raise InputError(f"unknown scenario {name!r}; allowed: {', '.join(repr(s) for s in SCENARIOS)}")
    tracked, size = SCENARIOS[name]
    n = int(round(duration / sample_time))
    ref = np.zeros((n, 2))
    ref[: n // 2, tracked] = size
    return ref


def rest_levels(plant: Plant, controller: Controller, scenario: str, seed: int) -> dict[float, float]:
    """The loop's wobble at rest at each target of a scenario: per target level (deviation rad) of the tracked axis,
    the standard deviation (rad) of its measured angle on a run holding it (:data:`REST_HOLD`: 60 s after the first
    20 s, long enough that the estimate is within about 10 % of the wobble), through
    the reference prefilter, at the plant's seed (the settling band of :func:`measures`).

    Examples
    --------
    >>> from trms.worlds import design_model, make_plant
    >>> plant = make_plant("twin", "2dof", still_air=True)
    >>> levels = rest_levels(plant, autopilot_controllers(design_model("2dof"), plant)["MIMO LQG"], "pitch step", 0)
    >>> {k: round(v, 4) for k, v in levels.items()}  # still air: an encoder count's limit cycle at 0.2 rad
    {0.0: 0.0, 0.2: 0.0007}
    """
    tracked, size = SCENARIOS[scenario]
    ts = plant.sample_time
    n, skip = int(round(REST_HOLD[0] / ts)), int(round(REST_HOLD[1] / ts))
    out = {}
    for level in (0.0, float(size)):
        ref = np.zeros((n, 2))
        ref[:, tracked] = level
        rec = closed_loop(plant, controller, ref, reference_prefilter(ts), seed=seed)
        out[level] = float(np.std(rec.deviations()[1][skip:, tracked]))
    return out


@dataclass
class AutopilotRun:
    """One controller in one scenario on one plant.

    Attributes
    ----------
    status : str
        ``"ran"`` or ``"diverged"``.
    measures : dict
        :func:`measures` of the run.
    record : Record or None
    """

    status: str
    measures: dict[str, float]
    record: Record | None


def measures(record: Record, tracked: int, rest: Mapping[float, float] | None = None) -> dict[str, float]:
    """The autopilot's measures of one closed-loop run (the columns of the chapter 8 tables).

    Parameters
    ----------
    record : Record
        A 2-DOF closed loop from :func:`trms.control.loop.closed_loop` (``reference`` and ``control`` extras).
    tracked : int
        The output that follows the step (0 pitch, 1 yaw); the other is the cross-coupled one.
    rest : mapping, optional
        :func:`rest_levels` of the loop: the settling band at each target is then the noise band; 2 % without.

    Returns
    -------
    dict
        ``TR``, ``TS`` (s, the worst step; nan when it never rose or settled), ``TS 1``, ``TS 2``, ... (s, each
        step's), ``TS 5 %`` (s), ``overshoot`` (%),
        ``cross`` (rad, largest excursion of the other output), ``rms u1``, ``rms u2`` (V), ``TV`` (V, total
        variation of both inputs).

    Examples
    --------
    >>> t = np.arange(200) * 0.1
    >>> ref = np.column_stack([np.where(t < 10, 0.2, 0.0), np.zeros(200)])
    >>> y = np.column_stack([ref[:, 0], np.full(200, 0.01)])
    >>> rec = Record(t, np.zeros((200, 2)), y, ("u1", "u2"), ("pitch", "yaw"), {"reference": ref,
    ...              "control": np.ones((200, 2))})
    >>> m = measures(rec, 0)
    >>> m["overshoot"], m["cross"], m["rms u1"]
    (0.0, 0.01, 1.0)
    """
    steps = square_wave_metrics(record, output=tracked, rest_std=dict(rest or {}))
    wide = square_wave_metrics(record, output=tracked, band=WIDE_BAND)
    other = 1 - tracked
    u = record.extras["control"]
    return {
        "TR": worst([m.rise_time for m in steps]),
        "TS": worst([m.settling_time for m in steps]),
        **{f"TS {k + 1}": float(m.settling_time) for k, m in enumerate(steps)},
        "TS 5 %": worst([m.settling_time for m in wide]),
        "overshoot": float(max(m.overshoot for m in steps)),
        "cross": float(np.max(np.abs(record.deviations()[1][:, other]))),
        "rms u1": float(np.sqrt(np.mean(u[:, 0] ** 2))),
        "rms u2": float(np.sqrt(np.mean(u[:, 1] ** 2))),
        "TV": total_variation(u),
    }


def meets_targets(scenario: str, m: Mapping[str, float]) -> list[str]:
    """What of :data:`TARGETS` a run's :func:`measures` miss (empty: every target met).

    Examples
    --------
    >>> meets_targets("yaw step", {"TS": 12.0, "cross": 0.08})
    ['cross 0.08 > 0.05']
    """
    missed = []
    for key, limit in TARGETS[scenario].items():
        value = m.get(key, float("nan"))
        if not value <= limit:
            missed.append(f"{key} {value:.3g} > {limit:g}")
    return missed


def _fly(
    plant: Plant, ctrl: Controller, scenario: str, seed: int, rest: Mapping[float, float], metadata: dict
) -> AutopilotRun:
    tracked = SCENARIOS[scenario][0]
    ref = scenario_reference(scenario, plant.sample_time)
    try:
        rec = closed_loop(plant, ctrl, ref, reference_prefilter(plant.sample_time), seed=seed, metadata=metadata)
    except DivergenceError:
        return AutopilotRun("diverged", {}, None)
    return AutopilotRun("ran", measures(rec, tracked, rest), rec)


def autopilot_runs(
    plant: Plant,
    model: control.StateSpace,
    seed: int = 0,
    scale: float = 1.0,
    inversion: bool = INVERSION,
    gains: AutopilotWeights | None = None,
    names: Sequence[str] = CONTROLLERS,
) -> dict[tuple[str, str], AutopilotRun]:
    """Both controllers in both scenarios on a 2-DOF plant, as they fly (:func:`autopilot_controllers`).

    Parameters
    ----------
    plant : Plant
        The linear model or the twin (2-DOF, 0.1 s).
    model : control.StateSpace
        Design model (:func:`trms.worlds.design_model` ``("2dof")``).
    seed : int
        Plant seed.
    scale : float
        Scale of the control weights (1: the design).
    inversion : bool
        Fly the twin behind its thrust-curve inversion.
    gains : AutopilotWeights, optional
        Other weights than the shipped ones.
    names : sequence of str
        The controllers flown (of :data:`CONTROLLERS`).

    Returns
    -------
    dict keyed ``(controller, scenario)``

    Examples
    --------
    >>> from trms.worlds import design_model, make_plant
    >>> runs = autopilot_runs(make_plant("linear", "2dof"), design_model("2dof"))
    >>> # without noise the settling band is 2 %: the pitch step's last percent creeps past the target (its 5 %
    >>> # settling time is 10.2 s); on the twin the band is the loop's own wobble at rest (:func:`rest_levels`)
    >>> [meets_targets(s, runs[("MIMO LQG", s)].measures) for s in SCENARIOS]
    [['TS 23.9 > 20'], []]
    >>> round(runs[("MIMO LQG", "pitch step")].measures["TS 5 %"], 1)
    10.2
    """
    out = {}
    built = autopilot_controllers(model, plant, scale, inversion, gains)  # each loop resets its controller
    for name in names:
        for scen in SCENARIOS:
            rest = rest_levels(plant, built[name], scen, seed)
            out[(name, scen)] = _fly(
                plant, built[name], scen, seed, rest, {"controller_design": name, "scenario": scen}
            )
    return out


def scan_runs(
    plant: Plant,
    model: control.StateSpace,
    scales: Sequence[float] = R_SCALES,
    seed: int = 0,
    flown: Mapping[float, Mapping[str, AutopilotRun]] | None = None,
    inversion: bool = INVERSION,
) -> dict[float, dict[str, AutopilotRun]]:
    """The MIMO LQG in both scenarios on ``plant`` for every scale of its control weights (the scan's runs).

    Parameters
    ----------
    plant : Plant
        The 2-DOF plant.
    model : control.StateSpace
        Design model (:func:`trms.worlds.design_model` ``("2dof")``).
    scales : sequence of float
        The scales of ``R = s diag(CONTROL_WEIGHTS)`` to fly.
    seed : int
        Plant seed.
    flown : mapping, optional
        Runs already flown on this plant at this seed, by scale then scenario (the MIMO LQG of
        :func:`autopilot_runs` at its weight): taken as they are, not flown again.
    inversion : bool
        Fly the twin behind its thrust-curve inversion.

    Returns
    -------
    dict
        ``{scale: {scenario: AutopilotRun}}``.

    Examples
    --------
    >>> from trms.worlds import design_model, make_plant
    >>> done = {1.0: {s: AutopilotRun("ran", {}, None) for s in SCENARIOS}}
    >>> scan_runs(make_plant("linear", "2dof"), design_model("2dof"), [1.0], flown=done) == done
    True
    """
    out: dict[float, dict[str, AutopilotRun]] = {}
    for s in scales:
        if flown is not None and float(s) in flown:
            out[float(s)] = dict(flown[float(s)])
            continue
        out[float(s)] = {}
        ctrl = autopilot_controllers(model, plant, s, inversion)["MIMO LQG"]  # each loop resets it
        for scen in SCENARIOS:
            rest = rest_levels(plant, ctrl, scen, seed)
            out[float(s)][scen] = _fly(plant, ctrl, scen, seed, rest, {"R scale": float(s), "scenario": scen})
    return out
