"""The autopilot's margins at each plant input: the SISO margins on a known loop, a criterion that can fail, the
shipped design's scan."""

import control
import numpy as np
import pytest

from trms.experiments import ch8_autopilot_margins as cm
from trms.experiments.ch8_mimo_lqg import R_SCALES
from trms.worlds import design_model


def test_siso_margins_on_a_known_loop():
    # L(z) = k / (z - 1): it meets the negative real axis at z = -1 (L = -k/2), and its gain crosses 1 at
    # theta = 2 asin(k/2), where its phase is -(90 deg + theta/2)
    k = 0.5
    gm, pm = cm._siso_margins(control.ss(control.tf([k], [1.0, -1.0], 0.1)))
    theta = np.degrees(2 * np.arcsin(k / 2))
    assert gm == pytest.approx(20 * np.log10(2 / k), abs=0.01)
    assert pm == pytest.approx(90.0 - theta / 2, abs=0.05)


def test_the_criterion_can_fail():
    good = cm.InputMargins(1.0, (7.0, 9.0), (35.0, 60.0), True)
    assert good.adequate
    assert not cm.InputMargins(1.0, (5.9, 9.0), (35.0, 60.0), True).adequate  # gain margin at u1
    assert not cm.InputMargins(1.0, (7.0, 9.0), (35.0, 29.0), True).adequate  # phase margin at u2
    assert not cm.InputMargins(1.0, (7.0, 9.0), (35.0, 60.0), False).adequate  # unstable


def test_a_scan_reads_each_scale_and_a_larger_control_weight_loses_no_gain_margin():
    m = design_model("2dof")
    scan = cm.margin_scan(m, m, R_SCALES)
    assert [s.scale for s in scan] == list(R_SCALES) and all(s.stable for s in scan)
    assert min(scan[-1].gain_margin_db) >= min(scan[0].gain_margin_db)
