"""Disturbances on the beam: pushes (torque pulses, thesis ch. 7.4) and seeded gusts."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, as_finite_array, check_in_range

__all__ = ["Push", "Gust"]


@dataclass(frozen=True)
class Push:
    """A torque pulse on the beam: ``torque`` (N m, about pitch then yaw) from ``time`` for ``duration`` s.

    The impulse is ``torque * duration`` (N m s). The thesis pushed the beam by hand at
    about 18-20 s (ch. 7.4).
    """

    time: float
    duration: float
    torque: tuple[float, float]

    def __post_init__(self) -> None:
        check_in_range("push time", self.time, 0.0, 1e9, unit=" s")
        check_in_range("push duration", self.duration, 0.0, 1e9, unit=" s", low_open=True)
        tq = as_finite_array("push torque (pitch, yaw) in N m", np.ravel(self.torque), (2,))
        if np.any(np.abs(tq) > 100):
            raise InputError(f"push torque {tq.tolist()} N m is outside [-100, 100] N m")
        object.__setattr__(self, "torque", (float(tq[0]), float(tq[1])))

    def steps(self, timestep: float) -> tuple[int, int]:
        """The physics steps ``[first, end)`` the push acts on, at a physics time step of ``timestep`` s
        (at least one step).

        Examples
        --------
        >>> Push(1.0, 0.1, (1.0, 0.0)).steps(0.001)
        (1000, 1100)
        """
        first = int(round(self.time / timestep))
        return first, first + max(1, int(round(self.duration / timestep)))

    @classmethod
    def impulse(cls, time: float, impulse: float, duration: float = 0.1, axis: str = "pitch") -> Push:
        """A push of a given angular impulse (N m s) about ``axis`` ("pitch" or "yaw") over ``duration`` s."""
        if axis not in ("pitch", "yaw"):
            raise InputError(f"push axis {axis!r} must be 'pitch' or 'yaw'")
        tq = float(impulse) / float(duration)
        return cls(time, duration, (tq, 0.0) if axis == "pitch" else (0.0, tq))


@dataclass(frozen=True)
class Gust:
    """Gust torques on pitch and yaw: a seeded Ornstein-Uhlenbeck (first-order filtered white) process.

    The torque is held over each control interval and updated by the exact discretisation
    ``g[k+1] = a g[k] + std sqrt(1 - a^2) w[k]``, ``a = exp(-Ts / time_constant)``, so its
    stationary standard deviation is ``std`` whatever the sample time.

    Parameters
    ----------
    std : float
        Stationary standard deviation of each torque (N m); 0 disables gusts.
    time_constant : float
        Correlation time (s).
    """

    std: float = 0.0
    time_constant: float = 2.0

    def __post_init__(self) -> None:
        check_in_range("gust std", self.std, 0.0, 10.0, unit=" N m")
        check_in_range("gust time_constant", self.time_constant, 0.0, 1e4, unit=" s", low_open=True)

    def start(self, rng: np.random.Generator) -> np.ndarray:
        """Initial torques (N m), drawn from the stationary distribution."""
        return self.std * rng.standard_normal(2) if self.std else np.zeros(2)

    def advance(self, torque: np.ndarray, dt: float, rng: np.random.Generator) -> np.ndarray:
        """Torques one interval of ``dt`` s later (N m)."""
        if not self.std:
            return np.zeros(2)
        a = np.exp(-dt / self.time_constant)
        return a * torque + self.std * np.sqrt(1.0 - a * a) * rng.standard_normal(2)
