"""The options that describe a rig's export (``--time``, ``--inputs``, ...) and reading the files they describe:
``trms import`` and ``trms calibrate --records`` share them."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from trms.errors import InputError
from trms.files import readable_file
from trms.record import Record
from trms.rigchecks import ANGLE_UNITS, JITTER_TOLERANCE, TIME_UNITS
from trms.rigdata import record_from_export
from trms.twin.model import get_configuration

__all__ = ["add_csv_arguments", "load_records"]


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
    out = []
    for path in paths:
        readable_file(path, "file")  # a folder, FIFO, device or unreadable file named as such
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
