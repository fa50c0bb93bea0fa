"""``trms compare-controllers``: LQG, PID, MPC and H-infinity on the same pitch scenarios and seeds (JSON, Markdown)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from trms.files import atomic_group, atomic_write

__all__ = ["NAME", "HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run"]

NAME = "compare-controllers"
HELP = "LQG, PID, MPC and H-infinity side by side on the 1-DOF pitch"
DESCRIPTION = (
    "Design every controller on eq. (3.11) and fly it on the same square wave (linear model, twin in moving and in "
    "still air) and the same push at the same seeds; print and write the table (overshoot, settling, control, "
    "saturation, push peak and recovery, disk margins). MPC and H-infinity need the control extra."
)
EPILOG = """examples:
  trms compare-controllers --out controllers
  trms compare-controllers --seeds 0 1 2 3 4 --ts 0.1 --out controllers_01
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``trms compare-controllers``."""
    p.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2], help="plant seeds (default 0 1 2)")
    p.add_argument("--ts", type=float, default=0.2, choices=[0.2, 0.1], help="sample time in s (default 0.2)")
    p.add_argument("--out", default="controllers", help="folder for comparison.json and comparison.md")


def run(args: argparse.Namespace) -> int:
    """Run ``trms compare-controllers``; return the exit status."""
    from trms.experiments.ch8_controllers import compare_controllers, table_controllers

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)  # a folder that cannot be made fails now, not after the runs
    table = table_controllers(compare_controllers(args.seeds, args.ts))
    text = table.to_markdown()
    with atomic_group():
        atomic_write(out / "comparison.json", lambda fh: fh.write(json.dumps(table.to_dict(), indent=1)), binary=False)
        atomic_write(out / "comparison.md", lambda fh: fh.write(text), binary=False)
    print(text)
    print(f"wrote {out / 'comparison.json'} and {out / 'comparison.md'}")
    return 0
