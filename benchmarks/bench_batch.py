"""Speed of batched closed loops, as ratios measured in one run (on demand: python benchmarks/bench_batch.py PART).

Every loop is the 2-DOF LQG autopilot of the robustness study (pitch step, gusts, encoder
noise) on a twin with its own spread parameters and seed (``trms.experiments.robustness``).

``cpu``   The CPU batch (:func:`trms.batch.batch_closed_loop`, one ``mujoco.rollout`` per interval on
          every core) against a loop over :func:`trms.control.loop.closed_loop`, B = 256. Goal >= 5x on 2 cores.
``dask``  A 512-sample Monte Carlo (:func:`trms.batch.distributed.map_samples`, batches of 16) on a
          ``LocalCluster`` of 2 worker processes against 1: parallel efficiency = t1 / (2 t2). Goal >= 80 %.
``mjx``   On a GPU machine: MJX (:func:`trms.batch.mjx.mjx_closed_loop`) against the CPU batch on the
          same machine (closed-loop physics steps per second), and the wall time of ``--n-mjx`` closed
          loops of 60 s (goal: 10 000 in under 2 minutes on one H100). Needs ``trms[mjx]`` and JAX's GPU
          plugin. For the 10 000 loops, 100 parameter sets are built and each serves 100 loops with
          their own seeds (gusts and noise), since building 10 000 twins (MJCF compile and trim) takes
          longer than running them; the built time is reported apart.
"""

from __future__ import annotations

import argparse
import copy
import os
import time

import mujoco
import numpy as np

from trms.batch import batch_closed_loop
from trms.batch.distributed import map_samples
from trms.control.loop import closed_loop
from trms.experiments import robustness as rb
from trms.worlds import make_plant

LOOP = "2-DOF LQG autopilot, pitch step"


def loops(indices, seed: int = 0, clones: int = 1):
    """Twins (each its own parameters and seed) and their controllers, reference and metadata."""
    twins = []
    for i in indices:
        params, twin_seed = rb.sample_parameters(seed, i)
        base = make_plant("twin", "2dof", gusts=True, parameters=params, seed=twin_seed)
        twins.append(base)
        for c in range(1, clones):
            twin = copy.copy(base)  # shares the compiled model and trim; own data, buffers and seed
            twin.data = mujoco.MjData(base.model)
            twin._state_buf = np.empty_like(base._state_buf)
            twin.seed = twin_seed + c
            twins.append(twin)
    setups = [rb.loop_setup(LOOP, t) for t in twins]
    return twins, [s[0] for s in setups], setups[0][1]


def bare_rate(twin, n: int) -> float:
    """Physics steps per second of one bare ``mj_step(nstep)`` call from hover, held at the trim, on one core."""
    model, data = twin.model, mujoco.MjData(twin.model)
    data.qpos[:], data.act[:], data.ctrl[:] = twin.trim.qpos, twin.trim.act, twin.trim.act
    t = time.perf_counter()
    mujoco.mj_step(model, data, n)
    return n / (time.perf_counter() - t)


def rollout_rate(twins, n: int, threads: int) -> float:
    """Physics steps per second of open-loop ``mujoco.rollout`` calls, one per interval, of every twin from hover
    (controls held at the trim): the batch's physics without its controllers, twins and records."""
    from mujoco import rollout

    nsub = int(round(twins[0].sample_time / twins[0].model.opt.timestep))
    full = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.empty((len(twins), mujoco.mj_stateSize(twins[0].model, full)))
    for b, tw in enumerate(twins):
        tw.reset()
        mujoco.mj_getState(tw.model, tw.data, state0[b], full)
    ctrl = np.stack([tw.trim.act for tw in twins])[:, None, :]
    datas = [mujoco.MjData(twins[0].model) for _ in range(threads)]
    models, buf = [tw.model for tw in twins], np.empty((len(twins), nsub, state0.shape[1]))
    t = time.perf_counter()
    with rollout.Rollout(nthread=threads) as pool:
        for _ in range(n):
            pool.rollout(models, datas, state0, ctrl, nstep=nsub, state=buf)
            state0 = buf[:, -1].copy()
    return len(twins) * n * nsub / (time.perf_counter() - t)


def steps(twins, n: int) -> int:
    return len(twins) * n * int(round(twins[0].sample_time / twins[0].model.opt.timestep))


def bench_cpu(b: int, duration: float, threads: int | None) -> None:
    twins, ctrls, ref = loops(range(b))
    n = int(round(duration / twins[0].sample_time))
    ref = ref[:n]
    t = time.perf_counter()
    serial = [closed_loop(tw, c, ref) for tw, c in zip(twins, ctrls)]
    t_serial = time.perf_counter() - t
    twins, ctrls, _ = loops(range(b))
    t = time.perf_counter()
    res = batch_closed_loop(twins, ctrls, ref, threads=threads)
    t_batch = time.perf_counter() - t
    same = all(np.array_equal(a.outputs, r.outputs) for a, r in zip(serial, res.records))
    s = steps(twins, n)
    bare = bare_rate(twins[0], min(s, 2_000_000))
    cores = len(os.sched_getaffinity(0))
    print(f"cpu: B = {b}, {duration:g} s loops, {cores} cores, rollout threads {threads or cores}")
    print(f"  loop over closed_loop: {t_serial:.2f} s ({s / t_serial / 1e6:.3f} M physics steps/s)")
    print(f"  batch_closed_loop:     {t_batch:.2f} s ({s / t_batch / 1e6:.3f} M physics steps/s)")
    print(f"  speed-up {t_serial / t_batch:.2f}x (goal >= 5x on 2 cores); outputs bit-identical: {same}")
    print(
        f"  bare mj_step on one core: {bare / 1e6:.3f} M steps/s; a batch that only divided the physics over "
        f"{cores} cores would reach {cores * bare / (s / t_serial):.2f}x"
    )
    roll = rollout_rate(twins, n, threads or cores)
    print(
        f"  open-loop rollouts of the same B models, one per interval (physics alone): {roll / 1e6:.3f} M steps/s, "
        f"{roll / (s / t_serial):.2f}x the loop over closed_loop"
    )


def _mc_task(indices, seed, duration):
    twins, ctrls, ref = loops(indices, seed)
    res = batch_closed_loop(twins, ctrls, ref[: int(round(duration / twins[0].sample_time))], threads=1)
    return [rb.measure(LOOP, r) for r in res.records]


def bench_dask(n: int, duration: float) -> None:
    times, results = {}, {}
    for workers in (1, 2):
        t = time.perf_counter()
        results[workers] = map_samples(_mc_task, n, (0, duration), chunk_size=16, workers=workers, progress=False)
        times[workers] = time.perf_counter() - t
    same = str(results[1]) == str(results[2])
    eff = times[1] / (2 * times[2])
    print(f"dask: {n}-sample Monte Carlo of {duration:g} s loops, batches of 16, LocalCluster of worker processes")
    print(
        f"  1 worker {times[1]:.1f} s, 2 workers {times[2]:.1f} s: speed-up {times[1] / times[2]:.2f}x, "
        f"parallel efficiency {eff:.0%} (goal >= 80 %); results identical: {same}"
    )


def bench_mjx(b_cpu: int, n_mjx: int, duration: float, threads: int | None) -> None:
    import jax

    from trms.batch.mjx import mjx_closed_loop

    print(f"mjx: JAX {jax.__version__} on {jax.devices()}")
    twins, ctrls, ref = loops(range(b_cpu))
    n = int(round(duration / twins[0].sample_time))
    ref = ref[:n] if n <= ref.shape[0] else np.concatenate([ref, np.repeat(ref[-1:], n - ref.shape[0], 0)])
    t = time.perf_counter()
    batch_closed_loop(twins, ctrls, ref, threads=threads)
    t_cpu = time.perf_counter() - t
    cpu_rate = steps(twins, n) / t_cpu
    print(
        f"  CPU batch: B = {b_cpu}, {duration:g} s, {threads or len(os.sched_getaffinity(0))} threads: {t_cpu:.1f} s, "
        f"{cpu_rate / 1e6:.2f} M physics steps/s"
    )
    small, ctrls_small, _ = loops(range(2))
    t = time.perf_counter()
    mjx_closed_loop(small, ctrls_small, ref)
    print(f"  MJX, 2 loops (nearly all of it jit compilation and transfers): {time.perf_counter() - t:.1f} s")
    t = time.perf_counter()
    sets = max(1, n_mjx // 100)
    twins, ctrls, _ = loops(range(sets), clones=max(1, n_mjx // sets))
    t_build = time.perf_counter() - t
    t = time.perf_counter()
    res = mjx_closed_loop(twins, ctrls, ref)
    t_mjx = time.perf_counter() - t
    ok = sum(e is None for e in res.errors)
    mjx_rate = steps(twins, n) / t_mjx
    print(
        f"  MJX: {len(twins)} loops of {duration:g} s ({sets} parameter sets, built in {t_build:.1f} s): "
        f"{t_mjx:.1f} s wall (jit compile, host preparation and Records included), {mjx_rate / 1e6:.2f} M physics "
        f"steps/s, {ok} ran to the end"
    )
    print(f"  MJX / CPU batch steps per second: {mjx_rate / cpu_rate:.1f}x")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("part", choices=["cpu", "dask", "mjx", "all"])
    p.add_argument("--b", type=int, default=256, help="cpu: loops per batch (default 256)")
    p.add_argument("--duration", type=float, default=20.0, help="cpu/dask: loop length in s (default 20)")
    p.add_argument("--n", type=int, default=512, help="dask: samples (default 512)")
    p.add_argument("--threads", type=int, default=None, help="rollout threads (default: all cores)")
    p.add_argument("--b-cpu", type=int, default=256, help="mjx: loops of the CPU batch beside it (default 256)")
    p.add_argument("--n-mjx", type=int, default=10000, help="mjx: loops (default 10000)")
    p.add_argument("--mjx-duration", type=float, default=60.0, help="mjx: loop length in s (default 60)")
    a = p.parse_args()
    if a.part in ("cpu", "all"):
        bench_cpu(a.b, a.duration, a.threads)
    if a.part in ("dask", "all"):
        bench_dask(a.n, a.duration)
    if a.part == "mjx":
        bench_mjx(a.b_cpu, a.n_mjx, a.mjx_duration, a.threads)


if __name__ == "__main__":
    main()
