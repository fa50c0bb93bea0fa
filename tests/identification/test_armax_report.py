"""An ARMAX fit of a Record with its tests, spectra and validation, on a system whose answer is known."""

import json

import numpy as np
import pytest

from trms.errors import InputError
from trms.identification.armax_report import PEAK_BAND, check_same_configuration, identify_armax
from trms.record import OperatingPoint, Record


def _record(seed, n=600):
    """y(k) = 0.8 y(k-1) + 0.5 u(k-1) + e(k): ARMAX(1,1,0,1) with A = 1 - 0.8 q^-1, B = 0.5 q^-1, DC gain 2.5."""
    rng = np.random.default_rng(seed)
    u = rng.choice([-1.0, 1.0], n)
    e = 1e-3 * rng.standard_normal(n)
    y = np.zeros(n)
    for k in range(1, n):
        y[k] = 0.8 * y[k - 1] + 0.5 * u[k - 1] + e[k]
    meta = {"config": "1dof", "operating_point": OperatingPoint.zero(["u1"], ["pitch"]).to_dict()}
    return Record(np.arange(n) * 0.2, u, y, ("u1",), ("pitch",), {}, meta)


def test_the_fit_recovers_the_system_and_its_json_says_so():
    ident = identify_armax(_record(0), (1, 1, 1, 1))
    np.testing.assert_allclose(ident.model.A, [1.0, -0.8], atol=2e-3)
    data = json.loads(json.dumps(ident.to_dict()))  # JSON-ready as it is
    assert data["orders"] == [1, 1, 1, 1] and data["input"] == "u1" and data["output"] == "pitch"
    assert data["dc_gain"] == pytest.approx(2.5, rel=1e-2) and data["sample_time"] == 0.2
    assert set(data["residual_tests"]) == {"ee", "ue"} and "validation_fit_percent" not in data
    assert ident.band == (PEAK_BAND[0], PEAK_BAND[1]) and ident.frequency[-1] == pytest.approx(2.5)


def test_a_validation_on_another_record_of_the_system_fits_nearly_perfectly():
    ident = identify_armax(_record(0), (1, 1, 1, 1)).validated(_record(1))
    assert ident.validation is not None and ident.to_dict()["validation_fit_percent"] > 99.0


def test_a_record_of_another_configuration_is_refused_naming_both():
    other = Record(np.arange(3.0), np.zeros((3, 2)), np.zeros((3, 2)), ("u1", "u2"), ("pitch", "yaw"))
    with pytest.raises(InputError, match=r"'b.npz' is a unknown record with inputs \(u1, u2\).*'a.npz' is a 1dof"):
        check_same_configuration(_record(0), other, "a.npz", "b.npz")


def test_no_input_delay_is_refused_for_a_record():
    """A Record's y_k is measured before u_k is applied: nk = 0 would fit a feedthrough the data cannot hold."""
    with pytest.raises(InputError, match=r"input delay nk = 0 lets y_k depend on u_k, .*; allowed: nk >= 1"):
        identify_armax(_record(0), (4, 4, 4, 0))
