"""Run the report: the jobs, the chapter sections built from their records, the headline, the files.

:func:`reproduce` is the report's entry point (see :mod:`trms.report`).
"""

from __future__ import annotations

import dataclasses
import html
import json
import os
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TypeVar

from trms.calibration import Targets, Verification
from trms.calibration.report import plot_targets, shipped_model_tables
from trms.errors import check_in_range
from trms.experiments import ch3_tables as ch3
from trms.experiments import ch4_tables as ch4
from trms.experiments import ch5_narx as ch5
from trms.experiments import ch67_chapter as ch67
from trms.experiments import ch67_lqg as runs67
from trms.experiments.ch8 import autopilot_section as ch8_section
from trms.experiments.ch8 import robustness as robustness
from trms.experiments.ch8.comparison import ControllerStudy, study_figures, study_tables
from trms.experiments.ch67_chapter import Chapter67, TwinEvidence
from trms.files import atomic_folder, atomic_write
from trms.present.figures import save_figure
from trms.present.sections import FigureRef, Section
from trms.present.seeds import Seeded
from trms.present.tables import inline_html
from trms.reference import EQ_3_11_NUM, SAMPLE_TIME_1DOF, eq_3_11_text
from trms.report.folder import TITLE, check_folder, keep_files, write_manifest
from trms.report.headline import agreement, headline, reader_summary
from trms.report.jobs import RENDERED, run_jobs
from trms.report.results import (
    Chapters,
    Control,
    Identification,
    Render,
    Report,
    Results,
    SeedControl,
    SeedIdentification,
    Settings,
)
from trms.twin import DEFAULT_MODEL_PATH, Twin, load_spec
from trms.twin.model import encoder_noise
from trms.worlds import GUST, NOISE_STD, WORLDS, make_plant

__all__ = ["reproduce"]

T = TypeVar("T")


def reproduce(
    out: str | os.PathLike[str] = "report",
    quick: bool = False,
    seed: int = 0,
    workers: int = 2,
    progress: Callable[[str], None] | None = None,
    force: bool = False,
) -> Report:
    """Run every experiment on both worlds and write the report folder (see :mod:`trms.report`).

    The folder is built aside and swapped in whole when the run has succeeded (:mod:`trms.report.folder`): a failure,
    Ctrl-C or SIGKILL at any moment leaves the old report or the new one, never parts of both.

    Parameters
    ----------
    out : path-like
        Report folder (created, or replaced whole). One holding files no trms run wrote is refused unless
        ``force``.
    quick : bool
        Reduced run.
    seed : int
        Seed of everything random.
    workers : int
        Worker processes (1 runs everything in this process), 1 to 64.
    progress : callable, optional
        Called with a line of text as each part finishes.
    force : bool
        Write into a folder holding files no trms run wrote; they are kept beside the report (but for those the
        report writes itself, which it replaces, with a warning).

    Returns
    -------
    Report

    Examples
    --------
    >>> reproduce("report", workers=0)
    Traceback (most recent call last):
    trms.errors.InputError: workers = 0 is outside the allowed range [1, 64]
    """
    started = time.perf_counter()
    n_workers = int(check_in_range("workers", workers, 1, 64))
    say = progress or (lambda msg: None)
    settings = Settings(bool(quick), int(seed))
    target = Path(out)
    foreign = check_folder(target, force)  # before any work: a folder the report may not replace is refused now
    with atomic_folder(target) as folder:
        figures = folder / "figures"
        figures.mkdir()
        say(f"running the experiments ({'quick' if quick else 'full'}, {n_workers} worker(s))")
        built = _Built(settings, figures, say)
        results = run_jobs(
            settings, n_workers, say, on_result=built.take, meanwhile=built.glance, render=figures / _GIF
        )
        say(f"robustness batch of {settings.samples} done in {results.robustness.seconds:.1f} s")
        chapters = built.chapters(results)
        for sec in chapters.sections():
            sec.conclusion = agreement(sec) + sec.conclusion
        say("figures written")
        assert built.at_a_glance is not None
        glance, calibration = built.at_a_glance
        report = Report(folder, [glance, *chapters.sections()], headline(chapters, calibration), 0.0)
        report.seconds = time.perf_counter() - started
        timing = {w: results.worlds[w].seconds for w in WORLDS} | {
            "robustness": results.robustness.seconds,
            "controllers": results.controllers.seconds,
            "sweep": results.controllers.sweep.seconds if results.controllers.sweep is not None else 0.0,
            "other seeds, identification": sum(r.seconds for r in results.seed_identification),
            "other seeds, control": sum(r.seconds for r in results.seed_control),
        }
        _write(report, settings, timing)
        if "gif" not in report.files and built.gif is not None:
            report.files["gif"] = built.gif
        write_manifest(folder, keep_files(foreign, target, folder))
    return _moved(report, folder, target)


def _moved(report: Report, built: Path, folder: Path) -> Report:
    """``report`` with its files' paths in ``folder``, where the folder it was ``built`` in now is."""

    def at(path: Path) -> Path:
        return folder / path.relative_to(built) if path.is_relative_to(built) else path

    report.folder = folder
    report.files = {k: at(v) for k, v in report.files.items()}
    for sec in report.sections:
        sec.figures = [dataclasses.replace(f, path=at(f.path)) for f in sec.figures]
    return report


#: The render's file name in the figures folder.
_GIF = "twin_csas_R125_lpf0p2.gif"


class _Built:
    """The report's parts built in this process while the jobs run: the twin at a glance (it needs no job), chapters
    3-5 once both worlds' identification parts are in, chapters 6/7 once both control parts are (the render, a job
    of its own, put in when both it and they are), chapter 8's figures as their jobs end and its tables at the end
    (the figures written into ``figures``)."""

    def __init__(self, settings: Settings, figures: Path, say: Callable[[str], None]) -> None:
        self.settings, self.figures, self.say = settings, figures, say
        self.got: dict[str, object] = {}
        self.ident: tuple[Section, Section, Section] | None = None
        self.ch67: Chapter67 | None = None
        self.gif: Path | None = None
        self.at_a_glance: tuple[Section, Verification] | None = None
        self.ch8_figures: dict[str, list[FigureRef]] = {}  # drawn as their job ends: "twin control", "controllers"

    def glance(self) -> None:
        """The twin at a glance."""
        self.at_a_glance = _twin_at_a_glance(self.figures, self.settings.quick)

    def _all(self, names: list[str], kind: type[T]) -> list[T] | None:
        """The records of the jobs ``names``, once every one of them is in (each a ``kind``); else ``None``."""
        got = [self.got.get(n) for n in names]
        return [r for r in got if isinstance(r, kind)] if all(isinstance(r, kind) for r in got) else None

    def take(self, name: str, outcome: object) -> None:
        """One job's record: build what it completes."""
        self.got[name] = outcome
        if name == "twin control" and isinstance(outcome, Control):
            self.ch8_figures[name] = ch8_section.autopilot_figures(outcome.autopilot, self.figures)
        if name == "controllers" and isinstance(outcome, ControllerStudy):
            self.ch8_figures[name] = study_figures(outcome, self.figures)
        others = self.settings.seeds[1:]
        ident = self._all([f"{w} identification" for w in WORLDS], Identification)
        more_ident = self._all([f"twin identification, seed {s}" for s in others], SeedIdentification)
        if self.ident is None and ident is not None and more_ident is not None:
            self.ident = _identification_chapters(dict(zip(WORLDS, ident)), more_ident, self.settings, self.figures)
        ctrl = self._all([f"{w} control" for w in WORLDS], Control)
        more_ctrl = self._all([f"twin control, seed {s}" for s in others], SeedControl)
        if self.ch67 is None and ctrl is not None and more_ctrl is not None:
            self.ch67 = _control_chapter(dict(zip(WORLDS, ctrl)), more_ctrl, self.settings, self.figures)
        render = self.got.get("twin render")
        if self.gif is None and self.ch67 is not None and isinstance(render, Render) and render.path is not None:
            self.gif = render.path
            self.ch67.section.figures.insert(
                0,
                FigureRef(
                    self.gif,
                    f"The twin during the {RENDERED[1]} manoeuvre (R = {RENDERED[0]:g}, square wave "
                    f"+-{runs67.DEFAULT_AMPLITUDE:g} rad), rendered offscreen.",
                ),
            )
            self.say("render written")

    def chapters(self, results: Results) -> Chapters:
        """Every chapter: those built while the jobs ran, and chapter 8."""
        assert self.ident is not None and self.ch67 is not None
        ctrl = {w: r.control for w, r in results.worlds.items()}
        twin_ctrl, rob = ctrl["twin"], results.robustness
        chapter_8 = ch8_section.section_8_autopilot(
            {w: r.autopilot for w, r in ctrl.items()},
            self.figures,
            [robustness.table(rob.batch, rob.nominal, self.settings.seed), *study_tables(results.controllers).values()],
            list(twin_ctrl.autopilot_margins),
            twin_ctrl.autopilot_scan,
            self.ch8_figures["controllers"],
            self.ch8_figures["twin control"],
        )
        return Chapters(*self.ident, self.ch67, chapter_8)


def _identification_chapters(
    ident: Mapping[str, Identification], more: list[SeedIdentification], settings: Settings, figures: Path
) -> tuple[Section, Section, Section]:
    """Chapters 3, 4 and 5 from both worlds' identification parts and the twin's at the run's other seeds."""
    twin_id, seeds = ident["twin"], settings.seeds

    def both(read_main, read_more) -> dict[str, object]:
        return {
            "linear": read_main(ident["linear"]),
            "twin": Seeded(seeds, (read_main(twin_id), *(read_more(m) for m in more))),
        }

    return (
        ch3.section_3(
            both(lambda r: r.ch3_1dof, lambda m: m.ch3_1dof),  # type: ignore[arg-type]
            both(lambda r: r.ch3_2dof, lambda m: m.ch3_2dof),  # type: ignore[arg-type]
            figures,
        ),
        ch4.section_4(
            both(lambda r: r.ch4_1dof, lambda m: m.ch4_1dof),  # type: ignore[arg-type]
            both(lambda r: r.ch4_2dof, lambda m: m.ch4_2dof),  # type: ignore[arg-type]
            figures,
            twin_id.floor,
        ),
        ch5.section_5(
            {
                "linear": ident["linear"].ch5,
                "twin": Seeded(
                    settings.narx_seeds, (twin_id.ch5, *twin_id.ch5_more, *(n for m in more for n in m.ch5))
                ),
            },
            {w: r.ch5_yaw for w, r in ident.items()},
            figures,
        ),
    )


def _control_chapter(
    ctrl: Mapping[str, Control], more: list[SeedControl], settings: Settings, figures: Path
) -> Chapter67:
    """Chapters 6 and 7 from both worlds' control parts and the twin's at the run's other seeds."""
    twin_ctrl, seeds = ctrl["twin"], settings.seeds
    return ch67.chapter(
        ctrl["linear"].lqg,
        Seeded(seeds, (twin_ctrl.lqg, *(m.lqg for m in more))),
        Seeded(seeds, (twin_ctrl.push or {}, *(m.push for m in more))),
        {w: r.margins for w, r in ctrl.items()},
        {w: r.margin_model for w, r in ctrl.items()},
        figures,
        settings.weights,
        TwinEvidence(
            twin_ctrl.side_mode,
            twin_ctrl.flight,
            Seeded(seeds, (twin_ctrl.amplitudes, *(m.amplitudes for m in more))),
            twin_ctrl.linearised,
        ),
        {w: r.estimators for w, r in ctrl.items()},
        float(make_plant("twin", "1dof").operating_point.inputs[0]),
    )


def _twin_at_a_glance(figures: Path, quick: bool = False) -> tuple[Section, Verification]:
    """The twin at a glance: hover trims and modes, parameters, ambient excitation, calibration targets."""
    lines = []
    for config in ("1dof", "2dof"):
        tw = Twin(config, 0.2 if config == "1dof" else 0.1)
        hover = ", ".join(f"{n} = {v:.3f} V" for n, v in zip(tw.input_names, tw.operating_point.inputs))
        modes = ", ".join(f"{m.frequency_hz:.3f} Hz (zeta {m.damping:.3f}, {m.dominant})" for m in tw.modes()[:4])
        lines.append(f"{config}: hover trim {hover}; lowest modes {modes}.")
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
        [cal_tables[-1], *cal_tables[:-1]],  # the parameters (the calibration's parameter table) first
        [
            FigureRef(
                png,
                "Calibration: the twin's PSDs with the thesis's target frequencies (green met, red "
                "not), and the 1-DOF ARMAX identified from the twin over eq. (3.11).",
            )
        ],
    ), check


_CSS = """body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:1em 0;font-size:0.85em}
th,td{border:1px solid #bbb;padding:3px 6px;text-align:left}
th{background:#eee}img{max-width:100%}figure{margin:1em 0}figcaption{font-style:italic;font-size:0.9em}"""


def _equations() -> list[str]:
    """The equations the report refers to, written out once: eq. (3.11) at the thesis's printed precision."""
    return [
        f"eq. (3.11), the 1-DOF pitch model (u1 in V, pitch in rad, Ts = {SAMPLE_TIME_1DOF:g} s), every coefficient "
        f"as the thesis prints it ({len(EQ_3_11_NUM)} numerator coefficients): {eq_3_11_text()}.",
        "The LQG cost (eq. 6.34): J = sum_k x_a(k)' Q x_a(k) + u(k)' R u(k), x_a = [x; integral of the tracking "
        "error]; Q = I throughout, R as in each table (the thesis's factor 1/2 does not change the gain).",
    ]


def _write(report: Report, settings: Settings, timing: Mapping[str, float]) -> None:
    """Write the report's Markdown, HTML and JSON files into its folder (recorded in ``report.files``)."""
    folder = report.folder
    mode = "quick (reduced)" if settings.quick else "full"
    intro = [
        f'Every experiment of the thesis "Modelling and Control of a Twin Rotor MIMO System" run on two worlds: the '
        f"linear model (eq. 3.11 for 1-DOF; the twin's linearisation for 2-DOF) and the MuJoCo twin. Run: {mode}, seed "
        f"{settings.seed}; wall time {report.seconds:.1f} s on {os.cpu_count()} CPU(s) "
        f"(linear world {timing['linear']:.1f} s, twin {timing['twin']:.1f} s, "
        f"robustness {timing['robustness']:.1f} s, controller comparison {timing['controllers']:.1f} s"
        + (f" and its amplitude sweep {timing['sweep']:.1f} s" if timing.get("sweep") else "")
        + ", "
        f"the twin's other seeds {timing['other seeds, identification']:.1f} s (chapters 3-5) and "
        f"{timing['other seeds, control']:.1f} s (chapters 6/7) of worker time).",
        f"Every twin cell that carries a verdict is measured at {len(settings.seeds)} seeds "
        f"({', '.join(str(s) for s in settings.seeds)}; the figures and the cells without a verdict are seed "
        f"{settings.seed}'s) and printed as its median (range): it agrees with the thesis only when it lies within "
        "30 % of the thesis's value at every seed, differs only when it lies outside at every seed, and is otherwise "
        "inconclusive at that many seeds. An explanation is printed as such only when it was computed in this run and "
        "its own check passed; one that holds in part says so.",
        "Each table holds the thesis's value, the linear model's, the twin's, and a note; a 'source' column says "
        "where a thesis-column value comes from when it is not printed in the thesis. 'not printed' marks a "
        "quantity the thesis shows only as a figure; '-' one it does not report.",
    ]
    toc = (
        [("headline", "Headline")] + [(sec.anchor, sec.title) for sec in report.sections] + [("equations", "Equations")]
    )
    eqs = _equations()
    md = [TITLE, ""] + [p + "\n" for p in intro]
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
