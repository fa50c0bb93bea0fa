"""Calibration of the twin's physical parameters against spectral and model targets.

``calibrate()`` fits named physical parameters (:mod:`trms.twin.parameters`) so the twin's
spectra put their peaks where the targets say and its identified 1-DOF model matches the
target model (the thesis's eq. 3.11 by default); ``write_report`` writes the JSON and the
figure; ``trms calibrate`` runs it from the command line (:mod:`trms.calibration.runs`). The protocols it
measures with are :mod:`trms.measurement`'s.
"""

from trms.calibration.calibrate import CalibrationResult, Progress, calibrate
from trms.calibration.checks import Check
from trms.calibration.report import format_table, write_report
from trms.calibration.targets import CoherenceTarget, ModelTarget, PeakTarget, Targets
from trms.calibration.verify import Verification, verify

__all__ = [
    "CalibrationResult",
    "Check",
    "CoherenceTarget",
    "ModelTarget",
    "PeakTarget",
    "Progress",
    "Targets",
    "Verification",
    "calibrate",
    "format_table",
    "verify",
    "write_report",
]
