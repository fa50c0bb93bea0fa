"""Exact order statistics of a stream from a bounded sample, against a full sort."""

import numpy as np
import pytest

from trms.identification.order_statistics import order_statistics


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("ties", [False, True])
def test_order_statistics_are_exact_with_a_bounded_sample(seed, ties):
    rng = np.random.default_rng(seed)
    values = rng.integers(0, 40, 4000).astype(float) if ties else rng.lognormal(0.0, 2.0, 4000)
    blocks = values.reshape(40, 100)
    truth = np.sort(values)
    for guide in (np.zeros(0), values[::97], np.full(5, truth[-1])):
        for ranks in ([0], [1999, 2000], [2345], [3998, 3999]):
            got = order_statistics(lambda: iter(blocks), values.size, ranks, guide, keep=64)
            assert got == [truth[r] for r in ranks]
