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
* timestamps on a uniform grid: jitter up to :data:`JITTER_TOLERANCE` of the sample time is snapped to
  the grid, anything beyond is refused unless ``resample`` asks for linear interpolation onto one;
* angles that fit the rig: within the end stops of the model's pitch and yaw joints (:func:`end_stops`,
  with :data:`END_STOP_MARGIN`) and no faster than :data:`MAX_RATE` -- degrees labelled radians are
  refused, radians labelled degrees are warned about.

Angles are converted to radians and the operating point stored: given by the user, or estimated as the
mean of a stated hover segment ``[t0, t1)``, and the metadata says which (``operating_point_source``).
Everything the reader did to the data (lines skipped, timestamps snapped, samples resampled) is said in
one line each as a :class:`RigDataWarning` and kept in the metadata (``import_warnings``). Nothing is
written when a file is refused.
"""

from __future__ import annotations

import argparse
import csv
import os
import re
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from trms.errors import InputError, as_finite_array, check_choice, short_repr
from trms.record import OperatingPoint, Record
from trms import reference
from trms.reference import EQ_3_11_MODE, SAMPLE_TIME_RANGE, VOLTAGE_LIMIT

__all__ = [
    "decode_export",
    "ANGLE_UNITS",
    "TIME_UNITS",
    "JITTER_TOLERANCE",
    "END_STOP_MARGIN",
    "MAX_RATE",
    "MAX_INPUT_V",
    "RigDataWarning",
    "add_csv_arguments",
    "beyond_end_stops",
    "end_stops",
    "hover_operating_point",
    "load_records",
    "record_from_csv",
    "record_from_export",
    "record_from_mat",
]

#: Angle units a rig's export may use, and their factor to radians.
ANGLE_UNITS = {"rad": 1.0, "deg": np.pi / 180.0}
#: Time units a rig's export may use, and their factor to seconds.
TIME_UNITS = {"s": 1.0, "ms": 1e-3}
#: Largest distance of a timestamp from the record's uniform grid that is snapped to it, as a fraction
#: of the sample time (logger jitter); beyond it the record is refused unless it is resampled.
JITTER_TOLERANCE = 0.05
#: How far an angle may read beyond its end stop, as a fraction of the stop: an encoder's zero a little
#: off the model's, the beam pressing into the rubber of the stop.
END_STOP_MARGIN = 0.2
#: Fastest each axis can move (rad/s), about twice the fastest the twin moves under +-10 V square waves on
#: both rotors (periods 0.5-12 s, 1-DOF, 2-DOF and yaw rigs, a 0.01 s sample time: pitch 12.7 rad/s, yaw
#: 19.6 rad/s, bouncing off the stops). An angle that changes faster between two samples is not that axis
#: in the stated unit.
MAX_RATE = {"pitch": 26.0, "yaw": 40.0}
#: Largest motor voltage (V) an export may hold: ten times the drives' +-10 V. Beyond it the column is not a
#: voltage in V (a raw count, another unit); between the two the drives saturated (a note says so).
MAX_INPUT_V = 10.0 * VOLTAGE_LIMIT
#: Relative spread of the timestamps below which they are on the grid already (printed rounding).
_UNIFORM_TOL = 1e-3
#: Bytes that never occur in a text export (control characters other than tab, newlines, form feed, ^Z).
_BINARY = re.compile(rb"[\x00-\x08\x0e-\x19\x1b-\x1f\x7f]")
#: Candidate delimiters, in order of preference on a tie; ``None`` is a run of whitespace.
_DELIMITERS: tuple[str | None, ...] = (",", ";", "\t", None)
_DELIMITER_NAMES = {",": "comma", ";": "semicolon", "\t": "tab", None: "whitespace"}
#: The first bytes of MATLAB v5/v7 and v7.3 MAT-files, and the HDF5 signature (at byte 512 of a v7.3 file).
_MAT_MAGIC = (b"MATLAB 5.0 MAT-file", b"MATLAB 7.3 MAT-file")
_HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"
#: A trailing MATLAB matrix index of a .mat column: ``NAME(:,K)`` or ``NAME(K,:)`` (1-based).
_MATRIX_INDEX = re.compile(r"^(?P<base>.+?)\(\s*(?P<row>:|\d+)\s*,\s*(?P<col>:|\d+)\s*\)$")
_PART = re.compile(r"^(?P<name>[A-Za-z]\w*)(?:\(\s*(?P<index>\d+)\s*\))?$")


class RigDataWarning(UserWarning):
    """What the reader did to a rig's export (lines skipped, timestamps snapped or resampled), or a doubt
    about it (angles that look like radians labelled degrees): one line, also kept in the Record's
    ``import_warnings`` metadata."""


@dataclass(frozen=True)
class _Layout:
    """The column options of an export (the same for text and .mat files)."""

    time: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    units: str
    time_unit: str
    resample: bool
    in_names: tuple[str, ...]
    out_names: tuple[str, ...]

    @property
    def wanted(self) -> tuple[str, ...]:
        return (self.time, *self.inputs, *self.outputs)


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
) -> _Layout:
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
    return _Layout(time, ins, outs, units, time_unit, bool(resample), in_names, out_names)


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


def beyond_end_stops(record: Record, margin: float = END_STOP_MARGIN) -> str | None:
    """Which of a record's angle outputs pass the rig's end stops (:func:`end_stops`), in one phrase, or ``None``.

    Parameters
    ----------
    record : Record
        Its outputs named for their axis (``pitch``, ``yaw``; others are not checked), in rad.
    margin : float
        Fraction of each stop an angle may read beyond it (:data:`END_STOP_MARGIN` for measured data, 0 for a
        model).

    Returns
    -------
    str or None
        E.g. ``"pitch reaches -13.2 rad (end stops +-1.1 rad)"``; ``None`` when every angle is within.

    Examples
    --------
    >>> r = Record(np.arange(3) * 0.1, np.zeros(3), [0.0, 0.5, 4.0], ("u1",), ("pitch",))
    >>> beyond_end_stops(r)
    'pitch reaches 4 rad (end stops +-1.1 rad)'
    """
    stops, parts = end_stops(), []
    for j, name in enumerate(record.output_names):
        y = record.outputs[:, j]
        if name not in stops or not np.isfinite(y).any():
            continue
        i = int(np.nanargmax(np.abs(y)))
        if abs(y[i]) > stops[name] * (1.0 + margin):
            parts.append(f"{name} reaches {y[i]:.3g} rad (end stops +-{stops[name]:g} rad)")
    return ", ".join(parts) or None


def hover_operating_point(record: Record, t0: float, t1: float) -> OperatingPoint:
    """The operating point as the mean inputs and outputs over the half-open segment ``t0 <= t < t1`` (s).

    Parameters
    ----------
    record : Record
    t0, t1 : float
        The hover segment ``[t0, t1)`` (s) on the record's time axis, holding at least 2 samples; the
        sample at ``t1`` is not in it (it is often the first excited one). It must lie inside the record
        (from its first sample to the end of its last, with half a sample of slack): a segment partly outside
        is refused, not cut to the overlap.

    Returns
    -------
    OperatingPoint

    Examples
    --------
    >>> r = Record(np.arange(5) * 0.1, [1.0, 1.0, 3.0, 3.0, 3.0], np.zeros(5), ("u1",), ("pitch",))
    >>> hover_operating_point(r, 0.0, 0.2).inputs
    array([1.])
    """
    t = record.time
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
def decode_export(raw: bytes, path: Path) -> tuple[str, str]:
    """The text of an export and its encoding (UTF-16 with a byte-order mark, UTF-8, else Latin-1).

    Raises
    ------
    InputError
        A zip archive (a saved Record), a MATLAB file, or binary data, in one line naming the file.

    Examples
    --------
    >>> decode_export("t,pitch [°]".encode("latin-1"), Path("rig.csv"))
    ('t,pitch [°]', 'latin-1')
    """
    if raw.startswith(b"PK\x03\x04"):
        raise InputError(
            f"{str(path)!r} is a zip archive (a saved Record .npz?), not a CSV export; "
            "a saved Record needs its .npz name, a rig's export is text (.csv) or MATLAB (.mat)"
        )
    if raw.startswith(_MAT_MAGIC) or raw[512:520] == _HDF5_MAGIC:
        raise InputError(f"{str(path)!r} is a MATLAB file, not a CSV export; give it its .mat name")
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        try:
            return raw.decode("utf-16"), "utf-16"
        except UnicodeDecodeError:
            pass
    bad = _BINARY.search(raw)
    if bad is not None:
        raise InputError(
            f"{str(path)!r} is not a text export: byte 0x{raw[bad.start()]:02x} at offset {bad.start()} is "
            "binary data; expected a CSV with a header row and one row of numbers per sample"
        )
    try:
        return raw.decode("utf-8-sig"), "utf-8"
    except UnicodeDecodeError:
        return raw.decode("latin-1"), "latin-1"


def _fields(line: str, delimiter: str | None) -> list[str]:
    """The fields of a line, trailing empty ones (a delimiter at the end of the line) dropped."""
    cells = line.split() if delimiter is None else line.split(delimiter)
    while cells and not cells[-1].strip():
        cells.pop()
    return cells


def _is_number(cell: str, delimiter: str | None) -> bool:
    try:
        float(_number_text(cell, delimiter))
    except ValueError:
        return False
    return True


def _number_text(cell: str, delimiter: str | None) -> str:
    """A cell as Python reads numbers: stripped, a decimal comma read as a point where commas do not delimit."""
    cell = cell.strip().strip('"').strip()
    return cell.replace(",", ".") if delimiter != "," else cell


def _sniff(content: list[tuple[int, str]]) -> tuple[str | None, int | None]:
    """The delimiter and the index (into ``content``) of the first data row: the delimiter that gives the
    longest run of rows of the same number (at least 2) of numeric fields."""
    best: tuple[tuple[int, int], str | None, int | None] = ((-1, -1), ",", None)
    head = content[:400]
    for d in _DELIMITERS:
        start = nf = None
        for i, (_, text) in enumerate(head):
            cells = _fields(text, d)
            if len(cells) >= 2 and all(_is_number(c, d) for c in cells):
                start, nf = i, len(cells)
                break
        if start is None or nf is None:
            continue
        run = 1
        for _, text in head[start + 1 : start + 50]:
            cells = _fields(text, d)
            if len(cells) != nf or not all(_is_number(c, d) for c in cells):
                break
            run += 1
        if (run, nf) > best[0]:
            best = ((run, nf), d, start)
    if best[2] is None and content:  # no data row: the delimiter that splits the header most
        counts = [len(_fields(content[0][1], d)) for d in _DELIMITERS]
        return _DELIMITERS[int(np.argmax(counts))], None
    return best[1], best[2]


def _parse(lines: list[str], delimiter: str | None, first_line: list[int], path: Path) -> list[list[str]]:
    """Split ``lines`` into fields (quoted fields allowed); a field beyond the csv module's limit is one line."""
    if delimiter is None:
        return [[c.strip('"') for c in ln.split()] for ln in lines]
    reader = csv.reader(lines, delimiter=delimiter)
    try:
        return [row for row in reader]
    except csv.Error as exc:
        line = first_line[min(reader.line_num, len(first_line)) - 1] if first_line else 1
        raise InputError(
            f"line {line} of {str(path)!r} has a field longer than {csv.field_size_limit()} characters ({exc}); "
            "a rig's export holds column names and numbers"
        ) from None


def _read_text(path: Path, layout: _Layout) -> tuple[np.ndarray, list[int], list[str], dict[str, Any]]:
    """The wanted columns of a text export as floats, the file line of each row, the notes, and what was read."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"CSV file {str(path)!r} cannot be read: {exc.strerror or exc}") from None
    text, encoding = decode_export(raw, path)
    content: list[tuple[int, str]] = []
    comments: list[int] = []
    for no, ln in enumerate(text.splitlines(), start=1):
        if not ln.strip():
            continue
        if ln.lstrip().startswith("#"):
            comments.append(no)
        else:
            content.append((no, ln))
    if not content:
        raise InputError(f"CSV file {str(path)!r} is empty")
    delimiter, start = _sniff(content)
    before = content if start is None else content[:start]
    if not before:
        raise InputError(
            f"{str(path)!r} has no header row: line {content[0][0]} is numbers already; the first line must name "
            "the columns (time, inputs, outputs)"
        )
    headers = _parse([t for _, t in before], delimiter, [n for n, _ in before], path)
    named = [i for i, h in enumerate(headers) if layout.time in (c.strip() for c in h)]
    h = named[-1] if named else len(before) - 1
    header = [c.strip() for c in headers[h]]
    notes = []
    skipped = [(n, t) for i, (n, t) in enumerate(before) if i != h]
    if skipped or comments:
        parts = [f"line {n} {_short(t)!r}" for n, t in skipped[:3]] + (["..."] if len(skipped) > 3 else [])
        if comments:
            parts.append(f"{len(comments)} comment line{'s' * (len(comments) > 1)} (#) from line {comments[0]}")
        notes.append(f"{str(path)!r}: skipped {', '.join(parts)} (its header is line {before[h][0]})")
    for col in layout.wanted:
        if col not in header:
            raise InputError(f"column {col!r} is missing from {str(path)!r}; it has {', '.join(header)}")
        at = [i + 1 for i, c in enumerate(header) if c == col]
        if len(at) > 1:
            raise InputError(
                f"column {col!r} is ambiguous: the header of {str(path)!r} has it twice (columns {at[0]} and "
                f"{at[1]}); rename one of them"
            )
    data_lines = [] if start is None else content[start:]
    rows = _parse([t for _, t in data_lines], delimiter, [n for n, _ in data_lines], path)
    line_of = [n for n, _ in data_lines]
    data = np.empty((len(rows), len(layout.wanted)))
    for j, col in enumerate(layout.wanted):
        k = header.index(col)
        cells = [_number_text(r[k], delimiter) if k < len(r) else "" for r in rows]
        try:
            data[:, j] = np.asarray(cells, dtype=float)
        except ValueError:
            i = next(i for i, c in enumerate(cells) if not _is_number(c, delimiter))
            raise InputError(f"row {line_of[i]}, column {col!r}: {cells[i]!r} is not a number") from None
        bad = np.flatnonzero(~np.isfinite(data[:, j]))
        if bad.size:
            raise InputError(f"row {line_of[bad[0]]}, column {col!r}: {cells[bad[0]]!r} is not a finite number")
    read = {"format": "text", "encoding": encoding, "delimiter": _DELIMITER_NAMES[delimiter]}
    return data, line_of, notes, read


def _short(text: str, n: int = 40) -> str:
    text = " ".join(text.split())
    return text if len(text) <= n else text[: n - 3] + "..."


# -------------------------------------------------------------------------------------------- .mat files
def _mat_variables(path: Path) -> dict[str, Any]:
    """The variables of a MATLAB v4-v7 file (structs as dicts, struct arrays as lists)."""
    import scipy.io

    try:
        with open(path, "rb") as fh:
            head = fh.read(520)
    except OSError as exc:
        raise InputError(f"MAT-file {str(path)!r} cannot be read: {exc.strerror or exc}") from None
    v73 = (
        f"{str(path)!r} is a MATLAB v7.3 (HDF5) MAT-file, which trms cannot read; save it as v7 in MATLAB "
        f"(save('{path.name}', ..., '-v7')) and import that"
    )
    if head.startswith(_MAT_MAGIC[1]) or head[512:520] == _HDF5_MAGIC:
        raise InputError(v73)
    if head.startswith(b"PK\x03\x04"):
        raise InputError(f"{str(path)!r} is a zip archive (a saved Record .npz?), not a MAT-file")
    try:
        mat = scipy.io.loadmat(path, simplify_cells=True)
    except NotImplementedError:
        raise InputError(v73) from None
    except Exception as exc:  # noqa: BLE001 -- scipy raises many kinds on a broken file; each becomes one line
        text = " ".join(str(exc).split()) or type(exc).__name__
        raise InputError(f"{str(path)!r} is not a MATLAB MAT-file trms can read ({text})") from None
    return {k: v for k, v in mat.items() if not k.startswith("__")}


def _describe(variables: dict[str, Any]) -> str:
    out = []
    for k, v in variables.items():
        if isinstance(v, dict):
            out.append(f"{k} (struct: {', '.join(v)})")
        elif isinstance(v, str):
            out.append(f"{k} (text)")
        elif isinstance(v, list):
            out.append(f"{k} (struct array of {len(v)})")
        else:
            shape = np.shape(v)
            out.append(f"{k} ({'x'.join(str(s) for s in shape) or 'scalar'})")
    return ", ".join(out) or "no variables"


def _mat_column(variables: dict[str, Any], spec: str, path: Path) -> np.ndarray:
    """One column of a .mat file named ``spec``: ``name``, ``struct.field``, ``s(2).values``, ``m(:,3)``."""
    where = f"{str(path)!r}"
    m = _MATRIX_INDEX.match(spec.strip())
    base: str = m["base"] if m else spec.strip()
    row: str = m["row"] if m else ""
    col: str = m["col"] if m else ""
    value: Any = variables
    parts = base.split(".")
    for depth, part in enumerate(parts):
        p = _PART.match(part)
        if p is None:
            raise InputError(f"{spec!r} is not a MAT-file variable name (e.g. t, data.pitch, log(:,2)) in {where}")
        if not isinstance(value, dict) or p["name"] not in value:
            if depth == 0 and len(parts) == 1:  # a field of a top-level struct, named alone
                owners = [k for k, v in variables.items() if isinstance(v, dict) and p["name"] in v]
                if len(owners) == 1:
                    value = variables[owners[0]]
                elif len(owners) > 1:
                    raise InputError(
                        f"{spec!r} is a field of several structs in {where} ({', '.join(owners)}); "
                        f"name one, e.g. {owners[0] + '.' + spec!r}"
                    )
            if not isinstance(value, dict) or p["name"] not in value:
                raise InputError(f"variable {spec!r} is missing from {where}; it has {_describe(variables)}")
        value = value[p["name"]]
        if p["index"] is not None:
            items = value if isinstance(value, list) else None
            k = int(p["index"])
            if items is None or not 1 <= k <= len(items):
                n = len(items) if items is not None else 1
                raise InputError(f"{spec!r}: {part!r} asks for element {k} of {n} in {where} (MATLAB counts from 1)")
            value = items[k - 1]
    if isinstance(value, dict):
        fields = list(value)
        raise InputError(
            f"variable {spec!r} of {where} is a struct (fields {', '.join(fields)}); name one of its fields, "
            f"e.g. {base + '.' + (fields[0] if fields else 'x')!r}"
        )
    if isinstance(value, list):
        raise InputError(
            f"variable {spec!r} of {where} is a struct array of {len(value)}; name an element, e.g. {base + '(1)'!r}"
        )
    arr = np.asarray(value)
    if m is not None:
        if arr.ndim != 2:
            raise InputError(f"variable {base!r} of {where} has shape {arr.shape}, not a matrix; {spec!r} needs one")
        rows, cols = arr.shape
        if row == ":" and col != ":" and 1 <= int(col) <= cols:
            arr = arr[:, int(col) - 1]
        elif col == ":" and row != ":" and 1 <= int(row) <= rows:
            arr = arr[int(row) - 1]
        else:
            raise InputError(
                f"{spec!r} is not a column of {base!r}, a {rows}x{cols} matrix of {where}: say {base}(:,K) with "
                f"K in 1..{cols} or {base}(K,:) with K in 1..{rows}"
            )
    arr = as_finite_array(f"variable {spec!r} of {where}", arr)
    if arr.ndim == 2 and 1 in arr.shape:
        arr = arr.ravel()
    if arr.ndim != 1:
        shape = "x".join(str(s) for s in arr.shape) or "one number"
        raise InputError(
            f"variable {spec!r} of {where} is {shape}, not one series; name one column, e.g. {base + '(:,1)'!r} "
            "(MATLAB counts from 1)"
        )
    return arr


def _read_mat(path: Path, layout: _Layout) -> tuple[np.ndarray, None, list[str], dict[str, Any]]:
    variables = _mat_variables(path)
    columns = [_mat_column(variables, spec, path) for spec in layout.wanted]
    lengths = {spec: c.size for spec, c in zip(layout.wanted, columns)}
    if len(set(lengths.values())) > 1:
        raise InputError(
            f"the columns of {str(path)!r} differ in length: "
            + ", ".join(f"{s!r} {n}" for s, n in lengths.items())
            + "; each needs one value per sample"
        )
    return np.column_stack(columns), None, [], {"format": "mat"}


# ----------------------------------------------------------------------------------------------- checks
def _grid(t: np.ndarray, ts: float) -> tuple[float, np.ndarray]:
    """The origin of the uniform grid of step ``ts`` (s) nearest to ``t`` and each timestamp's distance from it."""
    k = np.arange(t.size)
    origin = float(np.mean(t - k * ts))
    return origin, t - (origin + k * ts)


def _check_sample_time(ts: float, layout: _Layout, where: str) -> str | None:
    """Refuse a sample time outside the rig's kernel; a note for one too slow to see the pitch mode."""
    lo, hi, _ = SAMPLE_TIME_RANGE
    other = "ms" if layout.time_unit == "s" else "s"
    alt = ts / TIME_UNITS["ms"] if other == "s" else ts * TIME_UNITS["ms"]
    hint = (
        f": is the time column in {'milliseconds' if other == 'ms' else 'seconds'}? say time_unit={other!r} "
        f"(--time-unit {other})"
        if lo <= alt <= hi
        else ""
    )
    if not lo <= ts <= hi:
        raise InputError(
            f"column {layout.time!r}{where}: sample time {ts:.6g} s (median interval, time in {layout.time_unit}) is "
            f"outside the rig's range [{lo:g} s, {hi:g} s]{hint}"
        )
    nyquist = 1.0 / (2.0 * EQ_3_11_MODE[0])
    if ts > nyquist:
        return (
            f"column {layout.time!r}{where}: sample time {ts:.6g} s cannot resolve the rig's {EQ_3_11_MODE[0]:g} Hz "
            f"pitch mode (needs < {nyquist:.3g} s){hint or '; check the time column'}"
        )
    return None


def _uniform(
    data: np.ndarray, layout: _Layout, row: Callable[[int], str], where: str
) -> tuple[np.ndarray, float, float, list[str]]:
    """The data on a uniform time grid: ``(data, sample time s, origin s, notes)``; the time column in s."""
    t = data[:, 0]
    dt = np.diff(t)
    ts_med = float(np.median(dt))
    k = np.arange(t.size)
    slope = float(np.polyfit(k, t, 1)[0])
    res = SAMPLE_TIME_RANGE[2]
    on_kernel = round(slope / res) * res
    candidates = [c for c in (on_kernel, slope) if c > 0]
    for ts in candidates:
        origin, dev = _grid(t, ts)
        worst = float(np.max(np.abs(dev)))
        if worst <= JITTER_TOLERANCE * ts:
            break
    notes = []
    if worst > JITTER_TOLERANCE * ts:
        off = np.abs(dt - ts_med) > JITTER_TOLERANCE * ts_med
        i = int(np.argmax(off)) if off.any() else max(int(np.argmax(np.abs(dev))) - 1, 0)
        if not layout.resample:
            raise InputError(
                f"{row(i + 1)}, column {layout.time!r}: sample interval {dt[i]:.6g} s differs from the record's "
                f"{ts_med:.6g} s (timestamps up to {100 * worst / ts:.3g} % of a sample off a uniform grid, beyond the "
                f"{100 * JITTER_TOLERANCE:g} % jitter tolerance); resample=True (--resample) interpolates the record "
                "linearly onto a uniform grid"
            )
        ts = ts_med
        if abs(round(ts / res) * res - ts) <= _UNIFORM_TOL * ts:
            ts = round(ts / res) * res
        n = int(np.floor((t[-1] - t[0]) / ts + 1e-9)) + 1
        origin = float(t[0])
        grid = origin + np.arange(n) * ts
        out = np.column_stack([grid] + [np.interp(grid, t, data[:, j]) for j in range(1, data.shape[1])])
        notes.append(
            f"column {layout.time!r}{where}: timestamps up to {100 * worst / ts:.3g} % of a sample off a uniform grid "
            f"(beyond the {100 * JITTER_TOLERANCE:g} % jitter tolerance; intervals {dt.min():.6g} .. "
            f"{dt.max():.6g} s); "
            f"resampled by linear interpolation onto {ts:.6g} s: {t.size} rows -> {n} samples"
        )
        return out, ts, origin, notes
    if worst > _UNIFORM_TOL * ts:
        notes.append(
            f"column {layout.time!r}{where}: timestamps up to {100 * worst / ts:.3g} % of the {ts:.6g} s sample time "
            f"off a uniform grid (jitter tolerance {100 * JITTER_TOLERANCE:g} %); snapped to the grid"
        )
    out = data.copy()
    out[:, 0] = origin + k * ts
    return out, ts, origin, notes


def _axis(name: str, column: str) -> str | None:
    for text in (name, column):
        low = text.lower()
        hits = [a for a in ("pitch", "yaw") if a in low]
        if len(hits) == 1:
            return hits[0]
    return None


def _stop(name: str, column: str) -> tuple[str | None, float, str]:
    """The axis of an angle channel (or None), its end stop (rad; the widest when the axis is unknown), in words."""
    stops = end_stops()
    axis = _axis(name, column)
    stop = stops[axis] if axis else max(stops.values())
    return axis, stop, f"{axis}'s end stops +-{stop:g} rad" if axis else f"the rig's widest end stops +-{stop:g} rad"


def _check_inputs(u: np.ndarray, layout: _Layout, row: Callable[[int], str], where: str) -> list[str]:
    """Refuse a voltage beyond :data:`MAX_INPUT_V`; a note for one beyond the drives' saturation."""
    notes = []
    for j, col in enumerate(layout.inputs):
        i = int(np.argmax(np.abs(u[:, j])))
        if abs(u[i, j]) > MAX_INPUT_V:
            raise InputError(
                f"{row(i)}, column {col!r}: {u[i, j]:.6g} V is beyond the plausible +-{MAX_INPUT_V:g} V of a motor "
                f"voltage (the drives saturate at +-{VOLTAGE_LIMIT:g} V): is the column in volts?"
            )
        if abs(u[i, j]) > VOLTAGE_LIMIT:
            notes.append(
                f"column {col!r}{where}: voltage reaches {u[i, j]:.4g} V, beyond the drives' +-{VOLTAGE_LIMIT:g} V: "
                "the rig applied at most that"
            )
    return notes


def _check_angles(y_raw: np.ndarray, ts: float, layout: _Layout, row: Callable[[int], str], where: str) -> list[str]:
    """Refuse angles beyond the end stops or faster than the rig; a note for radians that look labelled degrees."""
    notes = []
    units = layout.units
    other = "deg" if units == "rad" else "rad"
    for j, (col, name) in enumerate(zip(layout.outputs, layout.out_names)):
        axis, stop, ends = _stop(name, col)
        max_rate = MAX_RATE[axis] if axis else max(MAX_RATE.values())
        what = axis or "an angle"
        limit = stop * (1.0 + END_STOP_MARGIN)
        raw = y_raw[:, j]
        y = raw * ANGLE_UNITS[units]
        i = int(np.argmax(np.abs(y)))
        if abs(y[i]) > limit:
            alt = float(np.max(np.abs(raw))) * ANGLE_UNITS[other]
            hint = (
                f"; as {other} it reaches {alt:.3g} rad: say units={other!r} (--units {other})"
                if alt <= limit
                else f"; in {other} too ({alt:.3g} rad): check the column"
            )
            raise InputError(
                f"{row(i)}, column {col!r}: {what} {raw[i]:.6g} {units}"
                + ("" if units == "rad" else f" ({y[i]:.3g} rad)")
                + f" is beyond {ends} "
                f"(with a {100 * END_STOP_MARGIN:g} % margin){hint}"
            )
        rate = np.abs(np.diff(y)) / ts
        if rate.size and rate.max() > max_rate:
            i = int(np.argmax(rate > max_rate))
            alt = float(rate.max()) / ANGLE_UNITS[units] * ANGLE_UNITS[other]
            hint = (
                f"; as {other} it would be {alt:.3g} rad/s: say units={other!r} (--units {other})"
                if alt <= max_rate
                else ""
            )
            raise InputError(
                f"{row(i + 1)}, column {col!r}: {what} moves {rate[i] * ts:.3g} rad in one sample ({ts:.6g} s), "
                f"{rate[i]:.3g} rad/s; the rig's {axis or 'fastest axis'} moves at most about {max_rate:g} rad/s{hint}"
            )
        as_rad_possible = np.max(np.abs(raw)) <= stop and np.max(np.abs(np.diff(raw))) / ts <= max_rate
        if units == "deg" and np.ptp(raw) > 0 and as_rad_possible:
            notes.append(
                f"column {col!r}{where}: {what} reads {raw.min():.4g} .. {raw.max():.4g} deg, a motion of only "
                f"{np.ptp(raw):.3g} deg; the numbers fit {ends} and speed as radians: if the column is in radians, say "
                "units='rad' (--units rad)"
            )
    return notes


def _assemble(
    path: Path,
    data: np.ndarray,
    lines: list[int] | None,
    notes: list[str],
    read: dict[str, Any],
    layout: _Layout,
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
    slow = _check_sample_time(float(np.median(dt)), layout, where)
    data, ts, origin, grid_notes = _uniform(data, layout, row, where)
    if grid_notes and lines is not None and data.shape[0] != n:
        lines = None  # resampled: rows are samples now
    n_in = len(layout.inputs)
    input_notes = _check_inputs(data[:, 1 : 1 + n_in], layout, row, where)
    angle_notes = _check_angles(data[:, 1 + n_in :], ts, layout, row, where)
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
        op = hover_operating_point(record, t0 - origin, t1 - origin)
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
            axis, stop, ends = _stop(name, col)
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
        end stops and speed (:func:`end_stops`, :data:`MAX_RATE`).
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
        :data:`JITTER_TOLERANCE` of a sample off one (refused otherwise). Jitter within the tolerance is
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
        :data:`MAX_INPUT_V`, an operating point beyond the end stops or the drives' +-10 V, a hover segment not
        inside the record, a column named twice in the header.

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
    if not path.is_file():
        raise InputError(f"CSV file {str(path)!r} does not exist")
    data, lines, notes, read = _read_text(path, layout)
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
    if not path.is_file():
        raise InputError(f"MAT-file {str(path)!r} does not exist")
    data, lines, notes, read = _read_mat(path, layout)
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
            is_mat = fh.read(len(_MAT_MAGIC[0])) in _MAT_MAGIC
    return record_from_mat(p, **columns) if is_mat else record_from_csv(p, **columns)


def add_csv_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options that describe a rig's export layout (``--time``, ``--inputs``, ...) to ``parser``."""
    g = parser.add_argument_group("rig export layout (for .csv/.txt and .mat files)")
    g.add_argument(
        "--time", default="time", help="time column (a .mat variable, struct field or log(:,1)); default: time"
    )
    g.add_argument("--time-unit", choices=list(TIME_UNITS), default="s", help="unit of the time column (default s)")
    g.add_argument("--inputs", nargs="+", metavar="COLUMN", help="voltage columns (V), in input order u1, u2")
    g.add_argument("--outputs", nargs="+", metavar="COLUMN", help="angle columns, in output order (pitch, yaw)")
    g.add_argument("--units", choices=list(ANGLE_UNITS), help="unit of the angle columns (required for an export)")
    g.add_argument(
        "--hover",
        metavar="T0:T1",
        help="estimate the operating point as the mean over T0 <= t < T1 (s; the sample at T1 is not in it)",
    )
    g.add_argument(
        "--resample",
        action="store_true",
        help=f"interpolate timestamps further than {100 * JITTER_TOLERANCE:g} %% of a sample off a uniform grid "
        "linearly onto one (refused otherwise; smaller jitter is snapped)",
    )
    g.add_argument(
        "--config",
        dest="rig_config",
        choices=["1dof", "2dof", "yaw"],
        help="the rig configuration the data were taken in",
    )


def _segment(text: str) -> tuple[float, float]:
    try:
        t0, t1 = (float(x) for x in text.split(":"))
    except ValueError:
        raise InputError(f"--hover must be T0:T1 in s, e.g. 0:10, got {text!r}") from None
    return t0, t1


def load_records(paths: Sequence[str], args: argparse.Namespace, *, saved: bool = True) -> list[Record]:
    """Records from ``.npz`` files (as saved) and rig exports (``.mat``, or text such as ``.csv``), read with
    the layout options in ``args``.

    Columns become the configuration's channel names (``u1``, ``u2``; ``pitch``, ``yaw``) when
    ``--config`` is given. With ``saved=False`` a saved Record is refused (``trms import`` reads exports).
    """
    from trms.twin.model import get_configuration

    out = []
    for path in paths:
        if Path(path).suffix.lower() == ".npz":
            if not saved:
                raise InputError(
                    f"{path!r} is a saved Record (.npz) already, not a rig's export; use it as it is "
                    "(e.g. trms identify), or import the rig's .csv or .mat"
                )
            rec = Record.load(path)
            if args.rig_config and rec.metadata.get("config", args.rig_config) != args.rig_config:
                raise InputError(
                    f"record {path!r} was taken in configuration {rec.metadata['config']!r}, not {args.rig_config!r}"
                )
            out.append(rec)
            continue
        if not args.inputs or not args.outputs:
            raise InputError(
                f"{path!r} is a rig's export: name its voltage and angle columns with --inputs and --outputs"
            )
        names: dict[str, Any] = {}
        if args.rig_config:
            cfg = get_configuration(args.rig_config)
            if len(args.inputs) != len(cfg.inputs) or len(args.outputs) != len(cfg.outputs):
                raise InputError(
                    f"configuration {cfg.name!r} has inputs {', '.join(cfg.inputs)} and outputs "
                    f"{', '.join(cfg.outputs)}; got {len(args.inputs)} input and "
                    f"{len(args.outputs)} output columns"
                )
            names = {"input_names": cfg.inputs, "output_names": cfg.outputs}
        out.append(
            record_from_export(
                path,
                time=args.time,
                inputs=args.inputs,
                outputs=args.outputs,
                units=args.units,
                hover_segment=_segment(args.hover) if args.hover else None,
                config=args.rig_config,
                time_unit=getattr(args, "time_unit", "s"),
                resample=getattr(args, "resample", False),
                **names,
            )
        )
    return out
