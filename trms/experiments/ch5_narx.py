"""Chapter 5 on a plant: NARX with a Gaussian RBF network (OLS centres) against the linear ARMAX.

1-DOF (ch. 5.4-5.6), ``Ts = 0.2 s``
    Two excitations of 60 s (300 samples, the thesis's training size): uniformly distributed noise
    with a 2 Hz clock (0.15 V half-width) and a two-level 5 Hz PRBS (0.1 V). On each, an 8th-order
    NARX (``ny = nu = 8``) with at most 13 centres plus a bias; on the uniform-noise data the five
    correlation tests of eq. (5.13) and a 4th-order ARMAX for Table 5.1 (variance of the one-step
    residuals on the training data). Beside them, a polynomial NARX chosen term by term by FROLS
    (:data:`POLY`) on the same data, with the same five tests. The RBF models, the polynomial one and
    the ARMAX then run free (model predicted output, eq. 5.14) on the 3211 and the doublet of ch. 3.
2-DOF future work (ch. 8): the ``u1 -> yaw`` channel, ``Ts = 0.1 s``
    Uniform noise (2 Hz clock, 0.05 V) on u1 for 60 s (600 samples), u2 at trim; an 8th-order
    NARX-RBF and a 4th-order ARMAX on the yaw (means removed), compared by residual variance and
    by their free run on a doublet on u1.

:func:`narx_1dof` and :func:`narx_yaw` are functions of a Plant; :func:`section_5` puts the linear
model's and the twin's results beside the thesis's.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np

from trms.experiments.ch3_identification import ORDERS, correlation_verdict, excite, validation_signals
from trms.identification import (
    Comparison,
    CorrelationTest,
    NarxRbf,
    PolynomialModel,
    PolynomialNarx,
    armax,
    compare,
    narx_poly,
    narx_rbf,
    residual_tests,
    residual_variance,
    siso_data,
)
from trms.measurement.protocol import armax_1dof
from trms.plant import Plant
from trms.present.figures import plot_correlation_tests, plot_series, save_figure
from trms.present.sections import FigureRef, Section
from trms.present.seeds import Seeded, seeded
from trms.present.tables import NOT_PRINTED, ComparisonTable, format_cell, note_far_cells, side_by_side
from trms.record import Record
from trms.reference import FROM_TABLE_5_1, PRINTED, TABLE_5_1
from trms.signals import doublet, random_binary, uniform_noise
from trms.worlds import NOISE_STD

__all__ = [
    "UNIFORM_1DOF",
    "PRBS_1DOF",
    "LAGS",
    "POLY",
    "MAX_CENTRES",
    "Narx",
    "NarxYaw",
    "narx_1dof",
    "narx_yaw",
    "section_5",
]

#: Uniform noise (1-DOF): duration (s), clock (Hz), half-width (V).
UNIFORM_1DOF = (60.0, 2.0, 0.15)
#: PRBS (1-DOF): duration (s), clock (Hz), amplitude (V).
PRBS_1DOF = (60.0, 5.0, 0.1)
#: Uniform noise on u1 (2-DOF yaw channel): duration (s), clock (Hz), half-width (V).
UNIFORM_YAW = (60.0, 2.0, 0.05)
#: NARX lags: ny = nu (the thesis's 8th order), input delay nk.
LAGS = (8, 8, 1)
#: The polynomial NARX beside it (FROLS, :mod:`trms.identification.frols`): lags ny, nu, delay nk, degree, and
#: the terms chosen (the RBF's budget: 13 centres). Six lags of degree 2 are 91 candidates, within what 300 samples
#: can choose from (eight would be 153).
POLY = (6, 6, 1, 2, 13)
#: Most Gaussian centres (the thesis: 13 plus a bias).
MAX_CENTRES = 13
#: Gaussian widths tried, as multiples of the median distance between candidate centres (the thesis's
#: "spread", chosen by generate and test).
WIDTH_FACTORS = (1.0, 2.0, 4.0, 8.0, 16.0)
#: OLS stops earlier only if the unexplained energy falls below this fraction.
OLS_TOLERANCE = 1e-4


@dataclass
class Narx:
    """One plant's chapter 5 results (see the module docstring; :func:`narx_1dof`'s ``full`` for what a run's other
    seeds hold)."""

    data: dict[str, Record]
    rbf: dict[str, NarxRbf]
    armax: PolynomialModel
    tests: list[CorrelationTest]
    mpo: dict[tuple[str, str], Comparison]
    variances: dict[str, float]
    poly: PolynomialNarx | None
    poly_tests: list[CorrelationTest]


@dataclass
class NarxYaw:
    """One plant's 2-DOF ``u1 -> yaw`` NARX-RBF against ARMAX."""

    data: Record
    validation: Record
    rbf: NarxRbf
    armax: PolynomialModel
    variances: dict[str, float]
    mpo: dict[str, Comparison]


def _fit_rbf(y: np.ndarray, u: np.ndarray, ts: float) -> NarxRbf:
    """Generate and test (ch. 5.5.1): one model per Gaussian width in :data:`WIDTH_FACTORS` times the
    median distance between candidate centres; keep the one whose free run best fits the training data."""
    ny, nu, nk = LAGS
    base = narx_rbf(y, u, ny, nu, nk, sample_time=ts, max_centres=MAX_CENTRES, tolerance=OLS_TOLERANCE)
    best, best_fit = base, -np.inf
    for factor in WIDTH_FACTORS:
        model = (
            base
            if factor == 1.0
            else narx_rbf(
                y,
                u,
                ny,
                nu,
                nk,
                sample_time=ts,
                max_centres=MAX_CENTRES,
                tolerance=OLS_TOLERANCE,
                width=factor * base.width,
            )
        )
        fit = compare(model, y, u, initial="measured").fit
        if fit > best_fit:
            best, best_fit = model, fit
    return best


def narx_1dof(plant: Plant, seed: int = 0, full: bool = True) -> Narx:
    """Chapter 5 on a 1-DOF plant (``u1 -> pitch``, 0.2 s).

    Parameters
    ----------
    plant : Plant
    seed : int
        Seed of the excitations and the plant's noise.
    full : bool
        Everything (False: Table 5.1's models on the uniform-noise training run only -- the RBF and the ARMAX, their
        residual variances and the RBF's tests -- what a cell carrying a verdict reads at a run's other seeds;
        ``poly`` is then ``None`` and ``mpo`` and ``poly_tests`` empty).
    """
    ts = plant.sample_time
    signals = {"uniform noise": uniform_noise(*UNIFORM_1DOF[:1], ts, *UNIFORM_1DOF[1:], seed=seed)}
    if full:
        signals["PRBS"] = random_binary(*PRBS_1DOF[:1], ts, *PRBS_1DOF[1:], seed=seed + 1)
        signals.update(validation_signals(ts, PRBS_1DOF[2], 30.0))
    data = {name: excite(plant, sig, seed=seed + i) for i, (name, sig) in enumerate(signals.items())}
    sd = {name: siso_data(rec) for name, rec in data.items()}
    rbf: dict[str, NarxRbf] = {
        name: _fit_rbf(sd[name].y, sd[name].u, ts) for name in ("uniform noise", "PRBS") if name in sd
    }
    train = sd["uniform noise"]
    lin = armax_1dof(train.y, train.u, ts)
    tests = residual_tests(rbf["uniform noise"], train.y, train.u)
    variances = {
        "linear ARMAX": residual_variance(lin, train.y, train.u),
        "NARX-RBF": residual_variance(rbf["uniform noise"], train.y, train.u),
    }
    if not full:
        return Narx(data, rbf, lin, tests, {}, variances, None, [])
    ny, nu, nk, degree, terms = POLY
    poly = narx_poly(train.y, train.u, ny, nu, nk, degree=degree, max_terms=terms, tolerance=0.0, sample_time=ts)
    mpo = {}
    for val in ("3211", "doublet"):
        d = sd[val]
        for name, model in rbf.items():
            mpo[(f"NARX-RBF ({name})", val)] = compare(model, d.y, d.u, initial="measured")
        mpo[("polynomial NARX (FROLS)", val)] = compare(poly, d.y, d.u, initial="measured")
        mpo[("linear ARMAX", val)] = compare(lin, d.y, d.u, initial="measured")
    variances["polynomial NARX (FROLS)"] = residual_variance(poly, train.y, train.u)
    return Narx(data, rbf, lin, tests, mpo, variances, poly, residual_tests(poly, train.y, train.u))


def narx_yaw(plant: Plant, seed: int = 0) -> NarxYaw:
    """The thesis's future work on a 2-DOF plant: a NARX-RBF model of ``u1 -> yaw`` against its ARMAX.

    Parameters
    ----------
    plant : Plant
        Inputs u1, u2; outputs pitch, yaw (0.1 s).
    seed : int
        Seed of the excitation and the plant's noise.
    """
    ts = plant.sample_time
    duration, clock, amp = UNIFORM_YAW
    data = excite(plant, uniform_noise(duration, ts, clock, amp, seed=seed), 0, seed=seed)
    val = excite(plant, doublet(ts, 2.0, amp, start=2.0, duration=40.0), 0, seed=seed + 1)
    d = siso_data(data, input="u1", output="yaw")
    y, u = d.y - d.y.mean(), d.u - d.u.mean()
    rbf = _fit_rbf(y, u, ts)
    lin = armax(y, u, *ORDERS, sample_time=ts, input="u1", output="yaw")
    dv = siso_data(val, input="u1", output="yaw")
    return NarxYaw(
        data,
        val,
        rbf,
        lin,
        {"linear ARMAX": residual_variance(lin, y, u), "NARX-RBF": residual_variance(rbf, y, u)},
        {
            "linear ARMAX": compare(lin, dv.y, dv.u, initial="measured"),
            "NARX-RBF": compare(rbf, dv.y, dv.u, initial="measured"),
        },
    )


def _variance(r: Narx, key: str) -> float:
    return r.variances[key]


def _passed(r: Narx, k: int) -> str:
    return "pass" if r.tests[k].passed else "fail"


def _table_5_1(res: Mapping[str, Narx | Seeded[Narx]]) -> ComparisonTable:
    lin, tw = seeded(res["linear"]).first, seeded(res["twin"])
    table = side_by_side("Table 5.1 and ch. 5 (1-DOF): NARX-RBF against the linear ARMAX", ["quantity"], sources=True)
    table.rows += _model_rows_5_1(lin, tw) + _test_rows_5_1(lin, tw) + _mpo_rows_5_1(lin, tw.first)
    why = _far_note_5_1(lin, tw.first, tw.seeds[0])
    note_far_cells(table, why)
    n = len(tw.seeds)
    table.notes.insert(
        0,
        "Source: where the thesis column's value comes from."
        + (
            f" Twin: at {n} seeds ({', '.join(str(s) for s in tw.seeds)}) the median (range) of Table 5.1's cells, "
            "judged at each seed (within 30 % of the thesis's: agrees at every seed, differs at none, else "
            f"inconclusive); the polynomial NARX and the free runs are seed {tw.seeds[0]}'s."
            if n > 1
            else ""
        ),
    )
    return table


def _model_rows_5_1(lin: Narx, tw: Seeded[Narx]) -> list[list[object]]:
    """Table 5.1's rows of the models: residual variances (the polynomial NARX's beside), their ratio, the RBF's
    centres and training error."""
    twin = tw.first
    table_rows: list[list[object]] = []
    for key, printed in TABLE_5_1.items():
        table_rows.append(
            [
                f"variance of residuals, {key} (rad^2)",
                printed,
                PRINTED,
                lin.variances[key],
                tw.cell(partial(_variance, key=key)),
                "one-step residuals on the 300 uniform-noise training samples",
            ]
        )
    ny, nu, nk, degree, terms = POLY
    if lin.poly is not None and twin.poly is not None:
        table_rows.append(
            [
                "variance of residuals, polynomial NARX by FROLS (rad^2)",
                NOT_PRINTED,
                "-",
                lin.variances["polynomial NARX (FROLS)"],
                twin.variances["polynomial NARX (FROLS)"],
                f"beside the thesis's RBF: monomials of degree <= {degree} of {ny} output and {nu} input lags, at "
                f"most {terms} terms chosen by their error-reduction ratio (chose {lin.poly.n_terms} and "
                f"{twin.poly.n_terms})",
            ]
        )

    def ratio(r: Narx) -> float:
        return r.variances["NARX-RBF"] / r.variances["linear ARMAX"]

    table_rows.append(
        [
            "variance ratio RBF / ARMAX",
            TABLE_5_1["NARX-RBF"] / TABLE_5_1["linear ARMAX"],
            FROM_TABLE_5_1,
            ratio(lin),
            tw.cell(ratio),
            "below 1: the RBF explains more; the thesis found the difference negligible",
        ]
    )
    table_rows.append(
        [
            "centres chosen by OLS",
            13,
            PRINTED,
            lin.rbf["uniform noise"].n_centres,
            tw.cell(lambda r: r.rbf["uniform noise"].n_centres),
            f"at most {MAX_CENTRES} plus a bias; Gaussian width by generate and test: the free run on the "
            f"training data decides among {', '.join(f'{k:g}' for k in WIDTH_FACTORS)} x the median distance "
            "between candidates",
        ]
    )
    table_rows.append(
        [
            "training sum-squared error (normalised)",
            0.002,
            PRINTED,
            lin.rbf["uniform noise"].training_sse,
            tw.cell(lambda r: r.rbf["uniform noise"].training_sse),
            f"sum over the {lin.rbf['uniform noise'].n_samples} training targets, in units of the output's "
            "standard deviation",
        ]
    )
    return table_rows


def _test_rows_5_1(lin: Narx, tw: Seeded[Narx]) -> list[list[object]]:
    """Table 5.1's correlation tests of the RBF (eq. 5.13), the polynomial NARX's beside."""
    twin = tw.first
    table_rows: list[list[object]] = []
    for k, tl in enumerate(lin.tests):
        table_rows.append(
            [
                f"correlation test phi_{tl.name}",
                "inside +-1.96/sqrt(N)",
                PRINTED,
                correlation_verdict(tl),
                tw.cell(partial(_passed, k=k)),
                f"95 % joint test over 20 lags, RBF on its training data (eq. 5.13); twin at seed {tw.seeds[0]}: "
                f"{correlation_verdict(twin.tests[k])}",
            ]
        )
    for tl, tt in zip(lin.poly_tests, twin.poly_tests):
        table_rows.append(
            [
                f"correlation test phi_{tl.name}, polynomial NARX",
                NOT_PRINTED,
                "-",
                correlation_verdict(tl),
                correlation_verdict(tt),
                "the same test, the FROLS model on the same data",
            ]
        )
    return table_rows


def _mpo_rows_5_1(lin: Narx, twin: Narx) -> list[list[object]]:
    """Table 5.1's free-run (MPO) fits on the validation signals, at the first seed."""
    table_rows: list[list[object]] = []
    for val in ("3211", "doublet"):
        for name in ("NARX-RBF (uniform noise)", "NARX-RBF (PRBS)", "polynomial NARX (FROLS)", "linear ARMAX"):
            if (name, val) not in lin.mpo or (name, val) not in twin.mpo:
                continue
            table_rows.append(
                [
                    f"MPO fit on the {val} (%), {name}",
                    NOT_PRINTED,
                    "-",
                    lin.mpo[(name, val)].fit,
                    twin.mpo[(name, val)].fit,
                    "thesis: the noise-trained model captures the dynamics better than the PRBS-trained one"
                    if "PRBS" in name
                    else "model predicted output (free run, eq. 5.14)",
                ]
            )
    return table_rows


def _far_note_5_1(lin: Narx, twin: Narx, seed: int):
    """The note of a cell far from the thesis: the world's noise floor of any one-step residual."""
    noise = NOISE_STD**2

    def why(row: list, col: str, v: object, thesis: object) -> str:
        world = lin if col == "linear model" else twin
        floor = (
            f"this world's measurement-noise variance is {noise:.3g} rad^2, the floor of any one-step residual "
            f"(at seed {seed}: ARMAX {world.variances['linear ARMAX'] / noise:.3g} x, RBF "
            f"{world.variances['NARX-RBF'] / noise:.3g} x that); the rig's noise level is not printed"
        )
        return f"{format_cell(v)} vs thesis {format_cell(thesis)}; not explained ({floor})."

    return why


def _table_yaw(res: Mapping[str, NarxYaw]):
    table = side_by_side(
        "Ch. 8 future work: a NARX-RBF model of the 2-DOF u1 -> yaw channel against its ARMAX", ["quantity"]
    )
    for key in ("linear ARMAX", "NARX-RBF"):
        table.rows.append(
            [
                f"variance of residuals, {key} (rad^2)",
                "-",
                res["linear"].variances[key],
                res["twin"].variances[key],
                "one-step residuals on 600 uniform-noise samples (means removed)",
            ]
        )
    for key in ("linear ARMAX", "NARX-RBF"):
        table.rows.append(
            [
                f"doublet MPO fit (%), {key}",
                "ARMAX 'not so good' (fig. 3.27)",
                res["linear"].mpo[key].fit,
                res["twin"].mpo[key].fit,
                "free run on a doublet on u1 (0.05 V, 2 s pulses)",
            ]
        )
    return table


def section_5(
    res: Mapping[str, Narx | Seeded[Narx]], yaw: Mapping[str, NarxYaw], folder: str | os.PathLike[str]
) -> Section:
    """The chapter 5 section: Table 5.1 side by side, correlation tests, MPO figures, the yaw RBF (the twin's results
    at every seed of the run, :class:`~trms.present.seeds.Seeded`, where its cells carry a verdict)."""
    folder = Path(folder)
    twin = seeded(res["twin"]).first
    figs = [
        FigureRef(
            save_figure(
                plot_correlation_tests(twin.tests, "Twin NARX-RBF correlation tests (fig. 5.5)"),
                folder / "ch5_correlation_twin.png",
            ),
            "The five correlation tests of eq. (5.13) on the twin's NARX-RBF residuals, 95 % bands.",
        )
    ]
    for val in ("3211", "doublet"):
        c = {name: twin.mpo[(name, val)] for name in ("NARX-RBF (uniform noise)", "NARX-RBF (PRBS)", "linear ARMAX")}
        first = next(iter(c.values()))
        series = {"twin pitch": first.y}
        series.update({f"{k} (fit {v.fit:.0f} %)": v.yhat for k, v in c.items()})
        figs.append(
            FigureRef(
                save_figure(
                    plot_series(
                        twin.data[val].time,
                        series,
                        f"Twin 1-DOF model predicted output on the {val} (figs. 5.8-5.12)",
                        "pitch (rad, deviation)",
                    ),
                    folder / f"ch5_mpo_{val}_twin.png",
                ),
                f"Twin pitch on the {val} and the free runs of the two RBF models and the ARMAX.",
            )
        )
    ty = yaw["twin"]
    series = {"twin yaw": ty.mpo["NARX-RBF"].y}
    series.update({f"{k} (fit {v.fit:.0f} %)": v.yhat for k, v in ty.mpo.items()})
    figs.append(
        FigureRef(
            save_figure(
                plot_series(
                    ty.validation.time,
                    series,
                    "Twin 2-DOF u1 -> yaw: NARX-RBF and ARMAX on a doublet",
                    "yaw (rad, deviation)",
                ),
                folder / "ch5_yaw_doublet_twin.png",
            ),
            "Twin yaw under a doublet on u1 and the free runs of its NARX-RBF and ARMAX models.",
        )
    )
    paragraphs = [
        "NARX-RBF models (8th order, OLS centre selection, at most 13 centres plus a bias, signals normalised) trained "
        "on 300 samples of uniformly distributed noise (2 Hz clock) and, for comparison, of a two-level 5 Hz PRBS; "
        "validated by the five correlation tests and in free run on the 3211 and the doublet of ch. 3.",
    ]
    return Section(
        "Chapter 5: nonlinear identification (NARX-RBF)", paragraphs, [_table_5_1(res), _table_yaw(yaw)], figs
    )
