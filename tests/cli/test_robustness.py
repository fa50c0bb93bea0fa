"""``trms robustness``: the study's files and success rates; a spread refused in one line."""

import json

import pytest

from trms.cli import main

from ._helpers import refusal


def test_cli_writes_the_study(tmp_path, capsys):
    assert (
        main(["robustness", "--n", "2", "--seed", "1", "--workers", "1", "--worst", "0", "--out", str(tmp_path)]) == 0
    )
    assert "success" in capsys.readouterr().out
    assert json.loads((tmp_path / "robustness.json").read_text())["samples"] == 2
    assert main(["robustness", "--n", "0", "--out", str(tmp_path)]) == 2


@pytest.mark.parametrize(
    "argv, match",
    [
        (
            ["robustness", "--spread", "-0.2", "--n", "1", "--out", "{o}/rb"],
            r"^trms robustness: error: spread = -0.2 is outside the allowed range \[0.0, 0.9\]$",
        ),
    ],
)
def test_refusals_name_the_value_the_user_gave(odd, tmp_path, capsys, argv, match):
    refusal(odd, tmp_path, capsys, argv, match)
