"""Continuous-time tfest and procest on known continuous systems sampled with a zero-order hold."""

from __future__ import annotations

from functools import cache

import control
import numpy as np
import pytest

from trms.errors import InputError
from trms.identification import ContinuousModel, procest, tfest
from trms.identification.data import detrend
from trms.record import Record

TS = 0.1
#: The truth: K wn^2 / (s^2 + 2 zeta wn s + wn^2) e^(-0.3 s), wn = 2 rad/s, zeta = 0.1 (lightly damped).
WN, ZETA, GAIN, DELAY = 2.0, 0.1, 1.5, 0.3


def _sampled(g: control.TransferFunction, u: np.ndarray, delay_samples: int) -> np.ndarray:
    """Exact sampled response of ``g`` to the held ``u``, delayed by whole samples (python-control's ZOH)."""
    shifted = np.concatenate([np.zeros(delay_samples), u[: u.size - delay_samples]])
    return control.forced_response(control.c2d(g, TS), U=shifted).outputs


@cache
def _data(seed: int, n: int = 1000) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = np.repeat(np.sign(rng.standard_normal(n // 4 + 1)), 4)[:n]
    y = _sampled(control.tf([GAIN * WN**2], [1.0, 2 * ZETA * WN, WN**2]), u, 3)
    return y + 0.05 * y.std() * rng.standard_normal(n), u


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_tfest_and_procest_recover_frequency_damping_and_delay(seed):
    y, u = _data(seed)
    model = tfest(y, u, 2, 0, sample_time=TS)
    assert isinstance(model, ContinuousModel) and model.method == "tfest"
    (mode,) = model.modes()
    # stated tolerances: natural frequency 1 %, damping +-0.01, delay +-0.01 s (a tenth of a sample)
    assert 2 * np.pi * mode.frequency_hz == pytest.approx(WN, rel=0.01)
    assert mode.damping == pytest.approx(ZETA, abs=0.01)
    assert model.delay == pytest.approx(DELAY, abs=0.01)
    assert model.dc_gain() == pytest.approx(GAIN, rel=0.01)
    proc = procest(y, u, "P2DU", sample_time=TS)
    p, se = proc.parameters, proc.std_errors
    assert list(p) == ["K", "Tw", "Zeta", "Td"]
    assert 1 / p["Tw"] == pytest.approx(WN, rel=0.01)
    assert p["Zeta"] == pytest.approx(ZETA, abs=0.01)
    assert p["Td"] == pytest.approx(DELAY, abs=0.01)
    assert p["K"] == pytest.approx(GAIN, rel=0.01)
    # the same model class: the process fit is the transfer-function optimum; errors within 4 standard errors
    assert proc.loss == pytest.approx(model.loss, rel=1e-6)
    for name, truth in (("K", GAIN), ("Tw", 1 / WN), ("Zeta", ZETA), ("Td", DELAY)):
        assert abs(p[name] - truth) < 4 * se[name], name
    # the model simulates the noise-free truth
    clean = _sampled(control.tf([GAIN * WN**2], [1.0, 2 * ZETA * WN, WN**2]), u, 3)
    assert np.sqrt(np.mean((proc.simulate(u) - clean) ** 2)) < 0.02 * clean.std()


def test_a_fractional_delay_a_fixed_delay_and_an_integrator():
    rng = np.random.default_rng(5)
    u = np.repeat(np.sign(rng.standard_normal(200)), 3)
    # 0.25 s = 2.5 samples: the fine-step response of 2 / (1 + 0.8 s), held input, sampled every 5th step
    fine = control.c2d(control.tf([2.0], [0.8, 1.0]), TS / 10)
    y = control.forced_response(fine, U=np.concatenate([np.zeros(25), np.repeat(u, 10)[:-25]])).outputs[::10]
    p1d = procest(y, u, "P1D", sample_time=TS)
    assert p1d.parameters == pytest.approx({"K": 2.0, "Tp1": 0.8, "Td": 0.25}, rel=1e-6)
    fixed = tfest(y, u, 1, sample_time=TS, delay=0.2)
    assert fixed.delay == 0.2 and fixed.std_errors["tau"] == 0.0 and fixed.loss > 1e-6
    # an integrator with a lag: 0.5 / (s (1 + 0.5 s)), delay 0.2 s
    ui = u - u.mean()
    yi = _sampled(control.tf([0.5], [0.5, 1.0, 0.0]), ui, 2)
    pi = procest(yi, ui, "P1DI", sample_time=TS)
    assert pi.parameters == pytest.approx({"K": 0.5, "Tp1": 0.5, "Td": 0.2}, rel=1e-5)
    assert pi.dc_gain() == np.inf


def test_a_record_gives_the_arrays_model():
    y, u = _data(0)
    rec = detrend(Record(np.arange(y.size) * TS, u[:, None], y[:, None], ("u1",), ("pitch",)))
    from_record = tfest(rec, np=2, nz=0)
    assert from_record.output_name == "pitch" and from_record.delay == pytest.approx(DELAY, abs=0.01)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda y, u: tfest(y, u, 0, sample_time=TS), r"np = 0 is outside the allowed range \[1"),
        (lambda y, u: tfest(y, u, 2, 2, sample_time=TS), r"nz = 2 is outside the allowed range \[0.*, 1"),
        (lambda y, u: tfest(y, u, 2, -1, sample_time=TS), r"nz = -1 is outside the allowed range \[0"),
        (lambda y, u: tfest(y, u, 2, sample_time=TS, delay=60.0), r"delay = 60.0 s is outside .* 50.0 s\]"),
        (lambda y, u: tfest(y, u, 2, sample_time=TS, max_delay=-1.0), r"max_delay = -1.0 s is outside"),
        (lambda y, u: procest(y, u, "P4D", sample_time=TS), r"kind = 'P4D' is not a process model"),
        (lambda y, u: procest(y, u, "P1U", sample_time=TS), r"kind = 'P1U' is not a process model"),
        (
            lambda y, u: procest(y[:20], u[:20], "P2DU", sample_time=TS),
            r"P2DU \(4 parameters, .*\) need at least 48 samples",
        ),
    ],
)
def test_bad_input_is_refused_with_one_line(call, match):
    y, u = _data(0)
    with pytest.raises(InputError, match=match):
        call(y, u)
