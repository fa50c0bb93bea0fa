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

Measurement filter (optional, ``tm > 0``): the PID reads ``y_f = F y`` instead of ``y``, with the second-order
filter ``F(s) = 1 / (1 + s tm + (s tm)^2 / 2)`` that Astrom and Hagglund recommend (2006, ch. 3.4), discretised by
the bilinear map (DC gain and stability kept). Beside removing noise, its phase lag is what lets a PID *damp* a
lightly damped mode that lags more than 90 deg behind the input, as the pitch's 0.34 Hz mode does on eq. (3.11): the
mode's damping grows under a controller phase near -150 deg there, which ``kp``, ``ki`` and ``kd >= 0`` alone (-90
to +90 deg) cannot give (:func:`~trms.control.pid_tuning.tune_pid` with ``min_damping``).

Anti-windup by back-calculation: while the actuator saturates, the integrator is driven back by
``(Ts / Tt) (u - v)`` towards the value at which the command leaves saturation. The tracking time
``Tt`` defaults to ``sqrt(Ti Td)`` (``Ti = kp / ki``, ``Td = kd / kp``), or ``Ti`` for a PI
(Astrom and Hagglund's rule); ``Tt = inf`` switches back-calculation off.

Tuning: :mod:`trms.control.pid_tuning` (the gains of a PID for a model; decentralised PIDs on a multivariable one).
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

from trms.control.arguments import real_array, real_vector
from trms.errors import InputError, check_in_range

__all__ = ["PIDController", "PIDGains", "pid_matrices", "DERIVATIVE_FILTER_N"]

#: Default derivative filter ``N``: the derivative gain is bounded at ``kp N`` (Astrom and Hagglund: 8 to 20).
DERIVATIVE_FILTER_N = 10.0


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
    tm : float
        Measurement filter time ``tm`` (s) of ``F(s) = 1 / (1 + s tm + (s tm)^2 / 2)``; 0: no filter.

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
    tm: float = 0.0

    def __post_init__(self) -> None:
        check_in_range("kp", self.kp, 0.0, 1e9, unit=" V/rad", low_open=True)
        check_in_range("ki", self.ki, 0.0, 1e9, unit=" V/(rad s)")
        check_in_range("kd", self.kd, 0.0, 1e9, unit=" V s/rad")
        check_in_range("N", self.N, 1.0, 1e4)
        check_in_range("b", self.b, 0.0, 1.0)
        check_in_range("c", self.c, 0.0, 1.0)
        check_in_range("tm", self.tm, 0.0, 1e4, unit=" s")

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
    """State space of the unsaturated PID: states ``[I, q]`` (and the measurement filter's two with ``tm > 0``),
    inputs ``[r, y]``, output ``u`` (module docstring)."""
    return pid_matrices(g.kp, g.ki, g.kd, g.N, g.b, g.c, g.tm, ts)


def pid_matrices(
    kp: float, ki: float, kd: float, N: float, b: float, c: float, tm: float, ts: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """State space ``(A, B, C, D)`` of the unsaturated PID (inputs ``[r, y]``, output ``u``) from plain numbers,
    unchecked (a tuner's inner loop; :class:`PIDGains` checks its fields): gains (V/rad, V/(rad s), V s/rad), the
    derivative filter ``N``, setpoint weights ``b``, ``c``, the measurement filter ``tm`` (s) and ``ts`` (s).

    Examples
    --------
    >>> A, B, C, D = pid_matrices(2.0, 0.0, 0.0, 10.0, 1.0, 0.0, 0.0, 0.1)
    >>> D.tolist()
    [[2.0, -2.0]]
    """
    tf = kd / (kp * N)
    a = tf / (tf + ts)
    gd = kd / (tf + ts)
    A = np.diag([1.0, a])
    B = np.array([[ki * ts, -ki * ts], [-gd * (1.0 - a) * c, gd * (1.0 - a)]])
    C = np.array([[1.0, 1.0]])
    D = np.array([[kp * b + gd * c, -(kp + gd)]])
    if tm == 0.0:
        return A, B, C, D
    Af, Bf, Cf, Df = _measurement_filter(tm, ts)  # y_f = Cf f + Df y
    return (
        np.block([[A, B[:, 1:] @ Cf], [np.zeros((2, 2)), Af]]),
        np.block([[B[:, :1], B[:, 1:] @ Df], [np.zeros((2, 1)), Bf]]),
        np.hstack([C, D[:, 1:] @ Cf]),
        np.hstack([D[:, :1], D[:, 1:] @ Df]),
    )


def _measurement_filter(tm: float, ts: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``F(s) = 1 / (1 + s tm + (s tm)^2 / 2)`` discretised at ``ts`` by the bilinear map: ``(A, B, C, D)``."""
    w2 = 2.0 / tm**2
    A = np.array([[0.0, 1.0], [-w2, -2.0 / tm]])
    B = np.array([[0.0], [w2]])
    C = np.array([[1.0, 0.0]])
    M = np.linalg.inv(np.eye(2) - 0.5 * ts * A)  # the bilinear map (scipy's cont2discrete, alpha = 1/2)
    return M @ (np.eye(2) + 0.5 * ts * A), ts * M @ B, C @ M, 0.5 * ts * C @ M @ B


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
        """Zero the integrator, the derivative filter and the measurement filter.

        Examples
        --------
        >>> pid = PIDController(PIDGains(kp=1.0, ki=2.0, kd=0.0), 0.1)
        >>> _ = pid.update(1.0, 0.0)
        >>> pid.reset()
        >>> pid.integral
        0.0
        """
        self._x = np.zeros(self._A.shape[0])

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
