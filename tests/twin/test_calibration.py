"""Calibration: the shipped model meets the thesis's targets; calibration recovers known parameters."""

import json

import numpy as np
import pytest

from trms.errors import InputError
from trms.twin import Twin, load_spec
from trms.twin.calibration import THESIS_PROTOCOLS, Targets, calibrate, verify, write_report
from trms.twin.calibration.coupling import MARGIN
from trms.twin.calibration.elastic_modes import side_peak_evidence
from trms.twin.calibration.large_signal import large_signal_checks
from trms.twin.calibration.protocol import (
    FIT_SEEDS,
    VERIFY_SEEDS,
    Protocol,
    coherence_floor,
    coherence_nperseg,
    protocol_records,
    repeated_records,
    step_figures,
)
from trms.twin.calibration.tradeoffs import coupling_tradeoff, phase_step_tradeoff
from trms.twin.parameters import read_parameters, with_parameters


@pytest.fixture(scope="module")
def shipped_verification():
    return verify(load_spec(), Targets.thesis())


#: The targets the twin's structure cannot meet together with the others, each with the test that measures why.
TRADE_OFFS = {
    "1dof step delay (to 5 %)": "test_phase_and_the_step_delay_pull_against_each_other",
    "2dof u1->pitch PSD peak": "test_u1_pitch_at_0p1_hz_and_u2_pitch_coherence_pull_against_each_other",
}


def test_shipped_model_meets_every_thesis_target_at_unseen_seeds(shipped_verification):
    """The thesis's protocol on the nonlinear twin, encoder quantisation on, at five seeds no fit used.

    Every target is met at every seed, but for the trade-offs whose measurement is tested below.
    """
    assert set(shipped_verification.seeds).isdisjoint(FIT_SEEDS) and len(shipped_verification.seeds) == 5
    failed = {c.name for c in shipped_verification.checks if not c.met}
    assert failed <= set(TRADE_OFFS), failed


COHERENCE = "2dof u2->pitch median coherence 0.02-1 Hz"


def test_u2_pitch_coherence_stays_low_at_every_unseen_seed(shipped_verification):
    levels = [c.achieved for c in shipped_verification.checks if c.name == COHERENCE]
    assert len(levels) == 5 and max(levels) <= 0.3, levels
    names = {c.name for c in shipped_verification.checks}
    assert {
        "1dof ARMAX phase from (3.11), 0.02-1 Hz",
        "1dof step delay (to 5 %)",
        "2dof rest pitch, rotors off",
        "2dof u2->pitch RMS over u1->pitch's",
    } <= names


def test_phase_and_the_step_delay_pull_against_each_other(shipped_verification):
    """Within 30 deg of (3.11)'s phase, no motor lag and transport delay brings the step delay within 0.15 s of
    (3.11)'s own, while the phase is met at every unseen seed."""
    target = Targets.thesis().model
    ref_delay, _ = step_figures(target.system)
    scan = phase_step_tradeoff(load_spec())
    assert scan.best_step_delay > ref_delay + target.delay_tolerance_s
    phase = [c for c in shipped_verification.checks if c.name.startswith("1dof ARMAX phase")]
    assert phase and all(c.met for c in phase)


def test_step_targets_are_the_thesis_models_own_step():
    """The step targets are (3.11)'s figures: they meet the thesis's delay reading (0.6-0.7 s, fig. 3.3) but not its
    time-constant reading (about 1.2 s), which is why the twin is held to (3.11) rather than to the readings."""
    target = Targets.thesis().model
    delay, time_constant = step_figures(target.system)
    assert 0.6 <= delay <= 0.7
    assert abs(time_constant - 1.2) > target.time_constant_tolerance_s


def test_time_constant_met_at_every_unseen_seed(shipped_verification):
    checks = [c for c in shipped_verification.checks if c.name == "1dof step time constant (5 % to 63 %)"]
    assert len(checks) == 5 and all(c.met for c in checks), [c.achieved for c in checks]


def test_coherence_estimator_reads_unrelated_signals_below_the_low_threshold():
    """The targets' coherence (256-sample segments) reads two unrelated signals of the 2-DOF record's length well
    below 0.3; the PSD's 512-sample segments would read them at 0.3 itself."""
    n = int(round(THESIS_PROTOCOLS[1].duration_s / THESIS_PROTOCOLS[1].sample_time))
    _, p95 = coherence_floor(n, coherence_nperseg(n))
    mean_long, _ = coherence_floor(n, 512)
    assert p95 < 0.3 * 0.7 and mean_long > 0.3


def test_u1_pitch_at_0p1_hz_and_u2_pitch_coherence_pull_against_each_other():
    """The strongest yaw-rate coupling the bounds allow shows 0.1 Hz in u1 -> pitch at more seeds than the shipped
    coupling, and carries u2 into pitch: its coherence rises at every seed, beyond the room the fit keeps for unseen
    seeds, while the shipped coupling stays inside it."""
    result = coupling_tradeoff(load_spec())
    shipped, strongest = result["shipped"]["by_seed"], result["strongest"]["by_seed"]
    assert sum(r["0.1 Hz met"] for r in strongest.values()) > sum(r["0.1 Hz met"] for r in shipped.values())
    assert max(r["u2->pitch coherence"] for r in shipped.values()) < 0.3 * MARGIN
    assert max(r["u2->pitch coherence"] for r in strongest.values()) > 0.3 * MARGIN
    for seed, row in strongest.items():
        assert row["u2->pitch coherence"] > shipped[seed]["u2->pitch coherence"] + 0.1


def test_tolerances_can_fail():
    """The same checks reject a twin without its transport delay (phase and step delay) at the same seeds."""
    spec = with_parameters(load_spec(), {"input_delay": 0.0})
    v = verify(spec, Targets.thesis(), seeds=VERIFY_SEEDS[:1])
    failed = {c.name for c in v.checks if not c.met}
    assert {"1dof ARMAX phase from (3.11), 0.02-1 Hz", "1dof step delay (to 5 %)"} <= failed


def test_large_signals_follow_the_published_model():
    """Full thrust is the published rotor's: after the twin's transport delay, the times to pass +-1 rad at +-10 V
    are within 30 % of the published model's, and the +0.5 V step at the equivalent input settles and peaks within 30 %.
    The raw times include the delay the published model lacks: they exceed it by about the delay."""
    spec = load_spec()
    checks = large_signal_checks(spec)
    assert all(np.isfinite(c.twin) for c in checks)
    assert [c.name for c in checks if not c.met and ("equivalent" in c.name or "transport delay" in c.name)] == []
    delay = Twin("1dof", 0.1, spec=spec).input_delay
    for raw in (c for c in checks if c.name.endswith("10 V")):
        shifted = next(c for c in checks if c.name.startswith(raw.name + " after"))
        assert raw.twin - shifted.twin == pytest.approx(delay)


def test_the_side_peaks_are_settled_by_measurement():
    """No compliant element gives a defensible 0.25 Hz mode; a one-mode twin shows side peaks in light spectra."""
    evidence = side_peak_evidence(load_spec(), seeds=range(1000, 1040))
    for c in evidence["structural_candidates"]:
        loses_pitch_mode = not any(abs(f - 0.342) <= 0.03 for f in c["modes_1dof_hz"])
        leaks = [f for f in c["modes_2dof_hz"] if all(abs(f - g) > 0.03 for g in (0.1, 0.342))]
        assert not c["reached"] or loses_pitch_mode or leaks or abs(c["deflection_rad_per_volt"]) > 0.5, c
    rates = evidence["estimator_statistics"]["rates"]
    assert rates["full-record periodogram"]["0.25"] > rates["Welch, 256-sample segments"]["0.25"]


def test_the_fit_seeds_read_every_2dof_peak_of_the_shipped_twin():
    """The spectral fit scores candidates on the spectra averaged over FIT_SEEDS: there, the shipped twin's peaks
    must sit where verification finds them, or the fit cannot tell candidates apart on those targets."""
    from trms.twin.calibration.protocol import averaged_spectra, main_peaks

    spec, targets = load_spec(), Targets.thesis()
    for protocol in (p for p in THESIS_PROTOCOLS if p.config == "2dof"):
        records = repeated_records(spec, protocol, FIT_SEEDS)
        for t in targets.peaks:
            if t.config != "2dof" or not t.channel.startswith(protocol.excited):
                continue
            if t.channel == "u1->pitch" and t.frequency_hz < 0.2:
                continue  # the trade-off measured by test_u1_pitch_at_0p1_hz_and_u2_pitch_coherence_pull_...
            n = sum(1 for o in targets.peaks if o.config == t.config and o.channel == t.channel)
            f, p, _ = averaged_spectra(records, "pitch" if t.channel.endswith("pitch") else "yaw")
            assert min(abs(x - t.frequency_hz) for x in main_peaks(f, p, n)) <= t.tolerance_hz * MARGIN, t


def test_repeated_records_equal_the_runs_one_at_a_time():
    """Verification runs every seed's repeats side by side: each run is the same bits as when run alone."""
    protocol = Protocol("2dof", "u2", 2.0, 10.0, 0.05)
    together = repeated_records(load_spec(), protocol, seeds=(7, 1007, 8))
    for record, seed in zip(together, (7, 1007, 8)):
        alone = protocol_records([load_spec()], protocol, seed=seed)[0]
        assert record.metadata["seed"] == seed
        assert np.array_equal(record.outputs, alone.outputs) and np.array_equal(record.inputs, alone.inputs)
    assert not np.array_equal(together[0].outputs, together[2].outputs)


def test_calibration_recovers_known_parameters():
    """Perturb the shipped values, calibrate against the shipped model's own protocol runs, get them back.

    Tolerances: 10 % on the pitch-plane parameters (the targets are an ARMAX fit of 60 s of quantised
    data and PSD peaks interpolated in 0.039 Hz bins); 15 % on the cable stiffness, set by the yaw peak
    near 0.1 Hz, where one bin is 40 % of the frequency; 0.05 s on the delay (a quarter of a 0.2 s sample) and 15 %
    on the motor lag, which trade against each other in the 0.02-1 Hz phase the model target pins (measured: the delay
    came back 0.018 s short with the lag 12 % long).
    """
    shipped = load_spec()
    fit = ("counterweight_mass", "pitch_damping", "main_motor_gain", "main_motor_lag", "input_delay", "cable_stiffness")
    truth = read_parameters(shipped, fit)
    # Three runs of each protocol, as verification measures one experiment.
    records = [r for p in THESIS_PROTOCOLS for r in repeated_records(shipped, p, seeds=(0, 1000, 2000))]
    targets = Targets.from_records(records)
    perturbed = {k: v * f for (k, v), f in zip(truth.items(), (1.2, 0.7, 0.85, 1.25, 0.7, 0.8))}
    result = calibrate(targets, with_parameters(shipped, perturbed), linear=fit, coupling=())
    tol = {
        "counterweight_mass": 0.1,
        "pitch_damping": 0.1,
        "main_motor_gain": 0.1,
        "main_motor_lag": 0.15,
        "cable_stiffness": 0.15,
    }
    for name, value in truth.items():
        if name == "input_delay":
            assert result.values[name] == pytest.approx(value, abs=0.05)
        else:
            assert result.values[name] == pytest.approx(value, rel=tol[name]), name
        assert abs(result.values[name] / value - 1) < abs(perturbed[name] / value - 1)


def test_unreachable_user_targets_are_reported_with_the_closest_achieved(tmp_path):
    table = tmp_path / "modes.json"
    table.write_text(json.dumps({"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 0.9}]}))
    targets = Targets.load(table)
    result = calibrate(targets, linear=("counterweight_mass",), coupling=())
    assert result.values["counterweight_mass"] == pytest.approx(0.30)  # pinned at its upper bound
    assert len(result.unreachable) == 1
    assert result.unreachable[0].startswith("1dof u1->pitch PSD peak = 0.9 Hz: achieved 0.")
    assert "outside its tolerance at the best parameters the fit found within their bounds" in result.unreachable[0]
    js, png = write_report(result, tmp_path / "report")
    data = json.loads(js.read_text())
    assert data["unreachable"] == result.unreachable and data["all_met"] is False
    assert png.stat().st_size > 10_000


@pytest.mark.parametrize(
    "content, match",
    [
        ('{"peaks": [{"config": "1dof", "channel": "u2->pitch", "frequency_hz": 0.3}]}', "not 'INPUT->OUTPUT'"),
        ('{"peaks": [{"config": "4dof", "channel": "u1->pitch", "frequency_hz": 0.3}]}', "unknown configuration"),
        ('{"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": -1}]}', "outside the allowed range"),
        ('{"peaks": []}', "no peak or coherence targets"),
        ("not json", "not a target table"),
        ("[1, 2]", r"the table must be a JSON object, got \[1, 2\]"),
        (
            '{"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 0.34}], "coherence": []}',
            r"the table has unknown key\(s\) \['coherence'\]; allowed: \['coherences', 'peaks'\]",
        ),
        ('{"peaks": [{"config": "1dof", "channel": "u1->pitch", "freq_hz": 0.3}]}', r"peaks\[0\] has unknown key"),
        ('{"peaks": {"config": "1dof"}}', "'peaks' must be a list of objects"),
        ('{"peaks": [3]}', r"peaks\[0\] must be a JSON object, got 3"),
    ],
)
def test_bad_target_tables(tmp_path, content, match):
    path = tmp_path / "t.json"
    path.write_text(content)
    with pytest.raises(InputError, match=match):
        Targets.load(path)


def test_calibration_candidates_run_as_dask_tasks_with_the_same_scores():
    """The spectral stage's candidates as Dask tasks: identical with 1 and 2 workers, equal to the in-process batch."""
    from trms.twin.calibration.coupling import _evaluate_candidates
    from trms.twin.calibration.protocol import Protocol

    protocols = (Protocol("2dof", "u1", 2.0, 30.0, 0.05), Protocol("2dof", "u2", 2.0, 30.0, 0.05))
    spec, targets = load_spec(), Targets.thesis()
    candidates = [{"main_rotor_tilt": 0.0}, {"main_rotor_tilt": 0.2}]
    here = _evaluate_candidates(spec, candidates, targets, protocols, None, None)
    one, two = (
        _evaluate_candidates(
            spec, candidates, targets, protocols, None, {"workers": w, "processes": False, "progress": False}
        )
        for w in (1, 2)
    )
    for a, b in zip(one, two):
        assert np.array_equal(a, b)
    for a, b in zip(here, one):
        np.testing.assert_allclose(a, b, rtol=1e-6, atol=1e-9)


def test_the_summary_keeps_two_peak_targets_of_one_channel_apart():
    """The thesis's 2-DOF u1 -> pitch has two peak targets: each is its own row, with its own achieved values."""
    from trms.twin.calibration.verify import Check, Verification

    targets = [p for p in Targets.thesis().peaks if (p.config, p.channel) == ("2dof", "u1->pitch")]
    assert len(targets) == 2 and targets[0].name == targets[1].name
    checks = [
        Check(t.name, t.frequency_hz, t.frequency_hz + 0.01 * k, "", k == 0, "Hz", seed=seed)
        for seed in (101, 102)
        for k, t in enumerate(targets)
    ]
    rows = Verification(checks, seeds=(101, 102)).summary()
    assert [r["target"] for r in rows] == [t.frequency_hz for t in targets]
    assert [r["met"] for r in rows] == [True, False]
    assert rows[1]["achieved"] == {"101": targets[1].frequency_hz + 0.01, "102": targets[1].frequency_hz + 0.01}


def test_a_row_measured_once_shows_its_value_once():
    """The rest pose has no seed: the table shows it under the first seed, not as if measured at each."""
    from trms.twin.calibration.verify import Check, Verification

    v = Verification(
        [Check("peak", 0.34, 0.33, "", True, "Hz", seed=s) for s in (101, 102)]
        + [Check("2dof rest pitch, rotors off", -0.62, -0.6, "", True, "rad")],
        seeds=(101, 102),
    )
    peak, rest = v.summary()
    assert v.seed_cells(peak) == [0.33, 0.33] and v.seed_cells(rest) == [-0.6, None]


def test_the_printed_table_states_the_large_signal_tolerance_it_checks(monkeypatch):
    from trms.twin.calibration import large_signal, report
    from trms.twin.calibration.calibrate import CalibrationResult
    from trms.twin.calibration.verify import Verification

    check = large_signal.LargeSignalCheck("time to pass +1 rad at +10 V", 1.0, 1.25, "s")
    result = CalibrationResult({}, {}, Verification([]), [], {}, Targets.thesis(), large_signal=[check])
    assert f"within {100 * large_signal.TOLERANCE:g} % |" in report.format_table(result)
    monkeypatch.setattr(report, "TOLERANCE", 0.25)
    table = report.format_table(result)
    assert "within 25 % |" in table
    assert table.splitlines()[-1].endswith(f"| {'yes' if check.met else 'no'} |")


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"seeds": ()}, "verify needs at least one seed"),
        ({"repeats": 0}, r"repeats = 0 is outside the allowed range \[1, 100\]"),
        ({"seeds": (101, 1101), "repeats": 2}, "use a run twice"),
        ({"seeds": (FIT_SEEDS[0],)}, "are fit seeds"),
    ],
)
def test_verify_refuses_seeds_that_are_not_independent_unseen_experiments(kwargs, message):
    with pytest.raises(InputError, match=message):
        verify(load_spec(), Targets.thesis(), **kwargs)


def test_the_thesis_target_notes_state_the_figures_of_the_model_they_hold_the_twin_to(monkeypatch):
    """The notes' numbers come from the reference model and the targets: another (3.11) gives other notes."""
    import control

    from trms import reference

    original = reference.eq_3_11()
    monkeypatch.setattr(reference, "eq_3_11", lambda: 2.0 * original)
    targets = Targets.thesis()
    model = targets.model.system
    gain = float(np.ravel(model.dcgain())[0])
    assert gain == pytest.approx(2.0 * float(np.ravel(control.dcgain(original))[0]))
    assert f"the DC gain {gain:.3g} rad/V" in targets.notes["model gain"]
    delay, time_constant = step_figures(model)
    assert f"({delay:.3g} s and {time_constant:.3g} s)" in targets.notes["model step"]
    rest = targets.rest
    assert f"pitch {rest.pitch:g} +- {rest.tolerance:g} rad" in targets.notes["rest"]


def test_the_evidence_tables_name_the_side_peaks_and_modes_of_the_targets(monkeypatch):
    """The report's evidence tables take their frequencies from the targets (the measurements are stubbed here)."""
    import importlib

    from trms.twin.calibration import elastic_modes, large_signal, report, targets
    from trms.twin.calibration.verify import Verification

    verify_module = importlib.import_module("trms.twin.calibration.verify")  # the package exports the function

    stats = {"n_seeds": 2, "window_hz": 0.03, "rates": {"a": {"0.2": 0.5, "0.5": 0.0}}, "both": {"a": 0.0}}
    monkeypatch.setattr(targets, "SIDE_PEAKS_HZ", (0.2, 0.5))
    monkeypatch.setattr(report, "SIDE_PEAKS_HZ", (0.2, 0.5))
    monkeypatch.setattr(verify_module, "verify", lambda spec, t: Verification([], seeds=(101,)))
    monkeypatch.setattr(
        elastic_modes, "side_peak_evidence", lambda spec: {"estimator_statistics": stats, "structural_candidates": []}
    )
    monkeypatch.setattr(large_signal, "large_signal_checks", lambda spec: [])
    monkeypatch.setattr(report, "tradeoff_tables", lambda spec: [])
    monkeypatch.setattr(report, "coherence_floor_note", lambda: "floor")
    tables, _ = report.shipped_model_tables(load_spec(), evidence=True)
    est, struct = tables[2], tables[3]
    assert "near 0.2 Hz or 0.5 Hz" in est.notes[0] and struct.title.startswith("Compliant elements tuned for a 0.2 Hz")
    thesis = Targets.thesis()
    two = " and ".join(f"{f:g}" for f in sorted({p.frequency_hz for p in thesis.peaks if p.config == "2dof"}))
    assert f"lists only {two} Hz in 2-DOF" in struct.notes[0]
