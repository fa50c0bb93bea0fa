"""Tuning PIDs on a model: the gains of one loop by constrained optimisation, decentralised loops on a multivariable
model.

Tuning (:func:`tune_pid`): the gains minimise the integrated squared tracking error of a unit
reference step on the linear design model, plus ``effort`` times the integrated squared control,
subject to a maximum sensitivity ``max |1 / (1 + C_y G)| <= Ms`` (default 1.7, a gain margin of at
least ``Ms / (Ms - 1) = 2.4`` and a phase margin of at least ``2 asin(1 / (2 Ms)) = 34`` deg),
a stable closed loop (the MIGO-style constrained optimisation of Astrom and Hagglund, ch. 7) and,
when asked, a least closed-loop damping ratio ``min_damping`` (the measurement filter's ``tm`` then tuned too).
The SIMC rule from a first-order-plus-dead-time fit is not used: the pitch axis is a lightly damped
pendulum (poles at ``|z| = 0.98``), which no first-order fit describes.

Several outputs (:func:`decentralised_pid`): one such PID per pair (output ``i``, input ``j``), each tuned by
:func:`tune_pid` on its own channel ``G_ij`` of the multivariable model (:func:`channel_model`) and run side by
side in a :class:`~trms.control.loop.DiagonalController`, each with its input's limits and its own
back-calculation. The coupling between channels is not designed for: each loop meets the others' effect on its
output as a disturbance (the decentralised baseline).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import control
import numpy as np
from scipy.optimize import minimize

from trms.control._checks import finite_system, index_tuple, is_discrete_dt
from trms.control.limits import limit_pair
from trms.control.loop import DiagonalController
from trms.control.pid import DERIVATIVE_FILTER_N, PIDController, PIDGains, pid_matrices
from trms.errors import DesignError, InputError, check_in_range

__all__ = ["tune_pid", "channel_model", "decentralised_pid"]

#: Starting grid of :func:`tune_pid`: ``kp, ki, kd`` times the model's static gain (dimensionless, 1/s, s).
_GRID = (np.logspace(-2, 1, 7), np.logspace(-3, 0, 4), np.logspace(-2, 1, 7))
#: Starting values of the measurement filter's ``tm`` (sample times) when :func:`tune_pid` constrains the damping.
_FILTER_GRID = (1.0, 2.5, 5.0, 10.0)


def _siso_discrete(model: object) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    if not isinstance(model, control.StateSpace) or not is_discrete_dt(model.dt):
        raise InputError(f"model must be a discrete python-control StateSpace (dt > 0 s), got {model!r:.60}")
    if model.ninputs != 1 or model.noutputs != 1:
        raise InputError(f"model must be SISO (one input, one output), got {model.noutputs}x{model.ninputs}")
    A, B, C, D = finite_system(model, "model")
    if np.any(D != 0):
        raise DesignError(f"model has a direct term D = {D.tolist()}; a sampled loop needs D = 0")
    return A, B, C, float(model.dt)


def _step_states(A: np.ndarray, b: np.ndarray, steps: int) -> np.ndarray:
    """States ``x_0 .. x_{steps-1}`` of ``x_{k+1} = A x_k + b`` from ``x_0 = 0`` (rows): ``x_k = sum_{j<k} A^j b``,
    the terms ``A^j b`` doubled in blocks (``log2(steps)`` matrix products instead of a loop per step)."""
    terms = b[None, :]
    power = A
    while terms.shape[0] < steps - 1:
        terms = np.vstack([terms, terms @ power.T])
        power = power @ power
    return np.vstack([np.zeros((1, b.size)), np.cumsum(terms[: steps - 1], axis=0)])


def tune_pid(
    model: control.StateSpace,
    Ms: float = 1.7,
    effort: float = 0.01,
    horizon: float = 30.0,
    N: float = DERIVATIVE_FILTER_N,
    b: float = 1.0,
    c: float = 0.0,
    min_damping: float = 0.0,
    damping_band: tuple[float, float] = (0.0, np.inf),
) -> PIDGains:
    """Tune a PID on a discrete SISO model by constrained optimisation (module docstring).

    Cost ``J = Ts sum_k (1 - y_k)^2 + effort Ts sum_k u_k^2`` over ``horizon`` seconds of the unit
    reference step response (no saturation), minimised over ``log kp, log ki, log kd`` by Nelder-Mead from the
    two best points of a fixed grid of 196, with the penalty ``1e3 (max|S| - Ms)^2`` when the maximum
    sensitivity exceeds ``Ms`` and an infinite cost when the loop is unstable. Deterministic.

    With ``min_damping > 0`` the measurement filter's ``tm`` is tuned too (``log tm`` a fourth variable, the grid
    times :data:`_FILTER_GRID` sample times) and the penalty ``1e4 (1.05 min_damping - zeta)^2`` keeps the least
    damping ratio ``zeta`` of the closed loop's oscillatory poles above ``min_damping`` (aimed 5 % above it, so that
    the optimum, which sits on the constraint, meets it).

    Parameters
    ----------
    model : control.StateSpace
        Discrete, SISO, ``D = 0`` (deviation V in, deviation rad out), e.g.
        :func:`trms.worlds.design_model`.
    Ms : float
        Largest allowed maximum sensitivity, in ``[1.2, 4]``.
    effort : float
        Weight on the control (rad^2 / V^2), ``>= 0``.
    horizon : float
        Length of the simulated step response (s).
    N, b, c : float
        Derivative filter and setpoint weights of the result (:class:`PIDGains`).
    min_damping : float
        Least damping ratio of the closed loop's oscillatory poles (-), in ``[0, 0.7]``; 0: no constraint and no
        measurement filter.
    damping_band : tuple of float
        The constraint counts the poles whose natural frequency lies in this band (Hz), e.g. around the mode the
        loop must damp when the model has others it cannot reach; every oscillatory pole by default.

    Returns
    -------
    PIDGains

    Raises
    ------
    DesignError
        No start gives a stable loop, or none meets ``min_damping``.

    Examples
    --------
    A PI on a lag of static gain 1 keeps the peak of ``|S| = |1 / (1 + C_y G)|`` within ``Ms = 1.7``:

    >>> model = control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)
    >>> g = tune_pid(model, horizon=3.0)
    >>> loop = control.series(model, -PIDController(g, 0.1).compensator()[0, 1])  # C_y G
    >>> z = np.exp(1j * np.linspace(1e-3, np.pi, 2000))
    >>> g.kp > 0 and g.ki > 0, bool(np.max(np.abs(1.0 / (1.0 + loop(z)))) <= 1.7)
    (True, True)

    On eq. (3.11) a PID alone leaves the 0.34 Hz pitch mode at damping 0.065; with its measurement filter tuned it
    damps the mode to 0.1:

    >>> from trms.control.damping import mode_damping
    >>> from trms.worlds import design_model
    >>> m = design_model("1dof")
    >>> g = tune_pid(m, min_damping=0.1)
    >>> k = -PIDController(g, 0.2).compensator()[0, 1]
    >>> g.tm > 0, bool(mode_damping(m, k).closed.damping >= 0.1)
    (True, True)
    """
    A, B, C, ts = _siso_discrete(model)
    Ms = check_in_range("Ms", Ms, 1.2, 4.0)
    effort = check_in_range("effort", effort, 0.0, 1e6, unit=" rad^2/V^2")
    horizon = check_in_range("horizon", horizon, 10 * ts, 1e5, unit=" s")
    min_damping = check_in_range("min_damping", min_damping, 0.0, 0.7)
    lo_hz, hi_hz = (float(v) for v in damping_band)
    if not (0.0 <= lo_hz < hi_hz) or np.isnan(hi_hz):
        raise InputError(f"damping_band must be (low, high) Hz with 0 <= low < high, got {damping_band!r}")
    band = (lo_hz, hi_hz)
    steps = int(round(horizon / ts))
    n = A.shape[0]
    z = np.exp(1j * np.linspace(1e-4, np.pi, 600))
    Gz = (C @ np.linalg.solve(z[:, None, None] * np.eye(n) - A, np.broadcast_to(B, (z.size, n, 1))))[:, 0, 0]
    low = Gz[0]  # the gain at the lowest frequency of the grid sets the scale of the starting gains
    if low.real <= 0:
        raise DesignError(f"model has a low-frequency gain {low.real:.6g} rad/V; tune_pid needs a positive one")
    dc = abs(low)
    filtered = min_damping > 0.0
    bilinear = 2.0 / ts * (z - 1.0) / (z + 1.0)  # s of the bilinear map on the grid

    def values_of(theta: np.ndarray) -> tuple[float, float, float, float]:
        kp, ki, kd = (float(v) for v in np.exp(np.clip(theta[:3], -20, 12)))
        return kp, ki, kd, float(np.exp(np.clip(theta[3], -10, 8))) if filtered else 0.0

    def cost(theta: np.ndarray) -> float:
        kp, ki, kd, tm = values_of(theta)
        Ac, Bc, Cc, Dc = pid_matrices(kp, ki, kd, N, b, c, tm, ts)
        nc = Ac.shape[0]
        # closed loop: plant x+ = A x + B u, y = C x; controller xc+ = Ac xc + Bc [r; y], u = Cc xc + Dc [r; y]
        Acl = np.block([[A + B @ Dc[:, 1:] @ C, B @ Cc], [Bc[:, 1:] @ C, Ac]])
        Bcl = np.vstack([B @ Dc[:, :1], Bc[:, :1]])
        poles = np.linalg.eigvals(Acl)
        if np.max(np.abs(poles)) >= 1.0:
            return 1e12
        Ccl_y = np.hstack([C, np.zeros((1, nc))])
        Ccl_u = np.hstack([Dc[:, 1:] @ C, Cc])
        x = _step_states(Acl, Bcl[:, 0], steps)
        y = x @ Ccl_y[0]
        u = x @ Ccl_u[0] + float(Dc[0, 0])
        J = float(np.sum((1.0 - y) ** 2 + effort * u * u))
        # C_y of the PID alone (its two states are decoupled), times the measurement filter's bilinear response
        Ap, Bp, Cp, Dp = pid_matrices(kp, ki, kd, N, b, c, 0.0, ts) if filtered else (Ac, Bc, Cc, Dc)
        Cy = -(Cp[0, 0] * Bp[0, 1] / (z - Ap[0, 0]) + Cp[0, 1] * Bp[1, 1] / (z - Ap[1, 1]) + Dp[0, 1])
        if filtered:
            sz = tm * bilinear
            Cy = Cy / (1.0 + sz + 0.5 * sz * sz)
        peak = float(np.max(np.abs(1.0 / (1.0 + Cy * Gz))))
        penalty = 1e3 * (peak - Ms) ** 2 if peak > Ms else 0.0
        if filtered:
            zeta = _least_damping(poles, ts, band)
            penalty += 1e4 * (1.05 * min_damping - zeta) ** 2 if zeta < 1.05 * min_damping else 0.0
        return ts * J + penalty

    grid = [np.log(np.array([kp, ki, kd]) / dc) for kp in _GRID[0] for ki in _GRID[1] for kd in _GRID[2]]
    if filtered:
        grid = [np.r_[theta, np.log(k * ts)] for theta in grid for k in _FILTER_GRID]
    values = np.array([cost(theta) for theta in grid])
    best: tuple[float, np.ndarray] | None = None
    for i in np.argsort(values)[:2]:
        if values[i] >= 1e12:
            break
        res = minimize(
            cost, grid[i], method="Nelder-Mead", options={"xatol": 1e-4, "fatol": 1e-9, "maxiter": 400 * len(grid[i])}
        )
        if best is None or res.fun < best[0]:
            best = (float(res.fun), res.x)
    if best is None or best[0] >= 1e12:
        raise DesignError("no PID from the starting grid stabilises the model; it may need a sign or a slower loop")
    result = PIDGains(*values_of(best[1])[:3], N, b, c, values_of(best[1])[3])
    if filtered:
        Ac, Bc, Cc, Dc = pid_matrices(result.kp, result.ki, result.kd, N, b, c, result.tm, ts)
        zeta = _least_damping(
            np.linalg.eigvals(np.block([[A + B @ Dc[:, 1:] @ C, B @ Cc], [Bc[:, 1:] @ C, Ac]])), ts, band
        )
        if zeta < min_damping:
            raise DesignError(
                f"no PID with a measurement filter found gives the closed loop a damping ratio of {min_damping:g}; "
                f"the best reached {zeta:.4f} (allowed: min_damping up to what the plant admits)"
            )
    return result


def _least_damping(poles: np.ndarray, ts: float, band: tuple[float, float] = (0.0, np.inf)) -> float:
    """Least damping ratio (-) of the oscillatory discrete poles (``Im z > 0``) whose natural frequency lies in
    ``band`` (Hz); 1 when there is none."""
    osc = poles[poles.imag > 1e-12]
    s = np.log(osc) / ts
    hz = np.abs(s) / (2.0 * np.pi)
    s = s[(hz >= band[0]) & (hz <= band[1])]
    if s.size == 0:
        return 1.0
    return float(np.min(-s.real / np.abs(s)))


def channel_model(model: control.StateSpace, output: int, input: int) -> control.StateSpace:
    """The SISO channel ``G_ij`` (input ``input`` to output ``output``) of a discrete multivariable model.

    Parameters
    ----------
    model : control.StateSpace
        Discrete (``dt > 0`` s), ``D = 0`` (deviation V in, deviation rad out).
    output, input : int
        Indices of the channel's output and input.

    Returns
    -------
    control.StateSpace
        ``(A, B[:, input], C[output], 0)`` at the model's sample time, with its labels.

    Raises
    ------
    InputError
        Not a discrete StateSpace, an index out of range.

    Examples
    --------
    >>> m = control.ss(np.diag([0.9, 0.5]), [[1.0, 0.0], [0.0, 2.0]], np.eye(2), np.zeros((2, 2)), 0.1)
    >>> g = channel_model(m, 1, 1)
    >>> g.B.ravel().tolist(), g.C.ravel().tolist(), g.dt
    ([0.0, 2.0], [0.0, 1.0], 0.1)
    """
    if not isinstance(model, control.StateSpace) or not is_discrete_dt(model.dt):
        raise InputError(f"model must be a discrete python-control StateSpace (dt > 0 s), got {model!r:.60}")
    A, B, C, _ = finite_system(model, "model")
    (i,) = index_tuple("channel output", (output,), C.shape[0], "output index")
    (j,) = index_tuple("channel input", (input,), B.shape[1], "input index")
    return control.ss(
        A,
        B[:, [j]],
        C[[i]],
        np.zeros((1, 1)),
        model.dt,
        states=list(model.state_labels),
        inputs=[model.input_labels[j]],
        outputs=[model.output_labels[i]],
    )


def decentralised_pid(
    model: control.StateSpace,
    input_limits: tuple[object, object] | None = None,
    gains: Sequence[PIDGains] | None = None,
    pairs: Sequence[tuple[int, int]] | None = None,
    **tuning: Any,
) -> DiagonalController:
    """Independent PID loops on a multivariable model, each tuned on its own channel (module docstring).

    Parameters
    ----------
    model : control.StateSpace
        Discrete, ``D = 0``, ``p`` outputs and ``m`` inputs (e.g. :func:`trms.worlds.design_model` ``("2dof")``:
        pitch from the main rotor u1, yaw from the tail rotor u2).
    input_limits : tuple of array_like, optional
        ``(lower, upper)`` deviation volts of the ``m`` inputs (scalars or ``(m,)``, e.g.
        :func:`trms.control.loop.deviation_limits`); unlimited by default.
    gains : sequence of PIDGains, optional
        One per pair; default :func:`tune_pid` on each pair's :func:`channel_model` with ``tuning``.
    pairs : sequence of tuple of int, optional
        ``(output, input)`` of each loop; default ``(0, 0), (1, 1), ...`` (the diagonal, ``min(p, m)`` loops).
    **tuning
        Options of :func:`tune_pid` (``Ms``, ``effort``, ``horizon``, ``N``, ``b``, ``c``).

    Returns
    -------
    trms.control.loop.DiagonalController
        Loop ``k`` reads reference ``k`` and output ``pairs[k][0]`` and drives input ``pairs[k][1]``.

    Raises
    ------
    InputError
        A pair out of range, an input driven by two loops, gains not one per pair, bad limits.
    DesignError
        A channel no PID from :func:`tune_pid`'s grid stabilises.

    Examples
    --------
    Two lags coupled by 0.1: each loop's integral action holds its own output at its reference:

    >>> m = control.ss(np.diag([0.9, 0.8]), [[0.1, 0.0], [0.01, 0.2]], np.eye(2), np.zeros((2, 2)), 0.1)
    >>> pid = decentralised_pid(m, (-10.0, 10.0), horizon=3.0)
    >>> x = np.zeros(2)
    >>> for _ in range(300):
    ...     x = m.A @ x + m.B @ pid.update([0.1, -0.2], x)
    >>> np.round(x, 4).tolist(), pid.inputs
    ([0.1, -0.2], (0, 1))
    """
    if not isinstance(model, control.StateSpace) or not is_discrete_dt(model.dt):
        raise InputError(f"model must be a discrete python-control StateSpace (dt > 0 s), got {model!r:.60}")
    p, m = model.noutputs, model.ninputs
    if pairs is None:
        pairs = [(k, k) for k in range(min(p, m))]
    if not isinstance(pairs, (list, tuple)) or not all(isinstance(q, (tuple, list)) and len(q) == 2 for q in pairs):
        raise InputError(f"pairs must be (output, input) index pairs, got {pairs!r:.80}")
    outputs = index_tuple("loop outputs", [q[0] for q in pairs], p, "output indices")
    inputs = index_tuple("loop inputs", [q[1] for q in pairs], m, "input indices")
    if gains is None:
        gains = [tune_pid(channel_model(model, i, j), **tuning) for i, j in zip(outputs, inputs)]
    elif len(gains) != len(pairs) or not all(isinstance(g, PIDGains) for g in gains):
        raise InputError(f"gains must be one PIDGains per pair ({len(pairs)}), got {gains!r:.80}")
    lo, hi = limit_pair("input_limits", input_limits, m)
    loops = [PIDController(g, float(model.dt), (lo[j], hi[j])) for g, j in zip(gains, inputs)]
    return DiagonalController(loops, outputs, inputs, m)
