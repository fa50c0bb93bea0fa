"""Input shapers on a sample grid: FIR filters that cancel a mode exactly at the controller's sample time.

A mode's vibration is cancelled exactly when the FIR ``H(z) = sum_k h_k z^-k`` of the taps has
a zero at the mode's discrete pole ``p = exp(s Ts)``, ``s = -zeta w + j w_d`` (ZV), and a double
zero there (ZVD: zero derivative with respect to the frequency too).

On a sample grid (:meth:`InputShaper.at <trms.control.shaping.continuous.InputShaper.at>`,
:func:`discrete_shaper`) a ZV or ZVD shaper is redesigned so that these zeros stay exact: with the
damped half period ``Td / 2 = (n + theta) Ts`` (``0 <= theta < 1``), the ZV's second impulse is
split between samples ``n`` and ``n + 1``,

``h = [1, 0, ..., 0, a, b] / (1 + a + b)``, ``a = -sin((n + 1) phi) / (r^n sin phi)``,
``b = sin(n phi) / (r^(n + 1) sin phi)``, ``phi = w_d Ts``, ``r = exp(zeta w Ts)``,

the unique taps on ``{0, n, n + 1}`` with ``H(p) = 0`` and unit static gain; both are
non-negative because ``n phi <= pi < (n + 1) phi``. The ZVD on the grid is this ZV convolved with
itself (as the continuous ZVD is the continuous ZV squared), so its zero is double. When ``Ts``
divides ``Td / 2`` (``theta = 0``), ``b = 0`` and both equal the continuous shapers sampled.
The grid shaper lasts ``(n + 1) Ts`` (ZV) or ``2 (n + 1) Ts`` (ZVD), at most one or two samples
more than the continuous one. Rounding each continuous impulse to the nearest sample instead
(:meth:`InputShaper.rounded <trms.control.shaping.continuous.InputShaper.rounded>`) moves the
cancelled frequency: for the 0.34 Hz, zeta 0.041 mode at ``Ts`` = 0.2 s it leaves 7.2 % (ZV) and
9.3 % (ZVD) residual vibration at the design mode, where the grid shapers leave none (below 1e-12).

Robustness (:meth:`SampledShaper.robust_band`): for that mode at 0.2 s and a 5 % limit: continuous
ZV -3.4 % / +3.4 %, grid ZV -3.5 % / +3.5 %; continuous ZVD -15.2 % / +15.5 %, grid ZVD
-15.5 % / +15.9 % (it lasts 3.2 s against 2.94 s); the rounded ZV and ZVD exceed 5 % at the design
frequency itself.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from trms.control.shaping.filters import shape_command
from trms.control.shaping.vibration import SHAPER_KINDS, mode_constants, mode_list, robust_band_of, shaper_residual
from trms.errors import InputError, as_finite_array, check_choice, check_in_range

__all__ = ["MAX_SHAPER_TAPS", "SampledShaper", "discrete_shaper"]

#: Most taps a shaper may have on a sample grid (:func:`discrete_shaper`, rounding): a mode far slower than the
#: sample rate would need a filter of millions of taps.
MAX_SHAPER_TAPS = 100_000


@dataclass(frozen=True)
class SampledShaper:
    """An input shaper on a sample grid: an FIR filter with taps summing to 1.

    Parameters
    ----------
    taps : numpy.ndarray
        Impulse amplitude (dimensionless) at each sample delay ``0, 1, ..., M - 1``.
    sample_time : float
        Sample time ``Ts`` (s), > 0.
    name : str
        Description.

    Examples
    --------
    Two equal taps 10 samples apart at 0.2 s: the ZV shaper of an undamped 0.25 Hz mode (half period 2 s):

    >>> s = SampledShaper(np.r_[0.5, np.zeros(9), 0.5], 0.2, "ZV 0.25 Hz")
    >>> s.duration, round(s.residual_vibration(0.25, 0.0), 12)
    (2.0, 0.0)
    """

    taps: np.ndarray
    sample_time: float
    name: str

    def __post_init__(self) -> None:
        h = as_finite_array("taps", self.taps, (None,))
        if h.shape[0] == 0 or not np.isclose(h.sum(), 1.0, rtol=0.0, atol=1e-9):
            raise InputError(f"taps must be non-empty and sum to 1, got {h.tolist()}")
        h.flags.writeable = False
        object.__setattr__(self, "taps", h)
        object.__setattr__(
            self, "sample_time", check_in_range("sample_time", self.sample_time, 0.0, np.inf, unit=" s", low_open=True)
        )

    @property
    def duration(self) -> float:
        """Delay of the last tap (s): the delay the shaper adds to a command.

        Examples
        --------
        >>> discrete_shaper([(0.25, 0.0)], 0.2, kind="zvd").duration
        4.0
        """
        return float((self.taps.size - 1) * self.sample_time)

    def _impulses(self) -> tuple[np.ndarray, np.ndarray]:
        """The nonzero taps and their times (s), the first at 0."""
        nz = np.flatnonzero(self.taps)
        return self.taps[nz], (nz - nz[0]) * self.sample_time

    def residual_vibration(self, frequency: float, damping: float) -> float:
        """Residual vibration ``V`` of a mode under the taps (1 = unshaped, 0 = cancelled).

        Parameters
        ----------
        frequency : float
            Natural frequency (Hz), > 0.
        damping : float
            Damping ratio, in [0, 1).

        Returns
        -------
        float
            ``V`` (fraction; :mod:`trms.control.shaping.vibration`).

        Examples
        --------
        Rounding the ZV impulses of the 0.34 Hz mode to a 0.2 s grid leaves 7.2 % (module docstring):

        >>> from trms.control.shaping.continuous import zv_shaper
        >>> round(zv_shaper(0.34, 0.041).rounded(0.2).residual_vibration(0.34, 0.041), 3)
        0.072
        """
        return shaper_residual(*self._impulses(), frequency, damping)

    def robust_band(self, frequency: float, damping: float, limit: float = 0.05) -> tuple[float, float]:
        """Relative frequency errors ``(low, high)`` around a mode over which ``V`` stays at or below ``limit``.

        Parameters
        ----------
        frequency : float
            Natural frequency the band is centred on (Hz), > 0.
        damping : float
            Damping ratio, in [0, 1).
        limit : float
            Largest acceptable residual vibration, in (0, 1].

        Returns
        -------
        tuple of float
            ``(low, high)`` (fractions of ``frequency``, searched up to +-95 %); ``(nan, nan)`` when
            ``V > limit`` at ``frequency`` itself.

        Examples
        --------
        The grid ZVD of the 0.34 Hz mode at 0.2 s keeps ``V <= 5 %`` from -15.5 % to +15.9 % (module docstring):

        >>> low, high = discrete_shaper([(0.34, 0.041)], 0.2).robust_band(0.34, 0.041)
        >>> round(100 * low, 1), round(100 * high, 1)
        (-15.5, 15.9)
        """
        return robust_band_of(*self._impulses(), frequency, damping, limit)

    def apply(self, command: np.ndarray, initial: float | Sequence[float] = 0.0) -> np.ndarray:
        """Convolve ``command`` causally with the taps.

        Parameters
        ----------
        command : array_like
            Sampled command (its unit, e.g. deviation rad), shape ``(N,)`` or ``(N, m)``; columns are shaped
            independently.
        initial : float or sequence of float
            Value at which each column rests before the first sample.

        Returns
        -------
        numpy.ndarray
            The shaped command, same shape and unit.

        Examples
        --------
        A unit step through a two-tap ZV shaper rises in two equal stairs:

        >>> discrete_shaper([(1.0, 0.0)], 0.25, kind="zv").apply(np.ones(4)).tolist()
        [0.5, 0.5, 1.0, 1.0]
        """

        def fir(x: np.ndarray) -> np.ndarray:
            n = x.shape[0]
            return np.column_stack([np.convolve(col, self.taps)[:n] for col in x.T])

        return shape_command(command, initial, fir)


def _check_nyquist(name: str, modes: Sequence[tuple[float, float]], ts: float) -> None:
    above = [f for f, _ in modes if f >= 0.5 / ts]
    if above:
        raise InputError(
            f"shaper {name!r} cancels a mode at {above[0]:g} Hz, at or above the Nyquist frequency "
            f"{0.5 / ts:g} Hz of sample_time = {ts:g} s; allowed: modes below {0.5 / ts:g} Hz"
        )


def _check_length(name: str, duration: float, ts: float) -> None:
    """Refuse a shaper of ``duration`` seconds that needs more than :data:`MAX_SHAPER_TAPS` taps of ``ts``."""
    taps = duration / ts + 3.0  # the grid design adds up to two samples
    if taps > MAX_SHAPER_TAPS:
        raise InputError(
            f"shaper {name!r} lasts {duration:g} s, {taps:.3g} taps of sample_time = {ts:g} s; "
            f"allowed: at most {MAX_SHAPER_TAPS} taps (a mode this slow needs a longer sample time)"
        )


def rounded_to_grid(
    amplitudes: np.ndarray, times: np.ndarray, name: str, modes: Sequence[tuple[float, float]], ts: float
) -> SampledShaper:
    """Impulses at ``times`` (s) moved to the nearest sample of ``ts`` (s), after the Nyquist and length checks."""
    _check_nyquist(name, modes, ts)
    _check_length(name, float(times[-1]), ts)
    idx = np.rint(times / ts).astype(np.int64)
    taps = np.zeros(int(idx[-1]) + 1)
    np.add.at(taps, idx, amplitudes)
    return SampledShaper(taps, ts, f"{name} @ {ts:g} s (rounded)")


def _zv_taps(frequency: float, damping: float, k: float, td: float, ts: float) -> np.ndarray:
    """Non-negative taps on the grid ``Ts`` with an exact zero at the mode's discrete pole (module docstring)."""
    wn = 2.0 * np.pi * frequency
    phi = wn * np.sqrt(1.0 - damping * damping) * ts
    half = 0.5 * td / ts  # = pi / phi, the half period in samples
    n = int(np.rint(half))
    taps = np.zeros(n + 2)
    taps[0] = 1.0
    if abs(half - n) <= 1e-9 * half:  # the grid holds the half period: the continuous ZV, sampled
        taps[n] = k
        taps = taps[:-1]
    else:
        n = int(np.floor(half))
        r = np.exp(damping * wn * ts)
        taps[n] = -np.sin((n + 1) * phi) / (r**n * np.sin(phi))
        taps[n + 1] = np.sin(n * phi) / (r ** (n + 1) * np.sin(phi))
        taps = taps[: n + 2]
    return taps / taps.sum()


def on_grid(modes: Sequence[tuple[float, float]], kinds: Sequence[str], ts: float) -> SampledShaper:
    """The design ``kinds[i]`` of each mode on the grid ``ts`` (s), convolved."""
    constants = [mode_constants(frequency, damping) for frequency, damping in modes]
    name = " * ".join(f"{kind.upper()} {c[0]:g} Hz" for kind, c in zip(kinds, constants))
    _check_nyquist(name, modes, ts)
    _check_length(name, sum(c[3] * (1.0 if kind == "zvd" else 0.5) for c, kind in zip(constants, kinds)), ts)
    taps = np.ones(1)
    labels = []
    for (f, z, k, td), kind in zip(constants, kinds):
        zv = _zv_taps(f, z, k, td, ts)
        taps = np.convolve(taps, zv if kind == "zv" else np.convolve(zv, zv))
        labels.append(f"{kind.upper()} {f:g} Hz, zeta {z:g}")
    return SampledShaper(taps / taps.sum(), ts, f"{' * '.join(labels)} on the {ts:g} s grid")


def discrete_shaper(modes: Iterable[tuple[float, float]], sample_time: float, kind: str = "zvd") -> SampledShaper:
    """ZV or ZVD shaper of each mode designed on the sample grid, convolved (the FIR of ``InputShaper.at``).

    Each mode's vibration is cancelled exactly (its discrete pole is a zero of the FIR; a double
    zero for ZVD) with non-negative taps, whatever ``Ts``; see the module docstring for the taps,
    their duration and their robustness to a frequency error.

    Parameters
    ----------
    modes : iterable of (frequency Hz, damping ratio)
        Modes to cancel, each below the Nyquist frequency ``1 / (2 Ts)``, damping in [0, 0.99).
    sample_time : float
        Sample time ``Ts`` (s), > 0.
    kind : {"zv", "zvd"}
        Design of every mode.

    Returns
    -------
    SampledShaper
        Taps summing to 1; equal to the continuous shaper sampled when ``Ts`` divides every half
        damped period.

    Raises
    ------
    InputError
        A mode at or above Nyquist, a damping outside [0, 0.99), more than :data:`MAX_SHAPER_TAPS` taps,
        an unknown kind.

    Examples
    --------
    >>> s = discrete_shaper([(0.34, 0.041)], 0.2, kind="zv")
    >>> s.taps.size, s.residual_vibration(0.34, 0.041) < 1e-12
    (9, True)
    >>> discrete_shaper([(0.25, 0.0)], 0.2, kind="zv").taps.nonzero()[0].tolist()
    [0, 10]
    """
    design = check_choice("shaper kind", kind, SHAPER_KINDS, error=InputError)
    ts = check_in_range("sample_time", sample_time, 0.0, np.inf, unit=" s", low_open=True)
    pairs = mode_list(modes)
    return on_grid(pairs, [design] * len(pairs), ts)
