"""The twin's experiments at the run's other seeds: each a job of its own in the report's worker pool.

Every twin cell that carries a verdict is judged over :attr:`~trms.report.results.Settings.seeds`. The run's own
seed is measured by the twin's full jobs (:func:`trms.report.jobs.run_identification`,
:func:`~trms.report.jobs.run_control`); each other seed by :func:`run_seed_identification` and
:func:`run_seed_control`, which run the same experiment functions without what only the figures and the unjudged
rows read, and hand back records without their runs' time histories (small to send back).
"""

from __future__ import annotations

import time

from trms.errors import InputError
from trms.experiments import ch3_identification as ch3
from trms.experiments import ch4_shaping as ch4
from trms.experiments import ch5_narx as ch5
from trms.experiments import ch67_lqg as runs67
from trms.experiments.ch67_amplitudes import amplitude_runs
from trms.reference import PUSH_WEIGHTS_R, TABLE_6_1
from trms.report.results import NARX_STRIDE, SeedControl, SeedIdentification, Settings
from trms.worlds import design_model, make_plant

__all__ = ["seed_cases", "run_seed_identification", "run_seed_control"]


def seed_cases(weights: tuple[float, ...]) -> dict[float, tuple[str, ...]]:
    """The LQG cases a seed's cells read, by R: Table 6.1's (R = 75 and 1) and those the ch. 7 findings compare at
    the rig's weights (SAS, the low-pass prefilters, the 0.34 Hz band-stop).

    Examples
    --------
    >>> {r: len(c) for r, c in seed_cases((75.0, 1.0, 125.0)).items()}
    {75.0: 6, 1.0: 4, 125.0: 5}
    """
    table = {r: {c for rr, c in TABLE_6_1 if rr == r} for r, _ in TABLE_6_1}
    rig = ("SAS", "CSAS LPF 0.1 Hz", "CSAS LPF 0.2 Hz", "CSAS LPF 0.3 Hz", "CSAS BSF 0.34 Hz")
    out = {}
    for r in weights:
        wanted = table.get(r, set()) | (set(rig) if r in PUSH_WEIGHTS_R else set())
        out[r] = tuple(c for c in runs67.ALL_CASES if c in wanted)
    return out


def run_seed_identification(settings: Settings, seed: int) -> SeedIdentification:
    """The twin's chapters 3-5 at ``seed``: the runs whose cells carry a verdict (one job).

    Examples
    --------
    >>> run_seed_identification(Settings(quick=True), 5)
    Traceback (most recent call last):
    trms.errors.InputError: seed = 5 is not one of the run's other seeds (1000,)
    """
    _check(settings, seed)
    started = time.perf_counter()
    one, two = make_plant("twin", "1dof", seed=seed), make_plant("twin", "2dof", seed=seed)
    ch3_1dof = ch3.identify_1dof(one, None, seed, validate=False)
    return SeedIdentification(
        seed,
        ch3_1dof,
        ch3.identify_2dof(two, seed, validate=False),
        ch4.shaping_1dof(one, ch3_1dof.model.to_tf(), seed, shapers=False),
        ch4.shaping_2dof(two, seed),
        tuple(ch5.narx_1dof(one, seed + NARX_STRIDE * j, full=False) for j in range(settings.narx_per_job)),
        time.perf_counter() - started,
    )


def run_seed_control(settings: Settings, seed: int) -> SeedControl:
    """The twin's chapters 6/7 at ``seed``: the LQG cases of :func:`seed_cases`, the push and R = 1 at the note's
    amplitudes, records dropped (one job).

    Examples
    --------
    >>> run_seed_control(Settings(), 0)
    Traceback (most recent call last):
    trms.errors.InputError: seed = 0 is not one of the run's other seeds (1000, 2000, 3000, 4000)
    """
    _check(settings, seed)
    started = time.perf_counter()
    model = design_model("1dof")
    plant = make_plant("twin", "1dof", seed=seed)
    lqg = {}
    for r, cases in seed_cases(settings.weights).items():
        lqg.update(runs67.without_records(runs67.lqg_cases(plant, model, [r], cases, seed=seed)))
    push = runs67.push_rejection(
        lambda p: make_plant("twin", "1dof", pushes=p, seed=seed), model, PUSH_WEIGHTS_R, seed=seed
    )
    push = {r: runs67.PushResult(p.status, p.peak, p.recovery, None) for r, p in push.items()}
    return SeedControl(seed, lqg, push, amplitude_runs(plant, model, seed), time.perf_counter() - started)


def _check(settings: Settings, seed: int) -> None:
    others = tuple(settings.seeds[1:])
    if seed not in others:
        raise InputError(f"seed = {seed!r} is not one of the run's other seeds {others}")
