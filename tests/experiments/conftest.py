"""Shared, module-cached experiment runs (each is deterministic: every signal and noise is seeded)."""

import pytest

from trms.experiments import ch3_identification as c3
from trms.worlds import make_plant


@pytest.fixture(scope="session")
def ch3_results():
    r1 = {w: c3.identify_1dof(make_plant(w, "1dof"), make_plant(w, "1dof", 0.1)) for w in ("linear", "twin")}
    r2 = {w: c3.identify_2dof(make_plant(w, "2dof")) for w in ("linear", "twin")}
    return r1, r2


@pytest.fixture(scope="session")
def ch4_results(ch3_results):
    from trms.experiments import ch4_shaping as c4

    r1, _ = ch3_results
    s1 = {w: c4.shaping_1dof(make_plant(w, "1dof"), r1[w].model.to_tf()) for w in ("linear", "twin")}
    s2 = {w: c4.shaping_2dof(make_plant(w, "2dof")) for w in ("linear", "twin")}
    return s1, s2


@pytest.fixture(scope="session")
def ch5_results():
    from trms.experiments import ch5_narx as c5

    r = {w: c5.narx_1dof(make_plant(w, "1dof")) for w in ("linear", "twin")}
    y = {w: c5.narx_yaw(make_plant(w, "2dof")) for w in ("linear", "twin")}
    return r, y


@pytest.fixture(scope="session")
def ch67_results():
    from trms.experiments import ch67_lqg as c6
    from trms.reference import PUSH_WEIGHTS_R
    from trms.twin import Twin
    from trms.worlds import design_model

    model = design_model("1dof")
    weights = (75.0, 1.0, 125.0)
    lin = c6.lqg_cases(make_plant("linear", "1dof"), model, weights)
    twin = c6.lqg_cases(make_plant("twin", "1dof", gusts=True), model, weights)
    push = c6.push_rejection(
        lambda pushes: make_plant("twin", "1dof", gusts=True, pushes=pushes), model, PUSH_WEIGHTS_R
    )
    twin_model = Twin("1dof", model.dt).linearise().discrete
    margins = {
        "linear": {r: c6.loop_margins(model, model, r) for r in weights},
        "twin": {r: c6.loop_margins(twin_model, model, r) for r in weights},
    }
    return lin, twin, push, weights, margins


@pytest.fixture(scope="session")
def side_mode_evidence():
    from trms.experiments import ch7_side_mode as side_mode
    from trms.reference import PUSH_WEIGHTS_R
    from trms.worlds import design_model

    return side_mode.prefilter_evidence(design_model("1dof"), PUSH_WEIGHTS_R)
