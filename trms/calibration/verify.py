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

from trms.calibration.checks import (
    Check,
    ambient_checks,
    coupling_checks,
    model_checks,
    rest_checks,
    spectral_checks,
    step_checks,
)
from trms.calibration.target_kinds import parse_channel
from trms.calibration.targets import Targets
from trms.errors import InputError, check_in_range
from trms.identification.polynomial import PolynomialModel
from trms.measurement.protocol import (
    FIT_SEEDS,
    HOVER_PROTOCOL,
    RESIDUAL_PROTOCOL,
    STEP_PROTOCOL,
    THESIS_PROTOCOLS,
    VERIFY_REPEATS,
    VERIFY_SEEDS,
    Protocol,
    mean_step,
    repeated_records,
)
from trms.record import Record
from trms.twin.disturbances import Gust

__all__ = ["Verification", "verify"]


#: A target judged at several seeds (independent experiments) is met when it holds at this fraction of them at least:
#: 9 of 10. One experiment's spectra and ARMAX scatter with its PRBS realisation and the rig's ambient excitation, as
#: the thesis's did ("repeated until a response, undisturbed by gust, was obtained"); a target missed at one seed
#: in ten is a disturbed run, one missed at two is a twin that does not match.
MET_FRACTION = 0.9


@dataclass
class Verification:
    """All checks, and the spectra and models they came from (for figures; those of the first seed).

    Parameters
    ----------
    checks : list of Check
        Every target's outcome at every seed (and the seedless ones).
    spectra : dict
        ``(config, channel)`` to ``(f (Hz), PSD (rad^2/Hz), coherence)`` of the first seed.
    model : PolynomialModel or None
        The first seed's 1-DOF ARMAX.
    records : dict
        ``(config, excited input)`` to the first seed's runs.
    seeds : tuple of int
        The verification seeds.
    step : (numpy.ndarray, numpy.ndarray) or None
        The first seed's mean step per volt: time (s) and response (rad/V).

    Examples
    --------
    A target met at 9 seeds of 10 is met (:data:`MET_FRACTION`):

    >>> checks = [Check("peak", 0.34, 0.34, "+-0.03 Hz", s != 110, "Hz", seed=s) for s in range(101, 111)]
    >>> v = Verification(checks, seeds=tuple(range(101, 111)))
    >>> v.met_at("peak", 0.34), v.all_met
    ((9, 10), True)
    """

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
    distinct and none of them a fit seed, :data:`~trms.measurement.protocol.FIT_SEEDS`) whose spectra are
    averaged; the ARMAX targets are the median over the 1-DOF runs' fits (:func:`model_checks`). With an ambient
    target, the
    rig at rest (:data:`~trms.measurement.protocol.HOVER_PROTOCOL`, ``repeats`` runs) and ch. 5's training
    experiment (:data:`~trms.measurement.protocol.RESIDUAL_PROTOCOL`, one run); with a model target, the
    step (:data:`~trms.measurement.protocol.STEP_PROTOCOL`, ``repeats`` runs up and as many down, the down
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
