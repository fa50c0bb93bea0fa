"""The spectral stage: coupling parameters chosen on the nonlinear twin, in batches.

Which modes a channel shows and how coherent it is depend on couplings (the main rotor's
lean and spin inertia, which turn its angular momentum into a yaw-rate-to-pitch torque, and
the tail rotor's reaction torque, which acts about the pitch axis) that the linearisation's modes
do not pin down, on the rig's ambient excitation and on the encoder's resolution, which only the
nonlinear, quantised twin has. So these parameters are chosen on a grid: every candidate whose
gyroscopic coupling (pitch torque per yaw rate, computed from the model) lies within its target runs the
thesis's 2-DOF protocols at each of the fit seeds (:data:`~trms.measurement.protocol.FIT_SEEDS`), all
candidates of a protocol in one batch, and each is scored on the targets as verification measures them
(:func:`~trms.calibration.checks.spectral_checks`, on the spectra averaged over the seeds: the summed
violation); a candidate outside the coupling target scores worse than any inside it without running.
Verification then runs at other seeds.
"""

from __future__ import annotations

import copy
import dataclasses
import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from trms.calibration.checks import coupling_checks, spectral_checks
from trms.calibration.targets import Targets
from trms.errors import DesignError
from trms.measurement.protocol import FIT_SEEDS, THESIS_PROTOCOLS, Protocol, protocol_records
from trms.twin.parameters import PARAMETERS, read_parameters, with_parameters

__all__ = ["DEFAULT_COUPLING", "COUPLING_GRID", "CouplingFit", "fit_coupling", "score_candidate"]

#: Parameters of the spectral stage by default: the main rotor's lean and spin inertia (their product is the
#: yaw-rate-to-pitch torque: at the published inertia no lean within its bounds reaches the thesis's coupling, so both
#: are chosen; among candidates that tie, the one closest to the current values wins) and its reaction torque (how
#: hard u1 drives yaw, hence how much of the 0.1 Hz yaw mode reaches pitch through the lean under u1 but not under u2).
DEFAULT_COUPLING = ("main_rotor_tilt", "main_rotor_inertia_radius", "main_reaction")
#: The first, coarse grid of each coupling parameter (refined by the compass search around the best point).
COUPLING_GRID = {
    "main_rotor_tilt": (0.25, 0.3, 0.35),
    "main_rotor_inertia_radius": (0.1, 0.18, 0.25),
    "tail_reaction": (0.0, 0.001, 0.003),
    "main_reaction": (0.1, 0.2, 0.3),
}


@dataclass
class CouplingFit:
    """Result of :func:`fit_coupling`.

    Attributes
    ----------
    values : dict of str to float
        The chosen value of each parameter (SI units of :data:`~trms.twin.parameters.PARAMETERS`).
    score : float
        Summed violation of the chosen candidate (0 when it meets every target with the margin).
    n_candidates : int
        Candidates scored.
    converged : bool
        Whether the compass search ended at a point better than each of its neighbours (False when it
        stopped after :data:`MAX_COMPASS_MOVES` moves still improving).

    Examples
    --------
    >>> CouplingFit({"main_rotor_tilt": 0.3}, 0.0, 5).converged
    True
    """

    values: dict[str, float]
    score: float
    n_candidates: int
    converged: bool = True


#: The violation of a candidate outside the gyroscopic coupling target, before its miss is added: more than any
#: candidate inside it can score on the spectral targets.
OUTSIDE_COUPLING = 100.0

#: Most moves of the compass search (each move scores at most 2 n new candidates).
MAX_COMPASS_MOVES = 4

#: Fraction of each tolerance a candidate must meet on the fit seeds, so that unseen seeds keep some room: a
#: 'low' coherence must come out below MARGIN x its threshold, a peak within MARGIN x its tolerance.
MARGIN = 0.7
#: The same for the RMS figures (an output's RMS over another's, an output's RMS in counts): the u2 -> pitch RMS
#: must lie between the least movement and the largest ratio, which leave it about 40 % of room, and it scatters
#: by about 10 % from seed to seed.
RMS_MARGIN = 0.9


def _snap(value: float) -> float:
    """``value`` rounded to 12 decimals: a candidate's coordinate and the key its score is cached under, so that a
    point reached from two centres (``0.15 + 0.075 - 0.075`` is ``0.14999999999999997``) is one point."""
    return float(round(float(value), 12))


def _with_margin(targets: Targets) -> Targets:
    """A copy of ``targets`` with the tolerances the fit scores against (:data:`MARGIN`)."""
    stricter = copy.copy(targets)
    stricter.peaks = [dataclasses.replace(p, tolerance_hz=p.tolerance_hz * MARGIN) for p in targets.peaks]
    stricter.coherences = [
        dataclasses.replace(
            c, threshold=c.threshold * MARGIN if c.level == "low" else 1.0 - (1.0 - c.threshold) * MARGIN
        )
        for c in targets.coherences
    ]
    stricter.ratios = [dataclasses.replace(r, max_ratio=r.max_ratio * RMS_MARGIN) for r in targets.ratios]
    stricter.movements = [dataclasses.replace(m, min_counts=m.min_counts / RMS_MARGIN) for m in targets.movements]
    return stricter  # the gyroscopic coupling has no seed to scatter with: its own tolerance


#: A peak whose prominence leads the most prominent peak left out of the main ones by this much (dB) is safely among
#: them: its room is full there.
LEAD_DB = 3.0


def _room(check) -> float:
    """How far a check is inside its tolerance, in units of the tolerance (negative when outside)."""
    if check.unit == "Hz":  # a peak: |f - target| against the tolerance, and how safely it is a main peak
        tol = float(check.tolerance.split()[0].lstrip("+-"))
        if not np.isfinite(check.achieved):
            return -1.0
        return min(1.0 - abs(check.achieved - check.target) / tol, check.lead_db / LEAD_DB)
    if check.unit == "counts":  # an output that must move: its RMS against the least
        return check.achieved / check.target - 1.0
    if check.tolerance.endswith("%") and check.tolerance.startswith("+-"):  # a relative tolerance
        tol = float(check.tolerance[2:-1]) / 100.0
        return 1.0 - abs(check.achieved - check.target) / (tol * abs(check.target))
    if check.tolerance.startswith("<="):
        return (check.target - check.achieved) / (0.1 if "coherence" in check.name else check.target)
    return (check.achieved - check.target) / 0.1


def _evaluate(
    specs: list[mujoco.MjSpec],
    targets: Targets,
    protocols: Sequence[Protocol],
    counts_per_rev: int | None,
    seeds: Sequence[int] = FIT_SEEDS,
) -> tuple[np.ndarray, np.ndarray]:
    """Summed violation (with :data:`MARGIN`) and the least room of any check, for each candidate.

    The violation is that of the checks on the spectra averaged over the fit runs, as verification measures an
    experiment; the room (what unseen seeds need) is taken on those checks and on each run's own coherences, so
    that a candidate whose coherence a single run pulls down (the lower tail that unseen experiments reach) has
    less of it. A candidate whose gyroscopic coupling (a figure of the model, with no seed to scatter with)
    misses its target is not run: its violation is :data:`OUTSIDE_COUPLING` plus the coupling's miss, worse than
    any candidate inside.
    """
    targets = _with_margin(targets)
    runs = [p for p in protocols if p.config == "2dof"]
    violation, room = np.empty(len(specs)), np.full(len(specs), -1.0)
    inside = []
    coupled = [coupling_checks(spec, targets) for spec in specs]
    for b, checks in enumerate(coupled):
        miss = sum(c.violation for c in checks)
        violation[b] = OUTSIDE_COUPLING + miss if miss > 0 else 0.0
        if miss == 0:
            inside.append(b)
    if not inside:
        return violation, room
    # per_protocol[p][s][k]: protocol p at seed s for the k-th candidate inside the coupling target.
    per_protocol = [
        [protocol_records([specs[b] for b in inside], p, counts_per_rev, seed=s) for s in seeds] for p in runs
    ]
    coherence_only = copy.copy(targets)
    coherence_only.peaks, coherence_only.ratios, coherence_only.movements = [], [], []
    for k, b in enumerate(inside):
        checks = spectral_checks(
            {(p.config, p.excited): [by_seed[k] for by_seed in recs] for p, recs in zip(runs, per_protocol)}, targets
        )
        single = [
            c
            for s in range(len(seeds))
            for c in spectral_checks(
                {(p.config, p.excited): recs[s][k] for p, recs in zip(runs, per_protocol)}, coherence_only
            )
        ]
        violation[b] = sum(c.violation for c in checks)
        room[b] = min((_room(c) for c in checks + single), default=0.0)
    return violation, room


def score_candidate(
    item: tuple[str, dict[str, float], Targets, tuple[Protocol, ...], int | None],
) -> tuple[float, float]:
    """Violation and least room of one candidate, from ``(MJCF text, values, targets, protocols, counts_per_rev)``.

    Everything in the item pickles, so candidates can run as tasks on a Dask cluster
    (:func:`trms.batch.distributed.map_items`); the result equals the in-process batch's.

    Parameters
    ----------
    item : tuple
        The model's MJCF text, the candidate's parameter values (SI units), the targets, the protocols and
        the encoder resolution (counts per revolution; None: the twin's default).

    Returns
    -------
    (float, float)
        The summed violation (0: every target met with the margin) and the least room left on a target
        (in tolerances).

    Examples
    --------
    >>> from trms.measurement.protocol import Protocol
    >>> from trms.calibration.target_kinds import PeakTarget
    >>> from trms.twin import load_spec
    >>> targets = Targets([PeakTarget("2dof", "u1->pitch", 0.34, 0.05)])
    >>> protocols = (Protocol("2dof", "u1", 2.0, 30.0, 0.05),)
    >>> violation, room = score_candidate((load_spec().to_xml(), {"main_rotor_tilt": 0.3}, targets, protocols, None))
    >>> violation, room > 0
    (0.0, True)
    """
    xml, values, targets, protocols, counts_per_rev = item
    violation, room = _evaluate(
        [with_parameters(mujoco.MjSpec.from_string(xml), values)], targets, protocols, counts_per_rev
    )
    return float(violation[0]), float(room[0])


def evaluate_candidates(
    spec: mujoco.MjSpec,
    candidates: list[dict[str, float]],
    targets: Targets,
    protocols: Sequence[Protocol],
    counts_per_rev: int | None,
    cluster: dict | None,
) -> tuple[np.ndarray, np.ndarray]:
    """All candidates' scores: one threaded batch here, or one Dask task per candidate with ``cluster``."""
    if cluster is None:
        return _evaluate([with_parameters(spec, c) for c in candidates], targets, protocols, counts_per_rev)
    from trms.batch.distributed import map_items

    xml = spec.to_xml()
    scores = map_items(
        score_candidate,
        [(xml, c, targets, tuple(protocols), counts_per_rev) for c in candidates],
        chunk_size=1,
        label="candidates",
        **cluster,
    )
    return np.array([s[0] for s in scores]), np.array([s[1] for s in scores])


def fit_coupling(
    spec: mujoco.MjSpec,
    targets: Targets,
    parameters: Sequence[str] = DEFAULT_COUPLING,
    grid: dict[str, Sequence[float]] | None = None,
    protocols: Sequence[Protocol] = THESIS_PROTOCOLS,
    counts_per_rev: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    cluster: dict | None = None,
    coarse: bool = True,
) -> CouplingFit:
    """Choose ``parameters`` on a grid (and the starting values), then by a compass search at half its spacing.

    The start is scored first: when it meets every target with the fit's margin (score 0) it is returned as it is
    (one candidate scored, converged): a model that meets its targets is not moved within the set that does.

    The compass search compares the best point with its neighbours half the grid's smallest spacing either
    side along each axis and moves to the best of them until the centre is best (at most
    :data:`MAX_COMPASS_MOVES` moves).
    With ``coarse=False`` (the calibration's later passes, which start from an earlier pass's choice) only
    the compass search runs, from the current values.

    Ties (several candidates meeting every target) go to the candidate with the most room on
    its tightest target, then to the one closest to the current values. With ``cluster``
    (keyword arguments of :func:`trms.batch.distributed.map_items`: ``workers``, ``scheduler``,
    ``processes``, ``progress``) every candidate is a task on a Dask cluster instead.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The model (not modified).
    targets : Targets
        Its 2-DOF spectral targets (and coupling target) score the candidates.
    parameters : sequence of str
        The parameters chosen, each with a grid.
    grid : dict of str to sequence of float, optional
        Grid values (SI units) replacing :data:`COUPLING_GRID`'s.
    protocols : sequence of Protocol
        The excitation experiments, run at the fit seeds.
    counts_per_rev : int, optional
        Encoder resolution (default: the twin's).
    progress : callable, optional
        Called with ``(candidates scored, candidates planned)``.
    cluster : dict, optional
        Run the candidates on a Dask cluster.
    coarse : bool
        Score the grid first (else only the compass search from the current values).

    Returns
    -------
    CouplingFit

    Examples
    --------
    >>> from trms.measurement.protocol import Protocol
    >>> from trms.calibration.target_kinds import PeakTarget
    >>> from trms.twin import load_spec
    >>> targets = Targets([PeakTarget("2dof", "u1->pitch", 0.34, 0.05)])
    >>> protocols = (Protocol("2dof", "u1", 2.0, 30.0, 0.05),)
    >>> fit = fit_coupling(load_spec(), targets, ("main_rotor_tilt",), protocols=protocols, coarse=False)
    >>> fit.score, fit.converged, fit.n_candidates  # the shipped model meets it: kept, one candidate scored
    (0.0, True, 1)
    """
    grid = {**COUPLING_GRID, **(grid or {})}
    for name in parameters:
        if name not in PARAMETERS or name not in grid:
            raise DesignError(f"no grid for coupling parameter {name!r}; give one in grid=")
    current = read_parameters(spec, parameters)
    scale = {n: (max(abs(v) for v in grid[n]) or 1.0) for n in parameters}
    axes = [sorted({_snap(v) for v in grid[n]}) for n in parameters]
    # The compass step: half the smallest spacing of each parameter's grid (a wider gap of an uneven grid takes
    # several moves).
    half = [(np.min(np.diff(a)) if len(a) > 1 else 0.1) / 2 for a in axes]
    start = tuple(_snap(current[n]) for n in parameters)
    scored: dict[tuple[float, ...], tuple[float, float]] = {}

    def key(combo: tuple[float, ...]) -> tuple[float, float, float]:
        # Least violation first; among equals, the most room left on the tightest target (what unseen seeds
        # need), then the candidate closest to the current values.
        score, room = scored[combo]
        distance = sum(((v - current[n]) / scale[n]) ** 2 for n, v in zip(parameters, combo))
        return float(score), -round(float(room), 3), distance

    def run(combos: list[tuple[float, ...]]) -> tuple[float, ...]:
        """Score the combinations not scored yet (one batch); return the best of ``combos``."""
        fresh = [c for c in dict.fromkeys(combos) if c not in scored]
        if fresh:
            got = evaluate_candidates(
                spec, [dict(zip(parameters, c)) for c in fresh], targets, protocols, counts_per_rev, cluster
            )
            scored.update(zip(fresh, zip(*got)))
            if progress is not None:
                progress(len(scored), max(total, len(scored)))
        return min(combos, key=key)

    def clip(name: str, value: float) -> float:
        return _snap(np.clip(value, *PARAMETERS[name].bounds))

    best = start
    total = 2 * len(parameters) + 1
    # A start that meets every target with the fit's margin is a solution: kept as it is. Ranking it against
    # candidates by room on the fit seeds would move a model that meets its targets to one tuned to those seeds.
    run([start])
    if scored[start][0] == 0.0:  # kept as it is: the exact values, not their 12-decimal grid coordinates
        return CouplingFit(dict(current), 0.0, len(scored), True)
    if coarse:
        coarse_combos = list(itertools.product(*axes))
        if start not in coarse_combos:  # the start competes too: the fit never ends worse than it began
            coarse_combos.append(start)
        total += len(coarse_combos) - 1  # the compass search's first centre is a grid point
        best = run(coarse_combos)
    # Compass search at half the grid's step: the centre against its neighbour on either side along each axis,
    # moving to the best until the centre is best (2 n new runs per move, 2 n + 1 from a fresh start).
    converged = False
    for _ in range(MAX_COMPASS_MOVES):
        around = [best] + [
            best[:i] + (clip(n, best[i] + k * h),) + best[i + 1 :]
            for i, (n, h) in enumerate(zip(parameters, half))
            for k in (-1, 1)
        ]
        moved = run(around)
        if moved == best:
            converged = True
            break
        best = moved
    return CouplingFit(dict(zip(parameters, best)), key(best)[0], len(scored), converged)
