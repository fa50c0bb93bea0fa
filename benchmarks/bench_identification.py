"""The identification toolkit against plain references and against peer libraries, in one run.

Run on demand (never a timed test):

    .venv/bin/python benchmarks/bench_identification.py

The peers are installed only for this benchmark (they are not dependencies of trms):

    .venv/bin/pip install statsmodels sippy-unipi sysidentpy

A peer that is not importable is skipped with a printed line.

Peer table (known truth, same data for everyone; accuracy and time as ratios to trms):

* ARMAX data: eq. (3.11) with ``C = [1, -0.7, 0.2]``, 600 samples: trms ``armax``;
  statsmodels ``ARIMA`` with the lagged outputs and inputs as regressors and MA(2) errors
  (exactly ARMAX, exact Gaussian likelihood); SIPPY ``ARMAX`` (``OPT``).
* Box-Jenkins data (plant ``B/F``, disturbance ``C/D e`` with its own pole), 2000 samples:
  trms ``bj`` and ``armax`` of the plant's order; SIPPY ``BJ``; sysidentpy FROLS (linear
  polynomial NARMAX, ``ylag = xlag = 2``).
* Output-error data (same plant, white output noise): trms ``oe``; SIPPY ``OE``; sysidentpy.
* The multistart of ``oe`` and ``bj`` (module :mod:`trms.identification.oe_bj`) against one start
  on the Box-Jenkins data, 400 and 1000 samples: time per fit, starts searched, loss ratio.
* A 6th-order two-resonance MIMO plant, both inputs excited at once, 4000 samples:
  trms ``n4sid``; SIPPY ``N4SID`` (order 6 given to both).
* Polynomial NARX (``peer_frols``): trms ``narx_poly`` against sysidentpy's FROLS on a 4-term degree-2 truth,
  sysidentpy both with trms's term count (the like-for-like time: the same terms and fit) and with its AIC order
  selection (15 candidate models fitted: not a like-for-like time), and the like-for-like ratio at N = 1200,
  12 000 and 60 000. sysidentpy's fixed cost dominates the short record and trms's cost grows faster with N, so
  the ratio falls as the record grows (below 1 at the longest): a speed-up quoted against the AIC mode, or at
  one record length, says nothing of the others.
* MIMO polynomial models on a 2x2 ARMAX truth (each output: both inputs, its own ``A`` and ``C``), 2000
  samples, 5 seeds: trms ``arx_mimo`` and ``armax_mimo``; SIPPY MIMO ``ARX`` (LLS) and ``ARMAX`` (ILLS, OPT);
  free-run fit on fresh noise-free data, largest DC-gain error, time (``peer_mimo_pem``, run last).
* ``n4sid`` on slow modes (0.1 and 0.34 Hz, zeta 0.05, 2x2, Ts 0.1 s, 2000 samples, 100 seeds):
  the former fixed 11-sample default horizon against the adaptive default; unstable models,
  median frequency and damping errors of the two modes, time per call.

* Non-parametric frequency response on a known 2nd-order system (``G = (0.5 q^-1 + 0.3 q^-2) /
  (1 - 1.2 q^-1 + 0.49 q^-2)``, white unit input, output noise 0.1, 4000 samples, 50 seeds): trms
  ``spa`` (default ``M = 30`` and ``M = 100``) and ``etfe`` (31-line smoothing) against the Welch
  ratio ``scipy.signal.csd / scipy.signal.welch`` (Hann, half overlap, 64 and 256 samples per
  segment): median largest error relative to the peak gain and time per call; ``impulseest``
  (TC kernel and plain least squares, 50 coefficients) on the same data; recursive ARX/ARMAX
  per-sample cost (batch function and online ``update``).

Accuracy: relative DC-gain error (SISO) or largest relative error of the two resonance
frequencies (MIMO), and the free-run fit (%) on fresh noise-free validation data.

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

import importlib
import statistics
import time
import tracemalloc
import warnings
from collections.abc import Callable
from typing import Any

import control
import numpy as np
import scipy.optimize
import scipy.signal
import scipy.spatial.distance

from trms.identification import armax_mimo, arx_mimo, bj, n4sid, oe
from trms.identification.data import lag_matrix, siso_data
from trms.identification.linear import _initial_armax, _regressors, armax
from trms.identification.nonparametric import etfe, impulseest, spa
from trms.identification.oe_bj import STARTS
from trms.identification.ols import ols_select
from trms.identification.polynomial import modes_of_poles
from trms.identification.rbf import narx_rbf
from trms.identification.recursive import RecursiveEstimator, recursive_armax, recursive_arx
from trms.identification.validation import fit_percent
from trms.reference import EQ_3_11_DEN, EQ_3_11_NUM
from trms.signals import random_binary, uniform_noise

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


# ---------------------------------------------------------------- peers on known truth
PLANT_B, PLANT_F = np.array([0.0, 0.4, 0.25]), np.array([1.0, -1.3, 0.6])
NOISE_C, NOISE_D = np.array([1.0, 0.5]), np.array([1.0, -0.9])
TS_BJ = 0.1


def _peer(name: str) -> Any | None:
    try:
        return importlib.import_module(name)
    except ImportError:
        print(f"  (peer {name} is not importable: skipped; pip install statsmodels sippy-unipi sysidentpy)")
        return None


def _binary(n: int, seed: int, channels: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    u = np.repeat(np.sign(rng.standard_normal((n // 2 + 1, channels))), 2, axis=0)[:n]
    return u[:, 0] if channels == 1 else u


def siso_case(kind: str, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    u = _binary(n, seed)
    e = 0.1 * np.random.default_rng(seed + 500).standard_normal(n)
    noise = scipy.signal.lfilter(NOISE_C, NOISE_D, e) if kind == "bj" else e
    return scipy.signal.lfilter(PLANT_B, PLANT_F, u) + noise, u


def _timed(fn: Callable[[], Any], repeat: int) -> tuple[float, Any]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return median_time(fn, repeat)


def _tf_row(
    name: str, tf: control.TransferFunction, seconds: float, truth_dc: float, uv: np.ndarray, yv: np.ndarray
) -> tuple[str, float, float, float]:
    dc = float(np.real(control.dcgain(tf)))
    sim = control.forced_response(tf, U=uv).outputs
    return name, 100 * (dc / truth_dc - 1), fit_percent(yv, sim), seconds


def _print_table(title: str, rows: list[tuple[str, float, float, float]], accuracy: str) -> None:
    print(title)
    print(f"  {'method':38s} {accuracy:>16s} {'val. fit %':>11s} {'time ms':>10s} {'time / trms':>12s}")
    base = rows[0][3]
    for name, err, fit, sec in rows:
        print(f"  {name:38s} {err:+16.3f} {fit:11.2f} {1e3 * sec:10.1f} {sec / base:12.1f}x")


def peer_armax() -> None:
    y, u = armax_data(600)
    a, b = np.array(EQ_3_11_DEN), np.array([0.0, *EQ_3_11_NUM])
    truth_dc = b.sum() / a.sum()
    uv = random_binary(120 * TS, TS, 5.0, 1.0, seed=77)
    yv = scipy.signal.lfilter(b, a, uv)
    rows = []
    t, m = _timed(lambda: armax(y, u, NA, NB, 2, NK, sample_time=TS), 10)
    rows.append(_tf_row("trms armax (4,4,2,1)", m.to_tf(), t, truth_dc, uv, yv))
    sm = _peer("statsmodels.tsa.arima.model")
    if sm is not None:
        start = max(NA, NK + NB - 1)
        x = np.hstack([-lag_matrix(y, range(1, NA + 1), start), lag_matrix(u, range(NK, NK + NB), start)])

        def fit_sm() -> Any:
            return sm.ARIMA(y[start:], exog=x, order=(0, 0, 2), trend="n").fit()

        t, res = _timed(fit_sm, 3)
        theta = np.asarray(res.params)[: NA + NB]
        tf = control.tf(theta[NA:], np.r_[1.0, theta[:NA]], TS)  # b1 z^3 + .. + b4 over z^4 + a1 z^3 + ..: nk = 1
        rows.append(_tf_row("statsmodels ARIMA, y/u lags + MA(2)", tf, t, truth_dc, uv, yv))
    si = _peer("sippy_unipi")
    if si is not None:
        t, res = _timed(
            lambda: si.system_identification(y, u, "ARMAX", ARMAX_orders=[NA, NB, 2, 0], ARMAX_mod="OPT", tsample=TS), 3
        )
        rows.append(_tf_row("SIPPY ARMAX (OPT)", res.G, t, truth_dc, uv, yv))
    _print_table("Peers on ARMAX data (eq. 3.11, C = [1, -0.7, 0.2], 600 samples)", rows, "DC gain err %")


def _sysidentpy_row(y: np.ndarray, u: np.ndarray, uv: np.ndarray, yv: np.ndarray, truth_dc: float) -> tuple | None:
    mss = _peer("sysidentpy.model_structure_selection")
    if mss is None:
        return None
    from sysidentpy.basis_function import Polynomial
    from sysidentpy.parameter_estimation import LeastSquares

    def fit() -> Any:
        model = mss.FROLS(
            ylag=2,
            xlag=2,
            elag=2,
            order_selection=True,
            info_criteria="aic",
            n_info_values=8,
            estimator=LeastSquares(),
            basis_function=Polynomial(degree=1),
            model_type="NARMAX",
        )
        model.fit(X=u[:, None], y=y[:, None])
        return model

    t, model = _timed(fit, 3)
    sim = model.predict(X=uv[:, None], y=yv[:, None][:2]).ravel()[: yv.size]
    step = model.predict(X=np.ones((400, 1)), y=np.zeros((2, 1))).ravel()
    return "sysidentpy FROLS (linear NARMAX)", 100 * (step[-1] / truth_dc - 1), fit_percent(yv, sim), t


def peer_bj_oe() -> None:
    truth_dc = PLANT_B.sum() / PLANT_F.sum()
    uv = _binary(1000, 99)
    yv = scipy.signal.lfilter(PLANT_B, PLANT_F, uv)
    si = _peer("sippy_unipi")
    for kind in ("bj", "oe"):
        y, u = siso_case(kind, 2000, 1)
        rows = []
        if kind == "bj":
            t, m = _timed(lambda y=y, u=u: bj(y, u, 2, 1, 1, 2, 1, sample_time=TS_BJ), 10)
            rows.append(_tf_row("trms bj (2,1,1,2,1)", m.to_tf(), t, truth_dc, uv, yv))
            t, m = _timed(lambda y=y, u=u: armax(y, u, 2, 2, 1, 1, sample_time=TS_BJ), 10)
            rows.append(_tf_row("trms armax (2,2,1,1), same plant order", m.to_tf(), t, truth_dc, uv, yv))
            if si is not None:
                t, res = _timed(
                    lambda y=y, u=u: si.system_identification(y, u, "BJ", BJ_orders=[2, 1, 1, 2, 0], tsample=TS_BJ), 1
                )
                rows.append(_tf_row("SIPPY BJ", res.G, t, truth_dc, uv, yv))
        else:
            t, m = _timed(lambda y=y, u=u: oe(y, u, 2, 2, 1, sample_time=TS_BJ), 10)
            rows.append(_tf_row("trms oe (2,2,1)", m.to_tf(), t, truth_dc, uv, yv))
            if si is not None:
                t, res = _timed(
                    lambda y=y, u=u: si.system_identification(y, u, "OE", OE_orders=[2, 2, 0], tsample=TS_BJ), 1
                )
                rows.append(_tf_row("SIPPY OE", res.G, t, truth_dc, uv, yv))
        row = _sysidentpy_row(y, u, uv, yv, truth_dc)
        if row is not None:
            rows.append(row)
        title = (
            "Peers on Box-Jenkins data (B/F plant, C/D disturbance, 2000 samples)"
            if kind == "bj"
            else "Peers on output-error data (B/F plant, white noise, 2000 samples)"
        )
        _print_table(title, rows, "DC gain err %")


def mimo_plant() -> control.StateSpace:
    """Rotor lags (0.8, 0.5 Hz) into a pitch (0.45 Hz) and a yaw (1.3 Hz) resonance, cross-coupled."""
    w1, w2, z1, z2, a1, a2 = 2 * np.pi * 0.45, 2 * np.pi * 1.3, 0.06, 0.1, 2 * np.pi * 0.8, 2 * np.pi * 0.5
    a = np.array(
        [
            [-a1, 0, 0, 0, 0, 0],
            [0, 0, 1, 0, 0, 0],
            [w1**2, -(w1**2), -2 * z1 * w1, 0.3 * w1**2, 0, 0],
            [0, 0, 0, -a2, 0, 0],
            [0, 0, 0, 0, 0, 1],
            [0.4 * w2**2, 0, 0, w2**2, -(w2**2), -2 * z2 * w2],
        ]
    )
    b = np.zeros((6, 2))
    b[0, 0], b[3, 1] = a1, a2
    c = np.zeros((2, 6))
    c[0, 1] = c[1, 4] = 1.0
    return control.c2d(control.ss(a, b, c, np.zeros((2, 2))), 0.05)


def peer_n4sid() -> None:
    truth = mimo_plant()
    res_f = np.array([m.frequency_hz for m in modes_of_poles(truth.poles(), 0.05) if m.damping < 0.5])
    u = _binary(4000, 1, channels=2)
    y = control.forced_response(truth, U=u.T).outputs.T
    y = y + 0.02 * y.std(axis=0) * np.random.default_rng(2).standard_normal(y.shape)
    uv = _binary(1000, 3, channels=2)
    yv = control.forced_response(truth, U=uv.T).outputs.T

    def row(name: str, sys: control.StateSpace, seconds: float) -> tuple[str, float, float, float]:
        f = np.array([m.frequency_hz for m in modes_of_poles(sys.poles(), 0.05) if m.damping < 0.5])
        err = 100 * np.max(np.abs(f / res_f - 1)) if f.size == res_f.size else float("nan")
        sim = control.forced_response(sys, U=uv.T).outputs.T
        return name, err, min(fit_percent(yv[:, k], sim[:, k]) for k in range(2)), seconds

    rows = []
    t, sys = _timed(lambda: n4sid(y, u, 6, sample_time=0.05), 5)
    rows.append(row("trms n4sid (order 6)", sys, t))
    t, sys_auto = _timed(lambda: n4sid(y, u, sample_time=0.05), 1)
    rows.append(row(f"trms n4sid (order chosen: {sys_auto.nstates})", sys_auto, t))
    si = _peer("sippy_unipi")
    if si is not None:
        t, res = _timed(lambda: si.system_identification(y.T, u.T, "N4SID", SS_fixed_order=6, tsample=0.05), 3)
        rows.append(row("SIPPY N4SID (order 6)", control.ss(res.A, res.B, res.C, res.D, 0.05), t))
    _print_table(
        "Peers on a 6th-order two-resonance MIMO plant (2 inputs at once, 4000 samples)", rows, "max res. f err %"
    )


# ---------------------------------------------------------------- n4sid on slow modes: the default horizon
def slow_modes_plant() -> control.StateSpace:
    """Two lightly damped modes, 0.1 and 0.34 Hz (zeta 0.05), 2 inputs into both, 2 outputs seeing both, Ts 0.1 s."""
    a = np.zeros((4, 4))
    for k, f in enumerate((0.1, 0.34)):
        w = 2 * np.pi * f
        a[2 * k : 2 * k + 2, 2 * k : 2 * k + 2] = [[0, 1], [-(w**2), -0.1 * w]]
    b = np.array([[0, 0], [1.0, 0.5], [0, 0], [0.6, 1.0]]) * np.array(
        [[1], [(0.2 * np.pi) ** 2], [1], [(0.68 * np.pi) ** 2]]
    )
    c = np.array([[1.0, 0, 0.7, 0], [0.4, 0, 1.0, 0]])
    return control.c2d(control.ss(a, b, c, np.zeros((2, 2))), 0.1)


def n4sid_slow_modes(runs: int = 100) -> None:
    """Monte Carlo: the former fixed default horizon (11 samples) against the adaptive default."""
    truth, f_true, z_true = slow_modes_plant(), np.array([0.1, 0.34]), 0.05
    print(f"n4sid on 0.1 and 0.34 Hz modes (zeta 0.05), 2x2, Ts 0.1 s, N 2000, 10 % output noise, {runs} seeds")
    print(f"  {'horizon':26s} {'unstable':>9s} {'f err % (median)':>18s} {'zeta err % (median)':>21s} {'ms/call':>8s}")
    data = []
    for seed in range(1000, 1000 + runs):
        rng = np.random.default_rng(seed)
        u = np.repeat(np.sign(rng.standard_normal((401, 2))), 5, axis=0)[:2000]
        y = control.forced_response(truth, U=u.T).outputs.T
        data.append((y + 0.1 * y.std(axis=0) * rng.standard_normal(y.shape), u))
    for label, horizon in (("fixed 11 (former)", 11), ("default (adaptive)", None)):
        unstable, f_err, z_err, times, used = 0, [], [], [], []
        for y, u in data:
            t, sys = _timed(lambda y=y, u=u, h=horizon: n4sid(y, u, sample_time=0.1, horizon=h), 1)
            times.append(t)
            used.append(sys.horizon)
            poles = sys.poles()
            unstable += int(np.any(np.abs(poles) > 1))
            modes = [m for m in modes_of_poles(poles, 0.1) if 0 < m.frequency_hz and m.damping < 0.5]
            best = [min(modes, key=lambda m, f=f: abs(m.frequency_hz - f)) for f in f_true]
            f_err.append([abs(m.frequency_hz / f - 1) for m, f in zip(best, f_true, strict=True)])
            z_err.append([abs(m.damping / z_true - 1) for m in best])
        fe, ze = 100 * np.median(f_err, axis=0), 100 * np.median(z_err, axis=0)
        name = f"{label}, {min(used)}-{max(used)}" if min(used) != max(used) else f"{label}, {used[0]}"
        print(
            f"  {name:26s} {unstable:5d}/{runs:<3d} {fe[0]:8.3f} {fe[1]:8.3f} {ze[0]:10.2f} {ze[1]:10.2f} "
            f"{1e3 * statistics.median(times):8.1f}"
        )


# ---------------------------------------------------------------- NARX-RBF scaling
def rbf_scaling() -> None:
    print("NARX-RBF training, ny = nu = 8, 30 centres: capped candidates (default) vs every training vector")
    print(f"  {'N':>6s} {'candidates':>12s} {'time s':>9s} {'peak MB':>9s} {'time ratio':>11s} {'memory ratio':>13s}")
    for n in (1000, 4000, 8000):
        u = uniform_noise(n * TS, TS, 2.0, 1.0, seed=1)
        y = scipy.signal.lfilter([0.0, 0.3], [1.0, -0.8], u + 0.5 * u**2)
        out = {}
        for label, cap in (("default", "default"), ("all (old)", None)):
            kwargs = {} if cap == "default" else {"max_candidates": None}
            tracemalloc.start()
            t0 = time.perf_counter()
            narx_rbf(y, u, 8, 8, 1, sample_time=TS, **kwargs)
            seconds = time.perf_counter() - t0
            peak = tracemalloc.get_traced_memory()[1] / 2**20
            tracemalloc.stop()
            out[label] = (seconds, peak)
        (t_new, m_new), (t_old, m_old) = out["default"], out["all (old)"]
        print(f"  {n:6d} {'default':>12s} {t_new:9.3f} {m_new:9.1f}")
        print(f"  {n:6d} {'all (old)':>12s} {t_old:9.3f} {m_old:9.1f} {t_old / t_new:10.1f}x {m_old / m_new:12.1f}x")


def multistart_cost() -> None:
    """OE and BJ from one start against the default multistart: time per fit and the loss reached."""
    print(f"OE/BJ multistart ({STARTS} starts at most) against one start, median of 20 fits")
    for kind, n in (("oe", 400), ("bj", 400), ("oe", 1000), ("bj", 1000)):
        y, u = siso_case("bj", n, 1)  # coloured disturbance: the plant's order, OE still unbiased

        def fit(starts: int, y: np.ndarray = y, u: np.ndarray = u, kind: str = kind) -> Any:
            if kind == "oe":
                return oe(y, u, 2, 2, 1, sample_time=TS_BJ, starts=starts)
            return bj(y, u, 2, 1, 1, 2, 1, sample_time=TS_BJ, starts=starts)

        t_one, one = _timed(lambda: fit(1), 20)
        t_multi, multi = _timed(lambda: fit(STARTS), 20)
        print(
            f"  {kind} N={n:5d}  one start {1e3 * t_one:7.2f} ms  default {1e3 * t_multi:7.2f} ms  "
            f"ratio {t_multi / t_one:4.2f}x  starts searched {multi.info['starts']}  "
            f"loss ratio {multi.loss / one.loss:.6f}"
        )


NP_A, NP_B = np.array([1.0, -1.2, 0.49]), np.array([0.0, 0.5, 0.3])


def _np_truth(f: np.ndarray, ts: float) -> np.ndarray:
    zinv = np.exp(-2j * np.pi * np.asarray(f) * ts)
    return np.polyval(NP_B[::-1], zinv) / np.polyval(NP_A[::-1], zinv)


def nonparametric_peers(runs: int = 50, n: int = 4000, ts: float = 0.1) -> None:
    """spa and etfe against the Welch ratio, impulseest, and the recursive estimators' cost."""
    peak = float(np.max(np.abs(_np_truth(np.linspace(0.0, 0.5 / ts, 2001), ts))))
    impulse = scipy.signal.lfilter(NP_B, NP_A, np.r_[1.0, np.zeros(49)])

    def welch_ratio(y: np.ndarray, u: np.ndarray, seg: int) -> tuple[np.ndarray, np.ndarray]:
        kw = dict(fs=1.0 / ts, window="hann", nperseg=seg, noverlap=seg // 2)
        f, pxy = scipy.signal.csd(u, y, **kw)
        return f[1:], pxy[1:] / scipy.signal.welch(u, **kw)[1][1:]

    methods: dict[str, Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]] = {
        "trms spa (M = 30, default)": lambda y, u: (lambda r: (r.frequency, r.response))(spa(y, u, sample_time=ts)),
        "trms spa (M = 100)": lambda y, u: (lambda r: (r.frequency, r.response))(spa(y, u, 100, sample_time=ts)),
        "trms etfe (31 lines)": lambda y, u: (lambda r: (r.frequency[1:], r.response[1:]))(
            etfe(y, u, 31, sample_time=ts)
        ),
        "scipy csd / welch (64)": lambda y, u: welch_ratio(y, u, 64),
        "scipy csd / welch (256)": lambda y, u: welch_ratio(y, u, 256),
    }
    errors: dict[str, list[float]] = {k: [] for k in methods}
    times: dict[str, list[float]] = {k: [] for k in methods}
    fir: dict[str, list[float]] = {"tc": [], "none": []}
    fir_time: dict[str, list[float]] = {"tc": [], "none": []}
    for seed in range(runs):
        u = np.random.default_rng(seed).standard_normal(n)
        y = scipy.signal.lfilter(NP_B, NP_A, u) + 0.1 * np.random.default_rng([seed, 1]).standard_normal(n)
        for name, fn in methods.items():
            t0 = time.perf_counter()
            f, g = fn(y, u)
            times[name].append(time.perf_counter() - t0)
            errors[name].append(float(np.max(np.abs(g - _np_truth(f, ts)))) / peak)
        if seed < 10:
            for kernel in fir:
                t0 = time.perf_counter()
                est = impulseest(y, u, 50, sample_time=ts, kernel=kernel)
                fir_time[kernel].append(time.perf_counter() - t0)
                fir[kernel].append(float(np.max(np.abs(est.coefficients - impulse))) / impulse.max())
    print(f"Non-parametric frequency response, 2nd-order system, N {n}, noise 0.1, {runs} seeds")
    print(f"  {'method':30s} {'max err % of peak (median)':>27s} {'ms/call':>9s} {'time / spa':>11s}")
    t_spa = statistics.median(times["trms spa (M = 30, default)"])
    for name in methods:
        t = statistics.median(times[name])
        print(f"  {name:30s} {100 * statistics.median(errors[name]):27.2f} {1e3 * t:9.2f} {t / t_spa:11.2f}")
    for kernel, label in (("tc", "TC kernel"), ("none", "least squares")):
        print(
            f"  impulseest {label:19s} {100 * statistics.median(fir[kernel]):27.2f} "
            f"{1e3 * statistics.median(fir_time[kernel]):9.2f}   (FIR error % of peak, 10 seeds)"
        )
    u = np.random.default_rng(0).standard_normal(10000)
    y = scipy.signal.lfilter(NP_B, NP_A, u) + scipy.signal.lfilter(
        [1.0, -0.7, 0.2], NP_A, 0.1 * np.random.default_rng(1).standard_normal(10000)
    )
    t_arx, _ = median_time(lambda: recursive_arx(y, u, 2, 2, 1, sample_time=ts), 3)
    t_armax, _ = median_time(lambda: recursive_armax(y, u, 2, 2, 2, 1, sample_time=ts), 3)

    def online() -> None:
        est = RecursiveEstimator(2, 2, 2, 1, sample_time=ts)
        for yt, ut in zip(y, u):
            est.update(yt, ut)

    t_online, _ = median_time(online, 3)
    print(
        f"  recursive ARX(2,2) {1e6 * t_arx / y.size:.1f} us/sample, ARMAX(2,2,2) {1e6 * t_armax / y.size:.1f} "
        f"us/sample, online update() ARMAX {1e6 * t_online / y.size:.1f} us/sample (10000 samples)"
    )


def _polynomial_truth(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """y(t) = 0.5 y(t-1) + 0.3 u(t-1) + 0.2 y(t-1) u(t-1) - 0.1 u(t-2)^2 + 0.01 e(t), u uniform in [-1, 1]."""
    rng = np.random.default_rng(seed)
    u, e = rng.uniform(-1, 1, n), 0.01 * rng.standard_normal(n)
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = 0.5 * y[t - 1] + 0.3 * u[t - 1] + 0.2 * y[t - 1] * u[t - 1] - 0.1 * u[t - 2] ** 2 + e[t]
    return y, u


def peer_frols(runs: int = 20) -> None:
    """Polynomial NARX: trms FROLS against sysidentpy's FROLS and the thesis's NARX-RBF, on a polynomial truth.

    sysidentpy runs twice: with the term count trms chose (``order_selection=False, n_terms=...``: the same
    algorithm and stopping point, the like-for-like time) and with its default AIC order selection (which fits
    ``n_info_values = 15`` candidate models and keeps the best: more work, a different stopping rule). Times are
    single fits (after one warm-up), medians over the seeds, and the ratio is the median of the per-seed ratios.
    """
    from trms.identification import narx_poly

    mss = _peer("sysidentpy.model_structure_selection")
    trms_name, fixed, aic = "trms narx_poly (FROLS)", "sysidentpy FROLS, same terms", "sysidentpy FROLS, AIC"
    fits: dict[str, list[float]] = {trms_name: [], "trms narx_rbf (ny = nu = 8)": []}
    times: dict[str, list[float]] = {k: [] for k in fits}
    terms: dict[str, list[int]] = {trms_name: []}
    right = 0
    if mss is not None:
        for name in (fixed, aic):
            fits[name], times[name], terms[name] = [], [], []
    for seed in range(runs):
        y, u = _polynomial_truth(1200, seed)
        yv, uv = _polynomial_truth(800, 1000 + seed)
        t, poly = _timed(lambda y=y, u=u: narx_poly(y, u, 2, 2, 1, degree=2, sample_time=TS), 1)
        right += sorted(poly.term_names()[:4]) == ["u(t-1)", "u(t-2) u(t-2)", "y(t-1)", "y(t-1) u(t-1)"]
        fits[trms_name].append(fit_percent(yv, poly.simulate(uv, yv)))
        times[trms_name].append(t)
        terms[trms_name].append(poly.n_terms)
        t, rbf = _timed(lambda y=y, u=u: narx_rbf(y, u, 8, 8, 1, sample_time=TS), 1)
        fits["trms narx_rbf (ny = nu = 8)"].append(fit_percent(yv, rbf.simulate(uv, yv)))
        times["trms narx_rbf (ny = nu = 8)"].append(t)
        if mss is None:
            continue
        from sysidentpy.basis_function import Polynomial
        from sysidentpy.parameter_estimation import LeastSquares

        for name, options in ((fixed, {"order_selection": False, "n_terms": poly.n_terms}), (aic, {})):

            def fit(y: np.ndarray = y, u: np.ndarray = u, options: dict = options) -> Any:
                model = mss.FROLS(
                    ylag=2,
                    xlag=2,
                    info_criteria="aic",
                    estimator=LeastSquares(),
                    basis_function=Polynomial(degree=2),
                    **({"order_selection": True} | options),
                )
                model.fit(X=u[:, None], y=y[:, None])
                return model

            t, model = _timed(fit, 1)
            sim = model.predict(X=uv[:, None], y=yv[:, None][:2]).ravel()[: yv.size]
            fits[name].append(fit_percent(yv, sim))
            times[name].append(t)
            terms[name].append(len(model.final_model))
    print(f"Polynomial NARX truth (4 terms, degree 2), 1200 training and 800 unseen samples, {runs} seeds")
    base = np.array(times[trms_name])
    for name in fits:
        f, n_terms = np.array(fits[name]), terms.get(name)
        counted = f"terms {int(np.median(n_terms)):2d}" if n_terms else " " * 8
        print(
            f"  {name:28s} free-run fit median {np.median(f):6.2f} % (min {f.min():6.2f})  {counted}  "
            f"time {1e3 * np.median(times[name]):8.2f} ms  its time / trms's {np.median(times[name] / base):6.1f}x"
        )
    print(f"  trms narx_poly's first four terms are the true ones in {right}/{runs} runs")
    if mss is not None:
        _frols_scaling(mss)


def _frols_scaling(mss: Any, sizes: tuple[int, ...] = (1200, 12_000, 60_000), runs: int = 5) -> None:
    """The like-for-like time ratio (sysidentpy's FROLS with trms's term count) as the record grows."""
    from sysidentpy.basis_function import Polynomial
    from sysidentpy.parameter_estimation import LeastSquares

    from trms.identification import narx_poly

    print("  same terms, by record length (medians of per-seed ratios, 5 seeds):")
    for n in sizes:
        ratios, own = [], []
        for seed in range(runs):
            y, u = _polynomial_truth(n, seed)
            t_trms, poly = _timed(lambda y=y, u=u: narx_poly(y, u, 2, 2, 1, degree=2, sample_time=TS), 1)

            def fit(y: np.ndarray = y, u: np.ndarray = u, k: int = poly.n_terms) -> Any:
                model = mss.FROLS(
                    ylag=2, xlag=2, order_selection=False, n_terms=k, estimator=LeastSquares(),
                    basis_function=Polynomial(degree=2),
                )  # fmt: skip
                return model.fit(X=u[:, None], y=y[:, None])

            t_peer, _ = _timed(fit, 1)
            ratios.append(t_peer / t_trms)
            own.append(t_trms)
        print(
            f"    N {n:6d}: trms {1e3 * np.median(own):8.1f} ms, sysidentpy's time / trms's {np.median(ratios):5.2f}x"
        )


def main() -> None:
    y, u = armax_data(600)
    t_fast, model = median_time(lambda: armax(y, u, NA, NB, NC, NK, sample_time=TS), 30)
    d = siso_data(y, u, sample_time=TS)
    theta0 = _initial_armax(d, NA, NB, NC, NK, max(NA, NK + NB - 1))
    t_loop, loss_loop = median_time(lambda: loop_pem(y, u, theta0), 3)
    t_scipy, loss_scipy = median_time(lambda: scipy_pem(y, u, theta0), 5)
    print("ARMAX(4,4,4,1) by PEM on 600 samples (goal < 50 ms)")
    print(
        f"  trms armax             {1e3 * t_fast:8.2f} ms  loss {model.loss:.6e}  "
        f"({model.info['iterations']} iterations)"
    )
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
    print(
        f"  textbook OLS           {1e3 * t_text:8.2f} ms  ratio {t_text / t_ols:6.1f}x  "
        f"same centres: {chosen == sel.selected.tolist()}"
    )
    print()
    peer_armax()
    print()
    peer_bj_oe()
    print()
    multistart_cost()
    print()
    peer_n4sid()
    print()
    n4sid_slow_modes()
    print()
    rbf_scaling()
    print()
    nonparametric_peers()
    print()
    peer_frols()


if __name__ == "__main__":
    main()


# ---------------------------------------------------------------- NARX-RBF training memory (streamed OLS)
_RBF_CHILD = """
import resource, statistics, sys, time, tracemalloc
import numpy as np, scipy.signal
from trms.identification.rbf import narx_rbf
from trms.signals import uniform_noise
n, repeat = int(sys.argv[1]), int(sys.argv[2])
u = uniform_noise(n * 0.2, 0.2, 2.0, 1.0, seed=1)
y = scipy.signal.lfilter([0.0, 0.3], [1.0, -0.8], u + 0.5 * u**2)
fit = lambda: narx_rbf(y, u, 8, 8, 1, sample_time=0.2, max_centres=13, tolerance=1e-4)
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
times = []
for _ in range(repeat):
    t0 = time.perf_counter()
    model = fit()
    times.append(time.perf_counter() - t0)
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
tracemalloc.start()
fit()
peak = tracemalloc.get_traced_memory()[1]
tracemalloc.stop()
print(statistics.median(times), peak / 2**20, (rss - base) / 2**10, model.n_centres, model.width)
"""


def rbf_training_memory() -> None:
    """Time and peak memory of ``narx_rbf`` in the ch. 5 configuration (ny = nu = 8, 13 centres, tolerance 1e-4,
    default candidate cap), each size in a fresh process: traced peak of the fit and growth of the peak RSS."""
    import subprocess
    import sys

    print("NARX-RBF training, ny = nu = 8, 13 centres, tolerance 1e-4, default candidates (fresh process per N)")
    print(
        f"  {'N':>6s} {'time s':>9s} {'traced peak MB':>15s} {'peak RSS growth MB':>19s} {'centres':>8s} {'width':>9s}"
    )
    for n, repeat in ((300, 21), (600, 21), (3000, 3), (10_000, 1), (30_000, 1)):
        out = subprocess.run(
            [sys.executable, "-c", _RBF_CHILD, str(n), str(repeat)], capture_output=True, text=True, check=True
        ).stdout.split()
        t, peak, rss, m, width = float(out[0]), float(out[1]), float(out[2]), int(out[3]), float(out[4])
        print(f"  {n:6d} {t:9.4f} {peak:15.1f} {rss:19.1f} {m:8d} {width:9.5f}")


if __name__ == "__main__":
    rbf_training_memory()


# ---------------------------------------------------------------- MIMO ARX / ARMAX against SIPPY
def _mimo_truth(u: np.ndarray, e: np.ndarray | None) -> np.ndarray:
    """The 2x2 ARMAX truth of tests/identification/test_mimo_pem.py (each output: both inputs, own A and C)."""
    a1, a2, lf = [1, -1.2, 0.5], [1, -0.6, 0.2], scipy.signal.lfilter
    y1 = lf([0, 1.0, 0.5], a1, u[:, 0]) + lf([0, 0.3], a1, u[:, 1])
    y2 = lf([0, 0.4], a2, u[:, 0]) + lf([0, 0.8, -0.2], a2, u[:, 1])
    if e is not None:
        y1, y2 = y1 + lf([1, 0.5], a1, e[:, 0]), y2 + lf([1, -0.4], a2, e[:, 1])
    return np.column_stack([y1, y2])


def _tf_matrix_response(g: control.TransferFunction, u: np.ndarray) -> np.ndarray:
    """Free run of a discrete MIMO TransferFunction, entry by entry (lfilter; no MIMO realisation needed)."""
    out = np.zeros((u.shape[0], g.noutputs))
    for j in range(g.noutputs):
        for i in range(g.ninputs):
            num, den = np.atleast_1d(g.num[j][i]), np.atleast_1d(g.den[j][i])
            out[:, j] += scipy.signal.lfilter(np.r_[np.zeros(den.size - num.size), num], den, u[:, i])
    return out


def peer_mimo_pem(runs: int = 5) -> None:
    """trms arx_mimo / armax_mimo against SIPPY's MIMO ARX (LLS) and ARMAX (ILLS, OPT) on the 2x2 ARMAX truth:
    N = 2000, white innovations 0.1, ``runs`` seeds; free-run fit on fresh noise-free data and the largest DC-gain
    error, medians over the seeds; median time per fit."""
    na, nb = np.diag([2, 2]), np.array([[2, 1], [1, 2]])
    uv = np.repeat(np.sign(np.random.default_rng(999).standard_normal((501, 2))), 2, axis=0)[:1000]
    yv = _mimo_truth(uv, None)
    dc_true = _dc_gains(lambda x: _mimo_truth(x, None))
    si = _peer("sippy_unipi")
    rows: dict[str, list[tuple[float, float, float]]] = {}
    arx_orders = [[2, 2], nb.tolist(), [[0, 0], [0, 0]]]  # SIPPY's delay 0 is nk = 1

    def add(name: str, sim: Callable[[np.ndarray], np.ndarray], seconds: float) -> None:
        fit = float(np.mean([fit_percent(yv[:, j], sim(uv)[:, j]) for j in range(2)]))
        dc = _dc_gains(sim)
        rows.setdefault(name, []).append((fit, 100 * float(np.max(np.abs(dc / dc_true - 1))), seconds))

    for seed in range(runs):
        rng = np.random.default_rng(seed)
        u = np.repeat(np.sign(rng.standard_normal((1001, 2))), 2, axis=0)[:2000]
        y = _mimo_truth(u, 0.1 * rng.standard_normal((2000, 2)))
        t, m = _timed(lambda y=y, u=u: arx_mimo(y, u, na, nb, 1, sample_time=TS_BJ), 5)
        add("trms arx_mimo", m.simulate, t)
        t, m = _timed(lambda y=y, u=u: armax_mimo(y, u, na, nb, 1, 1, sample_time=TS_BJ), 5)
        add("trms armax_mimo (nc = 1)", m.simulate, t)
        if si is None:
            continue
        t, res = _timed(lambda y=y, u=u: si.system_identification(y, u, "ARX", ARX_orders=arx_orders, tsample=TS_BJ), 1)
        add("SIPPY ARX (LLS)", lambda x, g=res.G: _tf_matrix_response(g, x), t)
        for mod in ("ILLS", "OPT"):
            t, res = _timed(
                lambda y=y, u=u, mod=mod: si.system_identification(
                    y, u, "ARMAX", ARMAX_orders=[[2, 2], nb.tolist(), [1, 1], [[0, 0], [0, 0]]], ARMAX_mod=mod,
                    tsample=TS_BJ,
                ),
                1,
            )  # fmt: skip
            add(f"SIPPY ARMAX ({mod})", lambda x, g=res.G: _tf_matrix_response(g, x), t)
    print(f"MIMO polynomial models on the 2x2 ARMAX truth (N 2000, innovations 0.1, {runs} seeds, medians)")
    print(f"  {'method':28s} {'val. fit %':>11s} {'max DC err %':>13s} {'time ms':>9s} {'time / trms armax':>18s}")
    base = statistics.median(r[2] for r in rows["trms armax_mimo (nc = 1)"])
    for name, vals in rows.items():
        fit, dc, sec = (statistics.median(v[k] for v in vals) for k in range(3))
        print(f"  {name:28s} {fit:11.2f} {dc:13.3f} {1e3 * sec:9.2f} {sec / base:17.1f}x")


def _dc_gains(sim: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """DC-gain matrix (outputs x inputs): the end of a 400-sample unit step on each input in turn."""
    return np.column_stack([sim(np.tile(np.eye(2)[i], (400, 1)))[-1] for i in range(2)])


if __name__ == "__main__":
    peer_mimo_pem()
