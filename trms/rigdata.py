"""A rig's own recordings in: CSV/text and MATLAB exports with named columns and units, as :class:`~trms.record.Record`.

A rig's data logger (its MATLAB/Simulink software) writes a time column and named columns, angles in
degrees or radians, voltages in volts, time in seconds or milliseconds. :func:`record_from_csv` reads
such a text file as it comes -- comma, semicolon, tab or whitespace delimited, UTF-8 or Latin-1, with
title or comment lines before the header -- and :func:`record_from_mat` reads a MATLAB v5/v7 ``.mat``
file (variables, fields of a struct, or columns of a matrix). Both check the data the same way:

* every named column present, once; every cell a finite real number;
* time increasing, with a sample time inside the rig's real-time kernel's range
  (:data:`trms.reference.SAMPLE_TIME_RANGE`): a time column in milliseconds read as seconds is refused
  with a line that says ``--time-unit ms``;
* timestamps on a uniform grid: jitter up to :data:`~trms.rigchecks.JITTER_TOLERANCE` of the sample time is snapped to
  the grid, anything beyond is refused unless ``resample`` asks for linear interpolation onto one;
* angles that fit the rig: within the end stops of the model's pitch and yaw joints (:func:`end_stops`,
  with :data:`~trms.rigchecks.END_STOP_MARGIN`) and no faster than :data:`~trms.rigchecks.MAX_RATE` --
  degrees labelled radians are refused, radians labelled degrees are warned about.

The checks live in :mod:`trms.rigchecks`, the parsing of text exports in :mod:`trms.rigtext` and of MATLAB
exports in :mod:`trms.rigmat`.

Angles are converted to radians and the operating point stored: given by the user, or estimated as the
mean of a stated hover segment ``[t0, t1)``, and the metadata says which (``operating_point_source``).
Everything the reader did to the data (lines skipped, timestamps snapped, samples resampled) is said in
one line each as a :class:`RigDataWarning` and kept in the metadata (``import_warnings``). Nothing is
written when a file is refused.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from trms import reference
from trms.errors import InputError, as_finite_array, check_choice, short_repr
from trms.files import readable_file
from trms.record import OperatingPoint, Record
from trms.reference import VOLTAGE_LIMIT
from trms.rigchecks import (
    ANGLE_UNITS,
    END_STOP_MARGIN,
    MAX_INPUT_V,
    TIME_UNITS,
    ExportLayout,
    angle_stop,
    beyond_end_stops,
    check_angles,
    check_sample_time,
    check_voltages,
    uniform_grid,
)
from trms.rigmat import is_mat_header, read_mat_columns
from trms.rigtext import decode_export, read_text_columns

__all__ = [
    "RigDataWarning",
    "end_stops",
    "hover_operating_point",
    "load_record",
    "read_inputs",
    "record_from_csv",
    "record_from_export",
    "record_from_mat",
]


class RigDataWarning(UserWarning):
    """What the reader did to a rig's export (lines skipped, timestamps snapped or resampled), or a doubt
    about it (angles that look like radians labelled degrees): one line, also kept in the Record's
    ``import_warnings`` metadata."""


def _as_path(path: object, what: str) -> Path:
    """``path`` as a Path; anything but a str or os.PathLike refused in one line."""
    if not isinstance(path, (str, os.PathLike)):
        raise InputError(f"{what} must be a file path (str or os.PathLike), got {short_repr(path)}")
    return Path(path)


def _names(value: str | Sequence[str], what: str) -> tuple[str, ...]:
    names = (value,) if isinstance(value, str) else tuple(value) if isinstance(value, (list, tuple)) else ()
    if not names or not all(isinstance(n, str) and n for n in names):
        raise InputError(f"{what} must name at least one column, got {value!r}")
    return names


def _layout(
    path: Path,
    time: str,
    inputs: str | Sequence[str],
    outputs: str | Sequence[str],
    units: str | None,
    time_unit: str,
    resample: bool,
    input_names: Sequence[str] | None,
    output_names: Sequence[str] | None,
    operating_point: object,
    hover_segment: object,
    config: object,
) -> ExportLayout:
    """Check the column options before the file is read."""
    if config is not None:
        check_choice("configuration", config, reference.CONFIGURATION_NAMES)
    if hover_segment is not None:
        as_finite_array("hover_segment (t0, t1) in s", hover_segment, (2,))
    if units is None:
        raise InputError(f"units of the angle columns not given for {str(path)!r}; say units='deg' or 'rad' (--units)")
    if units not in ANGLE_UNITS:
        raise InputError(f"unknown angle units {units!r}; allowed: {', '.join(repr(u) for u in ANGLE_UNITS)}")
    if time_unit not in TIME_UNITS:
        raise InputError(f"unknown time unit {time_unit!r}; allowed: {', '.join(repr(u) for u in TIME_UNITS)}")
    if not isinstance(time, str) or not time:
        raise InputError(f"time must name the time column, got {time!r}")
    ins, outs = _names(inputs, "inputs"), _names(outputs, "outputs")
    in_names = tuple(input_names) if input_names is not None else ins
    out_names = tuple(output_names) if output_names is not None else outs
    if len(in_names) != len(ins) or len(out_names) != len(outs):
        raise InputError(f"input_names/output_names must name each column once: {len(ins)} inputs, {len(outs)} outputs")
    if operating_point is not None and hover_segment is not None:
        raise InputError("give either operating_point or hover_segment, not both")
    roles = ("time", *in_names, *out_names)
    wanted = (time, *ins, *outs)
    for i, col in enumerate(wanted):
        if col in wanted[:i]:
            first = wanted.index(col)
            raise InputError(
                f"column {col!r} is given for both {roles[first]} and {roles[i]}; each channel needs its own column"
            )
    return ExportLayout(time, ins, outs, units, time_unit, bool(resample), in_names, out_names)


def end_stops() -> dict[str, float]:
    """The end stops of the rig's pitch and yaw axes (rad), :data:`trms.reference.END_STOPS`.

    The shipped MJCF's joint ranges are these (its tests check it).

    Returns
    -------
    dict
        ``{"pitch": ..., "yaw": ...}``, ``|angle|`` at each stop.

    Examples
    --------
    >>> end_stops()
    {'pitch': 1.1, 'yaw': 3.0}
    """
    return dict(reference.END_STOPS)


def hover_operating_point(record: Record, t0: float, t1: float, *, origin: float = 0.0) -> OperatingPoint:
    """The operating point as the mean inputs and outputs over the half-open segment ``t0 <= t < t1`` (s).

    Parameters
    ----------
    record : Record
    t0, t1 : float
        The hover segment ``[t0, t1)`` (s) on the clock ``origin + record.time`` (the record's own time axis by
        default; a rig's log clock with ``origin`` its first sample's time), holding at least 2 samples; the
        sample at ``t1`` is not in it (it is often the first excited one). It must lie inside the record (from
        its first sample to the end of its last, with half a sample of slack): a segment partly outside is
        refused, not cut to the overlap. Messages give times on the same clock.
    origin : float
        Time (s) on the segment's clock at the record's ``t = 0`` (a rig export's first sample: its Record's
        ``start_time``).

    Returns
    -------
    OperatingPoint

    Examples
    --------
    >>> r = Record(np.arange(5) * 0.1, [1.0, 1.0, 3.0, 3.0, 3.0], np.zeros(5), ("u1",), ("pitch",))
    >>> hover_operating_point(r, 0.0, 0.2).inputs
    array([1.])
    >>> hover_operating_point(r, 0.0, 10.0, origin=12.5)
    Traceback (most recent call last):
    ...
    trms.errors.InputError: hover segment [0, 10) s is not inside the record (time 12.5 .. 13 s); ...
    """
    t = record.time + origin
    if not (np.isfinite(t0) and np.isfinite(t1)) or t1 <= t0:
        raise InputError(f"hover segment [{t0!r}, {t1!r}) s must have t0 < t1")
    ts = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    eps = 1e-6 * ts if t.size > 1 else 1e-9  # a sample exactly at t1 is out
    if t.size and (t0 < t[0] - 0.5 * ts - eps or t1 > t[-1] + 1.5 * ts + eps):  # half a sample of slack
        raise InputError(
            f"hover segment [{t0:g}, {t1:g}) s is not inside the record (time {t[0]:g} .. {t[-1] + ts:g} s); "
            "allowed: a segment within it"
        )
    sel = (t >= t0 - eps) & (t < t1 - eps)
    if sel.sum() < 2:
        raise InputError(
            f"hover segment [{t0:g}, {t1:g}) s holds {int(sel.sum())} samples of the record "
            f"(time {t[0]:g} .. {t[-1]:g} s); at least 2 are needed"
        )
    return OperatingPoint(
        record.inputs[sel].mean(axis=0), record.outputs[sel].mean(axis=0), record.input_names, record.output_names
    )


# ------------------------------------------------------------------------------------------- text files
def _assemble(
    path: Path,
    data: np.ndarray,
    lines: list[int] | None,
    notes: list[str],
    read: dict[str, Any],
    layout: ExportLayout,
    operating_point: OperatingPoint | Sequence[Sequence[float]] | None,
    hover_segment: tuple[float, float] | None,
    config: str | None,
) -> Record:
    """The checks common to every export format, and the Record."""

    def row(i: int) -> str:
        return f"row {lines[i]}" if lines is not None else f"sample {i + 1}"

    where = f" of {str(path)!r}"
    n = data.shape[0]
    if n < 3:
        raise InputError(f"{str(path)!r} has {n} data rows; at least 3 are needed")
    data = data.copy()
    data[:, 0] *= TIME_UNITS[layout.time_unit]
    t = data[:, 0]
    dt = np.diff(t)
    bad = np.flatnonzero(dt <= 0)
    if bad.size:
        raise InputError(
            f"{row(bad[0] + 1)}, column {layout.time!r}: time {float(t[bad[0] + 1])!r} s does not increase "
            f"(previous {float(t[bad[0]])!r} s)"
        )
    slow = check_sample_time(float(np.median(dt)), layout, where)
    data, ts, origin, grid_notes = uniform_grid(data, layout, row, where)
    if grid_notes and lines is not None and data.shape[0] != n:
        lines = None  # resampled: rows are samples now
    n_in = len(layout.inputs)
    input_notes = check_voltages(data[:, 1 : 1 + n_in], layout, row, where)
    angle_notes = check_angles(data[:, 1 + n_in :], ts, layout, row, where, time=data[:, 0])
    notes = [*notes, *([slow] if slow else []), *grid_notes, *input_notes, *angle_notes]
    scale = ANGLE_UNITS[layout.units]
    meta: dict[str, Any] = {
        "sample_time": round(ts, 9),
        "source": str(path),
        "units": {"inputs": "V", "outputs": layout.units, "time": layout.time_unit},
        "plant": "rig",
        "start_time": float(origin),
        "import": read,
    }
    if notes:
        meta["import_warnings"] = list(notes)
    if config is not None:
        meta["config"] = config
    u = data[:, 1 : 1 + n_in]
    y = data[:, 1 + n_in :] * scale
    record = Record(np.arange(data.shape[0]) * ts, u, y, layout.in_names, layout.out_names, {}, meta)
    op: OperatingPoint | None = None
    if hover_segment is not None:
        t0, t1 = (float(x) for x in hover_segment)
        op = hover_operating_point(record, t0, t1, origin=origin)
        record.metadata["operating_point_source"] = f"mean of hover segment [{t0:g}, {t1:g}) s"
    elif operating_point is not None:
        if isinstance(operating_point, OperatingPoint):
            op_in, op_out = operating_point.inputs, operating_point.outputs
        else:
            op_in, op_out = (np.asarray(v, float) for v in operating_point)
        op = OperatingPoint(
            np.asarray(op_in, float), np.asarray(op_out, float) * scale, layout.in_names, layout.out_names
        )
        for name, col, value in zip(layout.out_names, layout.outputs, op.outputs):
            axis, stop, ends = angle_stop(name, col)
            if abs(value) > stop * (1.0 + END_STOP_MARGIN):
                raise InputError(
                    f"operating_point output {name!r} = {value:.6g} rad is beyond {ends} (with a "
                    f"{100 * END_STOP_MARGIN:g} % margin); give it in units={layout.units!r}, within the stops"
                )
        for name, value in zip(layout.in_names, op.inputs):
            if abs(value) > VOLTAGE_LIMIT:
                raise InputError(
                    f"operating_point input {name!r} = {value:.6g} V is outside the drives' +-{VOLTAGE_LIMIT:g} V"
                )
        record.metadata["operating_point_source"] = "given"
    if op is not None:
        record.metadata["operating_point"] = op.to_dict()
    for note in notes:
        warnings.warn(note, RigDataWarning, stacklevel=3)
    return record


# ------------------------------------------------------------------------------------------------ public
def record_from_csv(
    path: str | os.PathLike[str],
    *,
    time: str,
    inputs: str | Sequence[str],
    outputs: str | Sequence[str],
    units: str | None,
    operating_point: OperatingPoint | Sequence[Sequence[float]] | None = None,
    hover_segment: tuple[float, float] | None = None,
    input_names: Sequence[str] | None = None,
    output_names: Sequence[str] | None = None,
    config: str | None = None,
    time_unit: str = "s",
    resample: bool = False,
) -> Record:
    """Read a rig's text export (CSV) into a :class:`~trms.record.Record` (volts in, radians out).

    Parameters
    ----------
    path : path-like
        Text with a header row of column names and one row per sample: comma, semicolon, tab or
        whitespace delimited (found from the data), UTF-8 or Latin-1 (or UTF-16 with a byte-order mark).
        Lines starting with ``#`` and lines before the header (a title, a units row) are skipped and
        named in a :class:`RigDataWarning`.
    time : str
        Name of the time column (in ``time_unit``).
    inputs, outputs : str or sequence of str
        Names of the voltage columns (V) and of the angle columns, each column once.
    units : {"deg", "rad"}
        Unit of the angle columns; required (a rig's export rarely says). Checked against the rig's
        end stops and speed (:func:`end_stops`, :data:`~trms.rigchecks.MAX_RATE`).
    operating_point : OperatingPoint or (inputs, outputs), optional
        Trim in absolute volts and the output unit ``units``.
    hover_segment : (float, float), optional
        ``(t0, t1)`` in s on the file's time axis: estimate the operating point as the mean over
        ``t0 <= t < t1``. Give this or ``operating_point``; with neither, the record has none and
        identification refuses it until it is detrended.
    input_names, output_names : sequence of str, optional
        Names in the Record (default: the column names), e.g. ``("u1",)`` and ``("pitch",)``.
    config : str, optional
        The rig configuration the data were taken in (``1dof``, ``2dof``, ``yaw``).
    time_unit : {"s", "ms"}
        Unit of the time column.
    resample : bool
        Interpolate linearly onto a uniform grid a record whose timestamps are further than
        :data:`~trms.rigchecks.JITTER_TOLERANCE` of a sample off one (refused otherwise). Jitter within the tolerance is
        snapped to the grid either way.

    Returns
    -------
    Record
        Time from 0 on a uniform grid (s). Metadata: ``sample_time`` (s), ``source``, ``units``,
        ``start_time`` (the file's time of the first sample, s), ``import`` (format, encoding, delimiter),
        ``import_warnings`` (when any), ``operating_point`` and ``operating_point_source`` (``"given"`` or
        ``"mean of hover segment [t0, t1) s"``), ``config``.

    Raises
    ------
    InputError
        One line naming the column or row: a missing, binary or unreadable file, a missing or repeated
        column, a non-numeric or NaN cell, time not increasing, a sample time outside the rig's range
        (time in ms read as s), timestamps off a uniform grid (without ``resample``), angles beyond the end
        stops or faster than the rig (degrees labelled radians), unknown or missing units, a voltage beyond
        :data:`~trms.rigchecks.MAX_INPUT_V`, an operating point beyond the end stops or the drives' +-10 V, a
        hover segment not inside the record, a column named twice in the header.

    ConfigurationError
        An unknown ``config``.

    Warns
    -----
    RigDataWarning
        Lines skipped, timestamps snapped or resampled, a sample time too slow for the pitch mode,
        angle columns whose degrees look like radians, voltages beyond the drives' +-10 V.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "rig.csv"
    >>> _ = p.write_text("t;V;pitch\\n0;2.0;1.0\\n0.05;2.0;1.0\\n0.1;2.5;3.0\\n0.15;2.5;5.0\\n")
    >>> rec = record_from_csv(p, time="t", inputs="V", outputs="pitch", units="deg", hover_segment=(0, 0.1))
    >>> rec.sample_time, rec.operating_point.inputs, round(float(rec.outputs[3, 0]), 6)
    (0.05, array([2.]), 0.087266)
    """
    path = _as_path(path, "path")
    layout = _layout(
        path,
        time,
        inputs,
        outputs,
        units,
        time_unit,
        resample,
        input_names,
        output_names,
        operating_point,
        hover_segment,
        config,
    )
    readable_file(path, "CSV file")
    data, lines, notes, read = read_text_columns(path, layout)
    return _assemble(path, data, lines, notes, read, layout, operating_point, hover_segment, config)


def record_from_mat(
    path: str | os.PathLike[str],
    *,
    time: str,
    inputs: str | Sequence[str],
    outputs: str | Sequence[str],
    units: str | None,
    operating_point: OperatingPoint | Sequence[Sequence[float]] | None = None,
    hover_segment: tuple[float, float] | None = None,
    input_names: Sequence[str] | None = None,
    output_names: Sequence[str] | None = None,
    config: str | None = None,
    time_unit: str = "s",
    resample: bool = False,
) -> Record:
    """Read a rig's MATLAB export (a v4-v7 ``.mat`` file) into a :class:`~trms.record.Record`.

    The columns are named as in :func:`record_from_csv`, in MATLAB's words: a variable (``t``), a field of
    a struct (``data.pitch``, or ``pitch`` alone when one struct has it), an element of a struct array
    (``ScopeData.signals(2).values``), or a column or row of a matrix (``log(:,3)``, ``log(3,:)``; 1-based).
    The checks, units and metadata are :func:`record_from_csv`'s. A v7.3 (HDF5) file is refused with one
    line: save it as v7 in MATLAB.

    Parameters
    ----------
    path : path-like
        The ``.mat`` file.
    time, inputs, outputs, units, operating_point, hover_segment, input_names, output_names, config, time_unit, resample
        As in :func:`record_from_csv`.

    Returns
    -------
    Record

    Raises
    ------
    InputError
        As in :func:`record_from_csv`, naming the variable; complex or text variables, a matrix named
        without its column, columns of different lengths, a v7.3 file.

    Examples
    --------
    >>> import tempfile, pathlib, scipy.io
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "rig.mat"
    >>> scipy.io.savemat(p, {"log": np.column_stack([np.arange(4) * 50.0, np.full(4, 2.0), [0, 10, 20, 30]])})
    >>> rec = record_from_mat(p, time="log(:,1)", inputs="log(:,2)", outputs="log(:,3)", units="deg", time_unit="ms")
    >>> rec.sample_time, len(rec)
    (0.05, 4)
    """
    path = _as_path(path, "path")
    layout = _layout(
        path,
        time,
        inputs,
        outputs,
        units,
        time_unit,
        resample,
        input_names,
        output_names,
        operating_point,
        hover_segment,
        config,
    )
    readable_file(path, "MAT-file")
    data, lines, notes, read = read_mat_columns(path, layout)
    return _assemble(path, data, lines, notes, read, layout, operating_point, hover_segment, config)


def record_from_export(path: str | os.PathLike[str], **columns: Any) -> Record:
    """A rig's export, text or MATLAB: :func:`record_from_mat` for a ``.mat`` name or a MATLAB header,
    else :func:`record_from_csv` (same keyword arguments).

    Examples
    --------
    >>> record_from_export("missing.mat", time="t", inputs="V", outputs="p", units="deg")
    Traceback (most recent call last):
    ...
    trms.errors.InputError: MAT-file 'missing.mat' does not exist
    """
    p = Path(path)
    is_mat = p.suffix.lower() == ".mat"
    if not is_mat and p.is_file():
        with open(p, "rb") as fh:
            is_mat = is_mat_header(fh.read(19))  # the MAT-file's text header
    return record_from_mat(p, **columns) if is_mat else record_from_csv(p, **columns)


def read_inputs(path: str | os.PathLike[str], n_inputs: int) -> np.ndarray:
    """Input samples (V) from a file: ``.npy``, a Record ``.npz`` (its inputs), or text (``.csv``, ``.txt``: one
    row per sample, one column per input, comma or whitespace delimited, an optional header line).

    Parameters
    ----------
    path : path-like
        The file. Text is decoded as a rig's export is (:func:`trms.rigtext.decode_export`: binary data refused).
    n_inputs : int
        Columns expected (a single column may be a flat array).

    Returns
    -------
    ndarray, shape (N, n_inputs)
        At least one row, every value finite and within :data:`~trms.rigchecks.MAX_INPUT_V`.

    Raises
    ------
    InputError
        One line naming the file: missing, not numbers (Python objects in an ``.npy`` are never loaded),
        the wrong number of columns, no rows, or a value beyond :data:`~trms.rigchecks.MAX_INPUT_V`.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "volts.csv"
    >>> _ = p.write_text("u1,u2\\n2.0,-1.0\\n2.5,-1.0\\n")
    >>> read_inputs(p, 2)
    array([[ 2. , -1. ],
           [ 2.5, -1. ]])
    """
    p = readable_file(path, "input file")
    if p.suffix == ".npz":
        data = Record.load(p).inputs
    elif p.suffix == ".npy":
        try:
            data = np.load(p, allow_pickle=False)
        except ValueError as exc:
            if "allow_pickle" not in str(exc):
                raise InputError(f"input file {str(path)!r} is not a numpy array file: {exc}") from None
            raise InputError(
                f"input file {str(path)!r} holds Python objects, which are never loaded (they could run code); "
                "allowed: an .npy of numbers (np.save of a float array)"
            ) from None
    else:
        text, _ = decode_export(p.read_bytes(), p)  # refuses binary data in one line; UTF-8, else Latin-1
        lines = [ln for ln in text.splitlines() if ln.strip()]
        try:
            float(lines[0].replace(",", " ").split()[0])
        except (ValueError, IndexError):
            lines = lines[1:]
        try:
            data = np.array([[float(x) for x in ln.replace(",", " ").split()] for ln in lines])
        except ValueError as exc:
            raise InputError(f"input file {str(path)!r} holds a non-numeric value: {exc}") from exc
    label = f"inputs in {str(path)!r} (one column per input, {n_inputs} expected)"
    arr = as_finite_array(label, data)
    if arr.ndim == 1 and n_inputs == 1:
        arr = arr[:, None]
    arr = as_finite_array(label, arr, (None, n_inputs))
    worst = float(np.max(np.abs(arr), initial=0.0))
    if worst > MAX_INPUT_V:
        raise InputError(
            f"{label}: {worst:.6g} V is beyond the plausible +-{MAX_INPUT_V:g} V of a motor voltage "
            "(the drives saturate at +-10 V): is the file in volts?"
        )
    if arr.shape[0] == 0:
        raise InputError(f"input file {str(path)!r} holds no samples; allowed: at least 1 row")
    return arr


def load_record(path: str | os.PathLike[str]) -> Record:
    """A saved Record (:meth:`Record.load <trms.record.Record.load>`), with a warning (one line) when its angles
    pass the rig's end stops by more than :data:`~trms.rigchecks.END_STOP_MARGIN` (:func:`beyond_end_stops`).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "far.npz"
    >>> _ = Record(np.arange(3) * 0.1, np.zeros(3), [0.0, 0.5, 4.0], ("u1",), ("pitch",)).save(p)
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     rec = load_record(p)
    >>> len(rec), "beyond the rig's end stops" in str(caught[0].message)
    (3, True)
    """
    rec = Record.load(path)
    beyond = beyond_end_stops(rec)
    if beyond:
        warnings.warn(
            f"record {str(path)!r}: {beyond}, beyond the rig's end stops: no rig moves there (angles not in rad?)",
            stacklevel=2,
        )
    return rec
