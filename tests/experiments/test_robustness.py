"""The Monte Carlo's arguments are checked before any worker starts."""

import pytest

from trms.errors import InputError
from trms.experiments import robustness


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
    monkeypatch.setattr(robustness, "map_samples", lambda *a, **k: started.append(a) or [])
    with pytest.raises(InputError, match=match):
        robustness.monte_carlo(1, **kwargs)
    assert started == []
    robustness.monte_carlo(1, spread=0.9, seed=0, backend="cpu")  # the ends of the ranges reach the workers
    assert len(started) == 1
