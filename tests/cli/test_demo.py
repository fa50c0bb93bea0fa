"""``trms demo``: a record and renders of the twin around hover; refusals in one line."""

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from trms.cli import main
from trms.record import Record

from ._helpers import bad_input, known_failure, refusal, trms


def test_demo_writes_a_record_and_renders(tmp_path):
    out = tmp_path / "out"
    res = trms("demo", "--config", "1dof", "--duration", "6", "--out", str(out), cwd=tmp_path)
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


def test_the_demo_keeps_yaw_within_45_degrees_and_says_so(tmp_path, capsys, monkeypatch):
    """The default demo (2-DOF, 60 s, PRBS around hover): yaw stayed at the +-172 deg stops with 0.2 V."""
    import trms.twin.render as render

    monkeypatch.setattr(render, "render_record", lambda model, rec, path, **kw: Path(path))  # no pictures needed
    assert main(["demo", "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    rec = Record.load(tmp_path / "out" / "record.npz")
    excursion = np.degrees(np.max(np.abs(rec.deviations()[1]), axis=0))
    assert rec.output_names == ("pitch", "yaw") and len(rec) == 600
    assert 10.0 < excursion[1] <= 45.0 and excursion[0] > 1.0  # it moved, and stayed within
    assert (
        f"PRBS of +-0.02 V around hover; largest excursion from hover: pitch {excursion[0]:.1f} deg, "
        f"yaw {excursion[1]:.1f} deg"
    ) in out


@pytest.mark.parametrize(
    "argv, match",
    [
        (["demo", "--duration", "1e9"], "a longer run needs --max-duration"),
        (["demo", "--duration", "0.1", "--config", "1dof"], r"allowed range \[0.2 s, .* two samples of 0.1 s\)$"),
    ],
)
def test_known_failures_are_one_line(files, tmp_path, capsys, argv, match):
    known_failure(files, tmp_path, capsys, argv, match)


@pytest.mark.parametrize(
    "args, message",
    [
        (("demo", "--sample-time", "0.0105"), "not a whole multiple of the kernel's 0.001 s resolution"),
        (("demo", "--config", "3dof"), "invalid choice: '3dof'"),
    ],
)
def test_bad_input_exits_2_with_a_one_line_message(work, capsys, monkeypatch, args, message):
    bad_input(work, capsys, monkeypatch, args, message)


@pytest.mark.parametrize(
    "argv, match",
    [
        (["demo", "--modes", "-1", "--out", "{o}/demo"], r"--modes = -1 is outside the allowed range \[1, 100\]"),
    ],
)
def test_refusals_name_the_value_the_user_gave(odd, tmp_path, capsys, argv, match):
    refusal(odd, tmp_path, capsys, argv, match)
