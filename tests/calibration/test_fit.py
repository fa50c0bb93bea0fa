"""The linear stage of the calibration."""

import pytest

from trms.calibration import Targets
from trms.calibration.fit import DEFAULT_FIT, fit_linear
from trms.twin import load_spec
from trms.twin.parameters import model_key, read_parameters, with_parameters


def test_the_linear_fit_keeps_a_start_that_is_already_its_optimum():
    # The shipped model is the linear fit's optimum to the digits its file holds: the fit returns it unchanged (the
    # same model, hence the same verification's key), where the optimiser alone would move it by ~1e-5.
    shipped = load_spec()
    fit = fit_linear(shipped, Targets.thesis())
    assert fit.values == read_parameters(shipped, DEFAULT_FIT) == fit.start
    assert with_parameters(shipped, fit.values).to_xml() == shipped.to_xml()
    assert model_key(with_parameters(shipped, fit.values)) == model_key(shipped)
    # a start 5 % off the optimum is moved
    moved = fit_linear(
        with_parameters(shipped, {"counterweight_mass": 1.05 * fit.start["counterweight_mass"]}),
        Targets.thesis(),
        ["counterweight_mass"],
    )
    assert moved.values["counterweight_mass"] != pytest.approx(1.05 * fit.start["counterweight_mass"], rel=1e-3)
