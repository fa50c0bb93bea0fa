"""Small dense convex quadratic programs: the exact solution, and the optimality check of any candidate.

The problem is OSQP's form,

``minimise 1/2 x' H x + q' x  subject to  lower <= A x <= upper``,

with ``H`` positive definite (so the solution is unique) and ``+-inf`` for a side without a bound.

:func:`kkt_residuals` measures how far a candidate ``x`` with multipliers ``y`` (OSQP's sign convention: ``y_i > 0``
pushes on the upper side, ``y_i < 0`` on the lower one) is from the Karush-Kuhn-Tucker conditions: stationarity
``H x + q + A' y = 0``, primal feasibility, and complementarity (a multiplier only on a side the row touches). For a
convex problem these conditions are sufficient: a candidate whose residuals are at round-off is the optimum.

:func:`solve_exact` finds the optimum by a finite active-set method, not an iteration to a tolerance: with
``H = R' R`` and ``x = x_u + R^-1 z`` (``x_u = -H^-1 q``, the unconstrained optimum), the problem is the least-distance
programme ``minimise |z|^2 subject to E z >= f`` (``E = G R^-1``, ``f = h - G x_u`` for the finite sides written
``G x >= h``), which Lawson and Hanson (1974, ch. 23) solve by one non-negative least-squares problem
(``scipy.optimize.nnls``, their active-set algorithm): ``minimise |[E'; f'] w - e_(n+1)|`` over ``w >= 0``. A zero
residual proves the constraints infeasible; otherwise ``z`` and the multipliers follow from the residual, and are
refined to round-off on the constraints the algorithm made active (the minimum-norm ``z`` meeting them as equalities,
kept where its multipliers stay non-negative and its KKT residuals are the smaller).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg
import scipy.optimize

from trms.errors import SimulationError

__all__ = ["KKTResiduals", "kkt_residuals", "solve_exact", "solve_checked", "InfeasibleProblem"]


class InfeasibleProblem(SimulationError):
    """No ``x`` meets the constraints (the least-distance programme's residual is zero)."""


@dataclass(frozen=True)
class KKTResiduals:
    """How far a candidate is from optimality, each part scaled to be dimensionless.

    Attributes
    ----------
    stationarity : float
        ``max |H x + q + A' y|`` over ``1 + max |q|``.
    primal : float
        Largest bound violation of ``A x`` over ``1 + max |finite bound|``.
    complementarity : float
        Largest ``|y_i|`` times the distance of row ``i`` from the side its multiplier pushes on, over
        ``(1 + max |y|) (1 + max |finite bound|)``, or a multiplier on a side without a bound over ``1 + max |y|``.
    """

    stationarity: float
    primal: float
    complementarity: float

    @property
    def worst(self) -> float:
        """The largest of the three."""
        return max(self.stationarity, self.primal, self.complementarity)


def kkt_residuals(
    H: np.ndarray, q: np.ndarray, A: np.ndarray, lower: np.ndarray, upper: np.ndarray, x: np.ndarray, y: np.ndarray
) -> KKTResiduals:
    """The Karush-Kuhn-Tucker residuals of ``(x, y)`` (module docstring).

    Parameters
    ----------
    H, q, A, lower, upper : numpy.ndarray
        The problem, ``H`` ``(n, n)``, ``q`` ``(n,)``, ``A`` ``(k, n)``, bounds ``(k,)`` (``+-inf`` for none).
    x, y : numpy.ndarray
        Candidate solution ``(n,)`` and multipliers ``(k,)`` in OSQP's sign convention.

    Returns
    -------
    KKTResiduals

    Examples
    --------
    ``minimise (x - 2)^2 / 2`` with ``x <= 1``: the optimum ``x = 1`` with multiplier 1; ``x = 1.5`` is not:

    >>> H, q, A = np.eye(1), np.array([-2.0]), np.eye(1)
    >>> lo, hi = np.array([-np.inf]), np.array([1.0])
    >>> kkt_residuals(H, q, A, lo, hi, np.array([1.0]), np.array([1.0])).worst
    0.0
    >>> kkt_residuals(H, q, A, lo, hi, np.array([1.5]), np.array([0.5])).primal
    0.25
    """
    finite = np.concatenate([np.abs(lower[np.isfinite(lower)]), np.abs(upper[np.isfinite(upper)]), [0.0]])
    bound_scale = 1.0 + float(np.max(finite))
    rows = A @ x
    stationarity = float(np.max(np.abs(H @ x + q + A.T @ y), initial=0.0)) / (1.0 + float(np.max(np.abs(q), initial=0)))
    violation = np.maximum(np.maximum(rows - upper, lower - rows), 0.0)
    primal = float(np.max(violation, initial=0.0)) / bound_scale
    finite_up, finite_lo = np.isfinite(upper), np.isfinite(lower)
    push = np.zeros_like(y)
    on_up, on_lo = (y > 0) & finite_up, (y < 0) & finite_lo
    push[on_up] = y[on_up] * np.abs(upper[on_up] - rows[on_up])
    push[on_lo] = -y[on_lo] * np.abs(rows[on_lo] - lower[on_lo])
    y_scale = 1.0 + float(np.max(np.abs(y), initial=0.0))
    unbounded = ((y > 0) & ~finite_up) | ((y < 0) & ~finite_lo)  # a multiplier on a side with no bound
    complementarity = max(
        float(np.max(push, initial=0.0)) / (y_scale * bound_scale),
        float(np.max(np.abs(y[unbounded]), initial=0.0)) / y_scale,
    )
    return KKTResiduals(stationarity, primal, complementarity)


def solve_exact(
    H: np.ndarray, q: np.ndarray, A: np.ndarray, lower: np.ndarray, upper: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The optimum of the problem and its multipliers, by the least-distance programme (module docstring).

    Parameters
    ----------
    H : numpy.ndarray
        Positive definite ``(n, n)``.
    q, A, lower, upper : numpy.ndarray
        ``(n,)``, ``(k, n)`` and ``(k,)`` bounds (``+-inf`` for none).

    Returns
    -------
    tuple of numpy.ndarray
        ``x`` ``(n,)`` and ``y`` ``(k,)`` (OSQP's sign convention).

    Raises
    ------
    InfeasibleProblem
        No ``x`` meets the constraints.

    Examples
    --------
    ``minimise (x1 - 2)^2 + (x2 - 2)^2`` (halved) with ``x1 + x2 <= 2`` and ``x1 >= 0``: the projection ``(1, 1)``;
    ``x1 + x2 <= 2`` with ``x1 + x2 >= 3`` has no solution:

    >>> H, q = np.eye(2), np.array([-2.0, -2.0])
    >>> A = np.array([[1.0, 1.0], [1.0, 0.0]])
    >>> x, y = solve_exact(H, q, A, np.array([-np.inf, 0.0]), np.array([2.0, np.inf]))
    >>> np.round(x, 12).tolist(), np.round(y, 12).tolist()
    ([1.0, 1.0], [1.0, 0.0])
    >>> solve_exact(H, q, np.array([[1.0, 1.0], [1.0, 1.0]]), np.array([-np.inf, 3.0]), np.array([2.0, np.inf]))
    Traceback (most recent call last):
    ...
    trms.control.qp.InfeasibleProblem: the constraints admit no solution (least-distance residual 0)
    """
    r = scipy.linalg.cholesky(H)  # upper: H = R' R
    x_free = -scipy.linalg.cho_solve((r, False), q)
    up, lo = np.flatnonzero(np.isfinite(upper)), np.flatnonzero(np.isfinite(lower))
    g = np.vstack([-A[up], A[lo]])
    f = np.concatenate([-upper[up], lower[lo]]) - g @ x_free
    if not np.any(f > 0):
        return x_free, np.zeros(A.shape[0])  # the unconstrained optimum meets every bound
    e = scipy.linalg.solve_triangular(r, g.T, trans="T").T  # G R^-1
    norms = np.linalg.norm(e, axis=1)
    norms[norms == 0] = 1.0
    m = np.vstack([e.T, f]) / norms  # each constraint scaled to a unit normal: the same set, better conditioned
    target = np.zeros(m.shape[0])
    target[-1] = 1.0
    w, _ = scipy.optimize.nnls(m, target, maxiter=50 * m.shape[1])
    resid = m @ w - target
    if resid[-1] > -1e-12:  # the residual is 0: e_(n+1) is a non-negative combination of [E'; f']
        raise InfeasibleProblem("the constraints admit no solution (least-distance residual 0)")
    candidates = [(resid[:-1] / -resid[-1], w / -resid[-1])]
    # the active-set algorithm stops at its own tolerance (about 1e-9 here): on the constraints it made active,
    # the minimum-norm z with E_W z = f_W and its multipliers, each one least-squares solve, refine it to round-off
    act = np.flatnonzero(w > 0)
    e_w, f_w = m[:-1, act].T, m[-1, act]
    z_w = np.linalg.lstsq(e_w, f_w, rcond=None)[0]
    lam_w = np.linalg.lstsq(e_w.T, z_w, rcond=None)[0]
    if np.all(lam_w >= 0):
        candidates.append((z_w, np.zeros_like(w)))
        candidates[-1][1][act] = lam_w
    best: tuple[float, np.ndarray, np.ndarray] | None = None
    for z, lam_scaled in candidates:
        lam = lam_scaled / norms
        y = np.zeros(A.shape[0])
        y[up] += lam[: up.size]
        y[lo] -= lam[up.size :]
        x = x_free + scipy.linalg.solve_triangular(r, z)
        worst = kkt_residuals(H, q, A, lower, upper, x, y).worst
        if best is None or worst < best[0]:
            best = (worst, x, y)
    assert best is not None
    return best[1], best[2]


def solve_checked(
    solver: Any,
    H: np.ndarray,
    q: np.ndarray,
    A: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    *,
    tolerance: float = 1e-9,
) -> tuple[np.ndarray, dict[str, Any]]:
    """Solve by an OSQP solver set up for this ``H`` and ``A``; keep its answer only if the KKT conditions certify it.

    OSQP (an ADMM method, warm-started, polished on its active set) is fast but stops at an iteration cap or a
    tolerance; its answer is kept when :func:`kkt_residuals` are at most ``tolerance``, else :func:`solve_exact`
    solves the problem and its answer, certified the same way, is kept.

    Parameters
    ----------
    solver : osqp.OSQP
        Set up with ``H`` (upper triangle) and ``A``; its ``q`` and bounds are updated here.
    H, q, A, lower, upper : numpy.ndarray
        The problem (module docstring).
    tolerance : float
        Largest KKT residual (:attr:`KKTResiduals.worst`) of a certified answer.

    Returns
    -------
    tuple
        ``x`` ``(n,)`` and a dict: ``solver`` (``"osqp"`` or ``"exact"``), ``osqp_status``, ``osqp_iterations``,
        ``kkt_residual`` (of the answer returned) and ``converged`` (whether it is certified; if neither answer is,
        the one of the smaller residual is returned).

    Raises
    ------
    InfeasibleProblem
        The exact solver proves the constraints infeasible.

    Examples
    --------
    >>> import osqp, scipy.sparse as sp
    >>> H, A = np.eye(2), np.array([[1.0, 1.0]])
    >>> solver = osqp.OSQP()
    >>> solver.setup(sp.csc_matrix(H), np.zeros(2), sp.csc_matrix(A), np.array([-np.inf]), np.array([2.0]),
    ...              verbose=False)
    >>> x, info = solve_checked(solver, H, np.array([-2.0, -2.0]), A, np.array([-np.inf]), np.array([2.0]))
    >>> np.round(x, 9).tolist(), info["converged"]
    ([1.0, 1.0], True)
    """
    solver.update(q=q, l=lower, u=upper)
    res = solver.solve(raise_error=False)
    info: dict[str, Any] = {
        "solver": "osqp",
        "osqp_status": str(res.info.status),
        "osqp_iterations": int(res.info.iter),
    }
    best: tuple[float, np.ndarray] | None = None
    if res.x is not None and np.all(np.isfinite(res.x)) and np.all(np.isfinite(res.y)):
        worst = kkt_residuals(H, q, A, lower, upper, res.x, res.y).worst
        if worst <= tolerance:
            return res.x, info | {"kkt_residual": worst, "converged": True}
        best = (worst, res.x)
    try:
        x, y = solve_exact(H, q, A, lower, upper)
    except InfeasibleProblem:
        raise
    except RuntimeError as exc:  # the non-negative least squares ran out of iterations
        if best is None:
            raise SimulationError(f"OSQP ({info['osqp_status']}) and the exact solver ({exc}) found no x") from exc
    else:
        worst = kkt_residuals(H, q, A, lower, upper, x, y).worst
        if best is None or worst < best[0]:
            best = (worst, x)
            info["solver"] = "exact"
    assert best is not None
    return best[1], info | {"kkt_residual": best[0], "converged": best[0] <= tolerance}
