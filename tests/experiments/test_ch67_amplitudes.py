"""Table 6.1's R = 1 cell at several amplitudes: the twin's response measured, explained only where its check holds."""

import pytest

from trms.experiments import ch67_amplitudes as am
from trms.experiments.ch67_lqg import STOP_ANGLE, CaseResult, pitch_plant
from trms.present.seeds import Seeded


def _run(status="settled", overshoot=300.0, excursion=0.1, peak=1.0):
    return CaseResult(status, {"overshoot": overshoot, "excursion": excursion, "peak": peak}, None)


def test_the_runs_scale_with_the_amplitude_on_a_linear_loop():
    """Known truth: on eq. (3.11) without noise the loop is linear below the limits, so its overshoot (%) is the same
    at every amplitude and its largest excursion grows in proportion."""
    p = pitch_plant()
    runs = am.amplitude_runs(p, p.system, 0, (0.02, 0.05))
    assert all(r.record is None and r.status == "settled" for r in runs.values())
    assert runs[0.05].summary["overshoot"] == pytest.approx(runs[0.02].summary["overshoot"], rel=1e-6)
    assert runs[0.05].summary["excursion"] == pytest.approx(2.5 * runs[0.02].summary["excursion"], rel=1e-6)


def test_the_note_states_every_amplitude_and_explains_only_when_the_small_signal_loop_matches():
    twin = Seeded((0, 1000), ({0.02: _run(), 0.2: _run("hit the stops", 800.0, 1.1, 9.0)},) * 2)
    matching = {0.02: _run(overshoot=280.0), 0.2: _run(overshoot=280.0, excursion=1.3)}
    note = am.amplitude_note("R = 1, twin", twin, matching)
    assert "+-0.02 rad: settled at 2, overshoot 300 %" in note and "+-0.2 rad: hit the stops at 2" in note
    assert note.endswith("explained by the twin's small-signal loop.") and "(linearised_runs)" in note
    # planted failures of the check: the small-signal overshoot far from the twin's, or no stops where it has them
    assert am.amplitude_note("c", twin, {0.02: _run(overshoot=71.0), 0.2: _run(excursion=1.3)}).endswith(
        "the check fails)."
    )
    below = am.amplitude_note("c", twin, {0.02: _run(overshoot=280.0), 0.2: _run(excursion=0.5 * STOP_ANGLE)})
    assert "not explained" in below and "explained by" not in below
    assert am.amplitude_note("c", twin, {}).endswith("not explained (no small-signal loop to compare).")


def test_the_twins_linearisation_flies_the_r1_loop_without_the_stops():
    from trms.worlds import design_model

    runs = am.linearised_runs(design_model("1dof"), (0.02,))
    assert runs[0.02].status in ("settled", "not settled") and runs[0.02].summary["excursion"] < STOP_ANGLE
