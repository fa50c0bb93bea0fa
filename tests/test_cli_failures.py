"""Every failure of the ``trms`` command is one line on stderr and exit 2; a fuzz over its arguments."""

import io
import json
import re
import subprocess
import sys
import zipfile

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from trms.cli import MAX_DURATION, main
from trms.plant import LinearPlant, simulate
from trms.record import OperatingPoint, Record


def _run(argv, capsys):
    """``main(argv)`` in-process: (status, stderr lines); an escaped exception fails the test."""
    try:
        status = main(argv)
    except SystemExit as exc:  # --help and --version only
        status = exc.code
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    return status, err


def _assert_clean(status, err, argv):
    assert status == 0 or (status == 2 and len(err) == 1), (argv, status, err)
    if status == 2:
        assert "Traceback" not in err[0] and err[0].startswith("trms"), (argv, err)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Good, odd and broken record files."""
    d = tmp_path_factory.mktemp("bad")
    import control

    from trms.twin import Twin

    nq = Twin("1dof").model.nq
    lin = LinearPlant(
        control.ss([[0.9]], [[1.0]], [[1.0]], [[0.0]], dt=0.2),
        input_names=("u1",),
        output_names=("pitch",),
        noise_std=0.01,
    )
    u = np.random.default_rng(0).choice([-1.0, 1.0], size=200)
    rec = simulate(lin, u, seed=0, metadata={"config": "1dof"})
    rec.save(d / "one.npz")
    lin2 = LinearPlant(
        control.ss(0.9 * np.eye(2), np.eye(2), np.eye(2), np.zeros((2, 2)), dt=0.2),
        input_names=("u1", "u2"),
        output_names=("pitch", "yaw"),
        noise_std=0.01,
    )
    simulate(lin2, np.random.default_rng(1).choice([-1.0, 1.0], size=(200, 2)), metadata={"config": "2dof"}).save(
        d / "two.npz"
    )
    raw = (d / "one.npz").read_bytes()
    (d / "trunc.npz").write_bytes(raw[: len(raw) // 3])
    (d / "empty.npz").write_bytes(b"")
    with zipfile.ZipFile(d / "listhdr.npz", "w") as z:
        buf = io.BytesIO()
        np.save(buf, np.array(json.dumps([1, 2, 3])))
        z.writestr("header.npy", buf.getvalue())
    Record(
        np.zeros(0),
        np.zeros((0, 1)),
        np.zeros((0, 1)),
        ("u1",),
        ("pitch",),
        {"qpos": np.zeros((0, nq))},
        {"config": "1dof", "sample_time": 0.2},
    ).save(d / "zero.npz")
    Record(
        rec.time,
        rec.inputs,
        rec.outputs,
        rec.input_names,
        rec.output_names,
        {"qpos": np.zeros((200, nq))},
        {"config": "1dof", "sample_time": 0.0},
    ).save(d / "ts0.npz")
    np.save(d / "complex.npy", np.linspace(0, 1, 10) + 0.5j)
    np.save(d / "text.npy", np.array(["1.5", "2.5"]))
    return d


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
        (["run", "--amplitude", "1e300", "--plant", "linear"], r"allowed range \[0.0 rad, 1.1 rad\]"),
        (["demo", "--duration", "1e9"], "a longer run needs --max-duration"),
        (["simulate", "--seed", "1.5"], r"trms simulate: error: argument --seed: invalid int value: '1.5'"),
        (["simulate", "--seed", "-1", "--duration", "1"], "seed must be a non-negative integer"),
        (["design", "--q", "0"], "Q = 0 loses integral action"),
        (["simulate", "--bogus"], "unrecognized arguments: --bogus"),
        ([], "the following arguments are required: COMMAND"),
        (["identify", "{d}/trunc.npz"], "is not a trms Record file"),
        (["identify", "{d}/empty.npz"], "is not a trms Record file: not an .npz archive"),
        (["identify", "{d}/listhdr.npz"], "its header is not a trms.Record/1 header"),
        (
            ["identify", "{d}/one.npz", "--validate", "{d}/two.npz", "--orders", "1", "1", "1", "1"],
            r"is a 2dof record with inputs \(u1, u2\) .* they must match",
        ),
        (["render", "{d}/zero.npz"], "holds 0 samples"),
        (["render", "{d}/ts0.npz"], r"Record sample_time = 0.0 s is outside"),
        (["render", "{d}/one.npz", "--config", "yaw"], "--config yaw does not match record"),
        (["simulate", "--input", "{d}/zero.npz"], "holds no samples"),
        (
            ["simulate", "--duration", "0.01"],
            r"^trms simulate: error: --duration = 0.01 s is outside the allowed range \[0.4 s, 3600.0 s\] "
            r"\(a run needs at least two samples of 0.2 s\)$",
        ),
        (["demo", "--duration", "0.1", "--config", "1dof"], r"allowed range \[0.2 s, .* two samples of 0.1 s\)$"),
        (["simulate", "--input", "{d}/complex.npy"], r"must be real numbers .*: complex values are not allowed"),
        (["simulate", "--input", "{d}/text.npy"], r"must be real numbers .*: text values are not allowed"),
    ],
)
def test_known_failures_are_one_line(files, tmp_path, capsys, argv, match):
    argv = [a.format(d=files) for a in argv]
    if argv and argv[0] in ("simulate", "identify", "render", "design", "run", "demo"):
        argv += [
            "--out",
            str(tmp_path / ("o.npz" if argv[0] == "simulate" else "o.png" if argv[0] == "render" else "o")),
        ]
    status, err = _run(argv, capsys)
    assert status == 2 and len(err) == 1, err
    assert __import__("re").search(match, err[0]), err[0]
    assert list(tmp_path.iterdir()) == []  # nothing written by a failed command


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
    status, err = _run(argv, capsys)
    assert status == 0, err
    assert len(Record.load(tmp_path / "o.npz")) == round(MAX_DURATION * 2 / 0.2)


def test_debug_shows_the_traceback_and_subprocess_errors_are_one_line(files, tmp_path):
    cmd = [sys.executable, "-m", "trms.cli", "identify", str(files / "trunc.npz"), "--out", str(tmp_path)]
    plain = subprocess.run(cmd, capture_output=True, text=True)
    assert plain.returncode == 2 and len(plain.stderr.strip().splitlines()) == 1
    debug = subprocess.run(cmd + ["--debug"], capture_output=True, text=True)
    assert (
        debug.returncode == 2
        and "Traceback" in debug.stderr
        and debug.stderr.strip().splitlines()[-1] == plain.stderr.strip()
    )
    res = subprocess.run(
        [sys.executable, "-m", "trms.cli", "simulate", "--duration", "inf"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1 and list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------------------------------------- fuzz
_NUMBERS = st.sampled_from(
    [
        "0",
        "-1",
        "1",
        "0.05",
        "0.2",
        "2.5",
        "17",
        "1e300",
        "1e-300",
        "inf",
        "-inf",
        "nan",
        "1e400",
        "abc",
        "",
        "0x10",
        "1_0",
        "3600",
        "3601",
    ]
)
_CONFIG = st.sampled_from(["1dof", "2dof", "yaw", "bad"])


@st.composite
def _argv(draw, d):
    cmd = draw(st.sampled_from(["simulate", "design", "identify", "render", "run", "bogus"]))
    argv = [cmd]
    if cmd == "simulate":
        argv += ["--plant", "linear", "--config", draw(_CONFIG)]
        options = [
            "--duration",
            "--amplitude",
            "--bandwidth",
            "--step",
            "--start",
            "--period",
            "--seed",
            "--sample-time",
            "--noise",
            "--max-duration",
            "--max-amplitude",
        ]
        argv += ["--signal", draw(st.sampled_from(["prbs", "uniform", "3211", "doublet", "square", "hold", "x"]))]
        argv += ["--channel", draw(st.sampled_from(["u1", "u2", "u3"]))]
    elif cmd == "design":
        options = ["--q", "--r"]
        argv += ["--config", draw(st.sampled_from(["1dof", "2dof", "yaw"]))]
    elif cmd == "run":
        argv += [
            "--plant",
            "linear",
            "--config",
            draw(st.sampled_from(["1dof", "2dof"])),
            "--duration",
            draw(st.sampled_from(["2", "0", "-3", "inf", "1e9"])),
        ]
        options = ["--r", "--amplitude", "--period", "--seed", "--max-amplitude"]
    else:
        options = ["--every", "--width", "--height", "--orders"]
        argv.append(
            str(
                d
                / draw(
                    st.sampled_from(
                        [
                            "one.npz",
                            "two.npz",
                            "trunc.npz",
                            "empty.npz",
                            "listhdr.npz",
                            "zero.npz",
                            "ts0.npz",
                            "missing.npz",
                        ]
                    )
                )
            )
        )
        if cmd == "identify":
            options = ["--validate", "--input", "--output", "--orders"]
        if cmd == "render":
            argv += ["--config", draw(st.sampled_from(["1dof", "2dof", "yaw"]))] if draw(st.booleans()) else []
    for opt in draw(st.lists(st.sampled_from(options), max_size=3, unique=True)):
        if opt == "--orders":
            argv += [opt] + [draw(st.sampled_from(["0", "1", "2", "-1", "x"])) for _ in range(4)]
        elif opt == "--validate":
            argv += [opt, str(d / draw(st.sampled_from(["one.npz", "two.npz", "trunc.npz", "zero.npz"])))]
        elif opt in ("--input", "--output"):
            argv += [opt, draw(st.sampled_from(["u1", "u2", "pitch", "yaw", "nope"]))]
        else:
            argv += [opt, draw(_NUMBERS)]
    return argv


@settings(
    max_examples=60,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_fuzz_cli_exit_0_or_one_line(files, tmp_path, capsys, data):
    argv = data.draw(_argv(files))
    out = tmp_path / ("r.png" if argv[0] == "render" else "o")
    _assert_clean(*_run(argv + ["--out", str(out)], capsys), argv)


@settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    blob=st.one_of(st.binary(max_size=400), st.integers(1, 2000)),
    header=st.recursive(
        st.none() | st.booleans() | st.integers() | st.text(max_size=5),
        lambda c: st.lists(c, max_size=3) | st.dictionaries(st.text(max_size=12), c, max_size=4),
        max_leaves=8,
    ),
)
def test_fuzz_record_loader(files, tmp_path, capsys, blob, header):
    p = tmp_path / "f.npz"
    if isinstance(blob, int):  # a good record cut short
        raw = (files / "one.npz").read_bytes()
        p.write_bytes(raw[: blob % len(raw)])
    else:
        p.write_bytes(blob)
    _assert_clean(*_run(["identify", str(p), "--out", str(tmp_path / "id")], capsys), ["identify", blob])
    odd = {
        "format": "trms.Record/1",
        "input_names": ["u1"],
        "output_names": ["pitch"],
        "extras": [],
        "metadata": header,
    }
    for hdr in (header, odd, {**odd, "extras": header}, {**odd, "input_names": header}):
        np.savez(
            p, header=np.array(json.dumps(hdr)), time=np.arange(3.0), inputs=np.zeros((3, 1)), outputs=np.zeros((3, 1))
        )
        _assert_clean(*_run(["render", str(p), "--out", str(tmp_path / "r.png")], capsys), ["render", hdr])


def test_two_samples_are_the_shortest_simulation(tmp_path, capsys):
    status, err = _run(["simulate", "--plant", "linear", "--duration", "0.4", "--out", str(tmp_path / "o.npz")], capsys)
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
    status, err = _run(argv, capsys)
    target = npz if failing == "npz" else text
    assert status == 2 and err == [
        f"trms simulate: error: no space left on the device writing {str(target)!r}; nothing was written, old files "
        "are kept"
    ]
    assert (npz.read_bytes(), text.read_bytes()) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.csv", "o.npz"]


# ------------------------------------------------------------------------------------------ trms import
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
    status, err = _run(argv, capsys)
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
    status, err = _run([*argv, "--out", str(tmp_path / "o.npz")], capsys)
    assert status == 2 and len(err) == 1 and message in err[0] and "internal error" not in err[0]
    assert [p.name for p in tmp_path.iterdir()] == ["rig.csv"]


def test_import_help_names_the_new_options():
    res = subprocess.run([sys.executable, "-m", "trms.cli", "import", "--help"], capture_output=True, text=True)
    assert res.returncode == 0
    for text in ("--time-unit {s,ms}", "--resample", "--hover segment [T0, T1)", ".mat", "semicolon"):
        assert text in res.stdout, text


def test_a_closed_pipe_ends_quietly_after_the_record_is_written(tmp_path):
    """`trms import ... | head -1`: the reader is gone before the command prints; no message, the Record is saved."""
    path = _rig_export(tmp_path / "rig.csv")[0]
    argv = [sys.executable, "-m", "trms.cli", "import", str(path), "--inputs", "V1", "--outputs", "pitch"]
    argv += ["--units", "deg", "--hover", "0:10", "--out", str(tmp_path / "rig.npz")]
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # the reader went away: every write to stdout is EPIPE
    err = proc.stderr.read()
    proc.stderr.close()
    assert proc.wait(timeout=60) == 1 and err == b""
    assert len(Record.load(tmp_path / "rig.npz")) == 400
    shell = subprocess.run(
        " ".join(f"'{a}'" for a in argv) + " | head -1", shell=True, capture_output=True, text=True, cwd=tmp_path
    )
    assert shell.stderr == "" and shell.stdout.startswith("operating point (mean of hover segment [0, 10) s)")


@pytest.mark.parametrize(
    "args, wait",
    [(["simulate", "--duration", "3600", "--out", "long.npz"], 3.0), (["reproduce", "--quick", "--out", "rep"], 4.0)],
    ids=["simulate", "reproduce (worker pool)"],
)
def test_ctrl_c_ends_in_one_line_status_130_and_stops_the_workers(tmp_path, args, wait):
    import os
    import signal
    import time

    proc = subprocess.Popen(
        [sys.executable, "-m", "trms.cli", *args],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # its own process group, as a terminal's Ctrl-C reaches every process of the job
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    time.sleep(wait)
    assert proc.poll() is None, "the command ended before it could be interrupted"
    os.killpg(proc.pid, signal.SIGINT)
    start = time.perf_counter()
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert err.splitlines() == [f"trms {args[0]}: interrupted"]
    assert time.perf_counter() - start < 10  # the parallel jobs are stopped, not waited for
    assert not (tmp_path / "long.npz").exists()  # nothing half-written


@pytest.fixture(scope="module")
def odd(tmp_path_factory):
    """Records a rig never gives (all NaN, angles 1000 times the stops), a short one, odd input files."""
    d = tmp_path_factory.mktemp("odd")
    t = np.arange(300) * 0.2
    u = np.random.default_rng(4).choice([-0.5, 0.5], size=300)
    y = np.convolve(u, 0.9 ** np.arange(40))[:300] * 0.05  # a small, identifiable response (rad)
    meta = {"config": "1dof", "sample_time": 0.2, "operating_point": OperatingPoint.zero(["u1"], ["pitch"]).to_dict()}
    Record(t, u, y, ("u1",), ("pitch",), {}, meta).save(d / "good.npz")
    Record(t, u, 1000.0 * y, ("u1",), ("pitch",), {}, meta).save(d / "far.npz")
    Record(t, u, np.full(300, np.nan), ("u1",), ("pitch",), {}, meta).save(d / "nan.npz")
    Record(t[:50], u[:50], y[:50], ("u1",), ("pitch",), {}, meta).save(d / "short.npz")
    (d / "garbage.csv").write_bytes(bytes(range(256)) * 4)
    np.save(d / "objects.npy", np.array([{"a": 1}, None], dtype=object), allow_pickle=True)
    (d / "folder").mkdir()
    (d / "megavolts.csv").write_text("u1\n" + "\n".join(["0.5", "1e6", "0.5"] * 10))
    return d


@pytest.mark.parametrize(
    "argv, match",
    [
        (["identify", "{d}/nan.npz", "--out", "{o}/id"], r"output 'pitch' is NaN in every sample"),
        (
            ["identify", "{d}/short.npz", "--out", "{o}/id"],
            r"too short for correlation tests to max_lag = 20 samples: they need at least 80 samples .* give 4\d",
        ),
        (["simulate", "--duration", "2", "--out", "{o}/r.txt"], r"Record file '.*r\.txt' must end in \.npz"),
        (["simulate", "--duration", "2", "--out", "{d}/folder"], r"Record file '.*folder' is an existing folder"),
        (["design", "--out", "{d}/folder"], r"IsADirectoryError: .*an existing folder, not a file"),
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
            ["run", "--push-impulse", "0.01", "--push-time", "500", "--duration", "20", "--out", "{o}/run"],
            r"--push-time = 500.0 s is outside the allowed range \[0.0 s, 20.0 s\] \(the push must come within",
        ),
        (
            ["run", "--config", "2dof", "--push-impulse", "0.01", "--push-time", "81", "--out", "{o}/run"],
            r"--push-time = 81.0 s is outside the allowed range \[0.0 s, 80.0 s\]",
        ),
        (
            ["run", "--config", "2dof", "--r", "5", "--out", "{o}/run"],
            r"--r 5 sets the 1-DOF loop's R; .* leave --r out",
        ),
        (
            ["simulate", "--input", "{d}/megavolts.csv", "--out", "{o}/x.npz"],
            r"1e\+06 V is beyond the plausible \+-100 V of a motor voltage",
        ),
        (["demo", "--modes", "-1", "--out", "{o}/demo"], r"--modes = -1 is outside the allowed range \[1, 100\]"),
        (
            ["robustness", "--spread", "-0.2", "--n", "1", "--out", "{o}/rb"],
            r"^trms robustness: error: spread = -0.2 is outside the allowed range \[0.0, 0.9\]$",
        ),
    ],
)
def test_refusals_name_the_value_the_user_gave(odd, tmp_path, capsys, argv, match):
    argv = [a.format(d=odd, o=tmp_path) for a in argv]
    status, err = _run(argv, capsys)
    assert status == 2 and len(err) == 1, err
    assert re.search(match, err[0]), err[0]
    assert list(tmp_path.iterdir()) == []  # nothing written


@pytest.mark.parametrize(
    "argv, warning",
    [
        (
            ["simulate", "--plant", "linear", "--config", "2dof", "--amplitude", "5", "--duration", "60"],
            r"pitch reaches .* rad \(end stops \+-1.1 rad\).*: past the rig's end stops, where the linear model is "
            "not valid",
        ),
        (["simulate", "--plant", "linear", "--config", "2dof", "--amplitude", "0.01", "--duration", "60"], None),
        (["identify", "{d}/far.npz"], r"far.npz': pitch reaches .* rad \(end stops \+-1.1 rad\), beyond the rig's"),
        (["identify", "{d}/good.npz"], None),
    ],
)
def test_angles_past_the_end_stops_are_said_in_one_warning(odd, tmp_path, capsys, argv, warning):
    argv = [a.format(d=odd) for a in argv] + ["--out", str(tmp_path / ("o.npz" if argv[0] == "simulate" else "id"))]
    status, err = _run(argv, capsys)
    assert status == 0, err
    if warning is None:
        assert err == []
    else:
        assert len(err) == 1 and err[0].startswith(f"trms {argv[0]}: warning: ") and re.search(warning, err[0]), err
