"""Time-domain calibration (mujoco.sysid) of 6 parameters on 3 records of 60 s, on known truth.

Run on demand: ``python benchmarks/bench_timedomain.py`` (or with ``--gust-scale 0`` for
noise and quantisation only). A 2-DOF twin with six hidden parameter changes (+-20 % at
most, all at once; encoder quantisation, noise and the project's gusts on) records three
60 s PRBS runs; calibration starts from the shipped model and fits the six parameters on
them, and a fourth record, never fitted, measures the fit before and after. Printed: the
recovery table (truth, recovered, 95 % interval, inside or not), the fit, and the wall time
as a ratio to one rollout of the same three records (the custom rollout with the start
parameters). Goal: under 60 s on 2 cores.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from trms.experiments.plants import GUST
from trms.identification.signals import random_binary
from trms.twin import Gust, Twin, load_spec
from trms.twin.calibration import timedomain as td
from trms.twin.parameters import read_parameters

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


def records(spec, seeds, gust_scale: float):
    twin = Twin("2dof", TS, 0, spec=spec, noise_std=2e-4, gust=Gust(GUST[0] * gust_scale, GUST[1]))
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--gust-scale", type=float, default=1.0, help="gust std as a multiple of the project's")
    args = parser.parse_args()
    spec = load_spec()
    truth_spec = td.scaled_spec(spec, HIDDEN)
    truth = read_parameters(truth_spec, list(HIDDEN))
    recs = records(truth_spec, (1, 2, 3, 4), args.gust_scale)
    fit, held = recs[:3], recs[3:]

    rig = td._Rig(spec, "2dof", TS, 10.0)
    seq = rig.sequences(fit, ["a", "b", "c"], "bench")
    params = td._parameter_dict(spec, list(HIDDEN))
    model = rig.build(params)
    datas = [__import__("mujoco").MjData(model) for _ in range(os.cpu_count() or 1)]
    t0 = time.perf_counter()
    rig.rollout(models=[model] * 3, datas=datas, control_signal=seq.control, initial_states=seq.initial_state)
    one = time.perf_counter() - t0

    t0 = time.perf_counter()
    result = td.calibrate_records(fit, list(HIDDEN), spec, held_out=held, max_iters=40)
    wall = time.perf_counter() - t0

    print(
        f"2-DOF, {len(fit)} records of {DURATION:g} s at {TS} s fitted, 1 held out; gusts x{args.gust_scale:g} "
        f"of the project's, encoder quantisation and noise on; {os.cpu_count()} cores"
    )
    print("| parameter | truth | start | recovered | 95 % interval (+-) | white-noise interval (+-) | inside |")
    print("|---|---|---|---|---|---|---|")
    for n in HIDDEN:
        inside = abs(result.values[n] - truth[n]) <= result.intervals[n]
        print(
            f"| {n} | {truth[n]:.5g} | {result.start[n]:.5g} | {result.values[n]:.5g} | {result.intervals[n]:.3g} "
            f"| {result.white_intervals[n]:.3g} | {'yes' if inside else 'no'} |"
        )
    for o in result.fit_before:
        print(f"held-out fit of {o}: {result.fit_before[o][0]:.1f} % -> {result.fit_after[o][0]:.1f} %")
    print(
        f"residual autocorrelation time {result.residual_time:.1f} samples; {result.iterations} iterations, "
        f"{result.evaluations} rollouts; {result.stopped}"
    )
    print(
        f"one rollout of the 3 records: {one:.3f} s; calibration {wall:.1f} s = {wall / one:.0f}x one rollout "
        f"(optimisation {result.timings['optimisation']:.1f} s); goal < 60 s"
    )


if __name__ == "__main__":
    main()
