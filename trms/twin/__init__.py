"""The MuJoCo twin of the TRMS: model loading, the Twin plant, linearisation, rendering, environments.

Importing it sets no environment variable and loads no OpenGL library: rendering chooses its backend
when a renderer is created (``MUJOCO_GL``, else OSMesa; see :mod:`trms.twin.render`).
"""

from trms.twin.disturbances import Gust, Push
from trms.twin.linearise import Linearisation
from trms.twin.model import CONFIGURATIONS, DEFAULT_MODEL_PATH, load_spec
from trms.twin.rotors import ThrustCurve
from trms.twin.sampling import check_sample_time, physics_timestep
from trms.twin.sensors import DEFAULT_COUNTS_PER_REV, Encoder
from trms.twin.twin import Twin

__all__ = [
    "CONFIGURATIONS",
    "DEFAULT_COUNTS_PER_REV",
    "DEFAULT_MODEL_PATH",
    "Encoder",
    "Gust",
    "Linearisation",
    "Push",
    "ThrustCurve",
    "Twin",
    "check_sample_time",
    "load_spec",
    "physics_timestep",
]
