"""The parametric bootstrap of polynomial fits on known truth: interval widths, regions, seeding, bad input."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal
import scipy.stats

from trms.errors import InputError
from trms.identification import PolynomialModel, armax, arx, n4sid, oe
from trms.identification.bootstrap import bootstrap

TS = 0.1
B = np.array([0.0, 0.4, 0.25])
F = np.array([1.0, -1.3, 0.6])


def _truth(freq: np.ndarray) -> np.ndarray:
    zinv = np.exp(-2j * np.pi * freq * TS)
    return np.polyval(B[::-1], zinv) / np.polyval(F[::-1], zinv)


def _static(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """``y = 0.7 u(t) - 0.3 u(t-1) + e``, a static regression on the input and its last value."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    return 0.7 * u - 0.3 * np.concatenate([[0.0], u[:-1]]) + 0.5 * rng.standard_normal(n), u


@pytest.mark.parametrize("kind", ["studentized", "percentile"])
def test_the_interval_of_a_static_regression_has_the_t_intervals_width(kind):
    y, u = _static(200, 3)
    model = arx(y, u, 0, 2, 0, sample_time=TS)
    boot = bootstrap(model, u, y, n_boot=400, seed=4)
    low, high = boot.intervals(kind=kind)
    t = scipy.stats.t.ppf(0.975, model.n_samples - model.n_parameters)
    np.testing.assert_allclose(high - low, 2 * t * model.std_errors, rtol=0.15)
    np.testing.assert_allclose((low + high) / 2, model.parameters, atol=0.15 * t * model.std_errors.max())
    np.testing.assert_allclose(np.sqrt(np.diag(boot.covariance)), model.std_errors, rtol=0.15)
    narrow, _ = boot.intervals(0.5, kind=kind)
    assert np.all(narrow > low)
    assert boot.covariances.shape == (400, 2, 2)


def test_the_joint_region_covers_the_truth_at_about_its_level():
    """Over 60 seeds of a static regression the 90 % joint region holds the truth 0.8-1.0 of the time
    (a chi-square radius of 1 degree of freedom in place of 2 would hold it about 0.6 of the time)."""
    held = []
    for seed in range(60):
        y, u = _static(120, 100 + seed)
        boot = bootstrap(arx(y, u, 0, 2, 0, sample_time=TS), u, y, n_boot=60, seed=seed)
        held.append(boot.joint_contains([0.7, -0.3], 0.9))
    assert 0.8 <= np.mean(held) <= 1.0
    assert boot.joint_radius(0.9) > scipy.stats.chi2.ppf(0.5, 2)


@pytest.mark.parametrize("kind", ["studentized", "percentile"])
def test_contains_holds_the_true_response_and_rejects_one_far_outside(kind):
    rng = np.random.default_rng(8)
    u = np.sign(rng.standard_normal(400))
    y = scipy.signal.lfilter(B, F, u) + 0.1 * rng.standard_normal(400)
    model = oe(y, u, 2, 2, 1, sample_time=TS)
    boot = bootstrap(model, u, y, n_boot=60, seed=1)
    freq = np.geomspace(0.05, 5.0, 25)
    fr = boot.frequency_response(freq, kind=kind)
    truth = _truth(freq)
    assert fr.method == "bootstrap" and fr.confidence == 0.95
    assert fr.contains(truth, simultaneous=True).all()
    assert fr.contains(truth).mean() >= 0.9
    assert not fr.contains(1.3 * truth).any()
    assert np.all(fr.simultaneous_radius >= fr.region_radius)
    assert np.all(fr.magnitude_low <= fr.magnitude) and np.all(fr.magnitude <= fr.magnitude_high)
    assert np.all(fr.phase_low <= fr.phase) and np.all(fr.phase <= fr.phase_high)
    assert boot.seconds_per_refit > 0 and boot.failed == 0


def test_the_same_seed_gives_the_same_bits_and_gaussian_innovations_work():
    rng = np.random.default_rng(2)
    u = np.sign(rng.standard_normal(300))
    e = 0.1 * rng.standard_normal(300)
    y = scipy.signal.lfilter(B, F, u) + scipy.signal.lfilter([1.0, 0.5], F, e)
    model = armax(y, u, 2, 2, 1, 1, sample_time=TS)
    first = bootstrap(model, u, y, n_boot=12, seed=5)
    again = bootstrap(model, u, y, n_boot=12, seed=5)
    other = bootstrap(model, u, y, n_boot=12, seed=6)
    assert first.samples.tobytes() == again.samples.tobytes()
    assert not np.array_equal(first.samples, other.samples)
    gauss = bootstrap(model, u, y, n_boot=12, seed=5, innovations="gaussian")
    assert gauss.innovations == "gaussian" and gauss.samples.shape == (12, 5)
    np.testing.assert_allclose(gauss.samples.mean(axis=0), model.parameters, atol=4 * model.std_errors.max())


@pytest.mark.parametrize("kind", ["studentized", "percentile"])
def test_the_joint_region_is_an_ellipse_with_a_chi_square_like_radius(kind):
    """On a static regression (normal, linear) the radius is close to the chi-square quantile (2 d.o.f.)."""
    y, u = _static(200, 5)
    model = arx(y, u, 0, 2, 0, sample_time=TS)
    boot = bootstrap(model, u, y, n_boot=400, seed=2)
    assert boot.joint_radius(kind=kind) == pytest.approx(scipy.stats.chi2.ppf(0.95, 2), rel=0.25)
    step = np.sqrt(boot.joint_radius(kind=kind) / boot.distance(model.parameters + model.std_errors, kind=kind))
    inside = model.parameters + 0.99 * step * model.std_errors
    outside = model.parameters + 1.01 * step * model.std_errors
    assert boot.joint_contains(inside, kind=kind) and not boot.joint_contains(outside, kind=kind)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda m, u, y: bootstrap(m, u, y, n_boot=5), r"n_boot = 5 is outside the allowed range \[10"),
        (
            lambda m, u, y: bootstrap(PolynomialModel([1.0, -0.5], [0.0, 1.0], [1.0], TS), u, y),
            r"model.method = 'given': the bootstrap refits models of arx, armax, oe or bj",
        ),
        (lambda m, u, y: bootstrap(n4sid(y, u, 2, sample_time=TS), u, y), r"must be a PolynomialModel.*SubspaceModel"),
        (lambda m, u, y: bootstrap(m, y, u), r"not the data the model was fitted to"),
        (lambda m, u, y: bootstrap(m, u[:-5], y[:-5]), r"have 195 samples; the model was fitted to 200"),
        (lambda m, u, y: bootstrap(m, u, y, seed=-1), r"seed must be a non-negative integer"),
        (lambda m, u, y: bootstrap(m, u, y, innovations="wild"), r"unknown innovations 'wild'"),
        (lambda m, u, y: bootstrap(m, u, y, n_boot=10).intervals(1.0), r"confidence = 1.0 must be below 1"),
        (lambda m, u, y: bootstrap(m, u, y, n_boot=10).intervals(kind="basic"), r"unknown kind 'basic'"),
    ],
)
def test_bad_input_gets_one_clear_line(call, match):
    y, u = _static(200, 1)
    model = arx(y, u, 0, 2, 0, sample_time=TS)
    with pytest.raises(InputError, match=match) as info:
        call(model, u, y)
    assert "\n" not in str(info.value)
