"""Time-domain calibration (mujoco.sysid) of 6 parameters on 3 records of 60 s, on known truth.

Run on demand::

    python benchmarks/bench_timedomain.py                   # the recovery table and the timing
    python benchmarks/bench_timedomain.py --gust-scale 0    # noise and quantisation only
    python benchmarks/bench_timedomain.py --delay           # the transport delay fitted too (7 parameters)
    python benchmarks/bench_timedomain.py --coverage 4      # interval coverage over 4 hidden truths, gusts on and off

A 2-DOF twin with hidden parameter changes (all at once; encoder quantisation, noise and
the project's gusts on) records three 60 s PRBS runs; calibration starts from the shipped
model and fits the parameters on them, and a fourth record, never fitted, measures the fit
before and after. Printed: the recovery table (truth, recovered, 95 % interval, inside or
not), the fit, and the wall time as a ratio to one rollout of the same three records (the
custom rollout with the start parameters), with the machine's load. Goal: under 60 s on 2
cores.

``--coverage N`` (``--first K``) draws N hidden truths, numbered from K (each of the six parameters times a factor drawn
uniformly in [0.8, 1.2], seeded by the truth's number; records of their own seeds), with
gusts on and off, and prints per parameter how many truths lie inside their interval (the
interval the calibration reports -- sandwich or disturbance -- and the white-noise one of
``calculate_intervals``), the median interval half-width relative to the truth, and the
mean and spread of the error in units of the half-width (a mean far from 0 is bias, a
spread above 0.5 an interval too narrow for its scatter).
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from trms.calibration import timedomain as td
from trms.calibration.timedomain.rig import Rig, parameter_dict
from trms.signals import random_binary
from trms.twin import DEFAULT_COUNTS_PER_REV, Gust, Twin, load_spec
from trms.twin.parameters import read_parameters
from trms.worlds import GUST

TS = 0.05
DURATION = 60.0
HIDDEN = {
    "counterweight_mass": 1.15,
    "pitch_damping": 0.85,
    "main_motor_gain": 1.1,
    "main_motor_lag": 0.8,
    "yaw_damping": 1.2,
    "cable_stiffness": 0.85,
}
DELAY_FACTOR = 1.2  # the hidden transport delay with --delay, as a multiple of the shipped one


def records(spec, seeds, gust_scale: float, counts_per_rev: int = DEFAULT_COUNTS_PER_REV):
    """One 60 s two-input PRBS record a seed, from a twin on ``spec`` (quantised, noisy, gusts scaled)."""
    gust = Gust(GUST[0] * gust_scale, GUST[1])
    twin = Twin("2dof", TS, 0, spec=spec, counts_per_rev=counts_per_rev, noise_std=2e-4, gust=gust)
    hover = twin.operating_point.inputs
    out = []
    for s in seeds:
        u = np.column_stack(
            [
                hover[0] + random_binary(DURATION, TS, 1.0, 0.05, seed=s),
                hover[1] + random_binary(DURATION, TS, 1.0, 0.05, seed=s + 100),
            ]
        )
        out.append(twin.run(u, seed=s))
    return out


def recover(
    spec,
    factors: dict[str, float],
    seeds,
    gust_scale: float,
    held_out: bool = True,
    counts: int = DEFAULT_COUNTS_PER_REV,
):
    """Records of the truth ``spec`` scaled by ``factors``, calibrated back; (truth, result, wall s, fitted records).

    The result's ``timings["cpu"]`` is the calibration's CPU time (s), every thread's.
    """
    truth_spec = td.scaled_spec(spec, factors)
    truth = read_parameters(truth_spec, list(factors))
    recs = records(truth_spec, seeds, gust_scale, counts)
    fit, held = (recs[:-1], recs[-1:]) if held_out else (recs, [])
    t0, c0 = time.perf_counter(), time.process_time()
    result = td.calibrate_records(fit, list(factors), spec, held_out=held, max_iters=40)
    result.timings["cpu"] = time.process_time() - c0  # every thread's CPU time: what a busy machine does not hide
    return truth, result, time.perf_counter() - t0, fit


def inside(truth: dict[str, float], result) -> dict[str, bool]:
    return {n: abs(result.values[n] - truth[n]) <= result.intervals[n] for n in truth}


def print_table(truth: dict[str, float], result) -> None:
    ok = inside(truth, result)
    print("| parameter | truth | start | recovered | 95 % interval (+-) | white-noise interval (+-) | inside |")
    print("|---|---|---|---|---|---|---|")
    for n in truth:
        print(
            f"| {n} | {truth[n]:.5g} | {result.start[n]:.5g} | {result.values[n]:.5g} | {result.intervals[n]:.3g} "
            f"| {result.white_intervals[n]:.3g} | {'yes' if ok[n] else 'no'} |"
        )
    for o in result.fit_before:
        print(f"{result.fit_on} fit of {o}: {result.fit_before[o][0]:.1f} % -> {result.fit_after[o][0]:.1f} %")
    print(
        f"sandwich bandwidth {result.bandwidth} samples; {result.iterations} iterations, "
        f"{result.evaluations} rollouts, {result.profile_fits} delay-profile fits; {result.stopped}"
    )


def one_rollout(spec, fit) -> float:
    """Wall time (s) of one rollout of the fitted records with the start parameters, through the calibration's hook."""
    rig = Rig(spec, "2dof", TS, 10.0, os.cpu_count() or 1)
    try:
        seq = rig.sequences(fit, [f"r{i}" for i in range(len(fit))], "bench")
        model = rig.build(parameter_dict(spec, list(HIDDEN)))
        t0 = time.perf_counter()
        rig._roll([(model, traj.control, traj.initial_state) for traj in seq.measured_rollout])
        return time.perf_counter() - t0
    finally:
        rig.close()


def coverage(spec, n: int, gust_scale: float, counts: int = DEFAULT_COUNTS_PER_REV, first: int = 0) -> None:
    """Coverage of the intervals over ``n`` hidden truths drawn around the shipped model."""
    hits: dict[str, list[bool]] = {k: [] for k in HIDDEN}
    white: dict[str, list[bool]] = {k: [] for k in HIDDEN}
    width: dict[str, list[float]] = {k: [] for k in HIDDEN}
    zs: dict[str, list[float]] = {k: [] for k in HIDDEN}
    walls = []
    for i in range(first, first + n):
        rng = np.random.default_rng(1000 + i)
        factors = {k: float(f) for k, f in zip(HIDDEN, rng.uniform(0.8, 1.2, len(HIDDEN)))}
        seeds = [10 * i + 11, 10 * i + 12, 10 * i + 13]
        truth, result, wall, _ = recover(spec, factors, seeds, gust_scale, False, counts)
        walls.append(wall)
        for k in HIDDEN:
            err = result.values[k] - truth[k]
            hits[k].append(abs(err) <= result.intervals[k])
            white[k].append(abs(err) <= result.white_intervals[k])
            width[k].append(result.intervals[k] / abs(truth[k]))
            zs[k].append(err / result.intervals[k])
        print(
            f"truth {i}: inside {sum(abs(result.values[k] - truth[k]) <= result.intervals[k] for k in HIDDEN)}/6, "
            f"bandwidth {result.bandwidth}, {wall:.0f} s",
            flush=True,
        )
    print(
        f"\ngusts x{gust_scale:g}: {n} hidden truths, 3 records of {DURATION:g} s each, "
        f"mean wall {np.mean(walls):.0f} s"
    )
    print(
        "| parameter | inside (reported) | inside (white) | median half-width / truth | error / half-width: mean, std |"
    )
    print("|---|---|---|---|---|")
    for k in HIDDEN:
        print(
            f"| {k} | {sum(hits[k])}/{n} | {sum(white[k])}/{n} | {100 * np.median(width[k]):.2g} % "
            f"| {np.mean(zs[k]):+.2f}, {np.std(zs[k]):.2f} |"
        )
    total = sum(sum(v) for v in hits.values())
    print(
        f"all: {total}/{n * len(HIDDEN)} inside the reported intervals, "
        f"{sum(sum(v) for v in white.values())}/{n * len(HIDDEN)} inside the white ones"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--gust-scale", type=float, default=1.0, help="gust std as a multiple of the project's")
    parser.add_argument("--delay", action="store_true", help="hide and fit the transport delay too")
    parser.add_argument("--coverage", type=int, default=0, help="hidden truths for a coverage study (gusts on and off)")
    parser.add_argument("--first", type=int, default=0, help="number of the first hidden truth of --coverage")
    parser.add_argument(
        "--counts-per-rev",
        type=int,
        default=DEFAULT_COUNTS_PER_REV,
        help="encoder resolution of the records (counts a revolution; 0 for none)",
    )
    args = parser.parse_args()
    spec = load_spec()
    print(f"{os.cpu_count()} cores; load average before: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    if args.coverage:
        for scale in dict.fromkeys((args.gust_scale, 0.0)):
            coverage(spec, args.coverage, scale, args.counts_per_rev, args.first)
        print(f"load average after: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
        return
    factors = dict(HIDDEN, input_delay=DELAY_FACTOR) if args.delay else HIDDEN
    truth, result, wall, fit = recover(spec, factors, (1, 2, 3, 4), args.gust_scale, True, args.counts_per_rev)
    one = one_rollout(spec, fit)
    print(
        f"2-DOF, {len(fit)} records of {DURATION:g} s at {TS} s fitted, 1 held out; gusts x{args.gust_scale:g} "
        f"of the project's, encoder quantisation and noise on"
    )
    print_table(truth, result)
    print(
        f"one rollout of the 3 records: {one:.3f} s; calibration of {len(factors)} parameters {wall:.1f} s "
        f"= {wall / one:.0f}x one rollout (optimisation {result.timings['optimisation']:.1f} s), "
        f"{result.timings['cpu']:.1f} s of CPU on {os.cpu_count()} cores; goal < 60 s"
    )
    print(f"load average after: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
