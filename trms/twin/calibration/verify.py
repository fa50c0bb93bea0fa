"""Verification on the nonlinear, quantised twin with the thesis's spectral protocol.

Every target is measured the way the thesis measured it: PSD peaks and coherence from
PRBS runs (one input at a time), and a 4th-order ARMAX identified from the 1-DOF run
at 5 Hz. The result is a table of (target, achieved, tolerance, met).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import mujoco
import numpy as np

from ...errors import InputError
from ...plant import Record

from .protocol import (THESIS_PROTOCOLS, Protocol, channel_spectra, identify_1dof, lightly_damped, peaks_of,
                       protocol_records, step_figures)
from .targets import Targets, parse_channel

__all__ = ["Check", "Verification", "spectral_checks", "verify"]


@dataclass(frozen=True)
class Check:
    """One target's outcome.

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

    def to_dict(self) -> dict:
        """JSON-serialisable form (NaN as None)."""
        return {"name": self.name, "target": self.target,
                "achieved": None if not np.isfinite(self.achieved) else self.achieved,
                "tolerance": self.tolerance, "met": self.met, "unit": self.unit}


@dataclass
class Verification:
    """All checks, and the spectra they came from (for figures)."""

    checks: list[Check]
    spectra: dict[tuple[str, str], tuple[np.ndarray, np.ndarray, np.ndarray]] = field(default_factory=dict)
    model: object | None = None
    records: dict[tuple[str, str], object] = field(default_factory=dict)

    @property
    def all_met(self) -> bool:
        """Whether every target is met."""
        return all(c.met for c in self.checks)


def spectral_checks(records: dict[tuple[str, str], Record], targets: Targets,
                    spectra: dict[tuple[str, str], tuple[np.ndarray, np.ndarray, np.ndarray]] | None = None) -> list[Check]:
    """Check the peak and coherence targets that ``records`` ((config, excited input) -> Record) cover.

    ``spectra`` (optional) collects the (f, PSD, coherence) of each channel measured.
    """
    spectra = {} if spectra is None else spectra
    checks = []

    def channel(config: str, ch: str) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        u, y = parse_channel(ch, config)
        if (config, u) not in records:
            return None
        if (config, ch) not in spectra:
            spectra[(config, ch)] = channel_spectra(records[(config, u)], y)
        return spectra[(config, ch)]

    for t in targets.peaks:
        measured = channel(t.config, t.channel)
        if measured is None:
            continue
        found = peaks_of(measured[0], measured[1])
        near = min(found, key=lambda x: abs(x - t.frequency_hz)) if found else float("nan")
        miss = abs(near - t.frequency_hz) / t.tolerance_hz if found else 3.0
        checks.append(Check(t.name, t.frequency_hz, near, f"+-{t.tolerance_hz:g} Hz", bool(miss <= 1.0), "Hz",
                            max(0.0, miss - 1.0)))
    for c in targets.coherences:
        measured = channel(c.config, c.channel)
        if measured is None:
            continue
        f, _, coh = measured
        level = float(np.median(coh[(f >= c.band_hz[0]) & (f <= c.band_hz[1])]))
        miss = level - c.threshold if c.level == "low" else c.threshold - level
        checks.append(Check(c.name, c.threshold, level, f"{'<=' if c.level == 'low' else '>='} {c.threshold:g}",
                            bool(miss <= 0), "", max(0.0, miss) / 0.1))
    return checks


def verify(spec: mujoco.MjSpec, targets: Targets, protocols: Sequence[Protocol] = THESIS_PROTOCOLS,
           counts_per_rev: int | None = None) -> Verification:
    """Measure every target on the nonlinear twin built from ``spec``."""
    needed = {(t.config, parse_channel(t.channel, t.config)[0]) for t in targets.peaks}
    needed |= {(c.config, parse_channel(c.channel, c.config)[0]) for c in targets.coherences}
    if targets.model is not None:
        needed.add(("1dof", "u1"))
    records = {}
    for p in protocols:
        if (p.config, p.excited) in needed:
            records[(p.config, p.excited)] = protocol_records([spec], p, counts_per_rev)[0]
    missing = needed - set(records)
    if missing:
        raise InputError(f"no protocol excites {sorted(missing)}; give protocols for every targeted channel")
    out = Verification([], records=records)
    out.checks = spectral_checks(records, targets, out.spectra)
    if targets.model is not None:
        mt = targets.model
        ref = mt.system
        model = identify_1dof(records[("1dof", "u1")], decimate=max(1, int(round(ref.dt / records[("1dof", "u1")].sample_time))))
        out.model = model
        f_ref, z_ref = lightly_damped(ref.poles(), float(ref.dt))
        f_tw, z_tw = lightly_damped(model.poles(), model.sample_time)
        gain_ref = float(np.ravel(ref.dcgain())[0])
        gain_tw = model.dc_gain()
        d_ref, tc_ref = step_figures(ref)
        d_ref = mt.delay_s if mt.delay_s is not None else d_ref
        tc_ref = mt.time_constant_s if mt.time_constant_s is not None else tc_ref
        d_tw, tc_tw = step_figures(model.to_tf())
        out.checks += [
            Check("1dof ARMAX lightly damped mode", f_ref, f_tw, f"+-{mt.mode_tolerance_hz:g} Hz",
                  bool(abs(f_tw - f_ref) <= mt.mode_tolerance_hz), "Hz"),
            Check("1dof ARMAX damping ratio", z_ref, z_tw, f"+-{mt.damping_tolerance:g}", bool(abs(z_tw - z_ref) <= mt.damping_tolerance)),
            Check("1dof ARMAX DC gain", gain_ref, gain_tw, f"+-{100 * mt.gain_tolerance:g} %",
                  bool(abs(gain_tw - gain_ref) <= mt.gain_tolerance * abs(gain_ref)), "rad/V"),
            Check("1dof step delay (to 5 %)", d_ref, d_tw, f"+-{mt.delay_tolerance_s:g} s",
                  bool(abs(d_tw - d_ref) <= mt.delay_tolerance_s), "s"),
            Check("1dof step time constant (5 % to 63 %)", tc_ref, tc_tw, f"+-{mt.time_constant_tolerance_s:g} s",
                  bool(abs(tc_tw - tc_ref) <= mt.time_constant_tolerance_s), "s"),
        ]
    return out

