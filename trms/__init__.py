"""trms: a MuJoCo digital twin of the Twin Rotor MIMO System, with identification and control toolkits.

Subpackages
-----------
trms.twin            the MuJoCo twin (needs mujoco): Twin plant, linearisation, render, control tasks
                     (Gymnasium: ``import trms.envs.gym``; dm_env suite: ``trms.envs.suite``)
trms.identification  signals, spectra, ARX/ARMAX by PEM, NARX-RBF, validation tests
trms.control         command shaping, integral LQG, closed loops, metrics
trms.experiments     the thesis's experiments as functions of a Plant
"""

from trms.plant import LinearPlant, Plant, simulate
from trms.record import OperatingPoint, Record

__all__ = ["LinearPlant", "OperatingPoint", "Plant", "Record", "simulate"]
from importlib.metadata import PackageNotFoundError as _NotInstalled
from importlib.metadata import version as _version

try:
    __version__ = _version("trms")
except _NotInstalled:  # a source tree that was never installed
    __version__ = "0+unknown"
