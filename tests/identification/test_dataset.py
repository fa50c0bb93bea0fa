"""Datasets of several experiments, and ARX/ARMAX fitted on them, against known truth."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal

from trms.errors import InputError
from trms.identification import armax, arx, bj, detrend, narx_rbf, oe, select_order
from trms.identification.dataset import Dataset, merge, siso_experiments
from trms.record import Record

TS = 0.1
# The known truth: A y = B u + C e, a 2nd-order plant (poles 0.75 +- 0.37j) with an MA(1) noise.
A = np.array([1.0, -1.5, 0.7])
B = np.array([0.0, 1.0, 0.5])
C = np.array([1.0, 0.5])
ARX_TRUTH = np.array([-1.5, 0.7, 1.0, 0.5])
ARMAX_TRUTH = np.array([-1.5, 0.7, 1.0, 0.5, 0.5])
#: Input levels of the three experiments: each starts from rest and ends far from it, so the
#: junctions of the experiments joined end to end are large transitions the plant never made.
LEVELS = (2.0, -1.5, 1.0)


def _experiments(seed: int, noise: float = 0.0, lengths=(300, 250, 200)) -> tuple[list, list]:
    """Three experiments of the truth, each from rest, with input ``level + random binary``."""
    rng = np.random.default_rng(seed)
    ys, us = [], []
    for n, level in zip(lengths, LEVELS):
        u = level + np.sign(rng.standard_normal(n))
        e = noise * rng.standard_normal(n)
        ys.append(scipy.signal.lfilter(B, A, u) + scipy.signal.lfilter(C, A, e))
        us.append(u)
    return ys, us


def _one_line(exc: pytest.ExceptionInfo) -> str:
    text = str(exc.value)
    assert "\n" not in text and text
    return text


# ------------------------------------------------------------------ known truth


def test_arx_on_noise_free_experiments_from_rest_is_exact_and_joining_them_is_not():
    ys, us = _experiments(0)
    model = arx(Dataset(ys, us, TS), na=2, nb=2, nk=1)
    np.testing.assert_allclose(model.parameters, ARX_TRUTH, atol=1e-10)
    joined = arx(np.concatenate(ys), np.concatenate(us), na=2, nb=2, nk=1, sample_time=TS)
    # the invented transitions at the two junctions bias the joined fit by several hundredths
    assert np.max(np.abs(joined.parameters - ARX_TRUTH)) > 0.03
    assert joined.loss > 1e-3 and model.loss < 1e-20


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_armax_on_noisy_experiments_is_within_three_standard_errors_and_joining_them_is_biased(seed):
    ys, us = _experiments(seed, noise=0.5)
    model = armax(Dataset(ys, us, TS), na=2, nb=2, nc=1, nk=1)
    z = (model.parameters - ARMAX_TRUTH) / np.sqrt(np.diag(model.covariance))
    assert np.all(np.abs(z) < 3.0), z
    assert model.info["experiments"] == 3 and not model.info["on_stability_boundary"]
    joined = armax(np.concatenate(ys), np.concatenate(us), na=2, nb=2, nc=1, nk=1, sample_time=TS)
    z_joined = (joined.parameters - ARMAX_TRUTH) / np.sqrt(np.diag(joined.covariance))
    # the junctions look like huge innovations: C is pulled more than 10 standard errors away
    assert abs(z_joined[-1]) > 10.0, z_joined


def test_n_samples_sums_the_predictions_of_every_experiment():
    ys, us = _experiments(3, noise=0.1)
    data = Dataset(ys, us, TS)
    start = 2  # max(na, nk + nb - 1) for na = nb = 2, nk = 1
    assert arx(data, na=2, nb=2).n_samples == sum(n - start for n in data.n_samples) == 744
    assert armax(data, na=2, nb=2, nc=1).n_samples == 744
    assert arx(data, na=3, nb=2, nk=2).n_samples == sum(n - 3 for n in data.n_samples)
    # one experiment of a Dataset is the same fit as its arrays
    single = arx(data[0], na=2, nb=2)
    np.testing.assert_allclose(single.parameters, arx(ys[0], us[0], 2, 2, 1, sample_time=TS).parameters)
    assert single.n_samples == 298 and "experiments" not in single.info


def test_select_order_on_a_dataset_finds_the_true_order():
    ys, us = _experiments(4, noise=0.1)
    sel = select_order(Dataset(ys, us, TS), na=range(1, 4), nb=2, nc=1, criterion="bic")
    assert (sel.best.na, sel.best.nb, sel.best.nc) == (2, 2, 1)


def test_detrend_removes_each_experiments_own_mean_and_line():
    rng = np.random.default_rng(5)
    ys = [rng.standard_normal(50) + 3.0, rng.standard_normal(40) - 2.0]
    us = [rng.standard_normal(50) - 1.0, rng.standard_normal(40) + 4.0]
    data = Dataset(ys, us, TS)
    out = data.detrend()
    for y, u, yd, ud in zip(ys, us, out.outputs, out.inputs):
        np.testing.assert_allclose(yd[:, 0], y - y.mean(), atol=1e-12)
        np.testing.assert_allclose(ud[:, 0], u - u.mean(), atol=1e-12)
    # detrending the joined record would leave each experiment an offset of about +-2.5
    joined = detrend(np.concatenate(ys))
    assert abs(joined[:50].mean()) > 2.0
    # linear: a line per experiment, removed exactly; the functional form dispatches here
    t = [np.arange(50.0), np.arange(40.0)]
    lines = Dataset([0.3 * t[0] + 1.0, -0.2 * t[1] + 5.0], [2.0 * t[0], 1.0 - t[1]], TS)
    flat = detrend(lines, "linear")
    assert isinstance(flat, Dataset)
    assert max(np.max(np.abs(x)) for x in flat.outputs + flat.inputs) < 1e-12
    assert flat.experiment_names == lines.experiment_names and flat.start_times == lines.start_times


def test_arx_on_experiments_around_different_operating_points_after_detrend():
    """Each experiment's output sits on its own offset: detrending each experiment recovers the truth,
    detrending the joined record (one mean) does not, nor does no detrending."""
    ys, us = _experiments(6, lengths=(3000, 3000, 3000))
    data = Dataset([y + o for y, o in zip(ys, (50.0, -30.0, 100.0))], us, TS)
    # the means removed are not exactly the operating points (the start from rest): a tiny error remains
    model = arx(data.detrend(), na=2, nb=2)
    np.testing.assert_allclose(model.parameters, ARX_TRUTH, atol=1e-4)
    for other in (
        arx(data, na=2, nb=2),
        arx(detrend(np.concatenate(data.outputs)[:, 0]), detrend(np.concatenate(us)), 2, 2, 1, sample_time=TS),
    ):
        assert np.max(np.abs(other.parameters - ARX_TRUTH)) > 0.2


# ------------------------------------------------------------------ the Dataset API


def _three() -> Dataset:
    return Dataset(
        [np.arange(10.0), np.arange(6.0) * 2, np.arange(4.0) * 3],
        [np.ones(10), np.zeros(6), -np.ones(4)],
        0.5,
        experiment_names=["a", "b", "c"],
        start_times=[0.0, 10.0, 20.0],
    )


def test_views_and_selection_by_position_name_slice_and_list():
    data = _three()
    assert data.n_experiments == 3 and data.n_samples == (10, 6, 4)
    assert data.experiment_names == ("a", "b", "c") and data.start_times == (0.0, 10.0, 20.0)
    assert data.input_names == ("u",) and data.output_names == ("y",) and data.sample_time == 0.5
    assert data["b"].n_samples == (6,) and data[1].experiment_names == ("b",)
    assert data[-1].experiment_names == ("c",) and data[np.int64(0)].experiment_names == ("a",)
    assert data[1:].experiment_names == ("b", "c") and data[["c", 0]].experiment_names == ("c", "a")
    np.testing.assert_array_equal(data.time("b"), 10.0 + 0.5 * np.arange(6))
    assert not data.outputs[0].flags.writeable and not data.inputs[0].flags.writeable
    assert data.outputs[1].shape == (6, 1)
    assert repr(data) == "Dataset(3 experiments (a: 10, b: 6, c: 4 samples), Ts=0.5 s, inputs=(u), outputs=(y))"
    assert "experiment b" in data._repr_html_() and "6 samples from 10 s" in data._repr_html_()


@pytest.mark.parametrize(
    "key, match",
    [
        ("z", r"unknown experiment 'z'; this dataset has a, b, c"),
        (3, r"experiment index 3 is outside the allowed range \[-3, 2\]"),
        (-4, r"experiment index -4 is outside the allowed range \[-3, 2\]"),
        (1.0, r"selected by position \(int\) or name \(str\), got 1.0"),
        (True, r"got True"),
        (slice(5, None), r"holds no experiment"),
    ],
)
def test_bad_selections_are_refused(key, match):
    with pytest.raises(InputError, match=match) as exc:
        _three()[key]
    _one_line(exc)


def test_sample_and_time_slices_cut_every_experiment_and_move_the_start_times():
    data = _three()
    cut = data.sample_slice(2, 8)
    assert cut.n_samples == (6, 4, 2) and cut.start_times == (1.0, 11.0, 21.0)
    np.testing.assert_array_equal(cut.outputs[0][:, 0], np.arange(2.0, 8.0))
    # experiments left empty are dropped
    assert data.sample_slice(5).experiment_names == ("a", "b")
    window = data.time_slice(2.0, 12.0)  # a: t = 2 .. 4.5, b: t = 10 .. 11.5
    assert window.experiment_names == ("a", "b") and window.n_samples == (6, 4)
    assert window.start_times == (2.0, 10.0)
    with pytest.raises(InputError, match=r"holds no sample of the dataset"):
        data.time_slice(50.0, 60.0)
    with pytest.raises(InputError, match=r"start < stop"):
        data.time_slice(3.0, 3.0)
    with pytest.raises(InputError, match=r"stop"):
        data.sample_slice(4, 4)


def test_merge_keeps_order_and_names_and_renumbers_unnamed_experiments():
    a = Dataset(np.zeros(5), np.arange(5.0), 0.1)
    b = Dataset([np.ones(3), np.ones(4)], [np.arange(3.0), np.arange(4.0)], 0.1, experiment_names=["x", None])
    merged = merge(a, b)
    assert merged.experiment_names == ("exp1", "x", "exp3") and merged.n_samples == (5, 3, 4)
    assert a.merge(b, a).n_experiments == 4
    with pytest.raises(InputError, match=r"experiment names must be distinct"):
        merge(b, b)


def test_siso_to_record_and_from_records_round_trip():
    data = Dataset(
        [np.column_stack([np.arange(5.0), -np.arange(5.0)])] * 2,
        [np.column_stack([np.ones(5), np.zeros(5)])] * 2,
        0.2,
        input_names=["u1", "u2"],
        output_names=["pitch", "yaw"],
        start_times=[0.0, 3.0],
    )
    pairs = data.siso(input="u1", output="yaw")
    np.testing.assert_array_equal(pairs[1].y, -np.arange(5.0))
    assert (pairs[0].input_name, pairs[0].output_name, pairs[0].sample_time) == ("u1", "yaw", 0.2)
    with pytest.raises(InputError, match=r"name the output"):
        data.siso(input="u1")
    rec = data.to_record(1)
    np.testing.assert_allclose(rec.time, 3.0 + 0.2 * np.arange(5))
    back = Dataset.from_records(data.to_record(0), rec, names=["first", "second"])
    assert back.experiment_names == ("first", "second") and back.start_times == (0.0, 3.0)
    np.testing.assert_array_equal(back.outputs[1], data.outputs[1])
    assert len(siso_experiments(data, input="u2", output="pitch")) == 2


# ------------------------------------------------------------------ refusals


def _record(ts: float, output: str = "pitch") -> Record:
    return detrend(
        Record(np.arange(20) * ts, np.ones((20, 1)) + np.arange(20)[:, None] % 3, np.zeros((20, 1)), ("u1",), (output,))
    )


@pytest.mark.parametrize(
    "call, match",
    [
        (
            lambda: merge(Dataset(np.zeros(5), np.ones(5), 0.1), Dataset(np.zeros(5), np.ones(5), 0.2)),
            r"dataset 2 has sample time 0.2 s, dataset 1 0.1 s",
        ),
        (
            lambda: merge(
                Dataset(np.zeros(5), np.ones(5), 0.1), Dataset(np.zeros(5), np.ones(5), 0.1, output_names="q")
            ),
            r"dataset 2 has channels \('u',\) -> \('q',\)",
        ),
        (lambda: Dataset.from_records(_record(0.1), _record(0.2)), r"record 2 has sample time 0.2 s, record 1 0.1 s"),
        (lambda: Dataset.from_records(_record(0.1), _record(0.1, "yaw")), r"record 2 has channels"),
        (
            lambda: Dataset([np.zeros((5, 1)), np.zeros((5, 2))], [np.ones(5), np.ones(5)], 0.1),
            r"every experiment must have the same number of outputs, got \[1, 2\]",
        ),
        (
            lambda: Dataset([np.zeros(5), np.zeros(4)], [np.ones(5), np.ones(5)], 0.1),
            r"experiment 2: y and u must have the same length, got 4 and 5",
        ),
        (lambda: Dataset([np.zeros(5)], [np.ones(5), np.ones(5)], 0.1), r"y holds 1 experiments and u 2"),
        (lambda: Dataset(np.zeros(5), np.ones(5), 0.0), r"sample_time"),
        (lambda: Dataset(np.zeros(5), np.ones(5), 0.1, experiment_names=["a", "b"]), r"experiment_names must be 1"),
        (lambda: Dataset([np.zeros(5), np.array([1.0, np.nan])], [np.ones(5), np.ones(2)], 0.1), r"y of experiment 2"),
        (lambda: Dataset.from_records(), r"at least one Record"),
        (lambda: merge(), r"at least one Dataset"),
        (lambda: _three().detrend("quadratic"), r"unknown detrend kind 'quadratic'"),
        (
            lambda: Dataset([np.zeros(5), np.zeros(1)], [np.ones(5), np.ones(1)], 0.1).detrend(),
            r"experiment 'exp2' has 1 sample; detrending needs at least 2",
        ),
    ],
)
def test_inconsistent_datasets_are_refused_with_one_line(call, match):
    with pytest.raises(InputError, match=match) as exc:
        call()
    _one_line(exc)


def test_an_experiment_shorter_than_the_orders_start_is_refused():
    ys, us = _experiments(7)
    data = Dataset([ys[0], ys[1][:3]], [us[0], us[1][:3]], TS)
    with pytest.raises(
        InputError,
        match=r"experiment 2 of 2 has 3 samples; orders na=4, nb=2, nk=1 need more than "
        r"start = 4 in every experiment",
    ) as exc:
        arx(data, na=4, nb=2)
    _one_line(exc)
    with pytest.raises(InputError, match=r"experiment 2 of 2 has 3 samples"):
        armax(data, na=4, nb=2, nc=1)
    assert arx(data, na=2, nb=2).n_samples == 298 + 1  # start 2: the short one still gives one prediction


@pytest.mark.parametrize(
    "estimator",
    [
        lambda d: oe(d, nb=2, nf=2),
        lambda d: bj(d, nb=2, nc=1, nd=1, nf=2),
        lambda d: narx_rbf(d, ny=2, nu=2),
    ],
    ids=["oe", "bj", "narx_rbf"],
)
def test_a_dataset_of_several_experiments_is_refused_by_one_experiment_estimators(estimator):
    ys, us = _experiments(8, noise=0.1)
    with pytest.raises(
        InputError,
        match=r"the dataset has 3 experiments \(exp1, exp2, exp3\); this estimator takes "
        r"one: select it",
    ) as exc:
        estimator(Dataset(ys, us, TS))
    _one_line(exc)


def test_a_dataset_of_one_experiment_is_accepted_by_one_experiment_estimators():
    ys, us = _experiments(9, noise=0.1)
    data = Dataset(ys, us, TS)
    one = oe(data["exp1"], nb=2, nf=2)
    np.testing.assert_allclose(one.parameters, oe(ys[0], us[0], 2, 2, sample_time=TS).parameters)
