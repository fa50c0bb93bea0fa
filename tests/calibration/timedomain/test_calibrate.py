"""Time-domain calibration with mujoco.sysid, on known truth: a twin with hidden parameter changes.

The truth is the shipped model with several parameters moved by up to 20 % at once; its
records carry encoder quantisation and noise (the rig's rotor-wash turbulence off: still air), and in
a second set the project's gusts.
Calibration starts from the shipped model and must land on every hidden value within its
own 95 % interval, with and without gusts (the benchmark measures the intervals' coverage
over many hidden truths).
Nothing here is a number of the current model: truths are computed from it.
"""

import csv
import json
import re
import subprocess
import sys

import numpy as np
import pytest

from trms.calibration.timedomain import calibrate_records, scaled_spec
from trms.errors import ConfigurationError, InputError
from trms.record import Record
from trms.rig.exports import record_from_csv
from trms.rig.faked import faked_rig_records, to_rig_csv
from trms.signals import random_binary
from trms.twin import DEFAULT_MODEL_PATH, Gust, Twin, load_spec
from trms.twin.parameters import read_parameters
from trms.worlds import GUST

TS = 0.05
HIDDEN = {"counterweight_mass": 1.15, "pitch_damping": 0.85, "main_motor_gain": 1.1, "main_motor_lag": 0.8}


def _truth_records(spec, seeds, gust_scale, duration=30.0, still_air=False):
    gust = Gust(GUST[0] * gust_scale, GUST[1])
    twin = Twin("1dof", TS, 0, spec=spec, noise_std=2e-4, still_air=still_air, gust=gust)
    hover = twin.operating_point.inputs[0]
    return [twin.run((hover + random_binary(duration, TS, 0.5, 0.15, seed=s))[:, None], seed=s) for s in seeds]


def _to_rig_csv(record, path):
    """The rig's own layout: its column names, angles in degrees."""
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["Time [s]", "Main motor [V]", "Pitch [deg]"])
        for t, u, y in zip(record.time, record.inputs[:, 0], np.degrees(record.outputs[:, 0])):
            w.writerow([repr(float(t)), repr(float(u)), repr(float(y))])
    return path


@pytest.fixture(scope="module")
def known_truth():
    spec = load_spec()
    truth = scaled_spec(spec, HIDDEN)
    return (
        spec,
        read_parameters(truth, list(HIDDEN)),
        _truth_records(truth, (1, 2), gust_scale=0.0, still_air=True),
        _truth_records(truth, (3, 4), gust_scale=1.0, still_air=True),
    )


@pytest.mark.slow
def test_hidden_parameters_are_recovered_within_their_intervals_from_a_rig_csv(known_truth, tmp_path):
    """Quantised, noisy encoder; no gusts: every hidden value lies inside its own 95 % interval."""
    spec, truth, (fit_rec, held), _ = known_truth
    rec = record_from_csv(
        _to_rig_csv(fit_rec, tmp_path / "rig.csv"),
        time="Time [s]",
        inputs="Main motor [V]",
        outputs="Pitch [deg]",
        units="deg",
        hover_segment=(0.0, 2 * TS),  # two samples before the first switch (0.5 s)
        input_names=["u1"],
        output_names=["pitch"],
        config="1dof",
    )
    result = calibrate_records([rec], list(HIDDEN), spec, held_out=[held], max_iters=20)
    for name, value in truth.items():
        start, got, half = result.start[name], result.values[name], result.intervals[name]
        assert abs(start - value) > 20 * half, name  # the start is far outside the interval: the fit had to move
        assert abs(got - value) <= half, f"{name}: truth {value:.6g}, recovered {got:.6g} +- {half:.3g}"
        assert 0 < half < 0.02 * abs(value), name
    assert result.fit_on == "held-out" and result.fit_after["pitch"][0] > result.fit_before["pitch"][0] + 20
    assert result.fit_after["pitch"][0] > 95.0
    assert result.all_met, result.problems


@pytest.mark.slow
def test_with_gusts_the_sandwich_intervals_hold_the_truth_where_the_white_ones_do_not(known_truth):
    """Gusts at the project's level make the residuals correlated over seconds: the white-noise
    intervals miss the truth, the sandwich intervals (the reported ones) hold it."""
    spec, truth, _, (fit_rec, held) = known_truth
    result = calibrate_records([fit_rec], list(HIDDEN), spec, held_out=[held], max_iters=20)
    assert result.bandwidth > 10
    missed_by_white = 0
    for name, value in truth.items():
        got, half = result.values[name], result.intervals[name]
        assert abs(got - value) <= half, f"{name}: truth {value:.6g}, recovered {got:.6g} +- {half:.3g}"
        assert abs(got - value) <= 0.1 * abs(value), name
        missed_by_white += abs(got - value) > result.white_intervals[name]
    assert missed_by_white >= 2
    assert result.fit_after["pitch"][0] > result.fit_before["pitch"][0] + 20


@pytest.mark.slow
def test_the_transport_delay_is_fitted_by_its_profile(known_truth):
    """The delay acts in whole physics steps: the profile finds it, with the motor it trades off against."""
    spec = known_truth[0]
    hidden = {"main_motor_lag": 0.9, "main_motor_gain": 1.1, "input_delay": 1.2}
    truth_spec = scaled_spec(spec, hidden)
    truth = read_parameters(truth_spec, list(hidden))
    fit_rec, held = _truth_records(truth_spec, (5, 6), gust_scale=0.0, still_air=True)
    result = calibrate_records([fit_rec], list(hidden), spec, held_out=[held], max_iters=20)
    assert result.profile_fits >= 3
    step = Twin("1dof", TS, spec=spec).model.opt.timestep
    assert abs(result.values["input_delay"] - truth["input_delay"]) <= 2 * step
    for name, value in truth.items():
        assert abs(result.start[name] - value) > result.intervals[name], name  # the fit had to move
        got, half = result.values[name], result.intervals[name]
        assert abs(got - value) <= half, f"{name}: truth {value:.6g}, recovered {got:.6g} +- {half:.3g}"
    assert result.fit_after["pitch"][0] > 95.0


def test_the_start_model_predicts_its_own_noise_free_record_exactly():
    """The custom rollout (thrust curve, zero-order hold, trim start) is the twin, bit for bit up to rounding."""
    spec = load_spec()
    twin = Twin("1dof", TS, 0, spec=spec, counts_per_rev=0, still_air=True)
    u = twin.operating_point.inputs[0] + random_binary(6.0, TS, 0.5, 0.15, seed=3)
    rec = twin.run(u[:, None])
    result = calibrate_records([rec], ["main_motor_lag"], spec, max_iters=3)
    assert result.values["main_motor_lag"] == pytest.approx(result.start["main_motor_lag"], rel=1e-6)
    assert result.fit_before["pitch"][0] > 99.999


def test_records_of_another_configuration_or_without_one_are_refused():
    twin = Twin("2dof", TS, 0)
    rec = twin.run(np.tile(twin.operating_point.inputs, (10, 1)))
    with pytest.raises(
        ConfigurationError, match="record record 0 was taken in configuration '2dof'; the model is calibrated in '1dof'"
    ):
        calibrate_records([rec], config="1dof")
    bare = Record(rec.time, rec.inputs, rec.outputs, rec.input_names, rec.output_names)
    with pytest.raises(InputError, match="record record 0 has no 'config' in its metadata"):
        calibrate_records([bare])
    with pytest.raises(InputError, match="unknown parameter 'mass'"):
        calibrate_records([rec], ["mass"])
    for bad in (0, -3):
        with pytest.raises(InputError, match=rf"max_iters = {bad} is outside the allowed range \[1, 1000\]"):
            calibrate_records([rec], max_iters=bad)


def _one_dof(n=40, ts=0.1, seed=0, **meta):
    twin = Twin("1dof", ts, seed, counts_per_rev=0)
    u = twin.operating_point.inputs[0] + random_binary(n * ts, ts, 0.5, 0.1, seed=seed)
    rec = twin.run(u[:, None])
    rec.metadata.update(meta)
    return rec


@pytest.mark.parametrize(
    "change, match",
    [
        (
            lambda r: r.inputs.__setitem__((10, 0), np.nan),
            r"record b: input 'u1' is NaN in 1 sample\(s\), first at row 10",
        ),
        (
            lambda r: r.outputs.__setitem__((slice(3, 5), 0), np.inf),
            r"output 'pitch' is \+inf in 2 sample\(s\), first at",
        ),
        (
            lambda r: r.metadata.update(start_time=12.5) or r.outputs.__setitem__((4, 0), np.nan),
            r"row 4 \(t = 12.9 s\)",
        ),
    ],
)
def test_records_with_a_nan_or_inf_sample_are_refused_naming_row_and_time(change, match):
    a, b = _one_dof(seed=1), _one_dof(seed=2)
    change(b)
    with pytest.raises(InputError, match=match):
        calibrate_records([a, b], ["main_motor_gain"], labels=["a", "b"])


def test_records_given_twice_or_at_two_sample_times_are_refused_as_such():
    a, b, slow = _one_dof(seed=1), _one_dof(seed=2), _one_dof(20, 0.2, seed=3)
    with pytest.raises(InputError, match="record a is given twice: a record given twice counts twice"):
        calibrate_records([a, a], labels=["a", "a"])
    with pytest.raises(InputError, match="record b holds the same samples as record a"):
        calibrate_records([a, a], labels=["a", "b"])
    with pytest.raises(
        InputError, match="held-out record c holds the same samples as record a: a held-out record must"
    ):
        calibrate_records([a, b], held_out=[a], labels=["a", "b"], held_out_labels=["c"])
    with pytest.raises(
        InputError, match="record s is sampled every 0.2 s, record a every 0.1 s; calibrate the records"
    ):
        calibrate_records([a, slow], labels=["a", "s"])


def test_one_iteration_is_counted_as_one_and_moves_the_parameters():
    """``max_iters=1``: the optimiser takes its one step (its own line says 'after 0 iterations')."""
    truth = scaled_spec(load_spec(), {"main_motor_gain": 1.3})
    twin = Twin("1dof", 0.1, 0, spec=truth, counts_per_rev=0, still_air=True)
    u = twin.operating_point.inputs[0] + random_binary(12.0, 0.1, 0.5, 0.1, seed=4)
    result = calibrate_records([twin.run(u[:, None])], ["main_motor_gain"], max_iters=1)
    assert result.iterations == 1 and result.failures == []
    assert result.stopped.startswith("maximum iterations reached")
    assert result.values["main_motor_gain"] != result.start["main_motor_gain"]
    assert result.fit_after["pitch"][0] > result.fit_before["pitch"][0]


@pytest.mark.slow
def test_trms_calibrate_records_writes_a_new_model_the_report_and_the_sysid_html(known_truth, tmp_path):
    _, _, (fit_rec, held), _ = known_truth
    fit_rec.save(tmp_path / "rig1.npz")
    held.save(tmp_path / "rig2.npz")
    shipped = DEFAULT_MODEL_PATH.read_bytes()
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "trms.cli",
            "calibrate",
            "--records",
            "rig1.npz",
            "--held-out",
            "rig2.npz",
            "--parameters",
            "main_motor_lag",
            "main_motor_gain",
            "--max-iters",
            "10",
            "--out",
            "cal",
            "--accept-unmet",
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stderr
    report = json.loads((tmp_path / "cal" / "calibration.json").read_text())
    assert set(report["parameters"]) == {"main_motor_lag", "main_motor_gain"}
    assert report["fit_percent"]["on"] == "held-out" and "95 % interval" in res.stdout
    written = read_parameters(load_spec(tmp_path / "cal" / "trms.xml"), ["main_motor_lag", "main_motor_gain"])
    for name, value in written.items():
        assert value == pytest.approx(report["parameters"][name]["calibrated"], rel=1e-5)
    assert (tmp_path / "cal" / "sysid" / "report.html").stat().st_size > 10_000
    assert DEFAULT_MODEL_PATH.read_bytes() == shipped


def _calibrate_cli(cwd, *args):
    return subprocess.run(
        [sys.executable, "-m", "trms.cli", "calibrate", *args, "--out", "cal", "--quiet"],
        cwd=cwd,
        capture_output=True,
        text=True,
    )


def test_trms_calibrate_continues_from_a_feasible_start_when_the_start_runs_into_an_end_stop(tmp_path):
    """The faked rig driven at +-0.25 V: the shipped model, driven by its voltages, runs into the pitch stop
    that the rig never reaches; the fit goes on from the seeded coarse stage's best candidate, and says so."""
    _, (fit_rec, held) = faked_rig_records("1dof", 0.25, 10.0, ("prbs", "doublets"))
    to_rig_csv(fit_rec, tmp_path / "rig1.csv")
    to_rig_csv(held, tmp_path / "rig2.csv")
    res = _calibrate_cli(
        tmp_path,
        "--records",
        "rig1.csv",
        "--held-out",
        "rig2.csv",
        *("--time", "Time [s]", "--inputs", "Main motor [V]", "--outputs", "Pitch [deg]", "--units", "deg"),
        *("--hover", "0:0.1", "--config", "1dof", "--parameters", "main_motor_gain", "--max-iters", "5"),
    )
    report = json.loads((tmp_path / "cal" / "calibration.json").read_text())
    line = next(x for x in res.stdout.splitlines() if x.startswith("start: "))
    assert re.fullmatch(
        r"start: with the starting parameters it hits the pitch end stop \(\+1\.1 rad\) on record rig1\.csv at "
        r"\d+\.\d\d s, where the record stays within .* rad; the fit started from the best of 8 seeded "
        r"Latin-hypercube candidates that hits no stop the records do not reach",
        line,
    ), line
    assert report["start_candidates"] == 8 and report["iterations"] > 0
    p = report["parameters"]["main_motor_gain"]
    assert p["fit_start"] != p["start"] and p["calibrated"] != p["fit_start"]
    assert res.returncode in (0, 1, 3), res.stderr  # continued: its own verdict, not a refusal
    assert (res.returncode == 3) == bool(report["failed"]) and (tmp_path / "cal" / "trms.xml").exists() == (
        res.returncode != 3
    )


def test_trms_calibrate_exits_3_and_writes_no_model_when_the_optimiser_takes_no_step(tmp_path):
    """A record that the start reproduces to round-off: the gradient is zero, the optimiser takes no step."""
    twin = Twin("1dof", TS, 0, counts_per_rev=0, still_air=True)
    twin.run((twin.operating_point.inputs[0] + random_binary(4.0, TS, 0.5, 0.15, seed=3))[:, None]).save(
        tmp_path / "rig1.npz"
    )
    res = _calibrate_cli(tmp_path, "--records", "rig1.npz", "--parameters", "main_motor_lag", "--max-iters", "3")
    assert res.returncode == 3, res.stdout + res.stderr
    report = json.loads((tmp_path / "cal" / "calibration.json").read_text())
    assert report["iterations"] == 0 and not report["all_met"]
    assert "failed: the optimiser took no step (norm(gradient) < tol." in res.stdout
    assert "the start already reproduces the records" in res.stderr
    assert "no model written, exit status 3" in res.stdout
    assert not (tmp_path / "cal" / "trms.xml").exists()
