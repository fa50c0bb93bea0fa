"""One mode type for the whole package: a pole pair's natural frequency and damping.

Every part that speaks of modes -- the twin's linearisation (:mod:`trms.twin.linearise`), the
identified polynomial models (:mod:`trms.identification.polynomial`) and the reports -- returns
:class:`Mode`. :func:`oscillatory` keeps the poles that are modes a reader can see in a spectrum:
``0 < f < 0.8 x Nyquist`` and damping below 1; :func:`real_poles` lists the others (real poles,
listed separately, and poles at the Nyquist frequency).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

__all__ = ["Mode", "NYQUIST_FRACTION", "oscillatory", "real_poles", "mode_of_eigenvalue"]

#: Modes above this fraction of the Nyquist frequency are artefacts of sampling, not of the plant.
NYQUIST_FRACTION = 0.8


@dataclass(frozen=True)
class Mode:
    """A mode: natural frequency, damping ratio, the continuous-time eigenvalue, the dominant coordinate.

    Attributes
    ----------
    frequency_hz : float
        Undamped natural frequency ``|lambda| / 2 pi`` (Hz).
    damping : float
        Damping ratio ``-Re(lambda) / |lambda|`` (1 for a real pole).
    eigenvalue : complex
        Continuous-time eigenvalue (1/s), imaginary part >= 0 (for a discrete pole ``z``,
        ``ln(z) / Ts``).
    dominant : str
        Name of the coordinate with the largest share of the mode shape ("" when unknown).

    Examples
    --------
    >>> m = mode_of_eigenvalue(complex(-0.1, 2.0))
    >>> round(m.frequency_hz, 3), round(m.damping, 3)
    (0.319, 0.05)
    """

    frequency_hz: float
    damping: float
    eigenvalue: complex
    dominant: str = ""

    @property
    def damped_frequency_hz(self) -> float:
        """``Im(lambda) / 2 pi`` (Hz)."""
        return float(self.eigenvalue.imag / (2 * np.pi))


def mode_of_eigenvalue(lam: complex, dominant: str = "") -> Mode:
    """The :class:`Mode` of a continuous-time eigenvalue ``lam`` (1/s)."""
    lam = complex(lam.real, abs(lam.imag))
    wn = abs(lam)
    return Mode(float(wn / (2 * np.pi)), float(-lam.real / wn) if wn > 0 else 1.0, lam, dominant)


def oscillatory(modes: Iterable[Mode], sample_time: float | None = None) -> list[Mode]:
    """The modes with ``0 < f < 0.8 x Nyquist`` (any ``f > 0`` in continuous time) and damping below 1.

    Parameters
    ----------
    modes : iterable of Mode
    sample_time : float, optional
        Sample time (s) of a discrete model; ``None`` for a continuous one.

    Examples
    --------
    >>> ms = [mode_of_eigenvalue(-1.0), mode_of_eigenvalue(complex(-0.1, 2.0))]
    >>> [round(m.frequency_hz, 3) for m in oscillatory(ms)]
    [0.319]
    """
    top = np.inf if sample_time is None else NYQUIST_FRACTION * 0.5 / float(sample_time)
    return [m for m in modes if 0.0 < m.frequency_hz < top and m.damping < 1.0]


def real_poles(modes: Iterable[Mode], sample_time: float | None = None) -> list[Mode]:
    """The modes :func:`oscillatory` leaves out (real poles, poles near or at Nyquist), to be listed apart."""
    modes = list(modes)
    keep = set(id(m) for m in oscillatory(modes, sample_time))
    return [m for m in modes if id(m) not in keep]
