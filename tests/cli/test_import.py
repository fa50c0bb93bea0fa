"""``trms import``: a rig's text and MATLAB exports into a Record, what the reader did as warnings,
and files that are not exports refused in one line."""

import re
import subprocess
import sys

import numpy as np
import pytest

from trms.cli import main
from trms.record import Record

from ._helpers import run_main


def _rig_export(path, delimiter=",", head=(), time_scale=1.0, jitter=0.0, encoding="utf-8", header=None):
    """A 1-DOF rig's export: 20 s at 0.05 s, hover until 10 s, then a square wave; pitch in degrees."""
    t = np.arange(400) * 0.05
    u = 2.0 + np.where(t < 10, 0.0, 0.3 * np.sign(np.sin(t) + 1e-9))
    pitch = 1.5 + np.where(t < 10, 0.0, 5.0 * np.sin(t - 10))
    tt = t * time_scale + jitter * np.sin(7.3 * np.arange(400))
    lines = [*head, delimiter.join(header or ["time", "V1", "pitch"])]
    lines += [delimiter.join(f"{v:.6g}" for v in row) for row in zip(tt, u, pitch)]
    path.write_bytes(("\n".join(lines) + "\n").encode(encoding))
    return path, t, u, pitch


def test_trms_import_reads_a_semicolon_ms_export_with_a_title_and_says_what_it_did(tmp_path, capsys):
    path, t, u, pitch = _rig_export(
        tmp_path / "log.csv",
        ";",
        head=["Rig log 2024-05-01;;"],
        time_scale=1000.0,
        jitter=0.2,
        header=["t [ms]", "U1", "pitch [°]"],
        encoding="latin-1",
    )
    argv = ["import", str(path), "--time", "t [ms]", "--time-unit", "ms", "--inputs", "U1", "--outputs", "pitch [°]"]
    argv += ["--units", "deg", "--hover", "0:10", "--config", "1dof", "--out", str(tmp_path / "rig.npz")]
    status = main(argv)
    out, err = capsys.readouterr()
    assert status == 0, err
    assert out.splitlines() == [
        "operating point (mean of hover segment [0, 10) s): inputs [2.0] V, outputs [0.02618] rad",
        f"400 samples at 0.05 s, inputs u1, outputs pitch (rad); wrote {tmp_path / 'rig.npz'}",
    ]
    lines = err.splitlines()
    assert len(lines) == 2 and lines[0] == (
        f"trms import: warning: {str(path)!r}: skipped line 1 'Rig log 2024-05-01;;' (its header is line 2)"
    )
    assert re.fullmatch(  # +-0.2 ms of jitter on a 50 ms sample: 0.4 %
        rf"trms import: warning: column 't \[ms\]' of {re.escape(repr(str(path)))}: timestamps up to 0\.4\d* % of "
        r"the 0.05 s sample time off a uniform grid \(jitter tolerance 5 %\); snapped to the grid",
        lines[1],
    )
    rec = Record.load(tmp_path / "rig.npz")
    np.testing.assert_array_equal(rec.time, t)
    np.testing.assert_array_equal(rec.inputs[:, 0], u)
    np.testing.assert_allclose(rec.outputs[:, 0], np.radians(pitch), rtol=0, atol=1e-7)
    assert rec.metadata["import"] == {"format": "text", "encoding": "latin-1", "delimiter": "semicolon"}


def test_trms_import_reads_a_mat_file_and_resamples_only_when_asked(tmp_path, capsys):
    import scipy.io

    t = np.arange(400) * 0.05
    keep = np.arange(400) % 50 != 7  # the logger lost one sample in fifty
    scipy.io.savemat(tmp_path / "run.mat", {"log": np.column_stack([t, 2.0 + 0.01 * t, 10 * np.sin(t)])[keep]})
    argv = ["import", str(tmp_path / "run.mat"), "--time", "log(:,1)", "--inputs", "log(:,2)", "--outputs"]
    argv += ["log(:,3)", "--units", "deg", "--out", str(tmp_path / "rig.npz")]
    status, err = run_main(argv, capsys)
    assert status == 2 and err[0].startswith("trms import: error: sample 8, column 'log(:,1)': sample interval 0.1 s")
    assert err[0].endswith("resample=True (--resample) interpolates the record linearly onto a uniform grid")
    assert not (tmp_path / "rig.npz").exists()
    assert main([*argv, "--resample"]) == 0
    out, err = capsys.readouterr()
    assert "400 samples at 0.05 s" in out and len(err.splitlines()) == 1
    assert "resampled by linear interpolation onto 0.05 s: 392 rows -> 400 samples" in err
    rec = Record.load(tmp_path / "rig.npz")
    np.testing.assert_allclose(rec.inputs[:, 0], 2.0 + 0.01 * t, rtol=0, atol=1e-12)  # a ramp comes back exactly


@pytest.mark.parametrize(
    "content, message",
    [
        (b"PK\x03\x04" + bytes(100), "is a zip archive (a saved Record .npz?), not a CSV export"),
        (bytes(range(256)) * 4, "is not a text export: byte 0x00 at offset 0 is binary data"),
        (b"time,V1," + b"x" * 131_073 + b"\n0,1,2\n", "has a field longer than 131072 characters"),
    ],
)
def test_trms_import_refuses_what_is_not_an_export_with_one_line(tmp_path, capsys, content, message):
    (tmp_path / "rig.csv").write_bytes(content)
    argv = ["import", str(tmp_path / "rig.csv"), "--inputs", "V1", "--outputs", "pitch", "--units", "deg"]
    status, err = run_main([*argv, "--out", str(tmp_path / "o.npz")], capsys)
    assert status == 2 and len(err) == 1 and message in err[0] and "internal error" not in err[0]
    assert [p.name for p in tmp_path.iterdir()] == ["rig.csv"]


def test_import_help_names_the_new_options():
    res = subprocess.run([sys.executable, "-m", "trms.cli", "import", "--help"], capture_output=True, text=True)
    assert res.returncode == 0
    for text in ("--time-unit {s,ms}", "--resample", "--hover segment [T0, T1)", ".mat", "semicolon"):
        assert text in res.stdout, text


def test_trms_import_says_where_the_operating_point_came_from_and_writes_nothing_on_bad_input(
    rig_csv, capsys, monkeypatch
):
    path = rig_csv[0]
    monkeypatch.chdir(path.parent)
    args = [
        "import",
        path.name,
        "--time",
        "Time [s]",
        "--inputs",
        "Vmain",
        "--outputs",
        "Pitch_deg",
        "--config",
        "1dof",
        "--out",
        "rig.npz",
    ]
    assert main([*args, "--units", "deg", "--hover", "0:9.95"]) == 0
    out = capsys.readouterr().out
    assert "operating point (mean of hover segment [0, 9.95) s): inputs [2.0] V" in out
    rec = Record.load(path.parent / "rig.npz")
    assert rec.input_names == ("u1",) and rec.output_names == ("pitch",) and rec.metadata["config"] == "1dof"
    (path.parent / "rig.npz").unlink()
    assert main(args) == 2  # no --units
    assert "units of the angle columns not given" in capsys.readouterr().err
    assert main([*args[:7], "Pitch", *args[8:], "--units", "deg"]) == 2
    assert capsys.readouterr().err.strip() == (
        f"trms import: error: column 'Pitch' is missing from {path.name!r}; it has Time [s], Vmain, Pitch_deg, Tacho"
    )
    assert not (path.parent / "rig.npz").exists()


def test_a_saved_record_is_refused_by_trms_import_with_one_line(tmp_path, capsys):
    Record(np.arange(3) * 0.1, np.ones(3), np.zeros(3), ("u1",), ("pitch",)).save(tmp_path / "r.npz")
    args = ["import", str(tmp_path / "r.npz"), "--inputs", "u1", "--outputs", "pitch", "--units", "deg"]
    assert main([*args, "--out", str(tmp_path / "o.npz")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"trms import: error: {str(tmp_path / 'r.npz')!r} is a saved Record (.npz) already, not a rig's export; use "
        "it as it is (e.g. trms identify), or import the rig's .csv or .mat"
    ]
    assert not (tmp_path / "o.npz").exists()
