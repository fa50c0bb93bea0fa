"""The robustness study: one path (Dask tasks of batched closed loops), JSON identical for any split,
worst cases saved as Records that replay the same sample."""

import json

import numpy as np

from trms.experiments import robustness as rb
from trms.experiments import robustness_study as study
from trms.record import Record


def test_study_json_is_identical_for_one_and_two_workers(tmp_path):
    a = rb.monte_carlo(3, seed=2, workers=1, chunk_size=3, processes=False, progress=False)
    b = rb.monte_carlo(3, seed=2, workers=2, chunk_size=1, processes=False, progress=False)
    ja = json.dumps(study.summary(a, 2, rb.SPREAD, "cpu"), sort_keys=True)
    jb = json.dumps(study.summary(b, 2, rb.SPREAD, "cpu"), sort_keys=True)
    assert ja == jb
    out = study.write_study(a, tmp_path, 2, worst=1)
    data = json.loads(out["json"].read_text())
    assert data["samples"] == 3 and set(data["loops"]) == set(rb.LOOPS)
    assert all(p.stat().st_size > 0 for p in out["histograms"])
    name = next(iter(rb.LOOPS))
    index = data["loops"][name]["worst_samples"][0]
    rec = Record.load(next(p for p in out["records"] if p.name.startswith(f"worst_{study._slug(name)}")))
    assert rec.metadata["sample"] == index and rec.metadata["config"] == rb.LOOPS[name]
    status, over, _ = rb.measure(name, rec)
    sample = a[name][index]
    assert status == sample.status and np.isclose(over, sample.overshoot, rtol=0, atol=0)


def test_samples_differ_and_follow_their_seed():
    p0, s0 = rb.sample_parameters(1, 0)
    p1, s1 = rb.sample_parameters(1, 1)
    assert p0 != p1 and s0 != s1 and (p0, s0) == rb.sample_parameters(1, 0)
