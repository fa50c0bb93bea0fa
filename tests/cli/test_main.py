"""The entry point: every failure one line and status 2 (a fuzz over the arguments and record files),
``--debug``, ``--version``, Ctrl-C (status 130) and a closed pipe."""

import json
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from trms.record import Record

from ._helpers import assert_clean, run_main
from .test_import import _rig_export


def test_version_prints_the_installed_version(capsys):
    import trms
    from trms.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"trms {trms.__version__}" and trms.__version__ != "0+unknown"


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
    assert_clean(*run_main(argv + ["--out", str(out)], capsys), argv)


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
    assert_clean(*run_main(["identify", str(p), "--out", str(tmp_path / "id")], capsys), ["identify", blob])
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
        assert_clean(*run_main(["render", str(p), "--out", str(tmp_path / "r.png")], capsys), ["render", hdr])


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


def test_ctrl_c_while_numpy_and_mujoco_load_is_one_line_and_status_130(tmp_path):
    """Interrupts in the first second, while the command's modules load: three commands at once, each signalled at
    its own instant (the terminal's Ctrl-C reaches the whole process group)."""
    import os
    import signal
    import time

    jobs = [
        (["calibrate", "--out", "cal", "--quiet"], 0.1),
        (["compare-controllers", "--out", "cc"], 0.3),
        (["reproduce", "--quick", "--out", "rep"], 1.0),
    ]
    procs = [
        subprocess.Popen(
            [sys.executable, "-m", "trms.cli", *args],
            cwd=tmp_path,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        )
        for args, _ in jobs
    ]
    start = time.perf_counter()
    for proc, (_, at) in zip(procs, jobs):
        time.sleep(max(0.0, at - (time.perf_counter() - start)))
        os.killpg(proc.pid, signal.SIGINT)
    for proc, (args, at) in zip(procs, jobs):
        _, err = proc.communicate(timeout=60)
        assert (proc.returncode, err.splitlines()) == (130, [f"trms {args[0]}: interrupted"]), (at, err[-2000:])
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # nothing written


def test_the_command_module_loads_nothing_heavy_before_its_guard():
    """``import trms.cli`` (what the console script runs first) loads no numpy: a Ctrl-C is caught from the start."""
    code = "import sys, trms.cli; assert not {'numpy', 'mujoco', 'trms.cli.command'} & set(sys.modules), sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


_AFTER_THE_WORK = """
import signal, sys
from trms.cli import main
sys.argv = ["trms", "design", "--out", sys.argv[1]]
status = main()
print(status, signal.getsignal(signal.SIGINT) is signal.SIG_IGN)
"""


def test_a_press_once_the_work_is_written_changes_nothing(tmp_path):
    """A command line's run ignores Ctrl-C once its work is done and written: a press while the interpreter shuts down
    cannot end it by SIGINT (status -2, no line) after its files are whole."""
    res = subprocess.run(
        [sys.executable, "-c", _AFTER_THE_WORK, str(tmp_path / "d.json")], capture_output=True, text=True, timeout=120
    )
    assert res.stdout.split()[-2:] == ["0", "True"], res.stderr
