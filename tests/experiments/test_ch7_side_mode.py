"""The 0.25 Hz mode the thesis blames for its low-pass finding: its size, its plant, the evidence, the verdicts."""

import control
import numpy as np
import pytest

from trms.errors import InputError
from trms.experiments import ch7_findings as findings
from trms.experiments import ch7_side_mode as sm
from trms.experiments.ch67_lqg import CaseResult
from trms.reference import eq_3_11
from trms.twin import Twin


@pytest.fixture(scope="module")
def twin():
    return Twin("1dof", 0.2)


def test_thesis_damping_is_the_lightly_damped_pair_of_eq_3_11():
    f, zeta = sm.thesis_damping()
    # f is the damped frequency: s = 2 pi f (-zeta / sqrt(1 - zeta^2) + j)
    z = np.exp(2 * np.pi * f * (-zeta / np.sqrt(1 - zeta**2) + 1j) * 0.2)
    assert np.min(np.abs(np.asarray(control.poles(eq_3_11())) - z)) < 1e-9
    assert 0.3 < f < 0.4 and 0.0 < zeta < 0.1


def test_mode_size_equalises_the_two_peaks_on_a_known_plant():
    # a plant with one lightly damped mode at 0.34 Hz: the added 0.25 Hz mode is sized to the same peak
    w1, zeta = 2 * np.pi * 0.34, 0.05
    plant = control.ss(control.tf([w1**2], [1, 2 * zeta * w1, w1**2]))
    g = sm.side_mode_gain(plant)
    low, high, f_main = sm.mode_peaks(control.parallel(plant, sm._mode(g, 0.25, sm.thesis_damping()[1])))
    assert low == pytest.approx(high, rel=1e-6)
    assert f_main == pytest.approx(0.34, abs=0.005)
    # two well-separated light modes: each peak is about its own DC gain / (2 zeta)
    assert g / (2 * sm.thesis_damping()[1]) == pytest.approx(1 / (2 * zeta), rel=0.25)


def test_loop_plant_without_a_mode_is_the_twins_linearisation_and_the_mode_adds_its_dc_gain(twin):
    plain = sm.loop_plant(twin)
    lin = twin.linearise().discrete
    np.testing.assert_allclose(plain.system.A, lin.A, atol=1e-12)
    np.testing.assert_allclose(plain.system.B, lin.B, atol=1e-12)
    moded = sm.loop_plant(twin, 0.5)
    assert float(control.dcgain(moded.system)) == pytest.approx(float(control.dcgain(lin)) + 0.5, rel=1e-6)
    assert moded.system.nstates == lin.nstates + 2
    assert plain.operating_point.inputs == pytest.approx(twin.operating_point.inputs)


def test_bad_sizes_are_refused_with_one_line(twin):
    with pytest.raises(InputError, match=r"gain = -1.0 rad/V is outside"):
        sm.loop_plant(twin, -1.0)
    with pytest.raises(InputError, match="frequency_hz"):
        sm.side_mode_gain(twin.linearise().continuous, 0.5)


def test_evidence_holds_both_plants_with_the_mode_at_the_main_peak(side_mode_evidence):
    ev = side_mode_evidence
    assert set(ev.results) == set(sm.VARIANTS)
    plain, moded = (ev.peaks[v] for v in sm.VARIANTS)
    assert moded[0] == pytest.approx(moded[1], rel=1e-6)  # the mode's peak equals the main peak
    assert plain[0] < plain[1]  # the twin alone has no peak at 0.25 Hz as high as its main one
    assert ev.prefilter_db["CSAS LPF 0.3 Hz"] > ev.prefilter_db["CSAS LPF 0.2 Hz"]  # 0.3 Hz passes more at 0.25 Hz
    for res in ev.results.values():
        assert {k[1] for k in res} == set(sm.LPF_CASES)


# ------------------------------------------------------------------------------ the findings' criteria
def _case(overshoot=5.0, ts=8.0, peak=1.0, limit=9.0, control_="ok", status="settled"):
    summary = {"overshoot": overshoot, "TS": ts, "peak": peak, "limit": limit, "control": control_, "step": 0.4}
    return CaseResult(status, summary, None)


def _runs(lpf2=(5.0, 8.0), lpf3=(6.0, 9.0), weights=(75.0, 100.0, 125.0)):
    out = {}
    for r in weights:
        out[(r, "CSAS LPF 0.2 Hz")] = _case(*lpf2)
        out[(r, "CSAS LPF 0.3 Hz")] = _case(*lpf3)
    return out


def _evidence(plain_worse: bool, moded_worse: bool, calm_worse: bool | None = None) -> sm.SideModeEvidence:
    better, worse = ((5.0, 8.0), (4.0, 7.0)), ((5.0, 8.0), (6.0, 9.0))
    pick = {sm.VARIANTS[0]: worse if plain_worse else better, sm.VARIANTS[1]: worse if moded_worse else better}
    return sm.SideModeEvidence(
        0.25,
        0.04,
        0.5,
        {v: (1.0, 2.0, 0.34) for v in sm.VARIANTS},
        {"CSAS LPF 0.2 Hz": -5.0, "CSAS LPF 0.3 Hz": -2.0},
        {v: _runs(*pick[v]) for v in sm.VARIANTS},
        {} if calm_worse is None else _runs(*(worse if calm_worse else better)),
    )


def test_the_lpf_criterion_can_fail_and_then_carries_its_verdict():
    rig = [75.0, 100.0, 125.0]
    shown, _, (d_os, d_ts) = findings._lpf_worse(_runs(), rig)
    assert shown and d_os == pytest.approx(1.0) and d_ts == pytest.approx(1.0)
    mixed = _runs()
    mixed[(125.0, "CSAS LPF 0.3 Hz")] = _case(4.0, 9.0)  # better overshoot at one R: not shown
    assert not findings._lpf_worse(mixed, rig)[0]
    assert findings._lpf_explanation(_evidence(False, True), rig).endswith("the 0.25 Hz mode the twin does not have.")
    assert "not explained" in findings._lpf_explanation(_evidence(True, True), rig)  # no still-air run: unseparated
    calm = findings._lpf_explanation(_evidence(True, True, True), rig)
    assert calm.endswith("the ambient excitation of the twin's run hides it.")
    partly = findings._lpf_explanation(_evidence(True, True, False), rig)
    assert "explained in part" in partly and "in still air: not shown" in partly
    assert findings._lpf_explanation(_evidence(True, False), rig).startswith("at 0.25 Hz")
    assert "not explained" in findings._lpf_explanation(_evidence(False, False), rig)


def test_the_saturation_finding_follows_its_criterion_and_its_explanation_holds_only_where_its_flight_shows_it():
    assert findings._saturation(_case(overshoot=20.0, peak=12.0, limit=9.0, control_="high")).shown
    unflown = findings._saturation(_case(overshoot=20.0, peak=1.0, limit=9.0))
    assert not unflown.shown and "+-1.8 rad" in unflown.explanation and "(literature" in unflown.explanation
    assert unflown.explanation.endswith("not explained (not flown there).") and not unflown.partly
    # the check: flown behind the PCI set-up's limit, the run saturates and overshoots (a planted pass) ...
    flight = (0.45, _case(overshoot=30.0, peak=3.0, limit=1.9, control_="high"))
    f = findings._saturation(_case(overshoot=20.0, peak=1.0, limit=9.0), flight)
    assert f.partly and not f.explained and "flown beyond it (pci_flight: +-0.45 rad behind +-2.5 V)" in f.explanation
    # ... or it does not (a planted failure): never printed as explained
    failed = findings._saturation(_case(overshoot=20.0, peak=1.0, limit=9.0), (0.45, _case(overshoot=30.0)))
    assert failed.explanation.endswith("not explained (the flight fails).") and not (failed.partly or failed.explained)
    low = findings._saturation(_case(overshoot=4.0, peak=1.0, limit=9.0), flight)
    assert low.explanation.endswith("not explained by the command amplitude.")  # the overshoot fails as well


def test_the_pci_flight_flies_the_twin_behind_the_pci_limit_where_the_finding_shows():
    from trms.experiments.ch67_lqg import PCI_LIMIT, lqg_cases
    from trms.worlds import design_model, make_plant

    model = design_model("1dof")
    run = lqg_cases(make_plant("twin", "1dof"), model, [75.0], ["SAS"])[(75.0, "SAS")]
    amplitude, flown = findings.pci_flight(model, run)
    trim = 10.0 - float(run.summary["limit"])
    assert amplitude == pytest.approx(findings.PCI_MARGIN * findings.first_at_limit(run, PCI_LIMIT, trim))
    # each side's peak against its own room: never below the nearer room against the larger peak
    assert findings.first_at_limit(run, PCI_LIMIT, trim) >= findings.amplitude_at_limit(run, PCI_LIMIT, trim) - 1e-12
    assert flown.record is None and float(flown.summary["limit"]) == pytest.approx(
        min(PCI_LIMIT - trim, PCI_LIMIT + trim)
    )
    assert flown.summary["control"] == "high"  # above the amplitude where its peak meets the limit: it saturates
    assert findings.pci_flight(model, CaseResult("diverged", {}, None)) is None
