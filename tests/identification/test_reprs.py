"""Fitted models show compactly: a one-line repr of orders, sample time and fit figures, and an HTML table."""

import control
import numpy as np
import pytest
import scipy.signal

from trms.identification import SubspaceModel, armax, arx, bj, fit_percent, n4sid, narx_rbf, oe

TS = 0.1


@pytest.fixture(scope="module")
def data():
    rng = np.random.default_rng(3)
    u = np.sign(rng.standard_normal(600))
    y = scipy.signal.lfilter([0, 0.5, 0.3], [1, -1.2, 0.6], u) + 0.02 * rng.standard_normal(600)
    return y, u


def _compact(model, name):
    text, table = repr(model), model._repr_html_()
    assert text.startswith(f"{name}(") and "\n" not in text and "array(" not in text and len(text) < 200, text
    assert table.startswith("<table><caption>") and table.endswith("</table>")
    assert "array(" not in table and "[[" not in table
    return text, table


@pytest.mark.parametrize(
    "fit, method, orders",
    [
        (lambda y, u: arx(y, u, 2, 2, 1, sample_time=TS), "arx", "na=2 nb=2 nk=1"),
        (lambda y, u: armax(y, u, 2, 2, 1, 1, sample_time=TS), "armax-pem", "na=2 nb=2 nc=1 nk=1"),
        (lambda y, u: oe(y, u, 2, 2, 1, sample_time=TS), "oe-pem", "nb=2 nf=2 nk=1"),
        (lambda y, u: bj(y, u, 2, 1, 1, 2, 1, sample_time=TS), "bj-pem", "nb=2 nc=1 nd=1 nf=2 nk=1"),
    ],
    ids=["arx", "armax", "oe", "bj"],
)
def test_polynomial_models_show_orders_sample_time_and_variance(data, fit, method, orders):
    model = fit(*data)
    text, table = _compact(model, "PolynomialModel")
    assert f"{method}, u -> y, {orders}, Ts=0.1 s, N={model.n_samples}" in text
    assert f"noise variance {model.noise_variance:.3g}" in text and f"FPE {model.fpe:.3g}" in text
    assert f"<td>{orders}</td>" in table and f"<td>{model.dc_gain():.4g}</td>" in table
    # The plant's lightly damped pair is listed with its frequency and damping (the model's own modes).
    pair = min(model.modes(), key=lambda m: m.damping)
    assert f"{pair.frequency_hz:.3f} Hz, damping {pair.damping:.3f}" in table


def test_narx_rbf_shows_lags_centres_and_training_error(data):
    model = narx_rbf(*data, 2, 2, 1, sample_time=TS)
    text, table = _compact(model, "NarxRbf")
    assert f"ny=2 nu=2 nk=1, {model.n_centres} centres" in text and "Ts=0.1 s" in text
    assert model.training_mse == pytest.approx(model.training_sse / model.n_samples)
    assert f"training MSE {model.training_mse:.3g}" in text
    assert f"<td>{model.n_centres}</td>" in table


def test_n4sid_returns_a_state_space_with_a_compact_summary(data):
    y, u = data
    model = n4sid(y, u, sample_time=TS)
    assert isinstance(model, SubspaceModel) and model.nstates == 2 and model.n_samples == y.size
    # The estimation fit is the model simulated from its initial state, measured independently here.
    sim = control.forced_response(model, U=u, X0=_initial_state(model, y, u)).outputs
    assert model.fit[0] == pytest.approx(fit_percent(y, sim), abs=0.05)
    assert model.fit[0] > 95.0
    text, table = _compact(model, "SubspaceModel")
    assert f"order 2, 1 in, 1 out, Ts=0.1 s, horizon {model.horizon}, N={y.size}" in text
    assert f"{model.fit[0]:.1f}" in text and "<td>2</td>" in table


def _initial_state(model, y, u):
    """Least-squares initial state given the model: y - (zero-state response) = O x0."""
    forced = control.forced_response(model, U=u).outputs
    A, C = np.asarray(model.A), np.asarray(model.C)
    obs = np.vstack([C @ np.linalg.matrix_power(A, k) for k in range(y.size)])
    return np.linalg.lstsq(obs, y - forced, rcond=None)[0]
