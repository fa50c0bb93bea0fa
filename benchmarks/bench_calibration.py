"""Wall time of a full calibration from three starts, and whether it converged (run on demand).

    python benchmarks/bench_calibration.py [--start shipped|published|off ...]

Runs the thesis's calibration exactly as ``trms calibrate`` does (:func:`trms.calibration.calibrate`) from:

* ``shipped``: the shipped model;
* ``published``: the published (uncalibrated) parameter values (``trms.twin.parameters.published_parameters``);
* ``off``: the shipped model with every fitted parameter moved 8-15 % off (seeded: each factor
  ``1 +- u``, ``u`` uniform in [0.08, 0.15], the sign drawn too, kept within the parameter's bounds).

For each: the wall time (goal <= 60 s on 2 cores), how it splits between the linear, ambient and spectral fits and
the verification, the whole against one verification pass, the passes, whether it converged, and whether every
target is met by the verification's rule. The benchmark measures in a fresh cache folder, so that no start reads a
verification an earlier run stored (the shipped model's own, beside it, is read as ``trms calibrate`` reads it).
Then one protocol batch is timed against the same runs made one ``Twin.run`` after another: the ratio that batching
buys.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

import numpy as np

from trms.batch.rollouts import run_open_loop_batch
from trms.calibration import Targets, calibrate
from trms.calibration.ambient import AMBIENT_PARAMETERS
from trms.calibration.coupling import DEFAULT_COUPLING
from trms.calibration.fit import DEFAULT_FIT
from trms.calibration.verify import verify
from trms.measurement.protocol import FIT_SEEDS, THESIS_PROTOCOLS
from trms.twin import Twin, load_spec
from trms.twin.parameters import PARAMETERS, published_parameters, read_parameters, with_parameters

STARTS = ("shipped", "published", "off")
#: The ``off`` start: each fitted parameter moved by a factor 1 +- u, u uniform in this range.
OFF = (0.08, 0.15)


def start_model(name: str, seed: int = 0):
    """The starting MjSpec of ``name`` (module docstring)."""
    spec = load_spec()
    if name == "published":
        return with_parameters(spec, published_parameters())
    if name == "off":
        names = list(dict.fromkeys([*DEFAULT_FIT, *AMBIENT_PARAMETERS, *DEFAULT_COUPLING]))
        rng = np.random.default_rng(seed)
        values = read_parameters(spec, names)
        moved = {}
        for n in names:
            factor = 1.0 + rng.choice((-1.0, 1.0)) * rng.uniform(*OFF)
            lo, hi = PARAMETERS[n].bounds
            moved[n] = float(np.clip(values[n] * factor, lo, hi))
        return with_parameters(spec, moved)
    return spec


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--start", nargs="+", choices=STARTS, default=list(STARTS))
    args = parser.parse_args()
    # A cache of its own: a verification stored by an earlier calibration of the same model is not measured again.
    os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="trms-bench-")
    # One verification pass, measured (a calibration of a solved start reads its stored one instead of measuring).
    t0 = time.perf_counter()
    verify(load_spec(), Targets.thesis())
    one_pass = time.perf_counter() - t0
    print(f"one verification pass of the shipped model: {one_pass:.1f} s")
    for name in args.start:
        spec = start_model(name)
        t0 = time.perf_counter()
        result = calibrate(Targets.thesis(), spec)
        wall = time.perf_counter() - t0
        t = result.timings
        met = "every target met" if result.verification.all_met else "missed: " + "; ".join(result.unreachable)
        print(
            f"calibration from the {name} start: {wall:.1f} s (goal <= 60 s), {result.passes} pass(es), "
            f"{'converged' if result.converged else 'NOT converged'}, "
            f"{met}"
        )
        print(
            f"  linear fit {t['linear_fit']:.1f} s ({result.evaluations['linear']} linearisations), "
            f"ambient fit {t['ambient_fit']:.1f} s, spectral fit {t['spectral_fit']:.1f} s "
            f"({result.evaluations['spectral']} candidates x 2 protocols x {len(FIT_SEEDS)} runs), "
            f"verification {t['verification']:.1f} s; {wall / one_pass:.2f}x one verification pass"
        )

    start = with_parameters(load_spec(), published_parameters())
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
