"""``trms simulate``: a configuration and an input signal (generated or read from a file) -> a Record."""

from __future__ import annotations

import argparse
import warnings

import numpy as np

from trms.cli.options import (
    MAX_AMPLITUDE_V,
    add_cap_options,
    add_plant_options,
    check_caps,
    check_two_samples,
    plant_of,
    ranges,
)
from trms.errors import InputError
from trms.files import atomic_group

__all__ = ["NAME", "HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run"]

NAME = "simulate"
HELP = "run a plant on an input signal or file -> Record"
DESCRIPTION = (
    "Run the twin or the linear model open loop on a generated signal (around hover, on one input) or on "
    "inputs read from a file, and save the Record (.npz, optionally .csv)."
)
EPILOG = """examples:
  trms simulate --config 1dof --signal prbs --amplitude 0.1 --duration 60 --out prbs.npz
  trms simulate --plant linear --signal doublet --step 2 --amplitude 0.25 --out doublet.npz --csv
  trms simulate --config 2dof --channel u2 --signal uniform --bandwidth 2 --out yaw.npz
  trms simulate --config 1dof --input volts.csv --out mine.npz        # one column per input, absolute V
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``trms simulate``."""
    add_plant_options(p)
    p.add_argument(
        "--signal",
        default="prbs",
        choices=["prbs", "uniform", "3211", "doublet", "square", "hold"],
        help="generated signal, added to the hover trim of --channel (default prbs)",
    )
    p.add_argument("--input", metavar="FILE", help="inputs from a file instead (.csv/.txt, .npy, or a Record .npz)")
    p.add_argument(
        "--deviation", action="store_true", help="the --input file holds deviations from hover, not absolute V"
    )
    p.add_argument("--channel", default="u1", help="input the signal drives (default u1)")
    p.add_argument("--duration", type=float, default=60.0, help="s (default 60)")
    p.add_argument("--amplitude", type=float, default=0.1, help="V (default 0.1)")
    p.add_argument(
        "--bandwidth",
        type=float,
        default=2.0,
        help="clock of prbs (a random binary signal) and uniform in Hz (default 2)",
    )
    p.add_argument(
        "--step", type=float, default=2.0, help="unit step of the 3211 / pulse of the doublet in s (default 2)"
    )
    p.add_argument("--start", type=float, default=2.0, help="first edge of the 3211/doublet in s (default 2)")
    p.add_argument("--period", type=float, default=40.0, help="square-wave period in s (default 40)")
    p.add_argument("--gusts", action="store_true", help="gust torques on the twin")
    add_cap_options(p, "V", MAX_AMPLITUDE_V)
    p.add_argument("--out", default="record.npz", help="Record file (default record.npz)")
    p.add_argument("--csv", action="store_true", help="also write a CSV beside it")


def _signal(args: argparse.Namespace, ts: float) -> np.ndarray:
    from trms.signals import doublet, multistep_3211, random_binary, square_wave, uniform_noise

    kind, d, a, b, seed = args.signal, args.duration, args.amplitude, args.bandwidth, args.seed
    if kind == "prbs":
        return random_binary(d, ts, b, a, seed=seed)
    if kind == "uniform":
        return uniform_noise(d, ts, b, a, seed=seed)
    if kind == "3211":
        return multistep_3211(ts, args.step, a, start=args.start, duration=d)
    if kind == "doublet":
        return doublet(ts, args.step, a, start=args.start, duration=d)
    if kind == "square":
        return square_wave(d, ts, args.period, a)
    return np.zeros(int(round(d / ts)))


def run(args: argparse.Namespace) -> int:
    """Run ``trms simulate``; return the exit status."""
    from trms.plant import simulate
    from trms.rig.checks import beyond_end_stops
    from trms.rig.exports import read_inputs

    check_caps(args, MAX_AMPLITUDE_V, " V")
    plant = plant_of(args)
    op = plant.operating_point
    if args.input:
        u = read_inputs(args.input, len(plant.input_names))
        if args.deviation:
            u = op.absolute_input(u)
    else:
        check_two_samples(args, plant.sample_time)
        sig = _signal(args, plant.sample_time)
        if args.channel not in plant.input_names:
            raise InputError(f"unknown input channel {args.channel!r}; this plant has {', '.join(plant.input_names)}")
        u = op.with_signal(sig, args.channel)
    rec = simulate(plant, u, seed=args.seed, metadata={"config": args.config, "world": args.plant})
    if args.plant != "twin":
        beyond = beyond_end_stops(rec, margin=0.0)
        if beyond:  # the twin has the stops; the linear model runs through them
            warnings.warn(
                f"{beyond}: past the rig's end stops, where the linear model is not valid (the twin, --plant twin, "
                "has the stops; a smaller --amplitude stays within them)",
                stacklevel=1,
            )
    with atomic_group():  # written only now that the run succeeded: both files, or neither (old ones kept)
        out = rec.save(args.out)
        csv = rec.to_csv(out.with_suffix(".csv")) if args.csv else None
    print(
        f"{args.plant} {args.config}: {len(rec)} samples at {plant.sample_time} s; hover "
        + ", ".join(f"{n} = {v:.3f} V" for n, v in zip(plant.input_names, op.inputs))
    )
    print(ranges(rec))
    print(f"wrote {out}")
    if csv is not None:
        print(f"wrote {csv}")
    return 0
