"""Robustness of the closed loops to the twin's physical parameters: a seeded Monte Carlo batch.

Each sample draws :data:`SPREAD_PARAMETERS` independently and uniformly within +-:data:`SPREAD` of
their shipped values (one ``numpy`` generator seeded once: same seed, same batch) and builds the
twin from them (:func:`trms.twin.parameters.with_parameters`). Two loops run on every sample, with
the controllers designed once on the nominal models, as a rig's would be:

* 1-DOF CSAS, R = 125 with the 0.2 Hz low-pass prefilter (the thesis's best rig case), designed on
  eq. (3.11), square wave +-0.2 rad;
* the 2-DOF LQG autopilot of ch. 8 (pitch square wave, yaw held), designed on the nominal twin.

A sample succeeds when the run neither diverges nor reaches the stops and its last step settles
within the 5 % band. The nominal linear model's value of each measure stands beside the batch's
success rate and spread (median and range over the successful samples).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from ..errors import check_in_range
from ..plant import Plant
from .lqg_cases import WIDE_BAND, judge, run_case
from .mimo_lqg_ch8 import SCENARIOS, controllers, scenario_reference
from .plants import design_model, make_plant
from .section import finite_or
from .tables import ComparisonTable, side_by_side

__all__ = ["SPREAD", "SPREAD_PARAMETERS", "Sample", "draw_parameters", "monte_carlo", "table"]

#: Relative half-width of the uniform spread.
SPREAD = 0.2
#: Parameters spread (mass, stiffness, motor lags).
SPREAD_PARAMETERS = ("counterweight_mass", "beam_stiffness", "cable_stiffness", "main_motor_lag", "tail_motor_lag")
#: The 1-DOF loop of the batch: (R, case).
CASE_1DOF = (125.0, "CSAS LPF 0.2 Hz")


@dataclass
class Sample:
    """One loop on one parameter sample: success, and its overshoot (%) and 5 % settling time (s)."""

    parameters: dict[str, float]
    status: str
    overshoot: float
    settling: float

    @property
    def success(self) -> bool:
        """True when the run settled (see the module docstring)."""
        return self.status == "settled"


def draw_parameters(n: int, seed: int = 0, spread: float = SPREAD) -> list[dict[str, float]]:
    """``n`` parameter sets, each parameter uniform in ``[1 - spread, 1 + spread]`` times its shipped value."""
    from ..twin import load_spec
    from ..twin.parameters import read_parameters

    check_in_range("spread", spread, 0.0, 0.9)
    nominal = read_parameters(load_spec(), SPREAD_PARAMETERS)
    rng = np.random.default_rng(seed)
    factors = rng.uniform(1.0 - spread, 1.0 + spread, size=(int(n), len(SPREAD_PARAMETERS)))
    return [{k: float(nominal[k] * f) for k, f in zip(SPREAD_PARAMETERS, row)} for row in factors]


def _one_dof(plant: Plant, seed: int) -> tuple[str, float, float]:
    from ..errors import DivergenceError
    from ..control.metrics import square_wave_metrics

    r, case = CASE_1DOF
    try:
        record, steps = run_case(plant, r, case, seed=seed, model=design_model("1dof"))
    except DivergenceError:
        return "diverged", float("nan"), float("nan")
    wide = square_wave_metrics(record, band=WIDE_BAND)
    return judge(record, wide), max(m.overshoot for m in steps), max(m.settling_time for m in wide)


def _two_dof(plant: Plant, seed: int) -> tuple[str, float, float]:
    from ..control.loop import closed_loop, deviation_limits
    from ..control.metrics import square_wave_metrics
    from ..errors import DivergenceError

    scen = "pitch square wave"
    ctrl = controllers(design_model("2dof"), limits=deviation_limits(plant))["MIMO LQG"]
    try:
        record = closed_loop(plant, ctrl, scenario_reference(scen, plant.sample_time), seed=seed)
    except DivergenceError:
        return "diverged", float("nan"), float("nan")
    tracked = SCENARIOS[scen][0]
    wide = square_wave_metrics(record, output=tracked, band=WIDE_BAND)
    steps = square_wave_metrics(record, output=tracked)
    return judge(record, wide), max(m.overshoot for m in steps), max(m.settling_time for m in wide)


LOOPS: dict[str, tuple[str, Callable[[Plant, int], tuple[str, float, float]]]] = {
    "1-DOF CSAS R = 125, LPF 0.2 Hz": ("1dof", _one_dof),
    "2-DOF LQG autopilot, pitch square wave": ("2dof", _two_dof),
}


def monte_carlo(n: int, seed: int = 0, progress: Callable[[str], None] | None = None) -> dict[str, list[Sample]]:
    """Run every loop of :data:`LOOPS` on ``n`` seeded parameter samples of the twin (with gusts).

    Parameters
    ----------
    n : int
        Samples.
    seed : int
        Seed of the parameter draw (and of each twin's noise and gusts: ``seed + i``).
    progress : callable, optional
        Called with a short message after each sample.
    """
    out: dict[str, list[Sample]] = {name: [] for name in LOOPS}
    for i, params in enumerate(draw_parameters(n, seed)):
        for name, (config, loop) in LOOPS.items():
            plant = make_plant("twin", config, gusts=True, parameters=params, seed=seed + i)
            status, os_, ts = loop(plant, seed + i)
            out[name].append(Sample(params, status, float(os_), float(ts)))
        if progress:
            progress(f"robustness sample {i + 1}/{n}")
    return out


def nominal(world: str = "linear", seed: int = 0) -> dict[str, tuple[str, float, float]]:
    """Every loop of :data:`LOOPS` on the nominal plant of ``world`` (no spread)."""
    return {name: loop(make_plant(world, config), seed) for name, (config, loop) in LOOPS.items()}


def _spread(values: list[float]) -> str:
    v = np.asarray([x for x in values if np.isfinite(x)])
    if v.size == 0:
        return "none settled"
    return f"{np.median(v):.3g} [{v.min():.3g}, {v.max():.3g}]"


def table(batch: Mapping[str, list[Sample]], linear: Mapping[str, tuple[str, float, float]], seed: int = 0) -> ComparisonTable:
    """The batch beside the nominal linear model: success rate, overshoot and settling spreads."""
    n = len(next(iter(batch.values()))) if batch else 0
    t = side_by_side(f"Robustness: twin parameters spread +-{SPREAD:.0%} (uniform, seed {seed}), {n} samples",
                     ["loop", "measure"])
    for name, samples in batch.items():
        ok = [s for s in samples if s.success]
        status, os_, ts = linear[name]
        t.rows.append([name, "success rate", "-", f"nominal: {status}",
                       f"{len(ok)}/{len(samples)}", "settled within 5 %, no stops, no divergence"])
        t.rows.append([name, "overshoot (%): median [min, max]", "-", finite_or(os_),
                       _spread([s.overshoot for s in ok]), "over the successful samples"])
        t.rows.append([name, "settling time, 5 % (s): median [min, max]", "-", finite_or(ts),
                       _spread([s.settling for s in ok]), "over the successful samples"])
    t.notes = [f"Spread parameters: {', '.join(SPREAD_PARAMETERS)}; controllers designed once on the nominal models "
               "(eq. 3.11 for 1-DOF, the nominal twin's reduced linearisation for 2-DOF); each twin runs with gusts "
               "and measurement noise."]
    return t
