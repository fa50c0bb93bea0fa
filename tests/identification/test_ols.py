"""Orthogonal least squares on a candidate matrix given block by block, against the dense matrix."""

import numpy as np
import pytest

from trms.errors import EstimationError
from trms.identification import ols
from trms.identification.ols import ols_select


@pytest.mark.parametrize("cache, block", [(2**21, 2**17), (300, 200), (0, 100)])
def test_streamed_columns_select_what_the_dense_matrix_selects(monkeypatch, cache, block):
    # Known truth: the target is an exact combination of three columns, one of them forced first.
    P = np.random.default_rng(4).standard_normal((100, 40))
    d = 3.0 * P[:, 7] - 2.0 * P[:, 21] + 0.5 * P[:, 0]
    dense = ols_select(P, d, max_terms=5, tolerance=1e-12, forced=0)
    monkeypatch.setattr(ols, "OLS_CACHE", cache)
    monkeypatch.setattr(ols, "OLS_BLOCK", block)
    made = []
    streamed = ols.ols_blocks(lambda j0, j1: made.append(j1 - j0) or P[:, j0:j1], 40, d, 5, 1e-12, 0)
    assert dense.selected.tolist() == streamed.selected.tolist() == [0, 7, 21]
    np.testing.assert_allclose(streamed.err, dense.err, rtol=1e-12)
    assert streamed.unexplained < 1e-12
    assert max(made) <= max(1, block // 100, min(40, cache // 100))


def test_an_identically_zero_target_is_refused():
    with pytest.raises(EstimationError, match="identically zero"):
        ols.ols_blocks(lambda j0, j1: np.ones((5, j1 - j0)), 3, np.zeros(5), 2, 0.0, None)
