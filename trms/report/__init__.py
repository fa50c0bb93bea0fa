"""Run every experiment of the thesis on the linear model and on the twin, and write the report.

:func:`reproduce` writes a self-contained folder:

* ``report.md`` and ``report.html``: every thesis table with the columns thesis, linear model,
  twin and notes; the headline table first; the twin at a glance (hover trim, modes, parameters);
  the run's wall time;
* ``figures/``: PNG figures (responses, PSDs with modes marked, coherence, residual tests) and a
  GIF render of the twin during a CSAS manoeuvre;
* ``tables.json``: every table as data, for machine checks.

Each world's identification chapters (3-5), its control chapters (6-8), the robustness batch and the GIF render
are independent jobs and run in a pool of ``workers`` processes (:mod:`trms.report.jobs`), each handing back a
typed record (:mod:`trms.report.results`); the sections, the headline (:mod:`trms.report.headline`), the figures
and documents are built in this process as the records they need come in (:mod:`trms.report.pipeline`).
Every twin cell that carries a verdict is measured at :attr:`~trms.report.results.Settings.seeds` (5 in a full run,
2 in a quick one), the other seeds each in jobs of their own (:mod:`trms.report.seed_jobs`), and judged over them.
``quick`` shortens the run (two seeds, fewer LQG weights, a smaller Monte Carlo batch, the ch. 4 notes' ambient floor
on Table 4.2 only, Table 6.1's control at the thesis's estimator only, the ch. 8 scan of R flown on the twin at the
chosen weight and its two neighbours only, a coarser GIF) without leaving any table out.
"""

from trms.report.headline import (
    AGREES,
    DIFFERS,
    EXPLAINED,
    NOTHING,
    PARTLY,
    VERDICT,
    agreement,
    compared_row,
    headline,
    numeric_verdict,
    reader_summary,
)
from trms.report.jobs import (
    PARTS,
    run_control,
    run_identification,
    run_jobs,
    run_render,
    run_robustness,
    world_results,
)
from trms.report.pipeline import reproduce
from trms.report.results import (
    Chapters,
    Control,
    Identification,
    Render,
    Report,
    Results,
    Robustness,
    RobustnessPart,
    SeedControl,
    SeedIdentification,
    Settings,
    WorldResults,
)

__all__ = [
    "Settings",
    "Report",
    "PARTS",
    "reproduce",
    "world_results",
    "headline",
    "numeric_verdict",
    "reader_summary",
    "VERDICT",
    "AGREES",
    "EXPLAINED",
    "PARTLY",
    "DIFFERS",
    "NOTHING",
    "agreement",
    "compared_row",
    "Identification",
    "Control",
    "SeedIdentification",
    "SeedControl",
    "WorldResults",
    "RobustnessPart",
    "Robustness",
    "Render",
    "Chapters",
    "Results",
    "run_identification",
    "run_control",
    "run_robustness",
    "run_render",
    "run_jobs",
]
