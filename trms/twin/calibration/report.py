"""The calibration report: ``calibration.json`` and ``calibration.png``.

The figure shows the calibrated twin's PSDs from the thesis's protocol with every target
frequency marked (green: met, red: not), and the 1-DOF model identified from the twin's
data over the target model (eq. 3.11 by default), in magnitude and phase.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from matplotlib.figure import Figure

from ...experiments.figures import new_axes, save_figure
from ...files import atomic_write
from .calibrate import CalibrationResult
from .large_signal import TOLERANCE
from .protocol import step_figures
from .targets import SIDE_PEAKS_HZ, Targets
from .verify import Verification

__all__ = ["write_report", "plot_targets", "format_table"]


def format_table(result: CalibrationResult) -> str:
    """The target table (target, achieved at each verification seed, tolerance, met at all) as Markdown."""
    seeds = [str(s) for s in result.verification.seeds]
    lines = [
        "| target | value | " + " | ".join(f"seed {s}" for s in seeds) + " | tolerance | met |",
        "|---|---|" + "---|" * len(seeds) + "---|---|",
    ]
    for row in result.verification.summary():
        cells = ["-" if c is None else f"{c:.4g}" for c in result.verification.seed_cells(row)]
        lines.append(
            f"| {row['name']} | {row['target']:.4g} {row['unit']} | "
            + " | ".join(cells)
            + f" | {row['tolerance']} | {'yes' if row['met'] else 'no'} |"
        )
    if result.large_signal:
        lines += [
            "",
            f"| large signal (1-DOF, from hover) | published model | twin | ratio | within {100 * TOLERANCE:g} % |",
            "|---|---|---|---|---|",
        ]
        for c in result.large_signal:
            lines.append(
                f"| {c.name} | {c.published:.3g} {c.unit} | {c.twin:.3g} {c.unit} | {c.ratio:.2f} | "
                f"{'yes' if c.met else 'no'} |"
            )
    return "\n".join(lines)


def write_report(
    result: CalibrationResult, folder: str | os.PathLike[str], evidence: dict | None = None
) -> tuple[Path, Path]:
    """Write ``calibration.json`` and ``calibration.png`` into ``folder``; return their paths.

    ``evidence`` (:func:`~trms.twin.calibration.elastic_modes.side_peak_evidence`, with the
    trade-offs of :mod:`~trms.twin.calibration.tradeoffs`) adds the measured evidence section.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    js = folder / "calibration.json"
    data = result.to_dict()
    if evidence is not None:
        data["evidence"] = evidence
    atomic_write(js, lambda fh: fh.write(json.dumps(data, indent=2)), binary=False)
    png = save_figure(plot_targets(result.verification, result.targets), folder / "calibration.png", dpi=110)
    return js, png


def plot_targets(verification: Verification, targets: Targets, ax: Any = None) -> Figure:
    """The twin's PSDs with every target frequency marked, and its identified 1-DOF model over the target model.

    Parameters
    ----------
    verification : Verification
        What :func:`~trms.twin.calibration.verify` measured (its spectra and identified model).
    targets : Targets
        The targets it was measured against.
    ax : sequence of matplotlib Axes, optional
        One Axes per panel (a PSD per target channel, then magnitude and phase when there is a model
        target); by default a new figure, three panels a row, on matplotlib's Agg canvas.

    Returns
    -------
    matplotlib.figure.Figure
        Write it with :func:`trms.experiments.figures.save_figure`.

    Raises
    ------
    InputError
        ``ax`` holds another number of Axes than there are panels.
    """
    spectra = verification.spectra
    peaks_by_key: dict[tuple[str, str], list] = {}
    for t in targets.peaks:
        peaks_by_key.setdefault((t.config, t.channel), []).append(t)
    keys = list(peaks_by_key)
    n_panels = len(keys) + (2 if verification.model is not None and targets.model is not None else 0)
    if ax is None:
        cols = 3
        rows = int(np.ceil(n_panels / cols))
        fig, axes = new_axes(rows, cols, (5.0 * cols, 3.4 * rows))
    else:
        fig, axes = new_axes(1, n_panels, ax=ax)
    flat = axes.ravel()
    met = {(c.name, c.target): c.met for c in verification.checks}
    for panel, key in zip(flat, keys):
        f, p, _ = spectra[key]
        sel = (f > 0) & (f <= 1.5)
        panel.semilogy(f[sel], p[sel], color="k", lw=1.2, label="twin")
        for t in peaks_by_key[key]:
            ok = met.get((t.name, t.frequency_hz), False)
            panel.axvspan(
                t.frequency_hz - t.tolerance_hz, t.frequency_hz + t.tolerance_hz, color="g" if ok else "r", alpha=0.2
            )
            panel.axvline(t.frequency_hz, color="g" if ok else "r", ls="--", lw=1)
        panel.set_title(f"{key[0]} {key[1]}: PSD, targets marked", fontsize=9)
        panel.set_xlabel("frequency (Hz)")
        panel.set_ylabel("rad$^2$/Hz")
        panel.grid(True, which="both", alpha=0.3)
    used = len(keys)
    model = verification.model
    if model is not None and targets.model is not None:
        ref = targets.model.system
        dt = float(ref.dt)
        f = np.geomspace(0.01, 0.5 / dt, 300)
        z = np.exp(2j * np.pi * f * dt)
        h_ref = np.array([complex(np.ravel(ref(zi))[0]) for zi in z])
        tf = model.to_tf()
        h_tw = np.array([complex(np.ravel(tf(zi))[0]) for zi in z])
        mag, ph = flat[used], flat[used + 1]
        mag.semilogx(f, 20 * np.log10(np.abs(h_ref)), "b--", label="target model (eq. 3.11)")
        mag.semilogx(f, 20 * np.log10(np.abs(h_tw)), "k", label="ARMAX of the twin's data")
        mag.set_ylabel("magnitude (dB)")
        ph.semilogx(f, np.degrees(np.unwrap(np.angle(h_ref))), "b--")
        ph.semilogx(f, np.degrees(np.unwrap(np.angle(h_tw))), "k")
        ph.set_ylabel("phase (deg)")
        for panel, title in ((mag, "1-DOF u1 -> pitch: magnitude"), (ph, "1-DOF u1 -> pitch: phase")):
            panel.set_xlabel("frequency (Hz)")
            panel.set_title(title, fontsize=9)
            panel.grid(True, which="both", alpha=0.3)
        mag.legend(fontsize=8)
        used += 2
    for panel in flat[used:]:
        panel.axis("off")
    return fig


def shipped_model_tables(spec: mujoco.MjSpec, evidence: bool = True) -> tuple[list, Verification]:
    """The calibration's tables for the main report, measured now on ``spec`` (one builder for both reports).

    Returns ``([target table, large-signal table, side-peak tables...], verification)``; the side-peak
    evidence (:func:`~trms.twin.calibration.elastic_modes.side_peak_evidence`) only when
    ``evidence``.
    """
    from ...experiments.tables import ComparisonTable
    from .elastic_modes import side_peak_evidence
    from .large_signal import large_signal_checks
    from .verify import verify

    targets = Targets.thesis()
    check = verify(spec, targets)
    seeds = [str(s) for s in check.seeds]
    cal = ComparisonTable(
        f"Calibration targets on the shipped twin (thesis's protocol, encoder on; seeds {', '.join(seeds)}, "
        "none of them used by the fit)",
        ["target", "thesis", *(f"seed {s}" for s in seeds), "tolerance", "met"],
    )
    for row in check.summary():
        once = "-" in row["achieved"]  # measured once, without a seed: shown under the first seed only
        missing = "measured once (no seed)" if once else float("nan")
        cal.rows.append(
            [
                row["name"],
                row["target"],
                *[missing if c is None else c for c in check.seed_cells(row)],
                row["tolerance"],
                "yes" if row["met"] else "no",
            ]
        )
    cal.notes = [f"{k}: {v}" for k, v in targets.notes.items()]
    cal.notes.append(coherence_floor_note())
    large = ComparisonTable(
        f"Large signals, 1-DOF from hover: the twin beside Feedback's published nonlinear model "
        f"(within {100 * TOLERANCE:g} %)",
        ["figure", "published model", "twin", "ratio", "met"],
    )
    large.rows = [[c.name, c.published, c.twin, c.ratio, "yes" if c.met else "no"] for c in large_signal_checks(spec)]
    tables = [cal, large]
    if evidence:
        ev = side_peak_evidence(spec)
        stats = ev["estimator_statistics"]
        est = ComparisonTable(
            f"The thesis's 1-DOF side peaks in the twin's spectra ({stats['n_seeds']} seeds, a >= 1 dB "
            f"peak within +-{stats['window_hz']:g} Hz)",
            ["estimator", *(f"{f} Hz" for f in next(iter(stats["rates"].values()))), "both"],
        )
        est.rows = [
            [name, *(100 * r for r in rates.values()), 100 * stats["both"][name]]
            for name, rates in stats["rates"].items()
        ]
        est.notes = [
            "Percent of runs with a peak near "
            + " or ".join(f"{f:g} Hz" for f in SIDE_PEAKS_HZ)
            + ", by the estimator of each row."
        ]
        struct = ComparisonTable(
            f"Compliant elements tuned for a {SIDE_PEAKS_HZ[0]:g} Hz mode: what each costs",
            [
                "candidate",
                "stiffness (N m/rad)",
                "1-DOF modes < 1 Hz",
                "deflection (rad/V)",
                "2-DOF modes < 1 Hz",
                "0.25 Hz reached",
            ],
        )
        struct.rows = [
            [
                c["name"],
                c["stiffness_n_m_per_rad"],
                ", ".join(f"{f:.3f}" for f in c["modes_1dof_hz"]) or "-",
                c["deflection_rad_per_volt"],
                ", ".join(f"{f:.3f}" for f in c["modes_2dof_hz"]) or "-",
                "yes" if c["reached"] else "no",
            ]
            for c in ev["structural_candidates"]
        ]
        listed = sorted({p.frequency_hz for p in targets.peaks if p.config == "2dof"})
        kept = sorted({p.frequency_hz for p in targets.peaks if p.config == "1dof"})
        struct.notes = [
            "Deflection: the compliant joint's static change per volt of main-rotor input at hover. Table 3.1 "
            f"lists only {' and '.join(f'{f:g}' for f in listed)} Hz in 2-DOF; the thesis's 1-DOF "
            f"{' and '.join(f'{f:g}' for f in kept)} Hz mode must stay."
        ]
        tables += [est, struct, *tradeoff_tables(spec)]
    return tables, check


def coherence_floor_note() -> str:
    """What the 2-DOF coherence estimate reads for two unrelated signals, with the segments the targets use and
    with the PSD's longer ones (measured now, :func:`~trms.twin.calibration.protocol.coherence_floor`)."""
    from .protocol import COHERENCE_NPERSEG, NPERSEG_LONG, THESIS_PROTOCOLS, VERIFY_REPEATS, coherence_floor

    p = next(p for p in THESIS_PROTOCOLS if p.config == "2dof")
    n = int(round(p.duration_s / p.sample_time))
    parts = []
    for nper in (COHERENCE_NPERSEG, NPERSEG_LONG):
        mean, p95 = coherence_floor(n, nper, VERIFY_REPEATS, sample_time=p.sample_time)
        parts.append(f"{nper}-sample segments {mean:.2f} (95 % of trials below {p95:.2f})")
    return (
        f"coherence floor: two unrelated white signals of the 2-DOF record's length ({n} samples, "
        f"{VERIFY_REPEATS} runs averaged) read a median coherence of " + "; ".join(parts) + "."
    )


def tradeoff_tables(spec: mujoco.MjSpec) -> list:
    """The two trade-offs of :mod:`~trms.twin.calibration.tradeoffs` as report tables, measured on ``spec``."""
    from ...experiments.tables import ComparisonTable
    from .coupling import MARGIN
    from .tradeoffs import coupling_tradeoff, phase_step_tradeoff

    model = Targets.thesis().model
    assert model is not None
    scan = phase_step_tradeoff(spec)
    ref_delay, ref_tc = step_figures(model.system)
    within = [r for r in scan.rows if r["phase_deg"] <= scan.phase_tolerance_deg]
    phase = ComparisonTable(
        f"Phase against the step figures: motor lag and transport delay scanned on the linearised 1-DOF twin "
        f"({len(within)} of {len(scan.rows)} settings within {scan.phase_tolerance_deg:g} deg of (3.11)'s phase)",
        ["motor lag (s)", "delay (s)", "phase from (3.11) (deg)", "step delay (s)", "time constant (s)"],
    )
    phase.rows = [
        [r["motor_lag"], r["input_delay"], r["phase_deg"], r["step_delay"], r["time_constant"]]
        for r in scan.rows
        if r["phase_deg"] <= 2 * scan.phase_tolerance_deg
    ]
    phase.notes = [
        f"Within the phase tolerance the smallest step delay is {scan.best_step_delay:.3g} s and the largest time "
        f"constant {scan.best_time_constant:.3g} s; the targets are (3.11)'s own step, delay {ref_delay:.3g} +- "
        f"{model.delay_tolerance_s:g} s and time constant {ref_tc:.3g} +- {model.time_constant_tolerance_s:g} s "
        f"(the thesis reads 'about 0.6-0.7 s' and 'around 1.2 s' off its rig's step, fig. 3.3). "
        "Rows shown: phase within twice the tolerance."
    ]
    coupling = coupling_tradeoff(spec)
    low = next(c.threshold for c in Targets.thesis().coherences if c.level == "low")
    couple = ComparisonTable(
        "u1 -> pitch at 0.1 Hz against u2 -> pitch's low coherence (2-DOF protocol)",
        [
            "coupling",
            "seed",
            "u1 -> pitch peak near 0.1 Hz (Hz)",
            "0.1 Hz met",
            "u2 -> pitch coherence",
            f"coherence <= {low:g}",
        ],
    )
    for label, res in coupling.items():
        for seed, row in res["by_seed"].items():
            couple.rows.append(
                [
                    label,
                    seed,
                    row.get("u1->pitch peak near 0.1 Hz", float("nan")),
                    "yes" if row.get("0.1 Hz met") else "no",
                    row.get("u2->pitch coherence", float("nan")),
                    "yes" if row.get("coherence met") else "no",
                ]
            )
    couple.notes = [
        "strongest: "
        + ", ".join(f"{k} = {v:g}" for k, v in coupling["strongest"]["parameters"].items())
        + " (the bounds' strongest yaw-rate-to-pitch coupling, no tail reaction on pitch).",
        f"The spectral fit keeps room for seeds it never saw: it scores a 'low' coherence against "
        f"{MARGIN:g} x its threshold ({low * MARGIN:.2g}).",
    ]
    return [phase, couple]
