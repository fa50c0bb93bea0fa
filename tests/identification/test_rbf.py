"""NARX-RBF with OLS centre selection, on a known nonlinear system."""

from __future__ import annotations

import numpy as np
import pytest

from trms.errors import EstimationError, InputError
from trms.identification.linear import arx
from trms.identification.ols import ols_select
from trms.identification.rbf import narx_rbf
from trms.identification.validation import compare
from trms.signals import uniform_noise

TS = 0.2


@pytest.fixture(scope="module")
def nl_data(nonlinear):
    # 300 training samples of uniform noise in a 2 Hz band (the thesis's ch. 5 set-up) and a
    # held-out record from another seed
    u = uniform_noise(60.0, TS, 2.0, 1.0, seed=1)
    uv = uniform_noise(60.0, TS, 2.0, 1.0, seed=2)
    return nonlinear.simulate(u, 10), u, nonlinear.simulate(uv, 11), uv


def test_ols_picks_the_true_columns_in_order_of_their_energy():
    rng = np.random.default_rng(0)
    P = rng.standard_normal((200, 30))
    d = 3.0 * P[:, 4] + 1.0 * P[:, 17] + 0.3 * P[:, 9]
    sel = ols_select(P, d, max_terms=10, tolerance=1e-12)
    assert list(sel.selected[:3]) == [4, 17, 9]
    # exact after three terms: the unexplained fraction is at rounding level and selection stops
    assert sel.selected.size == 3 and sel.unexplained < 1e-12
    # ERR is the orthogonal decomposition of the energy: the first term alone explains
    # (q1 . d)^2 / (d . d), q1 the normalised column
    q1 = P[:, 4] / np.linalg.norm(P[:, 4])
    assert sel.err[0] == pytest.approx((q1 @ d) ** 2 / (d @ d))


def test_ols_respects_max_terms_and_a_forced_first_column():
    rng = np.random.default_rng(1)
    P = rng.standard_normal((100, 20))
    d = rng.standard_normal(100)
    sel = ols_select(P, d, max_terms=5, tolerance=0.0, forced=7)
    assert sel.selected.size == 5 and sel.selected[0] == 7 and len(set(sel.selected)) == 5
    with pytest.raises(EstimationError, match=r"identically zero"):
        ols_select(P, np.zeros(100), 5, 0.0)


def test_normalisation_and_training_error(nl_data):
    y, u, _, _ = nl_data
    model = narx_rbf(y, u, 2, 2, 1, sample_time=TS)
    # eq. (5.10)-(5.12): training mean and N - 1 standard deviation
    assert model.y_mean == pytest.approx(np.mean(y)) and model.y_std == pytest.approx(np.std(y, ddof=1))
    assert model.u_mean == pytest.approx(np.mean(u)) and model.u_std == pytest.approx(np.std(u, ddof=1))
    e = model.residuals(y, u)
    assert np.all(e[:2] == 0)
    assert model.training_sse == pytest.approx(np.sum((e / model.y_std) ** 2), rel=1e-9)
    assert model.n_centres == model.centres.shape[0] == model.weights.size <= 30
    assert model.err.size == model.n_centres + 1  # the bias first
    assert 1 - model.err.sum() == pytest.approx(
        model.training_sse / np.sum(((y[2:] - model.y_mean) / model.y_std) ** 2), abs=1e-3
    )


def test_rbf_beats_arx_in_free_run_on_held_out_data(nl_data):
    # The linear ARX cannot represent u^2 and y u; the RBF network can. Measured on a held-out
    # record in free run (MPO, eq. 5.14): the RBF fit is high and at least 30 points above ARX.
    y, u, yv, uv = nl_data
    rbf = narx_rbf(y, u, 2, 2, 1, sample_time=TS)
    lin = arx(y, u, 2, 2, 1, sample_time=TS)
    fit_rbf, fit_arx = compare(rbf, yv, uv).fit, compare(lin, yv, uv).fit
    assert fit_rbf > 85.0
    assert fit_rbf - fit_arx > 30.0
    # and one step ahead the network is better too
    assert compare(rbf, yv, uv, horizon=1).fit > compare(lin, yv, uv, horizon=1).fit


def test_more_centres_lower_the_training_error(nl_data):
    y, u, _, _ = nl_data
    sse = [narx_rbf(y, u, 2, 2, 1, max_centres=m, tolerance=0.0, sample_time=TS).training_sse for m in (3, 10, 25)]
    assert sse[0] > sse[1] > sse[2]
    loose = narx_rbf(y, u, 2, 2, 1, tolerance=0.05, sample_time=TS)
    assert 1 - loose.err.sum() < 0.05 and loose.n_centres < 25


def test_predictions_long_horizon_is_the_free_run(nl_data):
    y, u, yv, uv = nl_data
    model = narx_rbf(y, u, 2, 3, 1, sample_time=TS)
    assert model.start == 3
    np.testing.assert_allclose(model.predict(yv, uv, horizon=yv.size), model.simulate(uv, yv), atol=1e-10)
    np.testing.assert_array_equal(model.predict(yv, uv)[:3], yv[:3])
    # horizon 1 < horizon 3 < free run in fit on held-out data
    fits = [compare(model, yv, uv, h).fit for h in (1, 3, None)]
    assert fits[0] > fits[1] > fits[2]
    # from rest: the first outputs are zero
    assert np.all(model.simulate(uv)[:3] == 0.0)


def test_same_data_same_model(nl_data):
    y, u, _, _ = nl_data
    a, b = narx_rbf(y, u, 2, 2, 1, sample_time=TS), narx_rbf(y, u, 2, 2, 1, sample_time=TS)
    assert a.centres.tobytes() == b.centres.tobytes() and a.weights.tobytes() == b.weights.tobytes()


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(u=np.ones(300)), r"input u is constant: it cannot be normalised"),
        (dict(ny=0), r"ny = 0 is outside the allowed range \[1, inf\]"),
        (dict(ny=2.0), r"ny must be an int"),
        (dict(width=-1.0), r"width = -1\.0 is outside"),
        (dict(tolerance=2.0), r"tolerance = 2\.0 is outside"),
        (
            dict(y=np.zeros(20), u=np.arange(20.0)),
            r"ny=4, nu=4, nk=1 leave 16 training targets from 20 samples; at least 18",
        ),
        (dict(y=np.r_[np.zeros(299), np.nan]), r"y must be finite"),
    ],
)
def test_bad_input(nl_data, kwargs, match):
    y, u, _, _ = nl_data
    args = dict(y=y, u=u, ny=2, nu=2)
    args.update(kwargs)
    yy, uu = args.pop("y"), args.pop("u")
    if "leave" in match:
        args.update(ny=4, nu=4)
    with pytest.raises(InputError, match=match):
        narx_rbf(yy, uu, sample_time=TS, **args)


# ---------------------------------------------------------------- candidates, width, range
def test_candidates_are_capped_and_all_training_vectors_below_the_cap(nl_data):
    y, u, yv, uv = nl_data
    full = narx_rbf(y, u, 2, 2, 1, sample_time=TS, max_candidates=None)
    capped_above = narx_rbf(y, u, 2, 2, 1, sample_time=TS, max_candidates=10_000)
    np.testing.assert_array_equal(full.centres, capped_above.centres)  # below the cap: the textbook algorithm
    assert full.width == capped_above.width
    few = narx_rbf(y, u, 2, 2, 1, sample_time=TS, max_candidates=120)
    # the centres are training vectors among the 120 evenly spaced candidates
    x = np.column_stack(
        [np.r_[np.nan, y[:-1]], np.r_[np.nan, np.nan, y[:-2]], np.r_[np.nan, u[:-1]], np.r_[np.nan, np.nan, u[:-2]]]
    )[2:]
    xn = (x - [few.y_mean, few.y_mean, few.u_mean, few.u_mean]) / [few.y_std, few.y_std, few.u_std, few.u_std]
    cand = np.unique(np.round(np.linspace(0, xn.shape[0] - 1, 120)).astype(int))
    for c in few.centres:
        assert np.min(np.abs(xn[cand] - c).sum(axis=1)) < 1e-9
    # fewer candidates, still a useful model on held-out data
    assert compare(few, yv, uv).fit > compare(full, yv, uv).fit - 5.0
    with pytest.raises(InputError, match=r"max_candidates = 5 is outside the allowed range \[30, inf\]"):
        narx_rbf(y, u, 2, 2, 1, sample_time=TS, max_candidates=5)


def test_a_degenerate_width_warns(nl_data):
    from trms.identification.rbf import DegenerateWidthWarning

    y, u, yv, uv = nl_data
    with pytest.warns(DegenerateWidthWarning, match=r"width = 1e-06 .* indicator of its own sample"):
        tiny = narx_rbf(y, u, 2, 2, 1, sample_time=TS, width=1e-6, max_centres=5)
    assert compare(tiny, yv, uv, horizon=1).fit < 10.0  # useless out of sample, as warned
    with pytest.warns(DegenerateWidthWarning, match=r"nearly constant"):
        with pytest.raises(EstimationError, match=r"OLS selected no centre"):
            narx_rbf(y, u, 2, 2, 1, sample_time=TS, width=1e4, max_centres=5)


def test_the_default_width_is_not_degenerate(nl_data):
    import warnings

    y, u, yv, uv = nl_data
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = narx_rbf(y, u, 2, 2, 1, sample_time=TS)
    assert 0.1 < model.width < 10.0


def test_extrapolation_is_measured_and_warned(nl_data):
    from trms.identification.rbf import ExtrapolationWarning

    y, u, yv, uv = nl_data
    model = narx_rbf(y, u, 2, 2, 1, sample_time=TS)
    assert model.u_range == (u.min(), u.max()) and model.y_range == (y.min(), y.max())
    inside = model.extrapolation(y, u)
    assert inside.fraction == 0.0 and inside.worst == 0.0
    far = model.extrapolation(None, 3.0 * u)
    assert far.fraction > 0.3 and far.worst > 1.0
    with pytest.warns(ExtrapolationWarning, match=r"% of the samples lie outside the training range"):
        model.simulate(3.0 * u)
    with pytest.warns(ExtrapolationWarning):
        model.predict(y, 3.0 * u)


# ---------------------------------------------------------------- streamed OLS against the full candidate matrix
def reference_narx_rbf(y, u, ny, nu, nk, max_centres, tolerance, max_candidates=None, width=None):
    """The textbook algorithm on the whole candidate matrix in memory (small N only): normalise, every (or every
    evenly spaced) training vector a candidate, width the median distance to the other vectors, bias first, then
    modified Gram-Schmidt over all the columns at once, largest error-reduction ratio first."""
    yn, un = (y - y.mean()) / y.std(ddof=1), (u - u.mean()) / u.std(ddof=1)
    start, n = max(ny, nk + nu - 1), y.size
    x = np.column_stack(
        [yn[start - i : n - i] for i in range(1, ny + 1)] + [un[start - i : n - i] for i in range(nk, nk + nu)]
    )
    d = yn[start:]
    cand = np.arange(len(x))
    if max_candidates is not None and max_candidates < len(x):
        cand = np.unique(np.round(np.linspace(0, len(x) - 1, max_candidates)).astype(int))
    dist2 = ((x[:, None, :] - x[None, cand, :]) ** 2).sum(axis=2)
    own = np.zeros(dist2.shape, bool)
    own[cand, np.arange(cand.size)] = True
    sigma = np.sqrt(np.median(dist2[~own])) if width is None else width
    P = np.hstack([np.ones((len(x), 1)), np.exp(-dist2 / sigma**2)])
    W, norms0, dd = P.copy(), (P**2).sum(axis=0), d @ d
    alive, chosen, err = norms0 > 0, [], []
    for k in range(max_centres + 1):
        norms = (W**2).sum(axis=0)
        ratios = np.where(alive & (norms > 1e-10 * norms0), (W.T @ d) ** 2 / norms / dd, -1.0)
        j = 0 if k == 0 else int(np.argmax(ratios))
        if k and ratios[j] <= 0:
            break
        chosen.append(j)
        err.append((W[:, j] @ d) ** 2 / (norms[j] * dd))
        alive[j] = False
        q = W[:, j] / np.sqrt(norms[j])
        W -= np.outer(q, q @ W)
        if 1 - sum(err) < tolerance:
            break
    theta = np.linalg.lstsq(P[:, chosen], d, rcond=None)[0]
    return sigma, x[cand[np.array(chosen[1:]) - 1]], theta, np.array(err)


def random_case(seed, n):
    """A seeded nonlinear NARX system (square-law input, bilinear term) with 2 % output noise."""
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1.0, 1.0, n)
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = 0.6 * y[t - 1] - 0.1 * y[t - 2] + 0.4 * u[t - 1] + 0.3 * u[t - 1] ** 2 - 0.2 * y[t - 1] * u[t - 2]
    return y + 0.02 * np.std(y) * rng.standard_normal(n), u


# memory settings: the defaults (all in memory at these sizes), a few columns kept and the rest recomputed
# at every pass, and nothing kept (every column recomputed, a handful at a time)
MEMORY = {"default": None, "part kept": (2**14, 2**12), "nothing kept": (0, 2**12)}


@pytest.mark.parametrize("memory", MEMORY)
@pytest.mark.parametrize(
    "case",
    [
        ("nl_data", 2, 2, 1, dict(max_centres=30, tolerance=1e-3)),
        ("nl_data", 2, 3, 1, dict(max_centres=12, tolerance=0.0, max_candidates=120)),
        (0, 3, 3, 1, dict(max_centres=20, tolerance=1e-6)),
        (1, 2, 4, 2, dict(max_centres=15, tolerance=1e-4, max_candidates=150)),
        (2, 4, 2, 0, dict(max_centres=25, tolerance=1e-5, width=1.5)),
    ],
    ids=["nl 2,2,1", "nl capped", "seed 0", "seed 1 capped", "seed 2 width"],
)
def test_the_streamed_ols_equals_the_full_matrix_algorithm(nl_data, monkeypatch, memory, case):
    from trms.identification import ols, rbf

    data, ny, nu, nk, kw = case
    y, u = (nl_data[0], nl_data[1]) if data == "nl_data" else random_case(data, 240 + 60 * data)
    widest = []
    if MEMORY[memory] is not None:
        for module in (rbf, ols):
            monkeypatch.setattr(module, "OLS_CACHE", MEMORY[memory][0])
            monkeypatch.setattr(module, "OLS_BLOCK", MEMORY[memory][1])
        made = rbf._RbfColumns.__call__
        monkeypatch.setattr(rbf._RbfColumns, "__call__", lambda s, j0, j1: widest.append(j1 - j0) or made(s, j0, j1))
    model = narx_rbf(y, u, ny, nu, nk, sample_time=TS, **kw)
    sigma, centres, theta, err = reference_narx_rbf(y, u, ny, nu, nk, **kw)
    assert model.width == pytest.approx(sigma, rel=1e-12)
    assert model.n_centres == centres.shape[0] >= 5
    np.testing.assert_allclose(model.centres, centres, rtol=0, atol=1e-14)  # the same vectors in the same order
    np.testing.assert_allclose(np.r_[model.bias, model.weights], theta, rtol=1e-10, atol=1e-10 * np.abs(theta).max())
    np.testing.assert_allclose(model.err, err, rtol=1e-10, atol=1e-14)
    if widest:  # the candidate matrix was made a few columns at a time (the bias column aside), pass after pass
        n_x = y.size - model.start
        assert max(widest) <= max(1, MEMORY[memory][1] // n_x) + 1
        assert sum(widest) > 2 * min(kw.get("max_candidates") or n_x, n_x)


def test_streamed_training_holds_a_fraction_of_the_candidate_matrix(monkeypatch):
    import tracemalloc

    from trms.identification import ols, rbf

    for module in (rbf, ols):
        monkeypatch.setattr(module, "OLS_CACHE", 2**15)
        monkeypatch.setattr(module, "OLS_BLOCK", 2**14)
    y, u = random_case(3, 2002)
    tracemalloc.start()
    model = narx_rbf(y, u, 2, 2, 1, sample_time=TS, max_centres=13, tolerance=0.0, max_candidates=500)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    full = 2000 * 501 * 8  # bytes of the candidate matrix, bias column included
    assert model.n_centres == 13
    assert peak < full / 4  # a fraction of the one matrix
