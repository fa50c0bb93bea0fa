"""``trms render``: a GIF of a twin record; records it cannot render refused in one line."""

import pytest
from PIL import Image

from ._helpers import bad_input, known_failure, trms


def test_render_writes_a_gif_of_a_twin_record(work):
    res = trms("render", "prbs.npz", "--out", "prbs.gif", "--every", "30", cwd=work)
    assert res.returncode == 0, res.stderr
    with Image.open(work / "prbs.gif") as im:
        assert im.n_frames == 10 and im.size == (320, 240)


@pytest.mark.parametrize(
    "argv, match",
    [
        (["render", "{d}/zero.npz"], "holds 0 samples"),
        (["render", "{d}/ts0.npz"], r"sample_time = 0.0 s; allowed: a finite number of seconds > 0"),
        (["render", "{d}/one.npz", "--config", "yaw"], "--config yaw does not match record"),
    ],
)
def test_known_failures_are_one_line(files, tmp_path, capsys, argv, match):
    known_failure(files, tmp_path, capsys, argv, match)


@pytest.mark.parametrize(
    "args, message",
    [
        (("render", "prbs.npz", "--config", "2dof"), "pass the --config it was recorded with"),
    ],
)
def test_bad_input_exits_2_with_a_one_line_message(work, capsys, monkeypatch, args, message):
    bad_input(work, capsys, monkeypatch, args, message)
