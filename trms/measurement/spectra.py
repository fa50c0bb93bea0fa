"""The spectra of protocol records: Welch PSD and coherence as the thesis measured them, and their peaks.

Segment lengths follow the record (:func:`psd_nperseg`, :func:`coherence_nperseg`); repeats of one protocol
are averaged bin by bin (:func:`averaged_spectra`); peaks are ranked by prominence (:func:`ranked_peaks`).
"""

from __future__ import annotations

import numpy as np

from trms.identification import spectral
from trms.measurement.protocol import VERIFY_REPEATS
from trms.record import Record

__all__ = [
    "NPERSEG",
    "NPERSEG_LONG",
    "COHERENCE_NPERSEG",
    "psd_nperseg",
    "coherence_nperseg",
    "coherence_floor",
    "channel_spectra",
    "averaged_spectra",
    "peaks_of",
    "ranked_peaks",
    "main_peaks",
]

#: Spectra: 256-sample Hann segments at 10 Hz (0.039 Hz bins) for the 60 s 1-DOF records; 512 (0.0195 Hz bins)
#: for the 120 s 2-DOF ones, whose 0.1 Hz yaw mode is a peak narrower than a 0.039 Hz bin (damping about 0.04:
#: half-power width 0.008 Hz) and would fall between two bins' centres (0.078 and 0.117 Hz).
NPERSEG = 256
NPERSEG_LONG = 512
#: Coherence, whatever the record length: 256-sample segments. Coherence needs averages more than resolution: for
#: signals with no relation at all, the estimate's median over 0.02-1 Hz is about ``1 / K`` for ``K`` segments, which
#: 512-sample segments of a 120 s record (3 segments) put at the 'low' threshold itself (:func:`coherence_floor`).
COHERENCE_NPERSEG = 256


def psd_nperseg(n_samples: int) -> int:
    """Welch segment length (samples) of a protocol record's PSD: 512 when the record holds two, else 256.

    Parameters
    ----------
    n_samples : int
        The record's length (samples).

    Returns
    -------
    int
        Segment length (samples), at most half the record.

    Examples
    --------
    >>> psd_nperseg(600), psd_nperseg(1200), psd_nperseg(300)
    (256, 512, 150)
    """
    return NPERSEG_LONG if n_samples >= 2 * NPERSEG_LONG else min(NPERSEG, n_samples // 2)


def coherence_nperseg(n_samples: int) -> int:
    """Welch segment length (samples) of a protocol record's coherence (:data:`COHERENCE_NPERSEG`).

    Parameters
    ----------
    n_samples : int
        The record's length (samples).

    Returns
    -------
    int
        Segment length (samples), at most half the record.

    Examples
    --------
    >>> coherence_nperseg(1200), coherence_nperseg(300)
    (256, 150)
    """
    return min(COHERENCE_NPERSEG, n_samples // 2)


def coherence_floor(
    n_samples: int,
    nperseg: int,
    repeats: int = VERIFY_REPEATS,
    band_hz: tuple[float, float] = (0.02, 1.0),
    sample_time: float = 0.1,
    trials: int = 200,
    seed: int = 0,
) -> tuple[float, float]:
    """What the coherence estimate reads for two unrelated signals: the median over ``band_hz`` of the
    coherence averaged over ``repeats`` runs, as :func:`averaged_spectra` and the targets measure it.

    Parameters
    ----------
    n_samples : int
        Record length (samples).
    nperseg : int
        Welch segment length (samples).
    repeats : int
        Runs whose coherence is averaged bin by bin.
    band_hz : (float, float)
        Band of the median (Hz).
    sample_time : float
        Sample time (s).
    trials : int
        Monte Carlo trials (independent white signals, seeded).
    seed : int

    Returns
    -------
    (float, float)
        Mean and 95th percentile over the trials (dimensionless).

    Examples
    --------
    >>> mean, p95 = coherence_floor(1200, 256, trials=50)
    >>> 0.05 < mean < p95 < 0.2
    True
    """
    # every trial's runs at once (the same draws, in the same order, as one trial and run after another)
    xy = np.random.default_rng(seed).standard_normal((trials, repeats, 2, n_samples))
    f, c = spectral.coherence(xy[:, :, 0], xy[:, :, 1], sample_time, nperseg=nperseg)
    band = (f >= band_hz[0]) & (f <= band_hz[1])
    levels = np.median(np.mean(c, axis=1)[:, band], axis=1)
    return float(levels.mean()), float(np.percentile(levels, 95))


def channel_spectra(
    record: Record, channel_output: str, psd_segment: int | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(f, PSD of the output deviation, coherence with the excited input)`` of one protocol record.

    The PSD uses :func:`psd_nperseg` segments (or ``psd_segment`` samples), the coherence
    :func:`coherence_nperseg` ones, given on the PSD's frequencies (linear interpolation).

    Parameters
    ----------
    record : Record
        A protocol run (volts in, radians out), metadata ``excited`` naming the excited input.
    channel_output : str
        The output measured.
    psd_segment : int, optional
        PSD segment length (samples), at most half the record.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, numpy.ndarray)
        Frequencies (Hz), PSD (rad^2/Hz) and magnitude-squared coherence (0 to 1).

    Examples
    --------
    >>> from trms.measurement.protocol import Protocol, protocol_records
    >>> from trms.twin import load_spec
    >>> (rec,) = protocol_records([load_spec()], Protocol("1dof", "u1", 5.0, 30.0, 0.05))
    >>> f, p, c = channel_spectra(rec, "pitch")
    >>> f.shape == p.shape == c.shape, round(float(f[1]), 4)  # 150-sample segments at 10 Hz
    (True, 0.0667)
    """
    du, dy = record.deviations()
    k = record.input_names.index(record.metadata["excited"])
    j = record.output_names.index(channel_output)
    nper = psd_nperseg(len(record)) if psd_segment is None else min(psd_segment, len(record) // 2)
    f, p = spectral.psd(dy[:, j], record.sample_time, nperseg=nper)
    if np.ptp(dy[:, j]) == 0:  # the encoder never moved: no linear relation can be measured
        return f, p, np.zeros_like(f)
    fc, c = spectral.coherence(du[:, k], dy[:, j], record.sample_time, nperseg=coherence_nperseg(len(record)))
    return f, p, np.interp(f, fc, c)


def averaged_spectra(
    records: list[Record], channel_output: str, psd_segment: int | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`channel_spectra` averaged over repeated runs of one protocol (PSD and coherence, bin by bin).

    Parameters
    ----------
    records : list of Record
        Runs of one protocol (same length and sample time).
    channel_output : str
        The output measured.
    psd_segment : int, optional
        PSD segment length (samples).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, numpy.ndarray)
        Frequencies (Hz), mean PSD (rad^2/Hz) and mean coherence (0 to 1).

    Examples
    --------
    >>> from trms.measurement.protocol import Protocol, repeated_records
    >>> from trms.twin import load_spec
    >>> runs = repeated_records(load_spec(), Protocol("1dof", "u1", 5.0, 30.0, 0.05), seeds=(0, 1))
    >>> f, p, c = averaged_spectra(runs, "pitch")
    >>> bool(np.allclose(p, (channel_spectra(runs[0], "pitch")[1] + channel_spectra(runs[1], "pitch")[1]) / 2))
    True
    """
    spectra = [channel_spectra(r, channel_output, psd_segment) for r in records]
    f = spectra[0][0]
    return f, np.mean([s[1] for s in spectra], axis=0), np.mean([s[2] for s in spectra], axis=0)


def peaks_of(f: np.ndarray, p: np.ndarray, band: tuple[float, float] = (0.02, 1.0)) -> list[float]:
    """Peak frequencies (Hz) of a PSD in a band (at least 1 dB prominent), interpolated inside the bin.

    Parameters
    ----------
    f, p : numpy.ndarray
        Frequencies (Hz) and PSD (any unit per Hz).
    band : (float, float)
        The band searched (Hz).

    Returns
    -------
    list of float
        Peak frequencies (Hz), rising.

    Examples
    --------
    >>> f = np.linspace(0.0, 1.0, 101)
    >>> p = 1.0 + 9.0 * np.exp(-(((f - 0.3) / 0.02) ** 2)) + 2.0 * np.exp(-(((f - 0.7) / 0.02) ** 2))
    >>> [round(x, 2) for x in peaks_of(f, p)]
    [0.3, 0.7]
    """
    return [pk.frequency for pk in spectral.find_modes(f, p, band, min_prominence_db=1.0)]


def ranked_peaks(f: np.ndarray, p: np.ndarray, band: tuple[float, float] = (0.02, 1.0)) -> list[tuple[float, float]]:
    """Every peak of a PSD in a band at least 1 dB prominent, as ``(frequency (Hz), prominence (dB))``, the most
    prominent first; frequencies interpolated inside the bin.

    Examples
    --------
    >>> f = np.linspace(0.0, 1.0, 101)
    >>> p = 1.0 + 9.0 * np.exp(-(((f - 0.3) / 0.02) ** 2)) + 2.0 * np.exp(-(((f - 0.7) / 0.02) ** 2))
    >>> [(round(a, 2), round(b, 1)) for a, b in ranked_peaks(f, p)]
    [(0.3, 10.0), (0.7, 4.8)]
    """
    import scipy.signal

    level = 10.0 * np.log10(np.maximum(p, np.max(p) * 1e-30 if np.max(p) > 0 else 1e-300))
    idx, props = scipy.signal.find_peaks(level, prominence=1.0)
    inside = (f[idx] >= band[0]) & (f[idx] <= band[1])
    idx, prom = idx[inside], props["prominences"][inside]
    order = np.argsort(-prom, kind="stable")
    refined = peaks_of(f, p, band)  # the same peaks, their frequencies interpolated inside the bin
    return [(min(refined, key=lambda x: abs(x - f[idx[k]])), float(prom[k])) for k in order]


def main_peaks(f: np.ndarray, p: np.ndarray, n: int, band: tuple[float, float] = (0.02, 1.0)) -> list[float]:
    """The ``n`` most prominent peaks (Hz) of a PSD in a band, each at least 1 dB prominent.

    "Among the channel's main peaks": a target counts as met only if a peak this
    prominent sits near it, not any ripple of a lightly averaged spectrum.

    Parameters
    ----------
    f, p : numpy.ndarray
        Frequencies (Hz) and PSD (any unit per Hz).
    n : int
        How many peaks.
    band : (float, float)
        The band searched (Hz).

    Returns
    -------
    list of float
        Their frequencies (Hz), rising.

    Examples
    --------
    >>> f = np.linspace(0.0, 1.0, 101)
    >>> p = 1.0 + 9.0 * np.exp(-(((f - 0.3) / 0.02) ** 2)) + 2.0 * np.exp(-(((f - 0.7) / 0.02) ** 2))
    >>> [round(x, 2) for x in main_peaks(f, p, 1)]
    [0.3]
    """
    return sorted(freq for freq, _ in ranked_peaks(f, p, band)[:n])
