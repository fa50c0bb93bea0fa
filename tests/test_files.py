"""Atomic writes: no half-written file, no orphan after SIGKILL, an atomic CSV, JSON-exact metadata."""

import csv
import errno
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from trms.errors import InputError
from trms.files import TEMP_SUFFIX, atomic_group, atomic_write, sweep_temporary_files
from trms.record import Record


def _record(n=5):
    return Record(
        np.arange(n) * 0.1,
        np.ones((n, 1)),
        np.zeros((n, 1)),
        ("u1",),
        ("pitch",),
        {"flags": np.zeros((n, 2), bool)},
        {"sample_time": 0.1, "config": "1dof"},
    )


def test_sigkill_during_a_large_save_leaves_no_orphan_after_the_next_save(tmp_path):
    code = (
        "import numpy as np, sys; from trms.plant import Record; n = 3_000_000; "
        "r = Record(np.arange(n) * 0.1, np.zeros((n, 2)), np.zeros((n, 2)), ('u1', 'u2'), ('p', 'y'), "
        "{'x': np.zeros((n, 8))}, {}); print('saving', flush=True); r.save(sys.argv[1])"
    )
    target = tmp_path / "big.npz"
    # A writer may finish between the moment its temporary file is seen and the kill: try until a kill leaves one.
    for _ in range(5):
        proc = subprocess.Popen([sys.executable, "-c", code, str(target)], stdout=subprocess.PIPE)
        assert proc.stdout.readline().strip() == b"saving"
        deadline = time.monotonic() + 20
        while not list(tmp_path.glob(f"*{TEMP_SUFFIX}")) and time.monotonic() < deadline:
            time.sleep(0.005)
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        if list(tmp_path.glob(f"*{TEMP_SUFFIX}")):
            break
    assert list(tmp_path.glob(f"*{TEMP_SUFFIX}"))  # a kill mid-write left a temporary file
    rec = _record()
    rec.save(target)  # the next save sweeps the dead writers' files
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.npz"]
    assert Record.load(target).equals(rec)


def test_sweep_keeps_the_files_of_live_writers(tmp_path):
    live = tmp_path / f".a.npz.{__import__('os').getpid()}.0000{TEMP_SUFFIX}"
    dead = tmp_path / f".a.npz.{2**22 + 12345}.0000{TEMP_SUFFIX}"  # above Linux's default pid_max
    other = tmp_path / "notes.tmp"
    for p in (live, dead, other):
        p.write_text("x")
    assert sweep_temporary_files(tmp_path) == [dead]
    assert live.exists() and other.exists()


def test_a_failed_write_keeps_the_old_file_and_leaves_nothing(tmp_path):
    target = tmp_path / "a.txt"
    target.write_text("old")

    def fail(fh):
        fh.write("half")
        raise OSError("disk full")

    with pytest.raises(OSError, match="disk full"):
        atomic_write(target, fail, binary=False)
    assert target.read_text() == "old" and [p.name for p in tmp_path.iterdir()] == ["a.txt"]


def test_to_csv_is_atomic(tmp_path, monkeypatch):
    target = _record().to_csv(tmp_path / "r.csv")
    old = target.read_text()

    class Broken:
        def __init__(self, fh):
            self.fh = fh

        def writerow(self, row):
            self.fh.write(",".join(row) + "\n")

        def writerows(self, rows):
            raise OSError("No space left on device")

    monkeypatch.setattr(csv, "writer", Broken)
    with pytest.raises(OSError, match="No space"):
        _record(7).to_csv(target)
    assert target.read_text() == old and [p.name for p in tmp_path.iterdir()] == ["r.csv"]


def test_to_csv_of_a_zero_sample_record_is_its_header(tmp_path):
    text = _record(0).to_csv(tmp_path / "z.csv").read_text()
    assert text.splitlines() == ["time,u1,pitch,flags[0],flags[1]"]


@pytest.mark.parametrize(
    "content, match",
    [
        (b"", "not an .npz archive"),
        (b"PK\x03\x04 truncated", "not an .npz archive"),
        (b"time,u1,pitch\n0,1,0\n", "not an .npz archive"),
        (bytes(range(256)) * 8, "not a trms Record"),
    ],
)
def test_load_refuses_broken_files_with_one_line(tmp_path, content, match):
    p = tmp_path / "bad.npz"
    p.write_bytes(content)
    with pytest.raises(InputError, match=match) as info:
        Record.load(p)
    assert "\n" not in str(info.value) and "allow_pickle" not in str(info.value)


def test_load_refuses_a_truncated_record_and_odd_headers(tmp_path):
    good = _record().save(tmp_path / "good.npz")
    raw = good.read_bytes()
    (tmp_path / "cut.npz").write_bytes(raw[: len(raw) // 2])
    with pytest.raises(InputError, match="is not a trms Record file"):
        Record.load(tmp_path / "cut.npz")
    for header in ([1, 2], {"format": "trms.Record/1", "input_names": "u1"}, "text", None):
        np.savez(tmp_path / "odd.npz", header=np.array(__import__("json").dumps(header)), time=np.zeros(2))
        with pytest.raises(InputError, match="is not a trms Record file"):
            Record.load(tmp_path / "odd.npz")


def test_metadata_round_trips_exactly(tmp_path):
    meta = {"sample_time": 0.1, "nested": {"a": [1, 2.5, None, True, "x"]}, "seed": 3}
    rec = Record(np.arange(2) * 0.1, np.zeros(2), np.zeros(2), ("u",), ("y",), {}, meta)
    assert Record.load(rec.save(tmp_path / "m.npz")).metadata == meta


def test_a_full_disk_fails_at_once_names_the_file_and_keeps_the_old_one(tmp_path):
    """ENOSPC from the writer: one try (nothing retried, nothing waits), the old file kept, no temporary left."""
    target = tmp_path / "r.npz"
    target.write_bytes(b"old")
    calls = []

    def full(fh):
        calls.append(fh.name)
        fh.write(b"half a record")
        raise OSError(errno.ENOSPC, "No space left on device")

    start = time.monotonic()
    with pytest.raises(OSError) as info:
        atomic_write(target, full)
    assert time.monotonic() - start < 1.0 and len(calls) == 1
    assert info.value.errno == errno.ENOSPC and info.value.filename == str(target)
    assert str(info.value) == f"[Errno {errno.ENOSPC}] No space left on device: {str(target)!r}"
    assert target.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == ["r.npz"]


def test_a_full_disk_at_fsync_keeps_the_old_file(tmp_path, monkeypatch):
    target = tmp_path / "a.txt"
    target.write_text("old")

    def fsync(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr("os.fsync", fsync)
    with pytest.raises(OSError, match="No space left on device: .*a.txt"):
        atomic_write(target, lambda fh: fh.write("new"), binary=False)
    assert target.read_text() == "old" and [p.name for p in tmp_path.iterdir()] == ["a.txt"]


def test_an_atomic_group_replaces_all_its_files_or_none(tmp_path, monkeypatch):
    """A Record and its CSV: a full disk on the CSV keeps the old Record too (it was not replaced yet)."""
    old = _record(5)
    npz, text = old.save(tmp_path / "r.npz"), old.to_csv(tmp_path / "r.csv")
    before = (npz.read_bytes(), text.read_text())
    new = _record(9)
    with atomic_group():
        new.save(npz)
        assert Record.load(npz).equals(old)  # not replaced until the group ends
        new.to_csv(text)
    assert Record.load(npz).equals(new) and len(text.read_text().splitlines()) == 10

    class Full:
        def __init__(self, fh):
            self.fh = fh

        def writerow(self, row):
            self.fh.write(",".join(row) + "\n")

        def writerows(self, rows):
            raise OSError(errno.ENOSPC, "No space left on device")

    for p, content in zip((npz, text), before):
        p.write_bytes(content) if isinstance(content, bytes) else p.write_text(content)
    monkeypatch.setattr(csv, "writer", Full)
    with pytest.raises(OSError, match="No space left on device"), atomic_group():
        _record(7).save(npz)
        _record(7).to_csv(text)
    assert (npz.read_bytes(), text.read_text()) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv", "r.npz"]


def test_a_folder_in_the_way_is_named_and_left_alone(tmp_path):
    (tmp_path / "out.json").mkdir()
    with pytest.raises(
        IsADirectoryError, match=r"an existing folder, not a file \(nothing was written\): '.*out\.json'"
    ):
        atomic_write(tmp_path / "out.json", lambda fh: fh.write(b"x"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.json"]


@pytest.mark.parametrize("folder", ["/proc", "/sys"])
def test_a_folder_that_takes_no_file_is_named_with_the_target_not_the_temporary_file(folder):
    with pytest.raises(OSError, match=rf"the folder '{folder}' is not writable \(.*\); nothing was written") as exc:
        atomic_write(f"{folder}/x.npz", lambda fh: fh.write(b"x"))
    assert exc.value.filename == f"{folder}/x.npz" and TEMP_SUFFIX not in str(exc.value)


def test_an_atomic_folder_replaces_the_old_one_whole_or_not_at_all(tmp_path):
    from trms.files import atomic_folder

    out = tmp_path / "report"
    out.mkdir()
    (out / "old.md").write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_folder(out) as new:
            (new / "new.md").write_text("new")
            raise RuntimeError("the run failed")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]  # nothing built is left beside it
    assert sorted(p.name for p in out.iterdir()) == ["old.md"]
    with atomic_folder(out) as new:
        (new / "new.md").write_text("new")
        assert sorted(p.name for p in out.iterdir()) == ["old.md"]  # a reader sees the old folder until the end
    assert sorted(p.name for p in out.iterdir()) == ["new.md"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]


def test_a_folder_builder_killed_by_sigkill_leaves_the_old_folder_and_the_next_sweeps_its_part(tmp_path):
    """SIGKILL while the new folder is built: the old one is whole; the next build removes the dead one's part."""
    import signal
    import subprocess
    import sys
    import time

    from trms.files import BUILDING_SUFFIX, atomic_folder

    out = tmp_path / "report"
    out.mkdir()
    (out / "old.md").write_text("old")
    code = (
        "import sys, time\nfrom trms.files import atomic_folder\n"
        "with atomic_folder(sys.argv[1]) as new:\n"
        "    (new / 'half.md').write_text('half')\n    print('built', flush=True)\n    time.sleep(60)\n"
    )
    proc = subprocess.Popen([sys.executable, "-c", code, str(out)], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "built"
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert sorted(p.name for p in out.iterdir()) == ["old.md"]
    assert [p.name.endswith(BUILDING_SUFFIX) for p in tmp_path.iterdir() if p.name != "report"] == [True]
    start = time.perf_counter()
    with atomic_folder(out) as new:
        (new / "new.md").write_text("new")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"] and time.perf_counter() - start < 5
