"""Faults injected into the twin: a rotor losing thrust, a rotor stuck, an encoder dropping out.

:class:`FaultyTwin` wraps a :class:`~trms.twin.twin.Twin` and is a :class:`~trms.plant.Plant` itself, so every
closed-loop runner flies a controller through the faults unchanged. Each fault starts at a time ``at`` (s from the
run's start; the interval that starts at or after it is the first one faulty) and lasts to the end of the run
(a dropout may end earlier):

* :class:`ThrustLoss` -- a rotor's efficiency falls by ``loss`` (a damaged or iced blade): its thrust and its
  reaction torque are scaled by ``1 - loss`` at the same motor command (MuJoCo's actuator ``gear``);
* :class:`StuckRotor` -- a rotor's voltage no longer follows the command: it keeps the voltage it had when the
  fault began (or a stated one);
* :class:`EncoderDropout` -- an angle's reading freezes at its last value (the encoder's counter stops).

The record's ``faults`` channel says which fault is active at each sample. Reset restores the healthy rig.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from trms.errors import InputError, check_in_range
from trms.plant import InputVector, check_input_vector
from trms.record import OperatingPoint
from trms.twin.model import ROTORS
from trms.twin.twin import Twin

__all__ = ["ThrustLoss", "StuckRotor", "EncoderDropout", "Fault", "FaultyTwin"]

#: The rotor each input drives.
_ROTOR_OF = dict(zip(("u1", "u2"), ROTORS))
#: Each wrapped twin's healthy actuator gears, recorded the first time a FaultyTwin wraps it.
_HEALTHY: weakref.WeakKeyDictionary[Twin, np.ndarray] = weakref.WeakKeyDictionary()


@dataclass(frozen=True)
class ThrustLoss:
    """A rotor keeps ``1 - loss`` of its thrust (and reaction torque) from ``at`` seconds on.

    Parameters
    ----------
    input : str
        The rotor's input, ``"u1"`` (main) or ``"u2"`` (tail).
    loss : float
        Fraction of thrust lost, in ``(0, 1)``.
    at : float
        Start (s, at least 0).
    """

    input: str
    loss: float
    at: float


@dataclass(frozen=True)
class StuckRotor:
    """A rotor's voltage stops following the command from ``at`` seconds on.

    Parameters
    ----------
    input : str
        ``"u1"`` or ``"u2"``.
    at : float
        Start (s, at least 0).
    volts : float, optional
        The voltage it sticks at (V, within the rig's limits); by default the one applied when the fault begins.
    """

    input: str
    at: float
    volts: float | None = None


@dataclass(frozen=True)
class EncoderDropout:
    """An angle's reading freezes at its last value from ``at`` for ``duration`` seconds (to the end by default).

    Parameters
    ----------
    output : str
        ``"pitch"`` or ``"yaw"``.
    at : float
        Start (s, at least 0).
    duration : float
        Length (s, positive; ``inf`` for the rest of the run).
    """

    output: str
    at: float
    duration: float = math.inf


Fault = ThrustLoss | StuckRotor | EncoderDropout


class FaultyTwin:
    """A twin that develops ``faults`` during each run (a :class:`~trms.plant.Plant`).

    Parameters
    ----------
    twin : Twin
        The healthy twin. A thrust loss changes its model's actuator gears during a run; :meth:`reset` and
        :meth:`restore` put the healthy gears back (those recorded the first time any FaultyTwin wrapped this twin),
        and :meth:`Twin.reset <trms.twin.twin.Twin.reset>` alone does not: call :meth:`restore` before flying the
        twin itself again.
    faults : sequence of ThrustLoss, StuckRotor, EncoderDropout
        The faults, each checked against the twin's inputs, outputs and voltage limits.

    Examples
    --------
    >>> twin = Twin("1dof", 0.1)
    >>> plant = FaultyTwin(twin, [ThrustLoss("u1", 0.4, at=1.0)])
    >>> y0 = plant.reset(seed=0)
    >>> ys = [plant.step(plant.operating_point.inputs) for _ in range(40)]
    >>> bool(min(y[0] for y in ys) < y0[0] - 0.3)  # 40 % less thrust at the hover voltage: the beam falls
    True
    >>> plant.channels()["faults"].tolist()
    [True]
    >>> _ = plant.reset(seed=0)
    >>> plant.channels()["faults"].tolist()
    [False]
    """

    def __init__(self, twin: Twin, faults: Sequence[Fault]) -> None:
        if not isinstance(twin, Twin):
            raise InputError(f"twin must be a Twin, got {type(twin).__name__}")
        if not isinstance(faults, (list, tuple)):
            raise InputError(f"faults must be a list or tuple of faults, got {type(faults).__name__}")
        self.twin = twin
        self.faults = tuple(faults)
        self.input_names: tuple[str, ...] = twin.input_names
        self.output_names: tuple[str, ...] = twin.output_names
        self.sample_time: float = twin.sample_time
        lo, hi = twin.input_limits
        for i, f in enumerate(self.faults):
            where = f"faults[{i}]"
            if not isinstance(f, (ThrustLoss, StuckRotor, EncoderDropout)):
                raise InputError(f"{where} must be a ThrustLoss, StuckRotor or EncoderDropout, got {f!r}")
            check_in_range(f"{where}.at", f.at, 0.0, 1e9, unit=" s")
            if isinstance(f, EncoderDropout):
                if f.output not in twin.output_names:
                    raise InputError(f"{where}.output {f.output!r} is not measured; allowed: {twin.output_names}")
                if f.duration != math.inf:
                    check_in_range(f"{where}.duration", f.duration, 0.0, 1e9, unit=" s", low_open=True)
                continue
            if f.input not in twin.input_names:
                raise InputError(f"{where}.input {f.input!r} is not driven; allowed: {twin.input_names}")
            if isinstance(f, ThrustLoss):
                inside = isinstance(f.loss, (int, float, np.floating)) and not isinstance(f.loss, bool)
                if not (inside and 0.0 < float(f.loss) < 1.0):
                    raise InputError(f"{where}.loss = {f.loss!r} is outside the allowed range (0, 1)")
            elif f.volts is not None:
                j = twin.input_names.index(f.input)
                check_in_range(f"{where}.volts", f.volts, float(lo[j]), float(hi[j]), unit=" V")
        self._actuator = {
            name: twin.model.actuator(rotor).id for name, rotor in _ROTOR_OF.items() if name in twin.input_names
        }
        self._healthy_gear = _HEALTHY.setdefault(twin, twin.model.actuator_gear.copy())
        self._held: dict[int, float] = {}
        self._frozen: dict[int, float] = {}
        self._active = np.zeros(len(self.faults), bool)
        self._k = 0
        self._last_y = np.zeros(len(twin.output_names))

    # ------------------------------------------------------------ the Plant protocol

    @property
    def operating_point(self) -> OperatingPoint:
        """The healthy twin's hover trim."""
        return self.twin.operating_point

    @property
    def input_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """The twin's voltage limits (V)."""
        return self.twin.input_limits

    @property
    def applied_input(self) -> np.ndarray:
        """The voltages the rotors received in the last interval (V): a stuck rotor's, not the command."""
        return self.twin.applied_input

    def restore(self) -> None:
        """Give the twin its healthy actuator gears back (after a run with a thrust loss)."""
        self.twin.model.actuator_gear[:] = self._healthy_gear

    def reset(self, seed: int | None = None) -> np.ndarray:
        """Restore the healthy rig, reset the twin, and return the first measurement (rad)."""
        self.restore()
        self._held.clear()
        self._frozen.clear()
        self._active[:] = False
        self._k = 0
        self._last_y = np.asarray(self.twin.reset(seed), float).copy()
        return self._last_y.copy()

    def step(self, u: InputVector) -> np.ndarray:
        """Hold voltages ``u`` (V) for one sample through the active faults; return the readings (rad)."""
        volts = check_input_vector(u, len(self.input_names), self.input_names).copy()
        now = self._active_at(self._k * self.sample_time)
        for i, f in enumerate(self.faults):
            if now[i] and not self._active[i]:
                self._start(i, f)
            elif self._active[i] and not now[i]:  # a dropout that ended
                self._frozen.pop(i, None)
        self._active = now
        for i, v in self._held.items():
            volts[self.input_names.index(self.faults[i].input)] = v
        y = np.asarray(self.twin.step(volts), float).copy()
        for i, value in self._frozen.items():
            y[self.output_names.index(self.faults[i].output)] = value
        self._k += 1
        self._last_y = y.copy()
        return y

    def channels(self) -> dict[str, np.ndarray]:
        """The twin's channels and ``faults``: which fault acts over the next interval (bool, one per fault)."""
        return {**self.twin.channels(), "faults": self._active_at(self._k * self.sample_time)}

    def _active_at(self, t: float) -> np.ndarray:
        """Which faults act over the interval that starts at ``t`` (s)."""
        eps = 1e-9 * self.sample_time
        return np.array(
            [
                t >= f.at - eps and (not isinstance(f, EncoderDropout) or t < f.at + f.duration - eps)
                for f in self.faults
            ],
            bool,
        )

    # ------------------------------------------------------------ the faults
    def _start(self, i: int, f: Fault) -> None:
        self._active[i] = True
        if isinstance(f, ThrustLoss):
            self.twin.model.actuator_gear[self._actuator[f.input]] *= 1.0 - f.loss
        elif isinstance(f, StuckRotor):
            j = self.input_names.index(f.input)
            self._held[i] = float(self.twin.applied_input[j] if f.volts is None else f.volts)
        else:
            self._frozen[i] = float(self._last_y[self.output_names.index(f.output)])
