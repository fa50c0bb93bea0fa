"""One model of every input and output of a Record: known truth recovered by each estimator, refusals in one line."""

import json
import warnings

import numpy as np
import pytest

from trms.errors import InputError
from trms.identification.mimo_report import MIMO_METHODS, identify_all_channels
from trms.record import OperatingPoint, Record


def _record(seed, n=800, noise=0.0):
    """y1 = 0.8 y1 + 0.5 u1; y2 = 0.6 y2 + 0.3 u1 + 0.4 u2 (the first input drives both outputs, as on the rig)."""
    rng = np.random.default_rng(seed)
    u = np.repeat(rng.choice([-1.0, 1.0], (n // 4, 2)), 4, axis=0)
    y = np.zeros((n, 2))
    for k in range(1, n):
        y[k] = [0.8 * y[k - 1, 0] + 0.5 * u[k - 1, 0], 0.6 * y[k - 1, 1] + 0.3 * u[k - 1, 0] + 0.4 * u[k - 1, 1]]
    y += noise * rng.standard_normal(y.shape)
    op = OperatingPoint(np.array([0.5, 0.1]), np.array([-0.2, 0.0]), ("u1", "u2"), ("pitch", "yaw"))
    meta = {"config": "2dof", "operating_point": op.to_dict()}
    return Record(np.arange(n) * 0.1, u + op.inputs, y + op.outputs, ("u1", "u2"), ("pitch", "yaw"), {}, meta)


@pytest.mark.parametrize(
    "method, orders, states",
    [
        ("arx-mimo", (1, 1, 0, 1), None),
        ("armax-mimo", (1, 1, 1, 1), None),
        ("n4sid", (2, 2, 1, 1), 2),
        ("ssest", (2, 2, 1, 1), 2),
    ],
)
def test_every_estimator_gives_the_two_input_truth_back_on_an_unseen_record(method, orders, states):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an estimator's own notes are not what is tested here
        fit = identify_all_channels(_record(0, noise=1e-3), method, orders, states).validated(_record(1))
    assert fit.validation_fit.min() > 99.0 and fit.estimation_fit.min() > 99.0
    poles = np.sort(np.abs(fit.state_space.poles()))
    assert np.isclose(poles[-2:], [0.6, 0.8], atol=0.02).all()  # the truth's two modes, among any extra states
    data = json.loads(json.dumps(fit.to_dict()))  # JSON-ready as it is
    assert data["method"] == method and data["inputs"] == ["u1", "u2"] and data["outputs"] == ["pitch", "yaw"]
    assert set(data["validation_fit_percent"]) == {"pitch", "yaw"}
    assert {"pitch: ee", "pitch: ue:u1", "pitch: ue:u2", "yaw: ee"} <= set(data["residual_tests"])


def test_a_one_input_model_of_a_two_input_record_misses_what_the_mimo_one_sees():
    """The second output's single-input ARMAX (u2 alone) takes u1's part as noise; the MIMO model does not."""
    from trms.identification.armax_report import identify_armax

    a, b = _record(2, noise=1e-3), _record(3)
    siso = identify_armax(a, (1, 1, 1, 1), "u2", "yaw").validated(b)
    mimo = identify_all_channels(a, "arx-mimo", (1, 1, 0, 1)).validated(b)
    assert siso.validation.fit < 80.0 < 99.0 < mimo.validation_fit[1]


@pytest.mark.parametrize(
    "change, kwargs, match",
    [
        (None, {"method": "arx"}, r"unknown method 'arx'; allowed: 'arx-mimo', 'armax-mimo', 'n4sid', 'ssest'"),
        (None, {"method": "arx-mimo", "orders": (1, 1, 0, 0)}, r"nk = 0 lets y_k depend on u_k"),
        (None, {"method": "armax-mimo", "states": 3}, r"states = 3 sets n4sid's and ssest's order"),
        ("no operating point", {"method": "n4sid"}, r"the record has no operating point"),
    ],
)
def test_bad_settings_are_refused_in_one_line(change, kwargs, match):
    rec = _record(0)
    if change:
        del rec.metadata["operating_point"]
    with pytest.raises(InputError, match=match):
        identify_all_channels(rec, **kwargs)
    assert set(MIMO_METHODS) == {"arx-mimo", "armax-mimo", "n4sid", "ssest"}
