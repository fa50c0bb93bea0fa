"""A rig's files: its CSV/text and MATLAB exports read into :class:`~trms.record.Record` (:mod:`trms.rig.exports`,
on :mod:`trms.rig.text`, :mod:`trms.rig.mat` and the plausibility checks of :mod:`trms.rig.checks`), and a faked
rig of known truth whose logs check a calibration end to end (:mod:`trms.rig.faked`, above the twin).
"""

from trms.rig.exports import (
    RigDataWarning,
    hover_operating_point,
    load_record,
    read_inputs,
    record_from_csv,
    record_from_export,
    record_from_mat,
)

__all__ = [
    "RigDataWarning",
    "hover_operating_point",
    "load_record",
    "read_inputs",
    "record_from_csv",
    "record_from_export",
    "record_from_mat",
]
