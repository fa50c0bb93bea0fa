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

On a sampled command, each impulse falls on the nearest sample (:meth:`InputShaper.at`);
the rounding moves the cancelled frequency slightly, and :meth:`InputShaper.residual_vibration`
of the sampled shaper tells by how much it matters.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import control
import numpy as np

from ...errors import InputError, as_finite_array, check_in_range
from .filters import shape_command

__all__ = [
    "InputShaper",
    "SampledShaper",
    "zv_shaper",
    "zvd_shaper",
    "shaper_for_modes",
    "model_modes",
]


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
    """

    amplitudes: np.ndarray
    times: np.ndarray
    name: str
    modes: tuple[tuple[float, float], ...] = ()

    def __post_init__(self) -> None:
        a = as_finite_array("amplitudes", self.amplitudes, (None,))
        t = as_finite_array("times", self.times, (a.shape[0],))
        if a.shape[0] == 0:
            raise InputError("an input shaper needs at least one impulse")
        if not np.isclose(a.sum(), 1.0, rtol=0.0, atol=1e-9):
            raise InputError(f"shaper amplitudes must sum to 1, got {a.sum()!r}")
        if t[0] != 0.0 or np.any(np.diff(t) < 0):
            raise InputError(f"shaper times must start at 0 s and not decrease, got {t.tolist()}")
        a.flags.writeable = False
        t.flags.writeable = False
        object.__setattr__(self, "amplitudes", a)
        object.__setattr__(self, "times", t)

    @property
    def duration(self) -> float:
        """Time of the last impulse (s): the delay the shaper adds to a command."""
        return float(self.times[-1])

    def residual_vibration(self, frequency: float, damping: float) -> float:
        """Residual vibration ``V`` of a mode (1 = unshaped, 0 = cancelled).

        Parameters
        ----------
        frequency : float
            Natural frequency (Hz), > 0.
        damping : float
            Damping ratio, in [0, 1).
        """
        f = check_in_range("frequency", frequency, 0.0, np.inf, unit=" Hz", low_open=True)
        z = check_in_range("damping", damping, 0.0, 1.0 - 1e-9)
        wn = 2.0 * np.pi * f
        wd = wn * np.sqrt(1.0 - z * z)
        w = self.amplitudes * np.exp(z * wn * (self.times - self.times[-1]))
        return float(np.hypot(np.sum(w * np.cos(wd * self.times)), np.sum(w * np.sin(wd * self.times))))

    def convolve(self, other: InputShaper) -> InputShaper:
        """The shaper whose impulse train is the convolution of the two (cancels both sets of modes)."""
        times = (self.times[:, None] + other.times[None, :]).ravel()
        amps = (self.amplitudes[:, None] * other.amplitudes[None, :]).ravel()
        return _merged(amps, times, f"{self.name} * {other.name}", self.modes + other.modes)

    def at(self, sample_time: float) -> SampledShaper:
        """The shaper on the sample grid: each impulse moved to the nearest sample.

        Parameters
        ----------
        sample_time : float
            Sample time ``Ts`` (s), > 0.

        Raises
        ------
        InputError
            A designed mode at or above the Nyquist frequency ``1 / (2 Ts)``: on that grid the
            impulses merge and the shaper cannot cancel the mode.
        """
        ts = check_in_range("sample_time", sample_time, 0.0, np.inf, unit=" s", low_open=True)
        above = [f for f, _ in self.modes if f >= 0.5 / ts]
        if above:
            raise InputError(
                f"shaper {self.name!r} cancels a mode at {above[0]:g} Hz, at or above the Nyquist frequency "
                f"{0.5 / ts:g} Hz of sample_time = {ts:g} s; allowed: modes below {0.5 / ts:g} Hz"
            )
        idx = np.rint(self.times / ts).astype(np.int64)
        taps = np.zeros(int(idx[-1]) + 1)
        np.add.at(taps, idx, self.amplitudes)
        return SampledShaper(taps, ts, f"{self.name} @ {ts:g} s")


def _merged(
    amplitudes: np.ndarray, times: np.ndarray, name: str, modes: tuple[tuple[float, float], ...] = ()
) -> InputShaper:
    """Sort impulses by time and merge those at the same time."""
    order = np.argsort(times, kind="stable")
    t, a = times[order], amplitudes[order]
    keys, inverse = np.unique(np.round(t, 12), return_inverse=True)
    merged = np.zeros(keys.shape[0])
    np.add.at(merged, inverse, a)
    return InputShaper(merged, keys - keys[0], name, modes)


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

    def as_shaper(self) -> InputShaper:
        """The impulse sequence this FIR realises (times on the sample grid)."""
        nz = np.flatnonzero(self.taps)
        return InputShaper(self.taps[nz], (nz - nz[0]) * self.sample_time, self.name)

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


def _mode_constants(frequency: float, damping: float) -> tuple[float, float]:
    f = check_in_range("frequency", frequency, 0.0, np.inf, unit=" Hz", low_open=True)
    z = check_in_range("damping", damping, 0.0, 1.0 - 1e-9)
    root = np.sqrt(1.0 - z * z)
    return float(np.exp(-z * np.pi / root)), float(1.0 / (f * root))


def zv_shaper(frequency: float, damping: float) -> InputShaper:
    """Zero-vibration (ZV) shaper of a mode (Singer and Seering).

    Parameters
    ----------
    frequency : float
        Natural frequency of the mode (Hz), > 0.
    damping : float
        Damping ratio, in [0, 1).

    Returns
    -------
    InputShaper
        Two impulses, half a damped period apart.
    """
    k, td = _mode_constants(frequency, damping)
    return InputShaper(
        np.array([1.0, k]) / (1.0 + k),
        np.array([0.0, td / 2.0]),
        f"ZV {frequency:g} Hz, zeta {damping:g}",
        ((float(frequency), float(damping)),),
    )


def zvd_shaper(frequency: float, damping: float) -> InputShaper:
    """Zero-vibration-and-derivative (ZVD) shaper of a mode (Singer and Seering).

    Parameters
    ----------
    frequency : float
        Natural frequency of the mode (Hz), > 0.
    damping : float
        Damping ratio, in [0, 1).

    Returns
    -------
    InputShaper
        Three impulses over one damped period.
    """
    k, td = _mode_constants(frequency, damping)
    amps = np.array([1.0, 2.0 * k, k * k]) / (1.0 + k) ** 2
    return InputShaper(
        amps,
        np.array([0.0, td / 2.0, td]),
        f"ZVD {frequency:g} Hz, zeta {damping:g}",
        ((float(frequency), float(damping)),),
    )


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
    """
    designers = {"zv": zv_shaper, "zvd": zvd_shaper}
    if kind not in designers:
        raise InputError(f"unknown shaper kind {kind!r}; allowed: 'zv', 'zvd'")
    shapers = [designers[kind](f, z) for f, z in modes]
    if not shapers:
        raise InputError("modes must hold at least one (frequency, damping) pair")
    out = shapers[0]
    for s in shapers[1:]:
        out = out.convolve(s)
    return out


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
    if not isinstance(system, control.LTI) or dt is None or dt is True or not dt or dt <= 0:
        raise InputError(f"system must be a discrete-time python-control model with numeric dt > 0, got {system!r}")
    from ...identification.polynomial import modes_of_poles
    from ...modes import oscillatory

    modes = oscillatory(modes_of_poles(np.asarray(system.poles(), dtype=complex), float(dt)), float(dt))
    return [(m.frequency_hz, m.damping) for m in modes]
