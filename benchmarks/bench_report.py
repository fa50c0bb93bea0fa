"""The main job's time, part by part, and what one robustness sample costs (run on demand).

``python benchmarks/bench_report.py [--full]`` prints, in one run:

1. ``trms reproduce`` (quick by default): the wall time of each job as the report's worker pool ran it, and the
   whole run's wall time (goals: quick <= 15 s, full <= 60 s on 2 cores).
2. One Monte Carlo sample of the robustness study (both loops, on one core, after a warm-up sample) against its
   bare physics: per loop, one ``mj_step(nstep=...)`` call over the same model and number of physics steps,
   the controls held at the trim (no controller, no sensors, no records). Goal: <= 1 s a sample and <= 3x its
   bare physics.

The ratio is the one that holds the line; the seconds depend on the machine and its load (run it on a quiet one).
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")  # one core, for the sample's timing (before numpy loads)

import mujoco  # noqa: E402

from trms.experiments.ch8 import robustness as robustness  # noqa: E402
from trms.report import reproduce  # noqa: E402
from trms.worlds import make_plant  # noqa: E402

SAMPLES = 8


def report_parts(quick: bool) -> None:
    """Run the report and print each job's seconds and the wall time."""
    lines: list[str] = []
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        reproduce(out, quick=quick, progress=lines.append)
        wall = time.perf_counter() - start
    print(f"trms reproduce{' --quick' if quick else ''}: {wall:.1f} s wall")
    for line in lines:
        if " done in " in line:
            print(f"  {line}")


def bare_physics(samples: int) -> float:
    """Seconds of the same physics with nothing else: per loop and sample, one ``mj_step(nstep=...)`` call over
    the loop's horizon from the hover trim (no controller, no sensors, no records, no Python per step)."""
    total = 0.0
    for name in robustness.LOOPS:
        twin = make_plant("twin", robustness.LOOPS[name])
        _, ref, _, _ = robustness.loop_setup(name, twin)
        steps = int(round(len(ref) * twin.sample_time / twin.model.opt.timestep))
        for _ in range(samples):
            data = mujoco.MjData(twin.model)
            twin.put_at_trim(twin.model, data)
            start = time.perf_counter()
            mujoco.mj_step(twin.model, data, nstep=steps)
            total += time.perf_counter() - start
    return total


def robustness_sample() -> None:
    """Print one robustness sample's cost and its ratio to the bare physics."""
    robustness.run_samples([0], 0, robustness.SPREAD, "cpu")  # warm-up: imports, caches
    start = time.perf_counter()
    robustness.run_samples(list(range(1, 1 + SAMPLES)), 0, robustness.SPREAD, "cpu")
    per_sample = (time.perf_counter() - start) / SAMPLES
    bare = bare_physics(SAMPLES) / SAMPLES
    print(
        f"robustness: {per_sample:.3f} s a sample (both loops, one core, {SAMPLES} samples in one batch); "
        f"bare physics {bare:.3f} s; ratio {per_sample / bare:.2f}x"
    )


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="time the full report instead of the quick one")
    args = parser.parse_args()
    robustness_sample()
    report_parts(quick=not args.full)
