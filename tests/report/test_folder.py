"""The report's folder: files no trms run wrote refused (named) unless forced, a run's files listed, a failed run
leaving the old report whole."""

import json

import pytest

from trms.errors import InputError
from trms.report.folder import MANIFEST, TITLE, check_folder, keep_files, write_manifest


def _report(folder, *others):
    """A folder as a trms run leaves it (its manifest lists its files), with ``others`` beside them."""
    (folder / "figures").mkdir(parents=True)
    (folder / "report.md").write_text(TITLE + "\n")
    (folder / "figures" / "a.png").write_bytes(b"png")
    write_manifest(folder, [])
    for name in others:
        (folder / name).write_text("mine")
    return folder


def test_a_new_an_empty_and_a_run_s_own_folder_are_accepted(tmp_path):
    assert check_folder(tmp_path / "new") == []
    (tmp_path / "empty").mkdir()
    assert check_folder(tmp_path / "empty") == []
    assert check_folder(_report(tmp_path / "run")) == []
    listed = json.loads((tmp_path / "run" / MANIFEST).read_text())["files"]
    assert listed == ["figures/a.png", "report.md"]


def test_a_run_from_before_manifests_is_known_by_its_title(tmp_path):
    old = tmp_path / "old"
    (old / "figures").mkdir(parents=True)
    (old / "report.md").write_text(TITLE + "\nbody\n")
    (old / "tables.json").write_text("{}")
    (old / "figures" / "x.png").write_bytes(b"png")
    assert check_folder(old) == []
    (old / "notes.txt").write_text("mine")
    with pytest.raises(InputError, match=r"holds 1 file\(s\) no trms run wrote: notes.txt"):
        check_folder(old)


@pytest.mark.parametrize(
    "mine, named",
    [
        (("report.md", "tables.json"), "report.md, tables.json"),  # someone's own report, not a run's
        (("a", "b", "c", "d", "e", "f", "g"), "a, b, c, d, e and 2 more"),
    ],
)
def test_a_folder_holding_files_no_run_wrote_is_refused_naming_them(tmp_path, mine, named):
    folder = tmp_path / "out"
    folder.mkdir()
    for name in mine:
        (folder / name).write_text("mine")
    with pytest.raises(InputError) as exc:
        check_folder(folder)
    assert f"no trms run wrote: {named};" in str(exc.value) and "--force" in str(exc.value)
    assert sorted(check_folder(folder, force=True)) == sorted(mine)


def test_forced_the_foreign_files_are_kept_but_for_those_the_report_writes(tmp_path):
    old = _report(tmp_path / "old", "notes.txt", "report.html")
    new = _report(tmp_path / "new")
    (new / "report.html").write_text("the run's")
    foreign = check_folder(old, force=True)
    assert foreign == ["notes.txt", "report.html"]
    with pytest.warns(UserWarning, match=r"--force: the report replaced 1 file\(s\) no trms run wrote: report.html"):
        kept = keep_files(foreign, old, new)
    assert kept == ["notes.txt"] and (new / "notes.txt").read_text() == "mine"
    write_manifest(new, kept)
    assert check_folder(new, force=True) == ["notes.txt"]  # still no run's: the next run asks again


@pytest.mark.parametrize("where", ["", "file", "cwd", "parent"])
def test_a_folder_the_report_cannot_replace_whole_is_refused(tmp_path, monkeypatch, where):
    (tmp_path / "file").write_text("x")
    (tmp_path / "sub").mkdir()
    monkeypatch.chdir(tmp_path / "sub")
    out = {"": "", "file": str(tmp_path / "file"), "cwd": ".", "parent": str(tmp_path)}[where]
    match = {"": "name is empty", "file": "is a file", "cwd": "current folder", "parent": "current folder"}[where]
    with pytest.raises(InputError, match=match):
        check_folder(out)


def test_a_failed_run_leaves_the_old_report_whole_and_nothing_beside_it(tmp_path, monkeypatch):
    """The run fails after a figure of the new report was written: the old report is what the folder holds."""
    import trms.report.pipeline as pipeline

    old = _report(tmp_path / "report")
    before = {p.name: p.read_bytes() for p in old.rglob("*") if p.is_file()}

    def failing_jobs(settings, workers, say, on_result, meanwhile, render):
        (render.parent / "half.png").write_bytes(b"half")  # a figure of the new run, then the run fails
        raise KeyboardInterrupt

    monkeypatch.setattr(pipeline, "run_jobs", failing_jobs)
    with pytest.raises(KeyboardInterrupt):
        pipeline.reproduce(old, quick=True, workers=1)
    assert {p.name: p.read_bytes() for p in old.rglob("*") if p.is_file()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]
