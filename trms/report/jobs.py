"""The report's jobs and the worker pool that runs them.

Each world's identification chapters (3-5), its control chapters (6-8), the twin's chapters at each other seed of the
run (:mod:`trms.report.seed_jobs`), each part of the robustness batch and the twin's render are independent jobs
(:func:`run_identification`, :func:`run_control`, :func:`run_robustness`, :func:`run_render`), each returning a typed
record of :mod:`trms.report.results`. :func:`run_jobs` runs them, longest first, in a pool of worker processes with one
BLAS thread each, and stops every worker when one job fails or the user interrupts.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

from threadpoolctl import threadpool_limits

from trms.errors import InputError, check_choice, check_in_range
from trms.experiments import ch3_identification as ch3
from trms.experiments import ch4_shaping as ch4
from trms.experiments import ch5_narx as ch5
from trms.experiments import ch7_findings as findings7
from trms.experiments import ch7_side_mode as side_mode
from trms.experiments import ch67_lqg as runs67
from trms.experiments.ch8 import autopilot as ch8
from trms.experiments.ch8 import robustness as robustness
from trms.experiments.ch8.autopilot_margins import shipped_margin_scan
from trms.experiments.ch8.comparison import ControllerStudy, controller_study
from trms.experiments.ch8.sweep import Sweep, amplitude_sweep
from trms.experiments.ch67_amplitudes import amplitude_runs, linearised_runs
from trms.plant import Plant
from trms.processes import interrupts_held
from trms.reference import PUSH_WEIGHTS_R, TABLE_6_1
from trms.report.results import (
    NARX_STRIDE,
    Control,
    Identification,
    Render,
    Results,
    RobustnessPart,
    SeedControl,
    SeedIdentification,
    Settings,
    WorldResults,
)
from trms.report.seed_jobs import run_seed_control, run_seed_identification
from trms.report.workers import ONE_THREAD, ReportPool, blas_threads, environment
from trms.twin import Twin
from trms.worlds import WORLDS, design_model, make_plant

__all__ = [
    "PARTS",
    "run_identification",
    "run_control",
    "world_results",
    "run_robustness",
    "run_controllers",
    "run_sweep",
    "run_render",
    "RENDERED",
    "run_jobs",
]

#: The two parts of a world's chain, each run as one job.
PARTS = ("identification", "control")

#: What a job hands back.
Outcome = (
    Identification | Control | SeedIdentification | SeedControl | RobustnessPart | ControllerStudy | Render | Sweep
)
T = TypeVar(
    "T", Identification, Control, SeedIdentification, SeedControl, RobustnessPart, ControllerStudy, Render, Sweep
)

#: The twin's LQG run that the report renders: ``(R, case)`` of :func:`trms.experiments.ch67_lqg.lqg_cases`.
RENDERED = (125.0, "CSAS LPF 0.2 Hz")


def run_identification(world: str, settings: Settings) -> Identification:
    """One world's chapters 3-5 (runs in a worker process).

    Parameters
    ----------
    world : {"linear", "twin"}
    settings : Settings

    Returns
    -------
    Identification

    Examples
    --------
    >>> run_identification("moon", Settings())
    Traceback (most recent call last):
    trms.errors.InputError: unknown world 'moon'; allowed: 'linear', 'twin'
    """
    check_choice("world", world, WORLDS, error=InputError)
    seed = settings.seed
    started = time.perf_counter()

    def plant(config: str) -> Plant:
        return make_plant(world, config, seed=seed)

    ch3_1dof = ch3.identify_1dof(plant("1dof"), make_plant(world, "1dof", 0.1, seed=seed), seed)
    ch3_2dof = ch3.identify_2dof(plant("2dof"), seed)
    design = ch3_1dof.model.to_tf()
    ch4_1dof, ch4_2dof = ch4.shaping_1dof(plant("1dof"), design, seed), ch4.shaping_2dof(plant("2dof"), seed)
    # the ambient floor the ch. 4 notes test: the twin under the most ambient excitation its calibration allows
    floor = ch4.ambient_floors(design, seed, two_dof=not settings.quick) if world == "twin" else None
    # Table 5.1's models at the job's other NARX seeds (cheap; its verdict needs many)
    more = tuple(
        ch5.narx_1dof(plant("1dof"), seed + NARX_STRIDE * j, full=False)
        for j in range(1, settings.narx_per_job if world == "twin" else 1)
    )
    return Identification(
        ch3_1dof=ch3_1dof,
        ch3_2dof=ch3_2dof,
        ch4_1dof=ch4_1dof,
        ch4_2dof=ch4_2dof,
        ch5=ch5.narx_1dof(plant("1dof"), seed),
        ch5_yaw=ch5.narx_yaw(plant("2dof"), seed),
        floor=floor,
        ch5_more=more,
        seconds=time.perf_counter() - started,
    )


def run_control(world: str, settings: Settings) -> Control:
    """One world's chapters 6-8 (runs in a worker process).

    Parameters
    ----------
    world : {"linear", "twin"}
    settings : Settings

    Returns
    -------
    Control

    Examples
    --------
    >>> run_control("moon", Settings())
    Traceback (most recent call last):
    trms.errors.InputError: unknown world 'moon'; allowed: 'linear', 'twin'
    """
    check_choice("world", world, WORLDS, error=InputError)
    seed = settings.seed
    twin = world == "twin"
    started = time.perf_counter()
    model_1dof = design_model("1dof")
    lqg = _pitch_loops(world, settings, settings.weights)
    push = None
    if twin:
        push = runs67.push_rejection(
            lambda p: make_plant("twin", "1dof", pushes=p, seed=seed), model_1dof, PUSH_WEIGHTS_R, seed=seed
        )
    loop_plant, margin_model = model_1dof, "eq. (3.11)"
    if twin:
        loop_plant, margin_model = Twin("1dof", model_1dof.dt).linearise().discrete, "its linearisation at hover"
    margins = {float(r): runs67.loop_margins(loop_plant, model_1dof, r) for r in settings.weights}
    # Table 6.1's control under a slower and a faster estimator (its rows only).
    rows_6_1, cases_6_1 = sorted({r for r, _ in TABLE_6_1}, reverse=True), sorted({c for _, c in TABLE_6_1})
    estimators = {k: _pitch_loops(world, settings, rows_6_1, cases_6_1, k) for k in settings.estimator_speeds}
    # the low-pass finding under the alternative the thesis names (a 0.25 Hz mode)
    rig = [r for r in PUSH_WEIGHTS_R if r in settings.weights]
    evidence = side_mode.prefilter_evidence(model_1dof, rig, seed) if twin else None
    # the checks of the saturation finding's explanation and of the R = 1 note, and R = 1 at the note's amplitudes
    flight = findings7.pci_flight(model_1dof, lqg[(75.0, "SAS")], seed) if twin else None
    amplitudes = amplitude_runs(make_plant(world, "1dof", seed=seed), model_1dof, seed) if twin else {}
    linearised = linearised_runs(model_1dof) if twin else {}
    autopilot = ch8.autopilot_runs(make_plant(world, "2dof", seed=seed), design_model("2dof"), seed)
    # the design beside its control weights scaled: the margins on the twin's linearisation, the runs on the twin
    scan = shipped_margin_scan(0.1) if twin else ()
    scan_runs = {}
    if twin:
        scales: tuple[float, ...] = (1.0,) if settings.quick else ch8.R_SCALES
        # the autopilot's MIMO LQG is the scan's run at the design's scale: the same plant, seed and design
        flown = {1.0: {scen: run for (name, scen), run in autopilot.items() if name == "MIMO LQG"}}
        plant_2dof = make_plant(world, "2dof", seed=seed)
        scan_runs = ch8.scan_runs(plant_2dof, design_model("2dof"), scales, seed=seed, flown=flown)
    return Control(
        lqg=lqg,
        margins=margins,
        margin_model=margin_model,
        estimators=estimators,
        autopilot=autopilot,
        push=push,
        side_mode=evidence,
        autopilot_margins=scan,
        autopilot_scan=scan_runs,
        flight=flight,
        amplitudes=amplitudes,
        linearised=linearised,
        seconds=time.perf_counter() - started,
    )


def _pitch_loops(
    world: str,
    settings: Settings,
    weights: Sequence[float],
    cases: Sequence[str] = runs67.ALL_CASES,
    estimator: float = 1.0,
) -> dict[tuple[float, str], runs67.CaseResult]:
    """Chapters 6/7's LQG runs on ``world``'s 1-DOF plant at the run's seed, designed on eq. (3.11): what the
    control part and the render fly."""
    seed = settings.seed
    plant = make_plant(world, "1dof", seed=seed)
    return runs67.lqg_cases(plant, design_model("1dof"), weights, cases, seed=seed, estimator=estimator)


def world_results(world: str, settings: Settings) -> WorldResults:
    """One world's experiments, both parts in this process.

    Parameters
    ----------
    world : {"linear", "twin"}
    settings : Settings

    Returns
    -------
    WorldResults

    Examples
    --------
    >>> world_results("moon", Settings())
    Traceback (most recent call last):
    trms.errors.InputError: unknown world 'moon'; allowed: 'linear', 'twin'
    """
    return WorldResults(run_identification(world, settings), run_control(world, settings))


def run_robustness(settings: Settings, part: int) -> RobustnessPart:
    """Part ``part`` of the Monte Carlo batch (its samples; the first part also the nominal loops), one job.

    Parameters
    ----------
    settings : Settings
    part : int
        0 to ``settings.robustness_parts - 1``.

    Returns
    -------
    RobustnessPart

    Examples
    --------
    >>> run_robustness(Settings(quick=True), 1)
    Traceback (most recent call last):
    trms.errors.InputError: part = 1 is outside the allowed range [0, 0]
    """
    check_in_range("part", part, 0, settings.robustness_parts - 1)
    started = time.perf_counter()
    indices = list(range(settings.samples))[part :: settings.robustness_parts]
    rows = robustness.run_samples(indices, settings.seed, robustness.SPREAD, "cpu")
    return RobustnessPart(
        robustness.samples_of(rows),
        robustness.nominal("linear", settings.seed) if part == 0 else None,
        time.perf_counter() - started,
    )


def run_controllers(settings: Settings) -> ControllerStudy:
    """Chapter 8's controller comparison (:func:`trms.experiments.ch8.comparison.controller_study`), one job: the
    1-DOF comparison at the run's seed (the push in the full run only), the parameter spread and the MIMO comparison
    on the twin in moving air at the settings' counts (the amplitude sweep is :func:`run_sweep`'s job).

    Examples
    --------
    >>> Settings(quick=True).controller_samples, Settings().controller_mimo_seeds
    (0, (0,))
    """
    return controller_study(
        (settings.seed,),
        settings.controller_samples,
        settings.controller_mimo_seeds,
        mimo_worlds=("twin, moving air",),
        cases=settings.controller_cases,
        push=not settings.quick,
        sweep_seeds=(),  # a job of its own (run_sweep)
    )


def run_sweep(settings: Settings) -> Sweep:
    """Chapter 8's amplitude sweep (:func:`trms.experiments.ch8.sweep.amplitude_sweep`) at the settings' seeds, one
    job beside the comparison's (the report's study carries it, :func:`run_jobs`).

    Examples
    --------
    >>> Settings().controller_sweep_seeds, Settings(quick=True).controller_sweep_seeds
    ((0,), ())
    """
    return amplitude_sweep(settings.controller_sweep_seeds)


def run_render(settings: Settings, path: Path) -> Render:
    """The twin's :data:`RENDERED` run of chapter 6 replayed offscreen into a GIF at ``path``, one job.

    The run is the one the twin's control part flies (the same plant, design model, seed and case of
    :func:`trms.experiments.ch67_lqg.lqg_cases`, so the same bits); a job of its own, it is drawn while the other
    jobs run.

    Parameters
    ----------
    settings : Settings
        The seed, and every how many samples a frame is drawn (``gif_every``).
    path : pathlib.Path
        The GIF to write (``.gif``).

    Returns
    -------
    Render
        ``path`` is ``None`` when the run diverged.

    Raises
    ------
    InputError
        ``path`` does not end in ``.gif`` (checked before anything runs).

    Examples
    --------
    >>> run_render(Settings(quick=True), Path("csas.mp4"))
    Traceback (most recent call last):
    trms.errors.InputError: the report's render is a GIF: 'csas.mp4' must end in .gif
    """
    from trms.twin.render import render_record

    _check_gif(path)
    started = time.perf_counter()
    r, case = RENDERED
    record = _pitch_loops("twin", settings, [r], [case])[RENDERED].record
    gif = None
    if record is not None:
        model = Twin("1dof", record.sample_time).model
        gif = render_record(model, record, path, camera="oblique", every=settings.gif_every, width=320, height=240)
    return Render(gif, time.perf_counter() - started)


def _check_gif(path: Path) -> None:
    if Path(path).suffix.lower() != ".gif":
        raise InputError(f"the report's render is a GIF: {str(path)!r} must end in .gif")


@dataclass(frozen=True)
class _Job:
    """One job: its name (``"twin control"``) and the call that runs it."""

    name: str
    run: Callable[..., Outcome]
    args: tuple[object, ...]


def _jobs(settings: Settings, render: Path | None = None) -> list[_Job]:
    """Every job, in the order the workers take them, longest first: the controller comparison and its amplitude
    sweep (chapter 8's, the full run only) and the twin's control part; then the twin's identification parts (its own
    seed's, then the others', so that chapters 3-5, whose figures are the most this process draws, are built while
    the rest runs), the twin's control parts at the other seeds, the linear parts, the render (into ``render``, when
    given) and the robustness parts, so that the workers finish together. Measured CPU time of each, one after the
    other with one BLAS thread (5 ms physics), full run: the controller comparison 16.0 s, its sweep 15.0 s, the
    twin's control part 12.9 s, its identification 5.8 s, each other seed's identification 2.6-2.7 s and control
    2.7-3.1 s, the robustness parts 2.6-2.9 s, the linear parts 0.6 and 1.8 s; 82 s in all."""
    parts = [_Job(f"robustness {k}", run_robustness, (settings, k)) for k in range(settings.robustness_parts)]
    drawn = [] if render is None else [_Job("twin render", run_render, (settings, render))]
    others = settings.seeds[1:]
    return [
        _Job("controllers", run_controllers, (settings,)),
        *([_Job("controller sweep", run_sweep, (settings,))] if settings.controller_sweep_seeds else []),
        _Job("twin control", run_control, ("twin", settings)),
        _Job("twin identification", run_identification, ("twin", settings)),
        *(_Job(f"twin identification, seed {s}", run_seed_identification, (settings, s)) for s in others),
        _Job("linear identification", run_identification, ("linear", settings)),
        *(_Job(f"twin control, seed {s}", run_seed_control, (settings, s)) for s in others),
        _Job("linear control", run_control, ("linear", settings)),
        *drawn,
        *parts,
    ]


def _take(done: Mapping[str, Outcome], name: str, kind: type[T]) -> T:
    """Job ``name``'s record, checked to be a ``kind``."""
    value = done[name]
    if not isinstance(value, kind):
        raise TypeError(f"job {name!r} returned {type(value).__name__}, expected {kind.__name__}")
    return value


def run_jobs(
    settings: Settings,
    workers: int,
    say: Callable[[str], None],
    on_result: Callable[[str, Outcome], None] | None = None,
    meanwhile: Callable[[], None] | None = None,
    render: Path | None = None,
) -> Results:
    """Run every job of ``settings`` in ``workers`` processes (1: in this one), saying each as it finishes.

    Parameters
    ----------
    settings : Settings
    workers : int
        Worker processes, at least 1.
    say : callable
        Called with a line of text as each job finishes.
    on_result : callable, optional
        Called in this process with each job's name and record as it finishes (in the order they finish): work
        that needs some records only starts while the other jobs run.
    meanwhile : callable, optional
        Called in this process once the jobs are started (before them with one worker): work that needs none.
    render : pathlib.Path, optional
        Where the render job (:func:`run_render`) writes its GIF; no render without it.

    Returns
    -------
    Results

    Examples
    --------
    >>> run_jobs(Settings(quick=True), 0, print)
    Traceback (most recent call last):
    trms.errors.InputError: workers = 0 is outside the allowed range [1, 64]
    """
    check_in_range("workers", workers, 1, 64)
    if render is not None:
        _check_gif(render)
    jobs = _jobs(settings, render)
    done: dict[str, Outcome] = {}

    def finished(name: str, outcome: Outcome) -> None:
        done[name] = outcome
        say(f"{name} done in {outcome.seconds:.1f} s")
        if on_result is not None:
            on_result(name, outcome)

    if workers == 1:
        if meanwhile is not None:
            meanwhile()
        for job in jobs:
            finished(job.name, job.run(*job.args))
    else:
        limited = threadpool_limits(blas_threads())  # this process builds sections meanwhile: small linear algebra
        try:
            with ReportPool(workers) as pool:  # Ctrl-C or a failed job: the other jobs stopped now, not waited for
                # In the workers' environment (and their own processes'), whether they start fresh or forked.
                with environment(ONE_THREAD), interrupts_held():
                    futures = {pool.submit(job.run, *job.args): job.name for job in jobs}
                if meanwhile is not None:
                    meanwhile()
                for fut in as_completed(futures):
                    finished(futures[fut], pool.result(fut))
        finally:
            limited.restore_original_limits()
    worlds = {
        w: WorldResults(_take(done, f"{w} identification", Identification), _take(done, f"{w} control", Control))
        for w in WORLDS
    }
    parts = [_take(done, f"robustness {k}", RobustnessPart) for k in range(settings.robustness_parts)]
    drawn = None if render is None else _take(done, "twin render", Render)
    study = _take(done, "controllers", ControllerStudy)
    if settings.controller_sweep_seeds:
        study = dataclasses.replace(study, sweep=_take(done, "controller sweep", Sweep))
    others = settings.seeds[1:]
    return Results(
        worlds,
        RobustnessPart.merge(parts),
        study,
        drawn,
        tuple(_take(done, f"twin identification, seed {s}", SeedIdentification) for s in others),
        tuple(_take(done, f"twin control, seed {s}", SeedControl) for s in others),
    )
