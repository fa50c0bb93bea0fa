"""The MuJoCo twin of the TRMS: model loading, the Twin plant, linearisation, rendering, environments."""

import os as _os

# Offscreen rendering uses OSMesa unless the user chose another backend (must be set before mujoco
# creates a GL context or dm_control is imported).
_os.environ.setdefault("MUJOCO_GL", "osmesa")
_os.environ.setdefault("PYOPENGL_PLATFORM", _os.environ["MUJOCO_GL"] if _os.environ["MUJOCO_GL"] != "egl" else "egl")

from .disturbances import Gust, Push  # noqa: E402
from .linearise import Mode  # noqa: E402
from .model import CONFIGURATIONS, DEFAULT_MODEL_PATH, load_spec  # noqa: E402
from .rotors import ThrustCurve  # noqa: E402
from .sensors import DEFAULT_COUNTS_PER_REV, Encoder  # noqa: E402
from .twin import Linearisation, Twin, check_sample_time  # noqa: E402

__all__ = [
    "CONFIGURATIONS",
    "DEFAULT_COUNTS_PER_REV",
    "DEFAULT_MODEL_PATH",
    "Encoder",
    "Gust",
    "Linearisation",
    "Mode",
    "Push",
    "ThrustCurve",
    "Twin",
    "check_sample_time",
    "load_spec",
]
