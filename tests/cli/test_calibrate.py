"""``trms calibrate``: a user's mode table into a new MJCF, refusals before any run, exit 1 when unmet."""

import json
import shutil

import pytest

from trms.cli import main
from trms.twin import DEFAULT_MODEL_PATH

from ._helpers import trms


def test_calibrate_fits_a_user_mode_table_and_writes_a_new_model(tmp_path):
    """A one-target table (1-DOF pitch mode at 0.32 Hz): the values go into a new MJCF, the shipped one is untouched."""
    shipped = DEFAULT_MODEL_PATH.read_bytes()
    start = tmp_path / "rig.xml"
    shutil.copy(DEFAULT_MODEL_PATH, start)
    table = tmp_path / "modes.json"
    table.write_text(json.dumps({"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 0.32}]}))
    res = trms(
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
    res = trms("calibrate", "--targets", "missing.json", "--no-write", cwd=tmp_path)
    assert res.returncode == 2 and "target file 'missing.json' does not exist" in res.stderr
    res = trms("calibrate", "--targets", str(table), "--mjcf", str(DEFAULT_MODEL_PATH), "--quiet", cwd=tmp_path)
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


def test_calibrate_exits_1_on_an_unmet_target(tmp_path):
    """A peak no parameter within its bounds can reach (1-DOF pitch at 3 Hz): exit 1 (``--accept-unmet``: the next
    test)."""
    table = tmp_path / "modes.json"
    table.write_text(
        json.dumps({"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 3.0, "tolerance_hz": 0.01}]})
    )
    res = trms(
        "calibrate", "--targets", str(table), "--out", "cal", "--quiet", "--no-write", "--seeds", "101", cwd=tmp_path
    )
    assert res.returncode == 1, res.stderr
    assert "not met: " in res.stdout and "exit status 1" in res.stdout


def test_a_target_met_at_nine_of_ten_seeds_is_met_and_exits_0(tmp_path, monkeypatch, capsys):
    """The verification's rule (met at 9 of 10 seeds) decides the exit status, not one seed's miss."""
    from types import SimpleNamespace

    from trms.calibration import runs
    from trms.calibration.calibrate import CalibrationResult
    from trms.calibration.checks import Check
    from trms.calibration.targets import Targets
    from trms.calibration.verify import Verification

    seeds = tuple(range(101, 111))
    checks = [
        Check("1dof ARMAX DC gain", 1.5, 1.5 if s != 108 else 1.7, "+-10 %", s != 108, "rad/V", seed=s) for s in seeds
    ]
    result = CalibrationResult(
        {"counterweight_mass": 0.1},
        {"counterweight_mass": 0.1},
        Verification(checks, seeds=seeds),
        [],
        dict.fromkeys(("linear_fit", "ambient_fit", "spectral_fit", "verification"), 0.0),
        Targets.thesis(),
        passes=1,
    )
    assert result.verification.all_met
    done = SimpleNamespace(result=result, evidence=None, seconds=0.0, json=tmp_path / "c.json", png=tmp_path / "c.png")
    monkeypatch.setattr(runs, "spectral_run", lambda *a, **k: done)
    assert main(["calibrate", "--out", str(tmp_path / "cal"), "--quiet", "--no-write"]) == 0
    assert "not met" not in capsys.readouterr().out
    result.unreachable.append("1dof ARMAX DC gain = 1.5 rad/V: achieved 1.7 rad/V")
    assert main(["calibrate", "--out", str(tmp_path / "cal"), "--quiet", "--no-write"]) == 1
    # accepted: exit 0, and the model is written
    assert main(["calibrate", "--out", str(tmp_path / "cal2"), "--quiet", "--accept-unmet"]) == 0
    assert (tmp_path / "cal2" / "trms.xml").is_file() and "not met: 1dof ARMAX DC gain" in capsys.readouterr().out


def test_an_interrupted_calibration_leaves_none_of_its_report_files(tmp_path, monkeypatch):
    """The report's files are one change: Ctrl-C after the first is written leaves none of them (and no model)."""
    from trms.cli import calibrate as cli_calibrate
    from trms.files import atomic_write

    def interrupted(args, spec):
        atomic_write(tmp_path / "cal" / "calibration.json", lambda fh: fh.write("{}"), binary=False)
        raise KeyboardInterrupt

    (tmp_path / "cal").mkdir()
    monkeypatch.setattr(cli_calibrate, "_spectral", interrupted)
    assert main(["calibrate", "--out", str(tmp_path / "cal"), "--quiet"]) == 130  # one line, status 130
    assert list((tmp_path / "cal").iterdir()) == []
