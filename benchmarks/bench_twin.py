"""Speed of the twin, as ratios measured in one run (run on demand: python benchmarks/bench_twin.py).

1. ``Twin.run`` (2-DOF, 120 s, 10 Hz PRBS-like voltages, the rig's ambient excitation on: its rotor-wash
   turbulence drawn per control interval, its electronics noise and quantisation) against a bare MuJoCo loop
   over the same model and horizon (one ``mj_step(nstep=100)`` per control interval, no turbulence, no
   sensors, no records). Goal <= 1.25x.
2. The same horizon with scipy ``solve_ivp`` on Feedback's published nonlinear TRMS equations (the
   simplified model of PHYSICS.md: 2 rigid axes, 2 motor lags, reaction-torque filter), the reference
   implementation a user would otherwise write (from :mod:`trms.twin.published`), for scale: it has 7
   states; the twin models a flexible beam, spinning rotors, delay lines, encoders, saturation and
   disturbances.
"""

from __future__ import annotations

import statistics
import time

import mujoco
import numpy as np
from scipy.integrate import solve_ivp

from trms.twin import Twin
from trms.twin.published import feedback_rhs
from trms.twin.rotors import rotor_controls

HORIZON = 120.0
TS = 0.1
REPEATS = 5


def prbs_like(n: int, trim: np.ndarray, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return trim + 0.5 * rng.choice([-1.0, 1.0], size=(n, trim.size))


def bare_loop(twin: Twin, volts: np.ndarray) -> None:
    m, d = twin.model, mujoco.MjData(twin.model)
    twin.put_at_trim(m, d)
    nsub = int(round(TS / m.opt.timestep))
    ctrl = rotor_controls(twin.curves, volts, m.nu)
    for k in range(volts.shape[0]):
        d.ctrl[:] = ctrl[k]
        mujoco.mj_step(m, d, nsub)


def feedback_solve_ivp(volts: np.ndarray) -> np.ndarray:
    """Integrate interval by interval (zero-order hold), as a sampled-data simulation must."""
    x = np.zeros(7)
    for k in range(volts.shape[0]):
        u = volts[k]
        sol = solve_ivp(feedback_rhs, (0.0, TS), x, args=(lambda t, u=u: u,), rtol=1e-6, atol=1e-9)
        x = sol.y[:, -1]
    return x


def median_time(fn, *args, repeats: int = REPEATS) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(*args)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def paired_times(a, b, repeats: int = REPEATS) -> tuple[float, float, float]:
    """Median times of ``a()`` and ``b()`` run alternately, and the median of the per-pair ratios a/b: a slow
    spell of the machine falls on both members of a pair instead of on one side's runs."""
    ta, tb = [], []
    for _ in range(repeats):
        for fn, out in ((a, ta), (b, tb)):
            t0 = time.perf_counter()
            fn()
            out.append(time.perf_counter() - t0)
    return statistics.median(ta), statistics.median(tb), statistics.median(x / y for x, y in zip(ta, tb))


def main() -> None:
    twin = Twin("2dof", TS, seed=0)
    n = int(round(HORIZON / TS))
    volts = prbs_like(n, twin.operating_point.inputs)
    t_twin, t_bare, ratio = paired_times(lambda: twin.run(volts), lambda: bare_loop(twin, volts), repeats=2 * REPEATS)
    # The Feedback model gets the same +-0.5 V PRBS around its own working voltages (the published-parameter
    # hover, 1.27 V and -0.43 V), not around the twin's.
    t_ivp = median_time(feedback_solve_ivp, prbs_like(n, np.array([1.27, -0.43])), repeats=1)
    steps = n * int(round(TS / twin.model.opt.timestep))
    print(
        f"horizon {HORIZON:.0f} s, control {TS} s, physics step {twin.model.opt.timestep * 1e3:.1f} ms "
        f"({steps} physics steps), median of {2 * REPEATS} paired runs"
    )
    print(f"  Twin.run (2-DOF)       {t_twin * 1e3:8.1f} ms   real-time factor {HORIZON / t_twin:7.0f}x")
    print(
        f"  bare mj_step loop      {t_bare * 1e3:8.1f} ms   twin / bare = {ratio:.3f}  "
        "(median of paired runs; goal <= 1.25)"
    )
    print(
        f"  solve_ivp, Feedback    {t_ivp * 1e3:8.1f} ms   twin / solve_ivp = {t_twin / t_ivp:.3f}  (one run; the "
        "published model has 7 states and smoothed friction, the twin a flexible beam, spinning rotors and "
        "delay lines)"
    )
    print(f"  per physics step: twin {t_twin / steps * 1e6:.2f} us, bare {t_bare / steps * 1e6:.2f} us")


if __name__ == "__main__":
    main()
