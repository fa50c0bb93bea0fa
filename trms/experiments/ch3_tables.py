"""Chapter 3 presented: the 1-DOF table, Table 3.1 (2-DOF), and the chapter's figures.

The builders take each world's results of :mod:`trms.experiments.ch3_identification`; the twin's may be its results
at every seed of the run (:class:`~trms.present.seeds.Seeded`): every twin cell that carries a verdict is then
measured at each seed (median, range) and judged over them, the other cells read the run's own seed. Modes are the
identified model's modes the PSD shows (:func:`~trms.experiments.ch3_identification.confirmed_modes`), never raw
PSD maxima.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from functools import partial
from pathlib import Path

import numpy as np

from trms.experiments.ch3_identification import (
    MODE_BAND,
    PRBS_1DOF,
    PRBS_2DOF,
    Mimo2Dof,
    Siso1Dof,
    bin_1dof,
    bin_2dof,
    correlation_verdict,
    identified_modes,
    other_peaks,
    step_delay,
)
from trms.identification import Peak, psd
from trms.identification.spectral import mean_coherence
from trms.modes import oscillatory
from trms.present.figures import plot_coherence, plot_correlation_tests, plot_series, plot_spectra, save_figure
from trms.present.sections import FigureRef, Section, finite_or
from trms.present.seeds import AGREES, TOLERANCE, Seeded, seeded
from trms.present.seeds import verdict as seed_verdict
from trms.present.tables import NOT_PRINTED, ComparisonTable, format_cell, note_far_cells, side_by_side
from trms.reference import (
    EQ_3_11_DC_GAIN,
    EQ_3_11_MODE,
    FROM_EQ_3_11,
    MAIN_MODE_HZ,
    MODE_TABLE,
    PRINTED,
    PSD_MODES_1DOF,
    TABLE_3_1_MODES_HZ,
    eq_3_11,
)
from trms.worlds import NOISE_STD

__all__ = ["table_1dof", "table_2dof", "section_3"]

World = Siso1Dof | Seeded[Siso1Dof]


def _freqs(peaks: list[Peak]) -> str:
    return ", ".join(f"{p.frequency:.2f}" for p in sorted(peaks, key=lambda p: p.frequency)) or "none"


def _oscillatory(model) -> tuple[float, float]:
    """Lowest-damped oscillatory mode (Hz, damping) of a model; nan if none.

    Oscillatory: ``0 < f < 0.8 x Nyquist`` and damping below 1 (real poles and poles at the Nyquist
    frequency are not modes)."""
    osc = oscillatory(model.modes(), model.sample_time)
    if not osc:
        return float("nan"), float("nan")
    m = min(osc, key=lambda m: m.damping)
    return float(m.frequency_hz), float(m.damping)


def _notch(f: np.ndarray, c: np.ndarray, band: tuple[float, float] = (0.1, 1.0)) -> float:
    keep = (f >= band[0]) & (f <= band[1])
    return float(f[keep][np.argmin(c[keep])])


def _main(r: Siso1Dof) -> float | str:
    """The identified mode under the highest PSD peak that shows a mode (Hz), or "none"."""
    return max(r.modes, key=lambda p: p.height).frequency if r.modes else "none"


def _further(r: Siso1Dof) -> str:
    """The identified model's other modes the PSD shows (Hz), or "none"."""
    main = _main(r)
    return _freqs([p for p in r.modes if p.frequency != main])


def _unconfirmed(r: Siso1Dof) -> str:
    return _freqs(other_peaks(r.peaks, r.modes, bin_1dof(r.estimation.sample_time)))


def _passed(t) -> str:
    return "pass" if t.passed else "fail"


def table_1dof(res: Mapping[str, World]) -> ComparisonTable:
    """The 1-DOF identification beside the thesis (modes, ARMAX model, residual tests, validation, coherence).

    Parameters
    ----------
    res : mapping
        ``{"linear": Siso1Dof, "twin": Siso1Dof or Seeded}``
        (:func:`~trms.experiments.ch3_identification.identify_1dof`).

    Returns
    -------
    ComparisonTable
        With a ``source`` column: the thesis's value printed, or derived from eq. (3.11).
    """
    lin = seeded(res["linear"]).first
    tw = seeded(res["twin"])
    twin = tw.first
    table = side_by_side(
        "Ch. 3, 1-DOF identification (u1 -> pitch, Ts = 0.2 s): modes, ARMAX model, validation",
        ["quantity"],
        sources=True,
    )
    n = len(tw.seeds)
    table.rows += _model_rows_1dof(lin, tw)
    table.rows += _validation_rows_1dof(lin, twin)
    note_far_cells(table, _far_note_1dof(lin, twin, tw.seeds[0]))
    table.notes.insert(
        0,
        f"Twin: at {n} seeds ({', '.join(str(s) for s in tw.seeds)}) the median (range) of every cell with a value to "
        f"judge, judged at each seed (within 30 % of the thesis's: agrees at every seed, differs at none, else "
        f"inconclusive); the fits and the coherence rows are seed {tw.seeds[0]}'s. Source: where the thesis column's "
        "value comes from."
        if n > 1
        else "Source: where the thesis column's value comes from.",
    )
    return table


def _model_rows_1dof(lin: Siso1Dof, tw: Seeded) -> list[list[object]]:
    """Table 3.1's 1-DOF rows of the modes, the ARMAX model and its residual tests: thesis, source, linear model,
    twin (over its seeds), note."""
    twin = tw.first

    def rows(label: str, thesis: object, source: str, read, note: str) -> list[object]:
        return [label, thesis, source, read(lin), tw.cell(read), note]

    return [
        rows(
            "pitch PSD main mode (Hz)",
            MAIN_MODE_HZ,
            PRINTED,
            _main,
            "the mode of the same run's ARMAX under the highest peak of the pitch PSD (within 10 % or the Welch "
            "window's main lobe, 2 bins); the linear model is eq. (3.11), whose only resonance is "
            f"{EQ_3_11_MODE[0]:g} Hz",
        ),
        rows(
            "pitch PSD further modes (Hz)",
            ", ".join(f"{f:g}" for f in PSD_MODES_1DOF if f != MAIN_MODE_HZ),
            PRINTED,
            _further,
            "further modes of the run's ARMAX the PSD shows; the peaks no mode accounts for are the input's spectrum "
            f"and the noise, not modes (seed {tw.seeds[0]}: linear model {_unconfirmed(lin)} Hz, twin "
            f"{_unconfirmed(twin)} Hz); the calibration report examines the thesis's side peaks",
        ),
        rows(
            "ARMAX oscillatory mode (Hz)",
            EQ_3_11_MODE[0],
            FROM_EQ_3_11,
            lambda r: finite_or(_oscillatory(r.model)[0], "none"),
            "the lightest-damped pole pair of each world's ARMAX",
        ),
        rows(
            "ARMAX mode damping ratio",
            EQ_3_11_MODE[1],
            FROM_EQ_3_11,
            lambda r: finite_or(_oscillatory(r.model)[1], "none"),
            "lightly damped in every world: the (almost) unstable oscillatory mode",
        ),
        rows(
            "ARMAX DC gain (rad/V)",
            EQ_3_11_DC_GAIN,
            FROM_EQ_3_11,
            lambda r: r.model.dc_gain(),
            "the linear column recovers eq. (3.11) (known truth)",
        ),
        rows(
            "ARMAX zeros outside the unit circle",
            int(np.sum(np.abs(eq_3_11().zeros()) > 1)),
            FROM_EQ_3_11,
            lambda r: int(np.sum(np.abs(r.model.zeros()) > 1)),
            "non-minimum phase when > 0 (eq. 3.12)",
        ),
        rows(
            "step response delay to 5 % (s)",
            "0.6-0.7",
            PRINTED,
            lambda r: step_delay(r.model),
            "thesis read it off the rig's step response (fig. 3.3); here from the identified model",
        ),
        rows(
            "residuals: whiteness phi_ee",
            "pass",
            PRINTED,
            lambda r: _passed(r.tests[0]),
            f"95 % joint test over 20 lags (seed {tw.seeds[0]}: linear model {correlation_verdict(lin.tests[0])}, "
            f"twin {correlation_verdict(twin.tests[0])}); encoder quantisation and the twin's unmodelled dynamics "
            "colour its residuals",
        ),
        rows(
            "residuals: independence phi_ue",
            "pass",
            PRINTED,
            lambda r: _passed(r.tests[1]),
            f"95 % joint test over lags -20..20 (seed {tw.seeds[0]}: linear model "
            f"{correlation_verdict(lin.tests[1])}, twin {correlation_verdict(twin.tests[1])})",
        ),
    ]


def _validation_rows_1dof(lin: Siso1Dof, twin: Siso1Dof) -> list[list[object]]:
    """Table 3.1's 1-DOF validation rows at the first seed: the free-run fits and the coherence."""
    out: list[list[object]] = []
    for name, note in (
        ("3211", "thesis: faster dynamics follow well, the slower dominant ones less so (fig. 3.10a)"),
        ("doublet", "fit = 100 (1 - |y - yhat| / |y - mean y|)"),
    ):
        if name in lin.fits and name in twin.fits:
            out.append([f"{name} free-run fit (%)", NOT_PRINTED, "-", lin.fits[name].fit, twin.fits[name].fit, note])
    for key, label in (("5 Hz", "poor (resolution bias)"), ("10 Hz", "improved, notch near 0.4 Hz")):
        if key in lin.coherence and key in twin.coherence:
            cl, ct = (mean_coherence(*r.coherence[key], (0.0, 1.0)) for r in (lin, twin))
            out.append(
                [
                    f"mean coherence 0-1 Hz at {key}",
                    label,
                    PRINTED,
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
        out.append(
            [
                "lowest coherence in 0.1-1 Hz at 10 Hz (Hz)",
                "about 0.4",
                PRINTED,
                _notch(f_lin, c_lin),
                _notch(*twin.coherence["10 Hz"]),
                why,
            ]
        )
    return out


def _far_note_1dof(lin: Siso1Dof, twin: Siso1Dof, seed: int):
    """The note of a twin or linear cell far from the thesis (the zeros' magnitudes for the zeros' row)."""

    def far(row: list, col: str, v: object, thesis: object) -> str:
        model = (lin if col == "linear model" else twin).model
        if row[0].startswith("ARMAX zeros"):
            mags = ", ".join(f"{abs(z):.2f}" for z in sorted(model.zeros(), key=abs))
            ref = ", ".join(f"{abs(z):.2f}" for z in sorted(eq_3_11().zeros(), key=abs))
            return (
                f"{format_cell(v)} vs {format_cell(thesis)}; not explained (zero magnitudes at seed {seed}: "
                f"identified {mags}; eq. (3.11) {ref})."
            )
        return f"{format_cell(v)} vs thesis {format_cell(thesis)}; not explained."

    return far


def _thesis_modes() -> dict[str, list[float]]:
    out: dict[str, list[float]] = {}
    for m in MODE_TABLE:
        if m.configuration == "2dof":
            out.setdefault(m.channel, []).append(m.frequency_hz)
    return out


#: The thesis's words on each 2-DOF channel's doublet fit.
_FIT_NOTES = {
    ("u1", "pitch"): "thesis: the model closely follows the plant (fig. 3.26)",
    ("u1", "yaw"): "thesis: not so good, nonlinearity suspected (fig. 3.27)",
    ("u2", "yaw"): "thesis: excellent (fig. 3.28)",
}
#: What a free-run fit below 0 % means, flagged wherever such a model is shown.
_NEGATIVE_FIT = (
    "fit below 0 %: the model's free run is further from the output than the output's mean; not a usable model"
)


def _others(r: Mimo2Dof, ch: tuple[str, str]) -> str:
    rec = r.experiments[ch[0]]
    return _freqs(other_peaks(r.peaks[ch], r.modes[ch], bin_2dof(len(rec), rec.sample_time)))


def _procedure_misses(lin: Mimo2Dof, ch: tuple[str, str], thesis: list[float]) -> str:
    """The thesis's modes that the linear model's own response shows in channel ``ch`` but that its ARMAX, identified
    by the same procedure as the twin's, has no lightly damped mode near (within 30 %), as a clause of the table's
    notes; empty when there are none. A mode missed there is the procedure's miss, not a world's."""
    model = lin.identification.channels[ch].model
    if model is None or not lin.response.get(ch):
        return ""
    found = identified_modes(model)

    def near(f: float, fs: list[float]) -> bool:
        return any(abs(x - f) <= TOLERANCE * f for x in fs)

    missed = [f for f in thesis if near(f, [p.frequency for p in lin.response[ch]]) and not near(f, found)]
    if not missed:
        return ""
    return (
        f" (the linear model misses {', '.join(f'{f:g}' for f in missed)} Hz too, though its own response peaks "
        "there: its ARMAX, identified by the same procedure on 600 samples, has no lightly damped mode there (its "
        f"modes: {', '.join(f'{m:.3f}' for m in found) or 'none'} Hz): the procedure misses it, not the twin)"
    )


def _coherence(r: Mimo2Dof, ch: tuple[str, str]) -> float:
    return r.identification.channels[ch].mean_coherence


def table_2dof(res: Mapping[str, Mimo2Dof | Seeded[Mimo2Dof]]) -> ComparisonTable:
    """Table 3.1 / 4.1 and ch. 3.5 (2-DOF): each channel's modes, coupling and doublet fit beside the thesis.

    Parameters
    ----------
    res : mapping
        ``{"linear": Mimo2Dof, "twin": Mimo2Dof or Seeded}``
        (:func:`~trms.experiments.ch3_identification.identify_2dof`).
    """
    table = side_by_side(
        "Table 3.1 / 4.1 and ch. 3.5, 2-DOF identification (Ts = 0.1 s): modes, coupling, doublet fit",
        ["channel", "quantity"],
    )
    lin = seeded(res["linear"]).first
    tw = seeded(res["twin"])
    twin = tw.first
    thesis_modes = _thesis_modes()
    out_index = {"pitch": "y1", "yaw": "y2"}
    why: dict[tuple[str, str], str] = {}
    for name_in, name_out in lin.identification.channels:
        ch = (name_in, name_out)
        key = f"{name_in}->{out_index.get(name_out, name_out)}"
        thesis = thesis_modes.get(key)
        printed = ", ".join(f"{f:g}" for f in thesis) if thesis else "no coupling"
        why[(key, "PSD modes (Hz)")] = _procedure_misses(lin, ch, thesis or [])

        def modes(r: Mimo2Dof, ch: tuple[str, str] = ch) -> str:
            return _freqs(r.modes[ch]) if r.identification.channels[ch].model is not None else "not modelled"

        table.rows.append(
            [
                key,
                "PSD modes (Hz)",
                printed,
                modes(lin),
                tw.cell(modes),
                "the modes of the channel's identified ARMAX its output's PSD shows in 0.03-1 Hz (excited input's "
                f"run); the PSD peaks no mode accounts for at seed {tw.seeds[0]} (the input's spectrum and the noise): "
                f"linear model {_others(lin, ch)}, twin {_others(twin, ch)} Hz",
            ]
        )
        if ch in lin.response and ch in twin.response:
            table.rows.append(
                [
                    key,
                    "response peaks of the linear model (Hz)",
                    printed,
                    _freqs(lin.response[ch]),
                    _freqs(twin.response[ch]),
                    "peaks of the channel's frequency response: the linear model's (the twin's linearisation at "
                    "hover, as the twin's column): the modes one twin has in this channel, with no estimator between",
                ]
            )
        table.rows.append(
            [
                key,
                "mean coherence 0-1 Hz",
                "high" if thesis else "low",
                lin.identification.channels[ch].mean_coherence,
                tw.cell(partial(_coherence, ch=ch)),
                "coupled (ARMAX fitted) when >= 0.5, as fig. 3.14 decides",
            ]
        )
        table.rows.append(
            [
                key,
                "doublet free-run fit (%)",
                NOT_PRINTED if thesis else "not modelled",
                *(finite_or(r.fits[ch].fit) if ch in r.fits else "not modelled" for r in (lin, twin)),
                _FIT_NOTES.get(ch, "uncoupled: no model, as in the thesis")
                + "".join(
                    f"; {w}: {_NEGATIVE_FIT}"
                    for w, r in (("linear", lin), ("twin", twin))
                    if ch in r.fits and r.fits[ch].fit < 0
                ),
            ]
        )
    marks = [
        f"{row[0]} {row[1]}: {judged}{why.get((str(row[0]), str(row[1])), '')}"
        for row in table.rows
        if row[1] != "mean coherence 0-1 Hz"
        for judged in [seed_verdict(row[2], row[4])]
        if judged not in (None, AGREES)
    ]
    table.notes = [
        f"Modes in the thesis's column: Table 3.1 (printed). Twin: at {len(tw.seeds)} seed(s) "
        f"({', '.join(str(s) for s in tw.seeds)}) for the modes and the coherence, each seed judged; the fits are "
        f"seed {tw.seeds[0]}'s. A mode is the identified model's (a lightly damped one, damping below 0.5), named "
        "where the output's PSD peaks within 10 % or 2 Welch bins of it; no PSD peak alone is named a mode."
    ]
    if marks:
        table.notes.append("Not agreeing at every seed: " + "; ".join(marks) + ".")
    return table


def _unusable(fit: float) -> str:
    return ": not a usable model" if fit < 0 else ""  # said in the figure too, not only in its caption


def _fit_caption(fit: float) -> str:
    return f" (fit {fit:.0f} %: below 0 %, {_NEGATIVE_FIT.split(': ', 1)[1]})" if fit < 0 else f" (fit {fit:.0f} %)"


def _on_curve(f: np.ndarray, p: np.ndarray, peaks: list[Peak]) -> list[Peak]:
    """Each peak placed on the drawn curve (its height read off the spectrum at its frequency)."""
    return [Peak(pk.frequency, float(np.interp(pk.frequency, f, p))) for pk in peaks]


def section_3(
    res1: Mapping[str, World],
    res2: Mapping[str, Mimo2Dof | Seeded[Mimo2Dof]],
    folder: str | os.PathLike[str],
) -> Section:
    """The chapter 3 section: tables beside the thesis and figures (3.2, 3.5, 3.10-3.12, 3.14, 3.16, 3.26-3.28)."""
    folder = Path(folder)
    first1 = {w: seeded(r).first for w, r in res1.items()}
    first2 = {w: seeded(r).first for w, r in res2.items()}
    figs = []
    spectra = {f"{w} (pitch)": r.spectra["plant"] for w, r in first1.items()}
    figs.append(
        FigureRef(
            save_figure(
                plot_spectra(
                    spectra,
                    "1-DOF pitch PSD, 5 Hz PRBS (fig. 3.2b)",
                    PSD_MODES_1DOF,
                    {f"{w} (pitch)": _on_curve(*r.spectra["plant"], r.modes) for w, r in first1.items()},
                ),
                folder / "ch3_1dof_psd.png",
            ),
            "1-DOF pitch PSD under the 5 Hz PRBS, linear model and twin; thesis modes dashed, dots at the modes of "
            "the run's identified ARMAX the spectrum shows.",
        )
    )
    coh = {f"{w}, {k}": fc for w, r in first1.items() for k, fc in r.coherence.items()}
    figs.append(
        FigureRef(
            save_figure(
                plot_coherence(coh, "1-DOF coherence u1 -> pitch (fig. 3.5)", (0.4,)), folder / "ch3_1dof_coherence.png"
            ),
            "Coherence of the 1-DOF PRBS run at 5 Hz and 10 Hz sampling (the thesis's notch near 0.4 Hz dashed).",
        )
    )
    twin1 = first1["twin"]
    figs.append(
        FigureRef(
            save_figure(
                plot_correlation_tests(twin1.tests, "Twin 1-DOF ARMAX residual tests (fig. 3.11)"),
                folder / "ch3_1dof_residuals_twin.png",
            ),
            "Residual auto-correlation and input cross-correlation of the twin's 1-DOF ARMAX, 95 % bands.",
        )
    )
    for name in twin1.fits:
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
    for w, r in first2.items():
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
    twin2 = first2["twin"]
    spectra2, marks2 = {}, {}
    for a, b in twin2.peaks:
        rec = twin2.experiments[a]
        _, dy = rec.deviations()
        y = dy[:, rec.output_names.index(b)]
        f, p = psd(y - y.mean(), rec.sample_time)
        spectra2[f"{a} -> {b}"] = (f, p)
        marks2[f"{a} -> {b}"] = _on_curve(f, p, twin2.modes[(a, b)])
    figs.append(
        FigureRef(
            save_figure(
                plot_spectra(spectra2, "Twin 2-DOF output PSDs (figs. 3.16, 3.18)", TABLE_3_1_MODES_HZ, marks2),
                folder / "ch3_2dof_psd_twin.png",
            ),
            "PSD of each output of the twin under a PRBS on one input; thesis modes 0.1 and 0.34 Hz dashed, dots at "
            "the modes of the channel's identified ARMAX its output's PSD shows (its lightly damped modes: "
            + "; ".join(
                f"{a} -> {b} " + (", ".join(f"{m:.3f}" for m in identified_modes(ch.model, MODE_BAND)) or "none")
                for (a, b), ch in twin2.identification.channels.items()
                if ch.model is not None
            )
            + " Hz).",
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
    return Section("Chapter 3: linear identification", paragraphs, [table_1dof(res1), table_2dof(res2)], figs)
