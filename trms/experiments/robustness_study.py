"""The robustness study as files: success rates and metric distributions (JSON), histograms (PNG), worst cases
(Records that ``trms render`` replays), as ``trms robustness`` writes them.

The JSON holds only what the samples determine (no timings, no worker count), so it is the same
bytes for any split of the work (:func:`trms.batch.distributed.map_samples`).
"""

from __future__ import annotations

import json
import math
import re
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from trms.errors import check_in_range
from trms.experiments import robustness as rb
from trms.present.figures import new_axes, save_figure

__all__ = ["summary", "worst_samples", "plot_histograms", "write_study", "run_study"]

#: Histogram bins of each metric.
BINS = 20


def _slug(name: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", name.lower()).strip("_")


def _num(x: float) -> float | None:
    return None if not math.isfinite(x) else float(x)


def _distribution(values: Sequence[float]) -> dict[str, Any]:
    v = np.asarray([x for x in values if math.isfinite(x)], float)
    if v.size == 0:
        return {"count": 0}
    counts, edges = np.histogram(v, bins=BINS)
    q = np.percentile(v, [5, 50, 95])
    return {
        "count": int(v.size),
        "mean": float(v.mean()),
        "min": float(v.min()),
        "p05": float(q[0]),
        "median": float(q[1]),
        "p95": float(q[2]),
        "max": float(v.max()),
        "histogram": {"edges": edges.tolist(), "counts": counts.tolist()},
    }


def worst_samples(samples: Sequence[rb.Sample], k: int) -> list[rb.Sample]:
    """The ``k`` worst samples of a loop: failures first (in sample order), then the slowest to settle
    (a step that never settled counts as slowest), then the largest overshoot."""

    def key(s: rb.Sample) -> tuple:
        settle = s.settling if math.isfinite(s.settling) else math.inf
        over = s.overshoot if math.isfinite(s.overshoot) else math.inf
        return (s.success, -settle, -over, s.index)

    return sorted(samples, key=key)[: int(k)]


def summary(
    batch: Mapping[str, Sequence[rb.Sample]], seed: int, spread: float, backend: str, worst: int = 3
) -> dict[str, Any]:
    """The study as JSON-ready data: per loop the success rate, status counts, the overshoot (%) and 5 %
    settling time (s) distributions over the successful samples, the worst samples; and every sample."""
    loops: dict[str, Any] = {}
    per_sample: dict[str, Any] = {}
    for name, samples in batch.items():
        ok = [s for s in samples if s.success]
        statuses: dict[str, int] = {}
        for s in samples:
            statuses[s.status] = statuses.get(s.status, 0) + 1
        loops[name] = {
            "success_rate": len(ok) / len(samples) if samples else None,
            "status_counts": dict(sorted(statuses.items())),
            "overshoot_percent": _distribution([s.overshoot for s in ok]),
            "settling_time_s": _distribution([s.settling for s in ok]),
            "worst_samples": [s.index for s in worst_samples(samples, worst)],
        }
        per_sample[name] = {
            "status": [s.status for s in samples],
            "overshoot_percent": [_num(s.overshoot) for s in samples],
            "settling_time_s": [_num(s.settling) for s in samples],
        }
    first = next(iter(batch.values()), [])
    return {
        "samples": len(first),
        "seed": int(seed),
        "spread": float(spread),
        "backend": backend,
        "spread_parameters": list(rb.SPREAD_PARAMETERS),
        "success": "settled within the 5 % band at the last step, no stops, no divergence",
        "loops": loops,
        "per_sample": {
            "index": [s.index for s in first],
            "twin_seed": [s.seed for s in first],
            "parameters": {k: [s.parameters[k] for s in first] for k in rb.SPREAD_PARAMETERS},
            **per_sample,
        },
    }


def plot_histograms(name: str, samples: Sequence[rb.Sample], ax: Any = None) -> Figure:
    """Histograms of one loop's overshoot (%) and settling time (s, 5 % band) over its settled samples.

    Parameters
    ----------
    name : str
        The loop (a key of :data:`trms.experiments.robustness.LOOPS`), for the title.
    samples : sequence of Sample
        Its Monte Carlo samples; those that did not settle are counted in the title only.
    ax : pair of matplotlib Axes, optional
        Overshoot and settling axes; by default a new figure on matplotlib's Agg canvas.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_axes(1, 2, (9.0, 3.4), ax=ax)
    ok = [s for s in samples if s.success]
    for panel, (label, values) in zip(
        axes[0],
        [("overshoot (%)", [s.overshoot for s in ok]), ("settling time, 5 % band (s)", [s.settling for s in ok])],
    ):
        v = [x for x in values if math.isfinite(x)]
        panel.hist(v, bins=BINS, color="#4477aa")
        panel.set_xlabel(label)
        panel.set_ylabel("samples")
    fig.suptitle(f"{name}: {len(ok)}/{len(samples)} settled", fontsize=10)
    return fig


def _histograms(batch: Mapping[str, Sequence[rb.Sample]], folder: Path) -> list[Path]:
    return [
        save_figure(plot_histograms(name, samples), folder / f"hist_{_slug(name)}.png")
        for name, samples in batch.items()
    ]


def write_study(
    batch: Mapping[str, Sequence[rb.Sample]],
    out: str | Path,
    seed: int,
    spread: float = rb.SPREAD,
    backend: str = "cpu",
    worst: int = 3,
) -> dict[str, Any]:
    """Write ``robustness.json``, one histogram PNG per loop and the worst cases' Records into ``out``.

    The worst cases are replayed from their (seed, index) on the CPU path (:func:`trms.experiments.robustness.replay`);
    a sample that diverged has no Record. Returns the written paths by kind.
    """
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    data = summary(batch, seed, spread, backend, worst)
    json_path = folder / "robustness.json"
    tmp = json_path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=True, allow_nan=False))
    tmp.replace(json_path)
    records = []
    for name in batch:
        for rank, index in enumerate(data["loops"][name]["worst_samples"], 1):
            rec = rb.replay(name, seed, index, spread)
            if rec is not None:
                path = folder / f"worst_{_slug(name)}_{rank}_sample{index}.npz"
                rec.save(path)
                records.append(path)
    return {"json": json_path, "histograms": _histograms(batch, folder), "records": records, "summary": data}


def run_study(
    n: int,
    seed: int,
    out: str | Path,
    *,
    backend: str = "cpu",
    workers: int | None = None,
    scheduler: str | None = None,
    spread: float = rb.SPREAD,
    worst: int = 3,
    chunk_size: int | None = None,
    progress: bool | None = None,
) -> dict[str, Any]:
    """Run the Monte Carlo study (:func:`~trms.experiments.robustness.monte_carlo`), write it (:func:`write_study`)."""
    check_in_range("n", n, 1, 1e9)
    check_in_range("worst", worst, 0, 1000)
    started = time.perf_counter()
    batch = rb.monte_carlo(
        n,
        seed,
        spread=spread,
        backend=backend,
        workers=workers,
        scheduler=scheduler,
        progress=progress,
        chunk_size=rb.DEFAULT_CHUNK if chunk_size is None else chunk_size,
    )
    seconds = time.perf_counter() - started
    written = write_study(batch, out, seed, spread, backend, worst)
    written["seconds"] = seconds
    return written
