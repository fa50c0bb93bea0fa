"""LQG vs PID vs MPC vs H-infinity on the 1-DOF pitch (the table of :mod:`trms.experiments.ch8.controllers`), and
the MPC's solve times with its constraints active.

Run on demand: ``.venv/bin/python benchmarks/bench_controllers.py`` (needs the ``control`` extra). At
``Ts = 0.2 s`` (the thesis's 1-DOF sample time) and ``Ts = 0.1 s`` (its 2-DOF one), seeds 0, 1, 2: the comparison
table (``trms compare-controllers``), then the solve times of an MPC whose constraints are active (rate limit
0.3 V per sample, pitch within +-0.22 rad) on the twin: real time needs each below the sample time.
"""

from __future__ import annotations

import time

import numpy as np

from trms.control import closed_loop, mpc_for_plant
from trms.experiments.ch8.controllers import compare_controllers, table_controllers
from trms.signals import square_wave
from trms.worlds import design_model, make_plant

SAMPLE_TIMES = (0.2, 0.1)
SEEDS = (0, 1, 2)


def main() -> None:
    for ts in SAMPLE_TIMES:
        print(f"--- Ts = {ts} s")
        compare(ts)


def compare(TS: float) -> None:  # noqa: N803 - the sample time, as in the text
    t0 = time.perf_counter()
    table = table_controllers(compare_controllers(SEEDS, TS))
    print(table.to_markdown())
    print(f"(the comparison took {time.perf_counter() - t0:.1f} s)")
    model = design_model("1dof", TS)
    reference = square_wave(60.0, TS, 30.0, 0.2)
    # constraints active: rate limit 0.3 V per sample and pitch limited to +-0.22 rad (soft), on the twin
    times, qps, peak = [], 0, 0.0
    for seed in SEEDS:
        plant = make_plant("twin", "1dof", TS, seed=seed)
        mpc = mpc_for_plant(model, plant, horizon=30, rate_limit=0.3, output_limits=(-0.22, 0.22))
        record = closed_loop(plant, mpc, reference, seed=seed)
        times += mpc.solve_times
        qps += mpc.qp_solves
        peak = max(peak, float(np.max(np.abs(plant.operating_point.output_deviation(record.outputs)))))
    t = 1e3 * np.array(times)
    print(
        f"constrained MPC on the twin: {qps}/{t.size} samples needed OSQP; solve time worst {t.max():.1f} ms, "
        f"99th percentile {np.percentile(t, 99):.2f} ms, median {np.median(t):.3f} ms; largest |pitch| {peak:.3f} rad"
    )


if __name__ == "__main__":
    main()
