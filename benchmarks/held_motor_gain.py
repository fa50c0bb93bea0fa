"""The thesis's calibration with the main motor gain held at a more physical value (run on demand, minutes each).

    python benchmarks/held_motor_gain.py 1.1 2.0 2.6

For each gain (1/V; Feedback's published k1/T10 is 1.1): the calibration of ``trms calibrate`` from the published
values (:func:`trms.twin.parameters.published_parameters`) with ``main_motor_gain`` held there and every other
default parameter fitted, then the verification at the ten unseen seeds. Prints the 1-DOF hover voltage, at how
many seeds each target is met (``!`` marks a target missed by the verification's rule), the fitted values and the
wall time: whether a parameterisation nearer the published rotor meets what the shipped model meets. Measured in a
fresh cache folder, so that no run reads another's verification.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

from trms.calibration import Targets, calibrate
from trms.calibration.fit import DEFAULT_FIT
from trms.twin import Twin, load_spec
from trms.twin.parameters import published_parameters, with_parameters


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("gains", type=float, nargs="+", help="main motor gains to hold (1/V)")
    args = parser.parse_args()
    os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="trms-held-gain-")
    linear = [p for p in DEFAULT_FIT if p != "main_motor_gain"]
    for gain in args.gains:
        spec = with_parameters(load_spec(), {**published_parameters(), "main_motor_gain": gain})
        t0 = time.perf_counter()
        result = calibrate(Targets.thesis(), spec, linear=linear)
        wall = time.perf_counter() - t0
        fitted = with_parameters(spec, result.values)
        hover = float(Twin("1dof", spec=fitted).operating_point.inputs[0])
        rows = result.verification.summary()
        missed = [r for r in rows if not r["met"]]
        print(
            f"main motor gain held at {gain:g} 1/V: hover {hover:.3f} V (1-DOF); {len(rows) - len(missed)}/{len(rows)} "
            f"targets met; calibration {wall:.0f} s, {result.passes} passes"
        )
        for r in rows:
            met, judged = r["met_at"]
            print(f"  {'!' if not r['met'] else ' '} {r['name']} = {r['target']:.4g} {r['unit']}: {met}/{judged}")
        print("  fitted: " + ", ".join(f"{k} {v:.4g}" for k, v in result.values.items()))


if __name__ == "__main__":
    main()
