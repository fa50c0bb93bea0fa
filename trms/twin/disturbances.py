"""Disturbances: the rig's own rotor-wash turbulence, and the experiments' pushes (thesis ch. 7.4) and gusts.

The turbulence is part of the rig (the thesis: "a minor oscillatory tendency even in steady state"): a
seeded thrust fluctuation on each rotor, on by default in every :class:`~trms.twin.Twin`, its level a
calibrated parameter of the MJCF. Gusts and pushes are experiment choices, off unless asked for. The
turbulence and the gusts are the same process: first-order filtered white noise (Ornstein-Uhlenbeck),
held over each control interval and advanced by its exact discretisation, so their stationary standard
deviation does not depend on the sample time.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from trms.errors import InputError, as_finite_array, check_in_range

__all__ = ["Push", "Gust", "MOVING_AIR", "Turbulence", "NormalDraws", "Normals", "OUStep", "ou_advance", "ou_path"]


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


class NormalDraws:
    """A generator's standard normal draws, drawn a block at a time and handed out in order.

    ``standard_normal(shape)`` returns what the generator's own ``standard_normal(shape)`` would for the same
    sequence of calls, the same bits (a generator fills an array in the order its single draws come), but one call
    of the generator serves many: a twin asks for two or three numbers a control interval.

    Parameters
    ----------
    rng : numpy.random.Generator
        The generator (this object's alone from now on).
    block : int
        Numbers drawn at a time.

    Examples
    --------
    >>> a, b = np.random.default_rng(1), NormalDraws(np.random.default_rng(1), block=5)
    >>> same = [a.standard_normal(2).tolist() == b.standard_normal(2).tolist() for _ in range(9)]
    >>> all(same), bool((a.standard_normal((3, 2)) == b.standard_normal((3, 2))).all())
    (True, True)
    >>> a.standard_normal(3).tolist() == b.take(3)
    True
    """

    def __init__(self, rng: np.random.Generator, block: int = 256) -> None:
        self.rng = rng
        self._block = int(block)
        self._buffer = np.empty(0)
        self._values: list[float] = []  # the same numbers as plain floats, for take()
        self._at = 0

    def _ensure(self, size: int) -> int:
        """Make ``size`` numbers available from the current position; return that position."""
        at = self._at
        if at + size > self._buffer.size:  # the rest, then a new block (or more): the generator's order kept
            fresh = self.rng.standard_normal(max(self._block, size - (self._buffer.size - at)))
            self._buffer, at = np.concatenate([self._buffer[at:], fresh]), 0
            self._values = self._buffer.tolist()
        return at

    def standard_normal(self, shape: int | tuple[int, ...]) -> np.ndarray:
        """The next standard normal numbers, ``shape`` of them (a new array's shape, as the generator takes it)."""
        size = shape if isinstance(shape, int) else math.prod(shape)
        at = self._ensure(size)
        self._at = at + size
        out = self._buffer[at : at + size]
        return out if isinstance(shape, int) or len(shape) == 1 else out.reshape(shape)

    def take(self, size: int) -> list[float]:
        """The next ``size`` standard normal numbers as plain floats: what :meth:`standard_normal` would give, the
        same numbers in the same order (a control interval's few draws without an array)."""
        at = self._ensure(size)
        self._at = at + size
        return self._values[at : at + size]


#: What the disturbances and encoders draw from: a generator, or its draws a block at a time.
Normals = np.random.Generator | NormalDraws


def ou_advance(
    value: np.ndarray,
    std: np.ndarray | tuple[float, ...] | float,
    time_constant: float,
    dt: float,
    rng: Normals,
) -> np.ndarray:
    """One exact step of ``dt`` s of an Ornstein-Uhlenbeck process of stationary ``std`` and correlation time.

    ``x[k+1] = a x[k] + std sqrt(1 - a^2) w[k]``, ``a = exp(-dt / time_constant)``, ``w`` standard normal
    (one draw per channel of ``value``, drawn even where ``std`` is 0, so that a channel switched off does
    not shift another's realisation).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> x = np.zeros(2)
    >>> for _ in range(20000):
    ...     x = ou_advance(x, np.array([1.0, 0.0]), 1.0, 0.1, rng)
    >>> bool(x[1] == 0.0)
    True
    """
    try:  # a twin's every interval: computed once (its std a float or a tuple of floats)
        a, scale = _ou_coefficients(std, time_constant, dt)  # type: ignore[arg-type]
    except TypeError:  # an array (or anything else unhashable): computed here
        a, scale = _ou_coefficients.__wrapped__(std, time_constant, dt)
    if type(value) is np.ndarray and value.ndim == 1 and value.size <= 4:  # a twin's: plain floats, the same bits
        noise = rng.standard_normal(value.shape).tolist()
        a_f, scales = float(a), scale.tolist()  # a float for one std, a list for one per channel
        if type(scales) is list:
            return np.array([a_f * x + s * w for x, s, w in zip(value.tolist(), scales, noise)])
        return np.array([a_f * x + scales * w for x, w in zip(value.tolist(), noise)])
    return a * value + scale * rng.standard_normal(np.shape(value))


class OUStep:
    """One exact step of ``dt`` s of a two-channel Ornstein-Uhlenbeck process, its coefficients computed once: what
    :func:`ou_advance` computes, the same bits, for a twin's every control interval.

    Parameters
    ----------
    std : float or (float, float)
        Stationary standard deviation of both channels, or of each.
    time_constant : float
        Correlation time (s).
    dt : float
        Step (s).

    Examples
    --------
    >>> a, b = NormalDraws(np.random.default_rng(4)), NormalDraws(np.random.default_rng(4))
    >>> step, x, y = OUStep((1.0, 2.0), 0.7, 0.1), np.array([0.5, -0.2]), np.array([0.5, -0.2])
    >>> for _ in range(30):
    ...     x, y = step(x, a), ou_advance(y, (1.0, 2.0), 0.7, 0.1, b)
    >>> bool((x == y).all())
    True
    """

    __slots__ = ("_a", "_scales")

    def __init__(self, std: tuple[float, ...] | float, time_constant: float, dt: float) -> None:
        a, scale = _ou_coefficients(std, time_constant, dt)
        self._a = float(a)
        self._scales: list[float] = np.broadcast_to(scale, (2,)).tolist()

    def __call__(self, value: np.ndarray, rng: NormalDraws) -> np.ndarray:
        """The value (two channels) one step after ``value``, one draw per channel from ``rng``."""
        a = self._a
        (x0, x1), (s0, s1), (w0, w1) = value.tolist(), self._scales, rng.take(2)
        return np.array((a * x0 + s0 * w0, a * x1 + s1 * w1))


def ou_path(
    start: np.ndarray,
    std: np.ndarray | tuple[float, ...] | float,
    time_constant: float,
    dt: float,
    rng: Normals,
    n: int,
) -> np.ndarray:
    """``n`` successive :func:`ou_advance` steps from ``start`` at once: the same draws and the same bits.

    The white noise of all ``n`` steps is drawn in one call (a generator fills an array in the order that
    ``n`` draws of one step each would), and the recursion runs on plain floats, whose arithmetic is numpy's
    element by element.

    Returns
    -------
    numpy.ndarray
        ``(n + 1, len(start))``: ``start`` then the value after each step.

    Examples
    --------
    >>> a, b = np.random.default_rng(3), np.random.default_rng(3)
    >>> x = np.array([0.5, -0.2])
    >>> path = ou_path(x, (1.0, 2.0), 0.7, 0.1, a, 50)
    >>> for _ in range(50):
    ...     x = ou_advance(x, (1.0, 2.0), 0.7, 0.1, b)
    >>> bool((path[-1] == x).all()), path.shape
    (True, (51, 2))
    """
    value = np.asarray(start, float)
    try:
        a, scale = _ou_coefficients(std, time_constant, dt)  # type: ignore[arg-type]
    except TypeError:
        a, scale = _ou_coefficients.__wrapped__(std, time_constant, dt)
    noise = rng.standard_normal((int(n),) + value.shape)
    out = np.empty((int(n) + 1,) + value.shape)
    out[0] = value
    if not n:
        return out
    a_f = float(a)
    scales = np.broadcast_to(scale, value.shape).tolist()
    for j, (x, s, w) in enumerate(zip(value.tolist(), scales, noise.T.tolist())):
        column = [x]
        for w_k in w:
            x = a_f * x + s * w_k
            column.append(x)
        out[:, j] = column
    return out


@functools.lru_cache(maxsize=256)
def _ou_coefficients(
    std: np.ndarray | tuple[float, ...] | float, time_constant: float, dt: float
) -> tuple[float, np.ndarray]:
    """``a = exp(-dt / time_constant)`` and ``std sqrt(1 - a^2)`` (read-only)."""
    a = np.exp(-dt / time_constant)
    scale = np.asarray(std, float) * np.sqrt(1.0 - a * a)
    scale.setflags(write=False)
    return a, scale


@dataclass(frozen=True)
class Turbulence:
    """The rig's rotor-wash turbulence: a thrust fluctuation along each rotor's axis (N).

    Each rotor's thrust gets a seeded Ornstein-Uhlenbeck process (:func:`ou_advance`) of stationary
    standard deviation ``std`` and correlation time ``time_constant``, held over each control interval and
    applied by the rotor's turbulence actuator (``main_wash``, ``tail_wash`` in the MJCF: a force along the
    hub's axis, not delayed, not lagged). The values are the MJCF's custom numeric ``rotor_turbulence``
    (``[main std, tail std, time constant]``), calibrated parameters of the rig (:mod:`trms.twin.parameters`).

    Parameters
    ----------
    std : (float, float)
        Stationary standard deviation of the main and tail rotor's thrust turbulence (N), each in [0, 1].
    time_constant : float
        Correlation time (s), in (0, 100].

    Examples
    --------
    >>> t = Turbulence((0.003, 0.0), 1.0)
    >>> t.active, Turbulence((0.0, 0.0), 1.0).active
    (True, False)
    """

    std: tuple[float, float] = (0.0, 0.0)
    time_constant: float = 1.0

    def __post_init__(self) -> None:
        std = as_finite_array("turbulence std (main, tail) in N", np.ravel(self.std), (2,))
        for name, value in zip(("main", "tail"), std):
            check_in_range(f"{name} rotor turbulence std", value, 0.0, 1.0, unit=" N")
        check_in_range("turbulence time_constant", self.time_constant, 0.0, 100.0, unit=" s", low_open=True)
        object.__setattr__(self, "std", (float(std[0]), float(std[1])))

    @property
    def active(self) -> bool:
        """Whether any rotor has turbulence."""
        return any(s > 0 for s in self.std)

    @classmethod
    def from_array(cls, data: np.ndarray) -> Turbulence:
        """From the MJCF numeric ``[main std (N), tail std (N), time constant (s)]``."""
        values = np.ravel(np.asarray(data, float))
        if values.shape != (3,):
            raise InputError(
                "rotor_turbulence needs 3 numbers [main std (N), tail std (N), time constant (s)], "
                f"got {values.tolist()}"
            )
        return cls((float(values[0]), float(values[1])), float(values[2]))

    def start(self, rng: Normals) -> np.ndarray:
        """Initial thrust fluctuations (N), drawn from the stationary distribution."""
        return np.asarray(self.std) * rng.standard_normal(2)

    def advance(self, thrust: np.ndarray, dt: float, rng: Normals) -> np.ndarray:
        """Thrust fluctuations one interval of ``dt`` s later (N)."""
        return ou_advance(thrust, self.std, self.time_constant, dt, rng)

    def path(self, thrust: np.ndarray, dt: float, rng: Normals, n: int) -> np.ndarray:
        """``thrust`` (N) and the fluctuations after each of ``n`` intervals of ``dt`` s, ``(n + 1, 2)``: what ``n``
        calls of :meth:`advance` give, the same bits (none drawn when no rotor has turbulence)."""
        if not self.active:
            return np.zeros((int(n) + 1, 2))
        return ou_path(thrust, self.std, self.time_constant, dt, rng, n)


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

    def start(self, rng: Normals) -> np.ndarray:
        """Initial torques (N m), drawn from the stationary distribution."""
        return self.std * rng.standard_normal(2) if self.std else np.zeros(2)

    def advance(self, torque: np.ndarray, dt: float, rng: Normals) -> np.ndarray:
        """Torques one interval of ``dt`` s later (N m)."""
        if not self.std:
            return np.zeros(2)
        return ou_advance(torque, self.std, self.time_constant, dt, rng)

    def path(self, torque: np.ndarray, dt: float, rng: Normals, n: int) -> np.ndarray:
        """``torque`` (N m) and the torques after each of ``n`` intervals of ``dt`` s, ``(n + 1, 2)``: what ``n``
        calls of :meth:`advance` give, the same bits."""
        if not self.std:
            out = np.zeros((int(n) + 1, 2))
            out[0] = torque
            return out
        return ou_path(torque, self.std, self.time_constant, dt, rng, n)


#: Gusts of moving air, where an experiment names them (the closed-loop experiments on the twin, the
#: robustness study, the HoverGusts task): stationary torque standard deviation 0.0006 N m, correlation
#: time 1 s. This project's choice, standing for the rig's "minor oscillatory tendency even in steady
#: state" (ch. 7.3.1); the report measures the open-loop wander it causes.
MOVING_AIR = Gust(0.0006, 1.0)
