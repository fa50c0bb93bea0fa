"""Input shapers: the impulse-sequence family the thesis cites for command shaping (ch. 4.1).

Singer and Seering's shapers convolve a command with a short sequence of impulses whose
amplitudes and times cancel the residual vibration (:mod:`trms.control.shaping.vibration`) of a
mode of natural frequency ``f`` (Hz) and damping ratio ``zeta``:

* ZV (zero vibration): two impulses, ``A = [1, K] / (1 + K)`` at ``t = [0, Td / 2]``;
* ZVD (zero vibration and derivative): three impulses, ``A = [1, 2K, K^2] / (1 + K)^2`` at
  ``t = [0, Td / 2, Td]``, which also zeroes the sensitivity to the frequency;

with ``K = exp(-zeta pi / sqrt(1 - zeta^2))`` and the damped period
``Td = 1 / (f sqrt(1 - zeta^2))``. Shapers for several modes are convolved. A controller applies
a shaper on its sample grid: :meth:`InputShaper.at` redesigns it there so that it still cancels
its modes exactly (:mod:`trms.control.shaping.sampled`).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from trms.control.shaping.sampled import SampledShaper, on_grid, rounded_to_grid
from trms.control.shaping.vibration import SHAPER_KINDS, mode_constants, mode_list, robust_band_of, shaper_residual
from trms.errors import InputError, as_finite_array, check_choice, check_in_range

__all__ = ["InputShaper", "zv_shaper", "zvd_shaper", "shaper_for_modes"]


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
        """Time of the last impulse (s): the delay the shaper adds to a command.

        Examples
        --------
        Half the damped period of a 0.25 Hz mode of damping 0.6 (``Td = 1 / (0.25 x 0.8)`` = 5 s):

        >>> zv_shaper(0.25, 0.6).duration
        2.5
        """
        return float(self.times[-1])

    @property
    def designed(self) -> bool:
        """True when the impulses are the designs ``kinds`` of ``modes`` (so :meth:`at` can redesign them).

        Examples
        --------
        >>> zv_shaper(0.25, 0.0).designed, InputShaper(np.array([0.5, 0.5]), np.array([0.0, 2.0]), "two").designed
        (True, False)
        """
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
            ``V`` (fraction; :mod:`trms.control.shaping.vibration`).

        Examples
        --------
        >>> round(zv_shaper(0.25, 0.0).residual_vibration(0.25, 0.0), 12)
        0.0
        """
        return shaper_residual(self.amplitudes, self.times, frequency, damping)

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
        return robust_band_of(self.amplitudes, self.times, frequency, damping, limit)

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

        A designed shaper (:attr:`designed`: ZV/ZVD of known modes) is redesigned on the grid as by
        :func:`~trms.control.shaping.sampled.discrete_shaper` (zero residual vibration, and zero derivative for
        ZVD, at each mode); any other impulse sequence is rounded to the grid (:meth:`rounded`).

        Parameters
        ----------
        sample_time : float
            Sample time ``Ts`` (s), > 0.

        Returns
        -------
        SampledShaper
            Taps summing to 1 at ``sample_time``.

        Raises
        ------
        InputError
            A designed mode at or above the Nyquist frequency ``1 / (2 Ts)``: on that grid the
            impulses merge and the shaper cannot cancel the mode.

        Examples
        --------
        The 0.34 Hz mode on a 0.2 s grid: the redesign cancels it, rounding leaves 9.3 % (:meth:`rounded`):

        >>> grid = zvd_shaper(0.34, 0.041).at(0.2)
        >>> grid.residual_vibration(0.34, 0.041) < 1e-12, zvd_shaper(0.34, 0.041).rounded(0.2).taps.size
        (True, 16)
        """
        ts = check_in_range("sample_time", sample_time, 0.0, np.inf, unit=" s", low_open=True)
        if self.designed:
            return on_grid(self.modes, self.kinds, ts)
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
        return rounded_to_grid(self.amplitudes, self.times, self.name, self.modes, ts)


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


def zv_shaper(frequency: float, damping: float) -> InputShaper:
    """Zero-vibration (ZV) shaper of a mode (Singer and Seering).

    Parameters
    ----------
    frequency : float
        Natural frequency of the mode (Hz), > 0.
    damping : float
        Damping ratio, in [0, 0.99) (:data:`~trms.control.shaping.vibration.MAX_SHAPER_DAMPING`).

    Returns
    -------
    InputShaper
        Two impulses, half a damped period apart.

    Raises
    ------
    InputError
        A frequency that is not a positive number of Hz, a damping outside [0, 0.99).

    Examples
    --------
    An undamped 0.25 Hz mode (period 4 s): two equal impulses half a period apart.

    >>> s = zv_shaper(0.25, 0.0)
    >>> s.amplitudes.tolist(), s.times.tolist()
    ([0.5, 0.5], [0.0, 2.0])
    """
    f, z, k, td = mode_constants(frequency, damping)
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
        Damping ratio, in [0, 0.99) (:data:`~trms.control.shaping.vibration.MAX_SHAPER_DAMPING`).

    Returns
    -------
    InputShaper
        Three impulses over one damped period.

    Raises
    ------
    InputError
        A frequency that is not a positive number of Hz, a damping outside [0, 0.99).

    Examples
    --------
    >>> s = zvd_shaper(0.25, 0.0)
    >>> s.amplitudes.tolist(), s.times.tolist()
    ([0.25, 0.5, 0.25], [0.0, 2.0, 4.0])
    """
    f, z, k, td = mode_constants(frequency, damping)
    amps = np.array([1.0, 2.0 * k, k * k]) / (1.0 + k) ** 2
    return InputShaper(amps, np.array([0.0, td / 2.0, td]), f"ZVD {f:g} Hz, zeta {z:g}", ((f, z),), ("zvd",))


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
        The convolution of the shapers, ``kinds`` set (so :meth:`InputShaper.at` redesigns it on a grid).

    Raises
    ------
    InputError
        Not a sequence of (frequency, damping) pairs, a bad mode, an unknown kind.

    Examples
    --------
    Two ZV shapers of two impulses each convolve to four impulses:

    >>> s = shaper_for_modes([(0.25, 0.05), (0.34, 0.041)], kind="zv")
    >>> s.times.size, s.kinds
    (4, ('zv', 'zv'))
    """
    design = check_choice("shaper kind", kind, SHAPER_KINDS, error=InputError)
    designers = {"zv": zv_shaper, "zvd": zvd_shaper}
    shapers = [designers[design](f, z) for f, z in mode_list(modes)]
    out = shapers[0]
    for s in shapers[1:]:
        out = out.convolve(s)
    return out
