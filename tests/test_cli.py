"""The ``trms`` command, run as a user would: each subcommand in a subprocess."""

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from trms.cli import main
from trms.record import Record
from trms.twin import DEFAULT_MODEL_PATH


def _trms(*args, cwd):
    return subprocess.run([sys.executable, "-m", "trms.cli", *args], cwd=cwd, capture_output=True, text=True)


@pytest.fixture(scope="module")
def work(tmp_path_factory):
    """A folder with a simulated PRBS and a doublet record of the 1-DOF twin."""
    d = tmp_path_factory.mktemp("cli")
    for args in (
        ("--signal", "prbs", "--out", "prbs.npz"),
        ("--signal", "doublet", "--duration", "30", "--out", "doublet.npz", "--csv"),
    ):
        res = _trms("simulate", "--config", "1dof", *args, cwd=d)
        assert res.returncode == 0, res.stderr
    return d


def test_demo_writes_a_record_and_renders(tmp_path):
    out = tmp_path / "out"
    res = _trms("demo", "--config", "1dof", "--duration", "6", "--out", str(out), cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "hover voltages: u1 = " in res.stdout and "Hz  damping" in res.stdout
    rec = Record.load(out / "record.npz")
    assert len(rec) == 60 and rec.metadata["config"] == "1dof"
    assert np.ptp(rec.outputs) > 0  # the PRBS moved the beam
    assert (out / "record.csv").read_text().startswith("time,u1,pitch")
    with Image.open(out / "rig.png") as im:
        assert im.size == (480, 360) and len(set(np.asarray(im).ravel().tolist())) > 10
    with Image.open(out / "rig.gif") as im:
        assert im.n_frames == 12


def test_simulate_writes_records_from_signals_and_files(work):
    rec = Record.load(work / "prbs.npz")
    assert len(rec) == 300 and rec.metadata["config"] == "1dof" and rec.metadata["world"] == "twin"
    assert len(np.unique(rec.inputs)) == 2  # a PRBS about the hover trim
    assert (work / "doublet.csv").read_text().startswith("time,u1,pitch")
    # a file of absolute volts: one column per input, a header line allowed
    volts = rec.inputs[:50, 0]
    (work / "volts.csv").write_text("u1\n" + "\n".join(repr(float(v)) for v in volts))
    res = _trms("simulate", "--plant", "linear", "--input", "volts.csv", "--out", "mine.npz", cwd=work)
    assert res.returncode == 0, res.stderr
    mine = Record.load(work / "mine.npz")
    np.testing.assert_array_equal(mine.inputs[:, 0], volts)
    assert "saturated samples: 0" in res.stdout


def test_identify_writes_a_model_tests_and_plots(work):
    res = _trms("identify", "prbs.npz", "--validate", "doublet.npz", "--out", "ident", cwd=work)
    assert res.returncode == 0, res.stderr
    model = json.loads((work / "ident" / "model.json").read_text())
    assert model["orders"] == [4, 4, 4, 1] and len(model["A"]) == 5
    assert set(model["residual_tests"]) == {"ee", "ue"} and np.isfinite(model["validation_fit_percent"])
    for name in ("residuals.png", "psd.png", "validation.png"):
        assert (work / "ident" / name).stat().st_size > 5000
    assert "mode " in res.stdout and "validation fit" in res.stdout


def test_design_writes_gains_poles_and_prefilter(tmp_path):
    res = _trms("design", "--r", "75", "--case", "CSAS LPF 0.2 Hz", "--out", "lqg.json", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    d = json.loads((tmp_path / "lqg.json").read_text())
    assert np.array(d["K"]).shape == (1, 5) and d["estimator_faster"] is True
    assert d["prefilter"]["name"].startswith("Butterworth LPF order 2")
    assert all(np.hypot(*p) < 1 for p in d["regulator_poles"])


@pytest.mark.parametrize(
    "args",
    [
        ("--plant", "linear", "--r", "125", "--case", "CSAS LPF 0.2 Hz", "--duration", "40"),
        ("--config", "2dof", "--controller", "two SISO loops", "--scenario", "yaw square wave", "--gusts"),
    ],
)
def test_run_closes_a_loop_and_writes_its_record(tmp_path, args):
    res = _trms("run", *args, "--out", "run", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    rec = Record.load(tmp_path / "run" / "record.npz")
    assert {"reference", "control"} <= set(rec.extras) and rec.metadata["config"] in ("1dof", "2dof")
    assert (tmp_path / "run" / "response.png").stat().st_size > 5000


def test_render_writes_a_gif_of_a_twin_record(work):
    res = _trms("render", "prbs.npz", "--out", "prbs.gif", "--every", "30", cwd=work)
    assert res.returncode == 0, res.stderr
    with Image.open(work / "prbs.gif") as im:
        assert im.n_frames == 10 and im.size == (320, 240)


def test_calibrate_fits_a_user_mode_table_and_writes_a_new_model(tmp_path):
    """A one-target table (1-DOF pitch mode at 0.32 Hz): the values go into a new MJCF, the shipped one is untouched."""
    shipped = DEFAULT_MODEL_PATH.read_bytes()
    start = tmp_path / "rig.xml"
    shutil.copy(DEFAULT_MODEL_PATH, start)
    table = tmp_path / "modes.json"
    table.write_text(json.dumps({"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 0.32}]}))
    res = _trms(
        "calibrate",
        "--targets",
        str(table),
        "--start-from",
        str(start),
        "--out",
        "cal",
        "--quiet",
        "--seeds",
        "101",
        "102",
        cwd=tmp_path,
    )
    assert res.returncode == 0, res.stderr
    assert "| 1dof u1->pitch PSD peak | 0.32 Hz |" in res.stdout and "yes |" in res.stdout
    report = json.loads((tmp_path / "cal" / "calibration.json").read_text())
    assert report["all_met"] is True and report["targets"]["source"] == str(table)
    assert (tmp_path / "cal" / "calibration.png").stat().st_size > 10_000
    written = tmp_path / "cal" / "trms.xml"
    assert written.read_text() != start.read_text()  # the calibrated values went into the new file
    assert start.read_text() == DEFAULT_MODEL_PATH.read_text() and DEFAULT_MODEL_PATH.read_bytes() == shipped
    res = _trms("calibrate", "--targets", "missing.json", "--no-write", cwd=tmp_path)
    assert res.returncode == 2 and "target file 'missing.json' does not exist" in res.stderr
    res = _trms("calibrate", "--targets", str(table), "--mjcf", str(DEFAULT_MODEL_PATH), "--quiet", cwd=tmp_path)
    assert res.returncode == 2 and "is the shipped model; use --replace-shipped" in res.stderr
    assert DEFAULT_MODEL_PATH.read_bytes() == shipped


@pytest.mark.parametrize("mjcf", ["shipped", "start"])
def test_calibrate_refuses_its_mjcf_before_running(tmp_path, capsys, mjcf):
    """A refused --mjcf costs no calibration and leaves no report behind."""
    start = tmp_path / "rig.xml"
    shutil.copy(DEFAULT_MODEL_PATH, start)
    target = DEFAULT_MODEL_PATH if mjcf == "shipped" else start
    out = tmp_path / "cal"
    code = main(["calibrate", "--start-from", str(start), "--mjcf", str(target), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and str(target) in err[0]
    assert not out.exists()


@pytest.mark.parametrize(
    "args, message",
    [
        (("--held-out", "rig.npz"), "--held-out belongs to the time-domain calibration; give --records too"),
        (("--parameters", "pitch_damping"), "--parameters belongs to the time-domain calibration"),
        (("--records", "rig.npz", "--workers", "2"), "--workers runs the spectral stage's candidates"),
        (("--records", "rig.npz", "--seeds", "101"), "--seeds sets the spectral calibration's verification"),
    ],
)
def test_calibrate_refuses_an_option_of_the_other_calibration(tmp_path, capsys, args, message):
    code = main(["calibrate", "--out", str(tmp_path / "cal"), "--quiet", *args])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and message in err[0]
    assert not (tmp_path / "cal").exists()


def test_calibrate_exits_1_on_an_unmet_target_unless_accepted(tmp_path):
    """A peak no parameter within its bounds can reach (1-DOF pitch at 3 Hz): exit 1, and 0 with --accept-unmet."""
    table = tmp_path / "modes.json"
    table.write_text(
        json.dumps({"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 3.0, "tolerance_hz": 0.01}]})
    )
    res = _trms(
        "calibrate", "--targets", str(table), "--out", "cal", "--quiet", "--no-write", "--seeds", "101", cwd=tmp_path
    )
    assert res.returncode == 1, res.stderr
    assert "not met: " in res.stdout and "exit status 1" in res.stdout
    res = _trms(
        "calibrate",
        "--targets",
        str(table),
        "--out",
        "cal2",
        "--quiet",
        "--accept-unmet",
        "--seeds",
        "101",
        cwd=tmp_path,
    )
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "cal2" / "trms.xml").is_file()


@pytest.mark.parametrize(
    "command",
    ["reproduce", "simulate", "identify", "design", "run", "render", "calibrate", "demo", "import", "robustness"],
)
def test_every_subcommand_has_help_with_examples(capsys, command):
    with pytest.raises(SystemExit) as exc:
        main([command, "--help"])
    out = capsys.readouterr().out
    assert exc.value.code == 0 and "examples:" in out and f"trms {command}" in out


@pytest.mark.parametrize(
    "args, message",
    [
        (("demo", "--sample-time", "0.0105"), "not a whole multiple of the kernel's 0.001 s resolution"),
        (("demo", "--config", "3dof"), "invalid choice: '3dof'"),
        (("identify", "missing.npz"), "record file 'missing.npz' does not exist"),
        (("simulate", "--input", "missing.csv"), "input file 'missing.csv' does not exist"),
        (("simulate", "--input", "two_columns.csv"), "must have shape (any, 1), got shape (2, 2)"),
        (("run", "--plant", "linear", "--push-impulse", "0.02"), "needs --plant twin"),
        (("design", "--case", "LPF 9 Hz"), "unknown case 'LPF 9 Hz'; allowed: 'SAS'"),
        (("render", "prbs.npz", "--config", "2dof"), "pass the --config it was recorded with"),
        (("reproduce", "--workers", "0"), "workers = 0 is outside the allowed range"),
        (("run", "--bogus"), "unrecognized arguments: --bogus"),
    ],
)
def test_bad_input_exits_2_with_a_one_line_message(work, capsys, monkeypatch, args, message):
    (work / "two_columns.csv").write_text("1,2\n3,4\n")
    monkeypatch.chdir(work)
    try:
        code = main(list(args))
    except SystemExit as exc:  # argparse's own errors
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2
    assert message in err
    # our errors are one line; argparse's last line is its one-line message after the usage
    assert err.strip().splitlines()[-1].startswith("trms") and message in err.strip().splitlines()[-1]


def test_a_bad_input_in_a_real_process_exits_2_without_a_traceback(tmp_path):
    res = _trms("simulate", "--input", "missing.csv", cwd=tmp_path)
    assert res.returncode == 2 and res.stderr.strip() == "trms simulate: error: input file 'missing.csv' does not exist"


def test_version_prints_the_installed_version(capsys):
    import trms
    from trms.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"trms {trms.__version__}" and trms.__version__ != "0+unknown"


@pytest.fixture
def figures(monkeypatch):
    """The figures the command saves, by file name (they are still written)."""
    import trms.present.figures as figs

    saved, original = {}, figs.save_figure

    def keep(fig, path, *args, **kwargs):
        saved[Path(path).name] = fig
        return original(fig, path, *args, **kwargs)

    monkeypatch.setattr(figs, "save_figure", keep)
    return saved


def test_the_validation_figure_names_its_units(work, figures, capsys, monkeypatch):
    monkeypatch.chdir(work)
    argv = ["identify", "prbs.npz", "--validate", "doublet.npz", "--orders", "2", "2", "2", "1", "--out", "units"]
    assert main(argv) == 0, capsys.readouterr().err
    ax = figures["validation.png"].axes[0]
    assert ax.get_ylabel() == "pitch, deviation from the operating point (rad)" and ax.get_xlabel() == "time (s)"
    np.testing.assert_array_equal(ax.get_lines()[0].get_xdata(), Record.load(work / "doublet.npz").time)


def test_a_2dof_run_plots_pitch_and_yaw_and_says_its_units(tmp_path, figures, capsys):
    from trms.control.loop import deviation_limits
    from trms.worlds import make_plant

    assert main(["run", "--plant", "linear", "--config", "2dof", "--out", str(tmp_path / "run")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert re.fullmatch(
        r"MIMO LQG, pitch square wave \(linear\): (not )?settled within the 2 % band \(pitch tracked\)", out[0]
    )
    assert re.fullmatch(
        r"  TR (\d+\.\d\d s|not reached), TS \(2 %\) (\d+\.\d\d s|not settled), overshoot \S+ %, "
        r"yaw excursion \S+ rad, RMS u1 \S+ V, RMS u2 \S+ V, total variation of u \S+ V",
        out[1],
    ), out[1]
    assert ("TS (2 %) not settled" in out[1]) == (": not settled" in out[0])  # the status says what the line says
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
    from trms.cli import _step_line
    from trms.control.metrics import StepMetrics

    nan = float("nan")
    narrow = StepMetrics(20.0, -0.2, 0.2, 1.25, nan, 12.0, 3.1, 0.4, 0.0, 5.0)
    wide = StepMetrics(20.0, -0.2, 0.2, 1.25, 8.4, 12.0, 3.1, 0.4, 0.0, 5.0)
    never = StepMetrics(20.0, -0.2, 0.2, nan, nan, nan, 3.1, 0.4, 0.0, 5.0)
    assert _step_line(narrow, wide, 0.02, 0.05) == (
        "  step at  20.0 s: TR 1.25 s, TS (2 %) not settled, TS (5 %) 8.40 s, overshoot 12.0 %, peak |u| 3.10 V"
    )
    assert _step_line(never, never, 0.02, 0.05) == (
        "  step at  20.0 s: TR not reached, TS not settled within 5 %, overshoot not measured, peak |u| 3.10 V"
    )


def test_the_demo_keeps_yaw_within_45_degrees_and_says_so(tmp_path, capsys, monkeypatch):
    """The default demo (2-DOF, 60 s, PRBS around hover): yaw stayed at the +-172 deg stops with 0.2 V."""
    import trms.twin.render as render

    monkeypatch.setattr(render, "render_record", lambda model, rec, path, **kw: Path(path))  # no pictures needed
    assert main(["demo", "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    rec = Record.load(tmp_path / "out" / "record.npz")
    excursion = np.degrees(np.max(np.abs(rec.deviations()[1]), axis=0))
    assert rec.output_names == ("pitch", "yaw") and len(rec) == 600
    assert 10.0 < excursion[1] <= 45.0 and excursion[0] > 1.0  # it moved, and stayed within
    assert (
        f"PRBS of +-0.02 V around hover; largest excursion from hover: pitch {excursion[0]:.1f} deg, "
        f"yaw {excursion[1]:.1f} deg"
    ) in out
