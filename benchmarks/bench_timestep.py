"""Whether the physics step resolves what the thesis measures: the verification at the file's step and a finer one.

    python benchmarks/bench_timestep.py [--finer 0.001] [--integrator implicitfast]

Verifies the shipped model against the thesis's targets (:func:`trms.calibration.verify.verify`, the 10 unseen
seeds) at the model file's physics step and integrator, and at ``--finer`` with ``--integrator`` (the reference),
and prints, per target, at how many seeds each meets it, the mean of what is achieved at either, and, against the
figure's seed-to-seed standard deviation (the estimator's own scatter), the shift of the mean and the largest
change of any one seed's figure; with the wall time of each and the physics alone (one 120 s 2-DOF run's
``mj_step`` calls at either). A step that resolves the rig changes no count and moves each mean by a small
fraction of the scatter. Single seeds move even between two equally fine physics (a 120 s run is sensitive to
rounding): the same 1 ms step with another integrator (``--integrator discrete``) shows that floor.
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np

from trms.calibration import Targets
from trms.calibration.verify import Verification, verify
from trms.twin import Twin, load_spec

INTEGRATORS = {"euler": 0, "rk4": 1, "implicit": 2, "implicitfast": 3, "discrete": 4}


def _by_target(ver: Verification) -> dict[tuple[str, float], list[tuple[float, bool]]]:
    out: dict[tuple[str, float], list[tuple[float, bool]]] = {}
    for c in ver.checks:
        out.setdefault((c.name, c.target), []).append((float(c.achieved), bool(c.met)))
    return out


def _physics_seconds(spec: mujoco.MjSpec) -> float:
    """Seconds of ``mj_step`` alone over 120 s of the 2-DOF twin at hover (the best of three)."""
    twin = Twin("2dof", 0.1, spec=spec)
    steps = int(round(120.0 / twin.model.opt.timestep))
    best = np.inf
    for _ in range(3):
        data = mujoco.MjData(twin.model)
        twin.put_at_trim(twin.model, data)
        t0 = time.perf_counter()
        mujoco.mj_step(twin.model, data, nstep=steps)
        best = min(best, time.perf_counter() - t0)
    return float(best)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--finer", type=float, default=0.001, help="the reference's physics step (s)")
    parser.add_argument(
        "--integrator", choices=sorted(INTEGRATORS), default="implicitfast", help="the reference's integrator"
    )
    args = parser.parse_args()
    coarse = load_spec()
    fine = load_spec()
    fine.option.timestep = args.finer
    fine.option.integrator = INTEGRATORS[args.integrator]
    names = {v: k for k, v in INTEGRATORS.items()}
    results = {}
    for spec in (coarse, fine):
        label = f"{spec.option.timestep * 1e3:g} ms {names[int(spec.option.integrator)]}"
        t0 = time.perf_counter()
        results[label] = _by_target(verify(spec, Targets.thesis()))
        print(
            f"verification at {label}: {time.perf_counter() - t0:.1f} s; "
            f"120 s of 2-DOF physics alone: {_physics_seconds(spec):.3f} s"
        )
    (a_label, a), (b_label, b) = results.items()
    print(
        f"{'target':55s} {'met':>11s} {'mean ' + a_label:>24s} {'mean ' + b_label:>24s} {'mean shift':>11s} "
        f"{'max |change|':>13s}  (both / sd)"
    )
    worst, worst_mean = 0.0, 0.0
    for key, rows in a.items():
        x = np.array([r[0] for r in rows])
        y = np.array([r[0] for r in b[key]])
        change = float(np.nanmax(np.abs(x - y))) if x.size else 0.0
        sd = float(np.nanstd(y)) if y.size > 1 else 0.0
        ratio = change / sd if sd > 0 else 0.0
        shift = abs(float(np.nanmean(x) - np.nanmean(y)))
        mean_ratio = shift / sd if sd > 0 else 0.0
        worst, worst_mean = max(worst, ratio), max(worst_mean, mean_ratio)
        met = f"{sum(r[1] for r in rows)}/{len(rows)} {sum(r[1] for r in b[key])}/{len(rows)}"
        print(
            f"{key[0][:55]:55s} {met:>11s} {np.nanmean(x):24.5g} {np.nanmean(y):24.5g} {shift:11.3g} {change:13.3g}  "
            f"({mean_ratio:.2f}, {ratio:.2f})"
        )
    print(
        f"largest shift of a mean: {worst_mean:.2f}, largest change of one seed's figure: {worst:.2f}, "
        "of that figure's seed-to-seed standard deviation"
    )


if __name__ == "__main__":
    main()
