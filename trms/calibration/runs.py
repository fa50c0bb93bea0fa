"""A whole calibration run, from its inputs to its files: the spectral calibration against mode targets (with the
measured evidence and the report), or the time-domain calibration on a rig's records (with ``calibration.json``).
"""

from __future__ import annotations

import json
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import mujoco

from trms.calibration.calibrate import CalibrationResult, Progress, calibrate
from trms.calibration.evidence import measured_targets
from trms.calibration.report import write_report
from trms.calibration.targets import Targets
from trms.calibration.timedomain import calibrate_records
from trms.calibration.timedomain.result import TimeDomainResult
from trms.files import atomic_write
from trms.measurement.protocol import VERIFY_SEEDS
from trms.record import Record
from trms.twin.parameters import with_parameters

__all__ = ["SpectralRun", "choose_targets", "spectral_run", "time_domain_run"]


@dataclass(frozen=True)
class SpectralRun:
    """A spectral calibration and what it wrote.

    Attributes
    ----------
    result : CalibrationResult
    evidence : dict or None
        The measured side-peak and trade-off evidence of the calibrated model (thesis targets only).
    seconds : float
        Wall time of the calibration (s), the evidence not included.
    json, png : Path
        The report files.
    """

    result: CalibrationResult
    evidence: dict | None
    seconds: float
    json: Path
    png: Path


def choose_targets(table: str | None = None, records: Sequence[str] | None = None) -> Targets:
    """The spectral targets: a mode table (JSON), else peaks measured on saved Records of a rig, else the thesis's.

    Examples
    --------
    >>> choose_targets().source
    'thesis'
    """
    if table:
        return Targets.load(table)
    if records:
        return Targets.from_records([Record.load(p) for p in records])
    return Targets.thesis()


def spectral_run(
    targets: Targets,
    spec: mujoco.MjSpec,
    out: str | Path,
    *,
    quiet: bool = False,
    workers: int | None = None,
    scheduler: str | None = None,
    seeds: Sequence[int] | None = None,
    evidence: bool = True,
) -> SpectralRun:
    """Calibrate ``spec`` against ``targets`` (:func:`~trms.calibration.calibrate.calibrate`) and write the report.

    Parameters
    ----------
    targets : Targets
    spec : mujoco.MjSpec
        The model to start from.
    out : path-like
        Report folder (``calibration.json``, ``calibration.png``).
    quiet : bool
        No progress bars.
    workers, scheduler : optional
        Run the spectral stage's candidates on a local Dask cluster of ``workers`` processes, or on the
        cluster at ``scheduler``.
    seeds : sequence of int, optional
        The verification's unseen seeds (default :data:`~trms.measurement.protocol.VERIFY_SEEDS`).
    evidence : bool
        Measure the side-peak and trade-off evidence of the result (thesis targets only; the longest part).

    Returns
    -------
    SpectralRun
    """
    t0 = time.perf_counter()
    cluster = None
    if workers is not None or scheduler is not None:
        cluster = {"workers": workers, "scheduler": scheduler, "progress": not quiet}
    chosen = VERIFY_SEEDS if seeds is None else tuple(seeds)
    result = calibrate(targets, spec, progress=Progress(enabled=not quiet), cluster=cluster, seeds=chosen)
    wall = time.perf_counter() - t0
    found = None
    if targets.source == "thesis" and evidence:
        found = measured_targets(with_parameters(spec, result.values), side_peaks=True)[1]
    js, png = write_report(result, out, found)
    return SpectralRun(result, found, wall, js, png)


def time_domain_run(
    records: Sequence[Record],
    spec: mujoco.MjSpec,
    out: str | Path,
    *,
    held_out: Sequence[Record] = (),
    labels: Sequence[str] = (),
    held_out_labels: Sequence[str] = (),
    parameters: Sequence[str] | None = None,
    config: str | None = None,
    max_iters: int = 30,
    quiet: bool = False,
) -> tuple[TimeDomainResult, Path]:
    """Calibrate ``spec`` on a rig's records in the time domain (:func:`~trms.calibration.timedomain.calibrate_records`)
    and write ``calibration.json`` and the sysid report into ``out``.

    Parameters
    ----------
    records, held_out : sequence of Record
        The records fitted, and those the fit never sees (for the fit before/after).
    spec : mujoco.MjSpec
        The model to start from.
    out : path-like
        Output folder.
    labels, held_out_labels : sequence of str
        The records' names in the report (their files).
    parameters : sequence of str, optional
        Parameters to fit (default: those the configuration observes).
    config : str, optional
        The rig configuration the records were taken in.
    max_iters : int
        Most Gauss-Newton iterations.
    quiet : bool
        No progress bars.

    Returns
    -------
    result : TimeDomainResult
    json : Path
        The written ``calibration.json``.
    """
    folder = Path(out)
    result = calibrate_records(
        records,
        parameters,
        spec,
        held_out=held_out,
        labels=list(labels),
        held_out_labels=list(held_out_labels),
        config=config,
        max_iters=max_iters,
        report_dir=folder / "sysid",
        progress=Progress(enabled=not quiet),
    )
    text = json.dumps(result.to_dict(), indent=2)
    js = atomic_write(folder / "calibration.json", lambda fh: fh.write(text), binary=False)
    return result, js
