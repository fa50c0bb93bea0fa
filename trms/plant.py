"""The seam every experiment runs on: the Plant protocol, the Record, the operating point.

A :class:`Plant` has named inputs (volts) and outputs (radians), a ``sample_time`` in
seconds, ``reset(seed)`` returning the first measurement, and ``step(u)`` which holds
``u`` for one sample (zero-order hold) and returns the measurement at the next sample.
Plants speak absolute values; :class:`OperatingPoint` converts to and from the
deviations that identification and control work with.

Timing convention of a :class:`Record` of ``N`` rows: row ``k`` holds the time
``t_k = k * Ts``, the measurement ``y_k`` taken at ``t_k`` and the input ``u_k`` held
over ``[t_k, t_k + Ts)``. So ``y_k`` depends on ``u_0 .. u_{k-1}`` only, as in the
identification models of the thesis (eq. 3.2).
"""

from __future__ import annotations

import csv
import json
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, Protocol, Sequence, runtime_checkable

import control
import numpy as np

from .errors import ConfigurationError, InputError, as_finite_array

__all__ = [
    "OperatingPoint",
    "Plant",
    "Record",
    "LinearPlant",
    "saturate",
    "simulate",
    "drive",
]


@dataclass(frozen=True)
class OperatingPoint:
    """Trim inputs and outputs around which a plant is linearised and controlled.

    Parameters
    ----------
    inputs : numpy.ndarray
        Trim inputs, absolute volts, shape ``(n_inputs,)``.
    outputs : numpy.ndarray
        Trim outputs, absolute radians, shape ``(n_outputs,)``.
    input_names, output_names : tuple of str
        Channel names.
    """

    inputs: np.ndarray
    outputs: np.ndarray
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]

    def __post_init__(self) -> None:
        u = as_finite_array("operating point inputs", self.inputs, (len(self.input_names),))
        y = as_finite_array("operating point outputs", self.outputs, (len(self.output_names),))
        u.flags.writeable = False
        y.flags.writeable = False
        object.__setattr__(self, "inputs", u)
        object.__setattr__(self, "outputs", y)
        object.__setattr__(self, "input_names", tuple(self.input_names))
        object.__setattr__(self, "output_names", tuple(self.output_names))

    @classmethod
    def zero(cls, input_names: Sequence[str], output_names: Sequence[str]) -> "OperatingPoint":
        """An operating point at the origin (deviation models)."""
        return cls(np.zeros(len(input_names)), np.zeros(len(output_names)), tuple(input_names), tuple(output_names))

    def input_deviation(self, u: np.ndarray) -> np.ndarray:
        """Absolute inputs (V) to deviations from trim (V); any leading shape."""
        return np.asarray(u, dtype=float) - self.inputs

    def output_deviation(self, y: np.ndarray) -> np.ndarray:
        """Absolute outputs (rad) to deviations from trim (rad); any leading shape."""
        return np.asarray(y, dtype=float) - self.outputs

    def absolute_input(self, du: np.ndarray) -> np.ndarray:
        """Input deviations (V) to absolute inputs (V)."""
        return np.asarray(du, dtype=float) + self.inputs

    def absolute_output(self, dy: np.ndarray) -> np.ndarray:
        """Output deviations (rad) to absolute outputs (rad)."""
        return np.asarray(dy, dtype=float) + self.outputs

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable form."""
        return {
            "inputs": self.inputs.tolist(),
            "outputs": self.outputs.tolist(),
            "input_names": list(self.input_names),
            "output_names": list(self.output_names),
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "OperatingPoint":
        """Inverse of :meth:`to_dict`."""
        return cls(np.array(d["inputs"], float), np.array(d["outputs"], float), tuple(d["input_names"]), tuple(d["output_names"]))


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

    def step(self, u: np.ndarray) -> np.ndarray:
        """Hold ``u`` (absolute V) for one sample; return the next measurement."""
        ...

    def channels(self) -> dict[str, np.ndarray]:
        """Extra named values at the current sample (true angles, rotor states...)."""
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
    applied = np.clip(u, lower, upper)
    return applied, applied != u


def check_input_vector(u: object, n: int, names: Sequence[str]) -> np.ndarray:
    """Validate one input vector for ``step``: numeric, finite, shape ``(n,)`` (a scalar is accepted when n = 1)."""
    label = f"input u ({', '.join(names)}) in V"
    arr = as_finite_array(label, u)
    if arr.ndim == 0 and n == 1:
        arr = arr.reshape(1)
    return as_finite_array(label, arr, (n,))


@dataclass
class Record:
    """A sampled history of a plant: the thesis's GetHistory matrix, with names and metadata.

    Parameters
    ----------
    time : numpy.ndarray
        Sample times (s), shape ``(N,)``.
    inputs : numpy.ndarray
        Commanded inputs (V), shape ``(N, n_inputs)``; row k is held over ``[t_k, t_k + Ts)``.
    outputs : numpy.ndarray
        Measured outputs (rad), shape ``(N, n_outputs)``; row k is measured at ``t_k``.
    input_names, output_names : tuple of str
    extras : dict of str to numpy.ndarray
        Extra channels with ``N`` rows (applied inputs, saturation flags, true angles...).
    metadata : dict
        JSON-serialisable: ``sample_time``, ``config``, ``seed``, ``operating_point``...
    """

    time: np.ndarray
    inputs: np.ndarray
    outputs: np.ndarray
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    extras: dict[str, np.ndarray] = field(default_factory=dict)
    metadata: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.time = np.asarray(self.time, dtype=float)
        self.inputs = np.asarray(self.inputs, dtype=float)
        self.outputs = np.asarray(self.outputs, dtype=float)
        if self.inputs.ndim == 1:
            self.inputs = self.inputs[:, None]
        if self.outputs.ndim == 1:
            self.outputs = self.outputs[:, None]
        self.input_names = tuple(self.input_names)
        self.output_names = tuple(self.output_names)
        n = self.time.shape[0]
        if self.time.ndim != 1:
            raise InputError(f"Record time must be 1-D, got shape {self.time.shape}")
        if self.inputs.shape != (n, len(self.input_names)):
            raise InputError(f"Record inputs must have shape ({n}, {len(self.input_names)}), got {self.inputs.shape}")
        if self.outputs.shape != (n, len(self.output_names)):
            raise InputError(f"Record outputs must have shape ({n}, {len(self.output_names)}), got {self.outputs.shape}")
        for key, val in self.extras.items():
            arr = np.asarray(val)
            if arr.shape[:1] != (n,):
                raise InputError(f"Record extra channel {key!r} must have {n} rows, got shape {arr.shape}")
            self.extras[key] = arr
        json.dumps(self.metadata)  # fail early on non-serialisable metadata

    def __len__(self) -> int:
        return int(self.time.shape[0])

    @property
    def sample_time(self) -> float:
        """Seconds between samples (from the metadata, else from ``time``)."""
        if "sample_time" in self.metadata:
            return float(self.metadata["sample_time"])
        if len(self) < 2:
            raise InputError("Record has fewer than 2 samples and no sample_time in its metadata")
        return float(self.time[1] - self.time[0])

    @property
    def operating_point(self) -> OperatingPoint:
        """The plant's operating point stored in the metadata (zero if absent)."""
        if "operating_point" in self.metadata:
            return OperatingPoint.from_dict(self.metadata["operating_point"])
        return OperatingPoint.zero(self.input_names, self.output_names)

    def input(self, name: str) -> np.ndarray:
        """One input channel by name (V)."""
        return self.inputs[:, self._index(self.input_names, name, "input")]

    def output(self, name: str) -> np.ndarray:
        """One output channel by name (rad)."""
        return self.outputs[:, self._index(self.output_names, name, "output")]

    @staticmethod
    def _index(names: tuple[str, ...], name: str, kind: str) -> int:
        if name not in names:
            raise InputError(f"unknown {kind} {name!r}; this record has {', '.join(names)}")
        return names.index(name)

    def deviations(self) -> tuple[np.ndarray, np.ndarray]:
        """Inputs and outputs as deviations from the recorded operating point."""
        op = self.operating_point
        return op.input_deviation(self.inputs), op.output_deviation(self.outputs)

    def equals(self, other: "Record") -> bool:
        """Bit-for-bit equality of every array, name and metadata entry."""
        if (self.input_names, self.output_names, self.metadata) != (other.input_names, other.output_names, other.metadata):
            return False
        if set(self.extras) != set(other.extras):
            return False
        pairs = [(self.time, other.time), (self.inputs, other.inputs), (self.outputs, other.outputs)]
        pairs += [(self.extras[k], other.extras[k]) for k in self.extras]
        return all(a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes() for a, b in pairs)

    # ------------------------------------------------------------------ files
    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the record losslessly to ``path`` (``.npz``), atomically.

        The file is written to a temporary name in the same folder and renamed, so a
        reader never sees a half-written file.
        """
        path = Path(path)
        if path.suffix != ".npz":
            path = path.with_suffix(".npz")
        path.parent.mkdir(parents=True, exist_ok=True)
        header = {
            "input_names": list(self.input_names),
            "output_names": list(self.output_names),
            "extras": list(self.extras),
            "metadata": self.metadata,
            "format": "trms.Record/1",
        }
        arrays = {"time": self.time, "inputs": self.inputs, "outputs": self.outputs}
        arrays.update({f"extra_{i}": v for i, v in enumerate(self.extras.values())})
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as fh:
                np.savez(fh, header=np.array(json.dumps(header)), **arrays)
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the file the usual permissions
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        return path

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> "Record":
        """Read a record written by :meth:`save`."""
        path = Path(path)
        if not path.is_file():
            raise InputError(f"record file {str(path)!r} does not exist")
        try:
            with np.load(path, allow_pickle=False) as data:
                header = json.loads(str(data["header"]))
                extras = {name: data[f"extra_{i}"] for i, name in enumerate(header["extras"])}
                return cls(
                    data["time"], data["inputs"], data["outputs"],
                    tuple(header["input_names"]), tuple(header["output_names"]),
                    extras, header["metadata"],
                )
        except (KeyError, ValueError, OSError) as exc:
            raise InputError(f"{str(path)!r} is not a trms Record file: {exc}") from exc

    @classmethod
    def from_csv(cls, path: str | os.PathLike[str], **columns: Any) -> "Record":
        """Read a rig's CSV export; see :func:`trms.rigdata.record_from_csv` for the arguments."""
        from .rigdata import record_from_csv

        return record_from_csv(path, **columns)

    def to_csv(self, path: str | os.PathLike[str]) -> Path:
        """Export time, inputs, outputs and 1-D/2-D extra channels as CSV (one row per sample)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        columns: list[tuple[str, np.ndarray]] = [("time", self.time)]
        columns += [(n, self.inputs[:, i]) for i, n in enumerate(self.input_names)]
        columns += [(n, self.outputs[:, i]) for i, n in enumerate(self.output_names)]
        for key, val in self.extras.items():
            flat = val.reshape(len(self), -1).astype(float)
            if flat.shape[1] == 1:
                columns.append((key, flat[:, 0]))
            else:
                columns += [(f"{key}[{j}]", flat[:, j]) for j in range(flat.shape[1])]
        with open(path, "w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow([c[0] for c in columns])
            data = np.column_stack([c[1] for c in columns])
            writer.writerows((repr(float(x)) for x in row) for row in data)
        return path


def simulate(
    plant: Plant,
    inputs: Iterable[Sequence[float]] | np.ndarray,
    seed: int | None = None,
    metadata: Mapping[str, Any] | None = None,
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

    Returns
    -------
    Record
        ``N`` rows; extras ``applied_inputs`` and ``saturated`` plus the plant's channels.
    """
    n_in = len(plant.input_names)
    u = np.asarray(inputs, dtype=float)
    if u.ndim == 1 and n_in == 1:
        u = u[:, None]
    u = as_finite_array(f"inputs ({', '.join(plant.input_names)}) in V", u, (None, n_in))
    return drive(plant, u.shape[0], lambda k, y: u[k], seed, metadata)


def drive(
    plant: Plant,
    n_samples: int,
    policy: Callable[[int, np.ndarray], np.ndarray],
    seed: int | None = None,
    metadata: Mapping[str, Any] | None = None,
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

    Returns
    -------
    Record
        ``N`` rows; extras ``applied_inputs`` and ``saturated`` plus the plant's channels.
    """
    n = int(n_samples)
    n_in = len(plant.input_names)
    u = np.empty((n, n_in))
    y0 = plant.reset(seed)
    ys = np.empty((n, len(plant.output_names)))
    applied = np.empty_like(u)
    extras: dict[str, list[np.ndarray]] = {}
    y = y0
    for k in range(n):
        ys[k] = y
        for key, val in plant.channels().items():
            extras.setdefault(key, []).append(np.array(val))
        u[k] = policy(k, y)
        y = plant.step(u[k])
        applied[k] = plant.applied_input
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
    all_extras.update({k: np.stack(v) for k, v in extras.items()})
    time = np.arange(n) * float(plant.sample_time)
    return Record(time, u, ys, plant.input_names, plant.output_names, all_extras, meta)


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
            raise InputError(f"system must be a python-control StateSpace or TransferFunction, got {type(system).__name__}")
        dt = system.dt
        if dt is None or dt is True or not dt or dt <= 0:
            raise ConfigurationError(f"system must be discrete-time with a numeric dt > 0 (s), got dt = {dt!r}")
        ss = control.ss(system) if isinstance(system, control.TransferFunction) else system
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
        self._limits = (np.broadcast_to(np.asarray(lo, float), (ss.ninputs,)).copy(),
                        np.broadcast_to(np.asarray(hi, float), (ss.ninputs,)).copy())
        if np.any(self._limits[0] >= self._limits[1]) or np.any(np.isnan(self._limits)):
            raise InputError(f"input_limits must have lower < upper, got {self._limits}")
        self._noise = np.broadcast_to(np.asarray(noise_std, float), (ss.noutputs,)).copy()
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
        x = np.zeros(self._x.shape) if x0 is None else as_finite_array("x0", x0, self._x.shape)
        self._x = x
        self._rng = np.random.default_rng(seed)
        self._applied = self._op.inputs.copy()
        return self._measure()

    def step(self, u: Sequence[float] | float) -> np.ndarray:
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
