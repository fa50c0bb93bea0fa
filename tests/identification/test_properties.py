"""Property-based round trips: random stable low-order systems through ARX and ARMAX."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal
import scipy.stats
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from trms.identification.linear import armax, arx
from trms.signals import uniform_noise

TS = 0.1
radius = st.floats(0.1, 0.9)
angle = st.floats(0.2, 2.9)


@st.composite
def stable_system(draw):
    """A(q) of order 1 or 2 (real pole or complex pair inside radius 0.9), B of 1 or 2 terms, delay 1-2."""
    if draw(st.booleans()):
        r, th = draw(radius), draw(angle)
        a = np.array([1.0, -2 * r * np.cos(th), r * r])
    else:
        a = np.array([1.0, -draw(st.floats(-0.9, 0.9))])
    nb = draw(st.integers(1, 2))
    b = np.array([draw(st.floats(0.2, 1.0)) * draw(st.sampled_from([-1, 1])) for _ in range(nb)])
    nk = draw(st.integers(1, 2))
    poles = np.roots(a)
    zeros = np.roots(b) if nb > 1 else np.zeros(0)
    # a zero on a pole makes the structure unidentifiable (a common factor)
    assume(all(np.min(np.abs(poles - z)) > 0.1 for z in zeros))
    return a, b, nk


def _input(seed: int) -> np.ndarray:
    return uniform_noise(150.0, TS, 10.0, 1.0, seed=seed)  # white, uniform: 1500 samples


@settings(max_examples=25, deadline=None, derandomize=True)
@given(system=stable_system(), seed=st.integers(0, 10_000))
def test_arx_round_trip_is_exact_without_noise(system, seed):
    a, b, nk = system
    u = _input(seed)
    y = scipy.signal.lfilter(np.r_[np.zeros(nk), b], a, u)
    model = arx(y, u, a.size - 1, b.size, nk, sample_time=TS)
    np.testing.assert_allclose(model.A, a, atol=1e-8)
    np.testing.assert_allclose(model.B[nk:], b, atol=1e-8)
    assert model.nk == nk


@settings(max_examples=15, deadline=None, derandomize=True)
@given(system=stable_system(), c1=st.floats(-0.7, 0.7), seed=st.integers(0, 10_000))
def test_armax_round_trip_within_its_covariance(system, c1, seed):
    # Coloured noise C = 1 + c1 q^-1 at 10 % of the output's standard deviation. The estimate
    # must sit within the 99.99 % chi-square region of its own covariance (a correct estimator
    # fails this once in 10^4 draws).
    a, b, nk = system
    c = np.array([1.0, c1])
    u = _input(seed)
    y0 = scipy.signal.lfilter(np.r_[np.zeros(nk), b], a, u)
    e = np.random.default_rng(seed + 1).standard_normal(u.size) * 0.1 * np.std(y0)
    y = y0 + scipy.signal.lfilter(c, a, e)
    model = armax(y, u, a.size - 1, b.size, 1, nk, sample_time=TS)
    truth = np.r_[a[1:], b, c[1:]]
    d = model.parameters - truth
    assert d @ np.linalg.solve(model.covariance, d) < scipy.stats.chi2.ppf(0.9999, truth.size)
    # the innovations variance: 1500 samples give a relative standard error of sqrt(2/1500) = 3.7 %
    assert model.noise_variance == pytest.approx((0.1 * np.std(y0)) ** 2, rel=0.15)
