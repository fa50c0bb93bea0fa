"""Speed of a 1000-sample closed loop (integral LQG on eq. 3.11) through the Plant interface.

Run on demand: ``.venv/bin/python benchmarks/bench_control.py``. Goal: under 50 ms.
Compared with the same closed loop as one python-control system simulated by
``control.forced_response`` and with the open-loop plant alone through ``trms.plant.simulate``.
Also timed: the disk margin of that loop broken at the plant input, and the ZVD shaper of the
pitch mode designed on the 0.2 s grid and applied to the 1000-sample reference.
"""

from __future__ import annotations

import time

import control
import numpy as np

from trms.control import LQGController, closed_loop, design_lqg, disk_margin, observer_canonical
from trms.control.shaping import discrete_shaper
from trms.plant import LinearPlant, simulate
from trms.reference import eq_3_11
from trms.signals import square_wave

N = 1000
REPEATS = 7


def best_of(fn) -> float:
    """Best wall time (s) of ``REPEATS`` calls."""
    times = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    model = observer_canonical(eq_3_11())
    plant = LinearPlant(model, input_limits=(-10.0, 10.0))
    ctl = LQGController(design_lqg(model, Q=1.0, R=75.0), input_limits=(-10.0, 10.0))
    ref = square_wave(N * 0.2, 0.2, 40.0, 0.2)
    comp = ctl.compensator()
    loop = control.series(comp[:, :1], control.feedback(model, comp[:, 1:], sign=1))
    t = np.arange(N) * 0.2
    u_open = np.zeros(N)

    ours = best_of(lambda: closed_loop(plant, ctl, ref))
    lti = best_of(lambda: control.forced_response(loop, T=t, U=ref))
    open_loop = best_of(lambda: simulate(plant, u_open))
    print(f"closed_loop, {N} samples (Plant interface, LQG with limits): {ours * 1e3:.1f} ms (goal < 50 ms)")
    print(f"same loop as one LTI system, control.forced_response:        {lti * 1e3:.1f} ms  (ratio {ours / lti:.1f}x)")
    print(
        f"open-loop plant alone, trms.plant.simulate:                   {open_loop * 1e3:.1f} ms  "
        f"(ratio {ours / open_loop:.1f}x)"
    )
    c_y = control.ss(comp.A, comp.B[:, 1:2], comp.C, comp.D[:, 1:2], comp.dt)
    at_input = control.series(control.ss(model), -c_y)
    disk = best_of(lambda: disk_margin(at_input))
    shaper = best_of(lambda: discrete_shaper([(0.34, 0.041)], 0.2, kind="zvd").apply(ref))
    print(f"disk_margin of the loop at the plant input:                   {disk * 1e3:.1f} ms")
    print(f"ZVD shaper designed on the 0.2 s grid and applied, {N} samples: {shaper * 1e3:.2f} ms")


if __name__ == "__main__":
    main()
