"""One integral LQG design as data: the same gains as the design function, the prefilter of the case."""

import json

import numpy as np
import pytest

from trms.control.lqg import design_lqg
from trms.errors import InputError
from trms.experiments.ch67_lqg import ESTIMATOR_QE, ESTIMATOR_RE
from trms.experiments.lqg_design import integral_design
from trms.worlds import design_model


def test_the_design_is_design_lqg_on_eq_3_11_and_its_json_holds_it():
    found = integral_design("1dof", 1.0, 125.0)
    direct = design_lqg(design_model("1dof"), Q=1.0, R=125.0, Qe=ESTIMATOR_QE, Re=ESTIMATOR_RE)
    np.testing.assert_array_equal(found.design.K, direct.K)
    data = json.loads(json.dumps(found.to_dict()))
    assert data["Q"] == 1.0 and data["R"] == 125.0 and data["prefilter"] is None and data["sample_time"] == 0.2
    np.testing.assert_array_equal(data["K"], direct.K)
    poles = np.array([complex(*p) for p in data["regulator_poles"]])
    np.testing.assert_allclose(np.sort_complex(poles), np.sort_complex(direct.regulator_poles))


def test_a_csas_case_carries_its_prefilter_and_an_unknown_case_is_refused():
    data = integral_design("1dof", 1.0, 75.0, "CSAS LPF 0.2 Hz").to_dict()
    assert data["prefilter"]["name"].startswith("Butterworth LPF order 2") and len(data["prefilter"]["sos"]) == 1
    with pytest.raises(InputError, match="unknown case 'LPF 9 Hz'; allowed: 'SAS'"):
        integral_design("1dof", 1.0, 75.0, "LPF 9 Hz")
