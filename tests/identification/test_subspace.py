"""Subspace identification (n4sid) on a hidden 6th-order two-resonance MIMO system."""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.signal

from trms.errors import InputError
from trms.identification import n4sid, subspace_singular_values
from trms.identification.polynomial import modes_of_poles
from trms.plant import Record

TS = 0.05


def _truth() -> control.StateSpace:
    """TRMS-like: rotor lags (0.8 Hz, 0.5 Hz) drive a pitch (0.45 Hz, zeta 0.06) and a yaw
    (1.3 Hz, zeta 0.1) resonance, cross-coupled; outputs are the two angles."""
    w1, w2, z1, z2 = 2 * np.pi * 0.45, 2 * np.pi * 1.3, 0.06, 0.1
    a1, a2 = 2 * np.pi * 0.8, 2 * np.pi * 0.5
    a = np.array(
        [
            [-a1, 0, 0, 0, 0, 0],
            [0, 0, 1, 0, 0, 0],
            [w1**2, -(w1**2), -2 * z1 * w1, 0.3 * w1**2, 0, 0],
            [0, 0, 0, -a2, 0, 0],
            [0, 0, 0, 0, 0, 1],
            [0.4 * w2**2, 0, 0, w2**2, -(w2**2), -2 * z2 * w2],
        ]
    )
    b = np.zeros((6, 2))
    b[0, 0], b[3, 1] = a1, a2
    c = np.zeros((2, 6))
    c[0, 1] = c[1, 4] = 1.0
    return control.c2d(control.ss(a, b, c, np.zeros((2, 2))), TS)


def _data(n: int, seed: int, noise: float = 0.02) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = np.repeat(np.sign(rng.standard_normal((n // 2 + 1, 2))), 2, axis=0)[:n]  # both inputs at once
    y = control.forced_response(_truth(), U=u.T).outputs.T
    return y + noise * y.std(axis=0) * rng.standard_normal(y.shape), u


def _resonances(sys: control.StateSpace) -> np.ndarray:
    return np.array([m.frequency_hz for m in modes_of_poles(sys.poles(), TS) if m.damping < 0.5])


def test_n4sid_recovers_the_two_resonances_within_one_percent_and_picks_the_order():
    y, u = _data(4000, 1)
    est = n4sid(y, u, sample_time=TS)
    assert isinstance(est, control.StateSpace) and est.nstates == 6
    assert est.ninputs == 2 and est.noutputs == 2 and est.dt == TS
    true_f, est_f = _resonances(_truth()), _resonances(est)
    assert est_f.size == 2
    np.testing.assert_allclose(est_f, true_f, rtol=0.01)
    # out of sample: the model's free run on a fresh input reproduces the truth
    y2, u2 = _data(1000, 2, noise=0.0)
    sim = control.forced_response(est, U=u2.T).outputs.T
    fit = 100 * (1 - np.linalg.norm(y2 - sim, axis=0) / np.linalg.norm(y2 - y2.mean(axis=0), axis=0))
    assert np.all(fit > 90)


def test_the_singular_values_show_the_order_above_the_noise_floor():
    y, u = _data(3000, 3)
    sv = subspace_singular_values(y, u, sample_time=TS)
    assert sv.order == 6
    assert sv.singular_values[5] > 3 * sv.noise_floor > sv.singular_values[6]


def test_siso_exact_data_and_a_given_order():
    rng = np.random.default_rng(0)
    u = np.sign(rng.standard_normal(800))
    y = scipy.signal.lfilter([0.0, 0.5, 0.2], [1.0, -1.5, 0.7], u)
    est = n4sid(y, u, 2, sample_time=0.1)
    np.testing.assert_allclose(np.sort_complex(est.poles()), np.sort_complex(np.roots([1.0, -1.5, 0.7])), atol=1e-8)
    np.testing.assert_allclose(est.dcgain(), 0.7 / 0.2, rtol=1e-8)


def test_a_record_gives_all_its_channels():
    y, u = _data(2000, 4)
    rec = Record(
        time=np.arange(2000) * TS,
        inputs=u,
        outputs=y,
        input_names=("u1", "u2"),
        output_names=("pitch", "yaw"),
        metadata={"sample_time": TS},
    )
    est = n4sid(rec, order=6)
    assert est.ninputs == est.noutputs == 2
    np.testing.assert_allclose(_resonances(est), _resonances(_truth()), rtol=0.01)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda y, u: n4sid(y, u), r"sample_time \(s\) is required"),
        (
            lambda y, u: n4sid(y[:100], u[:100], sample_time=TS),
            r"horizon = 11 samples needs at least 109 samples for 2 inputs and 2 outputs; the data have 100",
        ),
        (lambda y, u: n4sid(y, u, 2.0, sample_time=TS), r"order must be an int, got 2\.0"),
        (
            lambda y, u: n4sid(y, u, 8, sample_time=TS, horizon=3),
            r"horizon = 3 samples with 2 outputs reveals at most order 5",
        ),
        (lambda y, u: n4sid(y, np.column_stack([u[:, 0], np.ones(len(u))]), sample_time=TS), r"input 1 is constant"),
        (lambda y, u: n4sid(y + 1j, u, sample_time=TS), r"must be real"),
        (lambda y, u: n4sid(y[:-1], u, sample_time=TS), r"same N"),
    ],
)
def test_bad_input(call, match):
    y, u = _data(600, 5)
    with pytest.raises(InputError, match=match):
        call(y, u)
