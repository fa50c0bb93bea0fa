"""Steady-state rotor thrust curves: the static (Hammerstein) part of the rotor model.

The motor voltage ``V`` sets a steady rotor state ``tau = k V`` (Feedback's simplified
model, ``k = k1 / T10``), and the thrust is ``F = a tau|tau| + b tau`` with different
coefficients for forward and reverse rotation (the propeller is asymmetric). The MJCF's
actuator takes ``F(V)`` as its control and lags it by the motor time constant.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelFileError

__all__ = ["ThrustCurve"]


@dataclass(frozen=True)
class ThrustCurve:
    """``F(V) = a tau|tau| + b tau``, ``tau = k V``; (a, b) by the sign of ``tau``.

    Parameters
    ----------
    k : float
        Rotor state per volt (1/V).
    a_pos, b_pos : float
        Quadratic and linear thrust coefficients for ``tau >= 0`` (N).
    a_neg, b_neg : float
        The same for ``tau < 0`` (N).
    """

    k: float
    a_pos: float
    b_pos: float
    a_neg: float
    b_neg: float

    def __post_init__(self) -> None:
        vals = np.array([self.k, self.a_pos, self.b_pos, self.a_neg, self.b_neg])
        if not np.all(np.isfinite(vals)) or np.any(vals < 0) or self.k == 0 or (self.b_pos == 0 and self.a_pos == 0):
            raise ModelFileError(
                f"thrust curve coefficients must be finite and >= 0 with k > 0, got k, a+, b+, a-, b- = {vals.tolist()}"
            )

    @classmethod
    def from_array(cls, data: np.ndarray) -> "ThrustCurve":
        """Build from ``[k, a_pos, b_pos, a_neg, b_neg]`` (the MJCF custom numeric)."""
        data = np.asarray(data, float).ravel()
        if data.shape != (5,):
            raise ModelFileError(f"a thrust curve needs 5 numbers [k, a+, b+, a-, b-], got {data.tolist()}")
        return cls(*(float(x) for x in data))

    def to_array(self) -> np.ndarray:
        """``[k, a_pos, b_pos, a_neg, b_neg]``."""
        return np.array([self.k, self.a_pos, self.b_pos, self.a_neg, self.b_neg])

    def _coeffs(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        pos = tau >= 0
        return np.where(pos, self.a_pos, self.a_neg), np.where(pos, self.b_pos, self.b_neg)

    def _scalar_coeffs(self, tau: float) -> tuple[float, float]:
        return (self.a_pos, self.b_pos) if tau >= 0 else (self.a_neg, self.b_neg)

    def thrust(self, volts: np.ndarray | float) -> np.ndarray | float:
        """Steady-state thrust (N) for a motor voltage (V); a float for a scalar voltage."""
        if np.ndim(volts) == 0:  # the per-step path: plain floats are ten times faster than 0-d arrays
            tau = self.k * float(volts)
            a, b = self._scalar_coeffs(tau)
            return a * tau * abs(tau) + b * tau
        tau = self.k * np.asarray(volts, float)
        a, b = self._coeffs(tau)
        return a * tau * np.abs(tau) + b * tau

    def slope(self, volts: np.ndarray | float) -> np.ndarray:
        """``dF/dV`` (N/V) at a voltage: the small-signal thrust gain."""
        tau = self.k * np.asarray(volts, float)
        a, b = self._coeffs(tau)
        return self.k * (2.0 * a * np.abs(tau) + b)

    def rotor_state(self, thrust: np.ndarray | float) -> np.ndarray | float:
        """Invert the curve: the rotor state ``tau`` that produces a thrust (N).

        This is what a tachogenerator reads, in the model's rotor-state units
        (``tau = k V`` at steady state). A float for a scalar thrust.
        """
        if np.ndim(thrust) == 0:
            f = float(thrust)
            a, b = self._scalar_coeffs(f)
            mag = abs(f)
            tau = (-b + math.sqrt(b * b + 4.0 * a * mag)) / (2.0 * a) if a > 0 else mag / b
            return math.copysign(tau, f)
        f = np.asarray(thrust, float)
        s = np.sign(f)
        a, b = self._coeffs(f)
        mag = np.abs(f)
        with np.errstate(divide="ignore", invalid="ignore"):
            quad = (-b + np.sqrt(b * b + 4.0 * a * mag)) / (2.0 * a)
        lin = mag / np.where(b > 0, b, np.inf)
        return s * np.where(a > 0, quad, lin)

    def voltage(self, thrust: np.ndarray | float) -> np.ndarray:
        """The voltage (V) whose steady thrust is ``thrust`` (N)."""
        return self.rotor_state(thrust) / self.k
