"""Spectra: Welch PSD and cross-spectra, coherence (eq. 3.1), modes, attenuation (ch. 3.2, 4).

Every estimate is Welch's averaged periodogram with a Hann window, 50 % overlap, the
mean of each segment removed and one-sided density scaling: a signal in units ``x``
sampled every ``Ts`` seconds has a PSD in ``x**2 / Hz`` on frequencies ``0 .. 1 / (2 Ts)``
Hz with bin spacing ``1 / (nperseg Ts)``. ``nperseg`` defaults to
``min(256, N)`` for spectra and to ``N // 8`` (at least 8 samples, about 15 averaged
segments) for coherence, which needs several averaged segments to mean anything: with a
single segment the estimate is identically 1. Longer segments reduce the resolution bias
of lightly damped modes (the thesis's reason to resample at 10 Hz, ch. 3.2.5).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
import scipy.signal

from trms.errors import InputError, as_finite_array, check_choice, check_in_range

__all__ = [
    "psd",
    "csd",
    "coherence",
    "transfer_estimate",
    "mean_coherence",
    "Peak",
    "find_modes",
    "attenuation_db",
    "welch_segments",
]

#: Smallest segment length accepted (samples).
_MIN_NPERSEG = 8


def _signal(name: str, x: object) -> np.ndarray:
    arr = as_finite_array(name, x)
    if arr.ndim != 1:
        raise InputError(f"{name} must be 1-D (one channel), got shape {arr.shape}")
    if arr.size < _MIN_NPERSEG:
        raise InputError(f"{name} has {arr.size} samples; spectra need at least {_MIN_NPERSEG}")
    return arr


def _pair(x: object, y: object) -> tuple[np.ndarray, np.ndarray]:
    xa, ya = _signal("x", x), _signal("y", y)
    if xa.size != ya.size:
        raise InputError(f"x and y must have the same length, got {xa.size} and {ya.size} samples")
    return xa, ya


def welch_segments(n: int, nperseg: int) -> int:
    """Number of half-overlapping Welch segments of ``nperseg`` samples in ``n`` samples."""
    return 1 + (n - nperseg) // (nperseg // 2)


def _nperseg(n: int, nperseg: int | None, default: int) -> int:
    if nperseg is None:
        return max(min(default, n), min(_MIN_NPERSEG, n))
    if isinstance(nperseg, bool) or not isinstance(nperseg, (int, np.integer)):
        raise InputError(f"nperseg must be an int, got {nperseg!r}")
    check_in_range("nperseg", nperseg, _MIN_NPERSEG, n, unit=" samples")
    return int(nperseg)


def _fs(sample_time: float) -> float:
    return 1.0 / check_in_range("sample_time", sample_time, 0.0, np.inf, unit=" s", low_open=True)


def _welch_kwargs(sample_time: float, nperseg: int) -> dict:
    return dict(fs=_fs(sample_time), window="hann", nperseg=nperseg, noverlap=nperseg // 2, detrend="constant")


def psd(x: object, sample_time: float, nperseg: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Welch power spectral density, one-sided.

    Parameters
    ----------
    x : array_like
        Signal, shape ``(N,)``, any unit ``x``.
    sample_time : float
        Sample time ``Ts`` (s).
    nperseg : int, optional
        Segment length (samples), in ``[8, N]``; default ``min(256, N)``.

    Returns
    -------
    f : numpy.ndarray
        Frequencies (Hz), ``0 .. 1 / (2 Ts)``.
    Pxx : numpy.ndarray
        PSD (``x**2 / Hz``); ``trapezoid(Pxx, f)`` is about the variance of ``x``.
    """
    xa = _signal("x", x)
    f, p = scipy.signal.welch(xa, **_welch_kwargs(sample_time, _nperseg(xa.size, nperseg, 256)))
    return f, p


def csd(x: object, y: object, sample_time: float, nperseg: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Welch cross-spectral density ``Sxy`` (complex, one-sided).

    With scipy's convention ``Sxy = E[conj(X) Y]``, so ``Sxy / Sxx`` estimates the
    frequency response from ``x`` to ``y``.

    Parameters
    ----------
    x, y : array_like
        Signals of equal length ``N``.
    sample_time : float
        Sample time (s).
    nperseg : int, optional
        Segment length (samples); default ``min(256, N)``.

    Returns
    -------
    f : numpy.ndarray
        Frequencies (Hz).
    Pxy : numpy.ndarray
        Complex cross-spectrum (``x y / Hz``).
    """
    xa, ya = _pair(x, y)
    return scipy.signal.csd(xa, ya, **_welch_kwargs(sample_time, _nperseg(xa.size, nperseg, 256)))


def _coherence_nperseg(n: int, nperseg: int | None) -> int:
    seg = _nperseg(n, nperseg, max(n // 8, _MIN_NPERSEG))
    if welch_segments(n, seg) < 2:
        raise InputError(
            f"nperseg = {seg} leaves {welch_segments(n, seg)} Welch segment in {n} samples; "
            f"coherence needs at least 2 (nperseg <= {2 * n // 3})"
        )
    return seg


def coherence(x: object, y: object, sample_time: float, nperseg: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Magnitude-squared coherence ``|Sxy|^2 / (Sxx Syy)`` (eq. 3.1), in ``[0, 1]``.

    1 for a noise-free linear relation, near 0 for unrelated signals (the bias of the
    estimate for independent signals is about ``1 / K`` for ``K`` averaged segments).

    Parameters
    ----------
    x, y : array_like
        Input and output, equal length ``N``; or arrays of the same shape ``(..., N)``, one pair of signals per
        index of the leading axes (the coherence of each, computed together).
    sample_time : float
        Sample time (s).
    nperseg : int, optional
        Segment length (samples); default ``N // 8`` (at least 8); must leave at least 2
        Welch segments.

    Returns
    -------
    f : numpy.ndarray
        Frequencies (Hz).
    Cxy : numpy.ndarray
        Coherence (dimensionless), shape ``(..., len(f))``.

    Examples
    --------
    A pair of signals at a time or many at once, the same numbers:

    >>> rng = np.random.default_rng(0)
    >>> x = rng.standard_normal((3, 512)); y = x + 0.5 * rng.standard_normal((3, 512))
    >>> f, many = coherence(x, y, 0.1, nperseg=64)
    >>> bool(np.allclose(many[1], coherence(x[1], y[1], 0.1, nperseg=64)[1], rtol=1e-12, atol=0.0))
    True
    """
    xa, ya = as_finite_array("x", x), as_finite_array("y", y)
    if xa.ndim == 1 or ya.ndim == 1 or xa.shape != ya.shape:
        xa, ya = _pair(x, y)
    elif xa.shape[-1] < _MIN_NPERSEG:
        raise InputError(f"x has {xa.shape[-1]} samples; spectra need at least {_MIN_NPERSEG}")
    seg = _coherence_nperseg(xa.shape[-1], nperseg)
    f, c = scipy.signal.coherence(xa, ya, axis=-1, **_welch_kwargs(sample_time, seg))
    return f, np.clip(c, 0.0, 1.0)


def transfer_estimate(
    x: object, y: object, sample_time: float, nperseg: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Non-parametric frequency response ``H1 = Sxy / Sxx`` from input ``x`` to output ``y``.

    Parameters
    ----------
    x, y : array_like
        Input and output, equal length.
    sample_time : float
        Sample time (s).
    nperseg : int, optional
        Segment length (samples); default as for :func:`coherence`.

    Returns
    -------
    f : numpy.ndarray
        Frequencies (Hz).
    H : numpy.ndarray
        Complex frequency response (``y`` units per ``x`` unit).
    """
    xa, ya = _pair(x, y)
    kw = _welch_kwargs(sample_time, _coherence_nperseg(xa.size, nperseg))
    f, pxy = scipy.signal.csd(xa, ya, **kw)
    _, pxx = scipy.signal.welch(xa, **kw)
    if np.any(pxx <= 0):
        raise InputError("input x has no power at some frequency (constant input?); H1 = Sxy / Sxx is undefined")
    return f, pxy / pxx


def mean_coherence(f: np.ndarray, cxy: np.ndarray, band: tuple[float, float]) -> float:
    """Average coherence over the bins with ``band[0] <= f <= band[1]`` (Hz)."""
    mask = _band_mask(np.asarray(f, float), band)
    return float(np.mean(np.asarray(cxy, float)[mask]))


def _band_mask(f: np.ndarray, band: tuple[float, float]) -> np.ndarray:
    lo, hi = (float(b) for b in band)
    if not (np.isfinite(lo) and not np.isnan(hi) and lo < hi):
        raise InputError(f"band must be (low, high) Hz with low < high, got {band!r}")
    mask = (f >= lo) & (f <= hi)
    if not np.any(mask):
        raise InputError(f"band {band!r} Hz holds no frequency bin (bins span {f[0]:g} .. {f[-1]:g} Hz)")
    return mask


class Peak(NamedTuple):
    """A spectral peak: frequency (Hz) and height (units of the spectrum), interpolated."""

    frequency: float
    height: float


def _vertex(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """Vertex of the parabola through three points (any spacing)."""
    (x0, x1, x2), (y0, y1, y2) = x, y
    d0, d1 = (y1 - y0) / (x1 - x0), (y2 - y1) / (x2 - x1)
    a = (d1 - d0) / (x2 - x0)
    if a >= 0:  # flat or not a maximum: keep the sample
        return float(x1), float(y1)
    b = d0 - a * (x0 + x1)
    xv = -b / (2 * a)
    xv = min(max(xv, x0), x2)
    return float(xv), float(y0 + d0 * (xv - x0) + a * (xv - x0) * (xv - x1))


def find_modes(
    f: object,
    P: object,
    band: tuple[float, float] = (0.0, np.inf),
    n: int | None = None,
    min_prominence_db: float = 1.0,
    quantity: str = "power",
) -> list[Peak]:
    """Local maxima of a spectrum or frequency-response magnitude inside a band.

    Each peak is refined by fitting a parabola to the logarithm of the three samples
    around it (exact for a Gaussian-shaped peak, close for a resonance), which resolves
    the frequency well inside one bin.

    Parameters
    ----------
    f : array_like
        Increasing frequencies (Hz); any spacing.
    P : array_like
        Non-negative spectrum (PSD, ``x**2 / Hz``) or magnitude ``|H|``, same length as ``f``.
    band : (float, float)
        Only peaks with ``band[0] <= f <= band[1]`` Hz are reported.
    n : int, optional
        Keep only the ``n`` highest peaks.
    min_prominence_db : float
        Minimum prominence of a peak (dB) above the higher of its two surrounding minima.
    quantity : {"power", "amplitude"}
        How dB are counted: ``10 log10`` for power quantities, ``20 log10`` for magnitudes.

    Returns
    -------
    list of Peak
        Sorted by frequency.
    """
    fa = as_finite_array("f", f)
    pa = as_finite_array("P", P)
    if fa.ndim != 1 or fa.shape != pa.shape or fa.size < 3:
        raise InputError(f"f and P must be 1-D of equal length >= 3, got shapes {fa.shape} and {pa.shape}")
    if np.any(np.diff(fa) <= 0):
        raise InputError("f must be strictly increasing")
    if np.any(pa < 0):
        raise InputError(f"P must be non-negative, found {pa.min()!r}")
    check_choice("quantity", quantity, ("power", "amplitude"), error=InputError)
    check_in_range("min_prominence_db", min_prominence_db, 0.0, np.inf, unit=" dB")
    if n is not None:
        check_in_range("n", n, 1, np.inf)
    scale = 10.0 if quantity == "power" else 20.0
    floor = np.max(pa) * 1e-30 if np.max(pa) > 0 else 1e-300
    level = scale * np.log10(np.maximum(pa, floor))
    mask = _band_mask(fa, band)
    idx, _ = scipy.signal.find_peaks(level, prominence=min_prominence_db)
    idx = idx[mask[idx]]
    if n is not None and idx.size > n:
        top = np.argsort(level[idx])[::-1][: int(n)]
        idx = idx[np.sort(top)]
    peaks = []
    for i in idx:
        fv, lv = _vertex(fa[i - 1 : i + 2], level[i - 1 : i + 2])
        peaks.append(Peak(fv, float(10.0 ** (lv / scale))))
    return sorted(peaks, key=lambda p: p.frequency)


def attenuation_db(
    f: object,
    P_reference: object,
    P_shaped: object,
    frequencies: Sequence[float] | float,
    halfwidth: float = 0.0,
) -> np.ndarray:
    """Reduction of a power spectrum at given frequencies, in dB (positive = less power).

    ``10 log10(P_reference / P_shaped)`` at each frequency, as in the thesis's tables 4.2
    and 4.3 (output PSD with the unshaped command vs with the shaped one).

    Parameters
    ----------
    f : array_like
        Increasing frequencies (Hz) of both spectra.
    P_reference, P_shaped : array_like
        Positive power spectra (same unit) on ``f``.
    frequencies : float or sequence of float
        Where to read the attenuation (Hz), inside ``[f[0], f[-1]]``.
    halfwidth : float
        0 (default): both spectra are interpolated linearly in dB at each frequency.
        > 0: each spectrum's maximum within ``+- halfwidth`` Hz is used instead (peak
        against peak, robust to a mode that moved by less than ``halfwidth``).

    Returns
    -------
    numpy.ndarray
        Attenuation (dB), one per frequency.
    """
    fa = as_finite_array("f", f)
    ref = as_finite_array("P_reference", P_reference)
    shp = as_finite_array("P_shaped", P_shaped)
    if fa.ndim != 1 or ref.shape != fa.shape or shp.shape != fa.shape:
        raise InputError(
            f"f, P_reference and P_shaped must be 1-D of equal length, got {fa.shape}, {ref.shape}, {shp.shape}"
        )
    if np.any(np.diff(fa) <= 0):
        raise InputError("f must be strictly increasing")
    for name, p in (("P_reference", ref), ("P_shaped", shp)):
        if np.any(p <= 0):
            raise InputError(f"{name} must be positive to take its logarithm, found {p.min()!r}")
    fq = np.atleast_1d(as_finite_array("frequencies", frequencies))
    for fv in fq:
        check_in_range("frequency", float(fv), float(fa[0]), float(fa[-1]), unit=" Hz")
    hw = check_in_range("halfwidth", halfwidth, 0.0, np.inf, unit=" Hz")
    ref_db, shp_db = 10 * np.log10(ref), 10 * np.log10(shp)
    if hw == 0.0:
        return np.interp(fq, fa, ref_db) - np.interp(fq, fa, shp_db)
    out = np.empty(fq.size)
    for k, fv in enumerate(fq):
        win = np.abs(fa - fv) <= hw
        if not np.any(win):
            win = np.abs(fa - fv) == np.min(np.abs(fa - fv))
        out[k] = ref_db[win].max() - shp_db[win].max()
    return out
