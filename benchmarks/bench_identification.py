"""Speed of the identification toolkit: ARMAX by PEM and RBF-OLS, against plain references.

Run on demand (never a timed test):

    .venv/bin/python benchmarks/bench_identification.py

Cases (goals in brackets):

* ARMAX ``na = nb = nc = 4``, ``nk = 1`` on 600 samples of eq. (3.11) with coloured noise
  [< 50 ms]; references on the same criterion from the same initial estimate: a per-sample
  Python-loop Gauss-Newton PEM, and ``scipy.optimize.least_squares`` (Levenberg-Marquardt,
  finite-difference Jacobian).
* NARX-RBF by OLS on 300 samples, ``ny = nu = 8`` (the thesis's ch. 5 set-up) [< 1 s];
  reference: textbook OLS that orthogonalises each candidate separately at every pass.

Prints median wall times, the ratios, and the losses reached (they must agree).
"""

from __future__ import annotations

import statistics
import time
from typing import Callable

import numpy as np
import scipy.optimize
import scipy.signal

import scipy.spatial.distance

from trms.identification.data import lag_matrix, siso_data
from trms.identification.linear import _initial_armax, _regressors, armax
from trms.identification.rbf import narx_rbf, ols_select
from trms.identification.signals import random_binary, uniform_noise
from trms.reference import EQ_3_11_DEN, EQ_3_11_NUM

TS = 0.2
NA = NB = NC = 4
NK = 1


def median_time(fn: Callable[[], object], repeat: int) -> tuple[float, object]:
    fn()  # warm up
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def armax_data(n: int = 600) -> tuple[np.ndarray, np.ndarray]:
    a, b, c = np.array(EQ_3_11_DEN), np.array([0.0, *EQ_3_11_NUM]), np.array([1.0, -0.7, 0.2])
    u = random_binary(n * TS, TS, 5.0, 1.0, seed=1)
    e = np.random.default_rng(1001).standard_normal(n) * 0.02
    return scipy.signal.lfilter(b, a, u) + scipy.signal.lfilter(c, a, e), u


def loop_pem(y: np.ndarray, u: np.ndarray, theta0: np.ndarray, tol: float = 1e-7, max_iter: int = 200) -> float:
    """Plain Gauss-Newton PEM with per-sample loops for the errors and their gradient."""
    start = max(NA, NK + NB - 1)
    n, p = y.size, NA + NB + NC

    def errors_and_gradient(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        c = theta[NA + NB :]
        eps = np.zeros(n)
        psi = np.zeros((n, p))
        for t in range(start, n):
            phi = np.empty(p)
            for i in range(NA):
                phi[i] = -y[t - 1 - i]
            for j in range(NB):
                phi[NA + j] = u[t - NK - j]
            for k in range(NC):
                phi[NA + NB + k] = eps[t - 1 - k]
            eps[t] = y[t] - phi @ theta
            row = phi.copy()
            for k in range(NC):
                row -= c[k] * psi[t - 1 - k]
            psi[t] = row
        return eps[start:], psi[start:]

    theta = theta0.copy()
    eps, psi = errors_and_gradient(theta)
    v = eps @ eps
    for _ in range(max_iter):
        step = np.linalg.lstsq(psi, eps, rcond=None)[0]
        if (psi.T @ eps) @ step / v < tol:
            break
        for k in range(11):
            cand = theta + step * 0.5**k
            if np.max(np.abs(np.roots(np.r_[1.0, cand[NA + NB :]]))) >= 1:
                continue
            e2, p2 = errors_and_gradient(cand)
            if e2 @ e2 < v:
                theta, eps, psi, v = cand, e2, p2, e2 @ e2
                break
        else:
            break
    return float(v / eps.size)


def scipy_pem(y: np.ndarray, u: np.ndarray, theta0: np.ndarray) -> float:
    """``scipy.optimize.least_squares`` (LM, finite differences) on the same conditional errors."""
    start = max(NA, NK + NB - 1)
    d = siso_data(y, u, sample_time=TS)
    phi_ab = _regressors(d, NA, NB, NK, start)
    target = y[start:]

    def errors(theta: np.ndarray) -> np.ndarray:
        return scipy.signal.lfilter([1.0], np.r_[1.0, theta[NA + NB :]], target - phi_ab @ theta[: NA + NB])

    res = scipy.optimize.least_squares(errors, theta0, method="lm", xtol=1e-10, ftol=1e-10)
    return float(res.fun @ res.fun / res.fun.size)


def textbook_ols(P: np.ndarray, d: np.ndarray, max_terms: int) -> list[int]:
    """Classical OLS: every pass orthogonalises every remaining candidate against the chosen
    basis, one candidate at a time; column 0 (the bias) is chosen first."""
    chosen: list[int] = [0]
    basis: list[np.ndarray] = [P[:, 0].copy()]
    dd = d @ d
    for _ in range(max_terms - 1):
        best, best_err, best_w = -1, 0.0, None
        for j in range(P.shape[1]):
            if j in chosen:
                continue
            w = P[:, j].copy()
            for q in basis:
                w -= (q @ P[:, j]) / (q @ q) * q
            ww = w @ w
            if ww < 1e-10 * (P[:, j] @ P[:, j]):
                continue
            err = (w @ d) ** 2 / (ww * dd)
            if err > best_err:
                best, best_err, best_w = j, err, w
        if best < 0:
            break
        chosen.append(best)
        basis.append(best_w)
    return chosen


def main() -> None:
    y, u = armax_data(600)
    t_fast, model = median_time(lambda: armax(y, u, NA, NB, NC, NK, sample_time=TS), 30)
    d = siso_data(y, u, sample_time=TS)
    theta0 = _initial_armax(d, NA, NB, NC, NK, max(NA, NK + NB - 1))
    t_loop, loss_loop = median_time(lambda: loop_pem(y, u, theta0), 3)
    t_scipy, loss_scipy = median_time(lambda: scipy_pem(y, u, theta0), 5)
    print("ARMAX(4,4,4,1) by PEM on 600 samples (goal < 50 ms)")
    print(f"  trms armax             {1e3 * t_fast:8.2f} ms  loss {model.loss:.6e}  ({model.info['iterations']} iterations)")
    print(f"  per-sample loop PEM    {1e3 * t_loop:8.2f} ms  loss {loss_loop:.6e}  ratio {t_loop / t_fast:6.1f}x")
    print(f"  scipy least_squares    {1e3 * t_scipy:8.2f} ms  loss {loss_scipy:.6e}  ratio {t_scipy / t_fast:6.1f}x")

    un = uniform_noise(60.0, TS, 2.0, 1.0, seed=1)
    yn = armax_data(300)[0] + 0.2 * scipy.signal.lfilter([0.0, 0.3], [1.0, -0.8], un**2)
    t_rbf, rbf = median_time(lambda: narx_rbf(yn, un, 8, 8, 1, max_centres=13, tolerance=0.0, sample_time=TS), 10)
    # the same candidate matrix for the OLS-only comparison
    ynn, unn = (yn - yn.mean()) / yn.std(ddof=1), (un - un.mean()) / un.std(ddof=1)
    x = np.hstack([lag_matrix(ynn, range(1, 9), 8), lag_matrix(unn, range(1, 9), 8)])
    P = np.hstack([np.ones((x.shape[0], 1)), np.exp(-scipy.spatial.distance.cdist(x, x, "sqeuclidean") / rbf.width**2)])
    target = ynn[8:]
    t_ols, sel = median_time(lambda: ols_select(P, target, 14, 0.0, forced=0), 10)
    t_text, chosen = median_time(lambda: textbook_ols(P, target, 14), 1)
    print("NARX-RBF by OLS on 300 samples, ny = nu = 8, 13 centres + bias (goal < 1 s)")
    print(f"  trms narx_rbf (whole)  {1e3 * t_rbf:8.2f} ms  training SSE {rbf.training_sse:.4g} (normalised)")
    print(f"  trms ols_select only   {1e3 * t_ols:8.2f} ms")
    print(f"  textbook OLS           {1e3 * t_text:8.2f} ms  ratio {t_text / t_ols:6.1f}x  "
          f"same centres: {chosen == sel.selected.tolist()}")


if __name__ == "__main__":
    main()
