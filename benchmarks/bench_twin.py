"""Speed of the twin, every ratio in one run (run on demand: ``python benchmarks/bench_twin.py [repeats]``).

Each figure is a ratio against the twin's own bare physics: a plain loop of one ``mj_step(nstep)`` per control
interval over the same model from the same state, replaying the controls the twin applied (its rotor controls, the
rotor-wash turbulence included, and its gust and push torques), so both sides integrate the same trajectory. The two
sides run alternately and each ratio is the median of the per-pair ratios: a slow spell of the shared machine falls on
both members of a pair. Beside it, in brackets, the ratio of each side's fastest run (for the closed loop: its fastest
run against the bare physics' fastest plus the controller's fastest): the least disturbed runs of a machine that
other work shares, which a pair's ratio still mixes when a slow spell falls on one member alone.

1. ``Twin.run`` open loop (2-DOF, 120 s at 0.1 s, PRBS of +-0.5 V, the rig's ambient excitation on). Goal <= 1.1.
2. The closed LQG loop of ``trms run`` (1-DOF, R = 125, SAS, 80 s square wave of 0.2 rad, at 0.2 s) against its bare
   physics plus the controller's own arithmetic (its ``update`` over the run's references and measurements, alone).
   Goal <= 1.5.
3. Each Gymnasium task's ``env.step`` over one episode (``gymnasium.make``, volts in +-0.3 V about the trim). Goal
   <= 1.5.
4. :class:`trms.envs.vector.TwinVectorEnv` at 8 environments (one process a core) against one environment: env-steps
   per second, the same number of env-steps each, episodes restarting as they end. Goal >= 1.6 on 2 cores. Paired
   with it, what two bare physics loops gain on two threads: on a shared machine, the most any parallel stepping can
   gain at that moment.
5. What the state sensors every twin model carries (what a rollout records) cost the physics: the bare loop over the
   twin's model against the same loop over the rig's model compiled without them.
6. For scale, scipy ``solve_ivp`` on Feedback's published 7-state model over the same horizon (one run).
"""

from __future__ import annotations

import statistics
import sys
import threading
import time
from collections.abc import Callable
from typing import cast

import gymnasium
import mujoco
import numpy as np
from scipy.integrate import solve_ivp

import trms.envs.gym  # noqa: F401  (registers the tasks)
from trms.control.loop import closed_loop
from trms.envs.gym import TwinTaskEnv
from trms.envs.tasks import TASKS
from trms.envs.vector import TwinVectorEnv
from trms.experiments.ch67_lqg import case_setup
from trms.record import Record
from trms.twin import Twin
from trms.twin.model import WASHES, build_model, spinning
from trms.twin.published import feedback_rhs
from trms.twin.rotors import rotor_controls
from trms.worlds import design_model, make_plant

HORIZON, TS = 120.0, 0.1
_FULL = mujoco.mjtState.mjSTATE_FULLPHYSICS
_CONTROL = mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_QFRC_APPLIED


def paired(fns: list[Callable[[], object]], repeats: int) -> list[list[float]]:
    """Times (s) of each of ``fns``, run in turn ``repeats`` times."""
    out: list[list[float]] = [[] for _ in fns]
    for _ in range(repeats):
        for fn, times in zip(fns, out):
            t0 = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t0)
    return out


def ratio(a: list[float], b: list[float]) -> float:
    """The median of the pairs' ratios a/b."""
    return statistics.median(x / y for x, y in zip(a, b))


def fastest(a: list[float], b: list[float]) -> float:
    """The ratio of the fastest runs, min(a) / min(b)."""
    return min(a) / min(b)


class Bare:
    """A bare ``mj_step(nstep)`` loop replaying per-interval controls (``(N, nu + nv)``, rollout's layout) from a
    saved full state and warm start, on ``model``."""

    def __init__(self, model: mujoco.MjModel, nsub: int, start: np.ndarray, warm: np.ndarray, rows: np.ndarray):
        self.model, self.nsub, self.start, self.warm = model, nsub, start, warm
        self.ctrl, self.qfrc = rows[:, : model.nu].copy(), rows[:, model.nu :].copy()
        self.data = mujoco.MjData(model)

    def __call__(self) -> None:
        m, d, nsub = self.model, self.data, self.nsub
        mujoco.mj_setState(m, d, self.start, _FULL)
        d.qacc_warmstart[:] = self.warm
        torques = bool(self.qfrc.any())
        for c, q in zip(self.ctrl, self.qfrc):
            d.ctrl[:] = c
            if torques:
                d.qfrc_applied[:] = q
            mujoco.mj_step(m, d, nsub)


def start_state(twin: Twin) -> tuple[np.ndarray, np.ndarray]:
    """The twin's full state and warm start now."""
    state = np.empty(mujoco.mj_stateSize(twin.model, _FULL))
    mujoco.mj_getState(twin.model, twin.data, state, _FULL)
    return state, twin.data.qacc_warmstart.copy()


def record_controls(twin: Twin, record: Record) -> np.ndarray:
    """The rotor controls a twin's record applied in each interval (rollout's layout; no torques)."""
    volts = np.tile(twin.trim.voltages, (len(record), 1))
    volts[:, twin.input_rotors] = record.extras["applied_inputs"]
    m = twin.model
    rows = np.zeros((len(record), m.nu + m.nv))
    rows[:, : m.nu] = rotor_controls(twin.curves, volts, m.nu, spinning(m))
    wash = [m.actuator(w).id for w in WASHES if w in [m.actuator(i).name for i in range(m.nu)]]
    rows[:, wash] = record.extras["turbulence"]
    return rows


def plain_model(twin: Twin) -> mujoco.MjModel:
    """The twin's rig compiled without the state sensors (the same physics)."""
    return build_model(twin.spec, twin.configuration, twin.voltage_limit, timestep=twin.model.opt.timestep)


def bench_run(repeats: int) -> dict[str, float]:
    twin = Twin("2dof", TS, seed=0)
    n = int(round(HORIZON / TS))
    volts = twin.operating_point.inputs + 0.5 * np.random.default_rng(0).choice([-1.0, 1.0], size=(n, 2))
    twin.reset(0)
    start, warm = start_state(twin)
    rows = record_controls(twin, twin.run(volts))
    nsub = int(round(TS / twin.model.opt.timestep))
    bare, plain = Bare(twin.model, nsub, start, warm, rows), Bare(plain_model(twin), nsub, start, warm, rows)
    t_run, t_bare, t_plain = paired([lambda: twin.run(volts), bare, plain], repeats)
    return {
        "run": statistics.median(t_run),
        "bare": statistics.median(t_bare),
        "ratio": ratio(t_run, t_bare),
        "fastest": fastest(t_run, t_bare),
        "sensors": ratio(t_bare, t_plain),
        "ratio_plain": ratio(t_run, t_plain),
        "steps": n * nsub,
    }


def bench_loop(repeats: int) -> dict[str, float]:
    plant = make_plant("twin", "1dof", None, seed=0)
    controller, ref, prefilter, meta = case_setup(plant, 125.0, "SAS", 0.2, 40.0, 80.0, design_model("1dof"))
    record = closed_loop(plant, controller, ref, prefilter, 0, meta)
    shaped, measured = record.extras["prefiltered_reference"], record.outputs - plant.operating_point.outputs

    def arithmetic() -> None:
        controller.reset()
        for r, y in zip(shaped, measured):
            controller.update(r, y)

    plant.reset(0)
    start, warm = start_state(plant)
    nsub = int(round(plant.sample_time / plant.model.opt.timestep))
    bare = Bare(plant.model, nsub, start, warm, record_controls(plant, record))
    t_loop, t_bare, t_ctrl = paired(
        [lambda: closed_loop(plant, controller, ref, prefilter, 0, meta), bare, arithmetic], repeats
    )
    return {
        "loop": statistics.median(t_loop),
        "bare": statistics.median(t_bare),
        "ctrl": statistics.median(t_ctrl),
        "ratio": statistics.median(a / (b + c) for a, b, c in zip(t_loop, t_bare, t_ctrl)),
        "fastest": fastest(t_loop, [min(t_bare) + min(t_ctrl)]),
        "n": len(record),
    }


def bench_env(name: str, repeats: int) -> dict[str, float]:
    env = gymnasium.make(f"trms/{name}-v0")
    twin = cast(TwinTaskEnv, env.unwrapped).twin
    n = TASKS[name].n_steps
    trim = twin.operating_point.inputs
    actions = trim + np.random.default_rng(0).uniform(-0.3, 0.3, (n, trim.size))
    env.reset(seed=0)
    start, warm = start_state(twin)
    rows = []
    for a in actions:  # the controls and torques each step feeds MuJoCo (then the step itself)
        controls, _, _ = twin.interval_controls(a)
        rows.append(controls[0])
        env.step(a)
    bare = Bare(twin.model, int(round(twin.sample_time / twin.model.opt.timestep)), start, warm, np.array(rows))

    def episode() -> None:
        for a in actions:
            env.step(a)

    times: list[list[float]] = [[], []]
    for _ in range(repeats):
        env.reset(seed=0)
        t0 = time.perf_counter()
        episode()
        times[0].append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        bare()
        times[1].append(time.perf_counter() - t0)
    env.close()
    return {
        "step": statistics.median(times[0]) / n,
        "bare": statistics.median(times[1]) / n,
        "ratio": ratio(*times),
        "fastest": fastest(*times),
    }


class Ceiling:
    """Two bare physics loops one after the other (``serial``) and on two threads (``parallel``): their ratio is the
    most that any stepping side by side can gain on this machine at that moment (other processes take cores too)."""

    def __init__(self, steps: int = 300) -> None:
        self.twins = [Twin("2dof", TS, seed=s) for s in range(2)]
        self.steps = steps

    def loop(self, twin: Twin) -> None:
        for _ in range(self.steps):
            mujoco.mj_step(twin.model, twin.data, 20)

    def serial(self) -> None:
        for twin in self.twins:
            self.loop(twin)

    def parallel(self) -> None:
        threads = [threading.Thread(target=self.loop, args=(twin,)) for twin in self.twins]
        for t in threads:
            t.start()
        for t in threads:
            t.join()


def bench_vector(name: str, repeats: int, num_envs: int = 8, calls: int = 60) -> dict[str, float]:
    """One environment against ``num_envs`` in a :class:`TwinVectorEnv` (its default workers: one per core), paired
    run by run with the machine's parallel ceiling (:class:`Ceiling`)."""
    single = gymnasium.make(f"trms/{name}-v0")
    vector = TwinVectorEnv(name, num_envs)
    trim = cast(TwinTaskEnv, single.unwrapped).twin.operating_point.inputs
    actions = trim + np.random.default_rng(0).uniform(-0.3, 0.3, (calls, num_envs, trim.size))
    single.reset(seed=0)
    vector.reset(seed=0)
    ceiling = Ceiling()

    def one() -> None:
        for a in actions.reshape(-1, trim.size):
            *_, terminated, truncated, _ = single.step(a)
            if terminated or truncated:
                single.reset()

    def many() -> None:
        for a in actions:
            vector.step(a)

    t_one, t_many, t_serial, t_parallel = paired([one, many, ceiling.serial, ceiling.parallel], repeats)
    workers = len(vector.processes) + 1  # this process steps the first share
    vector.close()
    steps = calls * num_envs
    return {
        "one": steps / statistics.median(t_one),
        "many": steps / statistics.median(t_many),
        "ratio": ratio(t_one, t_many),
        "fastest": fastest(t_one, t_many),
        "ceiling": ratio(t_serial, t_parallel),
        "ceiling_fastest": fastest(t_serial, t_parallel),
        "workers": workers,
    }


def feedback_solve_ivp(volts: np.ndarray) -> np.ndarray:
    """Integrate interval by interval (zero-order hold), as a sampled-data simulation must."""
    x = np.zeros(7)
    for u in volts:
        sol = solve_ivp(feedback_rhs, (0.0, TS), x, args=(lambda t, u=u: u,), rtol=1e-6, atol=1e-9)
        x = sol.y[:, -1]
    return x


def main(repeats: int = 7) -> None:
    run = bench_run(2 * repeats)
    n = int(round(HORIZON / TS))
    # The Feedback model gets the same +-0.5 V PRBS around its own working voltages (the published-parameter hover,
    # 1.27 V and -0.43 V), not around the twin's.
    rng = np.random.default_rng(0)
    t0 = time.perf_counter()
    feedback_solve_ivp(np.array([1.27, -0.43]) + 0.5 * rng.choice([-1.0, 1.0], size=(n, 2)))
    t_ivp = time.perf_counter() - t0
    print(
        f"paired runs: {2 * repeats} (open loop), {repeats} (the rest); ratios are medians of per-pair ratios (in "
        "brackets: the fastest runs' ratio)"
    )
    print(
        f"1. Twin.run, 2-DOF, {HORIZON:.0f} s at {TS} s ({run['steps']:.0f} physics steps): {run['run'] * 1e3:.1f} ms, "
        f"bare {run['bare'] * 1e3:.1f} ms: twin / bare = {run['ratio']:.3f} ({run['fastest']:.3f}; goal <= 1.1)"
    )
    loop = bench_loop(repeats)
    print(
        f"2. closed LQG loop (trms run, 1-DOF, {loop['n']:.0f} samples): {loop['loop'] * 1e3:.1f} ms, bare "
        f"{loop['bare'] * 1e3:.1f} ms + controller {loop['ctrl'] * 1e3:.1f} ms: loop / (bare + controller) = "
        f"{loop['ratio']:.3f} ({loop['fastest']:.3f}; goal <= 1.5)"
    )
    for name in TASKS:
        env = bench_env(name, repeats)
        print(
            f"3. {name:17s} env.step {env['step'] * 1e6:6.1f} us ({1 / env['step']:5.0f} steps/s), bare "
            f"{env['bare'] * 1e6:6.1f} us: step / bare = {env['ratio']:.3f} ({env['fastest']:.3f}; goal <= 1.5)"
        )
    for name in TASKS:
        vec = bench_vector(name, repeats)
        print(
            f"4. {name:17s} vector env, 8 envs in {vec['workers']:.0f} processes: {vec['many']:5.0f} env-steps/s "
            f"against one env's {vec['one']:5.0f}: {vec['ratio']:.2f}x ({vec['fastest']:.2f}x; goal >= 1.6 on 2 "
            f"cores); two bare physics loops on two threads, in the same pairs: {vec['ceiling']:.2f}x "
            f"({vec['ceiling_fastest']:.2f}x; the machine's ceiling then)"
        )
    print(
        f"5. state sensors: bare over the twin's model / over the rig's model without them = {run['sensors']:.3f}; "
        f"Twin.run / the latter = {run['ratio_plain']:.3f}"
    )
    print(
        f"6. solve_ivp on Feedback's 7-state model, same horizon: {t_ivp * 1e3:.1f} ms; Twin.run / solve_ivp = "
        f"{run['run'] / t_ivp:.3f} (one run)"
    )


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 7)
