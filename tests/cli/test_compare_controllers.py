"""``trms compare-controllers``: the table printed and written as JSON and Markdown; refusals in one line."""

import json

from trms.control.margins import DiskMargin
from trms.experiments import (
    ch8_comparison,
    ch8_controllers,
    ch8_controllers_mimo,
    ch8_designs,
    ch8_robustness,
    ch8_sweep,
)

from ._helpers import run_main


def _small(seeds, ts):
    """A known comparison, so the command's own work (options, files, printing) is what is tested."""
    case = ch8_controllers.ControllerCase("LQG", "linear model", 4.1, 9.7, 0, 4, 0.19, 0.0)
    margin = DiskMargin(1.05, (0.31, 3.21), 10.1, 55.4, 0.05, True)
    return ch8_controllers.Comparison((case,), {"LQG": 0.1}, {"LQG": 3.0}, {"LQG": margin}, tuple(seeds), ts)


def test_the_table_is_printed_and_written(tmp_path, capsys, monkeypatch):
    calls = []
    monkeypatch.setattr(ch8_comparison, "compare_controllers", lambda s, t, *_: calls.append((s, t)) or _small(s, t))
    argv = [
        "compare-controllers",
        "--seeds",
        "3",
        "4",
        "--ts",
        "0.1",
        "--samples",
        "0",
        "--mimo-seeds",
        "--sweep-seeds",
    ]
    status, err = run_main([*argv, "--out", str(tmp_path)], capsys)
    assert status == 0 and err == []
    assert calls == [((3, 4), 0.1)] and not (tmp_path / "spread.json").exists()
    assert not (tmp_path / "mimo.json").exists() and not (tmp_path / "ch8_controllers.png").exists()  # no records
    data = json.loads((tmp_path / "comparison.json").read_text())
    assert data["rows"][0][:4] == ["LQG", "linear model", 4.1, 9.7]
    md = (tmp_path / "comparison.md").read_text()
    assert "LQG | linear model | 4.1 | 9.7" in md and "seeds 3, 4" in md


def test_the_spread_table_follows_with_samples(tmp_path, capsys, monkeypatch):
    calls = []
    row = ch8_robustness.ControllerSpread("PID", ("settled", "not settled"), (12.0, 90.0), (9.0, float("nan")), 2.3)

    def spread(n, sample_time):
        calls.append((n, sample_time))
        return ch8_robustness.Robustness((row,), dict(ch8_designs.SPREAD_WEIGHT), n, 0, 0.2, sample_time)

    monkeypatch.setattr(ch8_comparison, "compare_controllers", lambda s, t, *_: _small(s, t))
    monkeypatch.setattr(ch8_comparison, "controller_robustness", spread)
    argv = ["compare-controllers", "--samples", "2", "--mimo-seeds", "--sweep-seeds", "--out", str(tmp_path)]
    status, err = run_main(argv, capsys)
    assert status == 0 and err == [] and calls == [(2, 0.2)]
    data = json.loads((tmp_path / "spread.json").read_text())
    assert data["rows"][0][:3] == ["PID", "1/2", 12.0]
    md = (tmp_path / "comparison.md").read_text()
    assert "no: LTI certificate" in md and "2 samples" in md


def test_the_mimo_table_follows_with_mimo_seeds(tmp_path, capsys, monkeypatch):
    calls = []
    case = ch8_controllers_mimo.MimoCase("MIMO PID", "pitch step", "twin, moving air", 10.5, 30.0, 1, 2, 0.26, 0.0, 3.0)

    def mimo(seeds, worlds):
        calls.append((seeds, worlds))
        return ch8_controllers_mimo.MimoComparison((case,), 0.79, seeds, 0.1, 80.0)

    monkeypatch.setattr(ch8_comparison, "compare_controllers", lambda s, t, *_: _small(s, t))
    monkeypatch.setattr(ch8_comparison, "compare_controllers_mimo", mimo)
    argv = ["compare-controllers", "--samples", "0", "--mimo-seeds", "5", "--sweep-seeds", "--out", str(tmp_path)]
    status, err = run_main(argv, capsys)
    assert status == 0 and err == [] and calls == [((5,), ("linear model", "twin, moving air"))]
    data = json.loads((tmp_path / "mimo.json").read_text())
    assert data["rows"][0][:4] == ["MIMO PID", "pitch step", "twin, moving air", 10.5]
    assert "MIMO PID" in (tmp_path / "comparison.md").read_text()


def test_the_sweep_table_follows_with_sweep_seeds(tmp_path, capsys, monkeypatch):
    calls = []
    point = ch8_sweep.SweepPoint("PID", "twin, moving air", 1.0, True, 13.0, 0, 8, 8.5)

    def sweep(seeds, sample_time):
        calls.append((seeds, sample_time))
        return ch8_sweep.Sweep((point,), seeds, sample_time)

    monkeypatch.setattr(ch8_comparison, "compare_controllers", lambda s, t, *_: _small(s, t))
    monkeypatch.setattr(ch8_comparison, "amplitude_sweep", sweep)
    argv = ["compare-controllers", "--samples", "0", "--mimo-seeds", "--sweep-seeds", "7", "--out", str(tmp_path)]
    status, err = run_main(argv, capsys)
    assert status == 0 and err == [] and calls == [((7,), 0.2)]
    data = json.loads((tmp_path / "sweep.json").read_text())
    assert data["rows"][0][:4] == ["PID", "twin, moving air", "on", 8.5]


def test_bad_options_are_one_line(tmp_path, capsys):
    for argv, text in (
        (["compare-controllers", "--samples", "-1"], "--samples must be a whole number 0 to 10000, got -1"),
        (["compare-controllers", "--samples", "x"], "--samples must be a whole number 0 to 10000, got 'x'"),
        (["compare-controllers", "--ts", "0.3"], "invalid choice: 0.3"),
        (["compare-controllers", "--seeds"], "expected at least one argument"),
    ):
        status, err = run_main(argv, capsys)
        assert status == 2 and len(err) == 1 and text in err[0]


def test_an_out_that_is_a_file_or_a_bad_seed_is_one_line_and_leaves_no_folder(tmp_path, capsys):
    afile = tmp_path / "afile"
    afile.write_text("x")
    status, err = run_main(["compare-controllers", "--samples", "0", "--mimo-seeds", "--out", str(afile)], capsys)
    assert status == 2 and len(err) == 1 and "is a file; give a folder" in err[0]
    out = tmp_path / "new"
    argv = ["compare-controllers", "--samples", "0", "--mimo-seeds", "-3", "--out", str(out)]
    status, err = run_main(argv, capsys)
    assert status == 2 and len(err) == 1 and "MIMO seed must be a non-negative integer, got -3" in err[0]
    assert not out.exists()


def test_a_seed_given_twice_is_refused_before_anything_runs(tmp_path, capsys):
    for option, seeds in (("--seeds", ["0", "0"]), ("--mimo-seeds", ["1", "2", "1"])):
        status, err = run_main(["compare-controllers", option, *seeds, "--out", str(tmp_path / "cc")], capsys)
        assert status == 2 and err == [
            f"trms compare-controllers: error: {option} gives seed {seeds[0]} more than once; a seed gives the same "
            "run every time, so each must be given once"
        ]
    assert list(tmp_path.iterdir()) == []
