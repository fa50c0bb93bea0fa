"""Digital command-shaping filters designed at a plant's sample time (thesis ch. 4.3, 6.9).

A command (a reference in deviation units) is passed through a discrete filter before it
reaches the plant or the feedback loop, so that it carries little energy at the plant's
lightly damped modes. The thesis uses Butterworth low-pass and band-stop filters
(1-DOF, ch. 4.4 and 6.9) and elliptic band-stop filters (2-DOF, ch. 4.7), including a
two-band band-stop (its Filter-2). All filters here are designed in the digital domain
at the sample time ``Ts`` by the bilinear transform with pre-warping (scipy's
``butter``/``ellip`` with ``fs``), so the edge frequencies are exact at ``Ts``, as with
MATLAB's ``butter``/``ellip``. They are stored as second-order sections.

Order convention (as in scipy and MATLAB): a band-stop filter of order ``N`` has ``2 N``
poles; a multi-band band-stop is the cascade of one band-stop per band.

Filtering is causal (``sosfilt``). The command is taken to rest at ``initial`` before the
first sample, so a command that starts away from ``initial`` is seen as a step at ``t = 0``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol, SupportsFloat, SupportsIndex, runtime_checkable

import numpy as np
from scipy import signal

from trms.control.arguments import real_array
from trms.errors import InputError, as_finite_array, check_choice, check_in_range

__all__ = [
    "Prefilter",
    "CommandFilter",
    "shape_command",
    "butterworth_lowpass",
    "butterworth_bandstop",
    "elliptic_bandstop",
    "multiband_bandstop",
    "bands_around",
]

#: Highest filter order accepted (a higher order is numerically fragile and never needed here).
MAX_ORDER = 12


@runtime_checkable
class Prefilter(Protocol):
    """Anything that shapes a sampled command: a :class:`CommandFilter` or a sampled input shaper.

    A prefilter has a ``sample_time`` (s), a ``name`` and ``apply(command, initial)``, which shapes a command
    (shape ``(N,)`` or ``(N, m)``, any unit) causally and returns the same shape;
    :func:`trms.control.loop.closed_loop` runs one on the reference (CSAS).

    Examples
    --------
    >>> from trms.control.shaping.sampled import discrete_shaper
    >>> shaper = discrete_shaper([(0.3, 0.1)], 0.1)
    >>> isinstance(butterworth_lowpass(2, 0.5, 0.1), Prefilter), isinstance(shaper, Prefilter), shaper.sample_time
    (True, True, 0.1)
    """

    @property
    def sample_time(self) -> float:
        """Seconds between samples."""
        ...

    @property
    def name(self) -> str:
        """A short label."""
        ...

    def apply(self, command: np.ndarray, initial: float | Sequence[float] = 0.0) -> np.ndarray:
        """Shape ``command`` (shape ``(N,)`` or ``(N, m)``) causally; same shape out."""
        ...


def shape_command(
    command: object,
    initial: float | Sequence[float],
    kernel: Callable[[np.ndarray], np.ndarray],
) -> np.ndarray:
    """Validate a command, run a causal ``kernel`` on its deviation from rest, restore the rest level.

    Parameters
    ----------
    command : array_like
        Shape ``(N,)`` or ``(N, m)``; each column is shaped independently.
    initial : float or sequence of float
        Rest value of each column before the first sample (same unit as the command).
    kernel : callable
        Maps an ``(N, m)`` array at rest at zero to its shaped version (along axis 0).

    Returns
    -------
    numpy.ndarray
        The shaped command, same shape as ``command``.

    Raises
    ------
    InputError
        A command that is not real and finite or has no sample; an ``initial`` of the wrong shape.

    Examples
    --------
    A kernel that doubles its input, on a command resting at 1 before the first sample:

    >>> shape_command([1.0, 2.0], 1.0, lambda x: 2 * x).tolist()
    [1.0, 3.0]
    """
    if isinstance(command, np.ndarray) and command.dtype.kind in "fiu" and command.ndim in (1, 2):
        arr = as_finite_array("command", command, (None,) * command.ndim)
    else:
        arr = real_array("command", command)
    if arr.ndim not in (1, 2) or arr.shape[0] == 0:
        raise InputError(f"command must have shape (N,) or (N, m) with N >= 1, got shape {arr.shape}")
    cols = arr.reshape(arr.shape[0], -1)
    rest = real_array("initial", initial)
    if rest.shape not in ((), (cols.shape[1],)):
        raise InputError(
            f"initial must be a scalar or hold one value per command column, shape ({cols.shape[1]},); "
            f"got shape {rest.shape}"
        )
    shaped = kernel(cols - rest) + rest
    return shaped.reshape(arr.shape)


def _sequence(name: str, value: object, what: str) -> list[Any]:
    """``value`` as a list, refusing text and non-sequences with one line."""
    if isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
        raise InputError(f"{name} must be a sequence of {what}, got {value!r}")
    return list(value)


def _check_order(order: object) -> int:
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or not 1 <= order <= MAX_ORDER:
        raise InputError(f"order = {order!r} must be an integer in [1, {MAX_ORDER}]")
    return int(order)


def _check_sample_time(sample_time: object) -> float:
    return check_in_range("sample_time", sample_time, 0.0, np.inf, unit=" s", low_open=True)


def _check_frequency(name: str, value: object, sample_time: float) -> float:
    nyquist = 0.5 / sample_time
    try:
        if isinstance(value, (str, bytes, bool, np.bool_)) or not isinstance(value, (SupportsFloat, SupportsIndex)):
            raise TypeError(f"{type(value).__name__} is not a number")
        f = float(value)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InputError(f"{name} must be a number in (0 Hz, {nyquist:g} Hz), got {value!r}") from exc
    if not (0.0 < f < nyquist):
        raise InputError(
            f"{name} = {value!r} Hz is outside the allowed range (0 Hz, {nyquist:g} Hz): "
            f"it must lie below the Nyquist frequency at sample_time = {sample_time:g} s"
        )
    return f


def _check_band(band: object, sample_time: float) -> tuple[float, float]:
    try:
        if not isinstance(band, Iterable):
            raise TypeError(f"{type(band).__name__} is not a sequence")
        low_edge, high_edge = band
    except (TypeError, ValueError) as exc:
        raise InputError(f"band must be a pair (low, high) in Hz, got {band!r}") from exc
    lo = _check_frequency("band low edge", low_edge, sample_time)
    hi = _check_frequency("band high edge", high_edge, sample_time)
    if not lo < hi:
        raise InputError(f"band = {band!r} Hz must have low edge < high edge")
    return lo, hi


@dataclass(frozen=True)
class CommandFilter:
    """A discrete filter in second-order sections, designed at ``sample_time``.

    Parameters
    ----------
    sos : numpy.ndarray
        Second-order sections, shape ``(n_sections, 6)`` (scipy convention).
    sample_time : float
        Sample time ``Ts`` (s) the filter was designed for.
    name : str
        Short description, e.g. ``"Butterworth LPF order 2, 0.2 Hz"``.

    Examples
    --------
    >>> f = butterworth_lowpass(2, 0.5, 0.1)
    >>> f.name, f.order, f.sos.shape, round(f.dc_gain(), 12)
    ('Butterworth LPF order 2, 0.5 Hz', 2, (1, 6), 1.0)
    """

    sos: np.ndarray
    sample_time: float
    name: str

    def __post_init__(self) -> None:
        sos = as_finite_array("sos", self.sos, (None, 6))
        if sos.shape[0] == 0 or np.any(sos[:, 3] == 0):
            raise InputError(f"sos must have at least one section and a0 != 0 in each, got shape {sos.shape}")
        sos.flags.writeable = False
        object.__setattr__(self, "sos", sos)
        object.__setattr__(self, "sample_time", _check_sample_time(self.sample_time))

    @property
    def order(self) -> int:
        """Number of poles of the whole cascade.

        Examples
        --------
        >>> butterworth_bandstop(3, (0.2, 0.5), 0.1).order  # a band-stop of order N has 2 N poles
        6
        """
        den = np.asarray(self.sos[:, 3:])
        return int(sum(np.count_nonzero(row != 0) - 1 for row in den))

    def apply(self, command: np.ndarray, initial: float | Sequence[float] = 0.0) -> np.ndarray:
        """Filter ``command`` causally (zero-order-hold samples at ``sample_time``).

        Parameters
        ----------
        command : array_like
            Shape ``(N,)`` or ``(N, m)``; columns are filtered independently.
        initial : float or sequence of float
            Value at which each column rests before the first sample.

        Returns
        -------
        numpy.ndarray
            The filtered command, same shape and unit.

        Examples
        --------
        A unit step through a low-pass (static gain 1) settles at 1:

        >>> round(float(butterworth_lowpass(2, 0.5, 0.1).apply(np.ones(200))[-1]), 9)
        1.0
        """
        return shape_command(command, initial, lambda x: signal.sosfilt(np.array(self.sos), x, axis=0))

    def frequency_response(self, frequencies: Sequence[float] | np.ndarray) -> np.ndarray:
        """Complex response (dimensionless) at ``frequencies`` (Hz, each in ``[0, 1 / (2 Ts)]``).

        Examples
        --------
        A second-order Butterworth low-pass is ``-j / sqrt(2)`` at its cutoff (-3 dB, -90 degrees):

        >>> h = butterworth_lowpass(2, 0.5, 0.1).frequency_response([0.0, 0.5])
        >>> np.round(h, 6).tolist()
        [(1+0j), -0.707107j]
        """
        f = np.atleast_1d(real_array("frequencies", frequencies))
        if f.ndim != 1:
            raise InputError(f"frequencies must be a number or a 1-D sequence (Hz), got shape {f.shape}")
        nyq = 0.5 / self.sample_time
        if np.any((f < 0) | (f > nyq)):
            raise InputError(f"frequencies must lie in [0, {nyq:g}] Hz, got min {f.min():g}, max {f.max():g}")
        _, h = signal.sosfreqz(np.array(self.sos), worN=f, fs=1.0 / self.sample_time)
        return h

    def gain_db(self, frequencies: Sequence[float] | np.ndarray) -> np.ndarray:
        """Magnitude response (dB) at ``frequencies`` (Hz).

        Examples
        --------
        >>> np.round(butterworth_bandstop(2, (0.2, 0.5), 0.1).gain_db([0.2, 0.5]), 3).tolist()
        [-3.01, -3.01]
        """
        with np.errstate(divide="ignore"):
            return 20.0 * np.log10(np.abs(self.frequency_response(frequencies)))

    def dc_gain(self) -> float:
        """Gain at 0 Hz (dimensionless).

        1 for the Butterworth filters and the odd-order elliptic band-stops; an even-order elliptic band-stop
        (as MATLAB's ``ellip`` designs it) sits at the bottom of its pass-band ripple there, ``10^(-ripple / 20)``,
        so a command through it ends at that fraction of its value.

        Examples
        --------
        >>> round(butterworth_bandstop(2, (0.2, 0.5), 0.1).dc_gain(), 9)
        1.0
        >>> round(elliptic_bandstop(2, (0.2, 0.5), 0.1).dc_gain(), 6), round(10 ** (-1.0 / 20.0), 6)  # 1 dB ripple
        (0.891251, 0.891251)
        """
        return float(np.real(self.frequency_response([0.0])[0]))

    def then(self, other: CommandFilter) -> CommandFilter:
        """The cascade ``other(self(command))``; both must share the sample time.

        Raises
        ------
        InputError
            ``other`` is not a CommandFilter or has another sample time.

        Examples
        --------
        >>> both = butterworth_lowpass(2, 0.5, 0.1).then(butterworth_bandstop(2, (0.2, 0.5), 0.1))
        >>> both.order, both.name
        (6, 'Butterworth LPF order 2, 0.5 Hz + Butterworth BSF order 2, 0.2-0.5 Hz')
        """
        if not isinstance(other, CommandFilter):
            raise InputError(f"other must be a CommandFilter, got {type(other).__name__}")
        if not np.isclose(other.sample_time, self.sample_time, rtol=1e-12, atol=0.0):
            raise InputError(
                "cannot cascade filters designed at different sample times: "
                f"{self.sample_time} s and {other.sample_time} s"
            )
        return CommandFilter(np.vstack([self.sos, other.sos]), self.sample_time, f"{self.name} + {other.name}")


def butterworth_lowpass(order: int, cutoff: float, sample_time: float) -> CommandFilter:
    """Butterworth low-pass filter (thesis eq. 4.1-4.2), digital, exact -3 dB point at ``cutoff``.

    Parameters
    ----------
    order : int
        Number of poles, 1 to 12.
    cutoff : float
        -3 dB frequency (Hz), ``0 < cutoff < 1 / (2 Ts)``.
    sample_time : float
        Sample time ``Ts`` (s).

    Returns
    -------
    CommandFilter
        Unit static gain.

    Raises
    ------
    InputError
        An order outside 1..12, a sample time that is not > 0, a cutoff not below Nyquist.

    Examples
    --------
    The gain is exactly -3.01 dB (``1 / sqrt(2)``) at the cutoff, whatever the sample time:

    >>> lp = butterworth_lowpass(2, 0.5, 0.1)
    >>> np.round(lp.gain_db([0.0, 0.5]), 3).tolist()
    [0.0, -3.01]
    """
    n = _check_order(order)
    ts = _check_sample_time(sample_time)
    fc = _check_frequency("cutoff", cutoff, ts)
    sos = signal.butter(n, fc, btype="lowpass", fs=1.0 / ts, output="sos")
    return CommandFilter(sos, ts, f"Butterworth LPF order {n}, {fc:g} Hz")


def butterworth_bandstop(order: int, band: tuple[float, float], sample_time: float) -> CommandFilter:
    """Butterworth band-stop filter, digital, -3 dB points at the band edges.

    Parameters
    ----------
    order : int
        Prototype order, 1 to 12 (the filter has ``2 order`` poles).
    band : tuple of float
        ``(low, high)`` stop-band edges (Hz), ``0 < low < high < 1 / (2 Ts)``.
    sample_time : float
        Sample time ``Ts`` (s).

    Returns
    -------
    CommandFilter
        Unit static gain.

    Raises
    ------
    InputError
        An order outside 1..12, a band that is not ``0 < low < high < 1 / (2 Ts)``.

    Examples
    --------
    -3.01 dB at both band edges, about -28 dB in the middle of the band:

    >>> bs = butterworth_bandstop(2, (0.2, 0.5), 0.1)
    >>> bs.order, np.round(bs.gain_db([0.2, 0.5]), 3).tolist(), bool(bs.gain_db([0.32])[0] < -20.0)
    (4, [-3.01, -3.01], True)
    """
    n = _check_order(order)
    ts = _check_sample_time(sample_time)
    lo, hi = _check_band(band, ts)
    sos = signal.butter(n, [lo, hi], btype="bandstop", fs=1.0 / ts, output="sos")
    return CommandFilter(sos, ts, f"Butterworth BSF order {n}, {lo:g}-{hi:g} Hz")


def elliptic_bandstop(
    order: int,
    band: tuple[float, float],
    sample_time: float,
    passband_ripple_db: float = 1.0,
    stopband_attenuation_db: float = 40.0,
) -> CommandFilter:
    """Elliptic band-stop filter (thesis eq. 4.3), digital.

    The thesis does not print the ripple or the stop-band attenuation of its elliptic
    filters; the defaults (1 dB ripple, 40 dB attenuation) are this project's choice.

    Parameters
    ----------
    order : int
        Prototype order, 1 to 12 (the filter has ``2 order`` poles).
    band : tuple of float
        ``(low, high)`` pass-band edges (Hz) around the stop band.
    sample_time : float
        Sample time ``Ts`` (s).
    passband_ripple_db : float
        Maximum pass-band ripple (dB), in (0, 10].
    stopband_attenuation_db : float
        Minimum stop-band attenuation (dB), greater than the ripple and at most 200.

    Returns
    -------
    CommandFilter
        Static gain 1 for an odd order, ``10^(-passband_ripple_db / 20)`` for an even one
        (:meth:`CommandFilter.dc_gain`).

    Raises
    ------
    InputError
        An order outside 1..12, a bad band, a ripple or attenuation outside its range.

    Examples
    --------
    The gain at the pass-band edges is the ripple, -1 dB; inside the stop band it is below -40 dB:

    >>> el = elliptic_bandstop(2, (0.2, 0.5), 0.1)
    >>> np.round(el.gain_db([0.2, 0.5]), 6).tolist(), bool(el.gain_db([0.3])[0] <= -40.0)
    ([-1.0, -1.0], True)
    """
    n = _check_order(order)
    ts = _check_sample_time(sample_time)
    lo, hi = _check_band(band, ts)
    rp = check_in_range("passband_ripple_db", passband_ripple_db, 0.0, 10.0, unit=" dB", low_open=True)
    rs = check_in_range("stopband_attenuation_db", stopband_attenuation_db, rp, 200.0, unit=" dB", low_open=True)
    sos = signal.ellip(n, rp, rs, [lo, hi], btype="bandstop", fs=1.0 / ts, output="sos")
    return CommandFilter(sos, ts, f"elliptic BSF order {n}, {lo:g}-{hi:g} Hz")


def multiband_bandstop(
    order: int,
    bands: Sequence[tuple[float, float]],
    sample_time: float,
    kind: str = "butterworth",
    **elliptic_options: float,
) -> CommandFilter:
    """Cascade of one band-stop filter per band (the thesis's Filter-2 and its 0.25 & 0.34 Hz BSF).

    Parameters
    ----------
    order : int
        Prototype order of each band-stop.
    bands : sequence of (low, high)
        Stop bands (Hz); they may overlap.
    sample_time : float
        Sample time ``Ts`` (s).
    kind : {"butterworth", "elliptic"}
        Filter family of every band.
    **elliptic_options
        ``passband_ripple_db`` and ``stopband_attenuation_db`` for ``kind="elliptic"``.

    Returns
    -------
    CommandFilter
        The cascade, ``2 order`` poles per band; the product of the bands' static gains
        (:meth:`CommandFilter.dc_gain`).

    Raises
    ------
    InputError
        An unknown kind, elliptic options for a Butterworth cascade, no band, a bad band.

    Examples
    --------
    The thesis's ch. 6 band-stop: 0.2 Hz wide bands around 0.25 Hz and 0.34 Hz, at 0.2 s:

    >>> f = multiband_bandstop(2, bands_around([0.25, 0.34], 0.2), 0.2)
    >>> f.order, f.name
    (8, 'Butterworth BSF order 2, 0.15-0.35 & 0.24-0.44 Hz')
    """
    designers = {"butterworth": butterworth_bandstop, "elliptic": elliptic_bandstop}
    kind = check_choice("band-stop kind", kind, tuple(designers), error=InputError)
    if kind == "butterworth" and elliptic_options:
        raise InputError(f"options {sorted(elliptic_options)} apply only to kind='elliptic'")
    band_list = _sequence("bands", bands, "(low, high) pairs in Hz")
    if not band_list:
        raise InputError("bands must hold at least one (low, high) pair")
    parts = [designers[kind](order, b, sample_time, **elliptic_options) for b in band_list]
    sos = np.vstack([p.sos for p in parts])
    label = " & ".join(f"{float(lo):g}-{float(hi):g}" for lo, hi in band_list)
    family = "Butterworth" if kind == "butterworth" else "elliptic"
    return CommandFilter(sos, parts[0].sample_time, f"{family} BSF order {order}, {label} Hz")


def bands_around(centres: Sequence[float], bandwidth: float) -> list[tuple[float, float]]:
    """Stop bands of width ``bandwidth`` centred (arithmetically) on each of ``centres``.

    The thesis specifies its ch. 6 band-stop as "centre frequency 0.25 and 0.34 Hz with a
    bandwidth of 0.2 Hz"; this reads it as the bands ``centre -+ bandwidth / 2``.

    Parameters
    ----------
    centres : sequence of float
        Centre frequencies (Hz), each greater than ``bandwidth / 2``.
    bandwidth : float
        Width of each band (Hz), > 0.

    Returns
    -------
    list of (low, high)
        Band edges (Hz).

    Raises
    ------
    InputError
        A bandwidth that is not > 0, a centre at or below ``bandwidth / 2``, no centre.

    Examples
    --------
    >>> [(round(lo, 6), round(hi, 6)) for lo, hi in bands_around([0.25, 0.34], 0.2)]
    [(0.15, 0.35), (0.24, 0.44)]
    """
    bw = check_in_range("bandwidth", bandwidth, 0.0, np.inf, unit=" Hz", low_open=True)
    out = []
    for c in _sequence("centres", centres, "frequencies in Hz"):
        fc = check_in_range("centre frequency", c, bw / 2.0, np.inf, unit=" Hz", low_open=True)
        out.append((fc - bw / 2.0, fc + bw / 2.0))
    if not out:
        raise InputError("centres must hold at least one frequency")
    return out
