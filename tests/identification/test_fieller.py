"""Fieller's region of ``G = N / D`` and its projections on known geometry."""

from __future__ import annotations

import numpy as np

from trms.identification.fieller import fieller, projected_bands


def _circle(g: np.ndarray, sd: np.ndarray) -> np.ndarray:
    """Covariance of ``(N, D) = (g, 1)`` with ``N`` circular (sd per component) and ``D`` exact."""
    cov = np.zeros((g.size, 4, 4))
    cov[:, 0, 0] = cov[:, 1, 1] = sd**2
    return cov


def test_with_an_exact_denominator_the_region_is_a_circle_and_its_shadows_are_known():
    g, sd, c = np.array([2.0 + 1.0j, 0.1 + 0.05j]), np.array([0.1, 0.2]), np.array([4.0, 4.0])
    cov = _circle(g, sd)
    np.testing.assert_allclose(fieller(g, np.ones(2), g + 0.3j, cov), (0.3 / sd) ** 2, rtol=1e-6)
    mag_lo, mag_hi, ph_lo, ph_hi = projected_bands(g, np.ones(2, complex), cov, c)
    half = np.degrees(np.arcsin(0.2 / abs(g[0])))
    np.testing.assert_allclose(
        [mag_lo[0], mag_hi[0], ph_lo[0], ph_hi[0]], [abs(g[0]) - 0.2, abs(g[0]) + 0.2, -half, half], rtol=1e-4
    )
    # the second circle (radius 0.4) holds g = 0: the magnitude band starts at 0 and the phase is free
    assert mag_lo[1] == 0.0 and (ph_lo[1], ph_hi[1]) == (-180.0, 180.0)


def test_a_denominator_not_distinct_from_zero_gives_an_unbounded_region():
    """``D = 1`` with standard deviation 1 per component: ``|D| / sd < sqrt(c)``, so ``|G|`` is unbounded."""
    num, den = np.array([1.0 + 0j]), np.array([1.0 + 0j])
    cov = np.diag([0.01, 0.01, 1.0, 1.0])[None]
    _, mag_hi, ph_lo, ph_hi = projected_bands(num, den, cov, np.array([5.99]))
    assert np.isinf(mag_hi[0]) and (ph_lo[0], ph_hi[0]) == (-180.0, 180.0)
    far = np.array([1e6 + 0j])
    assert fieller(num, den, far, cov)[0] < 5.99
