"""Every failure of the ``trms`` command is one line on stderr and exit 2; a fuzz over its arguments."""

import io
import json
import subprocess
import sys
import zipfile

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from trms.cli import MAX_DURATION, main
from trms.plant import LinearPlant, Record, simulate


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
