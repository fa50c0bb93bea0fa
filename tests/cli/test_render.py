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


def test_a_record_with_nan_joint_positions_is_refused_naming_the_sample(tmp_path, capsys):
    import numpy as np

    from trms.twin import Twin

    from ._helpers import run_main

    twin = Twin("1dof", 0.1)
    rec = twin.run(np.tile(twin.operating_point.inputs, (10, 1)))
    rec.extras["qpos"][4] = np.nan
    rec.save(tmp_path / "nan.npz")
    status, err = run_main(["render", str(tmp_path / "nan.npz"), "--out", str(tmp_path / "nan.png")], capsys)
    assert status == 2 and len(err) == 1
    assert "has joint positions that are not finite in 1 sample(s), first at sample 4 (t = 0.4 s)" in err[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["nan.npz"]
