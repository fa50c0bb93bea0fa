"""Steady-state rotor thrust curves: the static (Hammerstein) part of the rotor model.

The motor voltage ``V`` sets a steady rotor state ``tau = clip(k V, -tau_max, tau_max)``
(Feedback's simplified model, ``k = k1 / T10``; ``tau_max`` is the rotor's full speed), and
the thrust is ``F = a tau|tau| + b tau`` with different coefficients for forward and reverse
rotation (the propeller is asymmetric). The rotor spins at ``w = w_per_state tau`` (rad/s).
The MJCF's thrust actuator takes ``F(V)`` as its control and lags it by the motor time
constant; its spin motor takes ``w(V)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from trms.errors import ModelFileError

__all__ = ["ThrustCurve", "rotor_controls", "rotor_control_values"]


@dataclass(frozen=True)
class ThrustCurve:
    """``F(V) = a tau|tau| + b tau``, ``tau = clip(k V, -tau_max, tau_max)``; (a, b) by the sign of ``tau``.

    Parameters
    ----------
    k : float
        Rotor state per volt (1/V).
    a_pos, b_pos : float
        Quadratic and linear thrust coefficients for ``tau >= 0`` (N).
    a_neg, b_neg : float
        The same for ``tau < 0`` (N).
    tau_max : float
        Full speed, as a rotor state: beyond it more voltage gives no more thrust.
    w_per_state : float
        Rotor speed per unit of rotor state (rad/s); 0 for a model without spinning rotor bodies.

    Examples
    --------
    >>> c = ThrustCurve(1.1, 0.05625, 0.385, 0.03236, 0.2215, 11.0, 57.12)
    >>> round(c.thrust(10.0), 2), round(c.thrust(20.0), 2)
    (11.04, 11.04)
    """

    k: float
    a_pos: float
    b_pos: float
    a_neg: float
    b_neg: float
    tau_max: float = math.inf
    w_per_state: float = 0.0

    def __post_init__(self) -> None:
        vals = np.array([self.k, self.a_pos, self.b_pos, self.a_neg, self.b_neg, self.w_per_state])
        if (
            not np.all(np.isfinite(vals))
            or np.any(vals < 0)
            or self.k == 0
            or (self.b_pos == 0 and self.a_pos == 0)
            or not self.tau_max > 0
        ):
            raise ModelFileError(
                "thrust curve coefficients must be finite and >= 0 with k > 0 and tau_max > 0, got "
                f"k, a+, b+, a-, b-, tau_max, w_per_state = {self.to_array().tolist()}"
            )

    @classmethod
    def from_array(cls, data: np.ndarray) -> ThrustCurve:
        """Build from ``[k, a_pos, b_pos, a_neg, b_neg, tau_max, w_per_state]`` (the MJCF custom numeric).

        The last two may be left out (no speed limit, no spinning rotor).
        """
        data = np.asarray(data, float).ravel()
        if data.shape not in ((5,), (7,)):
            raise ModelFileError(
                "a thrust curve needs 7 numbers [k, a+, b+, a-, b-, tau_max, w_per_state] "
                f"(or the first 5), got {data.tolist()}"
            )
        return cls(*(float(x) for x in data))

    def to_array(self) -> np.ndarray:
        """``[k, a_pos, b_pos, a_neg, b_neg, tau_max, w_per_state]``."""
        return np.array([self.k, self.a_pos, self.b_pos, self.a_neg, self.b_neg, self.tau_max, self.w_per_state])

    @property
    def max_thrust(self) -> tuple[float, float]:
        """Thrust at full speed forward and in reverse (N): ``(F(+tau_max), F(-tau_max))``."""
        return (
            self.a_pos * self.tau_max**2 + self.b_pos * self.tau_max,
            -(self.a_neg * self.tau_max**2 + self.b_neg * self.tau_max),
        )

    def state(self, volts: np.ndarray | float) -> np.ndarray | float:
        """Steady rotor state ``clip(k V, -tau_max, tau_max)`` for a voltage; a float for a scalar."""
        if np.ndim(volts) == 0:
            return self._state_of(float(volts))
        return np.clip(self.k * np.asarray(volts, float), -self.tau_max, self.tau_max)

    # The per-step paths: one voltage or thrust as a plain float (ten times faster than 0-d arrays, the same bits).
    def _state_of(self, volts: float) -> float:
        return max(-self.tau_max, min(self.tau_max, self.k * volts))

    def _thrust_of(self, volts: float) -> float:
        return self._thrust_at(self._state_of(volts))

    def _thrust_at(self, t: float) -> float:
        """The thrust (N) at rotor state ``t``."""
        ka, kb = (self.a_pos, self.b_pos) if t >= 0 else (self.a_neg, self.b_neg)
        return ka * t * abs(t) + kb * t

    def _speed_of(self, volts: float) -> float:
        return self.w_per_state * self._state_of(volts)

    def _rotor_state_of(self, thrust: float) -> float:
        ka, kb = self._scalar_coeffs(thrust)
        m = abs(thrust)
        t = (-kb + math.sqrt(kb * kb + 4.0 * ka * m)) / (2.0 * ka) if ka > 0 else m / kb
        return math.copysign(t, thrust)

    def at_full_speed(self, volts: np.ndarray | float) -> np.ndarray:
        """Whether the voltage asks for more than full speed (the thrust no longer grows with it)."""
        return np.abs(self.k * np.asarray(volts, float)) > self.tau_max

    def speed(self, volts: np.ndarray | float) -> np.ndarray | float:
        """Steady rotor speed (rad/s) for a voltage."""
        if np.ndim(volts) == 0:
            return self._speed_of(float(volts))
        return self.w_per_state * np.asarray(self.state(volts))

    def _coeffs(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        pos = tau >= 0
        return np.where(pos, self.a_pos, self.a_neg), np.where(pos, self.b_pos, self.b_neg)

    def _scalar_coeffs(self, tau: float) -> tuple[float, float]:
        return (self.a_pos, self.b_pos) if tau >= 0 else (self.a_neg, self.b_neg)

    def thrust(self, volts: np.ndarray | float) -> np.ndarray | float:
        """Steady-state thrust (N) for a motor voltage (V); a float for a scalar voltage."""
        if np.ndim(volts) == 0:
            return self._thrust_of(float(volts))
        tau = np.asarray(self.state(volts))
        a, b = self._coeffs(tau)
        return a * tau * np.abs(tau) + b * tau

    def slope(self, volts: np.ndarray | float) -> np.ndarray:
        """``dF/dV`` (N/V) at a voltage: the small-signal thrust gain (0 beyond full speed)."""
        tau = self.k * np.asarray(volts, float)
        a, b = self._coeffs(tau)
        return np.where(np.abs(tau) > self.tau_max, 0.0, self.k * (2.0 * a * np.abs(tau) + b))

    def rotor_state(self, thrust: np.ndarray | float) -> np.ndarray | float:
        """Invert the curve: the rotor state ``tau`` that produces a thrust (N).

        This is what a tachogenerator reads, in the model's rotor-state units
        (``tau = k V`` at steady state). A float for a scalar thrust.
        """
        if np.ndim(thrust) == 0:
            return self._rotor_state_of(float(thrust))
        f = np.asarray(thrust, float)
        a, b = self._coeffs(f)
        mag = np.abs(f)
        with np.errstate(divide="ignore", invalid="ignore"):
            quad = (-b + np.sqrt(b * b + 4.0 * a * mag)) / (2.0 * a)
        lin = mag / np.where(b > 0, b, np.inf)
        return np.copysign(np.where(a > 0, quad, lin), f)  # the scalar path's sign, a zero's included

    def voltage(self, thrust: np.ndarray | float) -> np.ndarray | float:
        """The voltage (V) whose steady thrust is ``thrust`` (N); a float for a scalar thrust."""
        return self.rotor_state(thrust) / self.k


def rotor_controls(
    curves: tuple[ThrustCurve, ...], volts: np.ndarray, n_actuators: int, spinning: bool | None = None
) -> np.ndarray:
    """The model's actuator controls for rotor voltages, in actuator order.

    ``[thrust of each rotor (N), speed of each rotor (rad/s), 0 for each further actuator]``: the thrust
    actuators first, then the spin motors when the model has them, then any further actuators (the rotors'
    turbulence actuators, whose controls the twin sets itself) at 0.

    Parameters
    ----------
    curves : tuple of ThrustCurve
        One per rotor (main, tail).
    volts : numpy.ndarray
        Voltages (V), shape ``(n_rotors,)`` or ``(N, n_rotors)``.
    n_actuators : int
        ``model.nu``.
    spinning : bool, optional
        Whether the model has spin motors (default: ``n_actuators >= 2 n_rotors``).

    Returns
    -------
    numpy.ndarray
        Shape ``(n_actuators,)`` or ``(N, n_actuators)``.

    Examples
    --------
    >>> c = ThrustCurve(1.1, 0.05625, 0.385, 0.03236, 0.2215, 11.0, 57.12)
    >>> rotor_controls((c, c), np.array([10.0, 0.0]), 4).round(2).tolist()
    [11.04, 0.0, 628.32, 0.0]
    >>> rotor_controls((c, c), np.array([10.0, 0.0]), 6).round(2).tolist()
    [11.04, 0.0, 628.32, 0.0, 0.0, 0.0]
    """
    v = np.asarray(volts, float)
    if v.ndim == 1:  # one sample's voltages as plain floats: the curves' per-step path
        return np.array(rotor_control_values(curves, v.tolist(), n_actuators, spinning))
    n_rot = len(curves)
    spinning = n_actuators >= 2 * n_rot if spinning is None else spinning
    out = np.zeros(v.shape[:-1] + (n_actuators,))
    columns = [c.thrust(v[..., i]) for i, c in enumerate(curves)]
    if spinning:
        columns += [c.speed(v[..., i]) for i, c in enumerate(curves)]
    out[..., : len(columns)] = np.stack(columns, axis=-1)
    return out


def rotor_control_values(
    curves: tuple[ThrustCurve, ...], volts: list[float], n_actuators: int, spinning: bool | None = None
) -> list[float]:
    """:func:`rotor_controls` of one sample's voltages (V, plain floats) as plain floats: the per-step path.

    Examples
    --------
    >>> c = ThrustCurve(1.1, 0.05625, 0.385, 0.03236, 0.2215, 11.0, 57.12)
    >>> [round(x, 2) for x in rotor_control_values((c, c), [10.0, 0.0], 6)]
    [11.04, 0.0, 628.32, 0.0, 0.0, 0.0]
    """
    spinning = n_actuators >= 2 * len(curves) if spinning is None else spinning
    values, speeds = [], []
    for x, c in zip(volts, curves):  # one loop: a control interval's few numbers
        t = c._state_of(x)
        values.append(c._thrust_at(t))
        speeds.append(c.w_per_state * t)
    if spinning:
        values += speeds
    return values + [0.0] * (n_actuators - len(values))
