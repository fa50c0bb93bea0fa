"""Calibration of the twin's physical parameters against spectral and model targets.

``calibrate()`` fits named physical parameters (:mod:`trms.twin.parameters`) so the twin's
spectra put their peaks where the targets say and its identified 1-DOF model matches the
target model (the thesis's eq. 3.11 by default); ``write_report`` writes the JSON and the
figure; ``trms calibrate`` runs it from the command line.
"""

from trms.calibration.calibrate import CalibrationResult, Progress, calibrate
from trms.calibration.command import add_calibrate_arguments, run_calibrate
from trms.calibration.protocol import THESIS_PROTOCOLS, Protocol
from trms.calibration.report import format_table, write_report
from trms.calibration.targets import CoherenceTarget, ModelTarget, PeakTarget, Targets
from trms.calibration.verify import Check, Verification, verify

__all__ = [
    "CalibrationResult",
    "Check",
    "CoherenceTarget",
    "ModelTarget",
    "PeakTarget",
    "Progress",
    "Protocol",
    "THESIS_PROTOCOLS",
    "Targets",
    "Verification",
    "add_calibrate_arguments",
    "calibrate",
    "format_table",
    "run_calibrate",
    "verify",
    "write_report",
]
