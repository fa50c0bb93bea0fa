"""The LQG loops' robustness Monte Carlo: its table, one path (Dask tasks of batched closed loops) with JSON identical
for any split, worst cases saved as Records that replay the same sample, and its histograms."""

import json
import math

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from trms.errors import InputError
from trms.experiments.ch8 import robustness as rb
from trms.experiments.ch8.robustness import BINS, Sample, plot_histograms
from trms.record import Record


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"spread": -0.2}, r"spread = -0\.2 is outside the allowed range \[0\.0, 0\.9\]"),
        ({"spread": 0.95}, r"spread = 0\.95 is outside"),
        ({"spread": float("nan")}, r"spread = nan is outside"),
        ({"seed": -1}, r"seed must be a non-negative integer, got -1"),
        ({"seed": 1.5}, r"seed must be a non-negative integer, got 1\.5"),
        ({"backend": "gpu"}, r"unknown backend 'gpu'; allowed: 'cpu', 'mjx'"),
    ],
)
def test_bad_arguments_are_refused_before_the_cluster_starts(monkeypatch, kwargs, match):
    started = []
    monkeypatch.setattr(rb, "map_samples", lambda *a, **k: started.append(a) or [])
    with pytest.raises(InputError, match=match):
        rb.monte_carlo(1, **kwargs)
    assert started == []
    rb.monte_carlo(1, spread=0.9, seed=0, backend="cpu")  # the ends of the ranges reach the workers
    assert len(started) == 1


def test_study_json_is_identical_for_one_and_two_workers(tmp_path):
    a = rb.monte_carlo(3, seed=2, workers=1, chunk_size=3, processes=False, progress=False)
    b = rb.monte_carlo(3, seed=2, workers=2, chunk_size=1, processes=False, progress=False)
    ja = json.dumps(rb.summary(a, 2, rb.SPREAD, "cpu"), sort_keys=True)
    jb = json.dumps(rb.summary(b, 2, rb.SPREAD, "cpu"), sort_keys=True)
    assert ja == jb
    out = rb.write_study(a, tmp_path, 2, worst=1)
    data = json.loads(out["json"].read_text())
    assert data["samples"] == 3 and set(data["loops"]) == set(rb.LOOPS)
    assert all(p.stat().st_size > 0 for p in out["histograms"])
    name = next(iter(rb.LOOPS))
    index = data["loops"][name]["worst_samples"][0]
    rec = Record.load(next(p for p in out["records"] if p.name.startswith(f"worst_{rb._slug(name)}")))
    assert rec.metadata["sample"] == index and rec.metadata["config"] == rb.LOOPS[name]
    status, over, _ = rb.measure(name, rec)
    sample = a[name][index]
    assert status == sample.status and np.isclose(over, sample.overshoot, rtol=0, atol=0)


def test_samples_differ_and_follow_their_seed():
    p0, s0 = rb.sample_parameters(1, 0)
    p1, s1 = rb.sample_parameters(1, 1)
    assert p0 != p1 and s0 != s1 and (p0, s0) == rb.sample_parameters(1, 0)


def _samples() -> list[Sample]:
    rng = np.random.default_rng(0)
    ok = [Sample({}, "settled", float(o), float(s)) for o, s in zip(rng.uniform(0, 20, 30), rng.uniform(5, 15, 30))]
    return ok + [Sample({}, "diverged", math.nan, math.nan), Sample({}, "settled", 5.0, math.inf)]


def test_histograms_count_the_settled_samples():
    import matplotlib.pyplot as plt

    before = plt.get_fignums()
    samples = _samples()
    fig = plot_histograms("SAS", samples)
    assert isinstance(fig, Figure) and plt.get_fignums() == before
    overshoot, settling = fig.axes
    assert sum(p.get_height() for p in overshoot.patches) == 31  # every settled sample
    assert sum(p.get_height() for p in settling.patches) == 30  # the infinite settling time is left out
    assert len(overshoot.patches) == BINS
    assert fig._suptitle.get_text() == "SAS: 31/32 settled"


def test_histograms_draw_into_the_callers_axes():
    mine = Figure()
    FigureCanvasAgg(mine)
    axes = mine.subplots(1, 2)
    assert plot_histograms("SAS", _samples(), ax=axes) is mine
    with pytest.raises(InputError, match="this plot draws 2"):
        plot_histograms("SAS", _samples(), ax=axes[:1])
