"""Test-wide settings: headless rendering, one BLAS thread per test process.

(A RuntimeWarning raised by trms is a failure: pyproject.toml's pytest ``filterwarnings``.)
The suite runs one test process per core (pytest-xdist); a multi-threaded BLAS in each would oversubscribe
the cores. Set before numpy is imported; a value the user exported is kept.
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
