"""Rerun the search that chose the 2-DOF autopilot's weights (trms.experiments.ch8_autopilot_tuning); minutes.

    python benchmarks/tune_autopilot.py [seed]

Prints the best weights, their score (below 1: every requirement met with its margin) and the shipped weights'.
"""

import sys
import time

from trms.experiments.ch8_autopilot_tuning import score, tune_autopilot
from trms.experiments.ch8_mimo_lqg import AutopilotWeights

if __name__ == "__main__":
    started = time.perf_counter()
    best = tune_autopilot(int(sys.argv[1]) if len(sys.argv) > 1 else 0)
    print(f"found:   {best}  score {score(best):.3f}  ({time.perf_counter() - started:.0f} s)")
    print(f"shipped: {AutopilotWeights()}  score {score(AutopilotWeights()):.3f}")
