"""The time-domain calibration's rig: without the sysid extra it says how to install it."""

import pytest

from trms.calibration.timedomain import calibrate_records
from trms.calibration.timedomain import rig as timedomain_rig
from trms.errors import ConfigurationError


def test_without_the_sysid_extra_the_calibration_says_how_to_install_it(monkeypatch):
    monkeypatch.setattr(timedomain_rig, "_SYSID_ERROR", ImportError("No module named 'mujoco.sysid'"))
    with pytest.raises(ConfigurationError) as err:
        calibrate_records([])
    assert str(err.value).endswith("install it with pip install 'trms[sysid]'") and "\n" not in str(err.value)


def test_without_the_sysid_extra_the_command_says_so_in_one_line(tmp_path):
    """The extra missing (mujoco.sysid cannot be imported): no annotation of the calibration's modules needs it."""
    import subprocess
    import sys

    import numpy as np

    from trms.record import Record

    Record(np.arange(5) * 0.1, np.zeros(5), np.zeros(5), ("u1",), ("pitch",), {}, {"config": "1dof"}).save(
        tmp_path / "r.npz"
    )
    code = (
        "import sys; sys.modules['mujoco.sysid'] = None\nfrom trms.cli import main\n"
        "sys.exit(main(['calibrate', '--records', 'r.npz', '--out', 'cal']))"
    )
    res = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True)
    assert res.returncode == 2 and res.stderr.splitlines() == [
        "trms calibrate: error: time-domain calibration needs the sysid extra (mujoco.sysid is missing): "
        "install it with pip install 'trms[sysid]'"
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.npz"]
