"""Monte Carlo coverage of the identification toolkit's confidence intervals on known truth, and its audits.

Run on demand (minutes; never a timed test):

    .venv/bin/python benchmarks/bench_identification_mc.py [--runs 200] [--boot 200] [--sizes 300 1000]
        [--structures ARX ARMAX OE OE-noisy BJ] [--skip-n4sid]
        [--only coverage bj mpc n4sid oe ssest] [--audit-runs 100] [--audit-runs-long 40] [--mpc-cases 20]

``--only`` picks the tables (default all). The five audits of :mod:`mc_audits` (BJ local minima, MPC's plan
against an independent QP, n4sid's slow-mode damping under coloured noise, OE intervals under coloured noise,
ssest's speed) run against whatever ``trms`` is imported: with ``PYTHONPATH`` at an older checkout the same
command gives the before table (options that version lacks print as such). Timings assume one BLAS thread
(``OPENBLAS_NUM_THREADS=1``): on a shared machine a second thread can make the small factorisations far slower.

Known truths (Ts 0.1 s): the plant ``G = B / F`` with a lightly damped resonance at 0.5 Hz (zeta 0.05,
peak gain about 10, DC gain 1), ``B = [0, 0.0526, 0.0438]``; the input a random binary +-1 signal.

* ARX(2, 2, 1): ``F y = B u + e``, ``e`` white, sd 0.5;
* ARMAX(2, 2, 1, 1): ``F y = B u + C e``, ``C = [1, 0.5]`` (coloured noise), sd 0.5;
* OE(2, 2, 1): ``y = B / F u + e``, ``e`` white, sd 1; and "OE-noisy", the same with sd 4 (the phase at
  2 Hz then has a standard deviation of about 50 deg at N = 300: the normal approximation fails there);
* BJ(2, 1, 1, 2, 1): ``y = B / F u + C / D e``, ``C = [1, 0.5]``, ``D = [1, -0.85]`` (coloured), sd 0.5.

For each structure and ``N`` in ``--sizes``, ``--runs`` realisations (200: a binomial standard error of
0.015 at 0.95) are fitted and the coverage of the truth is counted for three methods: ``delta``, the
covariance with normal and chi-square quantiles (:func:`~trms.identification.frequency.frequency_response`,
whose ``contains()`` is Fieller's region with chi-square radii); ``boot %``, the bootstrap
(:func:`~trms.identification.bootstrap.bootstrap`, ``--boot`` refits, residual innovations) read by
percentiles; ``boot-t``, the same refits studentized (each with its own covariance; the frequency bands are
the projections of the calibrated Fieller region). A realisation the estimator refuses (an
:class:`~trms.errors.EstimationError`) is counted and left out. Columns: each parameter's 95 % interval, the joint 95 %
region, the magnitude band at the resonance (0.5 Hz), the phase band at 2 Hz, and ``contains()`` pointwise at
those two frequencies and simultaneous over 32 frequencies from 0.01 to 5 Hz. The goal: >= 0.93 at N = 1000
for every structure with the better method.

Audits: (1) OE and BJ: how many of the fits end at a local minimum (loss more than 0.1 % above that of a
search started from the truth), and how many of those silently (neither ``info["local_minima"]`` nor a
:class:`~trms.identification.oe_bj.LocalMinimumWarning`); (2) ``n4sid`` on the 2x2 slow-mode system of
``bench_identification.py`` (0.1 and 0.34 Hz, Ts 0.1 s, N 2000, 100 seeds): unstable models.
"""

from __future__ import annotations

import argparse
import time
import warnings
from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.signal
import scipy.stats
from mc_audits import audit_bj, audit_mpc, audit_n4sid, audit_oe, ssest_speed

from trms.errors import EstimationError
from trms.identification import LocalMinimumWarning, armax, arx, bj, frequency_response, oe
from trms.identification.bootstrap import bootstrap
from trms.identification.data import SisoData
from trms.identification.frequency import FrequencyResponse
from trms.identification.pem import Structure, fit
from trms.identification.polynomial import PolynomialModel

#: The tables ``--only`` picks from, in the order they print.
TABLES = ("bj", "mpc", "n4sid", "oe", "ssest", "coverage")

TS = 0.1
_W, _ZETA = 2 * np.pi * 0.5, 0.05
_R, _TH = np.exp(-_ZETA * _W * TS), _W * TS * np.sqrt(1 - _ZETA**2)
F = np.array([1.0, -2 * _R * np.cos(_TH), _R**2])
B = np.array([0.0, 0.06, 0.05]) * F.sum() / 0.11
C = np.array([1.0, 0.5])
D = np.array([1.0, -0.85])
RESONANCE, HIGH = 0.5, 2.0
GRID = np.concatenate([[RESONANCE, HIGH], np.geomspace(0.01, 5.0, 30)])


@dataclass(frozen=True)
class Truth:
    """A structure, its true parameters (``[a, b, c, d, f]`` layout), how to simulate and how to fit."""

    name: str
    theta: np.ndarray
    noise_num: np.ndarray
    noise_den: np.ndarray
    sd: float
    estimate: Callable[[np.ndarray, np.ndarray], PolynomialModel]


TRUTHS = (
    Truth("ARX", np.concatenate([F[1:], B[1:]]), np.ones(1), F, 0.5, lambda y, u: arx(y, u, 2, 2, 1, sample_time=TS)),
    Truth(
        "ARMAX",
        np.concatenate([F[1:], B[1:], C[1:]]),
        C,
        F,
        0.5,
        lambda y, u: armax(y, u, 2, 2, 1, 1, sample_time=TS),
    ),
    Truth(
        "OE",
        np.concatenate([B[1:], F[1:]]),
        np.ones(1),
        np.ones(1),
        1.0,
        lambda y, u: oe(y, u, 2, 2, 1, sample_time=TS),
    ),
    Truth(
        "OE-noisy",
        np.concatenate([B[1:], F[1:]]),
        np.ones(1),
        np.ones(1),
        4.0,
        lambda y, u: oe(y, u, 2, 2, 1, sample_time=TS),
    ),
    Truth(
        "BJ",
        np.concatenate([B[1:], C[1:], D[1:], F[1:]]),
        C,
        D,
        0.5,
        lambda y, u: bj(y, u, 2, 1, 1, 2, 1, sample_time=TS),
    ),
)


def simulate(truth: Truth, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Output and input of one realisation (the noise after a 2000-sample burn-in)."""
    rng = np.random.default_rng(seed)
    u = np.sign(rng.standard_normal(n))
    e = truth.sd * rng.standard_normal(n + 2000)
    return scipy.signal.lfilter(B, F, u) + scipy.signal.lfilter(truth.noise_num, truth.noise_den, e)[2000:], u


def true_response(freq: np.ndarray) -> np.ndarray:
    zinv = np.exp(-2j * np.pi * freq * TS)
    return np.polyval(B[::-1], zinv) / np.polyval(F[::-1], zinv)


def _band_hits(fr: FrequencyResponse, g0: np.ndarray) -> list[bool]:
    """Magnitude band at the resonance, phase band at 2 Hz, contains() at both, contains() simultaneous."""
    mag_ok = fr.magnitude_low[0] <= abs(g0[0]) <= fr.magnitude_high[0]
    phase0 = fr.phase[1] + np.degrees(np.angle(g0[1] / fr.response[1]))
    phase_ok = fr.phase_low[1] <= phase0 <= fr.phase_high[1]
    inside = fr.contains(g0)
    return [
        bool(mag_ok),
        bool(phase_ok),
        bool(inside[0]),
        bool(inside[1]),
        bool(fr.contains(g0, simultaneous=True).all()),
    ]


def _reference_loss(truth: Truth, model: PolynomialModel, y: np.ndarray, u: np.ndarray) -> float:
    """Loss of the search started from the truth (the global minimum's stand-in)."""
    s = Structure(model.na, model.nb, model.nc, model.nd, model.nf, model.nk)
    try:
        return fit(SisoData(y, u, TS), s, truth.theta, name="ref", method="ref", max_iter=200, tol=1e-7).loss
    except Exception:  # noqa: BLE001 - a failed reference search leaves the kept fit unjudged
        return np.inf


def coverage(truth: Truth, n: int, runs: int, n_boot: int) -> tuple[dict[str, np.ndarray], dict[str, float], list[str]]:
    """Hits per method (rows: realisations; columns: parameters, joint, the five frequency checks) and audit counts."""
    g0 = true_response(GRID)
    hits: dict[str, list[list[bool]]] = defaultdict(list)
    audit = {"refused": 0, "local": 0, "silent": 0, "flagged": 0, "refit_ms": 0.0, "fit_ms": 0.0, "failed": 0}
    chi2_joint = scipy.stats.chi2.ppf(0.95, truth.theta.size)
    for r in range(runs):
        y, u = simulate(truth, n, 10_000 * n + r)
        tic = time.perf_counter()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                model = truth.estimate(y, u)
            except EstimationError:
                audit["refused"] += 1  # the estimator refused the data (e.g. F on the stability boundary)
                continue
        audit["fit_ms"] += 1e3 * (time.perf_counter() - tic) / runs
        if truth.name.startswith(("OE", "BJ")):
            flagged = bool(model.info.get("local_minima")) or any(
                issubclass(w.category, LocalMinimumWarning) for w in caught
            )
            audit["flagged"] += int(flagged)
            if model.loss > (1 + 1e-3) * _reference_loss(truth, model, y, u):
                audit["local"] += 1
                audit["silent"] += int(not flagged)
        theta, sd = model.parameters, model.std_errors
        x = theta - truth.theta
        inside = list(np.abs(x) <= 1.959964 * sd)
        joint = float(x @ np.linalg.pinv(model.covariance) @ x) <= chi2_joint  # type: ignore[arg-type]
        hits["delta"].append([*inside, joint, *_band_hits(frequency_response(model, GRID), g0)])
        boot = bootstrap(model, u, y, n_boot=n_boot, seed=r)
        audit["refit_ms"] += 1e3 * boot.seconds_per_refit / runs
        audit["failed"] += boot.failed
        for kind, label in (("percentile", "boot %"), ("studentized", "boot-t")):
            low, high = boot.intervals(kind=kind)
            inside = list((low <= truth.theta) & (truth.theta <= high))
            fr = boot.frequency_response(GRID, kind=kind)
            hits[label].append([*inside, boot.joint_contains(truth.theta, kind=kind), *_band_hits(fr, g0)])
    return {k: np.array(v, float) for k, v in hits.items()}, audit, model.parameter_names


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=200, help="realisations per structure and size")
    parser.add_argument("--boot", type=int, default=200, help="bootstrap refits per realisation")
    parser.add_argument("--sizes", type=int, nargs="+", default=[300, 1000], help="samples per realisation")
    parser.add_argument("--structures", nargs="+", default=[t.name for t in TRUTHS], help="truths to run")
    parser.add_argument("--skip-n4sid", action="store_true", help="leave out the white-noise n4sid audit")
    parser.add_argument("--only", nargs="+", default=list(TABLES), choices=TABLES, help="tables to print (default all)")
    parser.add_argument("--audit-runs", type=int, default=100, help="audit realisations per cell at N = 300")
    parser.add_argument("--audit-runs-long", type=int, default=40, help="audit realisations per cell at N = 2000")
    parser.add_argument("--mpc-cases", type=int, default=20, help="MPC cases per model and kind")
    args = parser.parse_args()
    audits = {
        "bj": lambda: audit_bj({300: args.audit_runs, 2000: args.audit_runs_long}),
        "mpc": lambda: audit_mpc(args.mpc_cases),
        "n4sid": lambda: audit_n4sid(args.audit_runs),
        "oe": lambda: audit_oe({300: args.audit_runs, 2000: args.audit_runs_long}),
        "ssest": ssest_speed,
    }
    for name in (t for t in TABLES if t in args.only and t != "coverage"):
        tic = time.perf_counter()
        audits[name]()
        print(f"   ({time.perf_counter() - tic:.0f} s)\n")
    if "coverage" in args.only:
        coverage_tables(args)


def coverage_tables(args: argparse.Namespace) -> None:
    """The coverage tables of the intervals and the two older audits (module docstring)."""
    checks = ["joint", "|G| 0.5Hz", "ph 2Hz", "in 0.5Hz", "in 2Hz", "in all"]
    audits = []
    se = np.sqrt(0.95 * 0.05 / args.runs)
    for truth in (t for t in TRUTHS if t.name in args.structures):
        print(
            f"\n{truth.name}: coverage of the truth by 95 % intervals, {args.runs} realisations (s.e. {se:.3f}), "
            f"{args.boot} bootstrap refits"
        )
        for k, n in enumerate(args.sizes):
            tic = time.perf_counter()
            hits, audit, names = coverage(truth, n, args.runs, args.boot)
            if k == 0:
                print(f"  {'N':>5s} {'method':10s} " + " ".join(f"{c:>9s}" for c in names + checks))
            for method in ("delta", "boot %", "boot-t"):
                print(f"  {n:5d} {method:10s} " + " ".join(f"{v:9.3f}" for v in hits[method].mean(axis=0)))
            print(
                f"        fit {audit['fit_ms']:.1f} ms, bootstrap refit {audit['refit_ms']:.2f} ms "
                f"(x {args.boot}), failed refits {audit['failed']}, fits refused {audit['refused']} (left out), "
                f"{time.perf_counter() - tic:.0f} s"
            )
            if truth.name.startswith(("OE", "BJ")):
                audits.append((truth.name, n, audit))
    print(f"\nOE/BJ local minima over {args.runs} realisations (kept loss > 1.001 x the search from the truth)")
    print(f"  {'model':9s} {'N':>5s} {'local':>6s} {'silent':>7s} {'flagged fits':>13s}")
    for name, n, audit in audits:
        print(f"  {name:9s} {n:5d} {audit['local']:6d} {audit['silent']:7d} {audit['flagged']:13d}")
    if not args.skip_n4sid:
        from bench_identification import n4sid_slow_modes  # the same system and data as that benchmark

        print()
        n4sid_slow_modes(100)


if __name__ == "__main__":
    main()
