"""Run every experiment of the thesis on the linear model and on the twin, and write the report.

:func:`reproduce` writes a self-contained folder:

* ``report.md`` and ``report.html``: every thesis table with the columns thesis, linear model,
  twin and notes; the headline table first; the twin at a glance (hover trim, modes, parameters);
  the run's wall time;
* ``figures/``: PNG figures (responses, PSDs with modes marked, coherence, residual tests) and a
  GIF render of the twin during a CSAS manoeuvre;
* ``tables.json``: every table as data, for machine checks.

Each world's identification chapters (3-5), its control chapters (6-8) and the robustness batch
are independent jobs and run in a pool of ``workers`` processes; the figures and documents are then
written in this process. ``quick`` shortens the run (fewer LQG weights, a smaller Monte Carlo batch, one
level of the twin's ambient excitation in the ch. 4 notes, Table 6.1's control at the thesis's estimator
only, a coarser GIF) without leaving any table out.
"""

from __future__ import annotations

import contextlib
import html
import json
import multiprocessing
import os
import re
import signal
import time
from collections.abc import Callable, Iterator, Mapping
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from trms.errors import InputError, check_in_range
from trms.experiments import ch3_identification as ch3
from trms.experiments import ch4_shaping as ch4
from trms.experiments import ch5_narx as ch5
from trms.experiments import ch7_side_mode as side_mode
from trms.experiments import ch8_mimo_lqg as ch8
from trms.experiments import ch67_lqg as runs67
from trms.experiments import ch67_tables as ch67
from trms.experiments import robustness
from trms.files import atomic_write
from trms.present.figures import save_figure
from trms.present.sections import FigureRef, Section
from trms.present.tables import EXPLAIN_ABOVE, ComparisonTable, inline_html, relative_difference, side_by_side
from trms.reference import LQG_WEIGHTS_R, PUSH_WEIGHTS_R, TABLE_5_1, TABLE_6_1
from trms.worlds import GUST, NOISE_STD, WORLDS, design_model, make_plant

__all__ = ["Settings", "Report", "PARTS", "reproduce", "world_results", "headline", "numeric_verdict", "reader_summary"]


@dataclass(frozen=True)
class Settings:
    """What a run does.

    Attributes
    ----------
    quick : bool
        Reduced run (see the module docstring).
    seed : int
        Seed of every excitation, noise, gust and parameter draw.
    """

    quick: bool = False
    seed: int = 0

    @property
    def weights(self) -> tuple[float, ...]:
        """LQG weights R of chapters 6/7."""
        return (75.0, 1.0, 125.0) if self.quick else LQG_WEIGHTS_R

    @property
    def samples(self) -> int:
        """Monte Carlo batch size."""
        return 4 if self.quick else 24

    @property
    def robustness_parts(self) -> int:
        """Jobs the Monte Carlo batch is split into (so that the worker processes finish together)."""
        return 1 if self.quick else 2

    @property
    def ambient_scales(self) -> tuple[float, ...]:
        """Multiples of the twin's ambient excitation the ch. 4 notes rerun the shaped doublets under."""
        return (16.0, 64.0) if self.quick else ch4.AMBIENT_SCALES

    @property
    def estimator_speeds(self) -> tuple[float, ...]:
        """Estimator speeds beside the thesis's under which Table 6.1's control is re-measured."""
        return () if self.quick else runs67.ESTIMATOR_SPEEDS

    @property
    def gif_every(self) -> int:
        """Render every n-th sample of the CSAS run into the GIF."""
        return 5 if self.quick else 2


@dataclass
class Report:
    """What :func:`reproduce` wrote and found.

    Attributes
    ----------
    folder : pathlib.Path
    sections : list of Section
    headline : ComparisonTable
    seconds : float
        Wall time of the whole run (s).
    files : dict of str to pathlib.Path
        ``markdown``, ``html``, ``json``, ``gif``.
    """

    folder: Path
    sections: list[Section]
    headline: ComparisonTable
    seconds: float
    files: dict[str, Path] = field(default_factory=dict)

    def tables(self) -> list[ComparisonTable]:
        """The headline table and every section's tables."""
        return [self.headline] + [t for s in self.sections for t in s.tables]

    def statuses(self) -> dict[str, int]:
        """How many computed cells hold each named run status (:data:`trms.experiments.ch67_lqg.STATUSES`)."""
        from trms.experiments.ch67_lqg import STATUSES

        cells = [c for t in self.tables() for c in t.computed_cells()]
        return {s: sum(1 for c in cells if c == s) for s in STATUSES}

    def missing(self) -> list[str]:
        """Computed cells that are empty or not finite, across every table."""
        return [f"{t.title}: {m}" for t in self.tables() for m in t.missing()]


# ----------------------------------------------------------------------------------- the runs
#: The two parts of a world's chain, each run as one job.
PARTS = ("identification", "control")


def world_results(world: str, settings: Settings, part: str = "all") -> dict[str, Any]:
    """One world's experiments (runs in a worker process).

    Parameters
    ----------
    world : {"linear", "twin"}
    settings : Settings
    part : {"identification", "control", "all"}
        Chapters 3-5, chapters 6-8, or both.
    """
    seed = settings.seed
    twin = world == "twin"
    started = time.perf_counter()
    out: dict[str, Any] = {}
    if part in ("identification", "all"):
        out["ch3_1dof"] = ch3.identify_1dof(
            make_plant(world, "1dof", seed=seed), make_plant(world, "1dof", 0.1, seed=seed), seed
        )
        out["ch3_2dof"] = ch3.identify_2dof(make_plant(world, "2dof", seed=seed), seed)
        out["ch4_1dof"] = ch4.shaping_1dof(make_plant(world, "1dof", seed=seed), out["ch3_1dof"].model.to_tf(), seed)
        out["ch4_2dof"] = ch4.shaping_2dof(make_plant(world, "2dof", seed=seed), seed)
        if twin:  # the ambient floors the ch. 4 notes compare: the twin under its own ambient excitation, scaled
            out["ch4_floors"] = (
                {
                    k: ch4.shaping_1dof(ch4.ambient_twin("1dof", k, seed), out["ch3_1dof"].model.to_tf(), seed)
                    for k in settings.ambient_scales
                },
                {}
                if settings.quick
                else {k: ch4.shaping_2dof(ch4.ambient_twin("2dof", k, seed), seed) for k in settings.ambient_scales},
            )
        out["ch5"] = ch5.narx_1dof(make_plant(world, "1dof", seed=seed), seed)
        out["ch5_yaw"] = ch5.narx_yaw(make_plant(world, "2dof", seed=seed), seed)
    if part in ("control", "all"):
        model_1dof = design_model("1dof")
        out["ch67"] = runs67.lqg_cases(make_plant(world, "1dof", seed=seed), model_1dof, settings.weights, seed=seed)
        loop_plant, out["margin_model"] = model_1dof, "eq. (3.11)"
        if twin:
            out["push"] = runs67.push_rejection(
                lambda p: make_plant("twin", "1dof", pushes=p, seed=seed),
                model_1dof,
                PUSH_WEIGHTS_R,
                seed=seed,
            )
            from trms.twin import Twin

            loop_plant, out["margin_model"] = (
                Twin("1dof", model_1dof.dt).linearise().discrete,
                "its linearisation at hover",
            )
        out["margins"] = {float(r): runs67.loop_margins(loop_plant, model_1dof, r) for r in settings.weights}
        # Table 6.1's control under a slower and a faster estimator (its rows only).
        rows_6_1 = sorted({r for r, _ in TABLE_6_1}, reverse=True)
        out["estimators"] = {
            k: runs67.lqg_cases(
                make_plant(world, "1dof", seed=seed),
                model_1dof,
                rows_6_1,
                sorted({c for _, c in TABLE_6_1}),
                seed=seed,
                estimator=k,
            )
            for k in settings.estimator_speeds
        }
        if twin:  # the low-pass finding under the alternative the thesis names (a 0.25 Hz mode)
            rig = [r for r in PUSH_WEIGHTS_R if r in settings.weights]
            out["side_mode"] = side_mode.prefilter_evidence(model_1dof, rig, seed)
        out["ch8"] = ch8.autopilot_runs(make_plant(world, "2dof", seed=seed), design_model("2dof"), seed)
        if twin:  # the choice of R: the scan's margins on the twin's linearisation, and its runs on the twin
            from trms.twin import Twin

            out["ch8_margins"] = list(ch8.shipped_margin_scan(0.1))
            out["ch8_scan"] = ch8.scan_runs(make_plant(world, "2dof", seed=seed), design_model("2dof"), seed=seed)
    out["seconds"] = time.perf_counter() - started
    return out


def _robustness(settings: Settings, part: int) -> dict[str, Any]:
    """Part ``part`` of the Monte Carlo batch (its rows; the first part also the nominal loops), one job."""
    started = time.perf_counter()
    indices = list(range(settings.samples))[part :: settings.robustness_parts]
    return {
        "rows": robustness.run_samples(indices, settings.seed, robustness.SPREAD, "cpu"),
        "nominal": robustness.nominal("linear", settings.seed) if part == 0 else None,
        "seconds": time.perf_counter() - started,
    }


def _merge_robustness(parts: list[dict[str, Any]]) -> dict[str, Any]:
    """The parts of :func:`_robustness` as one batch, as :func:`~trms.experiments.robustness.monte_carlo` gives it
    (any split of the samples gives the same bits)."""
    return {
        "batch": robustness.samples_of([row for p in parts for row in p["rows"]]),
        "nominal": parts[0]["nominal"],
        "seconds": sum(p["seconds"] for p in parts),
    }


# ----------------------------------------------------------------------------------- the report
def _first_cell_ends_with(suffix: str) -> Callable[[list], bool]:
    """A row matcher: the row's first cell ends with ``suffix``."""
    return lambda r: str(r[0]).endswith(suffix)


def _cell(table: ComparisonTable, match: Callable[[list], bool], column: str) -> object:
    for row in table.rows:
        if match(row):
            return row[table.columns.index(column)]
    raise InputError(f"no row of {table.title!r} matches")


def headline(sections: Mapping[str, Section], calibration: Any = None) -> ComparisonTable:
    """The headline comparison, one row per chapter's key figure, read from the section tables.

    ``calibration`` (the shipped model's :class:`~trms.calibration.Verification`) adds, beside the
    twin's ARMAX DC gain, the same figure over the calibration's unseen seeds (the same protocol).
    """
    t = side_by_side("Headline: the thesis, the linear model and the twin", ["chapter", "quantity"])
    t.columns.insert(t.columns.index("notes"), VERDICT)

    def add(chapter: str, label: str, thesis: object, linear: object, twin: object, verdict: str, note: str) -> None:
        t.rows.append([chapter, label, thesis, linear, twin, verdict, note])

    def row(chapter: str, label: str, table: ComparisonTable, match: Callable[[list], bool], note: str = "") -> None:
        thesis, linear, twin = (_cell(table, match, c) for c in ("thesis", "linear model", "twin"))
        ref = _cell(table, match, "notes")
        cited = [n for n in table.notes if any(n.startswith(f"{r}:") for r in re.findall(r"note \d+", str(ref)))]
        own = [n for n in cited if ", linear model:" not in n.split(";")[0]]  # the twin's notes, and shared ones
        if isinstance(ref, str) and "note " in ref:
            ref = f"{ref} ({table.title.split(':')[0]})"
        add(chapter, label, thesis, linear, twin, numeric_verdict(thesis, twin, own), note or str(ref))

    c3a, c3b = sections["ch3"].tables
    row("3", "1-DOF pitch PSD main mode (Hz)", c3a, lambda r: r[0] == "pitch PSD main mode (Hz)")
    gain_checks = [c for c in getattr(calibration, "checks", []) if c.name == "1dof ARMAX DC gain"]
    gains = [c.achieved for c in gain_checks]
    runs = [g for c in gain_checks for g in c.runs]
    row(
        "3",
        "1-DOF ARMAX DC gain (rad/V)",
        c3a,
        lambda r: r[0] == "ARMAX DC gain (rad/V)",
        f"one 60 s run; the same signal and model (the calibration's 1-DOF protocol, recorded at 10 Hz) at its "
        f"{len(gains)} unseen seeds: single runs {min(runs):.3g}-{max(runs):.3g} ({len(runs)} runs, the scatter "
        f"of one run), each seed's median of its runs {min(gains):.3g}-{max(gains):.3g}, median "
        f"{float(np.median(gains)):.3g}"
        if runs
        else "",
    )
    row("3", "2-DOF u2 -> yaw modes (Hz)", c3b, lambda r: r[0] == "u2->y2" and r[1] == "PSD modes (Hz)")
    c42, c43 = sections["ch4"].tables
    row("4", "Table 4.2: LPF 0.1 Hz at 0.34 Hz (dB)", c42, lambda r: r[0] == "LPF 0.1 Hz" and r[1] == 0.34)
    row("4", "Table 4.3: u2 -> y2, Filter-3 at 0.1 Hz (dB)", c43, lambda r: r[0] == "u2->y2" and r[2] == "Filter-3")
    c51 = sections["ch5"].tables[0]
    for key in TABLE_5_1:
        row("5", f"Table 5.1: residual variance, {key} (rad^2)", c51, _first_cell_ends_with(f"{key} (rad^2)"))
    c61, _, cpush, cmarg, cfind = sections["ch67"].tables[:5]
    row("6", "Table 6.1: R = 75 SAS rise time (s)", c61, lambda r: r[:3] == [75.0, "SAS", "TR (s)"])
    row("6", "Table 6.1: R = 1 SAS settling (s)", c61, lambda r: r[:3] == [1.0, "SAS", "TS (s)"])
    row(
        "6",
        "Table 6.1: R = 75 CSAS LPF 0.2 Hz settling (s)",
        c61,
        lambda r: r[:3] == [75.0, "CSAS LPF 0.2 Hz", "TS (s)"],
    )
    margin = {
        w: next(r for r in cmarg.rows if r[0] == 1.0 and str(r[1]).startswith(w)) for w in ("linear model", "twin")
    }
    lin_m, twin_m = (f"{m[3]:.0f}; {m[6]}" for m in margin.values())
    add(
        "7",
        "R = 1: phase margin at the plant input (deg); with one sample of delay",
        "unstable on the rig",
        lin_m,
        twin_m,
        AGREES if twin_m.endswith("; unstable") else DIFFERS,
        "see the margins table",
    )
    twin_col = cfind.columns.index("twin")
    missed = [r for r in cfind.rows if r[twin_col] != "shown"]
    unexplained = [r for r in missed if "not explained" in str(r[-2]) or not str(r[-2]).strip()]
    add(
        "7",
        "ch. 7 findings shown",
        f"{len(cfind.rows)} findings",
        f"{sum(r[2] == 'shown' for r in cfind.rows)}",
        f"{len(cfind.rows) - len(missed)}",
        AGREES if not missed else (DIFFERS if unexplained else EXPLAINED),
        "see the ch. 7 findings table",
    )
    row(
        "7",
        "push: back within 0.02 rad after (s), R = 125",
        cpush,
        lambda r: r[0] == 125.0 and r[1].startswith("back within"),
    )
    c8 = {t.title.split(":")[0]: t for t in sections["ch8"].tables}
    autopilot = c8["Ch. 8 future work"]
    row(
        "8",
        "pitch command: yaw excursion (rad), MIMO LQG",
        autopilot,
        lambda r: r[:2] == ["pitch square wave", "MIMO LQG"] and r[2].startswith("other axis"),
    )
    row(
        "8",
        "pitch command: yaw excursion (rad), two SISO loops",
        autopilot,
        lambda r: r[:2] == ["pitch square wave", "two SISO loops"] and r[2].startswith("other axis"),
    )
    if "Robustness" in c8:
        row(
            "8",
            "robustness: 1-DOF CSAS R = 125 success",
            c8["Robustness"],
            lambda r: r[0].startswith("1-DOF") and r[1] == "success rate",
        )
    return t


#: The headline's verdict column, and its values: the twin within :data:`EXPLAIN_ABOVE` of a printed thesis
#: value (inside a printed range), off by more with every note on it explained by a measurement of the run, off
#: with a note that says "not explained", or nothing printed to compare with.
VERDICT = "twin vs thesis"
AGREES, EXPLAINED, DIFFERS, NOTHING = "agrees", "differs (explained)", "differs", "-"


def numeric_verdict(thesis: object, twin: object, notes: list[str]) -> str:
    """The headline verdict of a twin cell against the thesis's, given the notes the cell points at.

    A printed number or range is compared with :func:`relative_difference`; a status the thesis prints (a
    word) agrees when the twin's cell is the same word or, for "rejected"/"unstable", a run that shows it.

    Examples
    --------
    >>> numeric_verdict(7.0, 34.2, ["note 3: ... explained by an ambient floor"]), numeric_verdict(3.0, 3.4, [])
    ('differs (explained)', 'agrees')
    >>> numeric_verdict((5.0, 6.0), "hit the stops", ["note 6: ... not explained."])
    'differs'
    >>> numeric_verdict("0.1, 0.34", "0.10, 0.33, 0.87", []), numeric_verdict("0.1", "0.25", [])
    ('agrees', 'differs')
    """
    modes = _numbers(thesis), _numbers(twin)
    if all(modes) and isinstance(thesis, str):  # lists of modes (Hz): each printed one found within 30 %
        found = all(any(relative_difference(t, m) <= EXPLAIN_ABOVE for t in modes[1]) for m in modes[0])
        return AGREES if found else (EXPLAINED if notes and not any("not explained" in n for n in notes) else DIFFERS)
    if isinstance(thesis, (int, float, tuple)) and not isinstance(thesis, bool):
        if isinstance(twin, (int, float)) and not isinstance(twin, bool):
            if relative_difference(float(twin), thesis) <= EXPLAIN_ABOVE:
                return AGREES
        return EXPLAINED if notes and not any("not explained" in n for n in notes) else DIFFERS
    if thesis == "rejected":  # the thesis's push: a recovery time on the twin shows it
        return AGREES if isinstance(twin, (int, float)) else DIFFERS
    return NOTHING


def _numbers(cell: object) -> list[float]:
    """The numbers of a cell that lists them ("0.10, 0.34"); empty when it holds anything else."""
    if not isinstance(cell, str):
        return []
    try:
        return [float(x) for x in cell.split(",")]
    except ValueError:
        return []


def reader_summary(table: ComparisonTable) -> list[str]:
    """A few lines for a reader in a hurry, computed from the headline's verdicts: where the twin agrees with
    the thesis, where it differs for a measured reason, and where it differs unexplained.

    Examples
    --------
    >>> t = side_by_side("H", ["chapter", "quantity"])
    >>> t.columns.insert(t.columns.index("notes"), VERDICT)
    >>> t.rows = [["3", "mode (Hz)", 0.34, 0.33, 0.33, AGREES, ""], ["4", "LPF (dB)", 7, 31, 34, EXPLAINED, ""]]
    >>> reader_summary(t)[0]
    'The twin agrees with the thesis (within 30%) on 1 of its 2 headline figures: mode (Hz) (ch. 3).'
    """
    i = table.columns.index(VERDICT)
    by = {v: [f"{r[1]} (ch. {r[0]})" for r in table.rows if r[i] == v] for v in (AGREES, EXPLAINED, DIFFERS)}
    judged = sum(len(v) for v in by.values())
    out = [
        f"The twin agrees with the thesis (within {EXPLAIN_ABOVE:.0%}) on {len(by[AGREES])} of its {judged} headline "
        f"figures: " + ("; ".join(by[AGREES]) or "none") + "."
    ]
    if by[EXPLAINED]:
        out.append(
            f"It differs on {len(by[EXPLAINED])}, each explained by a measurement of this run (the notes say how): "
            + "; ".join(by[EXPLAINED])
            + "."
        )
    if by[DIFFERS]:
        out.append(f"It differs, not explained, on {len(by[DIFFERS])}: " + "; ".join(by[DIFFERS]) + ".")
    return out


def _agreement(section: Section) -> list[str]:
    """A conclusion line per table: how many twin cells with a printed thesis value lie within 30 % of it."""
    from trms.present.tables import EXPLAIN_ABOVE, relative_difference

    out = []
    for t in section.tables:
        if not {"thesis", "twin"} <= set(t.columns):
            continue
        i, j = t.columns.index("thesis"), t.columns.index("twin")
        pairs = [
            (row, row[j]) for row in t.rows if isinstance(row[i], (int, float, tuple)) and not isinstance(row[i], bool)
        ]
        near = [
            r for r, v in pairs if isinstance(v, (int, float)) and relative_difference(float(v), r[i]) <= EXPLAIN_ABOVE
        ]
        far = [r for r, v in pairs if r not in near]
        if not pairs:
            continue
        unexplained = sum("not explained" in n for n in t.notes)
        out.append(
            f"{t.title.split(':')[0]}: the twin is within {EXPLAIN_ABOVE:.0%} of the thesis in {len(near)} of "
            f"{len(pairs)} printed cells"
            + (f"; {len(far)} are not, each with its note ({unexplained} notes say 'not explained')" if far else "")
            + "."
        )
    return out


def _twin_at_a_glance(figures: Path, quick: bool = False) -> tuple[Section, Any]:
    from trms.calibration import Targets
    from trms.calibration.report import plot_targets, shipped_model_tables
    from trms.twin import DEFAULT_MODEL_PATH, Twin, load_spec
    from trms.twin.model import encoder_noise
    from trms.twin.parameters import PARAMETERS, published_parameters, read_parameters

    lines = []
    for config in ("1dof", "2dof"):
        tw = Twin(config, 0.2 if config == "1dof" else 0.1)
        hover = ", ".join(f"{n} = {v:.3f} V" for n, v in zip(tw.input_names, tw.operating_point.inputs))
        modes = ", ".join(f"{m.frequency_hz:.3f} Hz (zeta {m.damping:.3f}, {m.dominant})" for m in tw.modes()[:4])
        lines.append(f"{config}: hover trim {hover}; lowest modes {modes}.")
    params = read_parameters(load_spec())
    published = published_parameters()
    table = ComparisonTable(
        "The twin's physical parameters (shipped model)", ["parameter", "value", "published", "unit", "bounds"]
    )
    table.rows = [
        [k, v, published[k], PARAMETERS[k].unit or "-", f"{PARAMETERS[k].bounds[0]:g}-{PARAMETERS[k].bounds[1]:g}"]
        for k, v in params.items()
    ]
    twin = Twin("2dof", 0.1)
    lines.append(
        f"Model file: {DEFAULT_MODEL_PATH.name}. The twin is never still, as the rig: its rotor-wash turbulence "
        f"({1e3 * twin.turbulence.std[0]:.3g} and {1e3 * twin.turbulence.std[1]:.3g} mN on the main and tail rotor, "
        f"{twin.turbulence.time_constant:g} s correlation time) and its electronics noise on pitch "
        f"({1e3 * encoder_noise(load_spec())[0]:.3g} mrad) are calibrated parameters of the model, in every chapter; "
        f"the linear model gets white measurement noise of the same {NOISE_STD:.3g} rad. Gusts "
        f"({GUST[0]:g} N m, {GUST[1]:g} s: moving air) only where named (the robustness study, the HoverGusts task)."
    )
    # The calibration targets, measured now on the shipped model with the thesis's protocol (trms calibrate).
    targets = Targets.thesis()
    cal_tables, check = shipped_model_tables(load_spec(), evidence=not quick)
    if quick:
        lines.append("The side-peak evidence (0.25/0.46 Hz) is measured in the full run and by `trms calibrate`.")
    png = save_figure(plot_targets(check, targets), figures / "calibration.png", dpi=110)
    lines.append(
        "Calibration (`trms calibrate`) fits the named parameters above to the thesis's spectra and eq. (3.11); "
        "the table below re-measures every target on the shipped model."
    )
    return Section(
        "The twin at a glance",
        lines,
        [table, *cal_tables],
        [
            FigureRef(
                png,
                "Calibration: the twin's PSDs with the thesis's target frequencies (green met, red "
                "not), and the 1-DOF ARMAX identified from the twin over eq. (3.11).",
            )
        ],
    ), check


def _render_gif(record: Any, path: Path, every: int) -> Path:
    from trms.twin import Twin
    from trms.twin.render import render_record

    return render_record(Twin("1dof", 0.2).model, record, path, camera="oblique", every=every, width=320, height=240)


_CSS = """body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:1em 0;font-size:0.85em}
th,td{border:1px solid #bbb;padding:3px 6px;text-align:left}
th{background:#eee}img{max-width:100%}figure{margin:1em 0}figcaption{font-style:italic;font-size:0.9em}"""


def _equations() -> list[str]:
    """The equations the report refers to, written out once from the objects the run uses."""
    import control

    from trms.reference import eq_3_11

    g = control.tf(eq_3_11())
    num, den = (" ".join(f"{c:+.4g}" for c in np.ravel(v)) for v in (g.num[0][0], g.den[0][0]))
    return [
        f"eq. (3.11), the 1-DOF pitch model (u1 in V, pitch in rad, Ts = {g.dt:g} s): G(z) = ({num}) / ({den}) "
        "in descending powers of z.",
        "The LQG cost (eq. 6.34): J = sum_k x_a(k)' Q x_a(k) + u(k)' R u(k), x_a = [x; integral of the tracking "
        "error]; Q = I throughout, R as in each table (the thesis's factor 1/2 does not change the gain).",
    ]


def _write(report: Report, settings: Settings, timing: Mapping[str, float]) -> None:
    folder = report.folder
    mode = "quick (reduced)" if settings.quick else "full"
    intro = [
        f'Every experiment of the thesis "Modelling and Control of a Twin Rotor MIMO System" run on two worlds: the '
        f"linear model (eq. 3.11 for 1-DOF; the twin's linearisation for 2-DOF) and the MuJoCo twin. Run: {mode}, seed "
        f"{settings.seed}; wall time {report.seconds:.1f} s on {os.cpu_count()} CPU(s) "
        f"(linear world {timing['linear']:.1f} s, twin {timing['twin']:.1f} s, robustness {timing['robustness']:.1f} s "
        "of worker time).",
        "Each table holds the thesis's value, the linear model's, the twin's, and a note. 'not printed' marks a "
        "quantity the thesis shows only as a figure; '-' one it does not report.",
    ]
    toc = (
        [("headline", "Headline")] + [(sec.anchor, sec.title) for sec in report.sections] + [("equations", "Equations")]
    )
    eqs = _equations()
    md = ["# TRMS: the thesis on the linear model and on the twin", ""] + [p + "\n" for p in intro]
    md += ["**Contents:** " + " · ".join(f"[{title}](#{anchor})" for anchor, title in toc), ""]
    summary = reader_summary(report.headline)
    md += ["**In short.** " + " ".join(summary), ""]
    md += ['<a id="headline"></a>', "", report.headline.to_markdown(), ""]
    md += [s.to_markdown(folder) for s in report.sections]
    md += ['<a id="equations"></a>', "", "## Equations", ""] + [f"- {e}" for e in eqs] + [""]
    report.files["markdown"] = folder / "report.md"
    atomic_write(report.files["markdown"], lambda fh: fh.write("\n".join(md)), binary=False)
    body = ["<h1>TRMS: the thesis on the linear model and on the twin</h1>"]
    body += [f"<p>{inline_html(p)}</p>" for p in intro]
    body.append(
        "<p><b>Contents:</b> "
        + " · ".join(f'<a href="#{anchor}">{html.escape(title)}</a>' for anchor, title in toc)
        + "</p>"
    )
    body.append(f"<p><b>In short.</b> {inline_html(' '.join(summary))}</p>")
    body += ['<div id="headline"></div>', report.headline.to_html()] + [s.to_html(folder) for s in report.sections]
    body += ['<h2 id="equations">Equations</h2>', "<ul>" + "".join(f"<li>{html.escape(e)}</li>" for e in eqs) + "</ul>"]
    page = (
        f'<!DOCTYPE html>\n<html><head><meta charset="utf-8"><title>TRMS report</title><style>{_CSS}</style>'
        f"</head><body>\n{''.join(body)}</body></html>\n"
    )
    report.files["html"] = folder / "report.html"
    atomic_write(report.files["html"], lambda fh: fh.write(page), binary=False)
    data = {
        "mode": mode,
        "seed": settings.seed,
        "wall_time_s": report.seconds,
        "timing_s": dict(timing),
        "tables": [t.to_dict() for t in report.tables()],
        "missing": report.missing(),
        "statuses": report.statuses(),
    }
    report.files["json"] = folder / "tables.json"
    atomic_write(report.files["json"], lambda fh: fh.write(json.dumps(data, indent=1)), binary=False)


#: Thread counts of the numerical libraries in the report's worker processes (a variable the user set is kept).
_ONE_THREAD = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


@contextlib.contextmanager
def _environment(values: Mapping[str, str]) -> Iterator[None]:
    """Set the environment variables ``values`` that are not set already, for the block; then restore them."""
    added = {k: v for k, v in values.items() if k not in os.environ}
    os.environ.update(added)
    try:
        yield
    finally:
        for k in added:
            os.environ.pop(k, None)


@contextlib.contextmanager
def _interrupts_held() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) back for the block, then deliver it: processes started in the block inherit it blocked.

    The report's workers are stopped by the parent (see `_stop_workers`); a worker that a terminal's Ctrl-C reached
    while it was still importing would print its own traceback beside the command's one-line message.
    """
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _stop_workers(pool: ProcessPoolExecutor) -> None:
    """Cancel the pool's queued jobs and terminate its worker processes (and their own children)."""
    processes = list(getattr(pool, "_processes", {}).values())  # the executor offers no public handle
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in processes:
        for child in _children(proc.pid):
            _terminate(child)
        proc.terminate()
    for proc in processes:
        proc.join(timeout=5)


def _children(pid: int) -> list[int]:
    """Process ids of ``pid``'s children (Linux ``/proc``; none elsewhere)."""
    try:
        text = Path(f"/proc/{pid}/task/{pid}/children").read_text()
    except OSError:
        return []
    return [int(c) for c in text.split()]


def _terminate(pid: int) -> None:
    try:
        os.kill(pid, signal.SIGTERM)
    except OSError:
        pass


def reproduce(
    out: str | os.PathLike[str] = "report",
    quick: bool = False,
    seed: int = 0,
    workers: int = 2,
    progress: Callable[[str], None] | None = None,
) -> Report:
    """Run every experiment on both worlds and write the report folder (see the module docstring).

    Parameters
    ----------
    out : path-like
        Report folder (created; existing report files are replaced).
    quick : bool
        Reduced run.
    seed : int
        Seed of everything random.
    workers : int
        Worker processes (1 runs everything in this process).
    progress : callable, optional
        Called with a line of text as each part finishes.

    Returns
    -------
    Report
    """
    started = time.perf_counter()
    n_workers = int(check_in_range("workers", workers, 1, 64))
    say = progress or (lambda msg: None)
    settings = Settings(bool(quick), int(seed))
    folder = Path(out)
    figures = folder / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    say(f"running the experiments ({'quick' if quick else 'full'}, {n_workers} worker(s))")
    # Longest first, so that the worker processes finish together (measured on 2 cores: the twin's control part
    # about 20 s, its identification 10-20 s, each robustness part about 1 s a sample, the linear parts 1-3 s).
    jobs = [("twin", "control"), ("twin", "identification")]
    jobs += [("robustness", str(k)) for k in range(settings.robustness_parts)]
    jobs += [("linear", "control"), ("linear", "identification")]
    if settings.quick:  # four samples: shorter than the twin's identification
        jobs[1], jobs[2] = jobs[2], jobs[1]

    def run(world: str, part: str) -> dict[str, Any]:
        return _robustness(settings, int(part)) if world == "robustness" else world_results(world, settings, part)

    done: dict[tuple[str, str], dict[str, Any]] = {}
    if n_workers == 1:
        for world, part in jobs:
            done[(world, part)] = run(world, part)
            say(f"{world} {part} done in {done[(world, part)]['seconds']:.1f} s".replace("  ", " "))
    else:
        # Fresh interpreters with one BLAS thread each: n workers of a multi-threaded BLAS on n cores oversubscribe
        # them (a forked worker inherits the parent's thread pool); the quick report ran 32.6 s that way, 25.4 s so.
        pool = ProcessPoolExecutor(max_workers=n_workers, mp_context=multiprocessing.get_context("spawn"))
        try:
            # Read by each worker as it starts, at its first job's submission.
            with _environment(_ONE_THREAD), _interrupts_held():
                futures = {
                    job: (
                        pool.submit(_robustness, settings, int(job[1]))
                        if job[0] == "robustness"
                        else pool.submit(world_results, job[0], settings, job[1])
                    )
                    for job in jobs
                }
            for job, fut in futures.items():
                done[job] = fut.result()
                say(f"{job[0]} {job[1]} done in {done[job]['seconds']:.1f} s".replace("  ", " "))
        except BaseException:  # Ctrl-C or a failed job: stop the other jobs now rather than wait for them
            _stop_workers(pool)
            raise
        pool.shutdown()
    rob = _merge_robustness([done[("robustness", str(k))] for k in range(settings.robustness_parts)])
    results = {
        w: {
            **done[(w, "identification")],
            **done[(w, "control")],
            "seconds": done[(w, "identification")]["seconds"] + done[(w, "control")]["seconds"],
        }
        for w in WORLDS
    }
    say(f"robustness batch of {settings.samples} done in {rob['seconds']:.1f} s")
    lin, twin = results["linear"], results["twin"]
    sections: dict[str, Section] = {}
    sections["ch3"] = ch3.section(
        {w: r["ch3_1dof"] for w, r in results.items()}, {w: r["ch3_2dof"] for w, r in results.items()}, figures
    )
    sections["ch4"] = ch4.section(
        {w: r["ch4_1dof"] for w, r in results.items()},
        {w: r["ch4_2dof"] for w, r in results.items()},
        figures,
        *twin["ch4_floors"],
    )
    sections["ch5"] = ch5.section(
        {w: r["ch5"] for w, r in results.items()}, {w: r["ch5_yaw"] for w, r in results.items()}, figures
    )
    sections["ch67"] = ch67.section(
        lin["ch67"],
        twin["ch67"],
        twin["push"],
        {w: r["margins"] for w, r in results.items()},
        {w: r["margin_model"] for w, r in results.items()},
        figures,
        settings.weights,
        twin["side_mode"],
        {w: r["estimators"] for w, r in results.items()},
        float(make_plant("twin", "1dof").operating_point.inputs[0]),
    )
    sections["ch8"] = ch8.section(
        {w: r["ch8"] for w, r in results.items()},
        figures,
        [robustness.table(rob["batch"], rob["nominal"], settings.seed)],
        twin["ch8_margins"],
        twin["ch8_scan"],
    )
    for sec in sections.values():
        sec.conclusion = _agreement(sec) + sec.conclusion
    say("figures written")
    csas = twin["ch67"][(125.0, "CSAS LPF 0.2 Hz")]
    if csas.record is not None:
        gif = _render_gif(csas.record, figures / "twin_csas_R125_lpf0p2.gif", settings.gif_every)
        sections["ch67"].figures.insert(
            0,
            FigureRef(
                gif,
                "The twin during the CSAS manoeuvre (R = 125, LPF 0.2 Hz, square wave +-0.2 rad), rendered offscreen.",
            ),
        )
        say("render written")
    glance, calibration = _twin_at_a_glance(figures, settings.quick)
    report = Report(folder, [glance, *sections.values()], headline(sections, calibration), 0.0)
    report.seconds = time.perf_counter() - started
    _write(report, settings, {"linear": lin["seconds"], "twin": twin["seconds"], "robustness": rob["seconds"]})
    if "gif" not in report.files and csas.record is not None:
        report.files["gif"] = figures / "twin_csas_R125_lpf0p2.gif"
    return report
