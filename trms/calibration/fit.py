"""The fast inner fit: named physical parameters fitted on the twin's linearisation.

For a candidate parameter set the 1-DOF and 2-DOF twins are trimmed and linearised
(about 15 ms each). The residuals are:

* model target: the 1-DOF discrete frequency response (transport delay included) against
  the target model's, in log magnitude and phase over its phase band, the figures read
  off a model: its DC gain and the frequency and damping of its lightly damped pole pair,
  and its step's dead time and time constant by the tangent construction, read as the
  target model's own step is;
* rest target: the 2-DOF rest pose with the rotors off;
* peak targets: each target is matched one-to-one with a mode of its configuration below
  2 Hz (the assignment with the least total frequency error); the residual is the
  frequency error over the tolerance.

Targets with no mode left to match are unreachable by construction (a parameter set can
move modes, not add them) and are reported as such. Couplings (which modes a channel
shows, and how coherent it is) are fitted afterwards on the nonlinear twin
(:mod:`trms.calibration.coupling`).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import control
import mujoco
import numpy as np
import scipy.optimize

from trms.calibration.target_kinds import PeakTarget
from trms.calibration.targets import Targets
from trms.errors import DesignError, TrmsError
from trms.measurement.protocol import STEP_PROTOCOL, lightly_damped
from trms.measurement.step_response import system_step, tangent_figures
from trms.twin.model import CONFIGURATIONS, build_model
from trms.twin.parameters import PARAMETERS, read_parameters, with_parameters
from trms.twin.trim import rest_pose
from trms.twin.twin import Twin

__all__ = ["DEFAULT_FIT", "LinearFit", "LinearEvaluation", "evaluate_linear", "fit_linear"]

#: Parameters of the linear fit by default (the others keep their published values).
DEFAULT_FIT = (
    "counterweight_mass",
    "main_shield_mass",
    "pitch_damping",
    "main_motor_gain",
    "main_motor_lag",
    "input_delay",
    "cable_stiffness",
)
_MODE_BAND_HZ = (0.005, 2.0)
#: The linear fit keeps its start when the optimum it finds lowers the cost by no more than this fraction: a start
#: already at the optimum (the shipped model, whose values the file holds to 6 significant digits) is not moved by
#: the optimiser's last digits, which would make it another model to verify.
KEEP_START_GAIN = 1e-4
#: The fraction of the step tolerances the linearised step may use (the rest is room for the seeds' scatter): the
#: tangent dead time pulls against the phase (both are set by the motor lag and the transport delay), so the fit
#: holds it inside this room rather than pulling it to the target.
STEP_ROOM = 0.8


@dataclass
class LinearEvaluation:
    """The linear view of one parameter set: residuals, modes matched to peak targets, model error.

    Parameters
    ----------
    residuals : numpy.ndarray
        The weighted residuals the linear fit minimises (dimensionless: each miss over its scale).
    mode_match : dict of int to float or None
        Peak target index to the linearised mode matched to it (Hz), None when no mode is left for it.
    model_error_db : float
        RMS magnitude error of the 1-DOF linearisation against the model target over its band (dB).

    Examples
    --------
    >>> ev = LinearEvaluation(np.array([0.5, -0.2]), {0: 0.345})
    >>> float(ev.residuals @ ev.residuals), ev.mode_match
    (0.29, {0: 0.345})
    """

    residuals: np.ndarray
    mode_match: dict[int, float | None] = field(default_factory=dict)  # peak target index -> matched mode (Hz)
    model_error_db: float = float("nan")


@dataclass
class LinearFit:
    """Result of :func:`fit_linear`.

    Parameters
    ----------
    values, start : dict of str to float
        The fitted parameters after and before (SI units of :data:`~trms.twin.parameters.PARAMETERS`).
    evaluation : LinearEvaluation
        The linear view at ``values``.
    n_evaluations : int
        Linearisations the fit ran.
    cost : float
        Half the sum of squared residuals at ``values`` (dimensionless).
    unreachable : list of int
        Indices of the peak targets no mode of the model is left for.

    Examples
    --------
    >>> ev = LinearEvaluation(np.zeros(1))
    >>> fit = LinearFit({"counterweight_mass": 0.21}, {"counterweight_mass": 0.2}, ev, 8, 0.0, [])
    >>> round(fit.values["counterweight_mass"] / fit.start["counterweight_mass"], 3)
    1.05
    """

    values: dict[str, float]
    start: dict[str, float]
    evaluation: LinearEvaluation
    n_evaluations: int
    cost: float
    unreachable: list[int]


def _response(sys: control.StateSpace, f: np.ndarray, i: int, j: int) -> np.ndarray:
    """Frequency response of channel j -> i of a continuous or discrete state space at ``f`` (Hz)."""
    A, B, C = (np.asarray(m) for m in (sys.A, sys.B, sys.C))
    s = 2j * np.pi * f if not sys.isdtime() else np.exp(2j * np.pi * f * sys.dt)
    eye = np.eye(A.shape[0])
    return np.array([(C[i] @ np.linalg.solve(si * eye - A, B[:, j])) for si in s])


def _match_modes(targets: list[tuple[int, PeakTarget]], modes: list[float]) -> dict[int, float | None]:
    """One-to-one assignment of targets to modes minimising the total frequency error."""
    best: tuple[float, dict[int, float | None]] | None = None
    k = min(len(targets), len(modes))
    for chosen in itertools.combinations(range(len(targets)), k):
        for perm in itertools.permutations(range(len(modes)), k):
            cost = sum(abs(modes[m] - targets[t][1].frequency_hz) for t, m in zip(chosen, perm))
            if best is None or cost < best[0]:
                assign: dict[int, float | None] = {targets[t][0]: None for t in range(len(targets))}
                assign.update({targets[t][0]: modes[m] for t, m in zip(chosen, perm)})
                best = (cost, assign)
    return best[1] if best else {t[0]: None for t in targets}


def evaluate_linear(spec: mujoco.MjSpec, targets: Targets, skip: Sequence[int] = ()) -> LinearEvaluation:
    """Residuals of one parameter set (see the module docstring); peak targets in ``skip`` are left out.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The parameter set.
    targets : Targets
        Its peak, model and rest targets.
    skip : sequence of int
        Indices of peak targets left out.

    Returns
    -------
    LinearEvaluation

    Examples
    --------
    >>> from trms.calibration.target_kinds import PeakTarget
    >>> from trms.twin import load_spec
    >>> ev = evaluate_linear(load_spec(), Targets([PeakTarget("1dof", "u1->pitch", 0.34)]))
    >>> round(ev.mode_match[0], 1), ev.residuals.shape
    (0.3, (1,))
    """
    configs = sorted({t.config for t in targets.peaks} | ({"1dof"} if targets.model is not None else set()))
    lin = {c: Twin(c, 0.1, spec=spec).linearise() for c in configs}
    res: list[np.ndarray] = []
    ev = LinearEvaluation(np.zeros(0))

    if targets.model is not None:
        g = targets.model.system
        dt = float(g.dt)
        sys_d = lin["1dof"].discretise(dt)
        f = np.geomspace(targets.model.phase_band_hz[0], min(targets.model.phase_band_hz[1], 0.4 / dt), 40)
        h_twin = _response(sys_d, f, 0, 0)
        h_ref = np.array([complex(np.ravel(g(np.exp(2j * np.pi * fi * dt)))[0]) for fi in f])
        ratio = h_twin / h_ref
        mag = np.log(np.abs(ratio)) / 0.1
        phase = np.angle(ratio) / 0.2
        res.append(np.concatenate([mag, phase]) / np.sqrt(f.size))
        ev.model_error_db = float(np.sqrt(np.mean((20 * np.log10(np.abs(ratio))) ** 2)))
        # The figures the thesis reads off the model: DC gain, and the lightly damped pair.
        gain = np.log(float(np.ravel(control.dcgain(sys_d))[0]) / float(np.ravel(g.dcgain())[0])) / 0.05
        f_ref, z_ref = lightly_damped(g.poles(), dt)
        f_tw, z_tw = lightly_damped(np.linalg.eigvals(np.asarray(sys_d.A)), dt, near_hz=f_ref)
        res.append(np.array([gain, (f_tw - f_ref) / 0.005, (z_tw - z_ref) / 0.005]))
        # The step, read by the tangent construction on both (the twin's small-signal step is its linearisation's):
        # held within STEP_ROOM of each tolerance, free inside it (it pulls against the phase; see STEP_ROOM).
        dead_ref, lag_ref = tangent_figures(*system_step(g, STEP_PROTOCOL.duration_s))
        dead, lag = tangent_figures(*system_step(sys_d, STEP_PROTOCOL.duration_s))
        mt = targets.model
        res.append(
            np.array(
                [
                    max(0.0, abs(dead - dead_ref) - STEP_ROOM * mt.dead_time_tolerance_s) / 0.01,
                    max(0.0, abs(lag - lag_ref) - STEP_ROOM * mt.time_constant_tolerance_s) / 0.01,
                ]
            )
        )

    if targets.rest is not None:
        m = build_model(spec, CONFIGURATIONS["2dof"], delay=False)
        q = rest_pose(m)
        res.append(np.array([(float(q[m.jnt_qposadr[m.joint("pitch").id]]) - targets.rest.pitch) / 0.01]))

    by_channel: dict[tuple[str, str], list[tuple[int, PeakTarget]]] = {}
    for i, t in enumerate(targets.peaks):
        if i not in skip:
            by_channel.setdefault((t.config, t.channel), []).append((i, t))
    for (config, _channel), items in by_channel.items():
        sys_c = lin[config].continuous
        modes = [
            float(abs(lam) / (2 * np.pi))
            for lam in np.linalg.eigvals(np.asarray(sys_c.A))
            if lam.imag > 0 and _MODE_BAND_HZ[0] <= abs(lam) / (2 * np.pi) <= _MODE_BAND_HZ[1]
        ]
        assign = _match_modes(items, sorted(modes))
        for idx, t in items:
            fm = assign[idx]
            ev.mode_match[idx] = fm
            if fm is not None:
                res.append(np.array([(fm - t.frequency_hz) / t.tolerance_hz]))
    ev.residuals = np.concatenate(res) if res else np.zeros(1)
    return ev


def _transform(p: str) -> tuple[Callable[[float], float], Callable[[float], float]]:
    lo, _ = PARAMETERS[p].bounds
    if lo > 0:
        return np.log, np.exp
    return (lambda v: v), (lambda z: z)


def fit_linear(
    spec: mujoco.MjSpec,
    targets: Targets,
    fit: Sequence[str] = DEFAULT_FIT,
    max_evaluations: int = 400,
    progress: Callable[[int, float], None] | None = None,
) -> LinearFit:
    """Fit ``fit`` (parameter names) by Levenberg-Marquardt-type trust region on the linear residuals.

    Parameters are searched in log space when their bounds are positive. A candidate whose
    trim or linearisation fails (e.g. no hover within +-10 V) gets a large residual instead
    of stopping the fit. A start inside the bounds that the optimum improves on by no more than
    :data:`KEEP_START_GAIN` of its cost is returned as it is.

    Parameters
    ----------
    spec : mujoco.MjSpec
        Starting parameter set (not modified).
    targets : Targets
        Its peak, model and rest targets.
    fit : sequence of str
        Names of :data:`~trms.twin.parameters.PARAMETERS` to fit.
    max_evaluations : int
        Most linearisations.
    progress : callable, optional
        Called with ``(evaluations, cost)`` after each.

    Returns
    -------
    LinearFit

    Examples
    --------
    >>> from trms.calibration.target_kinds import PeakTarget
    >>> from trms.twin import load_spec
    >>> targets = Targets([PeakTarget("1dof", "u1->pitch", 0.34, 0.01)])
    >>> fit = fit_linear(load_spec(), targets, ["counterweight_mass"], max_evaluations=30)
    >>> abs(fit.evaluation.mode_match[0] - 0.34) < 0.01
    True
    """
    for name in fit:
        if name not in PARAMETERS:
            raise DesignError(f"unknown parameter {name!r}; known: {', '.join(PARAMETERS)}")
    start = read_parameters(spec, fit)
    fwd = [_transform(p)[0] for p in fit]
    inv = [_transform(p)[1] for p in fit]
    lo = np.array([fwd[i](PARAMETERS[p].bounds[0]) for i, p in enumerate(fit)])
    hi = np.array([fwd[i](PARAMETERS[p].bounds[1]) for i, p in enumerate(fit)])
    z0 = np.clip([fwd[i](start[p]) for i, p in enumerate(fit)], lo, hi)

    # Targets with no mode to match at the start stay unreachable (a parameter set cannot add modes).
    first = evaluate_linear(spec, targets)
    unreachable = [i for i, m in first.mode_match.items() if m is None]
    at_start = evaluate_linear(spec, targets, unreachable) if unreachable else first
    n_res = at_start.residuals.size
    count = [0]

    def values_of(z: np.ndarray) -> dict[str, float]:
        return {p: float(np.clip(inv[i](z[i]), *PARAMETERS[p].bounds)) for i, p in enumerate(fit)}

    def residual(z: np.ndarray) -> np.ndarray:
        count[0] += 1
        try:
            r = evaluate_linear(with_parameters(spec, values_of(z)), targets, unreachable).residuals
        except TrmsError:
            r = np.full(n_res, 1e3)
        if r.size != n_res:
            r = np.full(n_res, 1e3)
        if progress is not None:
            progress(count[0], float(r @ r))
        return r

    sol = scipy.optimize.least_squares(
        residual, z0, bounds=(lo, hi), x_scale=1.0, diff_step=1e-3, xtol=1e-6, ftol=1e-8, max_nfev=max_evaluations
    )
    values = values_of(sol.x)
    final = evaluate_linear(with_parameters(spec, values), targets, unreachable)
    cost, start_cost = float(final.residuals @ final.residuals), float(at_start.residuals @ at_start.residuals)
    inside = all(PARAMETERS[p].bounds[0] <= start[p] <= PARAMETERS[p].bounds[1] for p in fit)
    if inside and start_cost - cost <= KEEP_START_GAIN * start_cost:
        # The start is the optimum to within what the targets resolve: kept as it is, not moved by the last digits.
        return LinearFit(dict(start), start, at_start, count[0], start_cost, unreachable)
    return LinearFit(values, start, final, count[0], cost, unreachable)
