"""Targets that pull against each other on this rig's physics, measured in the run.

Two pairs of the thesis's figures cannot both be met by the twin's structure, and the
calibration report says so with numbers computed here rather than with prose:

* **Phase against the step figures.** Eq. (3.11) lags -475 deg at 1 Hz, yet its step leaves
  5 % of its final value after 0.63 s: its non-minimum-phase zeros add lag that a step does
  not show as delay. A pendulum driven through a motor lag and a transport delay gets its
  phase lag only from the lag and the delay, both of which delay the step.
  :func:`phase_step_tradeoff` scans the motor lag and the delay on the linearised 1-DOF twin
  (exact, transport delay included) and reports, among the settings whose phase stays within
  the tolerance of (3.11)'s, the smallest step delay and the largest time constant.
* **u1 -> pitch at 0.1 Hz against u2 -> pitch's low coherence.** At a flat hover the main
  rotor's angular momentum is parallel to the yaw axis, so yaw rate couples into pitch only
  through the rotor's lean. u2 excites the 0.1 Hz yaw mode as u1 does, so the coupling that
  shows 0.1 Hz in u1 -> pitch also carries u2 into pitch.
  :func:`coupling_tradeoff` runs the thesis's 2-DOF protocol, at every verification seed, at
  the strongest coupling the parameter bounds allow and reports both figures beside the
  shipped model's.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco

from ..parameters import PARAMETERS, with_parameters
from ..twin import Twin
from .protocol import VERIFY_SEEDS, step_figures
from .targets import ModelTarget, Targets
from .verify import phase_difference_deg, verify

__all__ = ["PhaseStepTradeoff", "phase_step_tradeoff", "coupling_tradeoff", "STRONGEST_COUPLING"]


@dataclass(frozen=True)
class PhaseStepTradeoff:
    """The scan of :func:`phase_step_tradeoff`.

    Attributes
    ----------
    rows : list of dict
        ``motor_lag`` (s), ``input_delay`` (s), ``phase_deg`` (largest difference from the target
        model over its band), ``step_delay`` and ``time_constant`` (s).
    phase_tolerance_deg : float
    best_step_delay : float
        Smallest step delay among the rows within the phase tolerance (NaN if none is).
    best_time_constant : float
        Largest time constant among those rows.
    """

    rows: list[dict]
    phase_tolerance_deg: float
    best_step_delay: float
    best_time_constant: float

    def to_dict(self) -> dict:
        """JSON-serialisable form."""
        return {
            "rows": self.rows,
            "phase_tolerance_deg": self.phase_tolerance_deg,
            "best_step_delay_s": self.best_step_delay,
            "best_time_constant_s": self.best_time_constant,
        }


def phase_step_tradeoff(
    spec: mujoco.MjSpec,
    model: ModelTarget | None = None,
    lags: Sequence[float] = (0.4, 0.6, 0.8, 1.0, 1.2, 1.5),
    delays: Sequence[float] = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6),
) -> PhaseStepTradeoff:
    """Scan motor lag and transport delay on the linearised 1-DOF twin (see the module docstring).

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> s = phase_step_tradeoff(load_spec(), lags=(1.0,), delays=(0.4,))
    >>> len(s.rows)
    1
    """
    model = model or Targets.thesis().model
    assert model is not None
    dt = float(model.system.dt)
    rows = []
    for lag in lags:
        for delay in delays:
            lin = Twin(
                "1dof", 0.1, spec=with_parameters(spec, {"main_motor_lag": lag, "input_delay": delay})
            ).linearise()
            sys_d = lin.discretise(dt)
            d, tc = step_figures(sys_d)
            phase = phase_difference_deg(sys_d, model.system, model.phase_band_hz)
            rows.append(
                {
                    "motor_lag": float(lag),
                    "input_delay": float(delay),
                    "phase_deg": phase,
                    "step_delay": d,
                    "time_constant": tc,
                }
            )
    ok = [r for r in rows if r["phase_deg"] <= model.phase_tolerance_deg]
    return PhaseStepTradeoff(
        rows,
        model.phase_tolerance_deg,
        min((r["step_delay"] for r in ok), default=float("nan")),
        max((r["time_constant"] for r in ok), default=float("nan")),
    )


#: The strongest yaw-rate-to-pitch coupling the parameter bounds allow, with no tail reaction on pitch.
STRONGEST_COUPLING = {
    "main_rotor_tilt": PARAMETERS["main_rotor_tilt"].bounds[1],
    "main_rotor_inertia_radius": PARAMETERS["main_rotor_inertia_radius"].bounds[1],
    "tail_reaction": 0.0,
}


def coupling_tradeoff(spec: mujoco.MjSpec, seeds: Sequence[int] = VERIFY_SEEDS) -> dict:
    """The 2-DOF pitch figures of the shipped coupling and of :data:`STRONGEST_COUPLING` (module docstring).

    Returns
    -------
    dict
        ``{"shipped": {...}, "strongest": {...}}``, each with, per seed, the u1 -> pitch peak nearest
        0.1 Hz among the main peaks (Hz), whether it meets its target, and the u2 -> pitch median coherence.
    """
    targets = Targets.thesis()
    targets.model, targets.rest = None, None
    targets.peaks = [p for p in targets.peaks if p.config == "2dof" and p.channel == "u1->pitch"]
    targets.coherences = [c for c in targets.coherences if c.channel == "u2->pitch"]
    targets.ratios = []
    out = {}
    for label, values in (("shipped", {}), ("strongest", STRONGEST_COUPLING)):
        v = verify(with_parameters(spec, values) if values else spec, targets, seeds=seeds)
        rows: dict[str, dict[str, float | bool]] = {}
        for c in v.checks:
            row = rows.setdefault(str(c.seed), {})
            if "PSD peak" in c.name and c.target < 0.2:
                row["u1->pitch peak near 0.1 Hz"], row["0.1 Hz met"] = c.achieved, c.met
            elif "coherence" in c.name:
                row["u2->pitch coherence"], row["coherence met"] = c.achieved, c.met
        out[label] = {"parameters": values, "by_seed": rows}
    return out
