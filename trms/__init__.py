"""trms: a MuJoCo digital twin of the Twin Rotor MIMO System, with identification and control toolkits.

Subpackages
-----------
trms.twin            the MuJoCo twin (needs mujoco): Twin plant, linearisation, render, dm_control env
trms.identification  signals, spectra, ARX/ARMAX by PEM, NARX-RBF, validation tests
trms.control         command shaping, integral LQG, closed loops, metrics
trms.experiments     the thesis's experiments as functions of a Plant
"""

from .plant import LinearPlant, OperatingPoint, Plant, Record, simulate

__all__ = ["LinearPlant", "OperatingPoint", "Plant", "Record", "simulate"]
__version__ = "0.1.0"
