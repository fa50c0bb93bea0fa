"""``trms design``: integral LQG gains, estimator and prefilter for given weights (JSON)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from trms.files import atomic_write

__all__ = ["NAME", "HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run"]

NAME = "design"
HELP = "integral LQG gains, estimator and prefilter for given weights"
DESCRIPTION = (
    "Design the integral LQG (current estimator, Qe = I, Re = 1) on the 1-DOF model eq. (3.11) or the 2-DOF "
    "reduced twin model, and write gains, poles and the prefilter as JSON. On 2dof without --q and --r: the "
    "autopilot's per-channel weights; `trms run --config 2dof --design FILE` flies the file."
)
EPILOG = """examples:
  trms design --r 125 --out lqg.json
  trms design --r 75 --case "CSAS LPF 0.2 Hz" --out lqg75.json
  trms design --config 2dof --out autopilot.json
  trms design --config 2dof --q 1 --r 1000 --out autopilot_qi.json
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``trms design``."""
    p.add_argument("--config", default="1dof", choices=["1dof", "2dof"], help="design model (default 1dof: eq. 3.11)")
    p.add_argument("--q", type=float, default=None, help="Q = q I (default 1; 2dof: the autopilot's weights)")
    p.add_argument("--r", type=float, default=None, help="R = r I (default 125; 2dof: the autopilot's weights)")
    p.add_argument("--case", default="SAS", help="SAS or a CSAS prefilter, e.g. 'CSAS LPF 0.2 Hz' (default SAS)")
    p.add_argument("--out", default="lqg.json", help="JSON file (default lqg.json)")


def run(args: argparse.Namespace) -> int:
    """Run ``trms design``; return the exit status."""
    from trms.experiments.lqg_design import integral_design

    found = integral_design(args.config, args.q, args.r, args.case)
    model, design, filt = found.model, found.design, found.prefilter
    out = Path(args.out)
    data = found.to_dict()
    atomic_write(out, lambda fh: fh.write(json.dumps(data, indent=1)), binary=False)
    mag = lambda v: ", ".join(f"{abs(c):.3f}" for c in v)  # noqa: E731
    weights = "the autopilot's per-channel weights" if found.q is None else f"Q = {found.q:g} I, R = {found.r:g}"
    print(
        f"integral LQG on the {args.config} design model ({model.nstates} states, Ts = {design.sample_time} s), "
        f"{weights}"
    )
    print(f"  K = {np.array2string(design.K, precision=4)}")
    print(f"  |regulator poles| {mag(design.regulator_poles)}")
    print(f"  |estimator poles| {mag(design.estimator_poles)} (faster than the regulator: {design.estimator_faster})")
    print(f"  prefilter: {'none (SAS)' if filt is None else filt.name}")
    print(f"wrote {out}")
    return 0
