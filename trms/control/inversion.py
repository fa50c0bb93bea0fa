"""The actuator's static nonlinearity inverted at the plant input: any controller on a linearised input.

The rig's rotors are Hammerstein actuators: a static, asymmetric thrust curve ``F(V)`` (quadratic in the rotor speed,
weaker in reverse, flat beyond full speed) followed by the motor's lag. A design made on a linear model (eq. 3.11,
or the twin's linearisation at hover) assumes the curve's slope at the trim voltage ``u0`` everywhere; the twin's
thrust slope is 0.98 N/V at -1 V, 1.85 at hover and 2.96 at +1 V (it changes by 60 % of its hover value per volt), so
its static pitch gain (pitch over voltage step) is 1.40 rad/V at -0.1 V and 2.68 at +0.3 V, and a loop tuned at hover
overshoots more the larger the step.

:class:`InvertedInputs` wraps a controller whose output ``v`` (deviation V) is read as a *linearised* voltage: the
thrust it asks for is the trim's plus the trim slope times ``v``, ``F = F(u0) + F'(u0) v``, and the voltage sent is
the curve's inverse of that thrust, ``u = F^-1(F) - u0``. Through the curve the rotor then produces exactly
``F(u0) + F'(u0) v``: the static part of the actuator is linear in ``v`` with the design model's slope, at every
amplitude. Commands beyond the rotor's reach (full speed, the voltage limits) are limited in ``v`` before the
inverse (:meth:`InvertedInputs.limits`), so the wrapped controller's anti-windup sees the limits it works against.

The curve comes from the plant's model (:func:`trms.worlds.input_inversion` reads the twin's calibrated curves, or
a rig owner's calibrated MJCF); any object with the :class:`StaticInputMap` methods will do. The layer is optional
and measured with and without in the controller comparison (:mod:`trms.experiments.ch8.controllers`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol, runtime_checkable

import numpy as np

from trms.control.arguments import real_array
from trms.control.loop import ControllerWrapper
from trms.errors import InputError

__all__ = ["StaticInputMap", "InvertedInputs", "linearised_limits"]


@runtime_checkable
class StaticInputMap(Protocol):
    """A static, monotonic actuator map ``F(V)`` with its inverse and slope (e.g. :class:`trms.twin.ThrustCurve`)."""

    def thrust(self, volts: Any) -> Any:
        """``F(V)`` (N) for a voltage (V)."""
        ...

    def voltage(self, thrust: Any) -> Any:
        """``F^-1``: the voltage (V) whose steady output is ``thrust`` (N)."""
        ...

    def slope(self, volts: Any) -> Any:
        """``dF/dV`` (N/V) at a voltage."""
        ...


class InvertedInputs(ControllerWrapper):
    """A controller whose outputs are linearised voltages, inverted through each input's static map.

    Parameters
    ----------
    controller : Controller
        Any sampled controller (``update(reference, measurement) -> v``, deviation V); give it the limits of
        :meth:`limits` so that its anti-windup acts where the inverted input saturates.
    maps : sequence of StaticInputMap or None
        One per plant input; ``None`` passes that input through unchanged.
    trim : array_like
        The plant's trim inputs ``u0`` (absolute V), one per input.
    input_limits : tuple of array_like
        The plant's absolute input limits (V), ``(lower, upper)``, scalars or one per input.

    Raises
    ------
    InputError
        Sizes that differ, a map without the methods, a trim outside the limits or where a map's slope is not
        positive.

    Examples
    --------
    A quadratic map ``F = V |V|`` trimmed at 1 V (slope 2 N/V): a linearised command of 0.5 V asks for
    ``1 + 2 x 0.5 = 2`` N, which the map gives at ``sqrt 2`` V:

    >>> class Square:
    ...     def thrust(self, v): return v * abs(v)
    ...     def voltage(self, f): return np.sign(f) * np.sqrt(abs(f))
    ...     def slope(self, v): return 2 * abs(v)
    >>> class Hold:
    ...     sample_time = 0.1
    ...     def reset(self): pass
    ...     def update(self, r, y): return np.array([0.5])
    >>> inv = InvertedInputs(Hold(), [Square()], [1.0], (-10.0, 10.0))
    >>> round(float(inv.update(0.0, 0.0)[0]), 6), round(2.0**0.5 - 1.0, 6)
    (0.414214, 0.414214)
    """

    def __init__(
        self,
        controller: Any,
        maps: Sequence[StaticInputMap | None],
        trim: object,
        input_limits: tuple[object, object],
    ) -> None:
        u0 = real_array("trim (absolute V)", trim, (None,))
        if len(maps) != u0.size:
            raise InputError(f"need one input map (or None) per input: {u0.size} inputs, got {len(maps)} maps")
        for i, mp in enumerate(maps):
            if mp is not None and not isinstance(mp, StaticInputMap):
                raise InputError(f"input map {i} must have thrust, voltage and slope methods, got {type(mp).__name__}")
        lo, hi = (
            np.broadcast_to(real_array(f"input_limits {n}", v, infinite=True), u0.shape).astype(float)
            for n, v in zip(("lower", "upper"), input_limits)
        )
        if np.any(u0 <= lo) or np.any(u0 >= hi):
            raise InputError(
                f"trim {u0.tolist()} V must lie strictly inside the input limits {lo.tolist()}..{hi.tolist()} V"
            )
        super().__init__(controller)
        self.maps = tuple(maps)
        self.trim = u0
        self._force0 = np.array([0.0 if m is None else float(m.thrust(float(u))) for m, u in zip(maps, u0)])
        self._slope0 = np.array([1.0 if m is None else float(m.slope(float(u))) for m, u in zip(maps, u0)])
        if np.any(self._slope0 <= 0.0):
            bad = int(np.flatnonzero(self._slope0 <= 0.0)[0])
            raise InputError(
                f"input {bad}'s map has slope {self._slope0[bad]:.6g} N/V at its trim {u0[bad]:.6g} V; allowed: > 0 "
                "(a trim beyond the actuator's reach cannot be linearised)"
            )
        self._lo, self._hi = lo, hi

    def limits(self) -> tuple[np.ndarray, np.ndarray]:
        """The plant's input limits as linearised deviations ``v`` (V): ``(F(lower) - F(u0)) / F'(u0)`` and the upper
        one likewise (a map flat beyond full speed gives the limit full speed sets).

        Examples
        --------
        >>> class Square:
        ...     def thrust(self, v): return v * abs(v)
        ...     def voltage(self, f): return np.sign(f) * np.sqrt(abs(f))
        ...     def slope(self, v): return 2 * abs(v)
        >>> [v.tolist() for v in InvertedInputs(None, [Square(), None], [1.0, 0.0], (-2.0, 2.0)).limits()]
        [[-2.5, -2.0], [1.5, 2.0]]
        """
        return linearised_limits(self.maps, self.trim, (self._lo, self._hi))

    def voltages(self, v: object) -> np.ndarray:
        """Linearised deviations ``v`` (V) to the deviation voltages ``F^-1(F(u0) + F'(u0) v) - u0`` (V).

        Examples
        --------
        >>> class Square:
        ...     def thrust(self, v): return v * abs(v)
        ...     def voltage(self, f): return np.sign(f) * np.sqrt(abs(f))
        ...     def slope(self, v): return 2 * abs(v)
        >>> InvertedInputs(None, [Square()], [1.0], (-10.0, 10.0)).voltages([-1.0]).tolist()  # F = -1 N
        [-2.0]
        """
        vv = np.ravel(np.asarray(v, dtype=float))
        force = self._force0 + self._slope0 * vv
        out = vv.copy()
        for i, m in enumerate(self.maps):
            if m is not None:
                out[i] = float(m.voltage(float(force[i]))) - self.trim[i]
        return out

    def update(self, reference: object, measurement: object) -> np.ndarray:
        """The wrapped controller's linearised command, inverted (deviation V, one per input)."""
        return self.voltages(self.controller.update(reference, measurement))


def linearised_limits(
    maps: Sequence[StaticInputMap | None], trim: object, input_limits: tuple[object, object]
) -> tuple[np.ndarray, np.ndarray]:
    """Absolute input limits (V) as the linearised deviations ``v`` of :class:`InvertedInputs` (V):
    ``(F(limit) - F(u0)) / F'(u0)`` per input with a map, ``limit - u0`` without one.

    Parameters
    ----------
    maps : sequence of StaticInputMap or None
        One per input.
    trim : array_like
        Trim inputs ``u0`` (absolute V).
    input_limits : tuple of array_like
        ``(lower, upper)`` absolute V, scalars or one per input.

    Examples
    --------
    >>> class Square:
    ...     def thrust(self, v): return v * abs(v)
    ...     def voltage(self, f): return np.sign(f) * np.sqrt(abs(f))
    ...     def slope(self, v): return 2 * abs(v)
    >>> [v.tolist() for v in linearised_limits([Square(), None], [1.0, 0.0], (-2.0, 2.0))]
    [[-2.5, -2.0], [1.5, 2.0]]
    """
    u0 = real_array("trim (absolute V)", trim, (len(maps),))
    out = []
    for side in input_limits:
        limit = np.broadcast_to(real_array("input limit (absolute V)", side, infinite=True), u0.shape)
        v = np.empty(u0.size)
        for i, (m, u) in enumerate(zip(maps, limit)):
            if m is None:
                v[i] = float(u) - u0[i]
            else:
                v[i] = (float(m.thrust(float(u))) - float(m.thrust(float(u0[i])))) / float(m.slope(float(u0[i])))
        out.append(v)
    return out[0], out[1]
