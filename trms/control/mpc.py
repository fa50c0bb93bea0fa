"""Constrained, offset-free model predictive control solved as a condensed QP by OSQP.

Model (deviations: V in, rad out): ``x(k+1) = A x(k) + B (u(k) + d(k))``, ``y(k) = C x(k)``, with a
constant *input* disturbance ``d`` (``d(k+1) = d(k)``) that stands for every steady model error.

Estimator
    A current Kalman filter on the augmented state ``[x; d]``
    (:func:`trms.control.lq_design.current_estimator_gain` on ``[[A, B], [0, I]]``, ``[C, 0]``) with process
    covariances ``Qx`` (plant states) and ``Qd`` (disturbance random walk), measurement covariance ``Re``.

Target
    The steady state ``(x_s, u_s)`` with ``x_s = A x_s + B (u_s + d_hat)`` and ``C_t x_s = r``
    (least squares if not square); with an integrating disturbance model this makes the tracking
    offset-free whenever the loop settles.

Regulator
    Over ``N`` samples, the inputs ``u_0 .. u_{N-1}`` minimise
    ``sum_k (x_k - x_s)' Q (x_k - x_s) + (u_k - u_s)' R (u_k - u_s) + (x_N - x_s)' P (x_N - x_s)``, ``P``
    the solution of the discrete Riccati equation (python-control ``dlqr``), so that with no constraint
    active the first move is the infinite-horizon LQR ``u_0 = u_s - K (x_0 - x_s)``. The state
    sequence is eliminated (condensed QP in the inputs only, plus one slack per constrained output).

Constraints
    Input limits ``lower <= u_k <= upper`` and rate limits ``|u_k - u_{k-1}| <= rate`` (``u_{-1}``
    the previous move), all hard; output limits ``y_lo <= C x_k <= y_hi`` for ``k = 1 .. N``,
    soft by default (one slack ``s >= 0`` per output and step, cost ``rho_1 s + rho_2 s^2`` each,
    an exact penalty for ``rho_1`` large enough: the limit then holds whenever some plan can keep it) or
    hard. A problem the solver proves infeasible raises :class:`~trms.errors.SimulationError`.

Solve
    Each sample first computes the unconstrained optimum ``-H^-1 q`` (a Cholesky factor of the fixed
    Hessian); when it meets every constraint it is the QP's solution, exactly. Otherwise OSQP solves the
    QP (set up with the row types of a plan, warm-started from the previous sample, polished on its active
    set, at most 4000 iterations), and its answer is used only if the Karush-Kuhn-Tucker conditions certify
    it (:func:`trms.control.qp.solve_checked`); else the exact active-set solver
    (:func:`trms.control.qp.solve_exact`) solves the QP. A plan neither certifies (never seen in the
    benchmark's cases) is flagged in ``info`` and by an :class:`UnconvergedPlanWarning`. Every plan returned
    meets the input and rate limits: each move is clipped in order to them (a certified plan moves by
    round-off at most).

:func:`mpc_for_plant` fills the limits from a plant: its absolute input limits as deviations
(:func:`trms.control.loop.deviation_limits`) and the pitch and yaw end stops of the twin's joints
(:func:`trms.rigdata.end_stops`) as deviations from the plant's trim outputs.

OSQP is an optional dependency: ``pip install 'trms[control]'``.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Sequence
from typing import Any

import control
import numpy as np
import scipy.sparse as sp
from scipy.linalg import cho_factor, cho_solve

from trms.control._checks import finite_system, index_tuple, is_discrete_dt, real_array
from trms.control.limits import limit_pair, output_stop_limits
from trms.control.loop import deviation_limits
from trms.control.lq_design import current_estimator_gain, weight_matrix
from trms.control.qp import InfeasibleProblem, solve_checked
from trms.errors import ConfigurationError, DesignError, InputError, SimulationError, check_in_range
from trms.plant import Plant

__all__ = ["MPCController", "mpc_for_plant", "load_osqp", "UnconvergedPlanWarning"]

#: Slack (V, rad) by which the unconstrained optimum may pass a bound and still count as meeting it.
_SLACK = 1e-12

#: OSQP's iteration cap per plan (the exact solver takes over from a plan not certified by then).
_MAX_ITER = 4000

#: A plan whose largest scaled KKT residual (:class:`~trms.control.qp.KKTResiduals`) is at most this is the optimum.
_CERTIFIED = 1e-9


class UnconvergedPlanWarning(UserWarning):
    """An MPC plan that neither OSQP nor the exact solver certified as the QP's optimum (see ``info``)."""


def load_osqp() -> Any:
    """The OSQP module, or a one-line :class:`~trms.errors.ConfigurationError` naming the extra to install.

    Examples
    --------
    >>> load_osqp().__name__
    'osqp'
    """
    try:
        import osqp  # type: ignore[import-untyped]
    except ImportError as exc:
        raise ConfigurationError("MPC needs the OSQP solver: pip install 'trms[control]'") from exc
    return osqp


class MPCController:
    """Offset-free constrained MPC as a sampled controller (module docstring).

    Parameters
    ----------
    model : control.StateSpace
        Discrete design model, ``D = 0`` (deviation V in, deviation rad out).
    horizon : int
        Prediction horizon ``N`` (samples), 1 to 500.
    Q, R : float or array_like
        State (``n`` square, PSD) and input (``m`` square, PD) weights; a scalar times the identity.
        Default ``Q = C' C`` (output weight, rad^-2), ``R = 1`` (V^-2).
    input_limits : tuple of array_like, optional
        ``(lower, upper)`` deviation volts (``lower <= 0 <= upper``); unlimited by default.
    rate_limit : float or array_like, optional
        Largest ``|u_k - u_{k-1}|`` (V per sample), ``> 0``; unlimited by default.
    output_limits : tuple of array_like, optional
        ``(lower, upper)`` deviation rad per output (``+-inf`` for none); none by default.
    soft : bool
        Soft output limits (default) or hard.
    softness : tuple of float
        ``(rho_1, rho_2)``, linear and quadratic slack weights.
    tracked_outputs : sequence of int, optional
        Outputs with a reference; default all.
    Qx, Qd, Re : float
        Estimator covariances: plant-state process noise (times I), disturbance random walk (V^2), and
        measurement noise (rad^2, times I).
    tolerance : float
        OSQP absolute and relative tolerance.

    Attributes
    ----------
    solve_times : list of float
        Wall time (s) of each sample's plan since the last reset.
    qp_solves : int
        How many of those plans needed OSQP (a constraint active); the others were the unconstrained optimum.
    exact_solves, unconverged : int
        How many of those the exact solver solved (OSQP's answer not certified), and how many neither certified.
    info : dict
        The last plan's solve: ``solver`` (``"unconstrained"``, ``"osqp"`` or ``"exact"``), ``osqp_status``,
        ``osqp_iterations``, ``kkt_residual`` and ``converged`` (certified optimal; module docstring, "Solve").

    Examples
    --------
    >>> m = control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)
    >>> mpc = MPCController(m, horizon=10, input_limits=(-1.0, 1.0))
    >>> u = mpc.update(5.0, 0.0)  # a far reference: the move stops at the limit
    >>> round(float(u[0]), 6)
    1.0
    """

    def __init__(
        self,
        model: control.StateSpace,
        horizon: int = 30,
        Q: float | np.ndarray | None = None,
        R: float | np.ndarray = 1.0,
        input_limits: tuple[object, object] | None = None,
        rate_limit: object = None,
        output_limits: tuple[object, object] | None = None,
        soft: bool = True,
        softness: tuple[float, float] = (1e4, 1e5),
        tracked_outputs: Sequence[int] | None = None,
        Qx: float = 1e-4,
        Qd: float = 1e-3,
        Re: float = 1e-4,
        tolerance: float = 1e-6,
    ) -> None:
        self._osqp = load_osqp()
        tolerance = check_in_range("tolerance", tolerance, 1e-12, 1e-2)
        if not isinstance(model, control.StateSpace) or not is_discrete_dt(model.dt):
            raise InputError(f"model must be a discrete python-control StateSpace (dt > 0 s), got {model!r:.60}")
        A, B, C, D = finite_system(model, "model")
        if np.any(D != 0):
            raise DesignError(f"model has a direct term D = {D.tolist()}; MPC needs a strictly proper model (D = 0)")
        n, m, p = A.shape[0], B.shape[1], C.shape[0]
        if isinstance(horizon, (bool, np.bool_)) or not isinstance(horizon, (int, np.integer)):
            raise InputError(f"horizon must be an integer number of samples in [1, 500], got {horizon!r}")
        N = int(check_in_range("horizon", horizon, 1, 500, unit=" samples"))
        self.model, self.horizon, self.soft = model, N, bool(soft)
        self.tracked = (
            tuple(range(p)) if tracked_outputs is None else index_tuple("tracked_outputs", tracked_outputs, p)
        )
        Qm = weight_matrix("Q", C.T @ C if Q is None else Q, n, definite=False)
        Rm = weight_matrix("R", R, m, definite=True)
        try:
            K, P, _ = control.dlqr(A, B, Qm, Rm, method="scipy")
        except Exception as exc:  # python-control raises several types for a failed Riccati solve
            raise DesignError(f"the regulator Riccati equation has no stabilising solution: {exc}") from exc
        self.K, self.P = np.asarray(K, float), np.asarray(P, float)
        self.Q, self.R = Qm, Rm
        # limits
        lo, hi = limit_pair("input_limits", input_limits, m)
        if np.any(lo > 0) or np.any(hi < 0) or np.any(lo >= hi):
            raise InputError(
                f"input_limits (deviation V) must satisfy lower <= 0 <= upper, lower < upper; got {lo}, {hi}"
            )
        rate = np.full(m, np.inf)
        if rate_limit is not None:
            arr = real_array("rate_limit", rate_limit, infinite=True)
            if arr.size not in (1, m) or arr.ndim > 1:
                raise InputError(f"rate_limit must be a scalar or have shape ({m},), got shape {arr.shape}")
            rate = np.broadcast_to(arr.ravel(), (m,)).astype(float)
        if np.any(rate <= 0):
            raise InputError(f"rate_limit must be > 0 V per sample, got {rate.tolist()}")
        ylo, yhi = limit_pair("output_limits", output_limits, p)
        if np.any(ylo >= yhi):
            raise InputError(f"output_limits (deviation rad) must satisfy lower < upper, got {ylo}, {yhi}")
        self.input_limits, self.rate_limit, self.output_limits = (lo, hi), rate, (ylo, yhi)
        rho1, rho2 = (check_in_range("softness", v, 0.0, 1e12, low_open=True) for v in softness)
        # condensed prediction: X = Phi x0 + Gam (U + d), X = [x_1 .. x_N]
        Phi = np.vstack([np.linalg.matrix_power(A, k) for k in range(1, N + 1)])
        Gam = np.zeros((N * n, N * m))
        for k in range(N):
            AkB = np.linalg.matrix_power(A, k) @ B
            for j in range(N - k):
                Gam[(j + k) * n : (j + k + 1) * n, j * m : (j + 1) * m] = AkB
        Qbar = np.kron(np.eye(N), Qm)
        Qbar[-n:, -n:] = P
        Rbar = np.kron(np.eye(N), Rm)
        self._Phi, self._Gam, self._Qbar, self._Rbar = Phi, Gam, Qbar, Rbar
        self._GamQ = Gam.T @ Qbar  # the linear term's fixed factor, formed once
        H = Gam.T @ Qbar @ Gam + Rbar
        out_rows = [i for i in range(p) if np.isfinite(ylo[i]) or np.isfinite(yhi[i])]
        self._out_rows = out_rows
        ns = N * len(out_rows) if self.soft else 0
        self._ns = ns
        Hfull = np.zeros((N * m + ns, N * m + ns))
        Hfull[: N * m, : N * m] = H
        Hfull[N * m :, N * m :] = rho2 * np.eye(ns)  # OSQP minimises half the cost
        self._rho1 = 0.5 * rho1
        # constraint rows: inputs, rates, outputs (+ slacks), slack >= 0
        rows = [np.hstack([np.eye(N * m), np.zeros((N * m, ns))])]
        Dm = np.eye(N * m) - np.eye(N * m, k=-m)
        rows.append(np.hstack([Dm, np.zeros((N * m, ns))]))
        Cy = np.kron(np.eye(N), C[out_rows]) if out_rows else np.zeros((0, N * n))
        self._CyGam, self._CyPhi = Cy @ Gam, Cy @ Phi
        if out_rows:
            slack = np.eye(ns) if self.soft else np.zeros((N * len(out_rows), 0))
            rows.append(np.hstack([self._CyGam, -slack]))  # upper side: Cy X - s <= y_hi
            rows.append(np.hstack([self._CyGam, slack]))  # lower side: Cy X + s >= y_lo
        if ns:
            rows.append(np.hstack([np.zeros((ns, N * m)), np.eye(ns)]))
        Acon = np.vstack(rows)
        self._nu = N * m
        self._Acon, self._H = Acon, Hfull
        self._chol = cho_factor(H)
        # estimator on [x; d]
        Ae = np.block([[A, B], [np.zeros((m, n)), np.eye(m)]])
        Ce = np.hstack([C, np.zeros((p, m))])
        Qe = np.diag(
            np.r_[
                np.full(n, check_in_range("Qx", Qx, 0.0, 1e6)),
                np.full(m, check_in_range("Qd", Qd, 0.0, 1e6, low_open=True)),
            ]
        )
        Rem = check_in_range("Re", Re, 0.0, 1e6, low_open=True) * np.eye(p)
        self._Lc = current_estimator_gain(Ae, Ce, np.eye(n + m), Qe, Rem)[0]
        self._Ae, self._Be, self._Ce = Ae, np.vstack([B, np.zeros((m, m))]), Ce
        self._A, self._B, self._C = A, B, C
        # target: [[I - A, -B], [C_t, 0]] [x_s; u_s] = [B d; r]
        self._target = np.linalg.pinv(
            np.block([[np.eye(n) - A, -B], [C[list(self.tracked)], np.zeros((len(self.tracked), m))]])
        )
        # OSQP's step sizes follow each row's type (equality, inequality, free) at setup: set it up with the bounds
        # of a plan from rest, whose rows have the types every plan's have.
        q0, lower0, upper0 = self._problem(np.zeros(n), np.zeros(m), np.zeros(len(self.tracked)), np.zeros(m))
        self._solver = self._osqp.OSQP()
        self._solver.setup(
            sp.csc_matrix(np.triu(Hfull)),
            q0,
            sp.csc_matrix(Acon),
            lower0,
            upper0,
            verbose=False,
            polishing=True,
            eps_abs=tolerance,
            eps_rel=tolerance,
            max_iter=_MAX_ITER,
            warm_starting=True,
        )
        self.solve_times: list[float] = []
        self.qp_solves = self.exact_solves = self.unconverged = 0
        self.info: dict[str, Any] = {}
        self.reset()

    # ------------------------------------------------------------------
    @property
    def sample_time(self) -> float:
        """Controller sample time (s).

        Examples
        --------
        >>> MPCController(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1), horizon=5).sample_time
        0.1
        """
        return float(self.model.dt)

    @property
    def n_references(self) -> int:
        """Number of references (tracked outputs).

        Examples
        --------
        >>> two = control.ss(np.diag([0.9, 0.5]), np.eye(2), np.eye(2), np.zeros((2, 2)), 0.1)
        >>> MPCController(two, horizon=5, tracked_outputs=[0]).n_references
        1
        """
        return len(self.tracked)

    @property
    def estimate(self) -> np.ndarray:
        """Current estimate of ``[x; d]`` (after the last update): plant states, then input disturbances (V).

        Examples
        --------
        Offset-free: on the model itself a 0.5 rad step is held with no disturbance left in the estimate:

        >>> model = control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)
        >>> mpc = MPCController(model, horizon=10, input_limits=(-1.0, 1.0))
        >>> y = 0.0
        >>> for _ in range(100):
        ...     y = 0.9 * y + 0.1 * float(mpc.update(0.5, y)[0])
        >>> round(y, 4), np.round(mpc.estimate, 4).tolist()
        (0.5, [0.5, 0.0])
        """
        return self._xe.copy()

    def reset(self) -> None:
        """Zero the estimate, the disturbance and the previous move; clear the solve times.

        Examples
        --------
        >>> mpc = MPCController(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1), horizon=5)
        >>> _ = mpc.update(0.5, 0.0)
        >>> mpc.reset()
        >>> mpc.estimate.tolist(), mpc.solve_times
        ([0.0, 0.0], [])
        """
        n, m = self._B.shape
        self._xbar = np.zeros(n + m)
        self._xe = np.zeros(n + m)
        self._u_prev = np.zeros(m)
        self.solve_times = []
        self.qp_solves = self.exact_solves = self.unconverged = 0
        self.info = {}

    def target(self, reference: np.ndarray, disturbance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Steady state and input ``(x_s, u_s)`` holding the tracked outputs at ``reference`` under ``disturbance``.

        Parameters
        ----------
        reference : numpy.ndarray
            Tracked-output references ``(p_t,)`` (deviation rad).
        disturbance : numpy.ndarray
            Input disturbance ``d`` ``(m,)`` (V).

        Returns
        -------
        tuple of numpy.ndarray
            ``x_s`` ``(n,)`` (state units) and ``u_s`` ``(m,)`` (deviation V).

        Examples
        --------
        ``y(k+1) = 0.9 y(k) + 0.1 (u(k) + d)`` rests at ``y = r`` with ``u_s = r - d`` (static gain 1):

        >>> mpc = MPCController(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1), horizon=5)
        >>> [v.round(9).tolist() for v in mpc.target(np.array([0.5]), np.array([0.2]))]
        [[0.5], [0.3]]
        """
        n, m = self._B.shape
        sol = self._target @ np.r_[self._B @ disturbance, reference]
        return sol[:n], sol[n:]

    def plan(
        self, state: object, disturbance: object, reference: object, previous_input: object | None = None
    ) -> np.ndarray:
        """Solve the QP from a state: the planned inputs ``(N, m)`` (deviation V).

        Parameters
        ----------
        state : array_like
            Plant state ``x_0`` ``(n,)``.
        disturbance : array_like
            Input disturbance ``d`` ``(m,)`` (V).
        reference : array_like
            Tracked-output references ``(p_t,)`` (deviation rad).
        previous_input : array_like, optional
            ``u_{-1}`` for the rate limits; default the last move.

        Returns
        -------
        numpy.ndarray
            Planned inputs ``u_0 .. u_{N-1}``, shape ``(N, m)`` (deviation V).

        Raises
        ------
        SimulationError
            The exact solver proves the constraints infeasible, or both solvers fail.

        Warns
        -----
        UnconvergedPlanWarning
            Neither OSQP's answer nor the exact solver's is certified optimal (``info["converged"]`` False).

        Examples
        --------
        With no constraint active the first move is the infinite-horizon LQR ``u_s - K (x_0 - x_s)``
        (module docstring):

        >>> mpc = MPCController(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1), horizon=10)
        >>> plan = mpc.plan([0.0], [0.0], [0.1])
        >>> xs, us = mpc.target(np.array([0.1]), np.zeros(1))
        >>> plan.shape, bool(np.isclose(plan[0, 0], (us - mpc.K @ (0.0 - xs))[0], rtol=1e-12))
        ((10, 1), True)
        """
        n, m = self._B.shape
        N = self.horizon
        x0 = real_array("state", state, (n,))
        d = real_array("disturbance", disturbance, (m,))
        r = real_array("reference (deviation rad)", np.ravel(np.asarray(reference, dtype=float)), (len(self.tracked),))
        up = self._u_prev if previous_input is None else real_array("previous_input", previous_input, (m,))
        q, lower, upper = self._problem(x0, d, r, up)
        start = time.perf_counter()
        free_u = -cho_solve(self._chol, q[: self._nu])
        rows = self._Acon[:, : self._nu] @ free_u
        if np.all(rows >= lower - _SLACK) and np.all(rows <= upper + _SLACK):
            self.solve_times.append(time.perf_counter() - start)
            self.info = {"solver": "unconstrained", "osqp_status": None, "kkt_residual": 0.0, "converged": True}
            return self._within_hard_limits(free_u.reshape(N, m), up)  # no constraint active: the exact optimum
        self.qp_solves += 1
        x, info = self._solve(q, lower, upper, x0)
        plan = self._within_hard_limits(x[: self._nu].reshape(N, m), up)
        self.solve_times.append(time.perf_counter() - start)
        self.info = info
        if not info["converged"]:
            self.unconverged += 1
            warnings.warn(
                f"MPC plan not certified optimal: {info['osqp_status']} and the exact solver failed "
                f"(KKT residual {info['kkt_residual']:.2g} > {_CERTIFIED:g}); the plan was made to meet the input "
                "and rate limits, its cost and predictions are not the QP's optimum",
                UnconvergedPlanWarning,
                stacklevel=2,
            )
        return plan

    def _problem(
        self, x0: np.ndarray, d: np.ndarray, r: np.ndarray, up: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The QP's linear term and the bounds of its rows for a state, disturbance, reference and previous move."""
        N = self.horizon
        xs, us = self.target(r, d)
        dU = np.tile(d, N)
        Xs, Us = np.tile(xs, N), np.tile(us, N)
        free = self._Phi @ x0 + self._Gam @ dU - Xs
        q = self._GamQ @ free - self._Rbar @ Us
        lo, hi = self.input_limits
        l_parts = [np.tile(lo, N), np.r_[up - self.rate_limit, np.tile(-self.rate_limit, N - 1)]]
        u_parts = [np.tile(hi, N), np.r_[up + self.rate_limit, np.tile(self.rate_limit, N - 1)]]
        if self._out_rows:
            ylo, yhi = (np.tile(v[self._out_rows], N) for v in self.output_limits)
            base = self._CyPhi @ x0 + self._CyGam @ dU
            l_parts += [np.full(base.size, -np.inf), ylo - base]
            u_parts += [yhi - base, np.full(base.size, np.inf)]
        if self._ns:
            l_parts.append(np.zeros(self._ns))
            u_parts.append(np.full(self._ns, np.inf))
            q = np.r_[q, np.full(self._ns, self._rho1)]
        return q, np.concatenate(l_parts), np.concatenate(u_parts)

    def _solve(
        self, q: np.ndarray, lower: np.ndarray, upper: np.ndarray, x0: np.ndarray
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """The QP's solution and how it was found (:func:`~trms.control.qp.solve_checked`)."""
        try:
            x, info = solve_checked(self._solver, self._H, q, self._Acon, lower, upper, tolerance=_CERTIFIED)
        except InfeasibleProblem as exc:
            raise SimulationError(
                f"the MPC problem is infeasible ({exc}; state pitch {float(self._C[0] @ x0):+.4g} rad, output limits "
                f"{self.output_limits[0].tolist()}..{self.output_limits[1].tolist()} rad, hard: {not self.soft}); "
                "allowed: constraints some input sequence can meet (soften the output limits or widen them)"
            ) from None
        self.exact_solves += info["solver"] != "osqp"
        return x, info

    def _within_hard_limits(self, plan: np.ndarray, up: np.ndarray) -> np.ndarray:
        """``plan`` with each move clipped in turn to the input limits and the rate limit from the move before."""
        out, (lo, hi), rate = plan.copy(), self.input_limits, self.rate_limit
        for k in range(out.shape[0]):
            prev = up if k == 0 else out[k - 1]
            out[k] = np.minimum(np.maximum(out[k], np.maximum(lo, prev - rate)), np.minimum(hi, prev + rate))
        return out

    def update(self, reference: object, measurement: object) -> np.ndarray:
        """One sample: estimate ``[x; d]``, solve the QP, apply the first move; returns ``(m,)`` deviation V.

        Parameters
        ----------
        reference : array_like
            Tracked-output references ``(p_t,)`` (deviation rad; a scalar for one).
        measurement : array_like
            Measured outputs ``(p,)`` (deviation rad).

        Raises
        ------
        InputError
            A reference or measurement that is not real and finite or has the wrong shape.
        SimulationError
            The QP is infeasible (hard output limits no input sequence can meet).

        Examples
        --------
        A rate limit of 0.25 V per sample: the first moves towards a far reference climb by 0.25 V:

        >>> mpc = MPCController(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1), horizon=10, rate_limit=0.25)
        >>> [round(float(mpc.update(5.0, 0.0)[0]), 9) for _ in range(3)]
        [0.25, 0.5, 0.75]
        """
        p = self._C.shape[0]
        y = real_array("measurement (deviation rad)", np.ravel(np.asarray(measurement, dtype=float)), (p,))
        n, m = self._B.shape
        self._xe = self._xbar + self._Lc @ (y - self._Ce @ self._xbar)
        u = self.plan(self._xe[:n], self._xe[n:], reference)[0]  # within the input and rate limits from u_prev
        self._u_prev = u
        self._xbar = self._Ae @ self._xe + self._Be @ u
        return u

    def compensator(self) -> control.StateSpace:
        """The controller while no constraint is active, a linear compensator: inputs ``[r, y]`` (deviation rad),
        output ``u`` (deviation V), ``dt = Ts``; its states are the estimator's prediction ``[x_bar; d_bar]``.

        With no constraint active the plan's first move is ``u = u_s - K (x_hat - x_s)`` (module docstring), linear
        in the estimate, which is linear in the measurement, and ``(x_s, u_s)`` linear in the reference and the
        disturbance estimate. So the unconstrained MPC is this LTI system exactly; its feedback part is
        ``-compensator()[:, n_references:]``, the ``K_y`` whose loop margins and closed-loop modes
        (:mod:`trms.control.damping`) are the MPC's away from its limits.

        Examples
        --------
        Updates away from every limit equal the compensator's response:

        >>> m = control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)
        >>> mpc = MPCController(m, horizon=10)
        >>> K = mpc.compensator()
        >>> x = np.zeros(K.nstates)
        >>> same = []
        >>> for r, y in [(0.1, 0.0), (0.1, 0.02), (0.1, 0.05)]:
        ...     w = np.array([r, y])
        ...     same.append(bool(np.isclose((K.C @ x + K.D @ w)[0], mpc.update(r, y)[0], rtol=1e-12, atol=1e-15)))
        ...     x = K.A @ x + K.B @ w
        >>> same
        [True, True, True]
        """
        n, m = self._B.shape
        nt = len(self.tracked)
        T = self._target
        # x_hat = M x_bar + L_c y (measurement update); [x_s; u_s] = T [B d_hat; r], d_hat = x_hat[n:]
        M = np.eye(n + m) - self._Lc @ self._Ce
        from_d = T[:, :n] @ self._B  # (n + m, m): x_s and u_s per unit of d_hat
        from_r = T[:, n:]  # (n + m, p_t)
        pick_x = np.hstack([np.eye(n), np.zeros((n, m))])
        pick_d = np.hstack([np.zeros((m, n)), np.eye(m)])
        # u = u_s - K (x - x_s) = F x_hat + G r
        F = from_d[n:] @ pick_d - self.K @ pick_x + self.K @ from_d[:n] @ pick_d
        G = from_r[n:] + self.K @ from_r[:n]
        C = F @ M
        D = np.hstack([G, F @ self._Lc])
        A = self._Ae @ M + self._Be @ C
        B = np.hstack([self._Be @ G, self._Ae @ self._Lc + self._Be @ F @ self._Lc])
        inputs = [f"r{i}" for i in range(nt)] + [f"y{i}" for i in range(self._C.shape[0])]
        return control.ss(A, B, C, D, self.model.dt, inputs=inputs, outputs=[f"u{i}" for i in range(m)], name="mpc")


def mpc_for_plant(model: control.StateSpace, plant: Plant, **options: Any) -> MPCController:
    """An :class:`MPCController` for ``plant`` with its input limits and its outputs' end stops (module docstring).

    Parameters
    ----------
    model : control.StateSpace
        Design model at the plant's sample time.
    plant : Plant
        Gives ``input_limits`` (:func:`~trms.control.loop.deviation_limits`) and ``output_limits``
        (:func:`~trms.control.limits.output_stop_limits`) unless ``options`` name them.
    **options
        Other :class:`MPCController` arguments.

    Examples
    --------
    >>> from trms.worlds import design_model, make_plant
    >>> mpc = mpc_for_plant(design_model("1dof", 0.1), make_plant("linear", "1dof", 0.1), horizon=20)
    >>> [round(float(v[0]), 3) for v in mpc.input_limits], [float(v[0]) for v in mpc.output_limits]
    ([-10.567, 9.433], [-1.1, 1.1])
    """
    options.setdefault("input_limits", deviation_limits(plant))
    options.setdefault("output_limits", output_stop_limits(plant))
    return MPCController(model, **options)
