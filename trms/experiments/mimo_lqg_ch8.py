"""Chapter 8's future work on a plant: a 2-DOF LQG autopilot for pitch and yaw against two SISO loops.

Design model: the twin's linearisation at hover reduced to its rigid-body and motor states (six:
pitch, yaw, their rates and the two rotor activations; the beam's bending states residualised,
which keeps the DC gain), discretised at 0.1 s (:func:`trms.experiments.plants.design_model`).

* MIMO LQG: integral LQG on both outputs, one current estimator on both measurements: u2 is free to
  cancel what u1 does to the yaw (the "decoupling objective" of ch. 8). Weights (this project's
  choice, in the spirit of the thesis's eq. 6.36, ``q_i = 1 / z_max^2``): :data:`STATE_WEIGHTS` on
  the pitch and yaw angles and integrators (pitch held ten times tighter, since it is the axis
  near its stops), 1 on the rates and rotor states, ``R = r I``. With ``Q = I`` the optimum moves
  the pitch by most of a radian to help the yaw with u1's reaction torque.
* Two SISO loops: the same design on the ``u1 -> pitch`` and the ``u2 -> yaw`` columns of the model
  alone (:class:`trms.control.loop.DiagonalController`), the way a per-channel design ignores the
  coupling.

Scenarios (references in deviation rad, 80 s at 0.1 s): a pitch square wave of +-0.2 rad with the
yaw held at 0, and a yaw square wave of +-0.3 rad with the pitch held at 0 (one period of 80 s, so
one step up at 0 s and one down at 40 s). Measures: the tracked channel's rise and settling times
(2 % band) and overshoot, the other channel's largest excursion (cross-coupling), and the control
effort (RMS and total variation of both commanded inputs).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import control
import numpy as np

from ..control.loop import Controller, DiagonalController, closed_loop, deviation_limits
from ..control.lqg import LQGController, design_lqg
from ..control.metrics import square_wave_metrics, total_variation
from ..errors import DivergenceError
from ..identification.signals import square_wave
from ..plant import Plant, Record
from ..reference import VOLTAGE_LIMIT
from .figures import plot_series, save_figure
from .lqg_cases import full_swing, worst
from .section import FigureRef, Section, finite_or
from .tables import side_by_side

__all__ = [
    "R_WEIGHT",
    "STATE_WEIGHTS",
    "INTEGRATOR_WEIGHTS",
    "weights",
    "SCENARIOS",
    "CONTROLLERS",
    "AutopilotRun",
    "controllers",
    "scenario_reference",
    "autopilot_runs",
    "section",
]

#: Control weight ``R = r I`` of both designs (``Q = I``): this project's choice, which keeps both
#: inputs well inside +-10 V on these steps.
R_WEIGHT = 10.0
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
    model: control.StateSpace, r_weight: float = R_WEIGHT, limits: tuple[np.ndarray, np.ndarray] | None = None
) -> dict[str, Controller]:
    """The MIMO LQG and the two SISO loops designed on the 2-DOF model (inputs u1, u2; outputs pitch, yaw),
    both with the weights of :func:`weights`.

    Parameters
    ----------
    model : control.StateSpace
        Discrete, ``D = 0``.
    r_weight : float
        ``R = r_weight I``.
    limits : tuple of numpy.ndarray, optional
        Deviation limits (V) of both inputs.
    """
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


def _measures(record: Record, tracked: int) -> dict[str, float]:
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
    plant: Plant, model: control.StateSpace, seed: int = 0, r_weight: float = R_WEIGHT
) -> dict[tuple[str, str], AutopilotRun]:
    """Both controllers in both scenarios on a 2-DOF plant.

    Parameters
    ----------
    plant : Plant
        The linear model or the twin (2-DOF, 0.1 s).
    model : control.StateSpace
        Design model (:func:`trms.experiments.plants.design_model` ``("2dof")``).
    seed : int
        Plant seed.
    r_weight : float
        ``R = r_weight I``.

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
            out[(name, scen)] = AutopilotRun("ran", _measures(rec, tracked), rec)
    return out


_LABELS = {
    "TR": "rise time (s)",
    "TS": "settling time, 2 % (s)",
    "overshoot": "overshoot (%)",
    "cross": "other axis' largest excursion (rad)",
    "rms u1": "RMS u1 (V)",
    "rms u2": "RMS u2 (V)",
    "TV": "total variation of u (V)",
}


def _table(res: Mapping[str, Mapping[tuple[str, str], AutopilotRun]]):
    table = side_by_side(
        f"Ch. 8 future work: 2-DOF LQG autopilot against two SISO loops (R = {R_WEIGHT:g} I)",
        ["scenario", "controller", "measure"],
    )
    for scen in SCENARIOS:
        for name in CONTROLLERS:
            a, b = res["linear"][(name, scen)], res["twin"][(name, scen)]
            for key, label in _LABELS.items():
                cells = [finite_or(r.measures[key], "not settled") if r.measures else r.status for r in (a, b)]
                note = ""
                if key == "cross":
                    note = (
                        "yaw moved by the pitch command: the u1 -> yaw coupling"
                        if scen.startswith("pitch")
                        else "pitch moved by the yaw command"
                    )
                table.rows.append([scen, name, label, "-", *cells, note])
    notes = []
    for w in ("linear", "twin"):
        for scen in SCENARIOS:
            m, s = res[w][("MIMO LQG", scen)], res[w][("two SISO loops", scen)]
            moved = "yaw" if scen.startswith("pitch") else "pitch"
            if m.measures and s.measures and s.measures["cross"] > 0:
                notes.append(
                    f"{w}, {scen}: the {moved} moves {m.measures['cross']:.3g} rad under the MIMO LQG against "
                    f"{s.measures['cross']:.3g} rad under the two SISO loops "
                    f"({m.measures['cross'] / s.measures['cross']:.0%})."
                )
    table.notes = notes + [
        "Design model: the twin's linearisation reduced to rigid-body and motor states (bending "
        "states residualised). The linear model column runs it on the full linearisation (18 states) "
        "with measurement noise; the twin adds quantisation, gusts and its nonlinear dynamics."
    ]
    return table


def section(
    res: Mapping[str, Mapping[tuple[str, str], AutopilotRun]], folder: str | os.PathLike[str], extra: list | None = None
) -> Section:
    """The chapter 8 section (the autopilot; ``extra`` tables such as the robustness batch are appended)."""
    folder = Path(folder)
    figs = []
    for scen, (tracked, _) in SCENARIOS.items():
        recorded = {name: res["twin"][(name, scen)].record for name in CONTROLLERS}
        runs = {name: rec for name, rec in recorded.items() if rec is not None}
        if len(runs) < len(recorded):
            continue
        first = next(iter(runs.values()))
        series = {"command": first.extras["reference"][:, tracked]}
        for name, rec in runs.items():
            dy = rec.deviations()[1]
            series[f"{name}: {rec.output_names[tracked]}"] = dy[:, tracked]
            series[f"{name}: {rec.output_names[1 - tracked]}"] = dy[:, 1 - tracked]
        inputs = {
            f"{name}: {rec.input_names[j]}": rec.extras["control"][:, j] for name, rec in runs.items() for j in (0, 1)
        }
        trim = first.operating_point.inputs
        limits = (
            float(np.max(-VOLTAGE_LIMIT - trim)),
            float(np.min(VOLTAGE_LIMIT - trim)),
        )  # the tighter of the two inputs
        figs.append(
            FigureRef(
                save_figure(
                    plot_series(
                        first.time,
                        series,
                        f"Twin 2-DOF, {scen}: MIMO LQG against two SISO loops",
                        "angle (rad, deviation)",
                        inputs,
                        limits=limits,
                    ),
                    folder / f"ch8_{scen.split()[0]}_twin.png",
                ),
                f"Twin under the {scen}: tracked and cross-coupled angles and both inputs, per controller.",
            )
        )
    paragraphs = [
        "A 2-DOF LQG autopilot for pitch and yaw together (the thesis's first suggestion for future work), designed on "
        "the twin's linearisation reduced to its rigid-body and motor states, against two SISO LQG loops designed on "
        "the u1 -> pitch and u2 -> yaw columns of the same model.",
    ]
    return Section(
        "Chapter 8 (future work): 2-DOF LQG autopilot and robustness", paragraphs, [_table(res), *(extra or [])], figs
    )
