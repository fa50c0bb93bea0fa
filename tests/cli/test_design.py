"""``trms design``: gains, poles and prefilter as JSON; refusals in one line."""

import json

import numpy as np
import pytest

from ._helpers import bad_input, known_failure, refusal, trms


def test_design_writes_gains_poles_and_prefilter(tmp_path):
    res = trms("design", "--r", "75", "--case", "CSAS LPF 0.2 Hz", "--out", "lqg.json", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    d = json.loads((tmp_path / "lqg.json").read_text())
    assert np.array(d["K"]).shape == (1, 5) and d["estimator_faster"] is True
    assert d["prefilter"]["name"].startswith("Butterworth LPF order 2")
    assert all(np.hypot(*p) < 1 for p in d["regulator_poles"])


@pytest.mark.parametrize(
    "argv, match",
    [
        (["design", "--q", "0"], "Q = 0 loses integral action"),
    ],
)
def test_known_failures_are_one_line(files, tmp_path, capsys, argv, match):
    known_failure(files, tmp_path, capsys, argv, match)


@pytest.mark.parametrize(
    "args, message",
    [
        (("design", "--case", "LPF 9 Hz"), "unknown case 'LPF 9 Hz'; allowed: 'SAS'"),
    ],
)
def test_bad_input_exits_2_with_a_one_line_message(work, capsys, monkeypatch, args, message):
    bad_input(work, capsys, monkeypatch, args, message)


@pytest.mark.parametrize(
    "argv, match",
    [
        (["design", "--out", "{d}/folder"], r"IsADirectoryError: .*an existing folder, not a file"),
    ],
)
def test_refusals_name_the_value_the_user_gave(odd, tmp_path, capsys, argv, match):
    refusal(odd, tmp_path, capsys, argv, match)
