"""Recorded experiments: the :class:`Record` (time, inputs, outputs, extra channels, metadata) and the operating point.

Timing convention of a :class:`Record` of ``N`` rows: row ``k`` holds the time ``t_k = k * Ts``, the measurement
``y_k`` taken at ``t_k`` and the input ``u_k`` held over ``[t_k, t_k + Ts)``. So ``y_k`` depends on
``u_0 .. u_{k-1}`` only, as in the identification models of the thesis (eq. 3.2).

Signal names, one naming across the package: inputs ``u1`` (main rotor voltage) and ``u2`` (tail rotor voltage), in
V; outputs ``pitch`` and ``yaw`` (the encoder angles), in rad. The inputs keep the rig's and the thesis's names; the
outputs are named for the axis rather than ``y1``/``y2``, so a column says what it measures. Plants speak absolute
values; :class:`OperatingPoint` converts to and from the deviations that identification and control work with.

A rig's own files (CSV, MAT) are read into a Record by :mod:`trms.rigdata`; ``Record.save``/``load`` keep the
project's own ``.npz`` form and ``to_csv`` writes one CSV row per sample.
"""

from __future__ import annotations

import csv
import json
import os
import zipfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import numpy as np

from trms.display import html_table
from trms.errors import ConfigurationError, InputError, as_finite_array, check_in_range
from trms.files import atomic_write, readable_file

__all__ = ["MAX_RECORD_BYTES", "OperatingPoint", "Record", "RowBuffer"]

#: Most bytes of arrays a Record file may declare (2 GiB), checked before anything is decompressed.
MAX_RECORD_BYTES = 2**31
#: How far a Record's time steps may differ from its sample time, relative to it (round-off of ``k * Ts``).
_TIME_RTOL = 1e-6


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
    def zero(cls, input_names: Sequence[str], output_names: Sequence[str]) -> OperatingPoint:
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

    def with_signal(self, signal: np.ndarray, channel: int | str = 0) -> np.ndarray:
        """Absolute inputs (V), shape ``(N, n_inputs)``: trim on every input plus ``signal`` (deviation V) on one.

        Parameters
        ----------
        signal : numpy.ndarray
            Deviation (V), shape ``(N,)``.
        channel : int or str
            The input the signal drives (index or name).

        Examples
        --------
        >>> op = OperatingPoint(np.array([1.0, 2.0]), np.zeros(2), ("u1", "u2"), ("pitch", "yaw"))
        >>> op.with_signal(np.array([0.5, -0.5]), "u2").tolist()
        [[1.0, 2.5], [1.0, 1.5]]
        """
        sig = as_finite_array("signal (deviation V)", signal)
        if sig.ndim != 1:
            raise InputError(f"signal must be one-dimensional (N,), got shape {sig.shape}")
        if isinstance(channel, str):
            if channel not in self.input_names:
                raise InputError(f"unknown input channel {channel!r}; allowed: {', '.join(self.input_names)}")
            channel = self.input_names.index(channel)
        if not 0 <= int(channel) < len(self.input_names):
            raise InputError(f"input channel = {channel!r} is outside 0..{len(self.input_names) - 1}")
        u = np.tile(self.inputs, (sig.size, 1))
        u[:, int(channel)] += sig
        return u

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable form."""
        return {
            "inputs": self.inputs.tolist(),
            "outputs": self.outputs.tolist(),
            "input_names": list(self.input_names),
            "output_names": list(self.output_names),
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> OperatingPoint:
        """Inverse of :meth:`to_dict`."""
        return cls(
            np.array(d["inputs"], float),
            np.array(d["outputs"], float),
            tuple(d["input_names"]),
            tuple(d["output_names"]),
        )


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
        ``sample_time``, ``config``, ``seed``, ``operating_point``... Restricted to values JSON keeps
        exactly (dicts with str keys, lists, str, int, float, bool, None), so a saved Record loads
        back equal; tuples, non-str keys and other types are refused with :class:`InputError`.
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
            raise InputError(
                f"Record outputs must have shape ({n}, {len(self.output_names)}), got {self.outputs.shape}"
            )
        for key, val in self.extras.items():
            arr = np.asarray(val)
            if arr.shape[:1] != (n,):
                raise InputError(f"Record extra channel {key!r} must have {n} rows, got shape {arr.shape}")
            self.extras[key] = arr
        if not isinstance(self.metadata, dict):
            raise InputError(f"Record metadata must be a dict, got {type(self.metadata).__name__}")
        _check_json_value("metadata", self.metadata)

    def __len__(self) -> int:
        return int(self.time.shape[0])

    def __repr__(self) -> str:
        n = len(self)
        span = f"{self.time[0]:g}-{self.time[-1]:g} s" if n else "empty"
        ts = f", Ts={self.metadata['sample_time']:g} s" if "sample_time" in self.metadata else ""
        extras = f", extras=[{', '.join(self.extras)}]" if self.extras else ""
        return (
            f"Record({n} samples, {span}{ts}, inputs=({', '.join(self.input_names)}) V, "
            f"outputs=({', '.join(self.output_names)}) rad{extras})"
        )

    def _repr_html_(self) -> str:
        rows = [
            ("samples", str(len(self))),
            ("inputs (V)", ", ".join(self.input_names)),
            ("outputs (rad)", ", ".join(self.output_names)),
            ("extras", ", ".join(self.extras) or "-"),
        ]
        rows += [(str(k), str(v)) for k, v in self.metadata.items() if isinstance(v, (str, int, float, bool))]
        return html_table("Record", rows)

    def to_dataframe(self) -> Any:
        """The record as a :class:`pandas.DataFrame` indexed by time (s): inputs, outputs and 1-D/2-D extras.

        Extra channels with several columns become ``name[i]``. Needs pandas (not a dependency of trms).

        Raises
        ------
        ConfigurationError
            pandas is not installed.
        """
        try:
            import pandas as pd
        except ImportError as exc:
            raise ConfigurationError("Record.to_dataframe needs pandas; install it with pip install pandas") from exc
        columns: dict[str, np.ndarray] = {}
        for names, values in ((self.input_names, self.inputs), (self.output_names, self.outputs)):
            for j, name in enumerate(names):
                columns[name] = values[:, j]
        for key, arr in self.extras.items():
            flat = np.asarray(arr).reshape(len(self), -1)
            if flat.shape[1] == 1:
                columns[key] = flat[:, 0]
            else:
                for j in range(flat.shape[1]):
                    columns[f"{key}[{j}]"] = flat[:, j]
        return pd.DataFrame(columns, index=pd.Index(self.time, name="time (s)"))

    @property
    def sample_time(self) -> float:
        """Seconds between samples (from the metadata, else from ``time``)."""
        if "sample_time" in self.metadata:
            ts = self.metadata["sample_time"]
        elif len(self) < 2:
            raise InputError("Record has fewer than 2 samples and no sample_time in its metadata")
        else:
            ts = float(self.time[1] - self.time[0])
        return check_in_range("Record sample_time", ts, 0.0, np.inf, unit=" s", low_open=True)

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

    def equals(self, other: Record) -> bool:
        """Bit-for-bit equality of every array, name and metadata entry."""
        if (self.input_names, self.output_names, self.metadata) != (
            other.input_names,
            other.output_names,
            other.metadata,
        ):
            return False
        if set(self.extras) != set(other.extras):
            return False
        pairs = [(self.time, other.time), (self.inputs, other.inputs), (self.outputs, other.outputs)]
        pairs += [(self.extras[k], other.extras[k]) for k in self.extras]
        return all(a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes() for a, b in pairs)

    # ------------------------------------------------------------------ files
    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the record losslessly to ``path`` (``.npz``), atomically.

        The file is written to a temporary name in the same folder and renamed
        (:func:`trms.files.atomic_write`), so a reader never sees a half-written file and a
        killed writer's temporary file is swept by the next save.

        Raises
        ------
        InputError
            A name not ending in ``.npz``, or an existing folder.
        """
        path = Path(path)
        if path.is_dir():
            raise InputError(f"Record file {str(path)!r} is an existing folder; allowed: a file name ending in .npz")
        if path.suffix != ".npz":
            raise InputError(f"Record file {str(path)!r} must end in .npz (a Record is saved as an .npz archive)")
        header = {
            "input_names": list(self.input_names),
            "output_names": list(self.output_names),
            "extras": list(self.extras),
            "metadata": self.metadata,
            "format": "trms.Record/1",
        }
        # Any: numpy's savez stub would otherwise match the arrays against its allow_pickle flag.
        arrays: dict[str, Any] = {"time": self.time, "inputs": self.inputs, "outputs": self.outputs}
        arrays.update({f"extra_{i}": v for i, v in enumerate(self.extras.values())})
        return atomic_write(path, lambda fh: np.savez(fh, header=np.array(json.dumps(header)), **arrays))

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Record:
        """Read a record written by :meth:`save`.

        Before any array is decompressed, the shape and type each member of the archive declares are checked
        against the header's names and against each other, and their sizes against what the archive holds and
        :data:`MAX_RECORD_BYTES`: a file whose header claims gigabytes (or a zip bomb) is refused at once.

        Raises
        ------
        InputError
            A missing file, a folder, a FIFO or device, an unreadable file, one :meth:`save` did not write,
            arrays of the wrong shape or type (booleans, complex numbers or text as inputs, outputs or time),
            more than :data:`MAX_RECORD_BYTES` of arrays, a time column that is not finite and increasing on the
            recorded sample time, a sample time that is not finite and positive, or an input or output that is
            NaN in every sample.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> p = pathlib.Path(tempfile.mkdtemp()) / "r.npz"
        >>> _ = Record([0.0, 0.2, 0.1], np.zeros(3), np.zeros(3), ("u1",), ("pitch",)).save(p)
        >>> Record.load(p)
        Traceback (most recent call last):
        ...
        trms.errors.InputError: ... time 0.1 s at row 2 does not increase (previous 0.2 s); ...
        """
        path = readable_file(path, "record file")
        where = f"{str(path)!r} is not a trms Record file"
        if not zipfile.is_zipfile(path):
            raise InputError(f"{where}: not an .npz archive (Record.save writes one)")
        try:
            with zipfile.ZipFile(path) as archive:
                declared = _declared_arrays(archive)
            if "header" not in declared or declared["header"][1].kind != "U" or declared["header"][0] != ():
                raise InputError(f"{where}: it has no text header (header.npy)")
            with np.load(path, allow_pickle=False) as data:
                header = json.loads(str(data["header"]))
                if not isinstance(header, dict) or header.get("format") != "trms.Record/1":
                    raise InputError(f"{where}: its header is not a trms.Record/1 header")
                names = {k: header.get(k) for k in ("input_names", "output_names", "extras")}
                for key, val in names.items():
                    if not isinstance(val, list) or not all(isinstance(v, str) for v in val):
                        raise InputError(f"{where}: header field {key!r} must be a list of names, got {val!r}")
                if not isinstance(header.get("metadata"), dict):
                    raise InputError(f"{where}: header field 'metadata' must be a dict")
                _check_declared(declared, header)
                extras = {name: data[f"extra_{i}"] for i, name in enumerate(header["extras"])}
                record = cls(
                    data["time"],
                    data["inputs"],
                    data["outputs"],
                    tuple(header["input_names"]),
                    tuple(header["output_names"]),
                    extras,
                    header["metadata"],
                )
            _check_time(record)
            for kind, channels, values in (
                ("input", record.input_names, record.inputs),
                ("output", record.output_names, record.outputs),
            ):
                empty = [n for n, column in zip(channels, values.T) if column.size and np.isnan(column).all()]
                if empty:
                    raise InputError(f"{where}: {kind} {empty[0]!r} is NaN in every sample (a channel without data)")
            return record
        except InputError as exc:
            if str(exc).startswith(where):
                raise
            raise InputError(f"{where}: {exc}") from exc
        except (KeyError, ValueError, TypeError, OSError, EOFError, zipfile.BadZipFile, RuntimeError) as exc:
            text = " ".join(str(exc).split())[:200]
            raise InputError(f"{where}: {type(exc).__name__}: {text}") from exc

    def to_csv(self, path: str | os.PathLike[str]) -> Path:
        """Export time, inputs, outputs and extra channels as CSV (one row per sample), atomically.

        Extra channels with several values per sample take one column each (``name[j]``). A
        0-sample record gives the header line only. The file is replaced atomically
        (:func:`trms.files.atomic_write`): a failed write leaves the old file intact.
        """
        n = len(self)
        columns: list[tuple[str, np.ndarray]] = [("time", self.time)]
        columns += [(name, self.inputs[:, i]) for i, name in enumerate(self.input_names)]
        columns += [(name, self.outputs[:, i]) for i, name in enumerate(self.output_names)]
        for key, val in self.extras.items():
            flat = val.reshape(n, int(np.prod(val.shape[1:], dtype=np.int64))).astype(float)
            if val.ndim == 1:
                columns.append((key, flat[:, 0]))
            else:
                columns += [(f"{key}[{j}]", flat[:, j]) for j in range(flat.shape[1])]
        data = np.column_stack([c[1] for c in columns]).reshape(n, len(columns))

        def write(fh: IO[str]) -> None:
            writer = csv.writer(fh)
            writer.writerow([c[0] for c in columns])
            writer.writerows((repr(float(x)) for x in row) for row in data)

        return atomic_write(Path(path), write, binary=False)


class RowBuffer:
    """A run's named channels, one row per sample, written into arrays of ``n`` rows allocated at the first sample:
    how a Record's extra channels grow without a new object per sample.

    Each channel's shape and dtype are its first row's.

    Parameters
    ----------
    n : int
        Number of samples.

    Examples
    --------
    >>> rows = RowBuffer(3)
    >>> for k in range(3):
    ...     rows.put(k, {"x": np.array([k, 2 * k]), "flag": k > 1})
    >>> rows.arrays()["x"].tolist(), rows.arrays()["flag"].tolist()
    ([[0, 0], [1, 2], [2, 4]], [False, False, True])
    """

    def __init__(self, n: int) -> None:
        self.n = int(n)
        self._arrays: dict[str, np.ndarray] | None = None

    def put(self, k: int, row: Mapping[str, Any]) -> None:
        """Write sample ``k`` of every channel of ``row`` (the channels of the first row)."""
        arrays = self._arrays
        if arrays is None:
            arrays = self._arrays = {}
            for key, value in row.items():
                first = np.asarray(value)
                arrays[key] = np.empty((self.n,) + first.shape, first.dtype)
        for key, value in row.items():
            arrays[key][k] = value

    def arrays(self) -> dict[str, np.ndarray]:
        """Every channel, ``(n, ...)`` (none before the first row)."""
        return dict(self._arrays or {})


def _check_json_value(where: str, value: object) -> None:
    """Refuse a metadata value that JSON would not give back identical (tuples, non-str keys...)."""
    if value is None or isinstance(value, (str, bool, int, float)):
        return
    if isinstance(value, list):
        for i, v in enumerate(value):
            _check_json_value(f"{where}[{i}]", v)
        return
    if isinstance(value, dict):
        for k, v in value.items():
            if not isinstance(k, str):
                raise InputError(
                    f"{where} has the key {k!r} ({type(k).__name__}); allowed: str keys only "
                    "(JSON turns every key into a string)"
                )
            _check_json_value(f"{where}[{k!r}]", v)
        return
    raise InputError(
        f"{where} = {value!r} is a {type(value).__name__}; allowed in Record metadata: dict (str keys), "
        "list, str, int, float, bool, None (use a list for a tuple)"
    )


def _declared_arrays(archive: zipfile.ZipFile) -> dict[str, tuple[tuple[int, ...], np.dtype[Any]]]:
    """Each ``.npy`` member's declared shape and type, read from its header alone (nothing else decompressed).

    Refuses a member whose declared size exceeds what the archive says it holds, and a total beyond
    :data:`MAX_RECORD_BYTES`.
    """
    out: dict[str, tuple[tuple[int, ...], np.dtype[Any]]] = {}
    total = 0
    for info in archive.infolist():
        if not info.filename.endswith(".npy"):
            continue
        with archive.open(info) as fh:
            version = np.lib.format.read_magic(fh)
            read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
            shape, _, dtype = read(fh, max_header_size=10_000)
            offset = fh.tell()
        size = int(np.prod(shape, dtype=object)) * dtype.itemsize
        name = info.filename[: -len(".npy")]
        if size > info.file_size - offset:
            raise InputError(
                f"member {name!r} declares shape {shape} of {dtype} ({size:,} bytes) but holds "
                f"{max(info.file_size - offset, 0):,} bytes"
            )
        total += size
        if total > MAX_RECORD_BYTES:
            raise InputError(
                f"its arrays declare more than {MAX_RECORD_BYTES:,} bytes (MAX_RECORD_BYTES); allowed: at most that"
            )
        out[name] = (tuple(shape), dtype)
    return out


def _check_declared(declared: Mapping[str, tuple[tuple[int, ...], np.dtype[Any]]], header: Mapping[str, Any]) -> None:
    """The members' declared shapes and types against the header's names and each other (before loading)."""
    members = {"time": ("array 'time'", None), "inputs": ("array 'inputs'", header["input_names"])}
    members["outputs"] = ("array 'outputs'", header["output_names"])
    members.update({f"extra_{i}": (f"array 'extra_{i}' ({n!r})", None) for i, n in enumerate(header["extras"])})
    for member in members:
        if member not in declared:
            raise InputError(f"it lacks the array {member!r}")
    n = declared["time"][0][0] if len(declared["time"][0]) == 1 else None
    if n is None:
        raise InputError(f"its array 'time' must be 1-D, declared shape {declared['time'][0]}")
    for member, (label, names) in members.items():
        shape, dtype = declared[member]
        numbers = "iuf" if names is not None or member == "time" else "biuf"
        if dtype.kind not in numbers:
            kind = {"b": "booleans", "c": "complex numbers", "U": "text", "S": "bytes", "O": "Python objects"}
            raise InputError(
                f"its {label} holds {kind.get(dtype.kind, str(dtype))} ({dtype}); allowed: real numbers (float)"
            )
        want = (n,) if names is None else (n, len(names))
        ok = (
            shape[:1] == (n,)
            if member.startswith("extra_")
            else shape == want or (names is not None and len(names) == 1 and shape == (n,))
        )
        if not ok:
            rows = f"{n} rows" if member.startswith("extra_") else f"shape {want}"
            raise InputError(f"its {label} must have {rows} (as its time), declared shape {shape}")


def _check_time(record: Record) -> None:
    """Refuse a time column that is not finite and increasing on the recorded sample time (s)."""
    t = record.time
    if "sample_time" in record.metadata:
        ts = record.metadata["sample_time"]
        if isinstance(ts, bool) or not isinstance(ts, (int, float)) or not np.isfinite(ts) or ts <= 0:
            raise InputError(f"its sample_time = {ts!r} s; allowed: a finite number of seconds > 0")
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise InputError(f"its time is {float(t[bad[0]])!r} at row {int(bad[0])}; allowed: finite times (s)")
    steps = np.diff(t)
    back = np.flatnonzero(steps <= 0)
    if back.size:
        k = int(back[0]) + 1
        raise InputError(
            f"its time {t[k]:.6g} s at row {k} does not increase (previous {t[k - 1]:.6g} s); "
            "allowed: strictly increasing times"
        )
    if steps.size and "sample_time" in record.metadata:
        ts = float(record.metadata["sample_time"])
        off = np.flatnonzero(np.abs(steps - ts) > _TIME_RTOL * ts)
        if off.size:
            k = int(off[0]) + 1
            raise InputError(
                f"its time steps {steps[off[0]]:.6g} s at row {k} (from {t[k - 1]:.6g} to {t[k]:.6g} s); its "
                f"sample_time is {ts:g} s: every step must be the sample time"
            )
