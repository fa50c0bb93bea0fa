"""The spectral stage: coupling parameters chosen on the nonlinear twin, in batches.

Which modes a channel shows and how coherent it is depend on couplings (the main rotor's
lean and spin inertia, which turn its angular momentum into a yaw-rate-to-pitch torque, and
the tail rotor's reaction torque, which acts about the pitch axis) that the linearisation's modes
do not pin down, and on the encoder's resolution, which only the nonlinear, quantised twin has. So
these parameters are chosen on a grid: every candidate runs the thesis's 2-DOF protocols at each of the fit seeds
(:data:`~trms.twin.calibration.protocol.FIT_SEEDS`), all candidates of a protocol in one
``mujoco.rollout`` call, and each is scored on the targets as verification measures them
(:func:`~trms.twin.calibration.verify.spectral_checks`, on the spectra averaged over the
seeds: the summed violation). Verification then runs at other seeds.
"""

from __future__ import annotations

import copy
import dataclasses
import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from ...errors import DesignError
from ..parameters import PARAMETERS, read_parameters, with_parameters
from .protocol import FIT_SEEDS, THESIS_PROTOCOLS, Protocol, protocol_records
from .targets import Targets
from .verify import spectral_checks

__all__ = ["DEFAULT_COUPLING", "COUPLING_GRID", "CouplingFit", "fit_coupling", "score_candidate"]

#: Parameters of the spectral stage by default.
DEFAULT_COUPLING = ("main_rotor_tilt", "main_rotor_inertia_radius", "tail_reaction")
#: The first, coarse grid of each coupling parameter (refined once around the best point).
COUPLING_GRID = {
    "main_rotor_tilt": (0.0, 0.15, 0.3),
    "main_rotor_inertia_radius": (0.1, 0.18, 0.25),
    "tail_reaction": (0.0, 0.001, 0.003),
    "main_reaction": (0.05, 0.1),
}


@dataclass
class CouplingFit:
    """Result of :func:`fit_coupling`."""

    values: dict[str, float]
    score: float
    n_candidates: int


#: Fraction of each tolerance a candidate must meet on the fit seeds, so that unseen seeds keep some room: a
#: 'low' coherence must come out below MARGIN x its threshold, a peak within MARGIN x its tolerance.
MARGIN = 0.7


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
    stricter.ratios = [dataclasses.replace(r, max_ratio=r.max_ratio * MARGIN) for r in targets.ratios]
    return stricter


def _room(check) -> float:
    """How far a check is inside its tolerance, in units of the tolerance (negative when outside)."""
    if check.unit == "Hz":  # a peak: |f - target| against the tolerance
        tol = float(check.tolerance.split()[0].lstrip("+-"))
        return 1.0 - abs(check.achieved - check.target) / tol if np.isfinite(check.achieved) else -1.0
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
    """Summed violation (with :data:`MARGIN`) and the least room of any check, for each candidate."""
    targets = _with_margin(targets)
    runs = [p for p in protocols if p.config == "2dof"]
    # per_protocol[p][s][b]: protocol p at seed s for candidate b.
    per_protocol = [[protocol_records(specs, p, counts_per_rev, seed=s) for s in seeds] for p in runs]
    violation, room = np.empty(len(specs)), np.empty(len(specs))
    for b in range(len(specs)):
        checks = spectral_checks(
            {(p.config, p.excited): [by_seed[b] for by_seed in recs] for p, recs in zip(runs, per_protocol)}, targets
        )
        violation[b] = sum(c.violation for c in checks)
        room[b] = min((_room(c) for c in checks), default=0.0)
    return violation, room


def score_candidate(
    item: tuple[str, dict[str, float], Targets, tuple[Protocol, ...], int | None],
) -> tuple[float, float]:
    """Violation and least room of one candidate, from ``(MJCF text, values, targets, protocols, counts_per_rev)``.

    Everything in the item pickles, so candidates can run as tasks on a Dask cluster
    (:func:`trms.batch.distributed.map_items`); the result equals the in-process batch's.
    """
    xml, values, targets, protocols, counts_per_rev = item
    violation, room = _evaluate(
        [with_parameters(mujoco.MjSpec.from_string(xml), values)], targets, protocols, counts_per_rev
    )
    return float(violation[0]), float(room[0])


def _evaluate_candidates(
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
    from ...batch.distributed import map_items

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
    """Choose ``parameters`` on a grid, then on a finer grid around the best point.

    With ``coarse=False`` only the finer grid runs, around the current values (the calibration's
    later passes, which start from an earlier pass's choice).

    Ties (several candidates meeting every target) go to the candidate with the most room on
    its tightest target, then to the one closest to the current values. With ``cluster``
    (keyword arguments of :func:`trms.batch.distributed.map_items`: ``workers``, ``scheduler``,
    ``processes``, ``progress``) every candidate is a task on a Dask cluster instead.
    """
    grid = {**COUPLING_GRID, **(grid or {})}
    for name in parameters:
        if name not in PARAMETERS or name not in grid:
            raise DesignError(f"no grid for coupling parameter {name!r}; give one in grid=")
    current = read_parameters(spec, parameters)
    scale = {n: (max(abs(v) for v in grid[n]) or 1.0) for n in parameters}
    axes = [sorted(set(grid[n]) | {current[n]}) for n in parameters]
    steps = [np.min(np.diff(a)) if len(a) > 1 else 0.1 for a in axes]
    done = 0
    total = (int(np.prod([len(a) for a in axes])) if coarse else 0) + 3 ** len(parameters)
    best: tuple[tuple[float, float, float], float, dict[str, float]] | None = None
    for stage in range(0 if coarse else 1, 2):
        if stage == 1:
            centre = best[2] if best is not None else current
            axes = [
                sorted({float(np.clip(centre[n] + k * s / 2, *PARAMETERS[n].bounds)) for k in (-1, 0, 1)})
                for n, s in zip(parameters, steps)
            ]
        candidates = [dict(zip(parameters, combo)) for combo in itertools.product(*axes)]
        scores, rooms = _evaluate_candidates(spec, candidates, targets, protocols, counts_per_rev, cluster)
        for cand, score, room in zip(candidates, scores, rooms):
            distance = sum(((cand[n] - current[n]) / scale[n]) ** 2 for n in parameters)
            # Least violation first; among equals, the most room left on the tightest target (what unseen seeds
            # need), then the candidate closest to the current values.
            key = (float(score), -round(float(room), 3), distance)
            if best is None or key < best[0]:
                best = (key, distance, cand)
        done += len(candidates)
        if progress is not None:
            progress(done, total)
    assert best is not None
    return CouplingFit(best[2], best[0][0], done)
