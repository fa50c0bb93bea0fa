"""The MuJoCo twin of the TRMS: model loading, the Twin plant, linearisation, rendering, environments.

Importing it sets no environment variable and loads no OpenGL library: rendering chooses its backend
when a renderer is created (``MUJOCO_GL``, else OSMesa; see :mod:`trms.twin.render`).
"""

from .disturbances import Gust, Push
from .linearise import Mode
from .model import CONFIGURATIONS, DEFAULT_MODEL_PATH, load_spec
from .rotors import ThrustCurve
from .sensors import DEFAULT_COUNTS_PER_REV, Encoder
from .twin import Linearisation, Twin, check_sample_time

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
