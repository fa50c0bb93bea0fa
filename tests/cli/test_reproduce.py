"""``trms reproduce``: its arguments refused in one line (the report itself: tests/test_report.py)."""

import pytest

from ._helpers import bad_input


@pytest.mark.parametrize(
    "args, message",
    [
        (("reproduce", "--workers", "0"), "workers = 0 is outside the allowed range"),
    ],
)
def test_bad_input_exits_2_with_a_one_line_message(work, capsys, monkeypatch, args, message):
    bad_input(work, capsys, monkeypatch, args, message)
