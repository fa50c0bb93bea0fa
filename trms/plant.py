"""The seam every experiment runs on: the Plant protocol, saturation, running a plant, and the linear plant.

A :class:`Plant` has named inputs (volts) and outputs (radians), a ``sample_time`` in
seconds, ``reset(seed)`` returning the first measurement, and ``step(u)`` which holds
``u`` for one sample (zero-order hold) and returns the measurement at the next sample.
Plants speak absolute values; :class:`~trms.record.OperatingPoint` converts to and from the
deviations that identification and control work with. :func:`simulate` and :func:`drive` run a plant into a
:class:`~trms.record.Record` (its timing convention and signal names: :mod:`trms.record`); :class:`LinearPlant`
is a discrete LTI system behind the same protocol.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any, Protocol, runtime_checkable

import control
import numpy as np

from trms.errors import ConfigurationError, InputError, as_finite_array, check_seed
from trms.record import OperatingPoint, Record, RowBuffer

#: What a plant's ``step`` takes: absolute volts, one per input (a scalar for a single input).
InputVector = np.ndarray | Sequence[float] | float

__all__ = [
    "Plant",
    "OpenLoopPlant",
    "LinearPlant",
    "saturate",
    "simulate",
    "drive",
    "history_record",
]


@runtime_checkable
class Plant(Protocol):
    """A sampled plant: named inputs (V) and outputs (rad), zero-order-hold steps.

    Attributes
    ----------
    input_names, output_names : tuple of str
    sample_time : float
        Seconds between samples.
    operating_point : OperatingPoint
        Trim around which deviations are taken.
    input_limits : tuple of numpy.ndarray
        Lower and upper absolute input limits (V); inputs beyond them saturate.
    applied_input : numpy.ndarray
        The input actually held during the last step, after saturation.
    """

    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    sample_time: float

    @property
    def operating_point(self) -> OperatingPoint: ...

    @property
    def input_limits(self) -> tuple[np.ndarray, np.ndarray]: ...

    @property
    def applied_input(self) -> np.ndarray: ...

    def reset(self, seed: int | None = None) -> np.ndarray:
        """Return the plant to its initial state; return the first measurement."""
        ...

    def step(self, u: InputVector) -> np.ndarray:
        """Hold ``u`` (absolute V) for one sample; return the next measurement."""
        ...

    def channels(self) -> dict[str, np.ndarray]:
        """Extra named values at the current sample (true angles, rotor states...)."""
        ...


@runtime_checkable
class OpenLoopPlant(Plant, Protocol):
    """A plant that also runs a whole open-loop record at once (the twin: one native rollout).

    :func:`simulate` takes that path where the plant has it.
    """

    def open_loop(
        self, inputs: np.ndarray, seed: int | None = None, channels: bool = True
    ) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]] | None:
        """Reset with ``seed``, hold each row of ``inputs`` (absolute V, ``(N, n_inputs)``) for one sample; return the
        measurements at ``t_0 .. t_{N-1}``, the applied inputs and the channels (``N`` rows each, none without
        ``channels``) that :func:`drive` would record, the same bits, or None where it cannot (then step it)."""
        ...


def saturate(u: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Clip ``u`` to ``[lower, upper]`` and report which channels saturated.

    Parameters
    ----------
    u : numpy.ndarray
        Commanded input (V).
    lower, upper : numpy.ndarray
        Limits (V), broadcastable to ``u``.

    Returns
    -------
    applied : numpy.ndarray
        The clipped input.
    saturated : numpy.ndarray of bool
        True where the command was outside the limits.
    """
    applied = np.minimum(np.maximum(u, lower), upper)  # np.clip's values, without its wrapper
    return applied, applied != u


def check_input_vector(u: object, n: int, names: Sequence[str], label: str | None = None) -> np.ndarray:
    """Validate one input vector for ``step``: numeric, finite, shape ``(n,)`` (a scalar is accepted when n = 1).

    ``label`` names it in a message (default ``input u (NAMES) in V``); ``None`` is refused as no voltage.

    Examples
    --------
    >>> check_input_vector(2.0, 1, ("u1",))
    array([2.])
    """
    if type(u) is np.ndarray and u.dtype == np.float64 and u.shape == (n,) and math.isfinite(sum(u.tolist())):
        return u.copy()  # the per-sample case (a finite sum: every value finite), a microsecond; else in full below
    label = f"input u ({', '.join(names)}) in V" if label is None else label
    if u is None or (isinstance(u, (list, tuple)) and any(v is None for v in u)):
        raise InputError(f"{label}: None is not a voltage; give {n} number{'s' * (n > 1)} (V)")
    arr = as_finite_array(label, u)
    if arr.ndim == 0 and n == 1:
        arr = arr.reshape(1)
    return as_finite_array(label, arr, (n,))


def simulate(
    plant: Plant,
    inputs: Iterable[Sequence[float]] | np.ndarray,
    seed: int | None = None,
    metadata: Mapping[str, Any] | None = None,
    channels: bool = True,
) -> Record:
    """Reset ``plant`` with ``seed`` and apply ``inputs`` one sample each; return the Record.

    Parameters
    ----------
    plant : Plant
        Any plant.
    inputs : array_like
        Absolute inputs (V), shape ``(N, n_inputs)`` (or ``(N,)`` for one input).
    seed : int, optional
        Passed to ``plant.reset``.
    metadata : mapping, optional
        Extra metadata merged into the Record's.
    channels : bool
        Record the plant's channels at every sample (False: only inputs, outputs and what was applied, for
        batches that read the outputs alone).

    Returns
    -------
    Record
        ``N`` rows; extras ``applied_inputs`` and ``saturated`` plus the plant's channels.
    """
    n_in = len(plant.input_names)
    label = f"inputs ({', '.join(plant.input_names)}) in V"
    u = as_finite_array(label, inputs)
    if u.ndim == 1 and n_in == 1:
        u = u[:, None]
    u = as_finite_array(label, u, (None, n_in))
    native = plant.open_loop(u, seed, channels) if isinstance(plant, OpenLoopPlant) else None
    if native is None:
        return drive(plant, u.shape[0], lambda k, y: u[k], seed, metadata, channels)
    outputs, applied, extras = native
    return history_record(plant, u, outputs, applied, extras, check_seed("seed", seed), metadata)


def drive(
    plant: Plant,
    n_samples: int,
    policy: Callable[[int, np.ndarray], np.ndarray],
    seed: int | None = None,
    metadata: Mapping[str, Any] | None = None,
    channels: bool = True,
) -> Record:
    """Reset ``plant`` with ``seed`` and run ``n_samples`` steps, asking ``policy`` for each input.

    This is the one place a plant's history becomes a :class:`Record`; :func:`simulate`
    (open loop) and closed loops both use it.

    Parameters
    ----------
    plant : Plant
        Any plant.
    n_samples : int
        Number of samples ``N``.
    policy : callable
        ``policy(k, y_k) -> u_k``: the absolute input (V) to hold over ``[t_k, t_k + Ts)``
        given the absolute measurement ``y_k`` (rad) at ``t_k``.
    seed : int, optional
        Passed to ``plant.reset``.
    metadata : mapping, optional
        Extra metadata merged into the Record's.
    channels : bool
        Record the plant's channels at every sample.

    Returns
    -------
    Record
        ``N`` rows; extras ``applied_inputs`` and ``saturated`` plus the plant's channels.
    """
    if isinstance(n_samples, (bool, np.bool_)) or not isinstance(n_samples, (int, np.integer)) or n_samples < 0:
        raise InputError(f"n_samples must be a non-negative integer, got {n_samples!r}")
    n = int(n_samples)
    seed = check_seed("seed", seed)
    n_in = len(plant.input_names)
    u = np.empty((n, n_in))
    y = plant.reset(seed)
    ys = np.empty((n, len(plant.output_names)))
    applied = np.empty_like(u)
    rows = RowBuffer(n)
    for k in range(n):
        ys[k] = y
        if channels:
            rows.put(k, plant.channels())
        u[k] = policy(k, y)
        y = plant.step(u[k])
        applied[k] = plant.applied_input
    return history_record(plant, u, ys, applied, rows.arrays(), seed, metadata)


def history_record(
    plant: Plant,
    inputs: np.ndarray,
    outputs: np.ndarray,
    applied: np.ndarray,
    channels: Mapping[str, np.ndarray],
    seed: int | None = None,
    metadata: Mapping[str, Any] | None = None,
) -> Record:
    """The Record of a run of ``plant``: the one place its metadata and extras are assembled.

    Parameters
    ----------
    plant : Plant
        The plant that ran (names, sample time, operating point, limits).
    inputs, outputs, applied : numpy.ndarray
        Commanded absolute inputs (V), measurements (rad) and applied inputs (V), ``N`` rows each.
    channels : mapping
        The plant's channels stacked over the run (``N`` rows each).
    seed : int, optional
        The reset seed.
    metadata : mapping, optional
        Extra metadata merged into the Record's.

    Examples
    --------
    >>> from trms.plant import LinearPlant
    >>> import control
    >>> p = LinearPlant(control.ss(0.5, 1.0, 1.0, 0.0, 0.1))
    >>> history_record(p, np.zeros((2, 1)), np.zeros((2, 1)), np.zeros((2, 1)), {}).time.tolist()
    [0.0, 0.1]
    """
    u, ys = inputs, outputs
    n = u.shape[0]
    lower, upper = plant.input_limits
    meta = {
        "sample_time": float(plant.sample_time),
        "seed": seed,
        "plant": type(plant).__name__,
        "operating_point": plant.operating_point.to_dict(),
        "input_limits": [np.asarray(lower, float).tolist(), np.asarray(upper, float).tolist()],
    }
    meta.update(dict(metadata or {}))
    all_extras = {"applied_inputs": applied, "saturated": applied != u}
    if n == 0:  # a 0-sample record keeps the channels' widths
        all_extras.update({k: np.empty((0,) + np.shape(v)) for k, v in plant.channels().items()})
    else:
        all_extras.update(channels)
    time = np.arange(n) * float(plant.sample_time)
    return Record(time, u, ys, plant.input_names, plant.output_names, all_extras, meta)


def _real_vector(name: str, value: object, n: int) -> np.ndarray:
    """A scalar or ``n`` real numbers (infinities allowed) as a float vector of length ``n``."""
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be one real number or {n} of them, got {value!r}") from exc
    if arr.dtype.kind not in "biuf" or arr.size not in (1, n) or arr.ndim > 1:
        raise InputError(f"{name} must be one real number or {n} of them, got {value!r}")
    return np.broadcast_to(arr.astype(float), (n,)).copy()


class LinearPlant:
    """A discrete linear model as a Plant (the thesis's "simulation" world, fig. 7.1).

    The model maps input deviations to output deviations around ``operating_point``;
    the plant itself speaks absolute values like the twin.

    Parameters
    ----------
    system : control.StateSpace or control.TransferFunction
        Discrete-time (``dt > 0``) model with no direct term (``D = 0``): a plant returns
        ``y(k+1)`` before ``u(k+1)`` is known, so a direct feed-through cannot be honoured.
        Use eq. (3.11) rather than its one-sample-ahead realisation (6.33).
    operating_point : OperatingPoint, optional
        Trim; zero by default.
    input_names, output_names : sequence of str, optional
        Defaults ``u1, u2, ...`` and ``y1, y2, ...``.
    input_limits : tuple of array_like, optional
        Absolute lower and upper input limits (V); unlimited by default.
    noise_std : float or array_like
        Standard deviation of white measurement noise per output (rad), default 0.
    """

    def __init__(
        self,
        system: control.StateSpace | control.TransferFunction,
        operating_point: OperatingPoint | None = None,
        input_names: Sequence[str] | None = None,
        output_names: Sequence[str] | None = None,
        input_limits: tuple[Sequence[float] | float, Sequence[float] | float] | None = None,
        noise_std: float | Sequence[float] = 0.0,
    ) -> None:
        if not isinstance(system, (control.StateSpace, control.TransferFunction)):
            raise InputError(
                f"system must be a python-control StateSpace or TransferFunction, got {type(system).__name__}"
            )
        dt = system.dt
        if dt is None or dt is True or not dt or not np.isfinite(dt) or dt <= 0:
            raise ConfigurationError(f"system must be discrete-time with a numeric dt > 0 (s), got dt = {dt!r}")
        # scipy's realisation whether slycot is installed or not: the same states, the same bits
        ss = control.tf2ss(system, method="scipy") if isinstance(system, control.TransferFunction) else system
        if np.any(np.asarray(ss.D) != 0):
            raise ConfigurationError(
                f"system has a direct term D = {np.asarray(ss.D).tolist()}; a plant returns y(k+1) before "
                "u(k+1) is known, so D must be 0 (use the strictly proper eq. 3.11, not 6.33)"
            )
        self.system = ss
        self.sample_time = float(dt)
        self.input_names = tuple(input_names or [f"u{i + 1}" for i in range(ss.ninputs)])
        self.output_names = tuple(output_names or [f"y{i + 1}" for i in range(ss.noutputs)])
        if len(self.input_names) != ss.ninputs or len(self.output_names) != ss.noutputs:
            raise InputError(
                f"names do not match the system: {ss.ninputs} inputs / {ss.noutputs} outputs, "
                f"got {self.input_names} / {self.output_names}"
            )
        self._op = operating_point or OperatingPoint.zero(self.input_names, self.output_names)
        if self._op.input_names != self.input_names or self._op.output_names != self.output_names:
            raise InputError("operating point channel names differ from the plant's")
        lo, hi = input_limits if input_limits is not None else (-np.inf, np.inf)
        self._limits = (
            _real_vector("input_limits lower (V)", lo, ss.ninputs),
            _real_vector("input_limits upper (V)", hi, ss.ninputs),
        )
        if np.any(self._limits[0] >= self._limits[1]) or np.any(np.isnan(self._limits)):
            raise InputError(f"input_limits must have lower < upper, got {self._limits}")
        self._noise = _real_vector("noise_std (rad)", noise_std, ss.noutputs)
        if np.any(~np.isfinite(self._noise)) or np.any(self._noise < 0):
            raise InputError(f"noise_std must be finite and >= 0 (rad), got {noise_std!r}")
        self._A, self._B, self._C = (np.asarray(m, float) for m in (ss.A, ss.B, ss.C))
        self._x = np.zeros(ss.nstates)
        self._applied = self._op.inputs.copy()
        self._rng = np.random.default_rng(None if not np.any(self._noise) else 0)

    @property
    def operating_point(self) -> OperatingPoint:
        """Trim inputs and outputs (absolute)."""
        return self._op

    @property
    def input_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Absolute input limits (V)."""
        return self._limits[0].copy(), self._limits[1].copy()

    @property
    def applied_input(self) -> np.ndarray:
        """Input held during the last step (V, absolute, after saturation)."""
        return self._applied.copy()

    @property
    def state(self) -> np.ndarray:
        """Model state (deviation coordinates)."""
        return self._x.copy()

    def _measure(self) -> np.ndarray:
        y = self._C @ self._x
        if np.any(self._noise):
            y = y + self._rng.standard_normal(y.shape) * self._noise
        return self._op.absolute_output(y)

    def reset(self, seed: int | None = None, x0: Sequence[float] | None = None) -> np.ndarray:
        """Return to ``x0`` (default: trim, zero deviation state); reseed the noise.

        Parameters
        ----------
        seed : int, optional
            Seed of the measurement noise generator.
        x0 : array_like, optional
            Initial state in deviation coordinates.
        """
        seed = check_seed("seed", seed)
        x = np.zeros(self._x.shape) if x0 is None else as_finite_array("x0", x0, self._x.shape)
        self._x = x
        self._rng = np.random.default_rng(seed)
        self._applied = self._op.inputs.copy()
        return self._measure()

    def step(self, u: InputVector) -> np.ndarray:
        """Hold ``u`` (absolute V) for one sample and return the next measurement (rad)."""
        u_abs = check_input_vector(u, len(self.input_names), self.input_names)
        applied, _ = saturate(u_abs, *self._limits)
        du = self._op.input_deviation(applied)
        self._x = self._A @ self._x + self._B @ du
        self._applied = applied
        return self._measure()

    def channels(self) -> dict[str, np.ndarray]:
        """The model state (deviation coordinates) as an extra channel."""
        return {"state": self._x.copy()}
