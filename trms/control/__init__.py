"""Control toolkit of the thesis (ch. 4 and 6): command shaping, integral LQG, closed loops, metrics.

No MuJoCo here: everything works on any :class:`trms.plant.Plant`.

Modules
-------
shaping      Butterworth / elliptic command filters (SOS) and ZV / ZVD input shapers (continuous and on the grid)
realization  observer canonical realisation (the form of eq. 6.33)
lq_design    weight checks, stabilisability, integral augmentation and the current Kalman gain
lqg          integral LQG design (current estimator) and the sampled controller
pid          discrete PID (filtered derivative, setpoint weights, back-calculation, measurement filter)
pid_tuning   its tuning by constrained optimisation (margins, damping), decentralised PIDs
damping      closed-loop modes: does a design damp the plant's mode or cancel it
inversion    the thrust curve inverted at the plant input (any controller on a linearised input)
generalised_plant  the mixed-sensitivity problem with an input-disturbance channel
mpc          constrained offset-free MPC (condensed QP, OSQP: the control extra)
qp           small dense QPs: the exact active-set solution and the KKT certificate of any candidate
hinf         H-infinity mixed-sensitivity design (slycot: the control extra) and its sampled controller
loop         closed_loop(plant, controller, reference, prefilter): SAS and CSAS
metrics      per-step rise/settling/overshoot/control measures, spectral attenuation at modes
margins      symmetric disk margin of a loop (simultaneous gain and phase variation)
plots        response and control figures with the actuator limit drawn
"""

from trms.control.hinf import HinfController, HinfDesign, design_mixsyn, diagonal_weights, pitch_weights
from trms.control.loop import Controller, DiagonalController, closed_loop, deviation_limits
from trms.control.lqg import LQGController, LQGDesign, design_lqg
from trms.control.margins import DiskMargin, disk_margin
from trms.control.metrics import StepMetrics, mode_attenuation, square_wave_metrics, step_metrics
from trms.control.mpc import MPCController, mpc_for_plant
from trms.control.pid import PIDController, PIDGains
from trms.control.pid_tuning import channel_model, decentralised_pid, tune_pid
from trms.control.realization import observer_canonical, residualise

__all__ = [
    "Controller",
    "DiagonalController",
    "closed_loop",
    "deviation_limits",
    "LQGController",
    "LQGDesign",
    "design_lqg",
    "PIDController",
    "PIDGains",
    "tune_pid",
    "channel_model",
    "decentralised_pid",
    "diagonal_weights",
    "MPCController",
    "mpc_for_plant",
    "HinfController",
    "HinfDesign",
    "design_mixsyn",
    "pitch_weights",
    "DiskMargin",
    "disk_margin",
    "StepMetrics",
    "mode_attenuation",
    "square_wave_metrics",
    "step_metrics",
    "observer_canonical",
    "residualise",
]
