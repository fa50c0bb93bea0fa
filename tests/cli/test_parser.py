"""The one parser: every subcommand's help with examples; a missing command refused in one line."""

import pytest

from trms.cli import main

from ._helpers import known_failure


@pytest.mark.parametrize(
    "command",
    [
        "reproduce",
        "simulate",
        "identify",
        "design",
        "run",
        "compare-controllers",
        "render",
        "calibrate",
        "demo",
        "import",
        "robustness",
    ],
)
def test_every_subcommand_has_help_with_examples(capsys, command):
    with pytest.raises(SystemExit) as exc:
        main([command, "--help"])
    out = capsys.readouterr().out
    assert exc.value.code == 0 and "examples:" in out and f"trms {command}" in out


@pytest.mark.parametrize(
    "argv, match",
    [
        ([], "the following arguments are required: COMMAND"),
    ],
)
def test_known_failures_are_one_line(files, tmp_path, capsys, argv, match):
    known_failure(files, tmp_path, capsys, argv, match)
