"""``trms demo``: trim the rig at hover, print its modes, excite it with a small PRBS, write a record and renders."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from trms.cli.options import (
    DEMO_AMPLITUDE,
    MAX_AMPLITUDE_V,
    add_cap_options,
    check_caps,
    check_two_samples,
    ranges,
)
from trms.errors import check_in_range

__all__ = ["NAME", "HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run"]

NAME = "demo"
HELP = "trim, excite around hover, write a record and renders"
DESCRIPTION = (
    "Trim the twin at hover, excite it with a small PRBS around hover, and write the record (npz, csv) and "
    "renders (png, gif)."
)
EPILOG = """examples:
  trms demo --out out
  trms demo --config 1dof --duration 30 --amplitude 0.3 --seed 2 --out out/1dof
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``trms demo``."""
    p.add_argument("--out", default="out", help="output folder (default: out)")
    p.add_argument("--config", default="2dof", choices=["1dof", "2dof", "yaw"], help="rig configuration")
    p.add_argument("--sample-time", type=float, default=0.1, help="control sample time in s (default 0.1)")
    p.add_argument("--duration", type=float, default=60.0, help="simulated seconds (default 60)")
    p.add_argument(
        "--amplitude",
        type=float,
        default=DEMO_AMPLITUDE,
        help=f"PRBS amplitude around hover in V (default {DEMO_AMPLITUDE:g}: yaw within +-45 deg)",
    )
    p.add_argument("--bandwidth", type=float, default=2.0, help="PRBS bandwidth in Hz (default 2)")
    p.add_argument("--seed", type=int, default=0, help="seed of the excitation and the twin (default 0)")
    p.add_argument("--modes", type=int, default=4, help="how many modes to print, 1-100 (default 4)")
    add_cap_options(p, "V", MAX_AMPLITUDE_V)


def run(args: argparse.Namespace) -> int:
    """Run ``trms demo``; return the exit status."""
    from trms.signals import random_binary
    from trms.twin import Twin
    from trms.twin.render import render_record

    check_caps(args, MAX_AMPLITUDE_V, " V")
    check_in_range("--modes", args.modes, 1, 100)
    out = Path(args.out)
    twin = Twin(args.config, args.sample_time, seed=args.seed)
    check_two_samples(args, twin.sample_time)
    hover = twin.operating_point.inputs
    print(f"TRMS twin, configuration {twin.configuration.name} ({twin.configuration.description})")
    print("hover voltages: " + ", ".join(f"{n} = {v:.4f} V" for n, v in zip(twin.input_names, hover)))
    print("modes at hover (linearised):")
    for mode in twin.modes()[: args.modes]:
        print(f"  {mode.frequency_hz:8.4f} Hz  damping {mode.damping:6.4f}  ({mode.dominant})")
    ts = twin.sample_time
    signals = [
        random_binary(args.duration, ts, args.bandwidth, args.amplitude, offset=float(v), seed=args.seed + i)
        for i, v in enumerate(hover)
    ]
    record = twin.run(np.column_stack(signals))
    out.mkdir(parents=True, exist_ok=True)
    npz = record.save(out / "record.npz")
    csv = record.to_csv(out / "record.csv")
    png = render_record(twin.model, record, out / "rig.png", camera="oblique", width=480, height=360)
    every = max(1, int(round(0.5 / ts)))
    gif = render_record(twin.model, record, out / "rig.gif", camera="oblique", every=every, width=320, height=240)
    print(f"simulated {record.time[-1] + ts:.1f} s at {ts} s: " + ranges(record))
    excursion = np.degrees(np.max(np.abs(record.deviations()[1]), axis=0))
    print(
        f"PRBS of +-{args.amplitude:g} V around hover; largest excursion from hover: "
        + ", ".join(f"{n} {e:.1f} deg" for n, e in zip(record.output_names, excursion))
    )
    for path in (npz, csv, png, gif):
        print(f"wrote {path}")
    return 0
