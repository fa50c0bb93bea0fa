"""The protocol records' spectra: the coherence estimator's floor on unrelated signals, the Welch peaks of a known
mode."""

from trms.measurement.protocol import THESIS_PROTOCOLS
from trms.measurement.spectra import coherence_floor, coherence_nperseg


def test_coherence_estimator_reads_unrelated_signals_below_the_low_threshold():
    """The targets' coherence (256-sample segments) reads two unrelated signals of the 2-DOF record's length well
    below 0.3; the PSD's 512-sample segments would read them at 0.3 itself."""
    n = int(round(THESIS_PROTOCOLS[1].duration_s / THESIS_PROTOCOLS[1].sample_time))
    _, p95 = coherence_floor(n, coherence_nperseg(n))
    mean_long, _ = coherence_floor(n, 512)
    assert p95 < 0.3 * 0.7 and mean_long > 0.3
