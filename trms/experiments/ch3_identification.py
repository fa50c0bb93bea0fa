"""Chapter 3 on a plant: 1-DOF and 2-DOF linear identification with the thesis's protocols.

1-DOF (ch. 3.2-3.3), ``Ts = 0.2 s``
    A 5 Hz PRBS of 60 s around hover drives ``u1``; the pitch PSD's peaks in 0-1 Hz are the
    modes; a 4th-order ARMAX (PEM) is fitted; its residuals get the whiteness and independence
    tests (eq. 3.9); it is cross-validated in free run on a 3211 multistep and a doublet (time
    domain) and by the PSD of its output against the plant's (frequency domain). The coherence
    (eq. 3.1) is computed at 5 Hz and again on a 10 Hz run of the same protocol (fig. 3.5).
2-DOF (ch. 3.4-3.5), ``Ts = 0.1 s``
    A 2 Hz PRBS of 120 s, smaller amplitude, on one input at a time (the other held at trim);
    coherence of every channel (fig. 3.14); a 4th-order ARMAX per coupled channel on the first
    600 samples (means removed, :func:`trms.identification.mimo.identify_mimo`); a doublet on
    each input for validation; PSD modes per channel (Table 3.1).

Amplitudes (the thesis prints none, only that they keep the rig in its linear range near hover):
the calibration's protocols (:data:`trms.calibration.THESIS_PROTOCOLS`), 0.05 V for both, so
that chapter 3 and the calibration identify the same experiment; validation signals of the same
amplitudes, 3211 unit step 1 s, doublet pulse 2 s, first edge at 2 s. This project's choices.
:func:`identify_1dof` and :func:`identify_2dof` are functions of a Plant; :func:`section` puts the linear
model's and the twin's results beside the thesis's.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from trms.calibration.protocol import ARMAX_ORDERS, THESIS_PROTOCOLS, armax_1dof
from trms.identification import (
    Comparison,
    CorrelationTest,
    MimoIdentification,
    Peak,
    PolynomialModel,
    coherence,
    compare,
    find_modes,
    identify_mimo,
    psd,
    residual_tests,
    siso_data,
)
from trms.identification.spectral import mean_coherence
from trms.modes import oscillatory
from trms.plant import Plant, simulate
from trms.present.figures import plot_coherence, plot_correlation_tests, plot_series, plot_spectra, save_figure
from trms.present.sections import FigureRef, Section, finite_or
from trms.present.tables import NOT_PRINTED, format_cell, note_far_cells, side_by_side
from trms.record import Record
from trms.reference import (
    EQ_3_11_DC_GAIN,
    EQ_3_11_MODE,
    MAIN_MODE_HZ,
    MODE_TABLE,
    PSD_MODES_1DOF,
    TABLE_3_1_MODES_HZ,
    eq_3_11,
)
from trms.signals import doublet, multistep_3211, random_binary
from trms.worlds import NOISE_STD

__all__ = [
    "PRBS_1DOF",
    "PRBS_2DOF",
    "Siso1Dof",
    "Mimo2Dof",
    "excite",
    "head",
    "validation_signals",
    "identify_1dof",
    "identify_2dof",
    "step_delay",
    "verdict",
    "section",
]

#: 1-DOF PRBS: duration (s), clock (Hz), amplitude (V): the calibration's 1-DOF protocol.
PRBS_1DOF = (THESIS_PROTOCOLS[0].duration_s, THESIS_PROTOCOLS[0].bandwidth_hz, THESIS_PROTOCOLS[0].amplitude_v)
#: 2-DOF PRBS: duration (s), clock (Hz), amplitude (V): the calibration's 2-DOF protocols.
PRBS_2DOF = (THESIS_PROTOCOLS[1].duration_s, THESIS_PROTOCOLS[1].bandwidth_hz, THESIS_PROTOCOLS[1].amplitude_v)
#: Samples used for the 2-DOF estimation (the thesis: 600).
ESTIMATION_SAMPLES_2DOF = 600
#: Welch segment of the 1-DOF spectra (samples): 25.6 s at 5 Hz, three averaged segments in 60 s.
PSD_SEGMENT_1DOF = 128
#: Welch segment of the 2-DOF coherence (samples): 25.6 s, long against the lightly damped modes'
#: decay (the resolution bias the thesis warns of, ch. 3.4.4), with about 8 averaged segments.
COHERENCE_SEGMENT_2DOF = 256
#: ARMAX orders (na, nb, nc, nk), as eq. (3.11).
ORDERS = ARMAX_ORDERS
#: Band (Hz) holding the significant modes (ch. 3.2.2).
MODE_BAND = (0.03, 1.0)


@dataclass
class Siso1Dof:
    """One plant's 1-DOF identification (see the module docstring)."""

    estimation: Record
    validation: dict[str, Record]
    model: PolynomialModel
    peaks: list[Peak]
    spectra: dict[str, tuple[np.ndarray, np.ndarray]]
    coherence: dict[str, tuple[np.ndarray, np.ndarray]]
    tests: list[CorrelationTest]
    fits: dict[str, Comparison]


@dataclass
class Mimo2Dof:
    """One plant's 2-DOF identification (see the module docstring)."""

    experiments: dict[str, Record]
    validation: dict[str, Record]
    identification: MimoIdentification
    coherence: dict[tuple[str, str], tuple[np.ndarray, np.ndarray]]
    peaks: dict[tuple[str, str], list[Peak]]
    fits: dict[tuple[str, str], Comparison]


def excite(plant: Plant, signal: np.ndarray, input_index: int = 0, seed: int = 0) -> Record:
    """Run ``plant`` with ``signal`` (deviation V) on one input, the others held at trim."""
    return simulate(plant, plant.operating_point.with_signal(signal, input_index), seed=seed)


def head(record: Record, n: int) -> Record:
    """The first ``n`` samples of a record."""
    extras = {k: v[:n] for k, v in record.extras.items()}
    return Record(
        record.time[:n],
        record.inputs[:n],
        record.outputs[:n],
        record.input_names,
        record.output_names,
        extras,
        dict(record.metadata),
    )


def step_delay(model: PolynomialModel, fraction: float = 0.05) -> float:
    """Apparent pure delay of a model's step response: the time (s) to reach ``fraction`` of its final value."""
    n = 400
    y = model.simulate(np.ones(n))
    final = y[-1]
    k = int(np.argmax(np.sign(final) * y >= fraction * abs(final)))
    if k == 0:
        return 0.0
    lo, hi = y[k - 1], y[k]
    frac = (fraction * final - lo) / (hi - lo)
    return float((k - 1 + frac) * model.sample_time)


def validation_signals(ts: float, amplitude: float, duration: float) -> dict[str, np.ndarray]:
    """The cross-validation inputs (deviation V): a 3211 (unit step 1 s) and a doublet (pulse 2 s), from 2 s."""
    return {
        "3211": multistep_3211(ts, 1.0, amplitude, start=2.0, duration=duration),
        "doublet": doublet(ts, 2.0, amplitude, start=2.0, duration=duration),
    }


def identify_1dof(plant: Plant, fast_plant: Plant | None = None, seed: int = 0) -> Siso1Dof:
    """The 1-DOF identification of ch. 3.2-3.3 on ``plant`` (``Ts = 0.2 s``).

    Parameters
    ----------
    plant : Plant
        SISO ``u1 -> pitch``.
    fast_plant : Plant, optional
        The same rig at ``Ts = 0.1 s`` for the 10 Hz coherence (fig. 3.5b); skipped if absent.
    seed : int
        Seed of the excitation and the plant's noise.
    """
    duration, clock, amp = PRBS_1DOF
    ts = plant.sample_time
    est = excite(plant, random_binary(duration, ts, clock, amp, seed=seed), seed=seed)
    d = siso_data(est)
    model = armax_1dof(d.y, d.u, ts, input=d.input_name, output=d.output_name)
    f, p = psd(d.y, ts, PSD_SEGMENT_1DOF)
    peaks = sorted(find_modes(f, p, MODE_BAND, n=3), key=lambda k: -k.height)
    f_model, p_model = psd(model.simulate(d.u, d.y), ts, PSD_SEGMENT_1DOF)
    coh = {"5 Hz": coherence(d.u, d.y, ts)}
    if fast_plant is not None:
        fast = excite(fast_plant, random_binary(duration, fast_plant.sample_time, clock, amp, seed=seed), seed=seed)
        df = siso_data(fast)
        coh["10 Hz"] = coherence(df.u, df.y, fast_plant.sample_time)
    validation, fits = {}, {}
    for i, (name, sig) in enumerate(validation_signals(ts, amp, 30.0).items()):
        validation[name] = excite(plant, sig, seed=seed + 1 + i)
        dv = siso_data(validation[name])
        fits[name] = compare(model, dv.y, dv.u, initial="measured")
    tests = residual_tests(model, d.y, d.u, nonlinear=False)
    return Siso1Dof(est, validation, model, peaks, {"plant": (f, p), "model": (f_model, p_model)}, coh, tests, fits)


def identify_2dof(plant: Plant, seed: int = 0) -> Mimo2Dof:
    """The 2-DOF identification of ch. 3.4-3.5 on ``plant`` (inputs u1, u2; outputs pitch, yaw; ``Ts = 0.1 s``)."""
    duration, clock, amp = PRBS_2DOF
    ts = plant.sample_time
    experiments, validation = {}, {}
    for j, name in enumerate(plant.input_names):
        experiments[name] = excite(
            plant, random_binary(duration, ts, clock, amp, seed=seed + 10 * j), j, seed=seed + 10 * j
        )
        validation[name] = excite(plant, doublet(ts, 2.0, amp, start=2.0, duration=40.0), j, seed=seed + 10 * j + 1)
    mimo = identify_mimo(
        list(experiments.values()),
        *ORDERS,
        band=(0.0, 1.0),
        nperseg=COHERENCE_SEGMENT_2DOF,
        estimation_samples=ESTIMATION_SAMPLES_2DOF,
    )
    coh, peaks, fits = {}, {}, {}
    for name_in, rec in experiments.items():
        du, dy = rec.deviations()
        j = rec.input_names.index(name_in)
        for i, name_out in enumerate(rec.output_names):
            y = dy[:, i] - dy[:, i].mean()
            coh[(name_in, name_out)] = (
                mimo.channels[(name_in, name_out)].frequencies,
                mimo.channels[(name_in, name_out)].coherence,
            )
            f, p = psd(y, ts)
            peaks[(name_in, name_out)] = find_modes(f, p, MODE_BAND, n=2)
            ch = mimo.channels[(name_in, name_out)]
            if ch.model is not None:
                dv = siso_data(validation[name_in], input=name_in, output=name_out)
                fits[(name_in, name_out)] = compare(ch.model, dv.y, dv.u, initial="measured")
    return Mimo2Dof(experiments, validation, mimo, coh, peaks, fits)


# ----------------------------------------------------------------------------------------- report
def _freqs(peaks: list[Peak]) -> str:
    return ", ".join(f"{p.frequency:.2f}" for p in sorted(peaks, key=lambda p: p.frequency)) or "none found"


def _oscillatory(model: PolynomialModel) -> tuple[float, float]:
    """Lowest-damped oscillatory mode (Hz, damping) of a model; nan if none.

    Oscillatory: ``0 < f < 0.8 x Nyquist`` and damping below 1 (real poles and poles at the Nyquist
    frequency are not modes)."""
    osc = oscillatory(model.modes(), model.sample_time)
    if not osc:
        return float("nan"), float("nan")
    m = min(osc, key=lambda m: m.damping)
    return float(m.frequency_hz), float(m.damping)


def verdict(t: CorrelationTest) -> str:
    """``"pass"``, or ``"fail (k of n lags outside)"``, for a table cell."""
    return "pass" if t.passed else f"fail ({t.n_outside} of {t.lags.size} lags outside)"


def _notch(f: np.ndarray, c: np.ndarray, band: tuple[float, float] = (0.1, 1.0)) -> float:
    keep = (f >= band[0]) & (f <= band[1])
    return float(f[keep][np.argmin(c[keep])])


def _off(value: float, thesis: float) -> str:
    if not np.isfinite(value):
        return "not found"
    return f"{100 * (value - thesis) / thesis:+.0f} % from the thesis"


def _table_1dof(res: Mapping[str, Siso1Dof]):
    lin, twin = res["linear"], res["twin"]
    table = side_by_side(
        "Ch. 3, 1-DOF identification (u1 -> pitch, Ts = 0.2 s): modes, ARMAX model, validation", ["quantity"]
    )
    main = {w: r.peaks[0].frequency if r.peaks else float("nan") for w, r in res.items()}
    osc = {w: _oscillatory(r.model) for w, r in res.items()}
    gain = {w: r.model.dc_gain() for w, r in res.items()}
    table.rows += [
        [
            "pitch PSD main mode (Hz)",
            MAIN_MODE_HZ,
            finite_or(main["linear"], "none"),
            finite_or(main["twin"], "none"),
            f"twin {_off(main['twin'], MAIN_MODE_HZ)}; the linear model is eq. (3.11), "
            f"whose only resonance is {EQ_3_11_MODE[0]:g} Hz",
        ],
        [
            "pitch PSD further peaks (Hz)",
            "0.25, 0.46",
            _freqs(lin.peaks[1:]),
            _freqs(twin.peaks[1:]),
            "the thesis's 0.25 and 0.46 Hz peaks are not in eq. (3.11), which has one oscillatory pole pair; "
            "the twin's further peaks are its own",
        ],
        [
            "ARMAX oscillatory mode (Hz)",
            EQ_3_11_MODE[0],
            finite_or(osc["linear"][0], "none"),
            finite_or(osc["twin"][0], "none"),
            f"thesis value derived from eq. (3.11); twin {_off(osc['twin'][0], EQ_3_11_MODE[0])}",
        ],
        [
            "ARMAX mode damping ratio",
            EQ_3_11_MODE[1],
            finite_or(osc["linear"][1], "none"),
            finite_or(osc["twin"][1], "none"),
            "lightly damped in every world: the (almost) unstable oscillatory mode",
        ],
        [
            "ARMAX DC gain (rad/V)",
            EQ_3_11_DC_GAIN,
            gain["linear"],
            gain["twin"],
            f"the linear column recovers eq. (3.11) (known truth); twin {_off(gain['twin'], EQ_3_11_DC_GAIN)}",
        ],
        [
            "ARMAX zeros outside the unit circle",
            int(np.sum(np.abs(eq_3_11().zeros()) > 1)),
            int(np.sum(np.abs(lin.model.zeros()) > 1)),
            int(np.sum(np.abs(twin.model.zeros()) > 1)),
            "non-minimum phase when > 0 (eq. 3.12)",
        ],
        [
            "step response delay to 5 % (s)",
            "0.6-0.7",
            step_delay(lin.model),
            step_delay(twin.model),
            "thesis read it off the rig's step response (fig. 3.3); here from the identified model",
        ],
        [
            "residuals: whiteness phi_ee",
            "pass",
            verdict(lin.tests[0]),
            verdict(twin.tests[0]),
            "95 % joint test over 20 lags; encoder quantisation and the twin's unmodelled dynamics "
            "colour its residuals",
        ],
        [
            "residuals: independence phi_ue",
            "pass",
            verdict(lin.tests[1]),
            verdict(twin.tests[1]),
            "95 % joint test over lags -20..20",
        ],
        [
            "3211 free-run fit (%)",
            NOT_PRINTED,
            lin.fits["3211"].fit,
            twin.fits["3211"].fit,
            "thesis: faster dynamics follow well, the slower dominant ones less so (fig. 3.10a)",
        ],
        [
            "doublet free-run fit (%)",
            NOT_PRINTED,
            lin.fits["doublet"].fit,
            twin.fits["doublet"].fit,
            "fit = 100 (1 - |y - yhat| / |y - mean y|)",
        ],
    ]
    for key, label in (("5 Hz", "poor (resolution bias)"), ("10 Hz", "improved, notch near 0.4 Hz")):
        if key in lin.coherence and key in twin.coherence:
            cl, ct = (mean_coherence(*r.coherence[key], (0.0, 1.0)) for r in (lin, twin))
            table.rows.append(
                [
                    f"mean coherence 0-1 Hz at {key}",
                    label,
                    cl,
                    ct,
                    "measurement noise lowers it where the response is small",
                ]
            )
    if "10 Hz" in lin.coherence and "10 Hz" in twin.coherence:
        f_lin, c_lin = lin.coherence["10 Hz"]
        depth = float(np.min(c_lin[(f_lin >= 0.1) & (f_lin <= 1.0)]))
        why = "the thesis suspected nonlinearity at its notch"
        if depth < 0.5:
            why += (
                f"; the linear model, linear by construction, has a notch too (coherence {depth:.2f}): short "
                "Welch segments against a lightly damped mode (resolution bias) make one without any nonlinearity"
            )
        table.rows.append(
            [
                "lowest coherence in 0.1-1 Hz at 10 Hz (Hz)",
                "about 0.4",
                _notch(f_lin, c_lin),
                _notch(*twin.coherence["10 Hz"]),
                why,
            ]
        )

    def far(row: list, col: str, v: float, thesis: object) -> str:
        model = res["linear" if col == "linear model" else "twin"].model
        if row[0].startswith("ARMAX zeros"):
            mags = ", ".join(f"{abs(z):.2f}" for z in sorted(model.zeros(), key=abs))
            ref = ", ".join(f"{abs(z):.2f}" for z in sorted(eq_3_11().zeros(), key=abs))
            return (
                f"{v:g} vs {format_cell(thesis)}; not explained (zero magnitudes: identified {mags}; eq. (3.11) {ref})."
            )
        return f"{v:.3g} vs thesis {format_cell(thesis)}; not explained."

    note_far_cells(table, far)
    return table


def _table_2dof(res: Mapping[str, Mimo2Dof]):
    table = side_by_side(
        "Table 3.1 / 4.1 and ch. 3.5, 2-DOF identification (Ts = 0.1 s): modes, coupling, doublet fit",
        ["channel", "quantity"],
    )
    thesis_modes: dict[str, list[float]] = {}
    for m in MODE_TABLE:
        if m.configuration == "2dof":
            thesis_modes.setdefault(m.channel, []).append(m.frequency_hz)
    fit_notes = {
        ("u1", "pitch"): "thesis: the model closely follows the plant (fig. 3.26)",
        ("u1", "yaw"): "thesis: not so good, nonlinearity suspected (fig. 3.27)",
        ("u2", "yaw"): "thesis: excellent (fig. 3.28)",
    }
    out_index = {"pitch": "y1", "yaw": "y2"}
    for name_in, name_out in res["linear"].identification.channels:
        key = f"{name_in}->{out_index.get(name_out, name_out)}"
        chans = {w: r.identification.channels[(name_in, name_out)] for w, r in res.items()}
        thesis = thesis_modes.get(key)
        table.rows.append(
            [
                key,
                "PSD modes (Hz)",
                ", ".join(f"{f:g}" for f in thesis) if thesis else "no coupling",
                _freqs(res["linear"].peaks[(name_in, name_out)]),
                _freqs(res["twin"].peaks[(name_in, name_out)]),
                "two highest PSD peaks in 0.03-1 Hz of the output, excited input's run",
            ]
        )
        table.rows.append(
            [
                key,
                "mean coherence 0-1 Hz",
                "high" if thesis else "low",
                chans["linear"].mean_coherence,
                chans["twin"].mean_coherence,
                "coupled (ARMAX fitted) when >= 0.5, as fig. 3.14 decides",
            ]
        )
        table.rows.append(
            [
                key,
                "doublet free-run fit (%)",
                NOT_PRINTED if thesis else "not modelled",
                *(
                    finite_or(r.fits[(name_in, name_out)].fit) if (name_in, name_out) in r.fits else "not modelled"
                    for r in (res["linear"], res["twin"])
                ),
                fit_notes.get((name_in, name_out), "uncoupled: no model, as in the thesis")
                + "".join(
                    f"; {w}: {_NEGATIVE_FIT}"
                    for w, r in res.items()
                    if (name_in, name_out) in r.fits and r.fits[(name_in, name_out)].fit < 0
                ),
            ]
        )
    return table


#: What a free-run fit below 0 % means, flagged wherever such a model is shown.
_NEGATIVE_FIT = (
    "fit below 0 %: the model's free run is further from the output than the output's mean; not a usable model"
)


def _unusable(fit: float) -> str:
    return ": not a usable model" if fit < 0 else ""  # said in the figure too, not only in its caption


def _fit_caption(fit: float) -> str:
    return f" (fit {fit:.0f} %: below 0 %, {_NEGATIVE_FIT.split(': ', 1)[1]})" if fit < 0 else f" (fit {fit:.0f} %)"


def section(res1: Mapping[str, Siso1Dof], res2: Mapping[str, Mimo2Dof], folder: str | os.PathLike[str]) -> Section:
    """The chapter 3 section: tables beside the thesis and figures (3.2, 3.5, 3.10-3.12, 3.14, 3.16, 3.26-3.28)."""
    folder = Path(folder)
    figs = []
    spectra = {f"{w} (pitch)": r.spectra["plant"] for w, r in res1.items()}
    figs.append(
        FigureRef(
            save_figure(
                plot_spectra(
                    spectra,
                    "1-DOF pitch PSD, 5 Hz PRBS (fig. 3.2b)",
                    PSD_MODES_1DOF,
                    {f"{w} (pitch)": r.peaks for w, r in res1.items()},
                ),
                folder / "ch3_1dof_psd.png",
            ),
            "1-DOF pitch PSD under the 5 Hz PRBS, linear model and twin; thesis modes dashed, found peaks dotted.",
        )
    )
    coh = {f"{w}, {k}": fc for w, r in res1.items() for k, fc in r.coherence.items()}
    figs.append(
        FigureRef(
            save_figure(
                plot_coherence(coh, "1-DOF coherence u1 -> pitch (fig. 3.5)", (0.4,)), folder / "ch3_1dof_coherence.png"
            ),
            "Coherence of the 1-DOF PRBS run at 5 Hz and 10 Hz sampling (the thesis's notch near 0.4 Hz dashed).",
        )
    )
    twin1 = res1["twin"]
    figs.append(
        FigureRef(
            save_figure(
                plot_correlation_tests(twin1.tests, "Twin 1-DOF ARMAX residual tests (fig. 3.11)"),
                folder / "ch3_1dof_residuals_twin.png",
            ),
            "Residual auto-correlation and input cross-correlation of the twin's 1-DOF ARMAX, 95 % bands.",
        )
    )
    for name in ("3211", "doublet"):
        c = twin1.fits[name]
        rec = twin1.validation[name]
        du, _ = rec.deviations()
        figs.append(
            FigureRef(
                save_figure(
                    plot_series(
                        rec.time,
                        {"twin pitch": c.y, f"ARMAX free run (fit {c.fit:.0f} %)": c.yhat},
                        f"Twin 1-DOF cross-validation on a {name} (fig. 3.10)",
                        "pitch (rad, deviation)",
                        {"u1": du[:, 0]},
                    ),
                    folder / f"ch3_1dof_{name}_twin.png",
                ),
                f"Twin pitch and its ARMAX model's free run on the {name}{_fit_caption(c.fit)}.",
            )
        )
    figs.append(
        FigureRef(
            save_figure(
                plot_spectra(
                    {"twin pitch": twin1.spectra["plant"], "ARMAX output": twin1.spectra["model"]},
                    "Twin 1-DOF frequency-domain validation (fig. 3.12)",
                    PSD_MODES_1DOF,
                ),
                folder / "ch3_1dof_model_psd_twin.png",
            ),
            "PSD of the twin's pitch and of its ARMAX model's output on the PRBS.",
        )
    )
    for w, r in res2.items():
        curves = {f"{a} -> {b}": fc for (a, b), fc in r.coherence.items()}
        figs.append(
            FigureRef(
                save_figure(
                    plot_coherence(curves, f"2-DOF coherence by channel, {w} (fig. 3.14)", (), 1.5),
                    folder / f"ch3_2dof_coherence_{w}.png",
                ),
                f"Coherence of each 2-DOF channel, {w}.",
            )
        )
    twin2 = res2["twin"]
    spectra2 = {}
    for a, b in twin2.peaks:
        rec = twin2.experiments[a]
        _, dy = rec.deviations()
        spectra2[f"{a} -> {b}"] = psd(dy[:, rec.output_names.index(b)], rec.sample_time)
    figs.append(
        FigureRef(
            save_figure(
                plot_spectra(
                    spectra2,
                    "Twin 2-DOF output PSDs (figs. 3.16, 3.18)",
                    TABLE_3_1_MODES_HZ,
                    {f"{a} -> {b}": pk for (a, b), pk in twin2.peaks.items()},
                ),
                folder / "ch3_2dof_psd_twin.png",
            ),
            "PSD of each output of the twin under a PRBS on one input; thesis modes 0.1 and 0.34 Hz dashed.",
        )
    )
    for (a, b), c in twin2.fits.items():
        figs.append(
            FigureRef(
                save_figure(
                    plot_series(
                        twin2.validation[a].time,
                        {f"twin {b}": c.y, f"ARMAX free run (fit {c.fit:.0f} %{_unusable(c.fit)})": c.yhat},
                        f"Twin 2-DOF doublet on {a}, channel {a} -> {b} (figs. 3.26-3.28)",
                        f"{b} (rad, deviation)",
                    ),
                    folder / f"ch3_2dof_doublet_{a}_{b}_twin.png",
                ),
                f"Twin {b} and its {a} -> {b} ARMAX model's free run on a doublet{_fit_caption(c.fit)}.",
            )
        )
    paragraphs = [
        "Protocols as in ch. 3: 1-DOF, 5 Hz PRBS for 60 s at Ts = 0.2 s, 4th-order ARMAX by PEM, validated on a 3211 "
        "and a doublet; 2-DOF, 2 Hz PRBS for 120 s at Ts = 0.1 s on one input at a time, ARMAX per coupled channel on "
        f"600 samples, doublet validation. Amplitudes {PRBS_1DOF[2]:g} V (1-DOF) and {PRBS_2DOF[2]:g} V (2-DOF) "
        "about the hover trim.",
        "Linear model column: eq. (3.11) (1-DOF) and the twin's own linearisation at hover "
        "(2-DOF, for which the thesis prints no model), each with white measurement noise "
        f"({NOISE_STD:.1e} rad). Twin column: the MuJoCo twin with the same noise and its encoder quantisation.",
    ]
    return Section("Chapter 3: linear identification", paragraphs, [_table_1dof(res1), _table_2dof(res2)], figs)
