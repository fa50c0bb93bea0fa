"""Chapter 8's designs: each damps the pitch mode, the disturbance weight is the lightest that does, the loops fly
behind the prefilter and, on the twin only, the thrust-curve inversion."""

import numpy as np
import pytest

from trms.control.damping import mode_damping
from trms.control.inversion import InvertedInputs
from trms.control.loop import deviation_limits
from trms.experiments import ch8_designs as cd
from trms.worlds import design_model, make_plant


@pytest.fixture(scope="module")
def designs():
    return cd.designs_at(0.2)


def test_every_design_damps_the_pitch_mode_and_each_disturbance_weight_is_the_lightest_that_does(designs):
    assert all(m.meets() for m in cd.design_damping(designs).values())
    model = designs.model
    for name, wd in designs.disturbance.items():
        assert wd in cd.DISTURBANCE_GRID
        lighter = [w for w in cd.DISTURBANCE_GRID if w < wd]
        if lighter:  # the next lighter weight leaves the mode below the design's damping
            import control

            from trms.control.hinf import design_mixsyn, pitch_weights

            kw, spread = cd._HINF[name]
            w3 = cd.input_uncertainty_weight(**cd.SPREAD_WEIGHT) if spread else None
            d = design_mixsyn(model, *pitch_weights(**kw), w3, Wd=control.tf([lighter[-1]], [1.0]))
            assert mode_damping(model, d.discrete_controller).closed.damping < cd.DESIGN_DAMPING, name
    assert designs.pid.tm > 0.0


def test_the_twins_controllers_fly_behind_the_inversion_and_the_linear_models_do_not(designs):
    twin, linear = make_plant("twin", "1dof"), make_plant("linear", "1dof")
    on_twin, _ = cd.controllers_for(designs, twin)
    assert all(isinstance(c, InvertedInputs) for c in on_twin.values())
    limits = on_twin["LQG"].limits()
    assert limits[1][0] < deviation_limits(twin)[1][0]  # the rotor reaches full speed before +10 V
    on_linear, _ = cd.controllers_for(designs, linear)
    assert not any(isinstance(c, InvertedInputs) for c in on_linear.values())
    raw, _ = cd.controllers_for(designs, twin, inversion=False)
    assert not any(isinstance(c, InvertedInputs) for c in raw.values())
    assert np.array_equal(raw["LQG"].input_limits[1], deviation_limits(twin)[1])


def test_the_prefilter_is_the_thesis_csas_low_pass():
    pf = cd.reference_prefilter(0.2)
    assert pf.name.startswith("Butterworth LPF order 2, 0.2 Hz") and pf.dc_gain() == pytest.approx(1.0)


def test_feedback_compensators_unwrap_the_inversion_and_give_mpc_its_law(designs):
    twin_ctrl, _ = cd.controllers_for(designs, make_plant("twin", "1dof"))
    for name, c in twin_ctrl.items():
        k = cd.feedback_compensator(c)
        assert k is not None and k.dt == 0.2, name
    assert design_model("1dof").dt == 0.2
