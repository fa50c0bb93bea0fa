"""Order selection on known truth: ARMAX/ARX on eq. (3.11), OE and BJ on 2nd-order plants, n4sid orders."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal

from trms.errors import EstimationError, InputError
from trms.identification.orders import select_n4sid_order, select_order
from trms.signals import random_binary

TS = 0.2


@pytest.mark.parametrize("criterion", ["aic", "bic"])
def test_order_selection_picks_four(criterion, truth):
    y, u = truth.data(1000, 2)
    sel = select_order(y, u, na=range(1, 7), nk=1, criterion=criterion, sample_time=TS)
    assert sel.best.orders[:2] == (4, 4)
    assert len(sel.table) == 6
    scores = {row.na: sel.score(row) for row in sel.table if not row.error}
    assert min(scores, key=scores.get) == 4


def test_order_selection_by_validation_loss_and_arx_delay_grid(truth):
    y, u = truth.data(1000, 2)
    yv, uv = truth.data(750, 3)
    sel = select_order(y, u, na=[2, 4], nc=2, criterion="loss", validation=(yv, uv), sample_time=TS)
    assert sel.best.na == 4 and all(np.isfinite(r.validation_loss) for r in sel.table)
    # over the delay: the true delay is 1 sample; a delay of 2 or 3 drops b1 = 0.0097 (ten of its
    # standard errors) and fits worse
    sel = select_order(y, u, na=4, nc=2, nk=[1, 2, 3], criterion="bic", sample_time=TS)
    assert [r.nk for r in sel.table] == [1, 2, 3] and sel.best.nk == 1
    # ARX over the same grid runs too (nc is ignored)
    assert select_order(y, u, na=4, nk=[1, 2], structure="arx", sample_time=TS).best.nc == 0


def test_order_selection_reports_failed_candidates_and_fails_when_all_do(truth):
    y, u = truth.data(750, 1)
    sel = select_order(y[:60], u[:60], na=[2, 12], nc=1, sample_time=TS)
    assert sel.best.na == 2
    failed = [r for r in sel.table if r.error]
    assert len(failed) == 1 and "need at least" in failed[0].error and np.isnan(failed[0].bic)
    with pytest.raises(EstimationError, match=r"no candidate order could be fitted"):
        select_order(y[:60], u[:60], na=[12, 14], sample_time=TS)


def test_an_unknown_criterion_is_refused(truth):
    y, u = truth.data(750, 1)
    with pytest.raises(InputError, match=r"unknown criterion 'r2'"):
        select_order(y, u, criterion="r2", sample_time=TS)


#: A 2nd-order output-error plant (poles 0.7 +- 0.2j) and a coloured disturbance for BJ.
PLANT_B, PLANT_F = np.array([0.0, 0.4, 0.25]), np.array([1.0, -1.4, 0.53])
NOISE_C, NOISE_D = np.array([1.0, 0.5]), np.array([1.0, -0.9])


def _plant_data(n, seed, coloured):
    u = random_binary(n * 0.1, 0.1, 5.0, 1.0, seed=seed)
    e = 0.05 * np.random.default_rng(seed + 1).standard_normal(n)
    v = scipy.signal.lfilter(NOISE_C, NOISE_D, e) if coloured else e
    return scipy.signal.lfilter(PLANT_B, PLANT_F, u) + v, u


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_oe_order_selection_finds_the_plants_order(seed):
    y, u = _plant_data(800, seed, coloured=False)
    sel = select_order(y, u, na=[1, 2, 3, 4], structure="oe", sample_time=0.1)
    assert sel.best.nf == 2 and sel.best.nb == 2
    assert [(r.nb, r.nf, r.na, r.nc) for r in sel.table] == [(n, n, 0, 0) for n in (1, 2, 3, 4)]
    # the first order underfits by far: its loss is above the truth's noise variance several times over
    assert sel.table[0].loss > 3 * sel.table[1].loss


@pytest.mark.parametrize("seed", [4, 5])
def test_bj_order_selection_finds_the_plant_and_the_noise_orders(seed):
    y, u = _plant_data(1500, seed, coloured=True)
    sel = select_order(y, u, na=[1, 2, 3], nc=[1, 2], nd=1, structure="bj", sample_time=0.1)
    assert (sel.best.nb, sel.best.nf, sel.best.nc, sel.best.nd) == (2, 2, 1, 1)
    assert len(sel.table) == 6 and all(r.nd == 1 for r in sel.table)


def test_oe_and_bj_take_one_experiment_and_a_known_structure():
    from trms.identification import Dataset

    y, u = _plant_data(300, 1, coloured=False)
    both = Dataset([y, y], [u, u], sample_time=0.1)
    with pytest.raises(InputError, match="oe takes one experiment; the data have 2"):
        select_order(both, na=2, structure="oe")
    with pytest.raises(InputError, match="unknown structure 'tf'"):
        select_order(y, u, structure="tf", sample_time=0.1)
    with pytest.raises(InputError, match="na must name at least one order"):
        select_order(y, u, na=[], sample_time=0.1)
    with pytest.raises(InputError, match="na must be an int, got 1.5"):
        select_order(y, u, na=[1.5], sample_time=0.1)
    with pytest.raises(InputError, match="na must be an int or an iterable of ints, got '12'"):
        select_order(y, u, na="12", sample_time=0.1)
    with pytest.raises(InputError, match=r"nk = -1 is outside the allowed range \[0, inf\]"):
        select_order(y, u, nk=-1, sample_time=0.1)
    # every OE order given: na does not enter, so the grid over it fits one model, not three
    assert len(select_order(y, u, na=[1, 2, 3], nb=2, nf=2, structure="oe", sample_time=0.1).table) == 1


def _slow_modes(n, seed):
    """A 2-output system with 0.1 and 0.34 Hz modes at Ts = 0.1 s, driven by two binary inputs, with noise."""
    import control

    modes = [(0.1, 0.08), (0.34, 0.05)]
    blocks = [control.tf([(2 * np.pi * f) ** 2], [1, 2 * z * 2 * np.pi * f, (2 * np.pi * f) ** 2]) for f, z in modes]
    g = control.ss(control.append(*[control.ss(b) for b in blocks]))
    mix = np.array([[1.0, 0.3], [0.2, 1.0]])
    sys = control.c2d(control.ss(g.A, g.B @ mix, g.C, g.D @ mix), 0.1)
    rng = np.random.default_rng(seed)
    u = np.column_stack([random_binary(n * 0.1, 0.1, 2.0, 1.0, seed=seed + k) for k in range(2)])
    resp = control.forced_response(sys, U=u.T)
    y = np.asarray(resp.outputs).T + 0.01 * rng.standard_normal((n, 2))
    return y, u


@pytest.mark.parametrize("criterion", ["aic", "bic"])
def test_n4sid_order_selection_finds_four_states_with_slow_modes(criterion):
    y, u = _slow_modes(2000, 11)
    sel = select_n4sid_order(y, u, orders=range(0, 9), criterion=criterion, sample_time=0.1)
    assert sel.best.nstates == 4
    assert [r.order for r in sel.table] == list(range(9))
    assert sel.table[2].loss > 2 * sel.table[4].loss  # two states miss a mode
    assert not any(r.unstable for r in sel.table[:5])
    assert sel.best.horizon == sel.horizon  # every order at one horizon


def test_n4sid_order_selection_gives_order_zero_on_a_static_gain_and_validates():
    u = np.sign(np.random.default_rng(0).standard_normal(1000))
    y = 2.0 * u + 0.1 * np.random.default_rng(1).standard_normal(1000)
    sel = select_n4sid_order(y, u, orders=range(0, 5), sample_time=0.1)
    assert sel.best.nstates == 0 and sel.table[0].n_parameters == 1
    uv = np.sign(np.random.default_rng(2).standard_normal(500))
    yv = 2.0 * uv + 0.1 * np.random.default_rng(3).standard_normal(500)
    by_val = select_n4sid_order(y, u, orders=[0, 2], criterion="loss", validation=(yv, uv), sample_time=0.1)
    assert by_val.best.nstates == 0 and all(np.isfinite(r.validation_loss) for r in by_val.table)
    assert by_val.table[0].validation_loss == pytest.approx(0.01, rel=0.2)  # the noise variance


def test_n4sid_order_selection_refuses_bad_input():
    u = np.sign(np.random.default_rng(0).standard_normal(400))
    y = 2.0 * u
    with pytest.raises(InputError, match="unknown criterion 'r2'"):
        select_n4sid_order(y, u, criterion="r2", sample_time=0.1)
    with pytest.raises(InputError, match="orders = -1 is outside"):
        select_n4sid_order(y, u, orders=[-1, 2], sample_time=0.1)
    with pytest.raises(InputError, match="the validation data have 2 inputs and 1 outputs"):
        select_n4sid_order(y, u, orders=[1], validation=(y[:200], np.ones((200, 2))), sample_time=0.1)
