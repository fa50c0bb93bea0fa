"""The ``trms`` command, run as a user would: in a subprocess."""

import subprocess
import sys

import numpy as np
from PIL import Image

from trms.plant import Record


def _trms(*args, cwd):
    return subprocess.run([sys.executable, "-m", "trms.cli", *args], cwd=cwd, capture_output=True, text=True)


def test_demo_writes_a_record_and_renders(tmp_path):
    out = tmp_path / "out"
    res = _trms("demo", "--config", "1dof", "--duration", "6", "--out", str(out), cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "hover voltages: u1 = " in res.stdout and "Hz  damping" in res.stdout
    rec = Record.load(out / "record.npz")
    assert len(rec) == 60 and rec.metadata["config"] == "1dof"
    assert np.ptp(rec.outputs) > 0  # the PRBS moved the beam
    assert (out / "record.csv").read_text().startswith("time,u1,pitch")
    with Image.open(out / "rig.png") as im:
        assert im.size == (480, 360) and len(set(np.asarray(im).ravel().tolist())) > 10
    with Image.open(out / "rig.gif") as im:
        assert im.n_frames == 12


def test_bad_options_exit_non_zero_with_a_message(tmp_path):
    res = _trms("demo", "--sample-time", "0.0105", "--out", str(tmp_path), cwd=tmp_path)
    assert res.returncode == 2 and "not a whole multiple of the kernel's 0.001 s resolution" in res.stderr
    res = _trms("demo", "--config", "3dof", cwd=tmp_path)
    assert res.returncode == 2 and "invalid choice: '3dof'" in res.stderr
    res = _trms("demo", "--help", cwd=tmp_path)
    assert res.returncode == 0 and "examples:" in res.stdout
