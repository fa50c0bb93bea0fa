"""What an input shaper cancels: the residual vibration of a mode after an impulse train (thesis ch. 4.1).

A mode of natural frequency ``f`` (Hz) and damping ratio ``zeta`` (``w = 2 pi f`` rad/s,
``w_d = w sqrt(1 - zeta^2)``) driven by impulses of amplitudes ``A_i`` (summing to 1) at times
``t_i`` (s) is left, after the last impulse, with the fraction ``V`` of the vibration that one unit
impulse would leave (Singer and Seering):

``V = exp(-zeta w t_N) sqrt(C^2 + S^2)``, ``C = sum A_i exp(zeta w t_i) cos(w_d t_i)``,
``S = sum A_i exp(zeta w t_i) sin(w_d t_i)``.

Shapers make ``V`` zero at the modes they were designed for; their robustness is the band of
relative frequency error over which ``V`` stays below a limit. The shapers are
:mod:`trms.control.shaping.continuous` (impulses at any time) and
:mod:`trms.control.shaping.sampled` (taps on a sample grid); the modes to cancel come from a
model's poles (:func:`model_modes`) or a spectrum's peaks.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import control
import numpy as np
from scipy.optimize import brentq

from trms.control.arguments import is_discrete_dt
from trms.errors import InputError, check_in_range
from trms.identification.polynomial import modes_of_poles
from trms.modes import oscillatory

__all__ = ["SHAPER_KINDS", "MAX_SHAPER_DAMPING", "model_modes"]

#: Shapers designed here: zero vibration, zero vibration and derivative.
SHAPER_KINDS = ("zv", "zvd")

#: Damping ratios at or above this are refused by the designers: such a mode barely vibrates, and its
#: shaper would last a damped period ``1 / (f sqrt(1 - zeta^2))`` (7 times the undamped one at 0.99).
MAX_SHAPER_DAMPING = 0.99

#: Largest relative frequency error a robustness band is searched over (each side).
_BAND_SEARCH = 0.95


def _vibration(amplitudes: np.ndarray, times: np.ndarray, frequencies: np.ndarray, damping: float) -> np.ndarray:
    """Residual vibration ``V`` of the impulses at each natural frequency (Hz), one damping ratio."""
    wn = 2.0 * np.pi * frequencies[:, None]
    wd = wn * np.sqrt(1.0 - damping * damping)
    w = amplitudes * np.exp(damping * wn * (times - times[-1]))
    return np.hypot(np.sum(w * np.cos(wd * times), axis=1), np.sum(w * np.sin(wd * times), axis=1))


def shaper_residual(amplitudes: np.ndarray, times: np.ndarray, frequency: object, damping: object) -> float:
    """``V`` of one mode, its frequency (Hz, > 0) and damping (in [0, 1)) checked."""
    f = check_in_range("frequency", frequency, 0.0, np.inf, unit=" Hz", low_open=True)
    z = check_in_range("damping", damping, 0.0, 1.0 - 1e-9)
    return float(_vibration(amplitudes, times, np.array([f]), z)[0])


def robust_band_of(
    amplitudes: np.ndarray, times: np.ndarray, frequency: object, damping: object, limit: object
) -> tuple[float, float]:
    """Relative frequency errors ``(low, high)`` around a mode where ``V <= limit``; ``nan`` if not at the mode."""
    f = check_in_range("frequency", frequency, 0.0, np.inf, unit=" Hz", low_open=True)
    z = check_in_range("damping", damping, 0.0, 1.0 - 1e-9)
    lim = check_in_range("limit", limit, 0.0, 1.0, low_open=True)

    def excess(e: np.ndarray) -> np.ndarray:
        return _vibration(amplitudes, times, f * (1.0 + e), z) - lim

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


def mode_constants(frequency: object, damping: object) -> tuple[float, float, float, float]:
    """``(f, zeta, K, Td)`` of a mode a shaper is designed for, checked: ``K = exp(-zeta pi / sqrt(1 - zeta^2))``
    and the damped period ``Td = 1 / (f sqrt(1 - zeta^2))`` (s)."""
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


def mode_list(modes: object) -> list[tuple[float, float]]:
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


def model_modes(system: control.LTI) -> list[tuple[float, float]]:
    """Oscillatory modes (natural frequency Hz, damping ratio) of a discrete model's poles.

    Each complex pole pair ``z`` maps to ``s = ln(z) / Ts``; ``f = |s| / (2 pi)``,
    ``zeta = -Re(s) / |s|``. Real poles and poles above 0.8 x Nyquist are not modes and are left
    out (:func:`trms.modes.oscillatory`).

    Parameters
    ----------
    system : control.LTI
        Discrete-time model (``dt > 0`` s), e.g. eq. (3.11).

    Returns
    -------
    list of (float, float)
        ``(f, zeta)`` pairs (Hz, dimensionless), sorted by frequency: the argument
        :func:`~trms.control.shaping.continuous.shaper_for_modes` takes.

    Raises
    ------
    InputError
        Not a discrete python-control model with a finite numeric ``dt``.

    Examples
    --------
    A 0.25 Hz mode of damping 0.05 and a real lag, sampled at 0.2 s:

    >>> w = 2 * np.pi * 0.25
    >>> g = control.tf([w * w], [1.0, 2 * 0.05 * w, w * w]) * control.tf([1.0], [1.0, 1.0])
    >>> [(round(f, 6), round(z, 6)) for f, z in model_modes(control.c2d(g, 0.2))]
    [(0.25, 0.05)]
    """
    dt = getattr(system, "dt", None)
    if not isinstance(system, control.LTI) or not is_discrete_dt(dt):
        raise InputError(
            f"system must be a discrete-time python-control model with a finite numeric dt > 0, got {system!r}"
        )
    ts = float(system.dt)
    modes = oscillatory(modes_of_poles(np.asarray(system.poles(), dtype=complex), ts), ts)
    return [(m.frequency_hz, m.damping) for m in modes]
