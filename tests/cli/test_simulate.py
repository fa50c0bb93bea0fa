"""``trms simulate``: records from generated signals and files, caps, refusals in one line."""

import numpy as np
import pytest

from trms.cli import MAX_DURATION
from trms.record import Record

from ._helpers import angle_warning, bad_input, known_failure, refusal, run_main, trms


def test_simulate_writes_records_from_signals_and_files(work):
    rec = Record.load(work / "prbs.npz")
    assert len(rec) == 300 and rec.metadata["config"] == "1dof" and rec.metadata["world"] == "twin"
    assert len(np.unique(rec.inputs)) == 2  # a PRBS about the hover trim
    assert (work / "doublet.csv").read_text().startswith("time,u1,pitch")
    # a file of absolute volts: one column per input, a header line allowed
    volts = rec.inputs[:50, 0]
    (work / "volts.csv").write_text("u1\n" + "\n".join(repr(float(v)) for v in volts))
    res = trms("simulate", "--plant", "linear", "--input", "volts.csv", "--out", "mine.npz", cwd=work)
    assert res.returncode == 0, res.stderr
    mine = Record.load(work / "mine.npz")
    np.testing.assert_array_equal(mine.inputs[:, 0], volts)
    assert "saturated samples: 0" in res.stdout


def test_caps_can_be_raised(tmp_path, capsys):
    argv = [
        "simulate",
        "--plant",
        "linear",
        "--duration",
        str(MAX_DURATION * 2),
        "--max-duration",
        str(MAX_DURATION * 3),
        "--amplitude",
        "30",
        "--max-amplitude",
        "40",
        "--out",
        str(tmp_path / "o.npz"),
    ]
    status, err = run_main(argv, capsys)
    assert status == 0, err
    assert len(Record.load(tmp_path / "o.npz")) == round(MAX_DURATION * 2 / 0.2)


def test_two_samples_are_the_shortest_simulation(tmp_path, capsys):
    status, err = run_main(
        ["simulate", "--plant", "linear", "--duration", "0.4", "--out", str(tmp_path / "o.npz")], capsys
    )
    assert status == 0 and not err and len(Record.load(tmp_path / "o.npz")) == 2


@pytest.mark.parametrize("failing", ["npz", "csv"])
def test_a_full_disk_during_simulate_is_one_line_and_keeps_both_old_files(tmp_path, capsys, monkeypatch, failing):
    """ENOSPC while writing the Record or its CSV: one line naming the file, both old files kept, nothing left."""
    import csv
    import errno

    old = Record(np.arange(3) * 0.2, np.ones(3), np.zeros(3), ("u1",), ("pitch",), {}, {"config": "1dof"})
    npz, text = old.save(tmp_path / "o.npz"), old.to_csv(tmp_path / "o.csv")
    before = (npz.read_bytes(), text.read_bytes())

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    if failing == "npz":
        monkeypatch.setattr(np, "savez", full)
    else:
        monkeypatch.setattr(csv, "writer", full)
    argv = ["simulate", "--plant", "linear", "--duration", "2", "--out", str(npz), "--csv"]
    status, err = run_main(argv, capsys)
    target = npz if failing == "npz" else text
    assert status == 2 and err == [
        f"trms simulate: error: no space left on the device writing {str(target)!r}; nothing was written, old files "
        "are kept"
    ]
    assert (npz.read_bytes(), text.read_bytes()) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.csv", "o.npz"]


def test_a_bad_input_in_a_real_process_exits_2_without_a_traceback(tmp_path):
    res = trms("simulate", "--input", "missing.csv", cwd=tmp_path)
    assert res.returncode == 2 and res.stderr.strip() == "trms simulate: error: input file 'missing.csv' does not exist"


@pytest.mark.parametrize(
    "argv, match",
    [
        (["simulate", "--duration", "inf"], r"--duration = inf s is outside the allowed range \(0.0 s, 3600.0 s\]"),
        (["simulate", "--duration", "1e9"], "a longer run needs --max-duration"),
        (["simulate", "--duration", "1e7"], "a longer run needs --max-duration"),
        (
            ["simulate", "--amplitude", "1e300"],
            r"--amplitude = 1e\+300 V is outside the allowed range \[0.0 V, 20.0 V\]",
        ),
        (["simulate", "--seed", "1.5"], r"trms simulate: error: argument --seed: invalid int value: '1.5'"),
        (["simulate", "--seed", "-1", "--duration", "1"], "seed must be a non-negative integer"),
        (["simulate", "--bogus"], "unrecognized arguments: --bogus"),
        (["simulate", "--input", "{d}/zero.npz"], "holds no samples"),
        (
            ["simulate", "--duration", "0.01"],
            r"^trms simulate: error: --duration = 0.01 s is outside the allowed range \[0.4 s, 3600.0 s\] "
            r"\(a run needs at least two samples of 0.2 s\)$",
        ),
        (["simulate", "--input", "{d}/complex.npy"], r"must be real numbers .*: complex values are not allowed"),
        (["simulate", "--input", "{d}/text.npy"], r"must be real numbers .*: text values are not allowed"),
    ],
)
def test_known_failures_are_one_line(files, tmp_path, capsys, argv, match):
    known_failure(files, tmp_path, capsys, argv, match)


@pytest.mark.parametrize(
    "args, message",
    [
        (("simulate", "--input", "missing.csv"), "input file 'missing.csv' does not exist"),
        (("simulate", "--input", "two_columns.csv"), "must have shape (any, 1), got shape (2, 2)"),
    ],
)
def test_bad_input_exits_2_with_a_one_line_message(work, capsys, monkeypatch, args, message):
    bad_input(work, capsys, monkeypatch, args, message)


@pytest.mark.parametrize(
    "argv, match",
    [
        (["simulate", "--duration", "2", "--out", "{o}/r.txt"], r"Record file '.*r\.txt' must end in \.npz"),
        (["simulate", "--duration", "2", "--out", "{d}/folder"], r"Record file '.*folder' is an existing folder"),
        (
            ["simulate", "--duration", "2", "--out", "/proc/x.npz"],
            r"the folder '/proc' is not writable .*'/proc/x.npz'",
        ),
        (["simulate", "--input", "{d}/garbage.csv", "--out", "{o}/x.npz"], r"garbage.csv' is not a text export"),
        (
            ["simulate", "--input", "{d}/objects.npy", "--out", "{o}/x.npz"],
            r"objects.npy' holds Python objects, which are never loaded",
        ),
        (
            ["simulate", "--input", "{d}/megavolts.csv", "--out", "{o}/x.npz"],
            r"1e\+06 V is beyond the plausible \+-100 V of a motor voltage",
        ),
    ],
)
def test_refusals_name_the_value_the_user_gave(odd, tmp_path, capsys, argv, match):
    refusal(odd, tmp_path, capsys, argv, match)


@pytest.mark.parametrize(
    "argv, warning",
    [
        (
            ["simulate", "--plant", "linear", "--config", "2dof", "--amplitude", "5", "--duration", "60"],
            r"pitch reaches .* rad \(end stops \+-1.1 rad\).*: past the rig's end stops, where the linear model is "
            "not valid",
        ),
        (["simulate", "--plant", "linear", "--config", "2dof", "--amplitude", "0.01", "--duration", "60"], None),
    ],
)
def test_angles_past_the_end_stops_are_said_in_one_warning(odd, tmp_path, capsys, argv, warning):
    angle_warning(odd, tmp_path, capsys, argv, warning)
