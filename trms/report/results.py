"""What a run of the report does and what its jobs hand back, as typed records.

Each job of :mod:`trms.report.jobs` returns one of these records from its worker process (so each is
picklable): a world's identification chapters (:class:`Identification`), its control chapters
(:class:`Control`), the twin's cells that carry a verdict at another seed (:class:`SeedIdentification`,
:class:`SeedControl`), a part of the Monte Carlo batch (:class:`RobustnessPart`) and the twin's render
(:class:`Render`). The report's sections are built from them (:class:`Chapters`), and its headline from the
sections' typed rows.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from trms.experiments import ch67_lqg as runs67
from trms.experiments.ch3_identification import Mimo2Dof, Siso1Dof
from trms.experiments.ch4_shaping import Floor, Shaping
from trms.experiments.ch5_narx import Narx, NarxYaw
from trms.experiments.ch7_side_mode import SideModeEvidence
from trms.experiments.ch8.autopilot import AutopilotRun
from trms.experiments.ch8.autopilot_margins import InputMargins
from trms.experiments.ch8.comparison import ControllerStudy
from trms.experiments.ch8.controllers import CASES as CONTROLLER_CASES
from trms.experiments.ch8.robustness import Sample
from trms.experiments.ch67_chapter import Chapter67
from trms.experiments.ch67_lqg import CaseResult, Margins, PushResult
from trms.present.sections import Section
from trms.present.seeds import OverSeeds
from trms.present.tables import ComparisonTable
from trms.reference import LQG_WEIGHTS_R

__all__ = [
    "SEED_STRIDE",
    "NARX_SEEDS",
    "NARX_STRIDE",
    "Settings",
    "Identification",
    "Control",
    "SeedIdentification",
    "SeedControl",
    "WorldResults",
    "RobustnessPart",
    "Robustness",
    "Render",
    "Results",
    "Chapters",
    "Report",
]

#: The LQG cases of chapters 6/7 by (R, case), as :func:`trms.experiments.ch67_lqg.lqg_cases` returns them.
Cases = dict[tuple[float, str], CaseResult]
#: How far apart the twin's seeds of one run are (the run's seed ``s``, then ``s + 1000``, ...): further than any
#: offset an experiment adds to its seed, so the seeds' realisations share nothing.
SEED_STRIDE = 1000
#: Table 5.1's NARX fits in a run (quick or full), shared among its seed jobs, :data:`NARX_STRIDE` apart: its fits
#: are cheap (0.17 s of CPU a seed), and its residual variances straddle the 30 % band (over 60 seeds the ARMAX's lay
#: within it at 70 % of them, the NARX-RBF's at 23 %): at 20 seeds a verdict other than "inconclusive" (every seed
#: inside, or every one outside) is drawn at 0.08 % and 0.5 % of runs, at 8 seeds at 6 % and 12 %.
NARX_SEEDS = 20
NARX_STRIDE = 100


@dataclass(frozen=True)
class Settings:
    """What a run does.

    Attributes
    ----------
    quick : bool
        Reduced run (see :mod:`trms.report`).
    seed : int
        Seed of every excitation, noise, gust and parameter draw.

    Examples
    --------
    >>> Settings(quick=True).weights, Settings().samples
    ((75.0, 1.0, 125.0), 24)
    >>> Settings(seed=3).seeds, Settings(quick=True).seeds
    ((3, 1003, 2003, 3003, 4003), (0, 1000))
    >>> Settings(quick=True).narx_per_job, len(Settings(quick=True).narx_seeds), Settings().narx_seeds[:5]
    (10, 20, (0, 100, 200, 300, 1000))
    """

    quick: bool = False
    seed: int = 0

    @property
    def seeds(self) -> tuple[int, ...]:
        """The twin's seeds: every twin cell that carries a verdict is measured at each (5 in a full run, 2 in a quick
        one), the run's own seed first (its figures and the cells without a verdict)."""
        return tuple(self.seed + SEED_STRIDE * k for k in range(2 if self.quick else 5))

    @property
    def narx_per_job(self) -> int:
        """Table 5.1's NARX fits in each seed's identification job: :data:`NARX_SEEDS` shared among :attr:`seeds`
        (4 in a full run, 10 in a quick one)."""
        return NARX_SEEDS // len(self.seeds)

    @property
    def narx_seeds(self) -> tuple[int, ...]:
        """Table 5.1's seeds: :attr:`narx_per_job` for each of :attr:`seeds`, :data:`NARX_STRIDE` apart
        (:data:`NARX_SEEDS` in a quick or full run), the run's own first."""
        return tuple(s + NARX_STRIDE * j for s in self.seeds for j in range(self.narx_per_job))

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
        return 1 if self.quick else 3

    @property
    def estimator_speeds(self) -> tuple[float, ...]:
        """Estimator speeds beside the thesis's under which Table 6.1's control is re-measured."""
        return () if self.quick else runs67.ESTIMATOR_SPEEDS

    @property
    def controller_samples(self) -> int:
        """Twins of the parameter spread each controller of the ch. 8 comparison flies (0: none)."""
        return 0 if self.quick else 4

    @property
    def controller_cases(self) -> tuple[str, ...]:
        """Square-wave cases of the ch. 8 comparison (:data:`trms.experiments.ch8.controllers.CASES`; the push is
        flown with the twin in moving air)."""
        return ("linear model", "twin, moving air") if self.quick else tuple(CONTROLLER_CASES)

    @property
    def controller_mimo_seeds(self) -> tuple[int, ...]:
        """Plant seeds of the ch. 8 MIMO comparison (empty: none)."""
        return () if self.quick else (self.seed,)

    @property
    def controller_sweep_seeds(self) -> tuple[int, ...]:
        """Moving-air seeds of the ch. 8 amplitude sweep (empty: none)."""
        return () if self.quick else (self.seed,)

    @property
    def gif_every(self) -> int:
        """Render every n-th sample of the CSAS run into the GIF."""
        return 5 if self.quick else 2


@dataclass(frozen=True)
class Identification:
    """One world's chapters 3-5 (one job).

    Attributes
    ----------
    ch3_1dof, ch3_2dof : Siso1Dof, Mimo2Dof
        :func:`trms.experiments.ch3_identification.identify_1dof` and ``identify_2dof``.
    ch4_1dof, ch4_2dof : Shaping
        :func:`trms.experiments.ch4_shaping.shaping_1dof` and ``shaping_2dof``.
    ch5, ch5_yaw : Narx, NarxYaw
        :func:`trms.experiments.ch5_narx.narx_1dof` and ``narx_yaw``.
    floor : Floor, optional
        :func:`trms.experiments.ch4_shaping.ambient_floors`: the twin's doublets under the most ambient excitation
        its calibration allows (the ch. 4 notes' floor, with its hover RMS check); ``None`` on the linear model.
    ch5_more : tuple of Narx
        Table 5.1's models at the job's other NARX seeds (:attr:`Settings.narx_seeds`; the twin only).
    seconds : float
        Worker time of the job (s).
    """

    ch3_1dof: Siso1Dof
    ch3_2dof: Mimo2Dof
    ch4_1dof: Shaping
    ch4_2dof: Shaping
    ch5: Narx
    ch5_yaw: NarxYaw
    floor: Floor | None = None
    ch5_more: tuple[Narx, ...] = ()
    seconds: float = 0.0


@dataclass(frozen=True)
class SeedIdentification:
    """The twin's chapters 3-5 at another seed of the run (one job): the experiments whose cells carry a verdict, run
    without what only the figures and the unjudged rows read (the validation runs, the shapers, the PRBS-trained and
    polynomial NARX).

    Attributes
    ----------
    seed : int
    ch3_1dof, ch3_2dof, ch4_1dof, ch4_2dof
        As :class:`Identification`'s.
    ch5 : tuple of Narx
        Table 5.1's models at the job's :attr:`Settings.narx_per_job` NARX seeds (:attr:`Settings.narx_seeds`).
    seconds : float
        Worker time of the job (s).
    """

    seed: int
    ch3_1dof: Siso1Dof
    ch3_2dof: Mimo2Dof
    ch4_1dof: Shaping
    ch4_2dof: Shaping
    ch5: tuple[Narx, ...]
    seconds: float = 0.0


@dataclass(frozen=True)
class SeedControl:
    """The twin's chapters 6/7 at another seed of the run (one job): the LQG cases Table 6.1 and the ch. 7 findings
    read, the push, and R = 1 at the note's amplitudes, records dropped.

    Attributes
    ----------
    seed : int
    lqg : dict
        :func:`trms.experiments.ch67_lqg.lqg_cases` at the cases of :func:`trms.report.seed_jobs.seed_cases`.
    push : dict of float to PushResult
    amplitudes : dict of float to CaseResult
        :func:`trms.experiments.ch67_amplitudes.amplitude_runs`.
    seconds : float
        Worker time of the job (s).
    """

    seed: int
    lqg: Cases
    push: dict[float, PushResult]
    amplitudes: dict[float, CaseResult]
    seconds: float = 0.0


@dataclass(frozen=True)
class Control:
    """One world's chapters 6-8 (one job).

    Attributes
    ----------
    lqg : dict
        :func:`trms.experiments.ch67_lqg.lqg_cases` at the run's weights.
    margins : dict of float to Margins
        The LQG loops' margins by R, on ``margin_model``.
    margin_model : str
        The plant model the margins are taken on ("eq. (3.11)" or the twin's linearisation).
    estimators : dict
        Table 6.1's cases by estimator speed (beside the thesis's; empty in a quick run).
    autopilot : dict
        :func:`trms.experiments.ch8.autopilot.autopilot_runs`.
    push : dict of float to PushResult, optional
        The push rejection by R (the twin only: the linear model has no torque input).
    side_mode : SideModeEvidence, optional
        The low-pass finding's evidence (the twin only).
    autopilot_margins : tuple of InputMargins
        The ch. 8 choice of R's margin scan (the twin only; empty otherwise).
    autopilot_scan : dict
        :func:`trms.experiments.ch8.autopilot.scan_runs` (the twin only; empty otherwise).
    flight : tuple, optional
        :func:`trms.experiments.ch7_findings.pci_flight` (the twin only).
    amplitudes : dict of float to CaseResult
        :func:`trms.experiments.ch67_amplitudes.amplitude_runs` (the twin only; empty otherwise).
    linearised : dict of float to CaseResult
        :func:`trms.experiments.ch67_amplitudes.linearised_runs` (the twin only; empty otherwise).
    seconds : float
        Worker time of the job (s).
    """

    lqg: Cases
    margins: dict[float, Margins]
    margin_model: str
    estimators: dict[float, Cases]
    autopilot: dict[tuple[str, str], AutopilotRun]
    push: dict[float, PushResult] | None = None
    side_mode: SideModeEvidence | None = None
    autopilot_margins: tuple[InputMargins, ...] = ()
    autopilot_scan: dict[float, dict[str, AutopilotRun]] = field(default_factory=dict)
    flight: tuple[float, CaseResult] | None = None
    amplitudes: dict[float, CaseResult] = field(default_factory=dict)
    linearised: dict[float, CaseResult] = field(default_factory=dict)
    seconds: float = 0.0


@dataclass(frozen=True)
class WorldResults:
    """Both parts of one world's chain."""

    identification: Identification
    control: Control

    @property
    def seconds(self) -> float:
        """Worker time of both parts (s)."""
        return self.identification.seconds + self.control.seconds


@dataclass(frozen=True)
class RobustnessPart:
    """One part of the Monte Carlo batch (one job).

    Attributes
    ----------
    samples : dict of str to list of Sample
        Loop name -> its samples of this part, in sample-index order.
    nominal : dict, optional
        :func:`trms.experiments.ch8.robustness.nominal` on the linear model (the first part only).
    seconds : float
        Worker time of the job (s).
    """

    samples: dict[str, list[Sample]]
    nominal: dict[str, tuple[str, float, float]] | None
    seconds: float

    @staticmethod
    def merge(parts: list[RobustnessPart]) -> Robustness:
        """The parts as one batch, as :func:`~trms.experiments.ch8.robustness.monte_carlo` gives it (any split of the
        samples gives the same bits).

        Examples
        --------
        >>> from trms.experiments.ch8.robustness import Sample
        >>> a = RobustnessPart({"loop": [Sample({}, "settled", 1.0, 2.0, 0)]}, {"loop": ("settled", 1.0, 2.0)}, 1.0)
        >>> b = RobustnessPart({"loop": [Sample({}, "diverged", 0.0, 0.0, 1)]}, None, 2.0)
        >>> m = RobustnessPart.merge([b, a])
        >>> [s.index for s in m.batch["loop"]], m.nominal is not None, m.seconds
        ([0, 1], True, 3.0)
        """
        names = parts[0].samples
        batch = {n: sorted((s for p in parts for s in p.samples[n]), key=lambda s: s.index) for n in names}
        nominal = next((p.nominal for p in parts if p.nominal is not None), None)
        if nominal is None:
            raise ValueError("no part of the robustness batch holds the nominal loops")
        return Robustness(batch, nominal, sum(p.seconds for p in parts))


@dataclass(frozen=True)
class Robustness:
    """The whole Monte Carlo batch: samples per loop, the nominal loops on the linear model, worker time (s)."""

    batch: dict[str, list[Sample]]
    nominal: dict[str, tuple[str, float, float]]
    seconds: float


@dataclass(frozen=True)
class Render:
    """The twin's CSAS manoeuvre rendered offscreen (one job).

    Attributes
    ----------
    path : pathlib.Path, optional
        The GIF written; ``None`` when the run it replays diverged (nothing to show).
    seconds : float
        Worker time of the job (s).
    """

    path: Path | None
    seconds: float


@dataclass(frozen=True)
class Results:
    """Every job's record (:func:`trms.report.jobs.run_jobs`): each world's chain, by world, the merged robustness
    batch, the controller study, the render (``None`` when none was asked for), and the twin's cells at the run's
    other seeds (in their order)."""

    worlds: dict[str, WorldResults]
    robustness: Robustness
    controllers: ControllerStudy
    render: Render | None = None
    seed_identification: tuple[SeedIdentification, ...] = ()
    seed_control: tuple[SeedControl, ...] = ()


@dataclass
class Chapters:
    """The report's chapter sections, by chapter."""

    ch3: Section
    ch4: Section
    ch5: Section
    ch67: Chapter67
    ch8: Section

    def sections(self) -> list[Section]:
        """The sections in the report's order."""
        return [self.ch3, self.ch4, self.ch5, self.ch67.section, self.ch8]


@dataclass
class Report:
    """What :func:`trms.report.reproduce` wrote and found.

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
        """How many computed cells hold each named run status (:data:`trms.experiments.ch67_lqg.STATUSES`), a cell
        measured at several seeds counted at each."""
        cells = [v for t in self.tables() for c in t.computed_cells() for v in _values(c)]
        return {s: sum(1 for c in cells if c == s) for s in runs67.STATUSES}

    def missing(self) -> list[str]:
        """Computed cells that are empty or not finite, across every table."""
        return [f"{t.title}: {m}" for t in self.tables() for m in t.missing()]


def _values(cell: object) -> tuple[object, ...]:
    return cell.values if isinstance(cell, OverSeeds) else (cell,)
