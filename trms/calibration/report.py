"""The calibration report: ``calibration.json`` and ``calibration.png``.

The figure shows the calibrated twin's PSDs from the thesis's protocol with every target
frequency marked (green: met, red: not), the 1-DOF model identified from the twin's
data over the target model (eq. 3.11 by default), in magnitude and phase, and the twin's
static pitch curve beside the published model's (:mod:`.static_pitch`). The tables give the
targets, the large signals and every calibrated parameter's role: physical, beside its
published value, or lumped, with what it stands for (:func:`parameter_table`).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from matplotlib.figure import Figure

from trms.calibration.calibrate import CalibrationResult
from trms.calibration.large_signal import TOLERANCE
from trms.calibration.static_pitch import StaticPitch, plot_static_pitch
from trms.calibration.targets import SIDE_PEAKS_HZ, Targets
from trms.calibration.verify import MET_FRACTION, Verification
from trms.files import atomic_write
from trms.measurement.step_response import crossing_figures, step_fit_percent, system_step, tangent_figures
from trms.present.figures import new_axes, save_figure
from trms.present.tables import ComparisonTable
from trms.reference import CHOSEN_HERE, FROM_EQ_3_11, LITERATURE, PRINTED
from trms.twin.parameters import PARAMETERS, SOURCES, read_parameters

__all__ = ["write_report", "plot_targets", "format_table", "parameter_table", "target_source"]

#: The thesis's targets by what their names hold, and where each value comes from (:data:`trms.reference.SOURCES`):
#: the first pattern a check's name holds decides.
_SOURCES = (
    ("PSD peak", PRINTED),
    ("(Table 5.1)", PRINTED),
    ("ARMAX lightly damped mode", FROM_EQ_3_11),
    ("ARMAX damping ratio", FROM_EQ_3_11),
    ("ARMAX DC gain", FROM_EQ_3_11),
    ("phase from (3.11)", FROM_EQ_3_11),
    ("step dead time", FROM_EQ_3_11),
    ("step time constant", FROM_EQ_3_11),
    ("rest pitch", LITERATURE),
    ("pitch torque per yaw rate", LITERATURE),
)


def target_source(name: str) -> str:
    """Where the value of the thesis's target ``name`` comes from: printed in the thesis, derived from eq. (3.11),
    published elsewhere, or chosen here (a coherence level, a ratio, a count, the hover RMS, a fit, the rest yaw).

    Examples
    --------
    >>> target_source("2dof u2->yaw PSD peak"), target_source("1dof ARMAX DC gain")
    ('thesis (printed)', 'from eq. 3.11')
    >>> target_source("2dof rest pitch, rotors off"), target_source("2dof u1->pitch median coherence 0.02-1 Hz")
    ('literature', 'target chosen here')
    """
    return next((source for pattern, source in _SOURCES if pattern in name), CHOSEN_HERE)


def parameter_table(values: Mapping[str, float], start: Mapping[str, float] | None = None) -> ComparisonTable:
    """The parameters with their role: physical ones beside their published value with the departure, lumped ones
    with what they stand for.

    Parameters
    ----------
    values : mapping of str to float
        The parameters' values (units of :data:`~trms.twin.parameters.PARAMETERS`).
    start : mapping of str to float, optional
        Where a calibration started from: adds a ``start`` column.

    Returns
    -------
    ComparisonTable
        One row per parameter; the departure is ``value / published - 1`` (%), ``-`` where the published value
        is 0.

    Examples
    --------
    >>> table = parameter_table({"main_motor_gain": 2.2, "counterweight_mass": 0.068})
    >>> for row in table.rows:
    ...     print(row[:5])
    ['main_motor_gain', 'lumped', '2.2', '1.1 [S]', '+100 %']
    ['counterweight_mass', 'physical', '0.068', '0.068 [F]', '+0 %']
    """
    columns = ["parameter", "role", "value", "published", "departure", "unit", "what it is"]
    if start is not None:
        columns.insert(2, "start")
    table = ComparisonTable(
        "The twin's parameters: physical (beside the published value) or lumped (what each stands for)", columns
    )
    for name, value in values.items():
        p = PARAMETERS[name]
        departure = p.departure(value)
        row: list[object] = [
            name,
            p.role,
            f"{value:.4g}",
            f"{p.published:.4g} [{p.source}]",
            f"{100 * departure:+.0f} %" if np.isfinite(departure) else "-",
            p.unit or "-",
            f"stands for {p.stands_for}" if p.role == "lumped" else p.description,
        ]
        if start is not None:
            row.insert(2, f"{start[name]:.4g}")
        table.rows.append(row)
    used = sorted({PARAMETERS[n].source for n in values}, key=list(SOURCES).index)
    table.notes = [
        "Physical: the quantity its name says, read against its published value; lumped: a knob that carries what "
        "the model has no element for. Departure: value / published - 1. Published values' sources: "
        + "; ".join(f"[{k}] {SOURCES[k]}" for k in used)
        + " (each cited beside its value in the MJCF)."
    ]
    return table


def format_table(result: CalibrationResult) -> str:
    """The target table (target, achieved at each verification seed, tolerance, met at all) as Markdown.

    Parameters
    ----------
    result : CalibrationResult
        The calibration (its verification and large-signal checks).

    Returns
    -------
    str
        Markdown: one row per target (values in their units), then the large-signal table, the static pitch
        curve and the calibrated parameters' roles (those the result holds).

    Examples
    --------
    >>> from trms.calibration.checks import Check
    >>> ver = Verification([Check("peak", 0.34, 0.33, "+-0.03 Hz", True, "Hz", seed=101)], seeds=(101,))
    >>> print(format_table(CalibrationResult({}, {}, ver, [], {}, Targets())).splitlines()[2])
    | peak | 0.34 Hz | 0.33 | +-0.03 Hz | 1/1 | yes |
    """
    seeds = [str(s) for s in result.verification.seeds]
    lines = [
        "| target | value | " + " | ".join(f"seed {s}" for s in seeds) + " | tolerance | met at | met |",
        "|---|---|" + "---|" * len(seeds) + "---|---|---|",
    ]
    for row in result.verification.summary():
        cells = ["-" if c is None else f"{c:.4g}" for c in result.verification.seed_cells(row)]
        lines.append(
            f"| {row['name']} | {row['target']:.4g} {row['unit']} | "
            + " | ".join(cells)
            + f" | {row['tolerance']} | {row['met_at'][0]}/{row['met_at'][1]} | {'yes' if row['met'] else 'no'} |"
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
    if result.static_pitch is not None:
        lines += ["", result.static_pitch.table().to_markdown().rstrip()]
    if result.values:
        lines += ["", parameter_table(result.values, result.start).to_markdown().rstrip()]
    return "\n".join(lines)


def write_report(
    result: CalibrationResult, folder: str | os.PathLike[str], evidence: dict | None = None
) -> tuple[Path, Path]:
    """Write ``calibration.json`` and ``calibration.png`` into ``folder``; return their paths.

    ``evidence`` (:func:`~trms.calibration.elastic_modes.side_peak_evidence`) adds the measured evidence
    section.

    Parameters
    ----------
    result : CalibrationResult
        The calibration.
    folder : path-like
        Where to write (created if missing).
    evidence : dict, optional
        The side-peak evidence.

    Returns
    -------
    (pathlib.Path, pathlib.Path)
        The JSON report and the figure.

    Examples
    --------
    >>> import tempfile
    >>> from trms.calibration.checks import Check
    >>> from trms.calibration.target_kinds import PeakTarget
    >>> f = np.linspace(0.0, 2.0, 101)
    >>> spectra = {("1dof", "u1->pitch"): (f, 1.0 + np.exp(-(((f - 0.34) / 0.02) ** 2)), np.ones_like(f))}
    >>> target = PeakTarget("1dof", "u1->pitch", 0.34)
    >>> ver = Verification([Check(target.name, 0.34, 0.34, "+-0.03 Hz", True, "Hz", seed=101)], spectra, seeds=(101,))
    >>> result = CalibrationResult({}, {}, ver, [], {}, Targets([target]))
    >>> [p.name for p in write_report(result, tempfile.mkdtemp())]
    ['calibration.json', 'calibration.png']
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    js = folder / "calibration.json"
    data = result.to_dict()
    if evidence is not None:
        data["evidence"] = evidence
    atomic_write(js, lambda fh: fh.write(json.dumps(data, indent=2)), binary=False)
    figure = plot_targets(result.verification, result.targets, static=result.static_pitch)
    png = save_figure(figure, folder / "calibration.png", dpi=110)
    return js, png


def plot_targets(
    verification: Verification, targets: Targets, ax: Any = None, static: StaticPitch | None = None
) -> Figure:
    """The twin's PSDs with every target frequency marked, its identified 1-DOF model over the target model, and
    (``static``) its static pitch curve beside the published model's.

    Parameters
    ----------
    verification : Verification
        What :func:`~trms.calibration.verify` measured (its spectra and identified model).
    targets : Targets
        The targets it was measured against.
    ax : sequence of matplotlib Axes, optional
        One Axes per panel (a PSD per target channel, then magnitude and phase when there is a model
        target, then pitch and gain with ``static``); by default a new figure, three panels a row, on
        matplotlib's Agg canvas.
    static : StaticPitch, optional
        The static pitch curve (:func:`~trms.calibration.static_pitch.static_pitch_curves`).

    Returns
    -------
    matplotlib.figure.Figure
        Write it with :func:`trms.present.figures.save_figure`.

    Raises
    ------
    InputError
        ``ax`` holds another number of Axes than there are panels.

    Examples
    --------
    >>> from trms.calibration.checks import Check
    >>> from trms.calibration.target_kinds import PeakTarget
    >>> f = np.linspace(0.0, 2.0, 101)
    >>> spectra = {("1dof", "u1->pitch"): (f, 1.0 + np.exp(-(((f - 0.34) / 0.02) ** 2)), np.ones_like(f))}
    >>> target = PeakTarget("1dof", "u1->pitch", 0.34)
    >>> ver = Verification([Check(target.name, 0.34, 0.34, "+-0.03 Hz", True, "Hz", seed=101)], spectra, seeds=(101,))
    >>> fig = plot_targets(ver, Targets([target]))
    >>> fig.axes[0].get_title()
    '1dof u1->pitch: PSD, targets marked'
    """
    spectra = verification.spectra
    peaks_by_key: dict[tuple[str, str], list] = {}
    for t in targets.peaks:
        peaks_by_key.setdefault((t.config, t.channel), []).append(t)
    keys = list(peaks_by_key)
    n_panels = len(keys) + (2 if verification.model is not None and targets.model is not None else 0)
    n_panels += 2 if static is not None else 0
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
    if static is not None:
        plot_static_pitch(static, ax=flat[used : used + 2])
        used += 2
    for panel in flat[used:]:
        panel.axis("off")
    return fig


def shipped_model_tables(spec: mujoco.MjSpec, evidence: bool = True) -> tuple[list, Verification]:
    """The calibration's tables for the main report, measured on ``spec`` (one builder for both reports).

    Returns ``([target table, step table, large-signal table, side-peak tables..., static pitch table,
    parameter table], verification)``; the side-peak evidence
    (:func:`~trms.calibration.elastic_modes.side_peak_evidence`) only when ``evidence``. The verification, the
    large-signal checks, the static pitch curve and the evidence come from
    :func:`~trms.calibration.evidence.measured`, :func:`~trms.calibration.evidence.measured_large_signal` and
    :func:`~trms.calibration.evidence.measured_static_pitch`: computed once per model and code.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The model.
    evidence : bool
        Add the side-peak tables.

    Returns
    -------
    (list of ComparisonTable, Verification)
        The tables (values in the units their headers name) and the verification they show.

    Examples
    --------
    A model whose verification is in the user's cache (a fresh one is measured in about a minute):

    >>> import json, os, tempfile
    >>> from trms.calibration.checks import Check
    >>> from trms.calibration.evidence import fingerprint, user_cache
    >>> from trms.twin import load_spec
    >>> spec = load_spec()
    >>> spec.modelname = "tables example"
    >>> old = os.environ.get("XDG_CACHE_HOME")
    >>> os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp()
    >>> stored = Verification([Check("peak", 0.34, 0.34, "+-0.03 Hz", True, "Hz", seed=101)], seeds=(101,))
    >>> store = user_cache() / f"evidence-{fingerprint(spec)[:32]}.json"
    >>> store.parent.mkdir(parents=True)
    >>> _ = store.write_text(json.dumps({"fingerprint": fingerprint(spec), "verification": stored.to_dict()}))
    >>> tables, ver = shipped_model_tables(spec, evidence=False)
    >>> len(tables), ver.seeds, tables[0].rows[0][0], tables[-1].rows[0][:2]
    (4, (101,), 'peak', ['counterweight_mass', 'physical'])
    >>> _ = os.environ.pop("XDG_CACHE_HOME") if old is None else os.environ.update(XDG_CACHE_HOME=old)
    """
    from trms.calibration.evidence import measured_large_signal, measured_static_pitch, measured_targets

    targets = Targets.thesis()
    check, ev = measured_targets(spec, side_peaks=evidence)
    seeds = [str(s) for s in check.seeds]
    cal = ComparisonTable(
        f"Calibration targets on the shipped twin (thesis's protocol, encoder on; seeds {', '.join(seeds)}, "
        "none of them used by the fit)",
        ["target", "value", "source", *(f"seed {s}" for s in seeds), "tolerance", "met at", "met"],
    )
    for row in check.summary():
        once = "-" in row["achieved"]  # measured once, without a seed: shown under the first seed only
        missing = "measured once (no seed)" if once else float("nan")
        cal.rows.append(
            [
                row["name"],
                row["target"],
                target_source(row["name"]),
                *[missing if c is None else c for c in check.seed_cells(row)],
                row["tolerance"],
                f"{row['met_at'][0]}/{row['met_at'][1]}",
                "yes" if row["met"] else "no",
            ]
        )
    cal.notes = [
        f"source: where each target value comes from: {PRINTED} (Table 3.1's modes, Table 5.1's variance), "
        f"{FROM_EQ_3_11} (computed here from its printed coefficients), {LITERATURE} (Rotondo et al.'s rest pose, "
        f"Feedback's model's Kgy), {CHOSEN_HERE} (where the thesis prints a word, 'low', 'high', 'a minor oscillatory "
        "tendency', or nothing)."
    ]
    cal.notes += [f"{k}: {v}" for k, v in targets.notes.items()]
    cal.notes.append(
        f"met: at {MET_FRACTION:.0%} of the seeds at least (a seedless figure outright); 'met at' counts them."
    )
    cal.notes.append(coherence_floor_note())
    large = ComparisonTable(
        f"Large signals, 1-DOF from hover: the twin beside Feedback's published nonlinear model "
        f"(within {100 * TOLERANCE:g} %)",
        ["figure", "published model", "twin", "ratio", "met"],
    )
    large.rows = [[c.name, c.published, c.twin, c.ratio, "yes" if c.met else "no"] for c in measured_large_signal(spec)]
    tables = [cal, large]
    if evidence:
        assert ev is not None
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
        tables += [est, struct]
    tables += [measured_static_pitch(spec).table(), parameter_table(read_parameters(spec))]
    step = step_table(check, targets)
    if step is not None:
        tables.insert(1, step)
    return tables, check


def coherence_floor_note() -> str:
    """What the 2-DOF coherence estimate reads for two unrelated signals, with the segments the targets use and
    with the PSD's longer ones (measured now, :func:`~trms.measurement.spectra.coherence_floor`: some 6 s).

    Returns
    -------
    str
        One sentence: the median coherence (dimensionless) and its 95th percentile for each segment length.

    Examples
    --------
    >>> print(coherence_floor_note())
    coherence floor: two unrelated white signals of the 2-DOF record's length (1200 samples, 3 runs averaged) read
    a median coherence of 256-sample segments 0.12 (95 % of trials below 0.15); 512-sample segments 0.33 ...
    """
    from trms.measurement.protocol import THESIS_PROTOCOLS, VERIFY_REPEATS
    from trms.measurement.spectra import COHERENCE_NPERSEG, NPERSEG_LONG, coherence_floor

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


def step_table(verification: Verification, targets: Targets) -> Any:
    """The step of the rig by both definitions: eq. (3.11)'s own step and the twin's mean step (first seed and the
    spread over every verification seed), beside the thesis's readings off its rig's step (fig. 3.3).

    The tangent figures and the fit are the targets; the 5 % crossing and the 5-63 % time are examined:
    (3.11) crosses 5 % through its first-sample response, which no transport-delayed plant has.

    Parameters
    ----------
    verification : Verification
        Its mean step per volt (time in s, response in rad/V) and step checks.
    targets : Targets
        The model target.

    Returns
    -------
    ComparisonTable or None
        Dead times and time constants (s) and the fit (%); None without a model target or a step.

    Examples
    --------
    The target model's own step reads as the target's:

    >>> from trms.measurement.step_response import system_step
    >>> targets = Targets.thesis()
    >>> table = step_table(Verification([], step=system_step(targets.model.system, 40.0)), targets)
    >>> table.rows[0][0], table.rows[0][2] == table.rows[0][3]
    ('dead time, tangent (s)', True)
    """
    model = targets.model
    if model is None or verification.step is None:
        return None
    t, y = verification.step
    t_ref, y_ref = system_step(model.system, float(t[-1]) + float(model.system.dt))

    def spread(name: str) -> str:
        got = [c.achieved for c in verification.checks if c.name == name]
        return f"{min(got):.3g}-{max(got):.3g}" if got else "-"

    tangent, tangent_ref = tangent_figures(t, y), tangent_figures(t_ref, y_ref)
    crossing, crossing_ref = crossing_figures(t, y), crossing_figures(t_ref, y_ref)
    table = ComparisonTable(
        "The step by both definitions: eq. (3.11)'s step and the twin's mean small-signal step",
        ["figure", "thesis (fig. 3.3)", "eq. (3.11)", "twin (first seed)", "twin (all seeds)", "role"],
    )
    table.rows = [
        ["dead time, tangent (s)", "-", tangent_ref[0], tangent[0], spread("1dof step dead time (tangent)"), "target"],
        [
            "time constant, tangent (s)",
            "-",
            tangent_ref[1],
            tangent[1],
            spread("1dof step time constant (tangent)"),
            "target",
        ],
        ["delay, 5 % crossing (s)", "0.6-0.7", crossing_ref[0], crossing[0], "-", "examined"],
        ["time constant, 5 % to 63 % (s)", "about 1.2", crossing_ref[1], crossing[1], "-", "examined"],
        [
            "NRMSE fit to (3.11)'s step, first 15 s (%)",
            "-",
            100.0,
            step_fit_percent(t, y, y_ref[: len(t)]),
            spread("1dof step fit to (3.11)'s (NRMSE, 0-15 s)"),
            "target",
        ],
    ]
    table.notes = [
        "Twin: the mean over the runs of (y+ - y-) / 2A for steps of +-A from hover (the two signs cancel the thrust "
        "curve's curvature, the runs the ambient excitation), read by the same functions as (3.11)'s step. "
        "(3.11)'s 5 % crossing comes from its first-sample response (b1 = "
        f"{float(np.ravel(model.system.num[0][0])[0]):.4g} rad/V at {float(model.system.dt):g} s), which no "
        "transport-delayed plant has; the thesis's readings are off its rig's step plot, by a construction it does "
        "not state."
    ]
    return table
