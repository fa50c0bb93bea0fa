"""LQG vs PID vs MPC vs H-infinity on the 1-DOF pitch: the linear model eq. (3.11) and the twin.

Run on demand: ``.venv/bin/python benchmarks/bench_controllers.py`` (needs the ``control`` extra).
Every controller is designed on the design model at ``Ts = 0.2 s`` (the thesis's 1-DOF sample time),
then again at ``Ts = 0.1 s`` (the thesis's 2-DOF one), and run through
:func:`trms.control.loop.closed_loop` on a 60 s square wave of +-0.2 rad (period 30 s), seeds 0, 1, 2,
with each world's measurement noise. Per controller and world: the mean over seeds and steps of the
overshoot (%), the settling time (s, 2 % band; steps that never settle counted apart), the RMS control
(V) and its total variation (V), from :func:`trms.control.metrics.square_wave_metrics`; for MPC also the
worst QP solve time over all runs (real time needs less than the sample time), then the solve times of
an MPC whose constraints are active (rate limit 0.3 V per sample, pitch within +-0.22 rad) on the twin.

Designs: integral LQG with the thesis's ``R = 75`` and estimator weights
(:func:`trms.experiments.ch67_lqg.design`); PID from :func:`trms.control.pid.tune_pid`;
MPC from :func:`trms.control.mpc.mpc_for_plant` (horizon 30, rate limit 1 V per sample, the end stops);
H-infinity from :func:`trms.control.hinf.pitch_weights`.
"""

from __future__ import annotations

import time

import numpy as np

from trms.control import (
    HinfController,
    LQGController,
    PIDController,
    closed_loop,
    design_mixsyn,
    deviation_limits,
    mpc_for_plant,
    pitch_weights,
    square_wave_metrics,
    tune_pid,
)
from trms.experiments.ch67_lqg import design as lqg_design
from trms.signals import square_wave
from trms.worlds import design_model, make_plant

SAMPLE_TIMES = (0.2, 0.1)
SEEDS = (0, 1, 2)


def main() -> None:
    for ts in SAMPLE_TIMES:
        print(f"--- Ts = {ts} s")
        compare(ts)


def compare(TS: float) -> None:  # noqa: N803 - the sample time, as in the text
    model = design_model("1dof", TS)
    t0 = time.perf_counter()
    lqg = lqg_design(model, 75.0)
    pid_gains = tune_pid(model)
    hinf = design_mixsyn(model, *pitch_weights())
    print(f"designs: {time.perf_counter() - t0:.2f} s; PID {pid_gains}; H-inf gamma {hinf.gamma:.4f}, ", end="")
    margin = hinf.margin(model)
    print(f"disk margin alpha {margin.alpha:.3f} ({margin.gain_margin_db:.1f} dB, {margin.phase_margin_deg:.1f} deg)")
    reference = square_wave(60.0, TS, 30.0, 0.2)
    worst_solve = 0.0
    print(
        f"{'world':7s} {'controller':11s} {'overshoot %':>11s} {'settling s':>10s} {'unsettled':>9s} "
        f"{'rms u V':>8s} {'TV u V':>8s} {'run s':>6s}"
    )
    for world in ("linear", "twin"):
        for name in ("LQG", "PID", "MPC", "H-infinity"):
            rows, took = [], 0.0
            for seed in SEEDS:
                plant = make_plant(world, "1dof", TS, seed=seed)
                limits = deviation_limits(plant)
                controller: object
                if name == "LQG":
                    controller = LQGController(lqg, limits)
                elif name == "PID":
                    controller = PIDController(pid_gains, TS, (float(limits[0][0]), float(limits[1][0])))
                elif name == "MPC":
                    controller = mpc_for_plant(model, plant, horizon=30, rate_limit=1.0)
                else:
                    controller = HinfController(hinf, (float(limits[0][0]), float(limits[1][0])))
                start = time.perf_counter()
                record = closed_loop(plant, controller, reference, seed=seed)  # type: ignore[arg-type]
                took += time.perf_counter() - start
                if name == "MPC":
                    worst_solve = max(worst_solve, max(controller.solve_times))  # type: ignore[attr-defined]
                rows += square_wave_metrics(record)
            settle = np.array([r.settling_time for r in rows])
            print(
                f"{world:7s} {name:11s} {np.mean([r.overshoot for r in rows]):11.1f} "
                f"{np.nanmean(settle) if np.isfinite(settle).any() else float('nan'):10.2f} "
                f"{int(np.isnan(settle).sum()):4d}/{settle.size:<4d} "
                f"{np.mean([r.rms_control for r in rows]):8.3f} {np.mean([r.total_variation for r in rows]):8.2f} "
                f"{took / len(SEEDS):6.2f}"
            )
    print(f"MPC worst solve time over {len(SEEDS) * 2} runs of 60 s at Ts = {TS} s: {1e3 * worst_solve:.1f} ms")
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
