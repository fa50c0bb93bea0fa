"""``trms compare-controllers``: the table printed and written as JSON and Markdown; refusals in one line."""

import json

from trms.control.margins import DiskMargin
from trms.experiments import ch8_controllers

from ._helpers import run_main


def _small(seeds, ts):
    """A known comparison, so the command's own work (options, files, printing) is what is tested."""
    case = ch8_controllers.ControllerCase("LQG", "linear model", 4.1, 9.7, 0, 4, 0.19, 0.0)
    margin = DiskMargin(1.05, (0.31, 3.21), 10.1, 55.4, 0.05, True)
    return ch8_controllers.Comparison((case,), {"LQG": 0.1}, {"LQG": 3.0}, {"LQG": margin}, tuple(seeds), ts)


def test_the_table_is_printed_and_written(tmp_path, capsys, monkeypatch):
    calls = []
    monkeypatch.setattr(ch8_controllers, "compare_controllers", lambda s, t: calls.append((s, t)) or _small(s, t))
    status, err = run_main(["compare-controllers", "--seeds", "3", "4", "--ts", "0.1", "--out", str(tmp_path)], capsys)
    assert status == 0 and err == []
    assert calls == [([3, 4], 0.1)]
    data = json.loads((tmp_path / "comparison.json").read_text())
    assert data["rows"][0][:4] == ["LQG", "linear model", 4.1, 9.7]
    md = (tmp_path / "comparison.md").read_text()
    assert "10.1 dB, 55.4 deg" in md and "seeds 3, 4" in md


def test_bad_options_are_one_line(tmp_path, capsys):
    for argv, text in (
        (["compare-controllers", "--ts", "0.3"], "invalid choice: 0.3"),
        (["compare-controllers", "--seeds"], "expected at least one argument"),
    ):
        status, err = run_main(argv, capsys)
        assert status == 2 and len(err) == 1 and text in err[0]
