"""The exact QP solver against an enumeration of every active set, its infeasibility proof, the KKT certificate,
and the checked OSQP solve that falls back on the exact solver."""

import itertools

import numpy as np
import pytest
import scipy.sparse as sp

from trms.control.qp import InfeasibleProblem, kkt_residuals, solve_checked, solve_exact

osqp = pytest.importorskip("osqp")


def _random_problem(rng: np.random.Generator, n: int, k: int) -> tuple[np.ndarray, ...]:
    """A strictly convex QP with ``k`` two-sided rows, bounds around a random point (so it is feasible)."""
    m = rng.standard_normal((n, n))
    H = m @ m.T + 0.1 * np.eye(n)
    q = 3.0 * rng.standard_normal(n)
    A = rng.standard_normal((k, n))
    centre = A @ rng.standard_normal(n)
    width = rng.uniform(0.1, 1.0, k)
    lower, upper = centre - width, centre + width
    lower[rng.random(k) < 0.3] = -np.inf
    upper[rng.random(k) < 0.3] = np.inf
    return H, q, A, lower, upper


def _enumerated(H, q, A, lower, upper):
    """The optimum by trying every active set (each row free, at its lower or at its upper bound): the one point
    that is feasible with multipliers of the right sign (the KKT conditions, sufficient for a convex problem)."""
    n, k = H.shape[0], A.shape[0]
    for sides in itertools.product((0, -1, 1), repeat=k):
        rows = [i for i, s in enumerate(sides) if s]
        bound = np.array([upper[i] if sides[i] > 0 else lower[i] for i in rows])
        if not np.all(np.isfinite(bound)) or len(rows) > n:
            continue
        kkt = np.block([[H, A[rows].T], [A[rows], np.zeros((len(rows), len(rows)))]])
        try:
            sol = np.linalg.solve(kkt, np.concatenate([-q, bound]))
        except np.linalg.LinAlgError:
            continue
        x, mult = sol[:n], sol[n:]
        signs_ok = all(mult[j] * sides[i] >= -1e-10 for j, i in enumerate(rows))
        if signs_ok and np.all(A @ x <= upper + 1e-9) and np.all(A @ x >= lower - 1e-9):
            return x
    raise AssertionError("no active set satisfies the KKT conditions")


@pytest.mark.parametrize("seed", range(8))
def test_the_exact_solution_is_the_enumerated_optimum(seed):
    rng = np.random.default_rng(9100 + seed)
    H, q, A, lower, upper = _random_problem(rng, n=int(rng.integers(2, 5)), k=int(rng.integers(3, 7)))
    x, y = solve_exact(H, q, A, lower, upper)
    np.testing.assert_allclose(x, _enumerated(H, q, A, lower, upper), atol=1e-9)
    assert kkt_residuals(H, q, A, lower, upper, x, y).worst < 1e-10


def test_an_unconstrained_optimum_inside_the_bounds_is_returned_as_it_is():
    H, q, A = np.diag([2.0, 1.0]), np.array([-2.0, 1.0]), np.eye(2)
    x, y = solve_exact(H, q, A, np.full(2, -5.0), np.full(2, 5.0))
    np.testing.assert_allclose(x, [1.0, -1.0], rtol=0, atol=1e-15)
    assert not np.any(y)


def test_infeasible_bounds_are_proved_so():
    H, q = np.eye(2), np.zeros(2)
    A = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])  # x1 >= 1, x2 >= 1, x1 + x2 <= 1
    with pytest.raises(InfeasibleProblem, match="no solution"):
        solve_exact(H, q, A, np.array([1.0, -np.inf, 1.0]), np.array([np.inf, 1.0, np.inf]))


def test_the_certificate_names_each_broken_condition():
    H, q, A = np.eye(1), np.array([-2.0]), np.eye(1)
    lo, hi = np.array([-np.inf]), np.array([1.0])
    assert kkt_residuals(H, q, A, lo, hi, np.array([1.0]), np.array([1.0])).worst == 0.0
    off = kkt_residuals(H, q, A, lo, hi, np.array([0.5]), np.array([1.5]))  # stationary, feasible, not touching
    assert off.stationarity == 0.0 and off.primal == 0.0 and off.complementarity > 0.1
    wrong_side = kkt_residuals(H, q, A, lo, hi, np.array([1.0]), np.array([-1.0]))  # a multiplier on no bound
    assert wrong_side.complementarity == pytest.approx(0.5)


def _osqp(H, A, lower, upper, **settings):
    solver = osqp.OSQP()
    solver.setup(
        sp.csc_matrix(np.triu(H)), np.zeros(H.shape[0]), sp.csc_matrix(A), lower, upper, verbose=False, **settings
    )
    return solver


def test_an_answer_osqp_cannot_certify_is_solved_exactly():
    rng = np.random.default_rng(9200)
    H, q, A, lower, upper = _random_problem(rng, n=4, k=6)
    capped = _osqp(H, A, lower, upper, max_iter=1, polishing=False)
    x, info = solve_checked(capped, H, q, A, lower, upper)
    assert info["solver"] == "exact" and info["converged"] and info["osqp_status"] != "solved"
    np.testing.assert_allclose(x, _enumerated(H, q, A, lower, upper), atol=1e-9)
    x, info = solve_checked(_osqp(H, A, lower, upper, eps_abs=1e-10, eps_rel=1e-10), H, q, A, lower, upper)
    assert info["solver"] == "osqp" and info["converged"] and info["kkt_residual"] <= 1e-9


def test_when_neither_answer_certifies_the_better_one_is_returned_flagged(monkeypatch):
    import trms.control.qp as qp

    rng = np.random.default_rng(9300)
    H, q, A, lower, upper = _random_problem(rng, n=4, k=6)
    exact = solve_exact(H, q, A, lower, upper)[0]
    monkeypatch.setattr(qp, "solve_exact", lambda *a: (_ for _ in ()).throw(RuntimeError("maximum iterations")))
    x, info = qp.solve_checked(_osqp(H, A, lower, upper, max_iter=3, polishing=False), H, q, A, lower, upper)
    assert not info["converged"] and info["kkt_residual"] > 1e-9 and info["solver"] == "osqp"
    assert np.max(np.abs(x - exact)) > 1e-6  # OSQP's unconverged answer, and it says so
