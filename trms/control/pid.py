"""Discrete PID with a filtered derivative, setpoint weighting and back-calculation anti-windup.

Continuous law (Astrom and Hagglund, *Advanced PID control*, 2006, ch. 3), on deviations
(reference ``r`` and measurement ``y`` in rad, control in V)::

    u = kp (b r - y) + ki int(r - y) dt + D,    Tf dD/dt + D = kd d(c r - y)/dt,    Tf = kd / (kp N)

``b`` and ``c`` are the setpoint weights of the proportional and derivative parts (``c = 0``:
derivative on the measurement only, no kick at a reference step); ``N`` bounds the derivative's
high-frequency gain at ``kp N`` (the derivative acts like ``kd s / (1 + s Tf)``).

Discretisation (sample time ``Ts``): forward Euler for the integral, backward difference for the
filtered derivative, so that with ``e = r - y`` and ``w = c r - y``::

    I(k+1) = I(k) + ki Ts e(k) + (Ts / Tt) (u(k) - v(k))
    D(k)   = Tf / (Tf + Ts) D(k-1) + kd / (Tf + Ts) (w(k) - w(k-1))
    v(k)   = kp (b r(k) - y(k)) + I(k) + D(k),     u(k) = clip(v(k), limits)

Without saturation the controller is ``u = C_r(z) r - C_y(z) y`` with
``C_y(z) = kp + ki Ts / (z - 1) + kd (z - 1) / ((Tf + Ts) z - Tf)`` and ``C_r`` the same with
``b kp`` and ``c kd``.

Anti-windup by back-calculation: while the actuator saturates, the integrator is driven back by
``(Ts / Tt) (u - v)`` towards the value at which the command leaves saturation. The tracking time
``Tt`` defaults to ``sqrt(Ti Td)`` (``Ti = kp / ki``, ``Td = kd / kp``), or ``Ti`` for a PI
(Astrom and Hagglund's rule); ``Tt = inf`` switches back-calculation off.

Tuning (:func:`tune_pid`): the gains minimise the integrated squared tracking error of a unit
reference step on the linear design model, plus ``effort`` times the integrated squared control,
subject to a maximum sensitivity ``max |1 / (1 + C_y G)| <= Ms`` (default 1.7, a gain margin of at
least ``Ms / (Ms - 1) = 2.4`` and a phase margin of at least ``2 asin(1 / (2 Ms)) = 34`` deg) and
a stable closed loop (the MIGO-style constrained optimisation of Astrom and Hagglund, ch. 7).
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
from dataclasses import dataclass
from typing import Any

import control
import numpy as np
from scipy.optimize import minimize

from trms.control._checks import finite_system, index_tuple, is_discrete_dt, real_array, real_vector
from trms.control.loop import DiagonalController
from trms.control.mpc import limit_pair
from trms.errors import DesignError, InputError, check_in_range

__all__ = ["PIDController", "PIDGains", "tune_pid", "channel_model", "decentralised_pid", "DERIVATIVE_FILTER_N"]

#: Default derivative filter ``N``: the derivative gain is bounded at ``kp N`` (Astrom and Hagglund: 8 to 20).
DERIVATIVE_FILTER_N = 10.0
#: Starting grid of :func:`tune_pid`: ``kp, ki, kd`` times the model's static gain (dimensionless, 1/s, s).
_GRID = (np.logspace(-2, 1, 7), np.logspace(-3, 0, 4), np.logspace(-2, 1, 7))


@dataclass(frozen=True)
class PIDGains:
    """PID parameters (see the module docstring).

    Attributes
    ----------
    kp : float
        Proportional gain (V/rad), ``> 0``.
    ki : float
        Integral gain (V/(rad s)), ``>= 0``.
    kd : float
        Derivative gain (V s/rad), ``>= 0``.
    N : float
        Derivative filter: ``Tf = kd / (kp N)``.
    b, c : float
        Setpoint weights of the proportional and the derivative parts, in ``[0, 1]``.

    Raises
    ------
    InputError
        A gain, ``N`` or weight outside its range.

    Examples
    --------
    ``Tf = kd / (kp N) = 0.4 / (2 x 10)`` and the tracking time ``sqrt(Ti Td) = sqrt(4 x 0.2)``:

    >>> g = PIDGains(kp=2.0, ki=0.5, kd=0.4)
    >>> round(g.filter_time, 12), round(g.default_tracking_time(), 6)
    (0.02, 0.894427)
    """

    kp: float
    ki: float
    kd: float
    N: float = DERIVATIVE_FILTER_N
    b: float = 1.0
    c: float = 0.0

    def __post_init__(self) -> None:
        check_in_range("kp", self.kp, 0.0, 1e9, unit=" V/rad", low_open=True)
        check_in_range("ki", self.ki, 0.0, 1e9, unit=" V/(rad s)")
        check_in_range("kd", self.kd, 0.0, 1e9, unit=" V s/rad")
        check_in_range("N", self.N, 1.0, 1e4)
        check_in_range("b", self.b, 0.0, 1.0)
        check_in_range("c", self.c, 0.0, 1.0)

    @property
    def filter_time(self) -> float:
        """Derivative filter time constant ``Tf = kd / (kp N)`` (s).

        Examples
        --------
        >>> PIDGains(kp=1.0, ki=0.0, kd=0.5, N=5.0).filter_time
        0.1
        """
        return float(self.kd / (self.kp * self.N))

    def default_tracking_time(self) -> float:
        """Back-calculation tracking time (s): ``sqrt(Ti Td)``, ``Ti`` without derivative, ``inf`` without integral.

        Examples
        --------
        ``Ti = kp / ki`` for a PI; no integral, nothing to track:

        >>> PIDGains(kp=2.0, ki=0.5, kd=0.0).default_tracking_time(), PIDGains(1.0, 0.0, 0.0).default_tracking_time()
        (4.0, inf)
        """
        if self.ki == 0.0:
            return float("inf")
        ti = self.kp / self.ki
        return float(np.sqrt(ti * self.kd / self.kp)) if self.kd > 0.0 else float(ti)


def _matrices(g: PIDGains, ts: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """State space of the unsaturated PID: states ``[I, q]``, inputs ``[r, y]``, output ``u`` (module docstring)."""
    tf = g.filter_time
    a = tf / (tf + ts)
    gd = g.kd / (tf + ts)
    A = np.diag([1.0, a])
    B = np.array([[g.ki * ts, -g.ki * ts], [-gd * (1.0 - a) * g.c, gd * (1.0 - a)]])
    C = np.array([[1.0, 1.0]])
    D = np.array([[g.kp * g.b + gd * g.c, -(g.kp + gd)]])
    return A, B, C, D


class PIDController:
    """The discrete PID as a sampled controller of one output and one input (module docstring).

    Parameters
    ----------
    gains : PIDGains
        The gains, filter and setpoint weights.
    sample_time : float
        Controller sample time ``Ts`` (s).
    input_limits : tuple of float, optional
        Actuator limits in *deviation* volts (``lower <= 0 <= upper``), e.g.
        :func:`trms.control.loop.deviation_limits`; unlimited by default.
    tracking_time : float, optional
        Back-calculation tracking time ``Tt`` (s); default :meth:`PIDGains.default_tracking_time`;
        ``inf`` disables back-calculation.

    Examples
    --------
    A P-controller with ``b = 1`` returns ``kp (r - y)``, clipped at the limits:

    >>> pid = PIDController(PIDGains(kp=2.0, ki=0.0, kd=0.0), 0.1, input_limits=(-1.0, 1.0))
    >>> float(pid.update(0.2, 0.0)[0]), float(pid.update(1.0, 0.0)[0])
    (0.4, 1.0)
    """

    def __init__(
        self,
        gains: PIDGains,
        sample_time: float,
        input_limits: tuple[object, object] | None = None,
        tracking_time: float | None = None,
    ) -> None:
        if not isinstance(gains, PIDGains):
            raise InputError(f"gains must be a PIDGains, got {type(gains).__name__}")
        self.gains = gains
        self._ts = check_in_range("sample_time", sample_time, 0.0, 1e3, unit=" s", low_open=True)
        lower, upper = (-np.inf, np.inf) if input_limits is None else _limits(input_limits)
        self.input_limits = (float(lower), float(upper))
        tt = gains.default_tracking_time() if tracking_time is None else tracking_time
        inf = isinstance(tt, (float, np.floating)) and tt == np.inf
        self.tracking_time = np.inf if inf else check_in_range("tracking_time", tt, 0.0, 1e9, unit=" s", low_open=True)
        self._A, self._B, self._C, self._D = _matrices(gains, self._ts)
        self._aw = 0.0 if np.isinf(self.tracking_time) else self._ts / self.tracking_time
        self.reset()

    @property
    def sample_time(self) -> float:
        """Controller sample time (s).

        Examples
        --------
        >>> PIDController(PIDGains(kp=1.0, ki=0.0, kd=0.0), 0.2).sample_time
        0.2
        """
        return self._ts

    @property
    def integral(self) -> float:
        """The integrator state ``I`` (V) used at the next update.

        Examples
        --------
        Two samples of a unit error with ``ki = 2 V/(rad s)`` at 0.1 s integrate to 0.4 V:

        >>> pid = PIDController(PIDGains(kp=1.0, ki=2.0, kd=0.0), 0.1)
        >>> _ = pid.update(1.0, 0.0), pid.update(1.0, 0.0)
        >>> round(pid.integral, 12)
        0.4
        """
        return float(self._x[0])

    def reset(self) -> None:
        """Zero the integrator and the derivative filter.

        Examples
        --------
        >>> pid = PIDController(PIDGains(kp=1.0, ki=2.0, kd=0.0), 0.1)
        >>> _ = pid.update(1.0, 0.0)
        >>> pid.reset()
        >>> pid.integral
        0.0
        """
        self._x = np.zeros(2)

    def update(self, reference: object, measurement: object) -> np.ndarray:
        """One sample: control from the reference and measurement (deviation rad); returns ``(1,)`` deviation V.

        Raises
        ------
        InputError
            A reference or measurement that is not one real, finite number.

        Examples
        --------
        A PI (``kp = 1``, ``ki = 2``, ``Ts = 0.1 s``) on a constant unit error ramps by ``ki Ts = 0.2 V`` a sample:

        >>> pid = PIDController(PIDGains(kp=1.0, ki=2.0, kd=0.0), 0.1)
        >>> [round(float(pid.update(1.0, 0.0)[0]), 12) for _ in range(3)]
        [1.0, 1.2, 1.4]
        """
        r = float(real_vector("reference (deviation rad)", reference, 1)[0])
        y = float(real_vector("measurement (deviation rad)", measurement, 1)[0])
        w = np.array([r, y])
        v = float(self._C[0] @ self._x + self._D[0] @ w)
        u = min(max(v, self.input_limits[0]), self.input_limits[1])
        self._x = self._A @ self._x + self._B @ w
        self._x[0] += self._aw * (u - v)
        return np.array([u])

    def compensator(self) -> control.StateSpace:
        """The unsaturated controller: inputs ``[r, y]`` (deviation rad), output ``u`` (deviation V), ``dt = Ts``.

        ``u = C_r r - C_y y``: ``compensator()[0, 0]`` is ``C_r`` and ``-compensator()[0, 1]`` is ``C_y``.

        Examples
        --------
        A P-controller with ``b = 1`` is the static ``u = kp r - kp y``:

        >>> pid = PIDController(PIDGains(kp=2.0, ki=0.0, kd=0.0), 0.1)
        >>> pid.compensator().D.tolist(), pid.compensator().dt
        ([[2.0, -2.0]], 0.1)
        """
        return control.ss(*_matrices(self.gains, self._ts), self._ts, inputs=["r", "y"], outputs=["u"], name="pid")


def _limits(value: object) -> tuple[float, float]:
    if not isinstance(value, (tuple, list)) or len(value) != 2:
        raise InputError(f"input_limits must be a pair (lower, upper) of deviation volts, got {value!r}")
    lo, hi = (float(np.ravel(real_array(f"input_limits {s}", v, infinite=True))[0]) for s, v in zip("lu", value))
    if not lo <= 0.0 <= hi or lo >= hi:
        raise InputError(
            f"input_limits (deviation V) must satisfy lower <= 0 <= upper and lower < upper, got {lo}, {hi}"
        )
    return lo, hi


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
) -> PIDGains:
    """Tune a PID on a discrete SISO model by constrained optimisation (module docstring).

    Cost ``J = Ts sum_k (1 - y_k)^2 + effort Ts sum_k u_k^2`` over ``horizon`` seconds of the unit
    reference step response (no saturation), minimised over ``log kp, log ki, log kd`` by Nelder-Mead from the
    two best points of a fixed grid of 196, with the penalty ``1e3 (max|S| - Ms)^2`` when the maximum
    sensitivity exceeds ``Ms`` and an infinite cost when the loop is unstable. Deterministic.

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

    Returns
    -------
    PIDGains

    Raises
    ------
    DesignError
        No start gives a stable loop.

    Examples
    --------
    A PI on a lag of static gain 1 keeps the peak of ``|S| = |1 / (1 + C_y G)|`` within ``Ms = 1.7``:

    >>> model = control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)
    >>> g = tune_pid(model, horizon=3.0)
    >>> loop = control.series(model, -PIDController(g, 0.1).compensator()[0, 1])  # C_y G
    >>> z = np.exp(1j * np.linspace(1e-3, np.pi, 2000))
    >>> g.kp > 0 and g.ki > 0, bool(np.max(np.abs(1.0 / (1.0 + loop(z)))) <= 1.7)
    (True, True)
    """
    A, B, C, ts = _siso_discrete(model)
    Ms = check_in_range("Ms", Ms, 1.2, 4.0)
    effort = check_in_range("effort", effort, 0.0, 1e6, unit=" rad^2/V^2")
    horizon = check_in_range("horizon", horizon, 10 * ts, 1e5, unit=" s")
    steps = int(round(horizon / ts))
    n = A.shape[0]
    z = np.exp(1j * np.linspace(1e-4, np.pi, 600))
    Gz = (C @ np.linalg.solve(z[:, None, None] * np.eye(n) - A, np.broadcast_to(B, (z.size, n, 1))))[:, 0, 0]
    low = Gz[0]  # the gain at the lowest frequency of the grid sets the scale of the starting gains
    if low.real <= 0:
        raise DesignError(f"model has a low-frequency gain {low.real:.6g} rad/V; tune_pid needs a positive one")
    dc = abs(low)

    def cost(theta: np.ndarray) -> float:
        kp, ki, kd = np.exp(np.clip(theta, -20, 12))
        g = PIDGains(kp, ki, kd, N, b, c)
        Ac, Bc, Cc, Dc = _matrices(g, ts)
        # closed loop: plant x+ = A x + B u, y = C x; controller xc+ = Ac xc + Bc [r; y], u = Cc xc + Dc [r; y]
        Acl = np.block([[A + B @ Dc[:, 1:] @ C, B @ Cc], [Bc[:, 1:] @ C, Ac]])
        Bcl = np.vstack([B @ Dc[:, :1], Bc[:, :1]])
        if np.max(np.abs(np.linalg.eigvals(Acl))) >= 1.0:
            return 1e12
        Ccl_y = np.hstack([C, np.zeros((1, 2))])
        Ccl_u = np.hstack([Dc[:, 1:] @ C, Cc])
        x = _step_states(Acl, Bcl[:, 0], steps)
        y = x @ Ccl_y[0]
        u = x @ Ccl_u[0] + float(Dc[0, 0])
        J = float(np.sum((1.0 - y) ** 2 + effort * u * u))
        Cy = -(Cc[0, 0] * Bc[0, 1] / (z - Ac[0, 0]) + Cc[0, 1] * Bc[1, 1] / (z - Ac[1, 1]) + Dc[0, 1])  # Ac diagonal
        peak = float(np.max(np.abs(1.0 / (1.0 + Cy * Gz))))
        return ts * J + (1e3 * (peak - Ms) ** 2 if peak > Ms else 0.0)

    grid = [np.log(np.array([kp, ki, kd]) / dc) for kp in _GRID[0] for ki in _GRID[1] for kd in _GRID[2]]
    values = np.array([cost(theta) for theta in grid])
    best: tuple[float, np.ndarray] | None = None
    for i in np.argsort(values)[:2]:
        if values[i] >= 1e12:
            break
        res = minimize(cost, grid[i], method="Nelder-Mead", options={"xatol": 1e-4, "fatol": 1e-9, "maxiter": 400})
        if best is None or res.fun < best[0]:
            best = (float(res.fun), res.x)
    if best is None or best[0] >= 1e12:
        raise DesignError("no PID from the starting grid stabilises the model; it may need a sign or a slower loop")
    kp, ki, kd = (float(v) for v in np.exp(best[1]))
    return PIDGains(kp, ki, kd, N, b, c)


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
