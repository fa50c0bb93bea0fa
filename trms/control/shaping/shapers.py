"""Input shapers: the impulse-sequence family the thesis cites for command shaping (ch. 4.1).

Singer and Seering's shapers convolve a command with a short sequence of impulses whose
amplitudes and times cancel the residual vibration of a mode of natural frequency
``f`` (Hz) and damping ratio ``zeta``:

* ZV (zero vibration): two impulses, ``A = [1, K] / (1 + K)`` at ``t = [0, Td / 2]``;
* ZVD (zero vibration and derivative): three impulses, ``A = [1, 2K, K^2] / (1 + K)^2`` at
  ``t = [0, Td / 2, Td]``, which also zeroes the sensitivity to the frequency;

with ``K = exp(-zeta pi / sqrt(1 - zeta^2))`` and the damped period
``Td = 1 / (f sqrt(1 - zeta^2))``. Shapers for several modes are convolved. The residual
vibration ``V`` (fraction of the unshaped vibration left after the last impulse) is the
measure they are designed to zero:

``V = exp(-zeta w t_N) sqrt(C^2 + S^2)``, ``C = sum A_i exp(zeta w t_i) cos(w_d t_i)``,
``S = sum A_i exp(zeta w t_i) sin(w_d t_i)``.

A mode's vibration is cancelled exactly when the FIR ``H(z) = sum_k h_k z^-k`` of the taps has
a zero at the mode's discrete pole ``p = exp(s Ts)``, ``s = -zeta w + j w_d`` (ZV), and a double
zero there (ZVD: zero derivative with respect to the frequency too).

On a sample grid (:meth:`InputShaper.at`, :func:`discrete_shaper`) a ZV or ZVD shaper is
redesigned so that these zeros stay exact: with the damped half period ``Td / 2 = (n + theta) Ts``
(``0 <= theta < 1``), the ZV's second impulse is split between samples ``n`` and ``n + 1``,

``h = [1, 0, ..., 0, a, b] / (1 + a + b)``, ``a = -sin((n + 1) phi) / (r^n sin phi)``,
``b = sin(n phi) / (r^(n + 1) sin phi)``, ``phi = w_d Ts``, ``r = exp(zeta w Ts)``,

the unique taps on ``{0, n, n + 1}`` with ``H(p) = 0`` and unit static gain; both are
non-negative because ``n phi <= pi < (n + 1) phi``. The ZVD on the grid is this ZV convolved with
itself (as the continuous ZVD is the continuous ZV squared), so its zero is double. When ``Ts``
divides ``Td / 2`` (``theta = 0``), ``b = 0`` and both equal the continuous shapers sampled.
The grid shaper lasts ``(n + 1) Ts`` (ZV) or ``2 (n + 1) Ts`` (ZVD), at most one or two samples
more than the continuous one. Rounding each continuous impulse to the nearest sample instead
(:meth:`InputShaper.rounded`) moves the cancelled frequency: for the 0.34 Hz, zeta 0.041 mode at
``Ts`` = 0.2 s it leaves 7.2 % (ZV) and 9.3 % (ZVD) residual vibration at the design mode, where
the grid shapers leave none (below 1e-12).

Robustness (:meth:`InputShaper.robust_band`): the band of frequency error over which the
residual vibration stays below a limit. For that mode at 0.2 s and a 5 % limit: continuous ZV
-3.4 % / +3.4 %, grid ZV -3.5 % / +3.5 %; continuous ZVD -15.2 % / +15.5 %, grid ZVD
-15.5 % / +15.9 % (it lasts 3.2 s against 2.94 s); the rounded ZV and ZVD exceed 5 % at the design
frequency itself.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import control
import numpy as np
from scipy.optimize import brentq

from trms.control._checks import is_discrete_dt
from trms.control.shaping.filters import shape_command
from trms.errors import InputError, as_finite_array, check_choice, check_in_range

__all__ = [
    "InputShaper",
    "SampledShaper",
    "SHAPER_KINDS",
    "MAX_SHAPER_DAMPING",
    "MAX_SHAPER_TAPS",
    "zv_shaper",
    "zvd_shaper",
    "shaper_for_modes",
    "discrete_shaper",
    "model_modes",
]

#: Shapers designed here: zero vibration, zero vibration and derivative.
SHAPER_KINDS = ("zv", "zvd")

#: Damping ratios at or above this are refused by the designers: such a mode barely vibrates, and its
#: shaper would last a damped period ``1 / (f sqrt(1 - zeta^2))`` (7 times the undamped one at 0.99).
MAX_SHAPER_DAMPING = 0.99

#: Most taps a shaper may have on a sample grid (:meth:`InputShaper.at`, :meth:`InputShaper.rounded`): a mode
#: far slower than the sample rate would need a filter of millions of taps.
MAX_SHAPER_TAPS = 100_000

#: Largest relative frequency error :meth:`InputShaper.robust_band` searches (each side).
_BAND_SEARCH = 0.95


@dataclass(frozen=True)
class InputShaper:
    """A sequence of impulses (amplitudes summing to 1) at non-negative times.

    Parameters
    ----------
    amplitudes : numpy.ndarray
        Impulse amplitudes, shape ``(M,)``, summing to 1 (unit static gain).
    times : numpy.ndarray
        Impulse times (s), shape ``(M,)``, non-decreasing, starting at 0.
    name : str
        Description.
    modes : tuple of (float, float)
        The (frequency Hz, damping) of each mode the shaper was designed to cancel (empty when
        unknown); :meth:`at` refuses a grid that cannot represent them.
    kinds : tuple of str
        The design (``"zv"`` or ``"zvd"``) of each mode, aligned with ``modes``, when the impulses
        are exactly the convolution of those designs (set by :func:`zv_shaper`, :func:`zvd_shaper`,
        :func:`shaper_for_modes` and :meth:`convolve`); empty for any other impulse sequence.
        :meth:`at` redesigns a shaper with kinds on the sample grid.

    Examples
    --------
    >>> s = zvd_shaper(0.25, 0.0)
    >>> s.times.tolist(), s.kinds
    ([0.0, 2.0, 4.0], ('zvd',))
    """

    amplitudes: np.ndarray
    times: np.ndarray
    name: str
    modes: tuple[tuple[float, float], ...] = ()
    kinds: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        a = as_finite_array("amplitudes", self.amplitudes, (None,))
        t = as_finite_array("times", self.times, (a.shape[0],))
        if a.shape[0] == 0:
            raise InputError("an input shaper needs at least one impulse")
        if not np.isclose(a.sum(), 1.0, rtol=0.0, atol=1e-9):
            raise InputError(f"shaper amplitudes must sum to 1, got {a.sum()!r}")
        if t[0] != 0.0 or np.any(np.diff(t) < 0):
            raise InputError(f"shaper times must start at 0 s and not decrease, got {t.tolist()}")
        kinds = tuple(self.kinds)
        if kinds and (len(kinds) != len(self.modes) or any(k not in SHAPER_KINDS for k in kinds)):
            raise InputError(
                f"kinds must hold one of {SHAPER_KINDS} per mode ({len(self.modes)} modes), got {self.kinds!r}"
            )
        a.flags.writeable = False
        t.flags.writeable = False
        object.__setattr__(self, "amplitudes", a)
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "kinds", kinds)

    @property
    def duration(self) -> float:
        """Time of the last impulse (s): the delay the shaper adds to a command."""
        return float(self.times[-1])

    @property
    def designed(self) -> bool:
        """True when the impulses are the designs ``kinds`` of ``modes`` (so :meth:`at` can redesign them)."""
        return bool(self.modes) and len(self.kinds) == len(self.modes)

    def residual_vibration(self, frequency: float, damping: float) -> float:
        """Residual vibration ``V`` of a mode (1 = unshaped, 0 = cancelled).

        Parameters
        ----------
        frequency : float
            Natural frequency (Hz), > 0.
        damping : float
            Damping ratio, in [0, 1).

        Returns
        -------
        float
            ``V`` (fraction; module docstring).

        Examples
        --------
        >>> round(zv_shaper(0.25, 0.0).residual_vibration(0.25, 0.0), 12)
        0.0
        """
        f = check_in_range("frequency", frequency, 0.0, np.inf, unit=" Hz", low_open=True)
        z = check_in_range("damping", damping, 0.0, 1.0 - 1e-9)
        return float(_vibration(self.amplitudes, self.times, np.array([f]), z)[0])

    def robust_band(self, frequency: float, damping: float, limit: float = 0.05) -> tuple[float, float]:
        """Relative frequency errors ``(low, high)`` around a mode over which ``V`` stays at or below ``limit``.

        The mode at ``frequency (1 + e)`` leaves ``V <= limit`` for every ``e`` in ``[low, high]``
        (``low <= 0 <= high``); the search stops at +-95 %.

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
            ``(low, high)`` (fractions of ``frequency``); ``(nan, nan)`` when ``V > limit`` at
            ``frequency`` itself.

        Examples
        --------
        >>> low, high = zvd_shaper(0.25, 0.0).robust_band(0.25, 0.0)
        >>> round(low, 3), round(high, 3)
        (-0.144, 0.144)
        """
        f = check_in_range("frequency", frequency, 0.0, np.inf, unit=" Hz", low_open=True)
        z = check_in_range("damping", damping, 0.0, 1.0 - 1e-9)
        lim = check_in_range("limit", limit, 0.0, 1.0, low_open=True)

        def excess(e: np.ndarray) -> np.ndarray:
            return _vibration(self.amplitudes, self.times, f * (1.0 + e), z) - lim

        if excess(np.zeros(1))[0] > 0.0:
            return float("nan"), float("nan")
        edges = []
        for sign in (-1.0, 1.0):
            grid = sign * np.linspace(0.0, _BAND_SEARCH, 951)
            over = np.flatnonzero(excess(grid) > 0.0)
            if over.size == 0:
                edges.append(sign * _BAND_SEARCH)
                continue
            k = int(over[0])
            edges.append(brentq(lambda e: float(excess(np.array([e]))[0]), grid[k - 1], grid[k], xtol=1e-12))
        return float(edges[0]), float(edges[1])

    def convolve(self, other: InputShaper) -> InputShaper:
        """The shaper whose impulse train is the convolution of the two (cancels both sets of modes).

        Examples
        --------
        >>> both = zv_shaper(0.25, 0.0).convolve(zv_shaper(0.5, 0.0))
        >>> both.times.tolist(), both.kinds
        ([0.0, 1.0, 2.0, 3.0], ('zv', 'zv'))
        """
        times = (self.times[:, None] + other.times[None, :]).ravel()
        amps = (self.amplitudes[:, None] * other.amplitudes[None, :]).ravel()
        kinds = self.kinds + other.kinds if self.designed and other.designed else ()
        return _merged(amps, times, f"{self.name} * {other.name}", self.modes + other.modes, kinds)

    def at(self, sample_time: float) -> SampledShaper:
        """The shaper on a sample grid, still cancelling its modes exactly.

        A designed shaper (:attr:`designed`: ZV/ZVD of known modes) is redesigned on the grid by
        :func:`discrete_shaper` (zero residual vibration, and zero derivative for ZVD, at each mode);
        any other impulse sequence is rounded to the grid (:meth:`rounded`).

        Parameters
        ----------
        sample_time : float
            Sample time ``Ts`` (s), > 0.

        Returns
        -------
        SampledShaper

        Raises
        ------
        InputError
            A designed mode at or above the Nyquist frequency ``1 / (2 Ts)``: on that grid the
            impulses merge and the shaper cannot cancel the mode.

        Examples
        --------
        >>> grid = zvd_shaper(0.34, 0.041).at(0.2)
        >>> grid.residual_vibration(0.34, 0.041) < 1e-12, zvd_shaper(0.34, 0.041).rounded(0.2).taps.size
        (True, 16)
        """
        ts = check_in_range("sample_time", sample_time, 0.0, np.inf, unit=" s", low_open=True)
        if self.designed:
            return _on_grid(self.modes, self.kinds, ts)
        return self.rounded(ts)

    def rounded(self, sample_time: float) -> SampledShaper:
        """The shaper with each impulse moved to the nearest sample (no redesign).

        Rounding moves the cancelled frequency; :meth:`at` keeps it for designed shapers.

        Parameters
        ----------
        sample_time : float
            Sample time ``Ts`` (s), > 0.

        Returns
        -------
        SampledShaper

        Raises
        ------
        InputError
            A designed mode at or above the Nyquist frequency (as :meth:`at`).

        Examples
        --------
        >>> round(zvd_shaper(0.34, 0.041).rounded(0.2).residual_vibration(0.34, 0.041), 3)
        0.093
        """
        ts = check_in_range("sample_time", sample_time, 0.0, np.inf, unit=" s", low_open=True)
        _check_nyquist(self.name, self.modes, ts)
        _check_length(self.name, self.duration, ts)
        idx = np.rint(self.times / ts).astype(np.int64)
        taps = np.zeros(int(idx[-1]) + 1)
        np.add.at(taps, idx, self.amplitudes)
        return SampledShaper(taps, ts, f"{self.name} @ {ts:g} s (rounded)")


def _vibration(amplitudes: np.ndarray, times: np.ndarray, frequencies: np.ndarray, damping: float) -> np.ndarray:
    """Residual vibration ``V`` of the impulses at each natural frequency (Hz), one damping ratio."""
    wn = 2.0 * np.pi * frequencies[:, None]
    wd = wn * np.sqrt(1.0 - damping * damping)
    w = amplitudes * np.exp(damping * wn * (times - times[-1]))
    return np.hypot(np.sum(w * np.cos(wd * times), axis=1), np.sum(w * np.sin(wd * times), axis=1))


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


def _merged(
    amplitudes: np.ndarray,
    times: np.ndarray,
    name: str,
    modes: tuple[tuple[float, float], ...] = (),
    kinds: tuple[str, ...] = (),
) -> InputShaper:
    """Sort impulses by time and merge those at the same time."""
    order = np.argsort(times, kind="stable")
    t, a = times[order], amplitudes[order]
    keys, inverse = np.unique(np.round(t, 12), return_inverse=True)
    merged = np.zeros(keys.shape[0])
    np.add.at(merged, inverse, a)
    return InputShaper(merged, keys - keys[0], name, modes, kinds)


@dataclass(frozen=True)
class SampledShaper:
    """An input shaper on a sample grid: an FIR filter with taps summing to 1.

    Parameters
    ----------
    taps : numpy.ndarray
        Impulse amplitude at each sample delay ``0, 1, ..., M - 1``.
    sample_time : float
        Sample time ``Ts`` (s).
    name : str
        Description.
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
        """Delay of the last tap (s): the delay the shaper adds to a command."""
        return float((self.taps.size - 1) * self.sample_time)

    def as_shaper(self) -> InputShaper:
        """The impulse sequence this FIR realises (times on the sample grid)."""
        nz = np.flatnonzero(self.taps)
        return InputShaper(self.taps[nz], (nz - nz[0]) * self.sample_time, self.name)

    def residual_vibration(self, frequency: float, damping: float) -> float:
        """Residual vibration ``V`` of a mode under the taps (see :meth:`InputShaper.residual_vibration`).

        Examples
        --------
        >>> round(zv_shaper(0.34, 0.041).rounded(0.2).residual_vibration(0.34, 0.041), 3)
        0.072
        """
        return self.as_shaper().residual_vibration(frequency, damping)

    def robust_band(self, frequency: float, damping: float, limit: float = 0.05) -> tuple[float, float]:
        """Frequency-error band where ``V <= limit`` (see :meth:`InputShaper.robust_band`).

        Examples
        --------
        >>> low, high = zvd_shaper(0.34, 0.041).at(0.2).robust_band(0.34, 0.041)
        >>> low < -0.1 and high > 0.1
        True
        """
        return self.as_shaper().robust_band(frequency, damping, limit)

    def apply(self, command: np.ndarray, initial: float | Sequence[float] = 0.0) -> np.ndarray:
        """Convolve ``command`` (shape ``(N,)`` or ``(N, m)``) causally with the taps.

        Parameters
        ----------
        command : array_like
            Sampled command; columns are shaped independently.
        initial : float or sequence of float
            Value at which each column rests before the first sample.
        """

        def fir(x: np.ndarray) -> np.ndarray:
            n = x.shape[0]
            return np.column_stack([np.convolve(col, self.taps)[:n] for col in x.T])

        return shape_command(command, initial, fir)


def _mode_constants(frequency: object, damping: object) -> tuple[float, float, float, float]:
    """``(f, zeta, K, Td)`` of a mode a shaper is designed for, checked (module docstring)."""
    f = check_in_range("frequency", frequency, 0.0, np.inf, unit=" Hz", low_open=True)
    try:
        z = check_in_range("damping", damping, 0.0, MAX_SHAPER_DAMPING)
    except InputError:
        z = MAX_SHAPER_DAMPING
    if z >= MAX_SHAPER_DAMPING:
        raise InputError(
            f"damping = {damping!r} is outside the allowed range [0, {MAX_SHAPER_DAMPING}) of a shaper's mode "
            "(a real number; a mode damped more barely vibrates and its shaper would last many periods)"
        )
    root = math.sqrt(1.0 - z * z)
    td = 1.0 / (f * root) if f * root > 0.0 else math.inf
    if not math.isfinite(td):
        raise InputError(
            f"frequency = {frequency!r} Hz is too low: its damped period is not a finite number of seconds "
            f"(allowed: frequency > {1.0 / (np.finfo(float).max * root):.3g} Hz)"
        )
    return f, z, math.exp(-z * math.pi / root), td


def zv_shaper(frequency: float, damping: float) -> InputShaper:
    """Zero-vibration (ZV) shaper of a mode (Singer and Seering).

    Parameters
    ----------
    frequency : float
        Natural frequency of the mode (Hz), > 0.
    damping : float
        Damping ratio, in [0, 0.99) (:data:`MAX_SHAPER_DAMPING`).

    Returns
    -------
    InputShaper
        Two impulses, half a damped period apart.

    Examples
    --------
    >>> zv_shaper(0.25, 0.0).amplitudes.tolist()
    [0.5, 0.5]
    """
    f, z, k, td = _mode_constants(frequency, damping)
    return InputShaper(
        np.array([1.0, k]) / (1.0 + k), np.array([0.0, td / 2.0]), f"ZV {f:g} Hz, zeta {z:g}", ((f, z),), ("zv",)
    )


def zvd_shaper(frequency: float, damping: float) -> InputShaper:
    """Zero-vibration-and-derivative (ZVD) shaper of a mode (Singer and Seering).

    Parameters
    ----------
    frequency : float
        Natural frequency of the mode (Hz), > 0.
    damping : float
        Damping ratio, in [0, 0.99) (:data:`MAX_SHAPER_DAMPING`).

    Returns
    -------
    InputShaper
        Three impulses over one damped period.

    Examples
    --------
    >>> zvd_shaper(0.25, 0.0).amplitudes.tolist()
    [0.25, 0.5, 0.25]
    """
    f, z, k, td = _mode_constants(frequency, damping)
    amps = np.array([1.0, 2.0 * k, k * k]) / (1.0 + k) ** 2
    return InputShaper(amps, np.array([0.0, td / 2.0, td]), f"ZVD {f:g} Hz, zeta {z:g}", ((f, z),), ("zvd",))


def _mode_list(modes: object) -> list[tuple[float, float]]:
    """``modes`` as a non-empty list of (frequency, damping) pairs; the values are checked by the designers."""
    try:
        if isinstance(modes, (str, bytes)) or not isinstance(modes, Iterable):
            raise TypeError
        out = []
        for pair in modes:
            if isinstance(pair, (str, bytes)):
                raise TypeError
            f, z = pair
            out.append((f, z))
    except (TypeError, ValueError) as exc:
        raise InputError(f"modes must be a sequence of (frequency Hz, damping) pairs, got {modes!r}") from exc
    if not out:
        raise InputError("modes must hold at least one (frequency, damping) pair")
    return out


def shaper_for_modes(modes: Iterable[tuple[float, float]], kind: str = "zvd") -> InputShaper:
    """Convolve one shaper per identified mode.

    Parameters
    ----------
    modes : iterable of (frequency Hz, damping ratio)
        The modes to cancel, e.g. from a model's poles or a PSD's peaks.
    kind : {"zv", "zvd"}
        Shaper of each mode.

    Returns
    -------
    InputShaper

    Examples
    --------
    >>> s = shaper_for_modes([(0.25, 0.05), (0.34, 0.041)], kind="zv")
    >>> s.times.size, s.kinds
    (4, ('zv', 'zv'))
    """
    design = check_choice("shaper kind", kind, SHAPER_KINDS, error=InputError)
    designers = {"zv": zv_shaper, "zvd": zvd_shaper}
    shapers = [designers[design](f, z) for f, z in _mode_list(modes)]
    out = shapers[0]
    for s in shapers[1:]:
        out = out.convolve(s)
    return out


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


def _on_grid(modes: Sequence[tuple[float, float]], kinds: Sequence[str], ts: float) -> SampledShaper:
    constants = [_mode_constants(frequency, damping) for frequency, damping in modes]
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
    """ZV or ZVD shaper of each mode designed on the sample grid, convolved (the FIR of :meth:`InputShaper.at`).

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
    pairs = _mode_list(modes)
    return _on_grid(pairs, [design] * len(pairs), ts)


def model_modes(system: control.LTI) -> list[tuple[float, float]]:
    """Oscillatory modes (natural frequency Hz, damping ratio) of a discrete model's poles.

    Each complex pole pair ``z`` maps to ``s = ln(z) / Ts``; ``f = |s| / (2 pi)``,
    ``zeta = -Re(s) / |s|``. Real poles and poles above 0.8 x Nyquist are not modes and are left
    out (:func:`trms.modes.oscillatory`).

    Parameters
    ----------
    system : control.LTI
        Discrete-time model (``dt > 0``), e.g. eq. (3.11).

    Returns
    -------
    list of (float, float)
        Sorted by frequency.
    """
    dt = getattr(system, "dt", None)
    if not isinstance(system, control.LTI) or not is_discrete_dt(dt):
        raise InputError(
            f"system must be a discrete-time python-control model with a finite numeric dt > 0, got {system!r}"
        )
    from trms.identification.polynomial import modes_of_poles
    from trms.modes import oscillatory

    ts = float(system.dt)
    modes = oscillatory(modes_of_poles(np.asarray(system.poles(), dtype=complex), ts), ts)
    return [(m.frequency_hz, m.damping) for m in modes]
