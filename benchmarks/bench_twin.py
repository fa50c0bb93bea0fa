"""Speed of the twin, as ratios measured in one run (run on demand: python benchmarks/bench_twin.py).

1. ``Twin.run`` (2-DOF, 120 s, 10 Hz PRBS-like voltages) against a bare MuJoCo loop over the same model
   and horizon (one ``mj_step(nstep=100)`` per control interval, no sensors, no records). Goal <= 1.25x.
2. The same horizon with scipy ``solve_ivp`` on Feedback's published nonlinear TRMS equations (the
   simplified model of PHYSICS.md: 2 rigid axes, 2 motor lags, reaction-torque filter), the reference
   implementation a user would otherwise write. Goal: the twin faster while modelling more (flexible
   beam, counterweight geometry, encoders, saturation, disturbances).
"""

from __future__ import annotations

import statistics
import time

import mujoco
import numpy as np
from scipy.integrate import solve_ivp

from trms.twin import Twin

HORIZON = 120.0
TS = 0.1
REPEATS = 5


def prbs_like(n: int, trim: np.ndarray, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return trim + 0.5 * rng.choice([-1.0, 1.0], size=(n, trim.size))


def bare_loop(twin: Twin, volts: np.ndarray) -> None:
    m, d = twin.model, mujoco.MjData(twin.model)
    d.qpos[:] = twin.trim.qpos
    d.act[:] = twin.trim.act
    nsub = int(round(TS / m.opt.timestep))
    thrust = np.stack([c.thrust(volts[:, i]) for i, c in enumerate(twin.curves)], axis=1)
    for k in range(volts.shape[0]):
        d.ctrl[:] = thrust[k]
        mujoco.mj_step(m, d, nsub)


# Feedback's simplified nonlinear model (PHYSICS.md), parameters as published.
P = dict(I1=0.068, I2=0.02, a1=0.0135, b1=0.0924, a2=0.02, b2=0.09, Mg=0.32, B1psi=6e-3, B2psi=1e-3,
         B1phi=0.1, B2phi=0.01, Kgy=0.05, k1=1.1, k2=0.8, T11=1.1, T10=1.0, T21=1.0, T20=1.0, Tp=2.0, T0=3.5, kc=-0.2)


def feedback_rhs(t: float, x: np.ndarray, u_of_t) -> np.ndarray:
    psi, dpsi, phi, dphi, tau1, tau2, mr_state = x
    u1, u2 = u_of_t(t)
    p = P
    f1 = p["a1"] * tau1 * abs(tau1) + p["b1"] * tau1
    f2 = p["a2"] * tau2 * abs(tau2) + p["b2"] * tau2
    # MR = kc (T0 s + 1)/(Tp s + 1) tau1, realised as mr_state' = (tau1 - mr_state)/Tp.
    mr = p["kc"] * (p["T0"] / p["Tp"] * tau1 + (1 - p["T0"] / p["Tp"]) * mr_state)
    ddpsi = (f1 - p["Mg"] * np.sin(psi) - p["B1psi"] * dpsi - p["B2psi"] * np.sign(dpsi)
             - p["Kgy"] * f1 * dphi * np.cos(psi)) / p["I1"]
    ddphi = (f2 - p["B1phi"] * dphi - p["B2phi"] * np.sign(dphi) - mr) / p["I2"]
    return np.array([dpsi, ddpsi, dphi, ddphi, (p["k1"] * u1 - p["T10"] * tau1) / p["T11"],
                     (p["k2"] * u2 - p["T20"] * tau2) / p["T21"], (tau1 - mr_state) / p["Tp"]])


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


def main() -> None:
    twin = Twin("2dof", TS, seed=0)
    n = int(round(HORIZON / TS))
    volts = prbs_like(n, twin.operating_point.inputs)
    t_twin = median_time(twin.run, volts)
    t_bare = median_time(bare_loop, twin, volts)
    # The Feedback model gets the same +-0.5 V PRBS around its own working voltages (the published-parameter
    # hover, 1.27 V and -0.43 V): near 0 V its sign() friction makes RK45 crawl, which would flatter the twin.
    t_ivp = median_time(feedback_solve_ivp, prbs_like(n, np.array([1.27, -0.43])), repeats=1)
    steps = n * int(round(TS / twin.model.opt.timestep))
    print(f"horizon {HORIZON:.0f} s, control {TS} s, physics step {twin.model.opt.timestep * 1e3:.1f} ms "
          f"({steps} physics steps), median of {REPEATS}")
    print(f"  Twin.run (2-DOF)       {t_twin * 1e3:8.1f} ms   real-time factor {HORIZON / t_twin:7.0f}x")
    print(f"  bare mj_step loop      {t_bare * 1e3:8.1f} ms   twin / bare = {t_twin / t_bare:.3f}  (goal <= 1.25)")
    print(f"  solve_ivp, Feedback    {t_ivp * 1e3:8.1f} ms   twin / solve_ivp = {t_twin / t_ivp:.3f}  (goal < 1; one run)")
    print(f"  per physics step: twin {t_twin / steps * 1e6:.2f} us, bare {t_bare / steps * 1e6:.2f} us")


if __name__ == "__main__":
    main()
