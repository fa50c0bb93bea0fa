"""The ``trms`` command.

Subcommands
-----------
demo
    The main job on the shipped defaults: trim the rig at hover, print the hover voltages
    and the twin's modes, excite it around hover with a small PRBS on each rotor, and write
    the Record (``.npz`` and ``.csv``), a PNG of the last frame and a GIF of the run.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Sequence

import numpy as np

from .errors import TrmsError

__all__ = ["main"]

_DEMO_EPILOG = """examples:
  trms demo --out out
  trms demo --config 1dof --duration 30 --amplitude 0.3 --seed 2 --out out/1dof
"""


def _demo(args: argparse.Namespace) -> int:
    from .identification.signals import prbs
    from .twin import Twin
    from .twin.render import render_record

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    twin = Twin(args.config, args.sample_time, seed=args.seed)
    hover = twin.operating_point.inputs
    print(f"TRMS twin, configuration {twin.configuration.name} ({twin.configuration.description})")
    print("hover voltages: " + ", ".join(f"{n} = {v:.4f} V" for n, v in zip(twin.input_names, hover)))
    print("modes at hover (linearised):")
    for mode in twin.modes()[: args.modes]:
        print(f"  {mode.frequency_hz:8.4f} Hz  damping {mode.damping:6.4f}  ({mode.dominant})")
    n_in = len(twin.input_names)
    inputs = np.column_stack([
        prbs(args.duration, twin.sample_time, args.bandwidth, args.amplitude, offset=float(hover[i]), seed=args.seed + i)
        for i in range(n_in)
    ])
    record = twin.run(inputs)
    npz = record.save(out / "record.npz")
    csv = record.to_csv(out / "record.csv")
    png = render_record(twin.model, record, out / "rig.png", camera="oblique", width=480, height=360)
    every = max(1, int(round(0.5 / twin.sample_time)))
    gif = render_record(twin.model, record, out / "rig.gif", camera="oblique", every=every, width=320, height=240)
    y = record.outputs
    print(f"simulated {record.time[-1] + twin.sample_time:.1f} s at {twin.sample_time} s: "
          + ", ".join(f"{n} in [{y[:, i].min():+.3f}, {y[:, i].max():+.3f}] rad" for i, n in enumerate(twin.output_names))
          + f"; saturated samples: {int(record.extras['saturated'].any(axis=1).sum())}")
    for path in (npz, csv, png, gif):
        print(f"wrote {path}")
    return 0


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="trms", description="TRMS digital twin: simulate, identify, control.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    demo = sub.add_parser("demo", help="trim, excite around hover, write a record and renders",
                          description="Trim the twin at hover, excite it with a small PRBS around hover, and write "
                                      "the record (npz, csv) and renders (png, gif).",
                          epilog=_DEMO_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    demo.add_argument("--out", default="out", help="output folder (default: out)")
    demo.add_argument("--config", default="2dof", choices=["1dof", "2dof", "yaw"], help="rig configuration")
    demo.add_argument("--sample-time", type=float, default=0.1, help="control sample time in s (default 0.1)")
    demo.add_argument("--duration", type=float, default=60.0, help="simulated seconds (default 60)")
    demo.add_argument("--amplitude", type=float, default=0.2, help="PRBS amplitude around hover in V (default 0.2)")
    demo.add_argument("--bandwidth", type=float, default=2.0, help="PRBS bandwidth in Hz (default 2)")
    demo.add_argument("--seed", type=int, default=0, help="seed of the excitation and the twin (default 0)")
    demo.add_argument("--modes", type=int, default=4, help="how many modes to print (default 4)")
    demo.set_defaults(func=_demo)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``trms`` command; returns the exit status."""
    args = _parser().parse_args(argv)
    try:
        return int(args.func(args))
    except TrmsError as exc:
        print(f"trms {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
