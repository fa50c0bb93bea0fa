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


def test_a_folder_with_someone_s_own_report_is_refused_naming_the_files_and_kept(tmp_path, capsys):
    from ._helpers import run_main

    out = tmp_path / "mine"
    out.mkdir()
    (out / "report.md").write_text("my notes\n")
    (out / "tables.json").write_text("{}\n")
    status, err = run_main(["reproduce", "--quick", "--out", str(out)], capsys)
    assert status == 2 and len(err) == 1
    assert "holds 2 file(s) no trms run wrote: report.md, tables.json;" in err[0] and "--force" in err[0]
    assert (out / "report.md").read_text() == "my notes\n" and sorted(p.name for p in tmp_path.iterdir()) == ["mine"]


@pytest.mark.parametrize("command", [["reproduce"], ["simulate"], ["identify", "x.npz"], ["calibrate"]])
def test_an_empty_out_is_refused_before_anything_runs(tmp_path, capsys, monkeypatch, command):
    from ._helpers import run_main

    monkeypatch.chdir(tmp_path)
    status, err = run_main([*command, "--out", ""], capsys)
    assert (status, err) == (2, [f"trms {command[0]}: error: --out is an empty name; give a file or folder name"])
    assert list(tmp_path.iterdir()) == []
