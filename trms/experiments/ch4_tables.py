"""Chapter 4 presented: Tables 4.2 and 4.3 beside the thesis, with computed notes, and the chapter's figures.

The twin's cells are its attenuations at every seed of the run (:class:`~trms.present.seeds.Seeded`), judged over
them (:func:`~trms.present.seeds.verdict`). A cell that differs from the thesis at every seed gets a note computed in
the same run, each explanation with its own check:

* **the filter's gain bound** -- the thesis's attenuation exceeds the filter's own attenuation at the mode
  (:meth:`~trms.control.shaping.CommandFilter.gain_db`) by more than the Welch estimate's 1 dB leakage, and the
  linear model's cell (a plant without ambient motion) stays within that bound: no plant shaped by this filter
  attenuates as much, so the thesis's filter differed;
* **the rig's ambient floor** -- the thesis's value lies between (or within 30 % of) the twin's cell at its
  calibrated ambient excitation and at the most its calibration allows
  (:func:`~trms.experiments.ch4_shaping.ambient_floors`), and the hover pitch RMS there lies within the calibrated
  range (:func:`~trms.experiments.ch4_shaping.hover_pitch_rms`);
* otherwise the note says "not explained", with those measurements.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

from trms.experiments.ch4_shaping import (
    DOUBLET_AMPLITUDE,
    DOUBLET_PULSE_WIDTH,
    DOUBLET_START,
    MODES,
    PSD_SEGMENT,
    PSD_SEGMENT_2DOF,
    RECORD_LENGTH,
    RECORD_LENGTH_2DOF,
    RESIDUAL_FROM,
    Floor,
    Shaping,
    filters_2dof,
    response,
    shaping_filters,
)
from trms.identification.spectral import psd
from trms.present.figures import plot_series, plot_spectra, save_figure
from trms.present.sections import FigureRef, Section
from trms.present.seeds import AGREES, DIFFERS, Seeded, agreeing, seeded, verdict
from trms.present.tables import EXPLAIN_ABOVE, ComparisonTable, relative_difference, side_by_side
from trms.reference import (
    FILTER_2_BANDS,
    HOVER_PITCH_RMS,
    SAMPLE_TIME_1DOF,
    SAMPLE_TIME_2DOF,
    TABLE_3_1_MODES_HZ,
    TABLE_4_2,
    TABLE_4_2_FILTERS,
    TABLE_4_3,
    VOLTAGE_LIMIT,
)

__all__ = ["explain", "table_4_2", "table_4_3", "section_4"]

World = Shaping | Seeded[Shaping]
#: The Welch estimate's leakage bias (dB) a linear plant's attenuation may exceed the filter's own by.
LEAKAGE_DB = 1.0


def explain(
    where: str,
    cell: object,
    printed: float,
    gain: float,
    linear: float,
    own: float,
    floor: tuple[float, float, float, float] | None,
) -> str | None:
    """The note of one attenuation cell that does not agree with the thesis at every seed (``None`` when it does).

    Parameters
    ----------
    where : str
        The cell, for the note ("LPF 0.1 Hz at 0.34 Hz, twin").
    cell : float or OverSeeds
        The cell (dB), at one seed or at each.
    printed : float
        The thesis's value (dB).
    gain : float
        The filter's own attenuation at the mode (dB).
    linear : float
        The linear model's cell at the run's seed (dB): the bound's check.
    own : float
        The twin's cell at the run's seed, at its calibrated ambient excitation (dB).
    floor : tuple, optional
        ``(scale, hover RMS there (rad), the twin's cell there (dB), hover RMS at the calibrated level (rad))`` from
        :func:`~trms.experiments.ch4_shaping.ambient_floors`; ``None`` when not measured.

    Returns
    -------
    str or None
        Ending "explained by ..." (its measurement and the function that computed it named) only when the
        explanation's own check passes; else with "not explained" or "inconclusive at N seeds".

    Examples
    --------
    >>> explain("LPF at 0.34 Hz, twin", 30.0, 7.0, 35.0, 31.0, 30.0, (1.3, 0.006, 29.0, 0.0046))[-62:]
    'hover_pitch_rms; the filter itself attenuates 35.0 dB there)).'
    >>> note = explain("F at 0.1 Hz, twin", 10.0, 20.0, 12.0, 11.5, 10.0, None)
    >>> note.endswith("explained by the filter's gain bound.")
    True
    """
    judged = verdict(printed, cell)
    if judged == AGREES:
        return None
    head = f"{where}: {cell:.3g} dB" if isinstance(cell, float) else f"{where}: {cell} dB"
    head += f" vs thesis {printed:g} dB"
    if judged != DIFFERS:
        k, n = agreeing(printed, cell)
        return f"{head}: within {EXPLAIN_ABOVE:.0%} at {k} of {n} seeds: {judged}."
    if printed > gain + LEAKAGE_DB:
        if linear <= gain + LEAKAGE_DB:
            return (
                f"{head}; the filter's own attenuation at the mode is {gain:.1f} dB (CommandFilter.gain_db), "
                f"{printed - gain:.1f} dB less than the thesis's, and the linear model, without ambient motion, reads "
                f"{linear:.3g} dB, within the bound: no plant shaped by this filter attenuates as much, so the "
                "thesis's filter differed (its ripple and stop band are not printed): explained by the filter's gain "
                "bound."
            )
        return (
            f"{head}; not explained (the filter's own attenuation there is {gain:.1f} dB, below the thesis's, but the "
            f"linear model reads {linear:.3g} dB, beyond that bound by more than the {LEAKAGE_DB:g} dB leakage)."
        )
    if floor is None:
        return f"{head}; not explained (the filter's own attenuation there is {gain:.1f} dB; no ambient floor here)."
    scale, rms, value, rms_own = floor
    lo, hi = HOVER_PITCH_RMS
    levels = {1.0: own, scale: value}
    ends = sorted(levels.values())
    reached = ends[0] <= printed <= ends[1] or any(relative_difference(v, printed) <= EXPLAIN_ABOVE for v in ends)
    measured = (
        f"at its calibrated ambient excitation (hover pitch RMS {1e3 * rms_own:.2g} mrad) the twin reads {own:.3g} dB, "
        f"at x{scale:.2g} of it (hover pitch RMS {1e3 * rms:.2g} mrad, the calibrated range's top "
        f"{1e3 * hi:.2g} mrad) {value:.3g} dB (ambient_floors, hover_pitch_rms; the filter itself attenuates "
        f"{gain:.1f} dB there)"
    )
    if reached and lo <= rms <= hi:
        return f"{head}; {measured}: explained by the rig's ambient floor, within the calibrated range."
    if reached:
        return f"{head}; not explained: {measured}, but that hover RMS is outside the calibrated {lo:g}-{hi:g} rad."
    return f"{head}; not explained: no ambient floor the calibration allows accounts for it ({measured})."


def _floor(floor: Floor | None, shaping: Shaping | None, key: tuple) -> tuple[float, float, float, float] | None:
    if floor is None or shaping is None:
        return None
    return floor.scale, floor.hover_rms[floor.scale], shaping.attenuation[key], floor.hover_rms[1.0]


def _judged(
    key: tuple,
    where: str,
    printed: float,
    gain: float,
    lin: Shaping,
    tw: Seeded[Shaping],
    floor: tuple[float, float, float, float] | None,
    flagged: list[str],
) -> tuple[list[object], str]:
    """One attenuation row's cells (the linear model's, the twin's over its seeds) and the notes it cites, the notes
    appended to ``flagged`` (the ambient floor is the twin's only)."""
    cells = [lin.attenuation[key], tw.cell(lambda r: r.attenuation[key])]
    own = tw.first.attenuation[key]
    marks = []
    for world, cell in zip(("linear model", "twin"), cells):
        note = explain(
            f"{where}, {world}", cell, printed, gain, lin.attenuation[key], own, floor if world == "twin" else None
        )
        if note:
            flagged.append(note)
            marks.append(f"note {len(flagged)}")
    return cells, ", ".join(marks)


def _seeds_note(tw: Seeded[Shaping]) -> str:
    n = len(tw.seeds)
    return (
        f"Twin: the median (range) over {n} seeds ({', '.join(str(s) for s in tw.seeds)}), each seed judged "
        "(within 30 % of the thesis's: agrees at every seed, differs at none, else inconclusive)."
        if n > 1
        else ""
    )


def table_4_2(res: Mapping[str, World], floor: Floor | None = None) -> ComparisonTable:
    """Table 4.2 (1-DOF) on both worlds beside the thesis, with computed notes (module docstring).

    Parameters
    ----------
    res : mapping
        ``{"linear": Shaping, "twin": Shaping or Seeded}`` from :func:`~trms.experiments.ch4_shaping.shaping_1dof`.
    floor : Floor, optional
        :func:`~trms.experiments.ch4_shaping.ambient_floors` on the twin at the run's seed.

    Returns
    -------
    ComparisonTable
        One row per (command, mode); the ZV/ZVD rows and the residual-vibration rows follow.

    Examples
    --------
    >>> from trms.experiments.ch4_shaping import shaping_1dof
    >>> from trms.worlds import make_plant
    >>> from trms.reference import eq_3_11
    >>> lin = shaping_1dof(make_plant("linear", "1dof"), eq_3_11())
    >>> table_4_2({"linear": lin, "twin": lin}).rows[0][:3]
    ['LPF 0.1 Hz', 0.25, 5.83]
    """
    lin, tw = seeded(res["linear"]).first, seeded(res["twin"])
    twin = tw.first
    filters = shaping_filters(SAMPLE_TIME_1DOF)
    table = side_by_side(
        "Table 4.2 (1-DOF): attenuation of the pitch PSD at each mode, shaped vs unshaped doublet (dB)",
        ["command", "mode (Hz)"],
    )
    flagged: list[str] = []
    shaping = floor.shaping_1dof if floor is not None else None
    for (name, mode), printed in TABLE_4_2.items():
        key = (name, mode)
        gain = -float(filters[name].gain_db([mode])[0])
        cells, marks = _judged(
            key, f"{name} at {mode:g} Hz", printed, gain, lin, tw, _floor(floor, shaping, key), flagged
        )
        table.rows.append([name, mode, printed, *cells, marks])
    for name in ("ZV", "ZVD"):
        for mode in MODES:
            if (name, mode) in lin.attenuation and (name, mode) in twin.attenuation:
                table.rows.append(
                    [f"{name} shaper", mode, "-", lin.attenuation[(name, mode)], twin.attenuation[(name, mode)], ""]
                )
    for name in lin.residual_db:
        if name in twin.residual_db:
            table.rows.append(
                [
                    name,
                    f"residual RMS after {RESIDUAL_FROM:g} s",
                    "-",
                    lin.residual_db[name],
                    twin.residual_db[name],
                    "",
                ]
            )
    modes = {
        w: ", ".join(f"{f:.3f} Hz (zeta {z:.3f})" for f, z in r.shaper_modes) or "none"
        for w, r in (("linear", lin), ("twin", twin))
    }
    off_mode = [
        f"{m:g} Hz" for m in MODES if not any(abs(f - m) <= 0.1 * m for r in (lin, twin) for f, _ in r.shaper_modes)
    ]
    table.notes = [
        f"Doublet {DOUBLET_AMPLITUDE:g} V, pulse {DOUBLET_PULSE_WIDTH:g} s, first edge {DOUBLET_START:g} s, "
        f"{RECORD_LENGTH:g} s at 0.2 s; Welch PSD, {PSD_SEGMENT}-sample Hann segments; attenuation read at the "
        "thesis's mode frequencies (thesis column: printed). '-': not in the thesis. ZV/ZVD shapers (designed from "
        f"each world's identified ARMAX modes at seed {tw.seeds[0]}: linear model {modes['linear']}; twin "
        f"{modes['twin']}); residual rows: reduction of the leftover vibration, dB (positive = less). "
        + _seeds_note(tw),
    ]
    if off_mode:
        table.notes.append(
            f"At {', '.join(off_mode)} neither world's identified ARMAX has a mode (its modes above): those rows read "
            "the attenuation off a frequency where the world has no mode, a measure of the filter and the noise, not "
            "of a vibration."
        )
    table.notes += [f"note {i + 1}: {n}" for i, n in enumerate(flagged)]
    return table


def table_4_3(res: Mapping[str, World], floor: Floor | None = None) -> ComparisonTable:
    """Table 4.3 (2-DOF) on both worlds beside the thesis, with computed notes (see :func:`table_4_2`).

    Parameters
    ----------
    res : mapping
        ``{"linear": Shaping, "twin": Shaping or Seeded}`` from :func:`~trms.experiments.ch4_shaping.shaping_2dof`.
    floor : Floor, optional
        :func:`~trms.experiments.ch4_shaping.ambient_floors` (its 2-DOF doublets) on the twin at the run's seed.
    """
    lin, tw = seeded(res["linear"]).first, seeded(res["twin"])
    table = side_by_side(
        "Table 4.3 (2-DOF): attenuation of the output PSD at each mode, shaped vs unshaped doublet (dB)",
        ["channel", "mode (Hz)", "filter"],
    )
    filters = filters_2dof(SAMPLE_TIME_2DOF)
    flagged: list[str] = []
    shaping = floor.shaping_2dof if floor is not None else None
    for (ch, mode, fname), printed in TABLE_4_3.items():
        key = (ch, mode, fname)
        gain = -float(filters[fname].gain_db([mode])[0])
        where = f"{ch} at {mode:g} Hz, {fname}"
        cells, marks = _judged(key, where, printed, gain, lin, tw, _floor(floor, shaping, key), flagged)
        table.rows.append([ch, mode, fname, printed, *cells, marks])
    table_band, text_band = FILTER_2_BANDS["table"], FILTER_2_BANDS["text"]
    table.notes = [
        f"Doublet {DOUBLET_AMPLITUDE:g} V, pulse {DOUBLET_PULSE_WIDTH:g} s on one input (the other at trim), "
        f"{RECORD_LENGTH_2DOF:g} s at 0.1 s; Welch PSD, {PSD_SEGMENT_2DOF}-sample segments; thesis column: printed. "
        "Elliptic band-stops order 2 with 1 dB ripple and 40 dB stop band (not printed in the thesis). Filter-2's "
        f"first band: the thesis prints it twice, {table_band[0]:g}-{table_band[1]:g} Hz in the table's header and "
        f"{text_band[0]:g}-{text_band[1]:g} Hz in its text; the text's is used. The linear model of the 2-DOF rig is "
        "the twin's linearisation at hover. " + _seeds_note(tw)
    ]
    table.notes += [f"note {i + 1}: {n}" for i, n in enumerate(flagged)]
    return table


def section_4(
    res1: Mapping[str, World],
    res2: Mapping[str, World],
    folder: str | os.PathLike[str],
    floor: Floor | None = None,
) -> Section:
    """The chapter 4 section: Tables 4.2 and 4.3 side by side, with the twin's responses (figs. 4.4-4.15)."""
    folder = Path(folder)
    figs = []
    twin1, twin2 = seeded(res1["twin"]).first, seeded(res2["twin"]).first
    runs = twin1.runs["u1"]
    t = runs["unshaped"].time
    trim_volts = float(runs["unshaped"].operating_point.inputs[0])
    series = {name: response(rec, "pitch") for name, rec in runs.items()}
    figs.append(
        FigureRef(
            save_figure(
                plot_series(
                    t,
                    series,
                    "Twin 1-DOF pitch under shaped doublets (figs. 4.4, 4.6)",
                    "pitch (rad, deviation)",
                    {name: rec.deviations()[0][:, 0] for name, rec in runs.items()},
                    limits=(-VOLTAGE_LIMIT - trim_volts, VOLTAGE_LIMIT - trim_volts),
                ),
                folder / "ch4_1dof_twin.png",
            ),
            "Twin pitch under the unshaped doublet and under each shaped one (LPF, BSF, ZV, ZVD).",
        )
    )
    spectra = {name: psd(y, SAMPLE_TIME_1DOF, PSD_SEGMENT) for name, y in series.items()}
    figs.append(
        FigureRef(
            save_figure(
                plot_spectra(spectra, "Twin 1-DOF pitch PSD by command", MODES), folder / "ch4_1dof_psd_twin.png"
            ),
            "PSD of the twin's pitch under each command; the thesis's modes dashed.",
        )
    )
    for name_in, name_out in (("u1", "pitch"), ("u1", "yaw"), ("u2", "yaw")):
        r = twin2.runs[name_in]
        spectra = {name: psd(response(rec, name_out), SAMPLE_TIME_2DOF, PSD_SEGMENT_2DOF) for name, rec in r.items()}
        figs.append(
            FigureRef(
                save_figure(
                    plot_spectra(
                        spectra,
                        f"Twin 2-DOF {name_in} -> {name_out} PSD by command (figs. 4.9-4.15)",
                        TABLE_3_1_MODES_HZ,
                    ),
                    folder / f"ch4_2dof_{name_in}_{name_out}_twin.png",
                ),
                f"PSD of the twin's {name_out} under a doublet on {name_in}, unshaped and shaped.",
            )
        )
    paragraphs = [
        "A doublet on the main rotor (and, 2-DOF, on each rotor in turn) is run unshaped and shaped; the "
        "attenuation is the drop of the output PSD at each mode. ZV and ZVD input shapers (Singer and Seering), "
        "designed from the modes of the ARMAX identified in ch. 3 on the same world, run on the same doublet.",
    ]
    tables = [table_4_2(res1, floor), table_4_3(res2, floor)]
    conclusion = []
    for table in tables:
        notes = [n for n in table.notes if n.startswith("note ")]
        conclusion.append(
            f"{table.title.split(':')[0]}, its {len(notes)} notes: "
            f"{sum('explained by the filter' in n for n in notes)} explained by the filter's own gain, "
            f"{sum('explained by the rig' in n for n in notes)} by an ambient floor within the calibrated range, "
            f"{sum('not explained' in n for n in notes)} not explained, "
            f"{sum('inconclusive at' in n for n in notes)} inconclusive over the seeds."
        )
    lpf, bsf = list(TABLE_4_2_FILTERS)
    twin_all = seeded(res1["twin"]).results
    ranked = [all(r.attenuation[(lpf, m)] > r.attenuation[(bsf, m)] for m in MODES) for r in twin_all]
    conclusion.append(
        "The thesis's ranking (the LPF attenuates more than the BSF at both modes) holds on the twin at "
        f"{sum(ranked)} of {len(ranked)} seeds."
    )
    if floor is not None:
        conclusion.append(
            f"The ambient floor the notes test: the twin at x{floor.scale:.2g} its calibrated ambient excitation, "
            "hover "
            f"pitch RMS {1e3 * floor.hover_rms[floor.scale]:.2g} mrad (at x1 {1e3 * floor.hover_rms[1.0]:.2g} mrad; "
            f"the calibrated range {1e3 * HOVER_PITCH_RMS[0]:g}-{1e3 * HOVER_PITCH_RMS[1]:g} mrad)."
        )
    return Section("Chapter 4: open-loop command shaping", paragraphs, tables, figs, conclusion=conclusion)
