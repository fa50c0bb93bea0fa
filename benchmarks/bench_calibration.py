"""Wall time of a full calibration from the uncalibrated physical defaults (run on demand).

    python benchmarks/bench_calibration.py

Starts from the published parameter values (``trms.twin.parameters.published_parameters``), runs
the thesis's calibration exactly as ``trms calibrate`` does, and reports the wall time and how it
splits between the linear inner fit, the spectral (batched rollout) fit and the verification.
Goal: under 2 minutes on this 2-core machine. Also times one protocol batch against the same
runs made one ``Twin.run`` after another, the ratio that batching buys.
"""

from __future__ import annotations

import time

import numpy as np

from trms.batch.rollouts import run_open_loop_batch
from trms.calibration import THESIS_PROTOCOLS, Targets, calibrate
from trms.calibration.protocol import FIT_SEEDS
from trms.twin import Twin, load_spec
from trms.twin.parameters import published_parameters, with_parameters


def main() -> None:
    start = with_parameters(load_spec(), published_parameters())
    t0 = time.perf_counter()
    result = calibrate(Targets.thesis(), start)
    wall = time.perf_counter() - t0
    t = result.timings
    print(
        f"full calibration from the published values: {wall:.1f} s (goal < 120 s), {result.passes} passes, "
        f"{'converged' if result.converged else 'not converged'}"
    )
    print(f"  linear inner fit     {t['linear_fit']:6.1f} s  ({result.evaluations['linear']} linearisations)")
    print(
        f"  spectral fit         {t['spectral_fit']:6.1f} s  "
        f"({result.evaluations['spectral']} candidates x 2 protocols x {len(FIT_SEEDS)} runs)"
    )
    print(f"  verification         {t['verification']:6.1f} s")
    print(f"  targets met: {sum(c.met for c in result.verification.checks)}/{len(result.verification.checks)}")

    protocol = THESIS_PROTOCOLS[1]
    twins = [Twin("2dof", protocol.sample_time, spec=start) for _ in range(8)]
    u = np.stack([protocol.inputs(tw) for tw in twins])
    t0 = time.perf_counter()
    run_open_loop_batch(twins, u)
    batch = time.perf_counter() - t0
    t0 = time.perf_counter()
    for b, tw in enumerate(twins):
        tw.run(u[b])
    serial = time.perf_counter() - t0
    print(
        f"8 x 120 s 2-DOF protocol runs: rollout batch {batch:.2f} s, Twin.run one by one {serial:.2f} s, "
        f"ratio {serial / batch:.2f}x"
    )


if __name__ == "__main__":
    main()
