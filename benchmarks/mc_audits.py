"""The audits of :mod:`bench_identification_mc`: estimators and solvers that must never return a wrong answer quietly.

Each audit is a seeded Monte Carlo on known truth and prints one table; every one runs on the current API and on an
older checkout of ``trms`` (``PYTHONPATH`` pointing at it) wherever the older API allows, so that the same command
measures before and after.

Known truths (never fitted to tune anything: the tests use other seeds):

* SISO, Ts 0.2 s (zero-order hold): one mode (0.34 Hz, zeta 0.05), or two (0.10 Hz, zeta 0.03, plus half of the
  0.34 Hz one), unit DC gain each; input +-1 random binary held 2 samples; AR(1) output noise (pole 0.9) scaled to
  a signal-to-noise power ratio (SNR) of 10 or 3; N 300 or 2000.
* 2x2, Ts 0.1 s: modes at 0.1 Hz (zeta 0.02 or 0.05) and 0.34 Hz (zeta 0.05), both inputs into both, both
  outputs seeing both (the system of ``bench_identification.py``), inputs +-1 held 5 samples, N 2000, AR(1)
  output noise (pole 0.9) per output at SNR 10.
"""

from __future__ import annotations

import statistics
import time
import warnings
from collections.abc import Callable
from typing import Any

import control
import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.signal
import scipy.sparse as sp
import scipy.stats

from trms.errors import EstimationError, SimulationError
from trms.identification import LocalMinimumWarning, bj, n4sid, oe, ssest
from trms.identification.data import SisoData
from trms.identification.pem import Structure, covariance, fit
from trms.identification.polynomial import modes_of_poles

TS_SISO, AR_POLE = 0.2, 0.9


# ------------------------------------------------------------------------------------------------ known truths
def siso_truth(two_modes: bool) -> tuple[np.ndarray, np.ndarray]:
    """``B, F`` (ascending powers of ``q^-1``, ``B[0] = 0``: one sample of delay) of the one- or two-mode plant."""
    modes = ((0.10, 0.03, 1.0), (0.34, 0.05, 0.5)) if two_modes else ((0.34, 0.05, 1.0),)
    g = sum(k * control.tf([(2 * np.pi * f) ** 2], [1, 4 * np.pi * z * f, (2 * np.pi * f) ** 2]) for f, z, k in modes)
    gd = control.c2d(g, TS_SISO, "zoh")
    num, den = np.ravel(gd.num[0][0]), np.ravel(gd.den[0][0])
    return np.r_[np.zeros(den.size - num.size), num] / den[0], den / den[0]


def siso_record(b: np.ndarray, f: np.ndarray, n: int, snr: float, seed: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Output and input of one realisation: the plant's response plus AR(1) noise at the given SNR."""
    rng = np.random.default_rng(seed)
    u = np.repeat(np.sign(rng.standard_normal(n // 2 + 1)), 2)[:n]
    clean = scipy.signal.lfilter(b, f, u)
    v = scipy.signal.lfilter([1.0], [1.0, -AR_POLE], rng.standard_normal(n + 1000))[1000:]
    return clean + v / v.std() * clean.std() / np.sqrt(snr), u


def mimo_truth(zeta_slow: float) -> control.StateSpace:
    """The 2x2 system with modes at 0.1 Hz (damping ``zeta_slow``) and 0.34 Hz (0.05), Ts 0.1 s."""
    a = np.zeros((4, 4))
    for k, (f, z) in enumerate(((0.1, zeta_slow), (0.34, 0.05))):
        w = 2 * np.pi * f
        a[2 * k : 2 * k + 2, 2 * k : 2 * k + 2] = [[0, 1], [-(w**2), -2 * z * w]]
    b = np.array([[0, 0], [1.0, 0.5], [0, 0], [0.6, 1.0]]) * np.array(
        [[1], [(0.2 * np.pi) ** 2], [1], [(0.68 * np.pi) ** 2]]
    )
    c = np.array([[1.0, 0, 0.7, 0], [0.4, 0, 1.0, 0]])
    return control.c2d(control.ss(a, b, c, np.zeros((2, 2))), 0.1)


def mimo_record(
    truth: control.StateSpace, seed: int, n: int = 2000, snr: float = 10.0
) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = np.repeat(np.sign(rng.standard_normal((n // 5 + 1, 2))), 5, axis=0)[:n]
    y = control.forced_response(truth, U=u.T).outputs.T
    v = scipy.signal.lfilter([1.0], [1.0, -AR_POLE], rng.standard_normal((n + 500, 2)), axis=0)[500:]
    return y + v / v.std(axis=0) * y.std(axis=0) / np.sqrt(snr), u


def _quiet(fn: Callable[..., Any], *args: Any, **kwargs: Any) -> tuple[Any, list[warnings.WarningMessage]]:
    """``fn(*args, **kwargs)`` and the warnings it gave."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = fn(*args, **kwargs)
    return out, caught


# ------------------------------------------------------------------------------------------- 1: BJ local minima
def audit_bj(runs: dict[int, int]) -> None:
    """BJ(nb = nf = plant order, nc = nd = 1): fits ending above the search from the truth, and how many silently."""
    print("1. BJ local minima: kept loss above 1.001 x that of the search started at the truth (the oracle); AR(1)")
    print("   noise; 'boundary' = the oracle's best point is on the stability boundary, which bj refuses")
    print(
        f"   {'truth':9s} {'N':>5s} {'SNR':>4s} {'fits':>5s} {'trapped':>8s} {'silent':>7s} {'worst %':>8s} "
        f"{'refused':>8s} {'interior above boundary':>24s} {'warned fits':>12s} {'ms/fit':>7s}"
    )
    for two in (False, True):
        b, f = siso_truth(two)
        nf, nb = f.size - 1, f.size - 1
        structure = Structure(0, nb, 1, 1, nf, 1)
        truth = np.r_[b[1:], 0.0, -AR_POLE, f[1:]]
        for n, count in runs.items():
            for snr in (10.0, 3.0):
                trapped = silent = refused = above_boundary = warned = fits = 0
                worst, seconds = 0.0, []
                for r in range(count):
                    y, u = siso_record(b, f, n, snr, [60_000, two, int(snr), n, r])
                    tic = time.perf_counter()
                    try:
                        model, caught = _quiet(bj, y, u, nb, 1, 1, nf, 1, sample_time=TS_SISO)
                    except EstimationError:
                        refused += 1
                        continue
                    seconds.append(time.perf_counter() - tic)
                    fits += 1
                    flagged = any(issubclass(w.category, LocalMinimumWarning) for w in caught)
                    warned += flagged
                    try:
                        oracle = fit(
                            SisoData(y, u, TS_SISO),
                            structure,
                            truth,
                            name="oracle",
                            method="bj",
                            max_iter=500,
                            tol=1e-9,
                        )
                    except EstimationError:
                        continue
                    if model.loss > (1 + 1e-3) * oracle.loss:
                        if oracle.info["on_stability_boundary"]:
                            above_boundary += 1
                        else:
                            trapped += 1
                            silent += not flagged
                            worst = max(worst, 100 * (model.loss / oracle.loss - 1))
                ms = 1e3 * statistics.median(seconds) if seconds else float("nan")
                print(
                    f"   {'two modes' if two else 'one mode':9s} {n:5d} {snr:4.0f} {fits:5d} {trapped:8d} {silent:7d} "
                    f"{worst:8.1f} {refused:8d} {above_boundary:24d} {warned:12d} {ms:7.0f}"
                )


# ------------------------------------------------------------------------------- 2: MPC against an independent QP
def _reference_plan(mpc: Any, x0: np.ndarray, d: np.ndarray, r: np.ndarray, up: np.ndarray) -> tuple[Any, ...]:
    """The MPC problem written afresh (predictions simulated input by input) and solved by a fresh OSQP at tight
    tolerances: the QP ``(H, q, A, l, u)`` in OSQP's half-cost form, OSQP's result and the softness used."""
    import osqp  # type: ignore[import-untyped]

    A, B, C = (np.asarray(v, float) for v in (mpc.model.A, mpc.model.B, mpc.model.C))
    n, m, p, N = A.shape[0], B.shape[1], C.shape[0], mpc.horizon
    xs, us = mpc.target(r, d)
    (lo, hi), rate, (ylo, yhi) = mpc.input_limits, mpc.rate_limit, mpc.output_limits

    def states(inputs: np.ndarray, start: np.ndarray, dist: np.ndarray) -> np.ndarray:
        x, out = start, []
        for uk in inputs.reshape(N, m):
            x = A @ x + B @ (uk + dist)
            out.append(x)
        return np.concatenate(out)

    free = states(np.zeros(N * m), x0, d)
    G = np.column_stack([states(e, np.zeros(n), np.zeros(m)) for e in np.eye(N * m)])
    Qb, Rb = scipy.linalg.block_diag(*([mpc.Q] * (N - 1) + [mpc.P])), np.kron(np.eye(N), mpc.R)
    rho1, rho2 = 1e4, 1e5  # the controller's default softness
    ns = N * p if mpc.soft else 0
    H = scipy.linalg.block_diag(G.T @ Qb @ G + Rb, rho2 * np.eye(ns))
    q = np.r_[G.T @ Qb @ (free - np.tile(xs, N)) - Rb @ np.tile(us, N), np.full(ns, 0.5 * rho1)]
    Cb = np.kron(np.eye(N), C)
    y_free, y_in = Cb @ free, Cb @ G
    slack = np.eye(ns) if ns else np.zeros((N * p, 0))
    rows = [
        (np.hstack([np.eye(N * m), np.zeros((N * m, ns))]), np.tile(lo, N), np.tile(hi, N)),
        (
            np.hstack([np.eye(N * m) - np.eye(N * m, k=-m), np.zeros((N * m, ns))]),
            np.r_[up - rate, np.tile(-rate, N - 1)],
            np.r_[up + rate, np.tile(rate, N - 1)],
        ),
        (np.hstack([y_in, -slack]), np.full(N * p, -np.inf), np.tile(yhi, N) - y_free),
        (np.hstack([y_in, slack]), np.tile(ylo, N) - y_free, np.full(N * p, np.inf)),
        (np.hstack([np.zeros((ns, N * m)), np.eye(ns)]), np.zeros(ns), np.full(ns, np.inf)),
    ]
    Acon = np.vstack([row[0] for row in rows])
    lower, upper = np.concatenate([row[1] for row in rows]), np.concatenate([row[2] for row in rows])
    solver = osqp.OSQP()
    solver.setup(
        sp.csc_matrix(np.triu(H)),
        q,
        sp.csc_matrix(Acon),
        lower,
        upper,
        verbose=False,
        eps_abs=1e-11,
        eps_rel=1e-11,
        max_iter=200_000,
        polish_refine_iter=20,
    )
    return H, q, y_in, y_free, solver.solve(raise_error=False)


def audit_mpc(cases: int) -> None:
    """Random cases on the 1-DOF and 2-DOF design models: soft limits met, soft limits missed, hard limits met."""
    from trms.control.mpc import MPCController
    from trms.worlds import design_model

    models = {c: design_model(c, 0.1) for c in ("1dof", "2dof")}
    print(
        f"2. MPC plan() against an independent QP (the problem re-condensed by simulation, fresh OSQP at 1e-11),"
        f" {cases} cases per row"
    )
    print(
        f"   {'model':5s} {'case':20s} {'|du0| max':>10s} {'within 1e-5':>12s} {'input viol V':>13s} "
        f"{'rate viol %':>12s} {'cost excess %':>14s} {'flagged':>8s} {'ms/plan':>8s}"
    )
    for config, model in models.items():
        n, m, p = model.nstates, model.ninputs, model.noutputs
        for case in ("soft, limits met", "soft, limits missed", "hard, limits met"):
            du, u_viol, r_viol, excess, flagged, ok, seconds = [], [], [], [], 0, 0, []
            for k in range(cases):
                rng = np.random.default_rng([3700, k, len(case), m])
                ulim, rate, ylim = rng.uniform(0.5, 3.0, m), rng.uniform(0.05, 0.4), rng.uniform(0.1, 0.3, p)
                r, d = rng.uniform(-0.5, 0.5, p) * ylim, 0.05 * rng.standard_normal(m)
                x0, up = np.zeros(n), np.zeros(m)
                for _ in range(15):  # a state the loop reaches, and the last move held before
                    up = np.clip(up + rng.uniform(-rate, rate, m), -ulim, ulim)
                    x0 = model.A @ x0 + model.B @ (up + d)
                horizon = int(rng.integers(10, 26))
                x, held = x0, []
                for _ in range(horizon):
                    x = model.A @ x + model.B @ (up + d)
                    held.append(model.C @ x)
                ylim = np.maximum(ylim, 1.2 * np.abs(np.array(held)).max(axis=0))  # holding u_{-1} meets them
                if case == "soft, limits missed":
                    x0 = (
                        x0
                        + np.linalg.lstsq(np.asarray(model.C), 2.0 * ylim * rng.choice([-1.0, 1.0], p), rcond=None)[0]
                    )
                mpc = MPCController(
                    model,
                    horizon=horizon,
                    input_limits=(-ulim, ulim),
                    rate_limit=rate,
                    output_limits=(-ylim, ylim),
                    soft=not case.startswith("hard"),
                )
                tic = time.perf_counter()
                try:
                    plan, caught = _quiet(mpc.plan, x0, d, r, previous_input=up)
                except SimulationError:
                    continue
                seconds.append(time.perf_counter() - tic)
                H, q, y_in, y_free, ref = _reference_plan(mpc, x0, d, r, up)
                if ref.info.status != "solved":
                    continue
                ok += 1
                flagged += (getattr(mpc, "info", {}).get("converged") is False) or any(
                    w.category.__name__ == "UnconvergedPlanWarning" for w in caught
                )
                du.append(float(np.max(np.abs(plan[0] - ref.x[:m]))))
                u_viol.append(float(np.max(np.r_[0.0, np.abs(plan).ravel() - np.tile(ulim, horizon)])))
                moves = np.abs(np.diff(np.vstack([up, plan]), axis=0))
                r_viol.append(100 * float(np.max(np.r_[0.0, (moves - rate).ravel()])) / rate)
                yp = y_free + y_in @ plan.ravel()
                s = (
                    np.maximum(0.0, np.maximum(yp - np.tile(ylim, horizon), -np.tile(ylim, horizon) - yp))
                    if mpc.soft
                    else np.zeros(0)
                )
                z = np.r_[plan.ravel(), s]
                cost, best = 0.5 * z @ H @ z + q @ z, 0.5 * ref.x @ H @ ref.x + q @ ref.x
                excess.append(100 * (cost - best) / abs(best))
            du_arr = np.array(du)
            print(
                f"   {config:5s} {case:20s} {du_arr.max():10.2e} {int(np.sum(du_arr <= 1e-5)):5d}/{ok:<6d} "
                f"{max(u_viol):13.2e} {max(r_viol):12.2f} {max(excess):14.3f} {flagged:8d} "
                f"{1e3 * statistics.median(seconds):8.2f}"
            )


# ------------------------------------------------------------------------------------ 3: n4sid's slow-mode damping
def _damping_errors(poles: np.ndarray, zeta_slow: float) -> list[float]:
    modes = [md for md in modes_of_poles(poles, 0.1) if 0 < md.frequency_hz and md.damping < 0.5]
    out = []
    for f0, z0 in ((0.1, zeta_slow), (0.34, 0.05)):
        near = min(modes, key=lambda md, f0=f0: abs(md.frequency_hz - f0)) if modes else None
        out.append(abs(near.damping / z0 - 1) if near is not None else np.inf)
    return out


def audit_n4sid(runs: int) -> None:
    """Median damping error of each mode, order 4 given, for each estimator on the same records."""
    estimators: dict[str, Callable[[np.ndarray, np.ndarray], Any]] = {
        "n4sid MOESP, no refinement": lambda y, u: n4sid(y, u, 4, sample_time=0.1, refine="none"),
        "n4sid CVA, no refinement": lambda y, u: n4sid(y, u, 4, sample_time=0.1, refine="none", weighting="cva"),
        "ssest order 6 (noise states)": lambda y, u: ssest(y, u, 6, sample_time=0.1),
        "n4sid default": lambda y, u: n4sid(y, u, 4, sample_time=0.1),
    }
    print(
        f"3. n4sid on the 2x2 system, AR(1) output noise at SNR 10, N 2000, order 4, {runs} seeds: median (90th "
        "percentile) damping error %"
    )
    print(
        f"   {'estimator':30s} {'zeta(0.1 Hz)':>12s} {'0.1 Hz':>16s} {'0.34 Hz':>14s} {'unstable':>9s} {'ms/call':>8s}"
    )
    for zeta in (0.02, 0.05):
        truth = mimo_truth(zeta)
        records = [mimo_record(truth, 5000 + r) for r in range(runs)]
        for name, estimate in estimators.items():
            errors, unstable, seconds = [], 0, []
            for y, u in records:
                tic = time.perf_counter()
                try:
                    model, _ = _quiet(estimate, y, u)
                except TypeError:  # an older trms without this option
                    break
                seconds.append(time.perf_counter() - tic)
                unstable += int(np.any(np.abs(model.poles()) > 1))
                errors.append(_damping_errors(model.poles(), zeta))
            if not errors:
                print(f"   {name:30s} {zeta:12.2f}   (not in this version)")
                continue
            e = 100 * np.array(errors)
            med, p90 = np.median(e, axis=0), np.percentile(e, 90, axis=0)
            print(
                f"   {name:30s} {zeta:12.2f} {med[0]:7.1f} ({p90[0]:6.1f}) {med[1]:6.1f} ({p90[1]:5.1f}) "
                f"{unstable:5d}/{len(e):<3d} {1e3 * statistics.median(seconds):8.0f}"
            )


# ------------------------------------------------------------------------------- 4: OE intervals under coloured noise
def audit_oe(runs: dict[int, int]) -> None:
    """Coverage of the truth by each parameter's 95 % interval: the white-noise covariance and the one oe returns."""
    print("4. OE 95 % intervals under AR(1) output noise: per-parameter coverage (min over parameters, mean), joint,")
    print(
        "   for the white-noise covariance lambda (psi'psi)^-1 and for the covariance oe returns (where it gives one;"
    )
    print("   'withheld min': the lowest coverage its covariance would have given on the fits it withheld)")
    print(
        f"   {'truth':9s} {'N':>5s} {'SNR':>4s} {'fits':>5s} {'white min/mean':>15s} {'joint':>6s} "
        f"{'oe min/mean':>12s} {'joint':>6s} {'withheld':>9s} {'withheld min':>13s} {'median N_eff/p':>15s}"
    )
    for two in (False, True):
        b, f = siso_truth(two)
        nf, nb = f.size - 1, f.size - 1
        theta, structure = np.r_[b[1:], f[1:]], Structure(0, nb, 0, 0, nf, 1)
        chi2 = scipy.stats.chi2.ppf(0.95, theta.size)
        for n, count in runs.items():
            for snr in (10.0, 3.0):
                white_hits, oe_hits, held_hits, white_joint, oe_joint, per = [], [], [], 0, 0, []
                for r in range(count):
                    y, u = siso_record(b, f, n, snr, [30_000, two, int(snr), n, r])
                    try:
                        model, _ = _quiet(oe, y, u, nb, nf, 1, sample_time=TS_SISO)
                    except EstimationError:
                        continue
                    d = SisoData(y, u, TS_SISO)
                    eps = structure.errors(model.parameters, d)
                    white = covariance(
                        structure.gradient(model.parameters, eps, d), eps @ eps / (eps.size - theta.size)
                    )
                    x = model.parameters - theta
                    white_hits.append(np.abs(x) <= 1.959964 * np.sqrt(np.diag(white)))
                    white_joint += float(x @ np.linalg.pinv(white) @ x) <= chi2
                    if "effective_samples" in model.info:
                        per.append(model.info["effective_samples"] / theta.size)
                    cov = model.covariance
                    if model.info.get("intervals_withheld"):
                        held_hits.append(np.abs(x) <= 1.959964 * np.sqrt(np.diag(cov)))
                        continue
                    oe_hits.append(np.abs(x) <= 1.959964 * np.sqrt(np.diag(cov)))
                    oe_joint += float(x @ np.linalg.pinv(cov) @ x) <= chi2
                wh, oh = np.mean(white_hits, axis=0), np.mean(oe_hits, axis=0) if oe_hits else np.full(1, np.nan)
                fits = len(white_hits)
                per_text = f"{np.median(per):15.1f}" if per else f"{'-':>15s}"
                held_text = f"{np.mean(held_hits, axis=0).min():13.3f}" if held_hits else f"{'-':>13s}"
                oe_text = (
                    f"{oh.min():5.3f}/{oh.mean():5.3f} {oe_joint / len(oe_hits):6.3f}"
                    if oe_hits
                    else f"{'-':>12s} {'-':>6s}"
                )
                print(
                    f"   {'two modes' if two else 'one mode':9s} {n:5d} {snr:4.0f} {fits:5d} "
                    f"{wh.min():7.3f}/{wh.mean():5.3f}   {white_joint / fits:6.3f} {oe_text} {len(held_hits):9d} "
                    f"{held_text} {per_text}"
                )


# ----------------------------------------------------------------------------------------------- 5: ssest speed
def _former_ssest(y: np.ndarray, u: np.ndarray, n: int, ts: float) -> float:
    """The former search, rebuilt: n4sid's subspace model with its own Kalman gain as the start, Levenberg-Marquardt
    on central differences (``scipy.optimize.least_squares(jac="3-point")``, tolerances 1e-12), at most six
    re-weighted passes; returns ``det`` of the innovation covariance reached."""
    from trms.identification.ss_predictor import _covariance_of, _Layout, _loss, _predictor_output

    start = n4sid(y, u, n, sample_time=ts, refine="none")
    p, m = y.shape[1], u.shape[1]
    layout = _Layout(n, m, p, False)
    theta = layout.pack(start.A, start.B, start.C, start.kalman_gain, np.zeros((p, m)))

    def errors(th: np.ndarray) -> np.ndarray:
        a, b, c, k, dd, _ = layout.unpack(th)
        return y - _predictor_output(a, b, c, dd, k, y, u)

    lam = _covariance_of(errors(theta))
    for _ in range(6):
        basis = layout.local_basis(theta, np.ones(layout.size, bool), similarity=True)
        white = np.linalg.inv(np.linalg.cholesky(lam)).T
        base = theta.copy()
        penalty = 1e3 * (errors(base) @ white).ravel()

        def whitened(
            eta: np.ndarray,
            base: np.ndarray = base,
            white: np.ndarray = white,
            penalty: np.ndarray = penalty,
            basis: np.ndarray = basis,
        ) -> np.ndarray:
            a, _, c, k, _, _ = layout.unpack(base + basis @ eta)
            if np.max(np.abs(np.linalg.eigvals(a - k @ c))) >= 1.0:
                return penalty
            return (errors(base + basis @ eta) @ white).ravel()

        res = scipy.optimize.least_squares(
            whitened,
            np.zeros(basis.shape[1]),
            jac="3-point",
            method="lm",
            x_scale="jac",
            ftol=1e-12,
            xtol=1e-12,
            gtol=1e-12,
            max_nfev=100 * (2 * basis.shape[1] + 1),
        )
        theta = base + basis @ res.x
        new = _covariance_of(errors(theta))
        settled = _loss(lam) - _loss(new) <= 1e-10 * _loss(lam)
        lam = new
        if settled:
            break
    return _loss(lam)


def ssest_speed() -> None:
    """ssest on a 2x2, order-6 record of 3000 samples (the two-resonance MIMO plant of bench_identification)."""
    from bench_identification import _binary, mimo_plant

    truth = mimo_plant()
    u = _binary(3000, 1, channels=2)
    y = control.forced_response(truth, U=u.T).outputs.T
    y = y + 0.05 * y.std(axis=0) * np.random.default_rng(2).standard_normal(y.shape)
    print("5. ssest on a 2x2, order 6, N 3000 record (5 % output noise), one BLAS thread advised")
    tic = time.perf_counter()
    model, _ = _quiet(ssest, y, u, 6, sample_time=0.05)
    t_new = time.perf_counter() - tic
    tic = time.perf_counter()
    try:
        former, _ = _quiet(_former_ssest, y, u, 6, 0.05)
    except (ImportError, TypeError):  # an older trms: its own ssest is the former search
        former = None
    t_old = time.perf_counter() - tic
    print(
        f"   ssest (this version)        {t_new:7.2f} s  loss {model.loss:.8e}  fit % "
        + ", ".join(f"{v:.3f}" for v in model.fit)
    )
    if former is not None:
        print(f"   former search (rebuilt)     {t_old:7.2f} s  loss {former:.8e}  ratio {t_old / t_new:5.1f}x")
