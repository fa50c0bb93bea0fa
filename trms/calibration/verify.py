"""Verification on the nonlinear, quantised twin with the thesis's protocols, at seeds no fit saw.

Every target is measured the way the thesis measured it: PSD peaks and coherence from
PRBS runs (one input at a time), a 4th-order ARMAX identified from the 1-DOF run at 5 Hz,
the ARMAX residual variance of ch. 5's training experiment, the rig's motion at rest, and
its mean small-signal step; each verification seed is one complete, independent set of runs
(new signal realisations, new ambient turbulence and encoder noise), and every target is
judged at each. The rest pose with the rotors off and the gyroscopic coupling are computed
once (they have no seed). The result is a table of (target, seed, achieved, tolerance, met).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import mujoco
import numpy as np

from trms.calibration.protocol import (
    FIT_SEEDS,
    HOVER_PROTOCOL,
    RESIDUAL_PROTOCOL,
    STEP_PROTOCOL,
    THESIS_PROTOCOLS,
    VERIFY_REPEATS,
    VERIFY_SEEDS,
    Protocol,
    armax_residual_variance,
    averaged_spectra,
    hover_rms,
    identify_1dof,
    lightly_damped,
    mean_step,
    ranked_peaks,
    repeated_records,
    step_fit_percent,
    system_step,
    tangent_figures,
)
from trms.calibration.targets import AmbientTarget, ModelTarget, Targets, parse_channel
from trms.errors import InputError, check_in_range
from trms.identification.polynomial import PolynomialModel
from trms.record import Record
from trms.twin.disturbances import Gust
from trms.twin.model import CONFIGURATIONS, build_model
from trms.twin.trim import rest_pose
from trms.twin.twin import Twin

__all__ = [
    "Check",
    "Verification",
    "spectral_checks",
    "model_checks",
    "step_checks",
    "ambient_checks",
    "rest_checks",
    "coupling_checks",
    "phase_difference_deg",
    "verify",
]


#: A target judged at several seeds (independent experiments) is met when it holds at this fraction of them at least:
#: 9 of 10. One experiment's spectra and ARMAX scatter with its PRBS realisation and the rig's ambient excitation, as
#: the thesis's did ("repeated until a response, undisturbed by gust, was obtained"); a target missed at one seed
#: in ten is a disturbed run, one missed at two is a twin that does not match.
MET_FRACTION = 0.9


@dataclass(frozen=True)
class Check:
    """One target's outcome (at one seed, or ``seed = None`` for a seedless figure).

    ``violation`` is 0 when the target is met and grows with the miss, in units of the
    tolerance (peaks: ``|f - f_target| / tol - 1``, 2 with no peak at all; coherence:
    the miss over 0.1); the spectral fit minimises its sum. A peak's ``lead_db`` is how far
    its prominence stands above the most prominent peak left out of the channel's main ones
    (how safely it is among them; NaN for other checks). ``runs`` holds the per-run values a median
    was taken of (the ARMAX figures; empty for other checks).
    """

    name: str
    target: float
    achieved: float
    tolerance: str
    met: bool
    unit: str = ""
    violation: float = 0.0
    seed: int | None = None
    lead_db: float = float("nan")
    runs: tuple[float, ...] = ()

    def to_dict(self) -> dict:
        """JSON-serialisable form (NaN as None)."""
        return {
            "name": self.name,
            "target": self.target,
            "achieved": None if not np.isfinite(self.achieved) else self.achieved,
            "tolerance": self.tolerance,
            "met": self.met,
            "unit": self.unit,
            "seed": self.seed,
        }


@dataclass
class Verification:
    """All checks, and the spectra and models they came from (for figures; those of the first seed)."""

    checks: list[Check]
    spectra: dict[tuple[str, str], tuple[np.ndarray, np.ndarray, np.ndarray]] = field(default_factory=dict)
    model: PolynomialModel | None = None
    records: dict[tuple[str, str], list[Record]] = field(default_factory=dict)
    seeds: tuple[int, ...] = ()
    step: tuple[np.ndarray, np.ndarray] | None = None

    def to_dict(self) -> dict:
        """JSON-serialisable form, everything but the records (:meth:`from_dict` reads it back)."""
        model = self.model
        return {
            "seeds": list(self.seeds),
            "checks": [
                {
                    **dataclasses.asdict(c),
                    "achieved": None if not np.isfinite(c.achieved) else c.achieved,
                    "lead_db": None if not np.isfinite(c.lead_db) else c.lead_db,
                    "runs": list(c.runs),
                }
                for c in self.checks
            ],
            "spectra": {f"{k[0]}|{k[1]}": [np.asarray(a).tolist() for a in v] for k, v in self.spectra.items()},
            "model": None
            if model is None
            else {
                **{k: np.asarray(getattr(model, k)).tolist() for k in ("A", "B", "C", "D", "F")},
                "sample_time": model.sample_time,
                "noise_variance": model.noise_variance,
                "n_samples": model.n_samples,
                "method": model.method,
                "input_name": model.input_name,
                "output_name": model.output_name,
            },
            "step": None if self.step is None else [np.asarray(a).tolist() for a in self.step],
        }

    @classmethod
    def from_dict(cls, data: Mapping) -> Verification:
        """The verification :meth:`to_dict` wrote (records left out)."""

        def number(x: float | None) -> float:
            return float("nan") if x is None else float(x)

        checks = [
            Check(**{**c, "achieved": number(c["achieved"]), "lead_db": number(c["lead_db"]), "runs": tuple(c["runs"])})
            for c in data["checks"]
        ]
        spectra = {tuple(k.split("|", 1)): tuple(np.asarray(a, float) for a in v) for k, v in data["spectra"].items()}
        m = data["model"]
        model = (
            None
            if m is None
            else PolynomialModel(
                np.asarray(m["A"], float),
                np.asarray(m["B"], float),
                np.asarray(m["C"], float),
                D=np.asarray(m["D"], float),
                F=np.asarray(m["F"], float),
                sample_time=m["sample_time"],
                noise_variance=m["noise_variance"],
                n_samples=m["n_samples"],
                method=m["method"],
                input_name=m["input_name"],
                output_name=m["output_name"],
            )
        )
        step = None if data["step"] is None else (np.asarray(data["step"][0]), np.asarray(data["step"][1]))
        return cls(checks, spectra, model, {}, tuple(data["seeds"]), step)  # type: ignore[arg-type]

    def met_at(self, name: str, target: float) -> tuple[int, int]:
        """At how many seeds a target (name and value) is met, of how many it was judged at (a seedless
        figure counts once)."""
        got = [c.met for c in self.checks if c.name == name and c.target == target]
        return sum(got), len(got)

    @property
    def all_met(self) -> bool:
        """Whether every target is met (:meth:`summary`: at :data:`MET_FRACTION` of the seeds at least)."""
        return all(row["met"] for row in self.summary())

    def summary(self) -> list[dict]:
        """One row per target (name and value: a channel may have several peak targets): achieved at each seed,
        ``met_at`` (seeds met, seeds judged) and ``met``: a seeded target at :data:`MET_FRACTION` of its seeds at
        least, a seedless one outright."""
        rows: dict[tuple[str, float], dict] = {}
        for c in self.checks:
            row = rows.setdefault(
                (c.name, c.target),
                {
                    "name": c.name,
                    "target": c.target,
                    "unit": c.unit,
                    "tolerance": c.tolerance,
                    "achieved": {},
                    "met_at": [0, 0],
                },
            )
            row["achieved"][str(c.seed) if c.seed is not None else "-"] = (
                None if not np.isfinite(c.achieved) else c.achieved
            )
            row["met_at"] = [row["met_at"][0] + int(c.met), row["met_at"][1] + 1]
        for row in rows.values():
            met, judged = row["met_at"]
            row["met"] = bool(met >= (np.ceil(MET_FRACTION * judged - 1e-9) if judged > 1 else judged))
        return list(rows.values())

    def seed_cells(self, row: dict) -> list[float | None]:
        """A :meth:`summary` row's achieved value under each seed; a row measured once, without a seed (the rest
        pose), under the first seed only."""
        got = row["achieved"]
        seeds = [str(s) for s in self.seeds]
        if "-" in got and not any(s in got for s in seeds):
            return [got["-"], *([None] * (len(seeds) - 1))]
        return [got.get(s) for s in seeds]


def spectral_checks(
    records: Mapping[tuple[str, str], Record | list[Record]],
    targets: Targets,
    spectra: dict[tuple[str, str], tuple[np.ndarray, np.ndarray, np.ndarray]] | None = None,
    seed: int | None = None,
) -> list[Check]:
    """Check the peak, coherence and ratio targets that ``records`` ((config, excited input) -> Record) cover.

    A list of Records (repeats of one protocol) is measured on its averaged spectra.
    ``spectra`` (optional) collects the (f, PSD, coherence) of each channel measured.
    """
    spectra = {} if spectra is None else spectra
    checks = []

    def runs(config: str, u: str) -> list[Record] | None:
        got = records.get((config, u))
        return None if got is None else (got if isinstance(got, list) else [got])

    def channel(config: str, ch: str) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        u, y = parse_channel(ch, config)
        recs = runs(config, u)
        if recs is None:
            return None
        if (config, ch) not in spectra:
            spectra[(config, ch)] = averaged_spectra(recs, y)
        return spectra[(config, ch)]

    per_channel: dict[tuple[str, str], int] = {}
    for t in targets.peaks:
        per_channel[(t.config, t.channel)] = per_channel.get((t.config, t.channel), 0) + 1
    for t in targets.peaks:
        measured = channel(t.config, t.channel)
        if measured is None:
            continue
        ranked = ranked_peaks(measured[0], measured[1])
        n_main = per_channel[(t.config, t.channel)] + 1
        found = ranked[:n_main]
        near = min(found, key=lambda x: abs(x[0] - t.frequency_hz)) if found else (float("nan"), 0.0)
        miss = abs(near[0] - t.frequency_hz) / t.tolerance_hz if found else 3.0
        left_out = ranked[n_main][1] if len(ranked) > n_main else 1.0  # else: the 1 dB a peak needs
        checks.append(
            Check(
                t.name,
                t.frequency_hz,
                near[0],
                f"+-{t.tolerance_hz:g} Hz, main peaks",
                bool(miss <= 1.0),
                "Hz",
                max(0.0, miss - 1.0),
                seed,
                near[1] - left_out if found else float("nan"),
            )
        )
    for c in targets.coherences:
        measured = channel(c.config, c.channel)
        if measured is None:
            continue
        f, _, coh = measured
        level = float(np.median(coh[(f >= c.band_hz[0]) & (f <= c.band_hz[1])]))
        miss = level - c.threshold if c.level == "low" else c.threshold - level
        checks.append(
            Check(
                c.name,
                c.threshold,
                level,
                f"{'<=' if c.level == 'low' else '>='} {c.threshold:g}",
                bool(miss <= 0),
                "",
                max(0.0, miss) / 0.1,
                seed,
            )
        )
    for r in targets.ratios:
        (u, y), (u_ref, y_ref) = parse_channel(r.channel, r.config), parse_channel(r.reference, r.config)
        recs, refs = runs(r.config, u), runs(r.config, u_ref)
        if recs is None or refs is None:
            continue

        def rms(rs: list[Record], out: str) -> float:
            return float(np.mean([np.std(x.deviations()[1][:, x.output_names.index(out)]) for x in rs]))

        ratio = rms(recs, y) / max(rms(refs, y_ref), 1e-300)
        checks.append(
            Check(
                r.name,
                r.max_ratio,
                ratio,
                f"<= {r.max_ratio:g}",
                bool(ratio <= r.max_ratio),
                "",
                max(0.0, ratio / r.max_ratio - 1.0),
                seed,
            )
        )
    for mv in targets.movements:
        u, y = parse_channel(mv.channel, mv.config)
        recs = runs(mv.config, u)
        if recs is None:
            continue
        counts = int(recs[0].metadata.get("counts_per_rev") or 0)
        if not counts:
            continue  # no encoder: nothing to count
        moved = hover_rms(recs, y) / (2 * np.pi / counts)
        checks.append(
            Check(
                mv.name,
                mv.min_counts,
                moved,
                f">= {mv.min_counts:g}",
                bool(moved >= mv.min_counts),
                "counts",
                max(0.0, 1.0 - moved / mv.min_counts),
                seed,
            )
        )
    return checks


def phase_difference_deg(system, reference_system, band_hz: tuple[float, float], n: int = 60) -> float:
    """Largest ``|phase(system) - phase(reference)|`` (deg) over ``band_hz``, both discrete at the same ``dt``."""
    dt = float(reference_system.dt)
    f = np.geomspace(band_hz[0], min(band_hz[1], 0.5 / dt * 0.999), n)
    z = np.exp(2j * np.pi * f * dt)
    h = np.array([complex(np.ravel(system(zi))[0]) for zi in z])
    h_ref = np.array([complex(np.ravel(reference_system(zi))[0]) for zi in z])
    return float(np.degrees(np.max(np.abs(np.angle(h / h_ref)))))


def _within(name: str, target: float, achieved: float, tolerance: float, unit: str, seed: int | None) -> Check:
    """A check met when ``|achieved - target| <= tolerance`` (in ``unit``)."""
    return Check(
        name, target, achieved, f"+-{tolerance:g} {unit}", bool(abs(achieved - target) <= tolerance), unit, seed=seed
    )


def model_checks(
    records: Record | Sequence[Record], mt: ModelTarget, seed: int | None = None
) -> tuple[list[Check], PolynomialModel]:
    """The 1-DOF model targets on 4th-order ARMAX models, one identified from each protocol record.

    With several records (the repeats of one experiment), each figure is the median over their models: one
    run's ARMAX scatters with its PRBS realisation and the rig's ambient excitation, and the median keeps one
    disturbed run from deciding, as the thesis repeated runs until one was undisturbed. Returns the checks and
    the first record's model.
    """
    ref = mt.system
    runs = [records] if isinstance(records, Record) else list(records)
    if not runs:
        raise InputError("model_checks needs at least one 1-DOF record")
    models = [identify_1dof(r, decimate=max(1, int(round(ref.dt / r.sample_time)))) for r in runs]
    model = models[0]
    f_ref, z_ref = lightly_damped(ref.poles(), float(ref.dt))
    gain_ref = float(np.ravel(ref.dcgain())[0])
    figures = np.array(
        [
            [
                *lightly_damped(m.poles(), m.sample_time),
                m.dc_gain(),
                phase_difference_deg(m.to_tf(), ref, mt.phase_band_hz),
            ]
            for m in models
        ]
    )
    f_tw, z_tw, gain_tw, phase = (float(x) for x in np.median(figures, axis=0))
    per_run = [tuple(float(x) for x in column) for column in figures.T]
    ratio = z_tw / z_ref if z_ref else float("nan")
    checks = [
        dataclasses.replace(
            _within("1dof ARMAX lightly damped mode", f_ref, f_tw, mt.mode_tolerance_hz, "Hz", seed), runs=per_run[0]
        ),
        Check(
            "1dof ARMAX damping ratio",
            z_ref,
            z_tw,
            f"x/ {mt.damping_factor:g}",
            bool(1 / mt.damping_factor <= ratio <= mt.damping_factor),
            seed=seed,
            runs=per_run[1],
        ),
        Check(
            "1dof ARMAX DC gain",
            gain_ref,
            gain_tw,
            f"+-{100 * mt.gain_tolerance:g} %",
            bool(abs(gain_tw - gain_ref) <= mt.gain_tolerance * abs(gain_ref)),
            "rad/V",
            seed=seed,
            runs=per_run[2],
        ),
        Check(
            f"1dof ARMAX phase from (3.11), {mt.phase_band_hz[0]:g}-{mt.phase_band_hz[1]:g} Hz",
            0.0,
            phase,
            f"<= {mt.phase_tolerance_deg:g} deg",
            bool(phase <= mt.phase_tolerance_deg),
            "deg",
            seed=seed,
            runs=per_run[3],
        ),
    ]
    return checks, model


def step_checks(time: np.ndarray, response: np.ndarray, mt: ModelTarget, seed: int | None = None) -> list[Check]:
    """The step targets on a mean step per volt (:func:`~trms.calibration.protocol.mean_step`), read as
    ``mt.system``'s own step is: tangent dead time and time constant, and the NRMSE fit to it."""
    t_ref, y_ref = system_step(mt.system, float(time[-1]) + float(mt.system.dt))
    dead_ref, lag_ref = tangent_figures(t_ref, y_ref)
    dead, lag = tangent_figures(time, response)
    n = min(len(time), len(t_ref))
    if not np.allclose(time[:n], t_ref[:n]):
        raise InputError(f"the step must be sampled at the target model's {float(mt.system.dt):g} s from its start")
    fit = step_fit_percent(time[:n], response[:n], y_ref[:n])
    return [
        _within("1dof step dead time (tangent)", dead_ref, dead, mt.dead_time_tolerance_s, "s", seed),
        _within("1dof step time constant (tangent)", lag_ref, lag, mt.time_constant_tolerance_s, "s", seed),
        Check(
            "1dof step fit to (3.11)'s (NRMSE, 0-15 s)",
            mt.step_fit_percent,
            fit,
            f">= {mt.step_fit_percent:g} %",
            bool(fit >= mt.step_fit_percent),
            "%",
            seed=seed,
        ),
    ]


def ambient_checks(
    hover: list[Record], residual: Record, target: AmbientTarget, seed: int | None = None
) -> list[Check]:
    """The rig at rest: hover pitch RMS within its range, and Table 5.1's ARMAX residual variance."""
    lo, hi = target.hover_rms
    rms = hover_rms(hover, "pitch")
    var = armax_residual_variance(residual)
    tol = target.tolerance * target.residual_variance
    return [
        Check(
            "2dof hover pitch RMS, constant inputs",
            0.5 * (lo + hi),
            rms,
            f"{lo:g}-{hi:g} rad",
            bool(lo <= rms <= hi),
            "rad",
            max(0.0, (lo - rms) / lo, (rms - hi) / hi),
            seed,
        ),
        Check(
            "1dof ARMAX residual variance (Table 5.1)",
            target.residual_variance,
            var,
            f"+-{100 * target.tolerance:g} %",
            bool(abs(var - target.residual_variance) <= tol),
            "rad^2",
            max(0.0, abs(var - target.residual_variance) / tol - 1.0),
            seed,
        ),
    ]


def coupling_checks(spec: mujoco.MjSpec, targets: Targets) -> list[Check]:
    """The gyroscopic coupling (pitch torque per yaw rate at hover) against ``targets.coupling``."""
    if targets.coupling is None:
        return []
    c = targets.coupling
    k = Twin("2dof", 0.1, spec=spec, still_air=True).yaw_rate_to_pitch_torque()
    miss = abs(k - c.value) / (c.tolerance * c.value)
    return [
        Check(
            "2dof pitch torque per yaw rate at hover",
            c.value,
            k,
            f"+-{100 * c.tolerance:g} %",
            bool(miss <= 1.0),
            "N m s/rad",
            max(0.0, miss - 1.0),
        )
    ]


def rest_checks(spec: mujoco.MjSpec, targets: Targets) -> list[Check]:
    """The 2-DOF rest pose with the rotors off against ``targets.rest``."""
    if targets.rest is None:
        return []
    m = build_model(spec, CONFIGURATIONS["2dof"], delay=False)
    q = rest_pose(m)
    pitch, yaw = (float(q[m.jnt_qposadr[m.joint(a).id]]) for a in ("pitch", "yaw"))
    r = targets.rest
    return [
        _within("2dof rest pitch, rotors off", r.pitch, pitch, r.tolerance, "rad", None),
        _within("2dof rest yaw, rotors off", 0.0, yaw, r.yaw_tolerance, "rad", None),
    ]


#: Seed offset of the mirror (down) step of each step run: its own ambient realisation, as on the rig.
MIRROR_SEED_OFFSET = 500


def verify(
    spec: mujoco.MjSpec,
    targets: Targets,
    protocols: Sequence[Protocol] = THESIS_PROTOCOLS,
    counts_per_rev: int | None = None,
    seeds: Sequence[int] = VERIFY_SEEDS,
    repeats: int = VERIFY_REPEATS,
    gust: Gust | None = None,
) -> Verification:
    """Measure every target on the nonlinear twin built from ``spec``, independently at each of ``seeds``.

    Each seed is one experiment of ``repeats`` (1 to 100) runs of every protocol (seeds ``s + 1000 r``, all
    distinct and none of them a fit seed, :data:`~trms.calibration.protocol.FIT_SEEDS`) whose spectra are
    averaged; the ARMAX targets are the median over the 1-DOF runs' fits (:func:`model_checks`). With an ambient
    target, the
    rig at rest (:data:`~trms.calibration.protocol.HOVER_PROTOCOL`, ``repeats`` runs) and ch. 5's training
    experiment (:data:`~trms.calibration.protocol.RESIDUAL_PROTOCOL`, one run); with a model target, the
    step (:data:`~trms.calibration.protocol.STEP_PROTOCOL`, ``repeats`` runs up and as many down, the down
    runs at seeds ``s + 1000 r +`` :data:`MIRROR_SEED_OFFSET`). Every run has the rig's ambient excitation; with
    ``gust``, gust torques too (seeded with the run): the targets measured in moving air.

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> from trms.calibration import Targets
    >>> v = verify(load_spec(), Targets.thesis(), seeds=(101,), repeats=1)
    >>> sorted({c.seed for c in v.checks} - {None})
    [101]
    """
    if len(seeds) == 0:
        raise InputError("verify needs at least one seed; got none")
    repeats = int(check_in_range("repeats", repeats, 1, 100))
    runs = [int(seed) + 1000 * r for seed in seeds for r in range(repeats)]
    mirrors = [s + MIRROR_SEED_OFFSET for s in runs] if targets.model is not None else []
    if len(set(runs) | set(mirrors)) != len(runs) + len(mirrors):
        raise InputError(
            f"seeds {tuple(seeds)} with {repeats} repeats (runs s, s + 1000, ..., and the mirror steps' "
            f"s + {MIRROR_SEED_OFFSET}, ...) use a run twice; give seeds whose runs are distinct"
        )
    if seen := sorted((set(runs) | set(mirrors)) & set(FIT_SEEDS)):
        raise InputError(f"verification runs {seen} are fit seeds {FIT_SEEDS}; verify on seeds no fit saw")
    needed = {(t.config, parse_channel(t.channel, t.config)[0]) for t in targets.peaks}
    needed |= {(c.config, parse_channel(c.channel, c.config)[0]) for c in targets.coherences}
    needed |= {(r.config, parse_channel(ch, r.config)[0]) for r in targets.ratios for ch in (r.channel, r.reference)}
    needed |= {(m.config, parse_channel(m.channel, m.config)[0]) for m in targets.movements}
    if targets.model is not None:
        needed.add(("1dof", "u1"))
    chosen = [p for p in protocols if (p.config, p.excited) in needed]
    missing = needed - {(p.config, p.excited) for p in chosen}
    if missing:
        raise InputError(f"no protocol excites {sorted(missing)}; give protocols for every targeted channel")
    out = Verification([], seeds=tuple(int(s) for s in seeds))
    # Every seed's repeats of a protocol in one batch, so that the runs share the cores.
    by_protocol = {(p.config, p.excited): repeated_records(spec, p, runs, counts_per_rev, gust) for p in chosen}
    if targets.ambient is not None:
        hover = repeated_records(spec, HOVER_PROTOCOL, runs, counts_per_rev, gust)
        residual = repeated_records(spec, RESIDUAL_PROTOCOL, [int(s) for s in seeds], counts_per_rev, gust)
    if targets.model is not None:
        down = dataclasses.replace(STEP_PROTOCOL, amplitude_v=-STEP_PROTOCOL.amplitude_v)
        steps_up = repeated_records(spec, STEP_PROTOCOL, runs, counts_per_rev, gust)
        steps_down = repeated_records(spec, down, mirrors, counts_per_rev, gust)
    for i, seed in enumerate(out.seeds):
        mine = slice(i * repeats, (i + 1) * repeats)
        records = {key: recs[mine] for key, recs in by_protocol.items()}
        spectra: dict = {}
        out.checks += spectral_checks(records, targets, spectra, seed=seed)
        if targets.model is not None:
            checks, model = model_checks(records[("1dof", "u1")], targets.model, seed)
            step = mean_step(steps_up[mine], steps_down[mine])
            out.checks += checks + step_checks(*step, targets.model, seed)
        if targets.ambient is not None:
            out.checks += ambient_checks(hover[mine], residual[i], targets.ambient, seed)
        if i == 0:
            out.records, out.spectra = records, spectra
            out.model = model if targets.model is not None else None
            out.step = step if targets.model is not None else None
    out.checks += rest_checks(spec, targets) + coupling_checks(spec, targets)
    return out
