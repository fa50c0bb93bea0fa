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

from .protocol import (THESIS_PROTOCOLS, Protocol, channel_spectra, identify_1dof, lightly_damped, peaks_of,
                       protocol_records, step_figures)
from .targets import Targets, parse_channel

__all__ = ["Check", "Verification", "verify"]


@dataclass(frozen=True)
class Check:
    """One target's outcome."""

    name: str
    target: float
    achieved: float
    tolerance: str
    met: bool
    unit: str = ""

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
        raise ValueError(f"no protocol for {sorted(missing)}")
    out = Verification([], records=records)
    for t in targets.peaks:
        u, y = parse_channel(t.channel, t.config)
        key = (t.config, t.channel)
        if key not in out.spectra:
            out.spectra[key] = channel_spectra(records[(t.config, u)], y)
        f, p, _ = out.spectra[key]
        found = peaks_of(f, p)
        near = min(found, key=lambda x: abs(x - t.frequency_hz)) if found else float("nan")
        out.checks.append(Check(t.name, t.frequency_hz, near, f"+-{t.tolerance_hz:g} Hz",
                                bool(abs(near - t.frequency_hz) <= t.tolerance_hz), "Hz"))
    for c in targets.coherences:
        u, y = parse_channel(c.channel, c.config)
        key = (c.config, c.channel)
        if key not in out.spectra:
            out.spectra[key] = channel_spectra(records[(c.config, u)], y)
        f, _, coh = out.spectra[key]
        band = (f >= c.band_hz[0]) & (f <= c.band_hz[1])
        level = float(np.median(coh[band]))
        ok = level <= c.threshold if c.level == "low" else level >= c.threshold
        out.checks.append(Check(c.name, c.threshold, level, f"{'<=' if c.level == 'low' else '>='} {c.threshold:g}", bool(ok)))
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

