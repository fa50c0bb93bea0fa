"""``trms compare-controllers``: LQG, PID, MPC and H-infinity on the same scenarios and seeds (JSON, Markdown, PNG)."""

from __future__ import annotations

import argparse
import json
from functools import partial
from pathlib import Path
from typing import IO

from trms.errors import InputError
from trms.files import atomic_group, atomic_write

__all__ = ["NAME", "HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run"]

NAME = "compare-controllers"
HELP = "LQG, PID, MPC and H-infinity side by side on the 1-DOF pitch and the 2-DOF rig"
DESCRIPTION = (
    "Design every controller on eq. (3.11) and fly it as chapter 8 does (the reference prefilter, the thrust-curve "
    "inversion on the twin) on the same square wave (linear model, twin in moving and in still air) and the same "
    "push at the same seeds; print and write the tables (overshoot, settling in the noise band and in 5 %, voltage "
    "jump, control, saturation, push peak and recovery; each design's damping of the pitch mode and disk margin); "
    "then the amplitude sweep at --sweep-seeds (0.1x-1x, with and without the inversion); then every controller on "
    "--samples twins of the robustness study's parameter spread (success rate, overshoot and settling over the "
    "successes, the LTI certificate max |W_I T| and the robust verdict); then their MIMO versions on the 2-DOF rig's "
    "pitch and yaw steps at --mimo-seeds. MPC and H-infinity need the control extra."
)
EPILOG = """examples:
  trms compare-controllers --out controllers
  trms compare-controllers --seeds 0 1 2 3 4 --ts 0.1 --out controllers_01
  trms compare-controllers --samples 24 --out controllers_spread
  trms compare-controllers --samples 0 --mimo-seeds --sweep-seeds --out controllers_siso   # the 1-DOF comparison only
"""
#: Default number of spread samples: a fourth of the LQG study's 24 (whose six batches took 106 s on a busy
#: two-core machine), so the spread adds about half a minute to the comparison.
DEFAULT_SAMPLES = 6


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``trms compare-controllers``."""
    p.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2], help="plant seeds (default 0 1 2)")
    p.add_argument("--ts", type=float, default=0.2, choices=[0.2, 0.1], help="sample time in s (default 0.2)")
    p.add_argument(
        "--samples",
        type=_samples,
        default=DEFAULT_SAMPLES,
        help=f"twins of the parameter spread each controller flies (0: none; default {DEFAULT_SAMPLES})",
    )
    p.add_argument(
        "--mimo-seeds",
        type=int,
        nargs="*",
        default=[0, 1, 2],
        help="plant seeds of the 2-DOF MIMO comparison (none: skip it; default 0 1 2)",
    )
    p.add_argument(
        "--sweep-seeds",
        type=int,
        nargs="*",
        default=[0],
        help="moving-air seeds of the amplitude sweep, with and without the thrust-curve inversion (none: skip it; "
        "default 0)",
    )
    p.add_argument(
        "--out",
        default="controllers",
        help="folder for comparison.json, designs.json, sweep.json, spread.json (with --samples), mimo.json, "
        "comparison.md and the figure",
    )


def _samples(text: str) -> int:
    """A count of spread samples, 0 to 10000."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--samples must be a whole number 0 to 10000, got {text!r}") from None
    if not 0 <= value <= 10_000:
        raise argparse.ArgumentTypeError(f"--samples must be a whole number 0 to 10000, got {value}")
    return value


def _write(text: str, fh: IO[str]) -> None:
    fh.write(text)


def run(args: argparse.Namespace) -> int:
    """Run ``trms compare-controllers``; return the exit status."""
    from trms.experiments.ch8_comparison import controller_study, study_figures, study_tables

    for option, seeds in (("--seeds", args.seeds), ("--mimo-seeds", args.mimo_seeds)):
        twice = sorted({s for s in seeds if seeds.count(s) > 1})
        if twice:
            raise InputError(
                f"{option} gives seed {', '.join(map(str, twice))} more than once; a seed gives the same run every "
                "time, so each must be given once"
            )
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} is a file; give a folder for the comparison's files")
    created = not out.exists()
    out.mkdir(parents=True, exist_ok=True)  # a folder that cannot be made fails now, not after the runs
    try:
        study = controller_study(args.seeds, args.samples, args.mimo_seeds, args.ts, sweep_seeds=args.sweep_seeds)
    except BaseException:
        if created and not any(out.iterdir()):  # no empty folder left behind
            out.rmdir()
        raise
    tables = study_tables(study)
    text = "\n".join(t.to_markdown() for t in tables.values())
    with atomic_group():
        for name, table in tables.items():
            data = json.dumps(table.to_dict(), indent=1)
            atomic_write(out / f"{name}.json", partial(_write, data), binary=False)
        atomic_write(out / "comparison.md", lambda fh: fh.write(text), binary=False)
        figures = study_figures(study, out)
    print(text)
    written = [str(out / f"{name}.json") for name in tables] + [str(f.path) for f in figures]
    print(f"wrote {', '.join(written)} and {out / 'comparison.md'} ({study.seconds:.0f} s)")
    return 0
