"""A rig's own recordings in: CSV exports with named columns and units, as :class:`~trms.plant.Record`.

A rig's data logger writes a time column and named columns, angles in degrees or
radians, voltages in volts. :func:`record_from_csv` reads such a file, checks it (every
named column present, every cell a finite number, time increasing with one sample time),
converts angles to radians and stores the operating point: given by the user, or
estimated as the mean of a stated hover segment, and the metadata says which
(``operating_point_source``). Nothing is written when the file is refused.

``Record.from_csv`` is this function.
"""

from __future__ import annotations

import argparse
import csv
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .errors import InputError
from .plant import OperatingPoint, Record

__all__ = ["ANGLE_UNITS", "add_csv_arguments", "hover_operating_point", "load_records", "record_from_csv"]

#: Angle units a rig's export may use, and their factor to radians.
ANGLE_UNITS = {"rad": 1.0, "deg": np.pi / 180.0}
#: Relative spread of the sample intervals accepted as uniform sampling.
_UNIFORM_TOL = 1e-3


def _names(value: str | Sequence[str], what: str) -> tuple[str, ...]:
    names = (value,) if isinstance(value, str) else tuple(value)
    if not names or not all(isinstance(n, str) and n for n in names):
        raise InputError(f"{what} must name at least one column, got {value!r}")
    return names


def hover_operating_point(record: Record, t0: float, t1: float) -> OperatingPoint:
    """The operating point as the mean inputs and outputs over ``t0 <= t <= t1`` (s).

    Parameters
    ----------
    record : Record
    t0, t1 : float
        The hover segment (s), inside the record, holding at least 2 samples.

    Returns
    -------
    OperatingPoint

    Examples
    --------
    >>> r = Record(np.arange(5) * 0.1, np.ones(5), np.zeros(5), ("u1",), ("pitch",))
    >>> hover_operating_point(r, 0.0, 0.2).inputs
    array([1.])
    """
    t = record.time
    if not (np.isfinite(t0) and np.isfinite(t1)) or t1 <= t0:
        raise InputError(f"hover segment ({t0!r}, {t1!r}) s must have t0 < t1")
    sel = (t >= t0 - 1e-9) & (t <= t1 + 1e-9)
    if sel.sum() < 2:
        raise InputError(
            f"hover segment ({t0}, {t1}) s holds {int(sel.sum())} samples of the record "
            f"(time {t[0]:g} .. {t[-1]:g} s); at least 2 are needed"
        )
    return OperatingPoint(
        record.inputs[sel].mean(axis=0), record.outputs[sel].mean(axis=0), record.input_names, record.output_names
    )


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
) -> Record:
    """Read a rig's CSV export into a :class:`~trms.plant.Record` (volts in, radians out).

    Parameters
    ----------
    path : path-like
        CSV with a header row of column names and one row per sample.
    time : str
        Name of the time column (s).
    inputs, outputs : str or sequence of str
        Names of the voltage columns (V) and of the angle columns.
    units : {"deg", "rad"}
        Unit of the angle columns; required (a rig's export rarely says).
    operating_point : OperatingPoint or (inputs, outputs), optional
        Trim in absolute volts and the output unit ``units``.
    hover_segment : (float, float), optional
        ``(t0, t1)`` in s: estimate the operating point as the mean over this segment.
        Give this or ``operating_point``; with neither, the record has none and
        identification refuses it until it is detrended.
    input_names, output_names : sequence of str, optional
        Names in the Record (default: the column names), e.g. ``("u1",)`` and ``("pitch",)``.
    config : str, optional
        The rig configuration the data were taken in (``1dof``, ``2dof``, ``yaw``).

    Returns
    -------
    Record
        Metadata: ``sample_time``, ``source``, ``units``, ``operating_point`` and
        ``operating_point_source`` (``"given"`` or ``"mean of hover segment t0..t1 s"``),
        ``config``.

    Raises
    ------
    InputError
        One line naming the column or row: a missing file or column, a non-numeric or
        NaN cell, time not increasing or not uniformly sampled, unknown or missing units.

    Examples
    --------
    >>> rec = record_from_csv("rig.csv", time="t", inputs="Vmain", outputs="pitch_deg", units="deg",
    ...                       hover_segment=(0, 10), input_names=["u1"], output_names=["pitch"],
    ...                       config="1dof")  # doctest: +SKIP
    """
    path = Path(path)
    if units is None:
        raise InputError(f"units of the angle columns not given for {str(path)!r}; say units='deg' or 'rad' (--units)")
    if units not in ANGLE_UNITS:
        raise InputError(f"unknown angle units {units!r}; allowed: {', '.join(repr(u) for u in ANGLE_UNITS)}")
    ins, outs = _names(inputs, "inputs"), _names(outputs, "outputs")
    in_names = tuple(input_names) if input_names is not None else ins
    out_names = tuple(output_names) if output_names is not None else outs
    if len(in_names) != len(ins) or len(out_names) != len(outs):
        raise InputError(f"input_names/output_names must name each column once: {len(ins)} inputs, {len(outs)} outputs")
    if operating_point is not None and hover_segment is not None:
        raise InputError("give either operating_point or hover_segment, not both")
    if not path.is_file():
        raise InputError(f"CSV file {str(path)!r} does not exist")
    with open(path, newline="") as fh:
        reader = csv.reader(fh)
        try:
            header = [h.strip() for h in next(reader)]
        except StopIteration:
            raise InputError(f"CSV file {str(path)!r} is empty") from None
        rows = [r for r in reader if any(c.strip() for c in r)]
    wanted = (time, *ins, *outs)
    for col in wanted:
        if col not in header:
            raise InputError(f"column {col!r} is missing from {str(path)!r}; it has {', '.join(header)}")
    index = [header.index(c) for c in wanted]
    data = np.empty((len(rows), len(wanted)))
    for i, row in enumerate(rows):
        line = i + 2  # 1-based, after the header
        for j, (col, k) in enumerate(zip(wanted, index)):
            cell = row[k].strip() if k < len(row) else ""
            try:
                v = float(cell)
            except ValueError:
                raise InputError(f"row {line}, column {col!r}: {cell!r} is not a number") from None
            if not np.isfinite(v):
                raise InputError(f"row {line}, column {col!r}: {cell!r} is not a finite number")
            data[i, j] = v
    if len(rows) < 3:
        raise InputError(f"{str(path)!r} has {len(rows)} data rows; at least 3 are needed")
    t = data[:, 0]
    dt = np.diff(t)
    bad = np.flatnonzero(dt <= 0)
    if bad.size:
        raise InputError(
            f"row {bad[0] + 3}, column {time!r}: time {float(t[bad[0] + 1])!r} s does not increase "
            f"(previous {float(t[bad[0]])!r} s)"
        )
    ts = float(np.median(dt))
    off = np.flatnonzero(np.abs(dt - ts) > _UNIFORM_TOL * ts)
    if off.size:
        raise InputError(
            f"row {off[0] + 3}, column {time!r}: sample interval {dt[off[0]]:.6g} s differs from the "
            f"record's {ts:.6g} s (non-uniform sampling; resample the export first)"
        )
    scale = ANGLE_UNITS[units]
    u = data[:, 1 : 1 + len(ins)]
    y = data[:, 1 + len(ins) :] * scale
    meta: dict[str, Any] = {
        "sample_time": round(ts, 9),
        "source": str(path),
        "units": {"inputs": "V", "outputs": units},
        "plant": "rig",
    }
    if config is not None:
        meta["config"] = config
    record = Record(t - t[0], u, y, in_names, out_names, {}, meta)
    op: OperatingPoint | None = None
    if hover_segment is not None:
        t0, t1 = (float(x) for x in hover_segment)
        op = hover_operating_point(record, t0 - t[0], t1 - t[0])
        record.metadata["operating_point_source"] = f"mean of hover segment {t0:g}..{t1:g} s"
    elif operating_point is not None:
        if isinstance(operating_point, OperatingPoint):
            op_in, op_out = operating_point.inputs, operating_point.outputs
        else:
            op_in, op_out = (np.asarray(v, float) for v in operating_point)
        op = OperatingPoint(np.asarray(op_in, float), np.asarray(op_out, float) * scale, in_names, out_names)
        record.metadata["operating_point_source"] = "given"
    if op is not None:
        record.metadata["operating_point"] = op.to_dict()
    return record


def add_csv_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options that describe a rig's CSV layout (``--time``, ``--inputs``, ...) to ``parser``."""
    g = parser.add_argument_group("rig CSV layout (for .csv files)")
    g.add_argument("--time", default="time", help="name of the time column in s (default: time)")
    g.add_argument("--inputs", nargs="+", metavar="COLUMN", help="voltage columns (V), in input order u1, u2")
    g.add_argument("--outputs", nargs="+", metavar="COLUMN", help="angle columns, in output order (pitch, yaw)")
    g.add_argument("--units", choices=list(ANGLE_UNITS), help="unit of the angle columns (required for CSV)")
    g.add_argument("--hover", metavar="T0:T1", help="estimate the operating point as the mean over T0..T1 s")
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


def load_records(paths: Sequence[str], args: argparse.Namespace) -> list[Record]:
    """Records from ``.npz`` files (as saved) and rig ``.csv`` files (read with the CSV options in ``args``).

    CSV columns become the configuration's channel names (``u1``, ``u2``; ``pitch``, ``yaw``)
    when ``--config`` is given.
    """
    from .twin.model import get_configuration

    out = []
    for path in paths:
        if Path(path).suffix.lower() != ".csv":
            rec = Record.load(path)
            if args.rig_config and rec.metadata.get("config", args.rig_config) != args.rig_config:
                raise InputError(
                    f"record {path!r} was taken in configuration {rec.metadata['config']!r}, not {args.rig_config!r}"
                )
            out.append(rec)
            continue
        if not args.inputs or not args.outputs:
            raise InputError(f"{path!r} is a CSV: name its voltage and angle columns with --inputs and --outputs")
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
            record_from_csv(
                path,
                time=args.time,
                inputs=args.inputs,
                outputs=args.outputs,
                units=args.units,
                hover_segment=_segment(args.hover) if args.hover else None,
                config=args.rig_config,
                **names,
            )
        )
    return out
