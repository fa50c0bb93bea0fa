"""Calibration: the shipped model meets the thesis's targets; calibration recovers known parameters."""

import json

import numpy as np
import pytest

from trms.calibration import Targets, calibrate, verify, write_report
from trms.calibration.coupling import MARGIN
from trms.calibration.large_signal import large_signal_checks
from trms.errors import InputError
from trms.measurement.protocol import FIT_SEEDS, THESIS_PROTOCOLS, VERIFY_SEEDS, Protocol, repeated_records
from trms.measurement.step_response import step_figures
from trms.twin import Twin, load_spec
from trms.twin.parameters import read_parameters, with_parameters


@pytest.fixture(scope="module")
def shipped_verification():
    """The shipped model's verification at the ten unseen seeds, as the store beside it holds it: current for this
    model and code (its fingerprint), and equal to a fresh verification at the seeds the store's test recomputes
    (``test_the_shipped_evidence_is_current_and_equals_a_fresh_verification``); a stale store is measured again."""
    from trms.calibration.evidence import measured_targets

    return measured_targets(load_spec(), side_peaks=False)[0]


#: At how many of the ten unseen seeds every seeded target must hold.
AT_LEAST = 9


def test_shipped_model_meets_every_thesis_target_at_unseen_seeds(shipped_verification):
    """The thesis's protocols on the nonlinear twin with its ambient excitation and encoder, at ten seeds no fit used:
    every target is met at nine of the ten at least, every seedless one (rest pose, gyroscopic coupling) outright."""
    v = shipped_verification
    assert set(v.seeds).isdisjoint(FIT_SEEDS) and len(v.seeds) == 10
    for row in v.summary():
        met, judged = v.met_at(row["name"], row["target"])
        assert met >= (AT_LEAST if judged == 10 else judged), (row["name"], row["target"], row["achieved"])
    names = {c.name for c in v.checks}
    for expected in (
        "2dof u2->pitch RMS (encoder counts)",
        "2dof hover pitch RMS, constant inputs",
        "1dof ARMAX residual variance (Table 5.1)",
        "1dof step dead time (tangent)",
        "1dof step fit to (3.11)'s (NRMSE, 0-15 s)",
        "2dof pitch torque per yaw rate at hover",
    ):
        assert expected in names


COHERENCE = "2dof u2->pitch median coherence 0.02-1 Hz"


def test_u2_pitch_is_low_in_coherence_while_the_pitch_encoder_moves(shipped_verification):
    """u2 -> pitch's low coherence is a measurement: the pitch encoder moves by several counts in u2's protocol
    (the rig's ambient excitation and the yaw-rate coupling), and what moves it is mostly not u2."""
    v = shipped_verification
    levels = [c.achieved for c in v.checks if c.name == COHERENCE]
    counts = [c.achieved for c in v.checks if c.name == "2dof u2->pitch RMS (encoder counts)"]
    assert len(levels) == len(counts) == 10
    assert max(levels) <= 0.3 and min(counts) >= 3.0, (levels, counts)


def test_u1_pitch_shows_the_yaw_mode_through_the_gyroscopic_coupling():
    """With the rotor's lean removed (no yaw-rate-to-pitch torque), the 2-DOF u1 -> pitch spectrum loses its 0.1 Hz
    peak at most seeds that the shipped twin shows it at: the coupling, not a ripple, puts it there."""
    targets = Targets.thesis()
    targets.model = targets.rest = targets.ambient = targets.coupling = None
    targets.coherences, targets.ratios, targets.movements = [], [], []
    targets.peaks = [
        p for p in targets.peaks if (p.config, p.channel) == ("2dof", "u1->pitch") and p.frequency_hz < 0.2
    ]
    protocols = [p for p in THESIS_PROTOCOLS if (p.config, p.excited) == ("2dof", "u1")]
    seeds = (101, 102, 103, 104)
    shipped = verify(load_spec(), targets, protocols, seeds=seeds)
    flat = verify(with_parameters(load_spec(), {"main_rotor_tilt": 0.0}), targets, protocols, seeds=seeds)
    assert sum(c.met for c in shipped.checks) == len(seeds)
    assert sum(c.met for c in flat.checks) <= 1


def test_the_gyroscopic_coupling_is_feedbacks_from_the_spinning_rotor():
    """The pitch torque per yaw rate at hover, from MuJoCo's dynamics, is the spinning rotor's: J w sin(lean) for the
    spin inertia J and hover speed w, within 30 % of Feedback's published Kgy M1 cos(psi) at its hover."""
    from trms.twin.published import gyroscopic_coupling

    twin = Twin("2dof", 0.1, still_air=True)
    m = twin.model
    spin = m.jnt_dofadr[m.joint("main_spin").id]
    inertia = 0.4 * 0.01 * read_parameters(load_spec(), ["main_rotor_inertia_radius"])["main_rotor_inertia_radius"] ** 2
    tilt = read_parameters(load_spec(), ["main_rotor_tilt"])["main_rotor_tilt"]
    gyro = inertia * twin.trim.qvel[spin] * np.sin(np.arctan(tilt))
    assert twin.yaw_rate_to_pitch_torque() == pytest.approx(gyro, rel=0.02)
    assert twin.yaw_rate_to_pitch_torque() == pytest.approx(gyroscopic_coupling(), rel=0.3)
    flat = Twin("2dof", 0.1, spec=with_parameters(load_spec(), {"main_rotor_tilt": 0.0}), still_air=True)
    assert abs(flat.yaw_rate_to_pitch_torque()) < 0.02 * gyro  # what is left: the beam's own Coriolis terms


def test_step_targets_are_read_the_same_way_on_3_11_and_on_the_twin(shipped_verification):
    """(3.11)'s own step by the tangent construction: dead time and time constant near 0.9 s each; its 5 % crossing
    (0.63 s) comes from the first-sample response that no transport-delayed plant has, and is examined, not held."""
    from trms import reference
    from trms.measurement.protocol import STEP_PROTOCOL
    from trms.measurement.step_response import system_step, tangent_figures

    dead, lag = tangent_figures(*system_step(reference.eq_3_11(), STEP_PROTOCOL.duration_s))
    assert 0.85 < dead < 1.0 and 0.85 < lag < 1.0
    delay, _ = step_figures(reference.eq_3_11())
    assert 0.6 <= delay <= 0.7 and abs(dead - delay) > Targets.thesis().model.dead_time_tolerance_s
    t, y = shipped_verification.step
    assert t[1] - t[0] == pytest.approx(float(reference.eq_3_11().dt))
    assert tangent_figures(t, y)[0] == pytest.approx(dead, abs=0.15)


def test_time_constant_met_at_every_unseen_seed(shipped_verification):
    checks = [c for c in shipped_verification.checks if c.name == "1dof step time constant (tangent)"]
    assert len(checks) == 10 and all(c.met for c in checks), [c.achieved for c in checks]


def _only(kind):
    """The thesis's targets of one kind (``"model"`` or ``"ambient"``): the same checks, only their protocols run."""
    targets = Targets.thesis()
    targets.peaks, targets.coherences, targets.ratios, targets.movements = [], [], [], []
    targets.rest = targets.coupling = None
    if kind == "model":
        targets.ambient = None
    else:
        targets.model = None
    return targets


def test_tolerances_can_fail(shipped_verification):
    """The same checks reject a twin without its transport delay (phase and step dead time), and a twin in still air
    (the ambient targets), at a seed where the shipped twin meets them."""
    seed = VERIFY_SEEDS[0]
    met = {c.name for c in shipped_verification.checks if c.seed == seed and c.met}
    delay = {"1dof ARMAX phase from (3.11), 0.02-1 Hz", "1dof step dead time (tangent)"}
    ambient = {"2dof hover pitch RMS, constant inputs", "1dof ARMAX residual variance (Table 5.1)"}
    assert delay | ambient <= met
    v = verify(with_parameters(load_spec(), {"input_delay": 0.0}), _only("model"), seeds=(seed,))
    assert delay <= {c.name for c in v.checks if not c.met}
    still = {"main_turbulence": 0.0, "tail_turbulence": 0.0, "pitch_encoder_noise": 0.0}
    v = verify(with_parameters(load_spec(), still), _only("ambient"), seeds=(seed,))
    assert ambient <= {c.name for c in v.checks if not c.met}


def test_large_signals_follow_the_published_model():
    """Full thrust is the published rotor's: after the twin's transport delay, the times to pass +-1 rad at +-10 V
    are within 30 % of the published model's, and the +0.5 V step at the equivalent input settles and peaks within 30 %.
    The raw times include the delay the published model lacks: they exceed it by about the delay."""
    from trms.calibration.evidence import measured_large_signal

    spec = load_spec()
    checks = large_signal_checks(spec)
    assert measured_large_signal(spec) == checks  # what the report reads: the shipped store holds the same bits
    assert all(np.isfinite(c.twin) for c in checks)
    assert [c.name for c in checks if not c.met and ("equivalent" in c.name or "transport delay" in c.name)] == []
    delay = Twin("1dof", 0.1, spec=spec).input_delay
    for raw in (c for c in checks if c.name.endswith("10 V")):
        shifted = next(c for c in checks if c.name.startswith(raw.name + " after"))
        assert raw.twin - shifted.twin == pytest.approx(delay)


def test_the_side_peaks_are_settled_by_measurement():
    """No compliant element gives a defensible 0.25 Hz mode; a one-mode twin shows side peaks in light spectra.

    Read from the evidence measured on this model with this code (100 seeds; its currency is the test below, and a
    stale store is measured again); the doctests of :mod:`trms.calibration.elastic_modes` run both measurements."""
    from trms.calibration.evidence import measured_targets

    evidence = measured_targets(load_spec())[1]
    assert evidence is not None and evidence["estimator_statistics"]["n_seeds"] == 100
    for c in evidence["structural_candidates"]:
        loses_pitch_mode = not any(abs(f - 0.342) <= 0.03 for f in c["modes_1dof_hz"])
        leaks = [f for f in c["modes_2dof_hz"] if all(abs(f - g) > 0.03 for g in (0.1, 0.342))]
        assert not c["reached"] or loses_pitch_mode or leaks or abs(c["deflection_rad_per_volt"]) > 0.5, c
    rates = evidence["estimator_statistics"]["rates"]
    assert rates["full-record periodogram"]["0.25"] > rates["Welch, 256-sample segments"]["0.25"]


def test_the_fit_seeds_read_every_2dof_peak_of_the_shipped_twin():
    """The spectral fit scores candidates on the spectra averaged over FIT_SEEDS: there, the shipped twin's peaks
    must sit where verification finds them, or the fit cannot tell candidates apart on those targets."""
    from trms.measurement.spectra import averaged_spectra, main_peaks

    spec, targets = load_spec(), Targets.thesis()
    for protocol in (p for p in THESIS_PROTOCOLS if p.config == "2dof"):
        records = repeated_records(spec, protocol, FIT_SEEDS)
        for t in targets.peaks:
            if t.config != "2dof" or not t.channel.startswith(protocol.excited):
                continue
            n = sum(1 for o in targets.peaks if o.config == t.config and o.channel == t.channel)
            f, p, _ = averaged_spectra(records, "pitch" if t.channel.endswith("pitch") else "yaw")
            assert min(abs(x - t.frequency_hz) for x in main_peaks(f, p, n)) <= t.tolerance_hz * MARGIN, t


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
    result = calibrate(targets, with_parameters(shipped, perturbed), linear=fit, coupling=(), seeds=VERIFY_SEEDS[:1])
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
        ('{"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": true}]}', "got True"),
        (
            '{"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 0.3, "frequency_hz": 0.4}]}',
            "key 'frequency_hz' appears twice",
        ),
        (
            '{"peaks": ['
            + ", ".join(['{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 0.3}'] * 1001)
            + "]}",
            "1001 peaks; allowed: up to 1000",
        ),
        ('{"peaks": ' + "[" * 100_000 + "]" * 100_000 + "}", "nested too deeply"),
        ('{"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 1' + "0" * 5000 + "}]}", "digits"),
        (
            '{"coherences": [{"config": "2dof", "channel": "u1->yaw", "level": "high", "threshold": 0.7, '
            '"band_hz": 3}]}',
            "band_hz must be two frequencies",
        ),
        (
            '{"coherences": [{"config": "2dof", "channel": "u1->yaw", "level": "high", "threshold": 0.7, '
            '"band_hz": [1.0, 0.5]}]}',
            "must rise",
        ),
        ('{"peaks": [{"config": "1dof", "channel": 5, "frequency_hz": 0.3}]}', "channel 5 is not 'INPUT->OUTPUT'"),
        (
            '{"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 0.3}, '
            '{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 0.3}]}',
            r"peaks\[1\] repeats peaks\[0\]",
        ),
    ],
)
def test_bad_target_tables(tmp_path, content, match):
    path = tmp_path / "t.json"
    path.write_text(content)
    with pytest.raises(InputError, match=match) as caught:
        Targets.load(path)
    assert "\n" not in str(caught.value) and len(str(caught.value)) < 400  # one line


def test_a_binary_or_oversized_target_file_is_one_line(tmp_path):
    path = tmp_path / "t.json"
    path.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(InputError, match="not UTF-8 text"):
        Targets.load(path)
    path.write_bytes(b" " * 1_000_001)
    with pytest.raises(InputError, match="allowed: up to 1000000"):
        Targets.load(path)


def test_calibration_candidates_run_as_dask_tasks_with_the_same_scores():
    """The spectral stage's candidates as Dask tasks: identical with 1 and 2 workers, equal to the in-process batch."""
    from trms.calibration.coupling import evaluate_candidates

    protocols = (Protocol("2dof", "u1", 2.0, 30.0, 0.05), Protocol("2dof", "u2", 2.0, 30.0, 0.05))
    spec, targets = load_spec(), Targets.thesis()
    candidates = [{"main_rotor_tilt": 0.3}, {"main_rotor_tilt": 0.35}]  # both inside the coupling target: both run
    here = evaluate_candidates(spec, candidates, targets, protocols, None, None)
    one, two = (
        evaluate_candidates(
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
    from trms.calibration.checks import Check
    from trms.calibration.verify import Verification

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
    from trms.calibration.checks import Check
    from trms.calibration.verify import Verification

    v = Verification(
        [Check("peak", 0.34, 0.33, "", True, "Hz", seed=s) for s in (101, 102)]
        + [Check("2dof rest pitch, rotors off", -0.62, -0.6, "", True, "rad")],
        seeds=(101, 102),
    )
    peak, rest = v.summary()
    assert v.seed_cells(peak) == [0.33, 0.33] and v.seed_cells(rest) == [-0.6, None]


def test_the_printed_table_states_the_large_signal_tolerance_it_checks(monkeypatch):
    from trms.calibration import large_signal, report
    from trms.calibration.calibrate import CalibrationResult
    from trms.calibration.verify import Verification

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
    assert f"crosses 5 % of its final value at {delay:.3g} s" in targets.notes["model step"]
    assert f"in {time_constant:.3g} s" in targets.notes["model step"]
    rest = targets.rest
    assert f"pitch {rest.pitch:g} +- {rest.tolerance:g} rad" in targets.notes["rest"]


def test_the_evidence_tables_name_the_side_peaks_and_modes_of_the_targets(monkeypatch):
    """The report's evidence tables take their frequencies from the targets (the measurements are stubbed here)."""
    from trms.calibration import evidence, large_signal, report, targets
    from trms.calibration.verify import Verification

    stats = {"n_seeds": 2, "window_hz": 0.03, "rates": {"a": {"0.2": 0.5, "0.5": 0.0}}, "both": {"a": 0.0}}
    monkeypatch.setattr(targets, "SIDE_PEAKS_HZ", (0.2, 0.5))
    monkeypatch.setattr(report, "SIDE_PEAKS_HZ", (0.2, 0.5))
    side = {"estimator_statistics": stats, "structural_candidates": []}
    monkeypatch.setattr(evidence, "measured_targets", lambda spec, side_peaks: (Verification([], seeds=(101,)), side))
    monkeypatch.setattr(large_signal, "large_signal_checks", lambda spec: [])
    monkeypatch.setattr(report, "coherence_floor_note", lambda: "floor")
    tables, _ = report.shipped_model_tables(load_spec(), evidence=True)
    est, struct = tables[2], tables[3]
    assert "near 0.2 Hz or 0.5 Hz" in est.notes[0] and struct.title.startswith("Compliant elements tuned for a 0.2 Hz")
    thesis = Targets.thesis()
    two = " and ".join(f"{f:g}" for f in sorted({p.frequency_hz for p in thesis.peaks if p.config == "2dof"}))
    assert f"lists only {two} Hz in 2-DOF" in struct.notes[0]


# ------------------------------------------------------------------ the measurements' store
#: The unseen seeds the store's test verifies afresh: each seed is its own experiment (its own runs, bit-identical
#: in any batch), so its checks, spectra, ARMAX model and step must equal the store's for that seed.
FRESH_SEEDS = VERIFY_SEEDS[:2]


def test_the_shipped_evidence_is_current_and_equals_a_fresh_verification(shipped_verification):
    """The store shipped beside the model holds this model's and this code's measurements, the same bits as the
    verification computed now: the report and the tests may read it instead of measuring again."""
    from trms.calibration.evidence import SHIPPED_PATH, fingerprint, measured_targets

    stored = json.loads(SHIPPED_PATH.read_text())
    assert stored["fingerprint"] == fingerprint(load_spec()), (
        "the shipped model or the code changed since trms/models/evidence.json was written: "
        "python -m trms.calibration.evidence"
    )
    cached, side_peaks = measured_targets(load_spec())
    assert cached.to_dict() == shipped_verification.to_dict() == stored["verification"]
    assert side_peaks is not None and side_peaks["estimator_statistics"]["n_seeds"] == 100
    fresh = verify(load_spec(), Targets.thesis(), seeds=FRESH_SEEDS).to_dict()
    kept = [c for c in stored["verification"]["checks"] if c["seed"] in FRESH_SEEDS or c["seed"] is None]
    assert len(kept) < len(stored["verification"]["checks"])  # the store holds other seeds too
    assert fresh == {**stored["verification"], "seeds": list(FRESH_SEEDS), "checks": kept}


def test_a_changed_model_is_measured_again_never_read_stale(tmp_path, monkeypatch):
    from trms.calibration import evidence

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    calls = []

    def fake(spec, side_peaks):
        calls.append(read_parameters(spec, ["pitch_damping"])["pitch_damping"])
        return {"verification": Verification([], seeds=(101,)).to_dict(), "side_peaks": {"n": len(calls)}}

    from trms.calibration.verify import Verification

    monkeypatch.setattr(evidence, "_compute", fake)
    changed = with_parameters(load_spec(), {"pitch_damping": 0.02})
    assert evidence.measured_targets(changed)[1] == {"n": 1} and calls == [0.02]
    assert evidence.measured_targets(changed)[1] == {"n": 1} and calls == [0.02]  # the user's cache holds it now
    other = with_parameters(load_spec(), {"pitch_damping": 0.021})
    assert evidence.measured_targets(other)[1] == {"n": 2} and calls == [0.02, 0.021]  # another model: another key
    assert len(list((tmp_path / "trms").glob("evidence-*.json"))) == 2
    # a record without the large-signal checks (this fake's) is not read for them: they are measured on the model
    assert evidence.measured_large_signal(changed) == evidence.large_signal_checks(changed)
