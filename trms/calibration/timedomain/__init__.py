"""Time-domain calibration against a rig's recorded time series, with ``mujoco.sysid``
(:func:`calibrate_records`; the whole method in :mod:`trms.calibration.timedomain.calibrate`).

calibrate       the calibration: records in, parameters, intervals and the held-out fit out
stages          its stages: the bounded fit, the feasible start, the delay profile, the disturbed refits
rig             the records as ``mujoco.sysid`` sequences, driven through the candidate's own thrust curve
feasible_start  a start inside the end stops: a Latin hypercube of candidates, the stop contacts counted
intervals       confidence intervals that hold for correlated residuals (sandwich, disturbance refits)
result          what a calibration found (:class:`TimeDomainResult`)
report          the library's HTML report, made self-contained
"""

from trms.calibration.timedomain.calibrate import DEFAULT_TIME_DOMAIN, MAX_ITERS, calibrate_records, scaled_spec
from trms.calibration.timedomain.result import TimeDomainResult

__all__ = ["DEFAULT_TIME_DOMAIN", "MAX_ITERS", "TimeDomainResult", "calibrate_records", "scaled_spec"]
