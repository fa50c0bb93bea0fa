"""``trms import``: a rig's CSV or MATLAB export -> a Record with its operating point."""

from __future__ import annotations

import argparse

import numpy as np

from trms.cli.options import say
from trms.cli.records import add_csv_arguments, load_records

__all__ = ["NAME", "HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run"]

NAME = "import"
HELP = "read a rig's CSV or MATLAB export into a Record"
DESCRIPTION = (
    "Read a rig's export -- CSV/text or a MATLAB .mat file: a time column (s or ms), named voltage and angle "
    "columns, degrees or radians -- check it, take the operating point as the mean of a hover segment, and "
    "write a Record (.npz)."
)
EPILOG = """examples:
  trms import rig.csv --time t --inputs Vmain --outputs pitch_deg --units deg --hover 0:10 --config 1dof --out rig.npz
  trms import rig.csv --time t --inputs V1 V2 --outputs pitch yaw --units rad --hover 0:5 --config 2dof
  trms import log.txt --time t_ms --time-unit ms --inputs V1 --outputs pitch --units deg --hover 0:10
  trms import run.mat --time 'log(:,1)' --inputs 'log(:,2)' --outputs 'log(:,3)' --units rad --hover 0:10
  trms import run.mat --time data.time --inputs data.u1 data.u2 --outputs data.pitch data.yaw --units deg

Text exports may be comma, semicolon, tab or whitespace delimited, UTF-8 or Latin-1; lines starting with
'#' and title lines before the header are skipped (and named). A .mat file (MATLAB v5/v7; save v7.3 files
as v7) names its columns as variables, struct fields or matrix columns (1-based). The time column must
increase with one sample time inside the rig's 0.001..32.767 s: jitter up to 5 % of a sample is snapped
to a uniform grid, more is refused unless --resample interpolates it. The angles are checked against the
rig's end stops and speed (degrees labelled radians are refused) and converted to radians. The operating
point is the mean of the --hover segment [T0, T1) (printed, and stored in the Record); without it the
Record has none and `trms identify` refuses it. What the reader did is printed as warnings.
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``trms import``."""
    p.add_argument("csv", metavar="EXPORT", help="the rig's export: text (.csv, .txt, ...) or MATLAB (.mat)")
    add_csv_arguments(p)
    p.add_argument("--out", default="rig.npz", help="Record file (default rig.npz)")


def run(args: argparse.Namespace) -> int:
    """Run ``trms import``; return the exit status."""
    rec = load_records([args.csv], args, saved=False)[0]
    out = rec.save(args.out)  # before anything is printed: a closed pipe cannot lose the Record
    src = rec.metadata.get("operating_point_source")
    if src is None:
        say("operating point: unknown (no --hover segment); identification refuses this record until it is detrended")
    else:
        op = rec.operating_point
        say(
            f"operating point ({src}): inputs {np.round(op.inputs, 4).tolist()} V, "
            f"outputs {np.round(op.outputs, 5).tolist()} rad"
        )
    start = float(rec.metadata.get("start_time", 0.0))
    late = abs(start) >= 0.5 * rec.sample_time  # a clock that did not start at the first sample (not jitter)
    clock = f" from the export's t = {start:g} s (the Record's t = 0; messages give the export's times)" if late else ""
    say(
        f"{len(rec)} samples at {rec.sample_time:g} s{clock}, inputs {', '.join(rec.input_names)}, outputs "
        f"{', '.join(rec.output_names)} (rad); wrote {out}"
    )
    return 0
