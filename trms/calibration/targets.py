"""What a calibration aims at: spectral peaks by channel, coherence levels, an identified model.

The thesis's targets come from :mod:`trms.reference`; a user can give a mode table (JSON)
or Records of their own rig instead (:meth:`Targets.from_records`).
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from trms import reference
from trms.calibration.target_kinds import (
    AmbientTarget,
    CoherenceTarget,
    CouplingTarget,
    ModelTarget,
    MovementTarget,
    PeakTarget,
    RatioTarget,
    RestTarget,
)
from trms.errors import InputError, short_repr
from trms.record import Record
from trms.twin.model import CONFIGURATIONS

#: The thesis's 1-DOF side peaks (Hz, :data:`trms.reference.SIDE_PEAKS_1DOF_HZ`): examined by measurement, not fitted.
SIDE_PEAKS_HZ = reference.SIDE_PEAKS_1DOF_HZ


__all__ = ["Targets"]


@dataclass
class Targets:
    """Everything a calibration aims at, with the excitation protocol's amplitudes.

    Attributes
    ----------
    peaks : list of PeakTarget
    coherences : list of CoherenceTarget
    model : ModelTarget or None
    rest : RestTarget or None
    ratios : list of RatioTarget
    examined : list of PeakTarget
        Peaks examined by measurement instead of fitted (the thesis's 1-DOF side peaks).
    movements : list of MovementTarget
    ambient : AmbientTarget or None
    coupling : CouplingTarget or None
    source : str
        Where the targets come from (for the report).
    notes : dict of str to str
        Why each tolerance is what it is.

    Examples
    --------
    >>> t = Targets.thesis()
    >>> sorted({p.frequency_hz for p in t.peaks if p.config == "1dof"}), float(t.model.system.dt)
    ([0.34], 0.2)
    >>> Targets([PeakTarget("1dof", "u1->pitch", 0.34)]).to_dict()["peaks"][0]["tolerance_hz"]
    0.03
    """

    peaks: list[PeakTarget] = field(default_factory=list)
    coherences: list[CoherenceTarget] = field(default_factory=list)
    model: ModelTarget | None = None
    source: str = "user"
    notes: dict[str, str] = field(default_factory=dict)
    rest: RestTarget | None = None
    ratios: list[RatioTarget] = field(default_factory=list)
    examined: list[PeakTarget] = field(default_factory=list)
    movements: list[MovementTarget] = field(default_factory=list)
    ambient: AmbientTarget | None = None
    coupling: CouplingTarget | None = None

    @classmethod
    def thesis(cls) -> Targets:
        """The thesis's targets (TARGETS.md: ch. 3 modes by channel, coherence, eq. 3.11), with the rig's published
        rest pose and the thesis's "no u2 -> pitch coupling" as measurable figures."""
        from trms.twin.published import REST_PITCH, gyroscopic_coupling

        all_peaks = [
            PeakTarget(m.configuration, m.channel.replace("y1", "pitch").replace("y2", "yaw"), m.frequency_hz)
            for m in reference.MODE_TABLE
        ]
        # The 1-DOF side peaks (0.25 Hz in Table 3.1; 0.46 Hz in the PSD) are examined, not fitted: no physically
        # defensible structure of this rig has such a mode, and a one-mode rig shows them through lightly averaged
        # spectra (trms.calibration.elastic_modes measures both in the calibration report).
        examined = [p for p in all_peaks if p.config == "1dof" and p.frequency_hz in SIDE_PEAKS_HZ]
        peaks = [p for p in all_peaks if p not in examined]
        coh = [
            CoherenceTarget("2dof", "u2->pitch", "low", 0.3),
            CoherenceTarget("2dof", "u1->pitch", "high", 0.8),
            # Section 3.4.5: u1 -> y2's coherence dips near its 0.1 Hz mode and its model fit was poorer.
            CoherenceTarget("2dof", "u1->yaw", "high", 0.7),
            CoherenceTarget("2dof", "u2->yaw", "high", 0.75),
        ]
        model = ModelTarget(reference.eq_3_11())
        ratios = [RatioTarget("2dof", "u2->pitch", "u1->pitch", 0.1)]
        movements = [MovementTarget("2dof", "u2->pitch")]
        rest = RestTarget(REST_PITCH)
        ambient = AmbientTarget(reference.HOVER_PITCH_RMS, reference.TABLE_5_1["linear ARMAX"])
        coupling = CouplingTarget(gyroscopic_coupling())
        notes = _thesis_notes(peaks, coh, model, ratios, rest, movements, ambient, coupling)
        notes["examined"] = (
            f"1-DOF {SIDE_PEAKS_HZ[0]:g} Hz (and the PSD's {SIDE_PEAKS_HZ[1]:g} Hz): examined by measurement, not "
            "fitted -- the structural candidates and the estimator statistics of the calibration report."
        )
        return cls(peaks, coh, model, "thesis", notes, rest, ratios, examined, movements, ambient, coupling)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Targets:
        """Read a mode table (JSON): ``{"peaks": [{"config", "channel", "frequency_hz", "tolerance_hz"?}],
        "coherences": [{"config", "channel", "level", "threshold"}]}``."""
        path = Path(path)
        if not path.is_file():
            raise InputError(f"target file {str(path)!r} does not exist")
        where = f"{str(path)!r} is not a target table"
        size = path.stat().st_size
        if size > MAX_TARGET_FILE_BYTES:
            raise InputError(f"{where}: {size} bytes; allowed: up to {MAX_TARGET_FILE_BYTES} (a table of modes)")
        try:
            data = json.loads(path.read_bytes().decode("utf-8"), object_pairs_hook=_unique_keys)
        except UnicodeDecodeError as exc:
            raise InputError(f"{where}: not UTF-8 text ({exc.reason} at byte {exc.start})") from exc
        except json.JSONDecodeError as exc:
            raise InputError(f"{where}: {exc}") from exc
        except RecursionError as exc:
            raise InputError(f"{where}: nested too deeply; allowed: the flat layout of the docstring") from exc
        except ValueError as exc:  # a duplicate key, or an integer too long to convert
            raise InputError(f"{where}: {' '.join(str(exc).split())[:200]}") from exc
        _check_keys(where, "the table", data, {"peaks", "coherences"})
        for key in ("peaks", "coherences"):
            if not isinstance(data.get(key, []), list):
                raise InputError(f"{where}: {key!r} must be a list of objects, got {short_repr(data[key])}")
            if len(data.get(key, [])) > MAX_TARGETS:
                raise InputError(f"{where}: {len(data[key])} {key}; allowed: up to {MAX_TARGETS}")
        fields = {"peaks": PeakTarget, "coherences": CoherenceTarget}
        for key, kind in fields.items():
            for i, entry in enumerate(data.get(key, [])):
                _check_keys(where, f"{key}[{i}]", entry, {f.name for f in dataclasses.fields(kind)})
        try:
            peaks = [PeakTarget(**p) for p in data.get("peaks", [])]
            coh = [
                CoherenceTarget(**{**c, "band_hz": c.get("band_hz", (0.02, 1.0))}) for c in data.get("coherences", [])
            ]
        except TypeError as exc:  # a required field missing
            raise InputError(f"{where}: {exc}") from exc
        if not peaks and not coh:
            raise InputError(f"{str(path)!r} holds no peak or coherence targets")
        groups: list[tuple[str, Sequence[PeakTarget | CoherenceTarget]]] = [("peaks", peaks), ("coherences", coh)]
        for key, targets in groups:
            seen: dict[PeakTarget | CoherenceTarget, int] = {}
            for i, t in enumerate(targets):
                first = seen.setdefault(t, i)
                if first != i:  # the same target twice would weigh twice in the fit and be counted twice as met
                    raise InputError(f"{where}: {key}[{i}] repeats {key}[{first}] ({short_repr(asdict(t))})")
        return cls(peaks, coh, None, str(path))

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable summary."""
        out: dict[str, Any] = {
            "source": self.source,
            "peaks": [asdict(p) for p in self.peaks],
            "coherences": [asdict(c) for c in self.coherences],
            "ratios": [asdict(r) for r in self.ratios],
            "rest": asdict(self.rest) if self.rest is not None else None,
            "examined": [asdict(p) for p in self.examined],
            "movements": [asdict(m) for m in self.movements],
            "ambient": asdict(self.ambient) if self.ambient is not None else None,
            "coupling": asdict(self.coupling) if self.coupling is not None else None,
            "notes": self.notes,
        }
        if self.model is not None:
            g = self.model.system
            out["model"] = {"num": np.ravel(g.num[0][0]).tolist(), "den": np.ravel(g.den[0][0]).tolist(), "dt": g.dt}
        return out

    @classmethod
    def from_records(cls, records: list[Record], n_peaks: int = 2, min_prominence_db: float = 3.0) -> Targets:
        """Targets measured on a rig, as verification measures the twin: peaks and coherences, an ARMAX model.

        Each record is one protocol run (one input excited, the others held), with metadata ``config``.
        Runs of the same protocol (same configuration and excited input) are repeats: their spectra are
        averaged (:func:`~trms.measurement.spectra.averaged_spectra`), as the thesis repeated its runs,
        with 256-sample segments for the PSD too (finding peaks needs averages more than resolution: 512-sample
        segments of 120 s runs show ripples as prominent as the modes). For every output, the median coherence
        over 0.02-1 Hz says whether the channel is coupled (a 'high' target at 0.8 of the level measured,
        else 'low' below 0.5); the ``n_peaks`` most prominent PSD peaks in 0.02-1 Hz of a coupled channel
        become peak targets. The
        1-DOF records give a 4th-order ARMAX model target at eq. (3.11)'s sample time (0.2 s: every
        other sample of a 10 Hz record; at 0.1 s a 4-sample B window would end before the rig's transport
        delay), as verification identifies the twin's records: one model per record, and the target is the
        one of median DC gain (a single run's ARMAX scatters with the rig's ambient excitation).

        Record several runs of each protocol: a single run's spectrum can have ripples as prominent as its modes.

        Examples
        --------
        >>> from trms.twin import load_spec
        >>> from trms.measurement.protocol import THESIS_PROTOCOLS
        >>> from trms.measurement.protocol import repeated_records
        >>> runs = repeated_records(load_spec(), THESIS_PROTOCOLS[0], seeds=(0, 1000, 2000))
        >>> t = Targets.from_records(runs)
        >>> [round(p.frequency_hz, 1) for p in t.peaks], t.coherences[0].level
        ([0.3], 'high')
        """
        from trms.identification import spectral
        from trms.identification.mimo import excited_input
        from trms.measurement.protocol import identify_protocol_record
        from trms.measurement.spectra import NPERSEG, averaged_spectra

        band = (0.02, 1.0)
        groups: dict[tuple[str, str], list[Record]] = {}
        for rec in records:
            config = rec.metadata.get("config")
            if config not in CONFIGURATIONS:
                raise InputError(f"record metadata 'config' must be one of {tuple(CONFIGURATIONS)}, got {config!r}")
            groups.setdefault((config, rec.input_names[excited_input(rec)]), []).append(rec)
        peaks: list[PeakTarget] = []
        coh: list[CoherenceTarget] = []
        for (config, u_name), runs in groups.items():
            for y_name in runs[0].output_names:
                channel = f"{u_name}->{y_name}"
                f, p, c = averaged_spectra(runs, y_name, psd_segment=NPERSEG)
                level = float(np.median(c[(f >= band[0]) & (f <= band[1])]))
                coupled = level >= 0.5
                coh.append(
                    CoherenceTarget(config, channel, "high" if coupled else "low", 0.8 * level if coupled else 0.5)
                )
                if coupled:
                    for peak in spectral.find_modes(f, p, band, n=n_peaks, min_prominence_db=min_prominence_db):
                        peaks.append(PeakTarget(config, channel, round(peak.frequency, 4)))
        model = None
        one_dof = [r for r in records if r.metadata.get("config") == "1dof"]
        if one_dof:
            step = float(reference.eq_3_11().dt)
            fits = [identify_protocol_record(r, decimate=max(1, int(round(step / r.sample_time)))) for r in one_dof]
            ranked = sorted(fits, key=lambda m: m.dc_gain())
            model = ModelTarget(ranked[(len(ranked) - 1) // 2].to_tf())
        return cls(peaks, coh, model, "records")


#: The most targets of one kind a target file may hold, and its largest size: a table of a rig's modes is short.
MAX_TARGETS = 1000
MAX_TARGET_FILE_BYTES = 1_000_000


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """``json`` object hook refusing a key given twice (``json`` would keep the last silently)."""
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise ValueError(f"key {key!r} appears twice in one object")
        out[key] = value
    return out


def _check_keys(where: str, what: str, value: object, allowed: set[str]) -> None:
    """Refuse (one line) a JSON value that is not an object with keys among ``allowed``."""
    if not isinstance(value, dict):
        raise InputError(f"{where}: {what} must be a JSON object, got {short_repr(value)}")
    unknown = sorted(set(value) - allowed)
    if unknown:
        raise InputError(f"{where}: {what} has unknown key(s) {unknown}; allowed: {sorted(allowed)}")


def _thesis_notes(
    peaks: list[PeakTarget],
    coherences: list[CoherenceTarget],
    model: ModelTarget,
    ratios: list[RatioTarget],
    rest: RestTarget,
    movements: list[MovementTarget],
    ambient: AmbientTarget,
    coupling: CouplingTarget,
) -> dict[str, str]:
    """Why each of the thesis's targets is what it is, every number read off the targets or computed here."""
    from trms.measurement.protocol import RESIDUAL_PROTOCOL, STEP_PROTOCOL, THESIS_PROTOCOLS, lightly_damped
    from trms.measurement.spectra import coherence_nperseg, psd_nperseg
    from trms.measurement.step_response import STEP_FIT_WINDOW, step_figures, system_step, tangent_figures

    g = model.system
    dt = float(g.dt)
    f_ref, z_ref = lightly_damped(g.poles(), dt)
    delay, time_constant = step_figures(g)
    dead, lag = tangent_figures(*system_step(g, STEP_PROTOCOL.duration_s))
    tol = sorted({p.tolerance_hz for p in peaks})
    # Welch segments (samples) and bin width (Hz) of each configuration's protocol record.
    segments = {
        p.config: (psd_nperseg(n), coherence_nperseg(n), 1.0 / (p.sample_time * psd_nperseg(n)))
        for p in THESIS_PROTOCOLS
        for n in [int(round(p.duration_s / p.sample_time))]
    }
    low = sorted({c.threshold for c in coherences if c.level == "low"})
    high = sorted({c.threshold for c in coherences if c.level == "high"})
    band = coherences[0].band_hz
    ratio = ratios[0]
    half_bin = min(b for _, _, b in segments.values()) / 2
    return {
        "peaks": f"+-{', '.join(f'{t:g}' for t in tol)} Hz, among the channel's main peaks (its n + 1 most prominent, "
        "n the channel's targets, each >= 1 dB); the spectra's bins are "
        + " and ".join(f"{b:.3g} Hz ({n}-sample segments, {c})" for c, (n, _, b) in segments.items())
        + f"; the tolerance is wider than half the finer bin ({half_bin:.3g} Hz), the estimator's resolution. A "
        "ripple elsewhere in the spectrum does not count.",
        "coherence": f"median over {band[0]:g}-{band[1]:g} Hz: 'low' below {', '.join(f'{x:g}' for x in low)} (the "
        f"thesis saw no u2 -> pitch coupling, low coherence), 'high' above {', '.join(f'{x:g}' for x in high)} "
        "('near unity at most frequencies of interest'; the u1 -> yaw channel's lower, section 3.4.5: its coherence "
        f"dips near the 0.1 Hz mode and its fit was poorer); estimated with {segments[coherences[0].config][1]}-sample "
        "segments whatever the PSD's (the calibration report measures what two unrelated signals read with both).",
        "ratio": f"{ratio.channel.replace('->', ' -> ')} RMS below {100 * ratio.max_ratio:g} % of "
        f"{ratio.reference.replace('->', ' -> ')}'s under the same PRBS: the thesis did not model the channel because "
        "nothing came through it.",
        "movement": "; ".join(
            f"{m.channel.replace('->', ' -> ')} RMS at least {m.min_counts:g} encoder counts in its protocol: a low "
            "coherence or a small ratio read off an encoder that does not move is not a measurement"
            for m in movements
        )
        + ".",
        "rest": f"pitch {rest.pitch:g} +- {rest.tolerance:g} rad with the rotors off (Rotondo et al.'s published rest "
        f"pose) and yaw within {rest.yaw_tolerance:g} rad of 0: the cable holds yaw at zero; nothing should twist it "
        "at rest.",
        "ambient": f"hover pitch RMS {1e3 * ambient.hover_rms[0]:g}-{1e3 * ambient.hover_rms[1]:g} mrad with "
        "constant inputs (the rig is never still: 'a minor oscillatory tendency even in steady state'), and "
        f"Table 5.1's ARMAX residual variance {ambient.residual_variance:.3g} rad^2 +- {100 * ambient.tolerance:g} % "
        f"on ch. 5's training experiment ({RESIDUAL_PROTOCOL.signal} noise, {RESIDUAL_PROTOCOL.bandwidth_hz:g} Hz "
        f"clock, {RESIDUAL_PROTOCOL.amplitude_v:g} V, {RESIDUAL_PROTOCOL.duration_s:g} s at "
        f"{RESIDUAL_PROTOCOL.sample_time:g} s).",
        "coupling": f"pitch torque per yaw rate at the flat hover within {100 * coupling.tolerance:g} % of Feedback's "
        f"published Kgy M1 cos(psi) = {coupling.value:.3g} N m s/rad (their model's hover): the twin's comes from "
        "its spinning main rotor (a lean of its spin axis towards the beam), computed from MuJoCo's own dynamics.",
        "model mode": f"+-{model.mode_tolerance_hz:g} Hz on the identified model's lightly damped pair ((3.11) puts "
        f"it at {f_ref:.3f} Hz), damping within a factor {model.damping_factor:g} of {z_ref:.3f}.",
        "model gain": f"+-{100 * model.gain_tolerance:g} % on the DC gain {float(np.ravel(g.dcgain())[0]):.3g} rad/V.",
        "model phase": f"within {model.phase_tolerance_deg:g} deg of (3.11)'s from {model.phase_band_hz[0]:g} to "
        f"{model.phase_band_hz[1]:g} Hz: the phase decides the ch. 6/7 loops.",
        "model step": f"the tangent (maximum-slope) construction read the same way off (3.11)'s step at {dt:g} s and "
        f"the twin's mean step (+-{abs(STEP_PROTOCOL.amplitude_v):g} V from hover, {STEP_PROTOCOL.duration_s:g} s): "
        f"dead time within {model.dead_time_tolerance_s:g} s of (3.11)'s {dead:.3g} s, time constant within "
        f"{model.time_constant_tolerance_s:g} s of its {lag:.3g} s, and an NRMSE fit of at least "
        f"{model.step_fit_percent:g} % over the first {STEP_FIT_WINDOW:g} s. Examined, not targeted: (3.11) "
        f"crosses 5 % of its final value at {delay:.3g} s (its first-sample response, which no transport-delayed "
        f"plant has) and goes from 5 % to 63 % in {time_constant:.3g} s; the thesis reads 'about 0.6-0.7 s' and "
        "'around 1.2 s' off its rig's step plot (fig. 3.3), by a construction it does not state.",
    }
