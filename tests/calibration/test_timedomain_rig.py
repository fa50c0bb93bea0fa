"""The time-domain calibration's rig: without the sysid extra it says how to install it."""

import pytest

from trms.calibration import timedomain_rig
from trms.calibration.timedomain import calibrate_records


def test_without_the_sysid_extra_the_calibration_says_how_to_install_it(monkeypatch):
    monkeypatch.setattr(timedomain_rig, "_SYSID_ERROR", ImportError("No module named 'mujoco.sysid'"))
    with pytest.raises(ImportError) as err:
        calibrate_records([])
    assert str(err.value).endswith("install it with pip install 'trms[sysid]'") and "\n" not in str(err.value)
