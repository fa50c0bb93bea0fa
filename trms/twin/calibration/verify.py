"""Verification on the nonlinear, quantised twin with the thesis's spectral protocol, at seeds no fit saw.

Every target is measured the way the thesis measured it: PSD peaks and coherence from
PRBS runs (one input at a time), and a 4th-order ARMAX identified from the 1-DOF run
at 5 Hz; each verification seed is one complete, independent set of runs (a new PRBS
realisation and new encoder noise), and every target must hold at each. The rest pose
with the rotors off is solved once (it has no seed). The result is a table of
(target, seed, achieved, tolerance, met).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import mujoco
import numpy as np

from ...errors import InputError, check_in_range
from ...identification.polynomial import PolynomialModel
from ...plant import Record
from ..disturbances import Gust
from ..model import CONFIGURATIONS, build_model
from ..trim import rest_pose
from .protocol import (
    FIT_SEEDS,
    THESIS_PROTOCOLS,
    VERIFY_REPEATS,
    VERIFY_SEEDS,
    Protocol,
    averaged_spectra,
    identify_1dof,
    lightly_damped,
    main_peaks,
    repeated_records,
    step_figures,
)
from .targets import ModelTarget, Targets, parse_channel

__all__ = ["Check", "Verification", "spectral_checks", "model_checks", "rest_checks", "phase_difference_deg", "verify"]


@dataclass(frozen=True)
class Check:
    """One target's outcome (at one seed, or ``seed = None`` for a seedless figure).

    ``violation`` is 0 when the target is met and grows with the miss, in units of the
    tolerance (peaks: ``|f - f_target| / tol - 1``, 2 with no peak at all; coherence:
    the miss over 0.1); the spectral fit minimises its sum.
    """

    name: str
    target: float
    achieved: float
    tolerance: str
    met: bool
    unit: str = ""
    violation: float = 0.0
    seed: int | None = None

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

    @property
    def all_met(self) -> bool:
        """Whether every target is met at every seed."""
        return all(c.met for c in self.checks)

    def summary(self) -> list[dict]:
        """One row per target (name and value: a channel may have several peak targets): achieved at each seed,
        met at all."""
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
                    "met": True,
                },
            )
            row["achieved"][str(c.seed) if c.seed is not None else "-"] = (
                None if not np.isfinite(c.achieved) else c.achieved
            )
            row["met"] = row["met"] and c.met
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
        found = main_peaks(measured[0], measured[1], per_channel[(t.config, t.channel)] + 1)
        near = min(found, key=lambda x: abs(x - t.frequency_hz)) if found else float("nan")
        miss = abs(near - t.frequency_hz) / t.tolerance_hz if found else 3.0
        checks.append(
            Check(
                t.name,
                t.frequency_hz,
                near,
                f"+-{t.tolerance_hz:g} Hz, main peaks",
                bool(miss <= 1.0),
                "Hz",
                max(0.0, miss - 1.0),
                seed,
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


def model_checks(record: Record, mt: ModelTarget, seed: int | None = None) -> tuple[list[Check], PolynomialModel]:
    """The 1-DOF model targets on a 4th-order ARMAX identified from one protocol record."""
    ref = mt.system
    model = identify_1dof(record, decimate=max(1, int(round(ref.dt / record.sample_time))))
    f_ref, z_ref = lightly_damped(ref.poles(), float(ref.dt))
    f_tw, z_tw = lightly_damped(model.poles(), model.sample_time)
    gain_ref = float(np.ravel(ref.dcgain())[0])
    gain_tw = model.dc_gain()
    d_ref, tc_ref = step_figures(ref)
    d_ref = mt.delay_s if mt.delay_s is not None else d_ref
    tc_ref = mt.time_constant_s if mt.time_constant_s is not None else tc_ref
    tf = model.to_tf()
    d_tw, tc_tw = step_figures(tf)
    phase = phase_difference_deg(tf, ref, mt.phase_band_hz)
    ratio = z_tw / z_ref if z_ref else float("nan")
    checks = [
        _within("1dof ARMAX lightly damped mode", f_ref, f_tw, mt.mode_tolerance_hz, "Hz", seed),
        Check(
            "1dof ARMAX damping ratio",
            z_ref,
            z_tw,
            f"x/ {mt.damping_factor:g}",
            bool(1 / mt.damping_factor <= ratio <= mt.damping_factor),
            seed=seed,
        ),
        Check(
            "1dof ARMAX DC gain",
            gain_ref,
            gain_tw,
            f"+-{100 * mt.gain_tolerance:g} %",
            bool(abs(gain_tw - gain_ref) <= mt.gain_tolerance * abs(gain_ref)),
            "rad/V",
            seed=seed,
        ),
        Check(
            f"1dof ARMAX phase from (3.11), {mt.phase_band_hz[0]:g}-{mt.phase_band_hz[1]:g} Hz",
            0.0,
            phase,
            f"<= {mt.phase_tolerance_deg:g} deg",
            bool(phase <= mt.phase_tolerance_deg),
            "deg",
            seed=seed,
        ),
        _within("1dof step delay (to 5 %)", d_ref, d_tw, mt.delay_tolerance_s, "s", seed),
        _within("1dof step time constant (5 % to 63 %)", tc_ref, tc_tw, mt.time_constant_tolerance_s, "s", seed),
    ]
    return checks, model


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
    distinct and none of them a fit seed, :data:`~trms.twin.calibration.protocol.FIT_SEEDS`) whose spectra are
    averaged; the model targets use the first run (one ARMAX fit, as the thesis's).
    With ``gust``, every run has ambient gust torques (seeded with the run): the targets measured
    in moving air rather than the still air the calibration fits in.

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> from trms.twin.calibration import Targets
    >>> v = verify(load_spec(), Targets.thesis(), seeds=(101,))
    >>> sorted({c.seed for c in v.checks} - {None})
    [101]
    """
    if len(seeds) == 0:
        raise InputError("verify needs at least one seed; got none")
    repeats = int(check_in_range("repeats", repeats, 1, 100))
    runs = [int(seed) + 1000 * r for seed in seeds for r in range(repeats)]
    if len(set(runs)) != len(runs):
        raise InputError(
            f"seeds {tuple(seeds)} with {repeats} repeats (runs s, s + 1000, ...) use a run twice; "
            "give seeds whose runs are distinct"
        )
    if seen := sorted(set(runs) & set(FIT_SEEDS)):
        raise InputError(f"verification runs {seen} are fit seeds {FIT_SEEDS}; verify on seeds no fit saw")
    needed = {(t.config, parse_channel(t.channel, t.config)[0]) for t in targets.peaks}
    needed |= {(c.config, parse_channel(c.channel, c.config)[0]) for c in targets.coherences}
    needed |= {(r.config, parse_channel(ch, r.config)[0]) for r in targets.ratios for ch in (r.channel, r.reference)}
    if targets.model is not None:
        needed.add(("1dof", "u1"))
    chosen = [p for p in protocols if (p.config, p.excited) in needed]
    missing = needed - {(p.config, p.excited) for p in chosen}
    if missing:
        raise InputError(f"no protocol excites {sorted(missing)}; give protocols for every targeted channel")
    out = Verification([], seeds=tuple(int(s) for s in seeds))
    # Every seed's repeats of a protocol in one batch, so that the runs share the cores.
    by_protocol = {(p.config, p.excited): repeated_records(spec, p, runs, counts_per_rev, gust) for p in chosen}
    for i, seed in enumerate(out.seeds):
        records = {key: recs[i * repeats : (i + 1) * repeats] for key, recs in by_protocol.items()}
        spectra: dict = {}
        out.checks += spectral_checks(records, targets, spectra, seed=seed)
        if targets.model is not None:
            checks, model = model_checks(records[("1dof", "u1")][0], targets.model, seed)
            out.checks += checks
        if i == 0:
            out.records, out.spectra = records, spectra
            out.model = model if targets.model is not None else None
    out.checks += rest_checks(spec, targets)
    return out
