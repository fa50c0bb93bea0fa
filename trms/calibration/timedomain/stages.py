"""The stages of a time-domain fit: Gauss-Newton, the feasible start, the delay profile, the verdict.

Each stage works on a :class:`~trms.calibration.timedomain.rig.Rig` and the library's residual
function: ``mujoco.sysid.optimize`` from a start (:func:`fit_bounded`), a start that hits no end stop the
records never reach (:func:`start_clear_of_stops`), the transport delay by its profile
(:func:`profile_delay`, :func:`delay_column`), seeded turbulence draws for the disturbance
intervals (:func:`disturbed_draws`) and why a fit cannot be trusted (:func:`fit_failures`); :class:`Tracker`
feeds the progress bars (see :mod:`trms.calibration.timedomain`).
"""

import io
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.signal

from trms.calibration.calibrate import Progress
from trms.calibration.timedomain.feasible_start import SPREAD, StopHit, best_feasible, latin_hypercube, stop_hit
from trms.calibration.timedomain.rig import Rig, sysid
from trms.errors import EstimationError
from trms.twin.parameters import PARAMETERS

__all__: list[str] = []

#: Step at which Gauss-Newton stops, relative to the parameters' norm (the last step is taken).
#: The library's 1e-8 spends its last iterations raising the damping against round-off, at
#: three times the rollouts; with 1e-8 the benchmark's gust-free truths miss the same intervals.
_XTOL = 1e-6


class Tracker:
    """Feeds the progress bar: the stage, the optimiser's iteration and cost, and the rollouts so far."""

    def __init__(self, progress: Progress, rig: Rig, max_iters: int) -> None:
        self.progress = progress
        self.rig = rig
        self.max_iters = max_iters
        self.stage = ""
        self.iteration = 0
        self.cost = float("nan")
        self.fraction = 0.0
        rig.on_rollout = self.rolled

    def begin(self, stage: str, fraction: float = 0.0) -> None:
        """Show ``stage`` (closing the previous one) at ``fraction`` done."""
        if stage != self.stage and self.stage:
            self.progress.done(self.stage, f"{self.rig.evaluations} rollouts")
        self.stage, self.fraction, self.iteration = stage, fraction, 0
        self.rolled()

    def iterated(self, trace: Sequence[Any]) -> None:
        """``iter_callback`` of the optimiser: one more Gauss-Newton iteration."""
        self.iteration, self.cost = len(trace), float(trace[-1].objective)
        if self.stage == "fit":
            self.fraction = min(self.iteration / self.max_iters, 1.0)
        self.rolled()

    def rolled(self) -> None:
        """A batch of rollouts finished."""
        detail = f"{self.rig.evaluations} rollouts"
        if self.iteration:
            detail = f"iteration {self.iteration}, cost {self.cost:.4g}, {detail}"
        self.progress.update(self.stage, self.fraction, detail)

    def close(self) -> None:
        """Finish the last stage's bar."""
        if self.stage:
            self.progress.done(self.stage, f"{self.rig.evaluations} rollouts")
        self.rig.on_rollout = None


@dataclass
class FitOutcome:
    """One Gauss-Newton fit: the parameters, and the residual and Jacobian at them."""

    params: Any
    residual: np.ndarray
    jacobian: np.ndarray
    iterations: int
    stopped: str
    extras: dict[str, Any] = field(default_factory=dict)

    @property
    def sse(self) -> float:
        return float(self.residual @ self.residual)


#: A sum of squares (rad^2) at or below which the start reproduces the records to round-off.
_EXACT = 1e-20
_TERMINATED = re.compile(r"^Terminated after \d+ iterations:")


def fit_bounded(params: Any, residual_fn: Any, max_iters: int, tracker: Tracker | None = None) -> FitOutcome:
    """``mujoco.sysid.optimize`` from ``params``.

    The optimiser's result holds the Jacobian at the end and, per iteration, the objective and
    candidate; its last log entry (kept by the iteration callback) the residual there. The
    iteration count is the steps the optimiser took: its trace has one entry per step it accepted
    and one for the end point. (Its termination line, ``Terminated after N iterations: why``, counts
    its loop's index, one less than the steps when it stopped for the iteration limit or a step below
    the tolerance; only the reason is kept from it, in ``stopped``.)
    """
    log = io.StringIO()  # mujoco.minimize's per-iteration lines; the last one says why it stopped
    kept: dict[str, Any] = {}

    def callback(trace: Sequence[Any]) -> None:
        kept["trace"] = trace
        if tracker is not None:
            tracker.iterated(trace)

    opt_params, result = sysid.optimize(
        params,
        residual_fn,
        optimizer="mujoco",
        verbose=False,
        max_iters=int(max_iters),
        output=log,
        x_scale="jac",  # parameters three orders of magnitude apart: steps in Jacobian-scaled units
        xtol=_XTOL,
        iter_callback=callback,
    )
    last = next((line for line in reversed(log.getvalue().splitlines()) if line.startswith("Terminated")), "")
    stopped = _TERMINATED.sub("", last).strip()
    extras = dict(result.extras)
    iterations = len(kept["trace"]) - 1
    residual = np.ravel(kept["trace"][-1].residual)
    return FitOutcome(opt_params, residual, np.asarray(result.jac), iterations, stopped, extras)


def _stop_hits(
    rig: Rig,
    residual_fn: Any,
    params: Any,
    candidates: np.ndarray,
    labels: Sequence[str],
    origins: Sequence[float],
) -> tuple[np.ndarray, list[StopHit | None]]:
    """Sum of squares of each candidate (a column of ``candidates``) and its first end-stop hit on the records.

    All candidates roll out in one batch, through the library's residual (the optimiser's objective). A hit's
    time is on its record's own clock: ``origins`` holds each record's first sample's time (s).
    """
    res, preds, meas = residual_fn(candidates, params.copy(), return_pred_all=True)
    k = candidates.shape[1]
    sse = np.array([sum(float(r[:, c] @ r[:, c]) for r in res) for c in range(k)])
    hits: list[StopHit | None] = []
    for c in range(k):
        found = (
            stop_hit(pr[c].data, mm[0].data, pr[c].times + t0, rig.stops, rig.config.outputs, label)
            for pr, mm, label, t0 in zip(preds, meas, labels, origins)
        )
        hits.append(next((h for h in found if h is not None), None))
    return sse, hits


def start_clear_of_stops(
    rig: Rig,
    residual_fn: Any,
    params: Any,
    labels: Sequence[str],
    origins: Sequence[float],
    tracker: Tracker,
    seed: int,
) -> tuple[Any, str, int]:
    """The parameters to fit from, a note when they are not the start, and how many candidates were tried.

    The start is rolled out on the fitted records; when it runs into an end stop that a record
    stays away from (or diverges), seeded Latin-hypercube candidates are drawn, first within a
    factor :data:`~trms.calibration.timedomain.feasible_start.SPREAD` of the start, then over the
    whole bounds, and the one of least sum of squares that hits no such stop is the start.
    """
    x0 = params.as_vector()
    tracker.begin("start check")
    _, (hit,) = _stop_hits(rig, residual_fn, params, x0[:, None], labels, origins)
    if hit is None:
        return params, "", 0
    lower, upper = params.get_bounds()
    n = max(8, 3 * x0.size)
    tried = 0
    for k, spread in enumerate((SPREAD, None)):
        tracker.begin("coarse start", k / 2)
        cand = latin_hypercube(x0, lower, upper, n, seed + k, spread)
        sse, hits = _stop_hits(rig, residual_fn, params, cand.T, labels, origins)
        tried += n
        best = best_feasible(sse, hits)
        if best is not None:
            out = params.copy()
            out.update_from_vector(cand[best])
            note = (
                f"with the starting parameters {hit}; the fit started from the best of {tried} seeded "
                "Latin-hypercube candidates that hits no stop the records do not reach"
            )
            return out, note, tried
    raise EstimationError(
        f"no feasible start: with the starting parameters {hit}, and each of {tried} seeded Latin-hypercube "
        "candidates within the parameters' bounds also runs into a stop the records do not reach (or diverges); "
        "check the records' units and channels, or start from a model nearer the rig (--start-from)"
    )


def profile_delay(
    rig: Rig, params: Any, residual_fn: Any, max_iters: int, start: float, tracker: Tracker
) -> tuple[float, FitOutcome, int]:
    """The transport delay that minimises the profile sum of squares, and the fit there.

    MuJoCo's actuator delay acts in whole physics steps: every delay strictly inside one
    step ``(k dt, (k + 1) dt)`` gives the same motion, so a finite-difference Jacobian sees
    none of it and the delay is known to a step at best. The profile runs on the steps'
    centres ``(k + 1/2) dt`` (an exact multiple of ``dt`` falls on either side by round-off):
    at each the other parameters are fitted (warm-started from the nearest delay already
    fitted). The search starts at ``start`` and its neighbours ``+-h`` steps (``h`` the
    larger of 10 and 10 % of ``start``), steps out by ``2 h`` while the least sum of
    squares is at an end, moves to the vertex of the parabola through the least point and
    its two neighbours until that vertex is already fitted, then walks one step at a time
    while the sum of squares falls. Returns the delay (s), its fit, and how many fits it took.
    """
    step = float(rig.start.model.opt.timestep)
    bounds = PARAMETERS["input_delay"].bounds
    lo, hi = int(np.ceil(bounds[0] / step - 0.5)), int(np.floor(bounds[1] / step - 0.5))
    fits: dict[int, FitOutcome] = {}

    def at(k: int) -> int:
        k = int(np.clip(k, lo, hi))
        if k not in fits:
            rig.delay = (k + 0.5) * step
            warm = params.copy()
            if fits:
                warm.update_from_vector(fits[min(fits, key=lambda j: abs(j - k))].params.as_vector())
            tracker.fraction = min(len(fits) / 10, 0.99)  # a profile takes some 5 to 10 fits
            fits[k] = fit_bounded(warm, residual_fn, max_iters, tracker)
        return k

    k0 = at(int(round(start / step - 0.5)))
    h = max(10, int(round(0.1 * k0)))
    at(k0 - h)
    at(k0 + h)
    for _ in range(20):
        ks = sorted(fits)
        sse = [fits[k].sse for k in ks]
        b = int(np.argmin(sse))
        if b in (0, len(ks) - 1):
            nxt = int(np.clip(ks[b] + (2 * h if b else -2 * h), lo, hi))
            if nxt in fits:
                break  # the least sum of squares is at a bound
            at(nxt)
            continue
        x = np.array(ks[b - 1 : b + 2], float)
        curv, slope, _ = np.polyfit(x - x[1], sse[b - 1 : b + 2], 2)
        vertex = int(round(x[1] - slope / (2 * curv))) if curv > 0 else ks[b]
        if vertex in fits:
            break
        at(vertex)
    best = min(fits, key=lambda k: fits[k].sse)
    for direction in (-1, 1):
        while fits[at(best + direction)].sse < fits[best].sse:
            best = int(np.clip(best + direction, lo, hi))
    rig.delay = (best + 0.5) * step
    return rig.delay, fits[best], len(fits)


def delay_column(rig: Rig, params: Any, residual_fn: Any, delay: float, steps: int = 10) -> np.ndarray:
    """Central difference of the residual in the transport delay, over ``+-steps`` physics steps (per s)."""
    dt = float(rig.start.model.opt.timestep)
    lo, hi = PARAMETERS["input_delay"].bounds
    ends = [float(np.clip(delay + sgn * steps * dt, lo, hi)) for sgn in (-1, 1)]
    cols = []
    for d in ends:
        rig.delay = d
        cols.append(np.concatenate(residual_fn(params.as_vector(), params)[0]))
    rig.delay = delay
    return (cols[1] - cols[0]) / (ends[1] - ends[0])


def disturbed_draws(rig: Rig, residual_fn: Any, params: Any, seq: Any, draws: int, seed: int) -> np.ndarray:
    """The change of the residual when the fitted model is driven by each of ``draws`` seeded turbulence draws.

    Each draw is the model's own rotor-wash turbulence (an Ornstein-Uhlenbeck thrust per rotor, held
    over each control interval, from its stationary distribution: :class:`~trms.twin.disturbances.Turbulence`)
    at the model's own level; :func:`~trms.calibration.timedomain.intervals.disturbance_intervals` scales it to
    the data.
    Returns ``(draws, R)`` in the residual's layout; zeros when the model has no turbulence.
    """
    base = np.concatenate(residual_fn(params.as_vector(), params)[0])
    model = rig.build(params)
    turb = rig._by_model[id(model)].turbulence
    if not turb.active or not rig.wash_columns:
        return np.zeros((1, base.size))
    a = float(np.exp(-rig.sample_time / turb.time_constant))
    std = np.asarray(turb.std, float)[: len(rig.wash_columns)]
    group = [(traj.control, traj.initial_state) for traj in seq.measured_rollout]
    rng = np.random.default_rng(np.random.SeedSequence([seed, 1]))
    washes = []
    for _ in range(draws):
        for c, _ in group:
            w = rng.standard_normal((c.data.shape[0], std.size))
            w[0] /= np.sqrt(1.0 - a * a)  # the first value from the stationary distribution
            washes.append(std * np.sqrt(1.0 - a * a) * scipy.signal.lfilter([1.0], [1.0, -a], w, axis=0))
    # every draw of every record in one batch on all threads; the library's residual then finds them rolled out
    trajs = rig._roll([(model, c, x0) for _ in range(draws) for c, x0 in group], washes)
    out = np.empty((draws, base.size))
    for m in range(draws):
        rig._done = {(id(model), id(c)): trajs[m * len(group) + i] for i, (c, _) in enumerate(group)}
        out[m] = np.concatenate(residual_fn(params.as_vector(), params)[0]) - base
    rig._done = {}
    return out


def fit_failures(
    fit: FitOutcome,
    before: dict[str, list[float]],
    after: dict[str, list[float]],
    labels: Sequence[str],
    kind: str,
    at_stops: Sequence[str] = (),
) -> list[str]:
    """Why a fit cannot be trusted: no optimiser step; a checked record's fit below 0 % or worse than the start's.

    Without a step, the reason named is the fitted records' first end-stop contact when they have one
    (``at_stops``, :func:`~trms.calibration.timedomain.feasible_start.stop_reached`, each with how far the record's
    inputs
    swing): its impacts make the residual jump with the parameters; else a residual flat in them. A fit that
    failed otherwise on records that reach a stop names every contact first, and asks for a lower amplitude.

    Examples
    --------
    >>> fit = FitOutcome(None, np.ones(1), np.zeros((1, 1)), 0, "norm(gradient) < tol")
    >>> for line in fit_failures(fit, {"pitch": [-17.1]}, {"pitch": [-17.2]}, ["r3"], "held-out"):
    ...     print(line)
    the optimiser took no step (norm(gradient) < tol): the residual is flat in the parameters there; nothing ...
    pitch: the fit on held-out record r3 is -17.2 % after calibration, below 0 % (its mean predicts it better)
    pitch: the fit on held-out record r3 got worse than the start's (-17.1 % -> -17.2 %)
    """
    out = []
    if fit.iterations == 0 and at_stops:
        out.append(
            f"the optimiser took no step ({fit.stopped}): {at_stops[0]}, and its impacts make the residual jump "
            "with the parameters; nothing was calibrated (record the rig again with a lower amplitude, that keeps "
            "it off its end stops)"
        )
    elif fit.iterations == 0 and fit.sse <= _EXACT:
        out.append(
            f"the optimiser took no step ({fit.stopped}): the start already reproduces the records "
            f"(sum of squares {fit.sse:.3g}); nothing was calibrated"
        )
    elif fit.iterations == 0:
        out.append(
            f"the optimiser took no step ({fit.stopped}): the residual is flat in the parameters there; "
            "nothing was calibrated"
        )
    for o in after:
        for label, b, a in zip(labels, before[o], after[o]):
            if not a >= 0:  # a NaN fit (a constant record) is no fit either
                out.append(
                    f"{o}: the fit on {kind} record {label} is {a:.1f} % after calibration, below 0 % "
                    "(its mean predicts it better)"
                )
            if a < b:
                out.append(f"{o}: the fit on {kind} record {label} got worse than the start's ({b:.1f} % -> {a:.1f} %)")
    if out and at_stops and fit.iterations > 0:  # the contacts first: the line a failed command prints
        out.insert(
            0,
            f"the fitted records reach end stops, where the beam rests on a stop and a fit cannot follow it sample "
            f"by sample: {'; '.join(at_stops)}; record the rig again with a lower amplitude, that keeps it off its "
            "end stops",
        )
    return out
