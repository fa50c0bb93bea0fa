"""``trms run``: closed loops on the twin and the linear model, their lines and figures; refusals."""

import re

import numpy as np
import pytest

from trms.cli import main
from trms.record import Record

from ._helpers import bad_input, known_failure, refusal, trms


@pytest.mark.parametrize(
    "args",
    [
        ("--plant", "linear", "--r", "125", "--case", "CSAS LPF 0.2 Hz", "--duration", "40"),
        ("--config", "2dof", "--controller", "two SISO loops", "--scenario", "yaw step", "--gusts"),
    ],
)
def test_run_closes_a_loop_and_writes_its_record(tmp_path, args):
    res = trms("run", *args, "--out", "run", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    rec = Record.load(tmp_path / "run" / "record.npz")
    assert {"reference", "control"} <= set(rec.extras) and rec.metadata["config"] in ("1dof", "2dof")
    assert (tmp_path / "run" / "response.png").stat().st_size > 5000


def test_a_2dof_run_plots_pitch_and_yaw_and_says_its_units(tmp_path, figures, capsys):
    from trms.control.loop import deviation_limits
    from trms.worlds import make_plant

    assert main(["run", "--plant", "linear", "--config", "2dof", "--out", str(tmp_path / "run")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert re.fullmatch(
        r"MIMO LQG, pitch step \(linear\): (not )?settled within the noise band \(pitch tracked\); "
        r"(every target met|targets missed: .*)",
        out[0],
    ), out[0]
    assert re.fullmatch(
        r"  TR (\d+\.\d\d s|not reached), TS \(noise band\) (\d+\.\d\d s|not settled), "
        r"TS \(5 %\) (\d+\.\d\d s|not settled), overshoot \S+ %, "
        r"yaw excursion \S+ rad, RMS u1 \S+ V, RMS u2 \S+ V, total variation of u \S+ V",
        out[1],
    ), out[1]
    assert ("TS (noise band) not settled" in out[1]) == (": not settled" in out[0])  # the status says the line
    assert "nan" not in "\n".join(out)
    fig = figures["response.png"]
    pitch, yaw, control = fig.axes
    assert [a.get_ylabel() for a in fig.axes] == ["pitch (rad)", "yaw (rad)", "control (V)"]
    rec = Record.load(tmp_path / "run" / "record.npz")
    np.testing.assert_array_equal(yaw.get_lines()[1].get_ydata(), rec.deviations()[1][:, 1])  # the yaw it drew
    lower, upper = deviation_limits(make_plant("linear", "2dof"))
    label = [t.get_text() for t in control.texts]
    assert (
        len(label) == 1
        and label[0].startswith(f"actuator limits: u1 {lower[0]:+.3g} / {upper[0]:+.3g} V")
        and f"; u2 {lower[1]:+.3g} / {upper[1]:+.3g} V" in label[0]
    )
    assert lower[0] != lower[1] and upper[0] != upper[1]  # a mixed label would show it


def test_a_step_line_never_prints_nan_beside_settled():
    from trms.cli.run import step_line
    from trms.control.metrics import StepMetrics

    nan = float("nan")
    narrow = StepMetrics(20.0, -0.2, 0.2, 1.25, nan, 12.0, 3.1, 0.4, 0.0, 5.0)
    wide = StepMetrics(20.0, -0.2, 0.2, 1.25, 8.4, 12.0, 3.1, 0.4, 0.0, 5.0)
    never = StepMetrics(20.0, -0.2, 0.2, nan, nan, nan, 3.1, 0.4, 0.0, 5.0)
    assert step_line(narrow, wide, 0.02, 0.05) == (
        "  step at  20.0 s: TR 1.25 s, TS (2 %) not settled, TS (5 %) 8.40 s, overshoot 12.0 %, peak |u| 3.10 V"
    )
    assert step_line(never, never, 0.02, 0.05) == (
        "  step at  20.0 s: TR not reached, TS not settled within 5 %, overshoot not measured, peak |u| 3.10 V"
    )


@pytest.mark.parametrize(
    "argv, match",
    [
        (["run", "--amplitude", "1e300", "--plant", "linear"], r"allowed range \[0.0 rad, 1.1 rad\]"),
    ],
)
def test_known_failures_are_one_line(files, tmp_path, capsys, argv, match):
    known_failure(files, tmp_path, capsys, argv, match)


@pytest.mark.parametrize(
    "args, message",
    [
        (("run", "--plant", "linear", "--push-impulse", "0.02"), "needs --plant twin"),
        (("run", "--bogus"), "unrecognized arguments: --bogus"),
    ],
)
def test_bad_input_exits_2_with_a_one_line_message(work, capsys, monkeypatch, args, message):
    bad_input(work, capsys, monkeypatch, args, message)


@pytest.mark.parametrize(
    "argv, match",
    [
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
            ["run", "--design", "{o}/nothing.json", "--out", "{o}/run"],
            r"--design flies a 2-DOF design file; the 1-DOF loop takes --r and --case",
        ),
        (
            ["run", "--config", "2dof", "--design", "{o}/nothing.json", "--out", "{o}/run"],
            r"--design '.*nothing.json' is not a file \(write one with trms design --config 2dof\)",
        ),
    ],
)
def test_refusals_name_the_value_the_user_gave(odd, tmp_path, capsys, argv, match):
    refusal(odd, tmp_path, capsys, argv, match)


@pytest.mark.parametrize("controller", ["MIMO MPC", "MIMO H-infinity", "MIMO PID"])
def test_a_2dof_run_flies_every_chapter_8_controller(tmp_path, capsys, controller):
    argv = ["run", "--plant", "linear", "--config", "2dof", "--controller", controller, "--scenario", "yaw step"]
    assert main([*argv, "--out", str(tmp_path / "run")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(f"{controller}, yaw step (linear): ")
    rec = Record.load(tmp_path / "run" / "record.npz")
    assert rec.extras["reference"][0, 1] == 0.5


def test_a_2dof_design_file_is_flown_and_an_edited_one_refused(tmp_path, capsys):
    import json

    design = tmp_path / "autopilot.json"
    assert main(["design", "--config", "2dof", "--out", str(design)]) == 0
    assert "the autopilot's per-channel weights" in capsys.readouterr().out
    argv = ["run", "--config", "2dof", "--design", str(design), "--out", str(tmp_path / "mine")]  # the README's
    assert main(argv) == 0
    flown = capsys.readouterr().out.splitlines()[0]
    assert flown.startswith("MIMO LQG (autopilot.json), pitch step (twin): ") and "every target met" in flown
    data = json.loads(design.read_text())
    data["K"][0][0] *= 2.0
    design.write_text(json.dumps(data))
    assert main([*argv[:-1], str(tmp_path / "edited")]) == 2
    assert "differ from what its weights give" in capsys.readouterr().err


@pytest.mark.parametrize("impulse, way", [("-0.02", "lowering the main rotor (pitch down)"), ("0.02", "raising")])
def test_a_push_says_which_way_it_acts(tmp_path, capsys, impulse, way):
    argv = ["run", "--push-impulse", impulse, "--push-time", "2", "--duration", "4", "--amplitude", "0"]
    assert main([*argv, "--out", str(tmp_path / "push")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1].startswith(f"  push of {float(impulse):+g} N m s about pitch at 2 s, {way}")
    pitch = Record.load(tmp_path / "push" / "record.npz").extras["true_angles"][:, 0]
    assert np.sign(pitch[13] - pitch[10]) == np.sign(float(impulse))  # 0.6 s after the push: the way the line says
