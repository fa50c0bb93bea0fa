"""Integral LQG: LQR on a model augmented with the integrated tracking error, and a current estimator.

Thesis ch. 6.3-6.7. The design model is a discrete state space ``x(k+1) = A x(k) + B u(k)``,
``y(k) = C x(k)`` (strictly proper: a sampled controller cannot honour a direct term
without an algebraic loop, so ``D`` must be 0; use eq. (3.11), not the one-sample-ahead
eq. (6.33)). Units are those of the model: deviation volts in, deviation radians out.

Regulator
    One integral state per tracked output, ``xi(k+1) = xi(k) + r(k) - y_t(k)`` (no ``Ts``
    factor, as in Franklin, Powell and Workman, the thesis's ref. [85]). The augmented pair
    ``Aa = [[A, 0], [-C_t, I]]``, ``Ba = [[B], [0]]`` is regulated by ``u = -K [x; xi]`` with
    ``K`` from the discrete Riccati equation (6.35) (python-control ``dlqr``); the cost
    ``J = sum_k x_a' Q x_a + u' R u`` from ``x_a(0)`` is ``x_a(0)' P x_a(0)``.

Estimator (eq. 6.12-6.14, the *current* estimator)
    ``x_hat(k) = x_bar(k) + Lc (y(k) - C x_bar(k))`` (measurement update), then
    ``x_bar(k+1) = A x_hat(k) + B u(k)`` (time update), for the plant states only, with the
    stationary Kalman gain ``Lc`` of :func:`~trms.control.lq_design.current_estimator_gain` (the
    predictor ``x_bar(k+1) = A x_bar(k) + B u(k) + Lp (y(k) - C x_bar(k))`` has ``Lp = A Lc``).
    Both estimators have the poles ``eig(A - A Lc C)`` (eq. 6.18).

Separation (eq. 6.31)
    The closed loop of the plant and the compensator has the regulator poles
    ``eig(Aa - Ba K)`` and the estimator poles ``eig(A - A Lc C)``.

Reference injection
    ``"error"`` (the thesis's fig. 6.5 and eq. 6.37): the compensator ``H`` sees only the
    tracking error ``e = r - y``: the estimator is fed ``y - r`` and the integrator ``e``.
    A step in ``r`` therefore kicks the estimate and the control (the "sharp control
    demands" of ch. 7). ``"integrator"``: the reference enters the integrator only and the
    estimator sees ``y``; the control is smoother.

Anti-windup (conditional integration)
    The controller knows the actuator limits in deviation volts. At a sample where a
    commanded input is beyond its limit and one more integration step would push that
    input further beyond it, the integral state is held. The estimator's time update
    always uses the input the actuator will hold (the command clipped to the limits).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import control
import numpy as np

from trms.control.arguments import finite_system, index_tuple, is_discrete_dt, real_array
from trms.control.lq_design import (
    augment_with_integrators,
    current_estimator_gain,
    unreachable_unstable_modes,
    weight_matrix,
)
from trms.errors import ConfigurationError, DesignError, InputError, as_finite_array, check_choice

__all__ = ["LQGDesign", "LQGController", "design_lqg", "REFERENCE_INJECTIONS"]

#: Ways the reference enters the compensator (see the module docstring).
REFERENCE_INJECTIONS = ("error", "integrator")


def _discrete_state_space(system: object) -> control.StateSpace:
    if not isinstance(system, control.StateSpace):
        raise InputError(
            f"system must be a python-control StateSpace, got {type(system).__name__} "
            "(realise a transfer function first, e.g. trms.control.realization.observer_canonical)"
        )
    dt = system.dt
    if not is_discrete_dt(dt):
        raise ConfigurationError(f"system must be discrete-time with a finite numeric dt > 0 (s), got dt = {dt!r}")
    finite_system(system)
    if np.any(np.asarray(system.D) != 0):
        raise DesignError(
            f"system has a direct term D = {np.asarray(system.D).tolist()}; the controller needs a strictly proper "
            "model (D = 0) such as eq. (3.11), not its one-sample-ahead realisation (6.33)"
        )
    return system


@dataclass(frozen=True)
class LQGDesign:
    """An integral LQG design (see the module docstring for the equations).

    Attributes
    ----------
    model : control.StateSpace
        The design model (deviation V in, deviation rad out, ``D = 0``).
    tracked : tuple of int
        Indices of the outputs with integral action (one reference each).
    reference_injection : str
        ``"error"`` or ``"integrator"``.
    Q, R : numpy.ndarray
        Regulator weights on ``[x; xi]`` and on ``u``.
    G, Qe, Re : numpy.ndarray
        Process-noise input matrix and the estimator covariances.
    K : numpy.ndarray
        State-feedback gain on ``[x; xi]``, ``(m, n + p_t)``.
    P : numpy.ndarray
        Regulator Riccati solution.
    Lc, Lp, Pe : numpy.ndarray
        Current-estimator gain, predictor gain (``A Lc``), a-priori error covariance.

    Examples
    --------
    A first-order lag ``y(k+1) = 0.9 y(k) + 0.1 u(k)`` at 0.1 s with one integrator: ``K = [Kx, Ki]``, the
    estimator pole ``0.9 (1 - Lc)``:

    >>> d = design_lqg(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1))
    >>> d.sample_time, d.n_states, np.round(d.K, 4).tolist(), d.tracked, bool(np.all(d.K == np.hstack([d.Kx, d.Ki])))
    (0.1, 1, [[3.6666, -0.8274]], (0,), True)
    >>> round(float(d.estimator_poles[0].real), 6), round(0.9 * (1.0 - float(d.Lc[0, 0])), 6), d.estimator_faster
    (0.362333, 0.362333, True)
    """

    model: control.StateSpace
    tracked: tuple[int, ...]
    reference_injection: str
    Q: np.ndarray
    R: np.ndarray
    G: np.ndarray
    Qe: np.ndarray
    Re: np.ndarray
    K: np.ndarray
    P: np.ndarray
    Lc: np.ndarray
    Lp: np.ndarray
    Pe: np.ndarray

    @property
    def sample_time(self) -> float:
        """Sample time (s) of the model and so of the controller."""
        return float(self.model.dt)

    @property
    def n_states(self) -> int:
        """Plant states ``n``."""
        return int(self.model.nstates)

    @property
    def Kx(self) -> np.ndarray:
        """Gain on the estimated plant state, ``(m, n)`` (V per state unit)."""
        return self.K[:, : self.n_states]

    @property
    def Ki(self) -> np.ndarray:
        """Gain on the integral states, ``(m, p_t)`` (V per rad sample)."""
        return self.K[:, self.n_states :]

    def augmented(self) -> tuple[np.ndarray, np.ndarray]:
        """The augmented pair ``(Aa, Ba)`` the regulator was designed on (:func:`augment_with_integrators`).

        Examples
        --------
        >>> Aa, Ba = design_lqg(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)).augmented()
        >>> Aa.tolist(), Ba.tolist()
        ([[0.9, 0.0], [-1.0, 1.0]], [[0.1], [0.0]])
        """
        A, B, C = (np.asarray(m, float) for m in (self.model.A, self.model.B, self.model.C))
        return augment_with_integrators(A, B, C[list(self.tracked)])

    @property
    def regulator_poles(self) -> np.ndarray:
        """``eig(Aa - Ba K)``, sorted by decreasing magnitude.

        Examples
        --------
        >>> np.round(design_lqg(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)).regulator_poles, 4).tolist()
        [(0.7667-0.1682j), (0.7667+0.1682j)]
        """
        Aa, Ba = self.augmented()
        return _sorted(np.linalg.eigvals(Aa - Ba @ self.K))

    @property
    def estimator_poles(self) -> np.ndarray:
        """``eig(A - A Lc C)`` (eq. 6.18), sorted by decreasing magnitude.

        Examples
        --------
        The scalar case ``A = C = 1``, ``Qe = Re = 1``: ``1 - Lc`` with ``Lc`` the inverse golden ratio:

        >>> d = design_lqg(control.ss([[1.0]], [[1.0]], [[1.0]], [[0.0]], 0.1))
        >>> round(float(d.estimator_poles[0].real), 9), round(1.0 - 2.0 / (1.0 + 5**0.5), 9)
        (0.381966011, 0.381966011)
        """
        A, C = np.asarray(self.model.A, float), np.asarray(self.model.C, float)
        return _sorted(np.linalg.eigvals(A - A @ self.Lc @ C))

    @property
    def estimator_faster(self) -> bool:
        """True when the slowest estimator pole is faster (smaller ``|z|``) than the slowest regulator pole.

        Examples
        --------
        >>> design_lqg(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)).estimator_faster  # |z| 0.36 against 0.78
        True
        """
        return bool(np.max(np.abs(self.estimator_poles)) < np.max(np.abs(self.regulator_poles)))

    def cost(self, initial_state: Sequence[float]) -> float:
        """Optimal infinite-horizon cost ``x_a(0)' P x_a(0)`` from an augmented initial state ``[x; xi]``.

        Examples
        --------
        >>> d = design_lqg(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1))
        >>> bool(d.cost([1.0, 0.0]) == d.P[0, 0]), round(d.cost([0.0, 2.0]) / d.cost([0.0, 1.0]), 9)
        (True, 4.0)
        """
        x0 = as_finite_array("initial_state", initial_state, (self.P.shape[0],))
        return float(x0 @ self.P @ x0)


def _sorted(z: np.ndarray) -> np.ndarray:
    return z[np.lexsort((z.imag, z.real, -np.abs(z)))]


def design_lqg(
    system: control.StateSpace,
    Q: float | np.ndarray = 1.0,
    R: float | np.ndarray = 1.0,
    Qe: float | np.ndarray = 1.0,
    Re: float | np.ndarray = 1.0,
    noise_input: np.ndarray | None = None,
    tracked_outputs: Sequence[int] | None = None,
    reference_injection: str = "error",
) -> LQGDesign:
    """Design an integral LQG compensator for a discrete, strictly proper model.

    Parameters
    ----------
    system : control.StateSpace
        Discrete (``dt > 0``), ``D = 0``; deviation volts in, deviation radians out.
    Q : float or array_like
        Weight on ``[x; xi]`` (``n + p_t`` square), positive semi-definite; a scalar means
        that multiple of the identity (the thesis: ``Q = I``).
    R : float or array_like
        Weight on ``u`` (``m`` square), positive definite (the thesis: 75, 1, 100, 125).
    Qe : float or array_like
        Process-noise covariance (square, size of ``noise_input``'s columns), PSD.
    Re : float or array_like
        Measurement-noise covariance (``p`` square), positive definite.
    noise_input : array_like, optional
        Process-noise input matrix ``G`` (``n`` rows); default the identity.
    tracked_outputs : sequence of int, optional
        Outputs given integral action and a reference; default all.
    reference_injection : {"error", "integrator"}
        How the reference enters the compensator (module docstring).

    Returns
    -------
    LQGDesign

    Raises
    ------
    InputError, ConfigurationError
        Not a discrete StateSpace, bad indices or shapes.
    DesignError
        ``D != 0``; ``Q`` not PSD; ``R`` not PD; a weight entry beyond
        :data:`~trms.control.lq_design.WEIGHT_RANGE`; ``(Aa, Ba)`` not stabilisable (e.g. a plant zero at ``z = 1``
        or an uncontrollable unstable mode); ``(A, C)`` not detectable; a Riccati equation without stabilising
        solution.

    Examples
    --------
    On an integrator ``y(k+1) = y(k) + u(k)`` with ``Qe = Re = 1`` the estimator is the scalar Kalman filter
    of a random walk: ``Lc = 2 / (1 + sqrt 5)``, the inverse golden ratio; every pole lies inside the unit circle:

    >>> d = design_lqg(control.ss([[1.0]], [[1.0]], [[1.0]], [[0.0]], 0.1), Q=1.0, R=1.0, Qe=1.0, Re=1.0)
    >>> round(float(d.Lc[0, 0]), 9), bool(np.all(np.abs(d.regulator_poles) < 1.0))
    (0.618033989, True)
    """
    sys = _discrete_state_space(system)
    A, B, C = (np.asarray(m, float) for m in (sys.A, sys.B, sys.C))
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    check_choice("reference_injection", reference_injection, REFERENCE_INJECTIONS, error=InputError)
    tracked = (
        tuple(range(p))
        if tracked_outputs is None
        else index_tuple("tracked_outputs", tracked_outputs, p, "output indices")
    )
    G = np.eye(n) if noise_input is None else real_array("noise_input", noise_input, (n, None))
    Qm = weight_matrix("Q", Q, n + len(tracked), definite=False)
    Rm = weight_matrix("R", R, m, definite=True)
    Qem = weight_matrix("Qe", Qe, G.shape[1], definite=False)
    Rem = weight_matrix("Re", Re, p, definite=True)
    Aa, Ba = augment_with_integrators(A, B, C[list(tracked)])
    bad = unreachable_unstable_modes(Aa, Ba)
    if bad:
        raise DesignError(
            "the augmented pair (Aa, Ba) is not stabilisable: modes "
            f"{[complex(round(z.real, 6), round(z.imag, 6)) for z in bad]} with |z| >= 1 cannot be reached by u "
            "(an uncontrollable unstable plant mode, or a plant zero at z = 1 that blocks integral action)"
        )
    bad_obs = unreachable_unstable_modes(A.T, C.T)
    if bad_obs:
        raise DesignError(
            "the pair (A, C) is not detectable: modes "
            f"{[complex(round(z.real, 6), round(z.imag, 6)) for z in bad_obs]} "
            "with |z| >= 1 are not seen by the measurements"
        )
    try:
        K, P, _ = control.dlqr(Aa, Ba, Qm, Rm, method="scipy")  # the same numbers with or without slycot
    except Exception as exc:  # python-control raises several types for a failed Riccati solve
        raise DesignError(f"the regulator Riccati equation has no stabilising solution: {exc}") from exc
    poles = np.linalg.eigvals(Aa - Ba @ np.asarray(K, float))
    if np.max(np.abs(poles)) >= 1.0 - 1e-9:
        raise DesignError(
            f"the regulator leaves poles on or outside the unit circle (largest |z| = {np.max(np.abs(poles)):.9g}; "
            "allowed: < 1): Q does not weight every unstable or integrator state (Q = 0 loses integral action)"
        )
    Lc, Lp, Pe = current_estimator_gain(A, C, G, Qem, Rem)
    return LQGDesign(
        sys, tracked, reference_injection, Qm, Rm, G, Qem, Rem, np.asarray(K, float), np.asarray(P, float), Lc, Lp, Pe
    )


class LQGController:
    """The integral LQG compensator as a sampled controller with actuator limits.

    Parameters
    ----------
    design : LQGDesign
        The design.
    input_limits : tuple of array_like, optional
        Lower and upper actuator limits in *deviation* volts (absolute limits minus the
        trim), shape ``(m,)`` each or scalars; unlimited by default.

    Notes
    -----
    :meth:`update` returns the commanded input (deviation V), which may lie beyond the
    limits: the actuator (the plant) saturates it and records that it did. Internally the
    controller uses the clipped value for its estimator and holds its integrators when
    they would wind up (module docstring).

    Examples
    --------
    Integral action: the lag ``y(k+1) = 0.9 y(k) + 0.1 u(k)`` follows a 0.1 rad step with no offset:

    >>> c = LQGController(design_lqg(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)), input_limits=(-1.0, 1.0))
    >>> c.sample_time, c.n_inputs
    (0.1, 1)
    >>> y = 0.0
    >>> for _ in range(300):
    ...     y = 0.9 * y + 0.1 * float(np.clip(c.update(0.1, y)[0], -1.0, 1.0))
    >>> round(y, 9)
    0.1
    """

    def __init__(self, design: LQGDesign, input_limits: tuple[object, object] | None = None) -> None:
        self.design = design
        A, B, C = (np.asarray(mat, float) for mat in (design.model.A, design.model.B, design.model.C))
        self._A, self._B, self._C = A, B, C
        self._Lc, self._Kx, self._Ki = design.Lc, design.Kx, design.Ki
        self._tracked = np.asarray(design.tracked, dtype=np.intp)
        self._inject = 1.0 if design.reference_injection == "error" else 0.0
        m = B.shape[1]
        if input_limits is None:
            input_limits = (-np.inf, np.inf)
        if not isinstance(input_limits, (tuple, list)) or len(input_limits) != 2:
            raise InputError(f"input_limits must be a pair (lower, upper) of deviation volts, got {input_limits!r}")
        lower, upper = (_limit(side, value, m) for side, value in zip(("lower", "upper"), input_limits))
        if np.any(lower >= upper) or np.any(lower > 0) or np.any(upper < 0):
            raise InputError(
                "input_limits (deviation V) must satisfy lower <= 0 <= upper and lower < upper, "
                f"got {lower.tolist()}, {upper.tolist()}"
            )
        self.input_limits = (lower, upper)
        self.reset()

    # ------------------------------------------------------------------ sizes
    @property
    def sample_time(self) -> float:
        """Controller sample time (s)."""
        return self.design.sample_time

    @property
    def n_references(self) -> int:
        """Number of references (tracked outputs).

        Examples
        --------
        >>> two = control.ss(np.diag([0.9, 0.5]), np.eye(2), np.eye(2), np.zeros((2, 2)), 0.1)
        >>> c = LQGController(design_lqg(two, tracked_outputs=[1]))
        >>> c.n_references, c.n_measurements, c.n_inputs
        (1, 2, 2)
        """
        return int(self._tracked.size)

    @property
    def n_measurements(self) -> int:
        """Number of measured outputs."""
        return int(self._C.shape[0])

    @property
    def n_inputs(self) -> int:
        """Number of plant inputs."""
        return int(self._B.shape[1])

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        """Zero the estimate and the integrators (the plant is assumed at trim).

        Examples
        --------
        >>> c = LQGController(design_lqg(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)))
        >>> _ = c.update(0.1, 0.0)
        >>> c.reset()
        >>> c.integral.tolist(), c.estimate.tolist()
        ([0.0], [0.0])
        """
        n = self._A.shape[0]
        self._x_bar = np.zeros(n)
        self._x_hat = np.zeros(n)
        self._xi = np.zeros(self._tracked.size)
        self._saturated = np.zeros(self._B.shape[1], dtype=bool)
        self._handover: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    @property
    def estimate(self) -> np.ndarray:
        """Current estimate ``x_hat(k)`` of the plant state (after the last update), in the model's state units.

        Examples
        --------
        From rest, the first estimate is the measurement update of ``y - r`` (error injection),
        ``x_hat = Lc (y - r)``:

        >>> c = LQGController(design_lqg(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)))
        >>> _ = c.update(0.0, 0.5)
        >>> round(float(c.estimate[0]), 6), round(0.5 * float(c.design.Lc[0, 0]), 6)
        (0.298704, 0.298704)
        """
        return self._x_hat.copy()

    @property
    def integral(self) -> np.ndarray:
        """Integral states ``xi`` (rad samples), to be used at the next update.

        Examples
        --------
        >>> c = LQGController(design_lqg(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)))
        >>> _ = c.update(0.1, 0.0), c.update(0.1, 0.0)
        >>> np.round(c.integral, 12).tolist()  # two samples of a 0.1 rad error
        [0.2]
        """
        return self._xi.copy()

    @property
    def saturated(self) -> np.ndarray:
        """Which inputs were commanded beyond their limits at the last update.

        Examples
        --------
        >>> c = LQGController(design_lqg(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)), input_limits=(-1.0, 1.0))
        >>> c.update(1.0, 0.0).round(4).tolist(), c.saturated.tolist()
        ([2.1905], [True])
        """
        return self._saturated.copy()

    def update(self, reference: object, measurement: object) -> np.ndarray:
        """One controller sample: measurement update, control, anti-windup, time update.

        Parameters
        ----------
        reference : array_like
            Reference of each tracked output (deviation rad), shape ``(p_t,)`` (scalar if 1).
        measurement : array_like
            Measured outputs (deviation rad), shape ``(p,)`` (scalar if 1).

        Returns
        -------
        numpy.ndarray
            Commanded input (deviation V), shape ``(m,)``; not clipped.

        Raises
        ------
        InputError
            A reference or measurement that is not real and finite or has the wrong shape.

        Examples
        --------
        The first sample of a step, plant at rest: ``u = Kx Lc r`` (error injection):

        >>> c = LQGController(design_lqg(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)))
        >>> u = float(c.update(0.1, 0.0)[0])
        >>> round(u, 9) == round(0.1 * float(c.design.Kx[0, 0] * c.design.Lc[0, 0]), 9)
        True
        """
        r = _vector("reference (deviation rad)", reference, self._tracked.size)
        y = _vector("measurement (deviation rad)", measurement, self._C.shape[0])
        y_est = y.copy()
        y_est[self._tracked] -= self._inject * r
        x_hat = self._x_bar + self._Lc @ (y_est - self._C @ self._x_bar)
        if self._handover is not None:  # the first sample after continue_from: match the old command
            kx, ki, xi = self._handover
            self._xi = np.linalg.lstsq(self._Ki, kx @ x_hat + ki @ xi - self._Kx @ x_hat, rcond=None)[0]
            self._handover = None
        u = -(self._Kx @ x_hat) - self._Ki @ self._xi
        lower, upper = self.input_limits
        held = np.minimum(np.maximum(u, lower), upper)
        over, under = u > upper, u < lower
        error = r - y[self._tracked]
        if over.any() or under.any():
            du = -(self._Ki @ error)
            if np.any(over & (du > 0)) or np.any(under & (du < 0)):
                error = np.zeros_like(error)
        self._xi = self._xi + error
        self._x_hat = x_hat
        self._x_bar = self._A @ x_hat + self._B @ held
        self._saturated = over | under
        return u

    def continue_from(self, other: LQGController) -> None:
        """Take over ``other``'s estimate, and set the integrators so the command goes on without a jump.

        Both designs must share the state and output dimensions (e.g. one model with another input gain). The
        estimate is taken as it is; at the next :meth:`update`, once the measurement has updated the estimate
        ``x_hat``, the integrators ``xi`` are set so that this design commands what ``other`` would have:
        ``Kx x_hat + Ki xi = Kx' x_hat + Ki' xi'`` (least squares where ``Ki`` is not square), the bumpless
        transfer of a switched state feedback with integral action.

        Raises
        ------
        InputError
            Another number of states or tracked outputs.

        Examples
        --------
        >>> plant = control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)
        >>> a, b = LQGController(design_lqg(plant)), LQGController(design_lqg(plant, R=10.0))
        >>> y, u = 0.0, []
        >>> for k in range(24):
        ...     if k == 20:
        ...         b.continue_from(a)
        ...     u.append(float((a if k < 20 else b).update(0.1, y)[0]))
        ...     y = 0.9 * y + 0.1 * u[-1]
        >>> [round(v, 4) for v in u[18:22]]  # no jump at the switch (sample 20)
        [0.0958, 0.0971, 0.0981, 0.0985]
        """
        if other._x_bar.shape != self._x_bar.shape or other._xi.shape != self._xi.shape:
            raise InputError(
                f"cannot continue from a controller of {other._x_bar.size} states and {other._xi.size} tracked "
                f"outputs; this one has {self._x_bar.size} and {self._xi.size}"
            )
        self._x_bar = other._x_bar.copy()
        self._x_hat = other._x_hat.copy()
        self._xi = other._xi.copy()
        self._saturated = other._saturated.copy()
        self._handover = (other._Kx.copy(), other._Ki.copy(), other._xi.copy())

    def compensator(self) -> control.StateSpace:
        """The linear compensator (no limits) as a python-control system.

        States ``[x_bar; xi]``; inputs ``[r (p_t); y (p)]``; output ``u`` (deviation V);
        ``dt`` the controller's. Stepping it gives the same ``u`` as :meth:`update` while no
        input saturates.

        Examples
        --------
        >>> K = LQGController(design_lqg(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1))).compensator()
        >>> K.input_labels, K.output_labels, K.nstates, K.dt
        (['r_y[0]', 'y[0]'], ['u[0]'], 2, 0.1)
        """
        A, B, C, Lc, Kx, Ki = self._A, self._B, self._C, self._Lc, self._Kx, self._Ki
        n, p, pt = A.shape[0], C.shape[0], self._tracked.size
        S = np.zeros((p, pt))
        S[self._tracked, np.arange(pt)] = self._inject
        T = np.zeros((pt, p))
        T[np.arange(pt), self._tracked] = 1.0
        M = np.eye(n) - Lc @ C
        F = A - B @ Kx
        Ac = np.block([[F @ M, -B @ Ki], [np.zeros((pt, n)), np.eye(pt)]])
        Bc = np.block([[-F @ Lc @ S, F @ Lc], [np.eye(pt), -T]])
        Cc = np.hstack([-Kx @ M, -Ki])
        Dc = np.hstack([Kx @ Lc @ S, -Kx @ Lc])
        model = self.design.model
        ref_names = [f"r_{model.output_labels[i]}" for i in self.design.tracked]
        return control.ss(
            Ac,
            Bc,
            Cc,
            Dc,
            self.sample_time,
            inputs=ref_names + list(model.output_labels),
            outputs=list(model.input_labels),
            name="lqg_compensator",
        )


def _limit(side: str, value: object, m: int) -> np.ndarray:
    """One side of the actuator limits: a scalar or ``(m,)`` deviation volts, infinite allowed."""
    arr = real_array(f"input_limits {side}", value, infinite=True)
    if arr.shape not in ((), (m,)):
        raise InputError(f"input_limits {side} must be a scalar or have shape ({m},), got shape {arr.shape}")
    return np.broadcast_to(arr, (m,)).copy()


def _vector(name: str, value: object, n: int) -> np.ndarray:
    if isinstance(value, np.ndarray) and value.shape == (n,) and value.dtype == float and np.isfinite(value).all():
        return value
    return real_array(name, value if np.ndim(np.asarray(value, dtype=object)) else [value], (n,))
