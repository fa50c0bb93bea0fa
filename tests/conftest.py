"""Test-wide settings (headless rendering, one BLAS thread per test process) and the rig CSV fixture.

(A RuntimeWarning raised by trms is a failure: pyproject.toml's pytest ``filterwarnings``.)
The suite runs one test process per core (pytest-xdist); a multi-threaded BLAS in each would oversubscribe
the cores. Set before numpy is imported; a value the user exported is kept.
"""

import csv
import os

import pytest

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")


@pytest.fixture
def rig_csv(tmp_path):
    """A rig's layout: time in s, main voltage, pitch in degrees, a column the twin does not know."""
    import numpy as np  # here: the thread settings above come before numpy's first import

    t = np.arange(400) * 0.05
    u = 2.0 + np.where(t < 10, 0.0, 0.3 * np.sign(np.sin(t)))
    pitch_deg = 1.5 + np.where(t < 10, 0.0, 5.0 * np.sin(t - 10))
    path = tmp_path / "rig.csv"
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["Time [s]", "Vmain", "Pitch_deg", "Tacho"])
        w.writerows([f"{a:.6g}", f"{b:.6g}", f"{c:.6g}", "7"] for a, b, c in zip(t, u, pitch_deg))
    return path, t, u, pitch_deg
