"""``trms calibrate``: arguments and the run (wired into :mod:`trms.cli`)."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from ...plant import Record
from ..model import DEFAULT_MODEL_PATH, load_spec
from ..parameters import write_parameters
from .calibrate import Progress, calibrate
from .report import format_table, write_report
from .targets import Targets

__all__ = ["add_calibrate_arguments", "run_calibrate", "EPILOG"]

EPILOG = """examples:
  trms calibrate                                  # thesis targets, writes trms/models/trms.xml and ./calibration
  trms calibrate --no-write --out /tmp/cal        # report only, model untouched
  trms calibrate --targets my_modes.json          # your own mode table (JSON)
  trms calibrate --records run1.npz run2.npz      # targets measured on your rig's records
  trms calibrate --model my_rig.xml --start-from my_rig.xml

mode table format: {"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 0.34,
  "tolerance_hz": 0.02}], "coherences": [{"config": "2dof", "channel": "u2->pitch", "level": "low",
  "threshold": 0.5}]}
"""


def add_calibrate_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the ``calibrate`` options to ``parser``."""
    src = parser.add_mutually_exclusive_group()
    src.add_argument("--targets", metavar="JSON", help="a mode table (JSON) instead of the thesis's targets")
    src.add_argument("--records", metavar="NPZ", nargs="+", help="Records of your rig (one protocol run each)")
    parser.add_argument("--model", default=str(DEFAULT_MODEL_PATH), help="MJCF to write the calibrated values into "
                        "(default: the shipped trms/models/trms.xml)")
    parser.add_argument("--start-from", metavar="MJCF", help="MJCF to start from (default: --model)")
    parser.add_argument("--out", default="calibration", help="report folder (default: ./calibration)")
    parser.add_argument("--no-write", action="store_true", help="do not modify the model file")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def run_calibrate(args: argparse.Namespace) -> int:
    """Run ``trms calibrate``; return the exit status (0: all reachable targets met, 1: some missed)."""
    if args.targets:
        targets = Targets.load(args.targets)
    elif args.records:
        targets = Targets.from_records([Record.load(p) for p in args.records])
    else:
        targets = Targets.thesis()
    spec = load_spec(args.start_from or args.model)
    t0 = time.perf_counter()
    result = calibrate(targets, spec, progress=Progress(enabled=not args.quiet))
    wall = time.perf_counter() - t0
    js, png = write_report(result, args.out)
    print(format_table(result))
    print()
    for name, v in result.values.items():
        print(f"  {name:22s} {result.start[name]:10.5g} -> {v:10.5g}")
    t = result.timings
    print(f"calibration {wall:.1f} s: linear fit {t['linear_fit']:.1f} s, spectral fit {t['spectral_fit']:.1f} s, "
          f"verification {t['verification']:.1f} s ({result.passes} passes)")
    for line in result.unreachable:
        print(f"not met: {line}")
    if not args.no_write:
        write_parameters(Path(args.model), result.values)
        print(f"wrote calibrated values into {args.model}")
    print(f"wrote {js} and {png}")
    return 0
