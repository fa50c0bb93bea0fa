"""Each target's check on the twin's measurements: spectra, 1-DOF ARMAX, step, rest, coupling, ambient.

A :class:`Check` is one target's outcome at one seed (or seedless); the functions here measure one kind
of target each, the way the thesis measured it, on records or a spec, and :func:`~trms.calibration.verify.verify`
runs them at every verification seed.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from trms.calibration.target_kinds import AmbientTarget, ModelTarget, parse_channel
from trms.calibration.targets import Targets
from trms.errors import InputError
from trms.identification.polynomial import PolynomialModel
from trms.measurement.protocol import armax_residual_variance, hover_rms, identify_protocol_record, lightly_damped
from trms.measurement.spectra import averaged_spectra, ranked_peaks
from trms.measurement.step_response import step_fit_percent, system_step, tangent_figures
from trms.record import Record
from trms.twin.model import CONFIGURATIONS, build_model
from trms.twin.trim import rest_pose
from trms.twin.twin import Twin

__all__ = [
    "Check",
    "spectral_checks",
    "model_checks",
    "step_checks",
    "ambient_checks",
    "rest_checks",
    "coupling_checks",
    "phase_difference_deg",
]


@dataclass(frozen=True)
class Check:
    """One target's outcome (at one seed, or ``seed = None`` for a seedless figure).

    ``violation`` is 0 when the target is met and grows with the miss, in units of the
    tolerance (peaks: ``|f - f_target| / tol - 1``, 2 with no peak at all; coherence:
    the miss over 0.1); the spectral fit minimises its sum. A peak's ``lead_db`` is how far
    its prominence stands above the most prominent peak left out of the channel's main ones
    (how safely it is among them; NaN for other checks). ``runs`` holds the per-run values a median
    was taken of (the ARMAX figures; empty for other checks).

    Parameters
    ----------
    name : str
        The target's label.
    target, achieved : float
        The target's value and the one measured (in ``unit``).
    tolerance : str
        The tolerance as printed (e.g. ``"+-0.03 Hz"``).
    met : bool
        Whether the target is met.
    unit : str
        Unit of ``target`` and ``achieved``.
    violation : float
        0 when met, else the miss in tolerances.
    seed : int or None
        The verification seed, None for a seedless figure.
    lead_db : float
        A peak's prominence above the most prominent peak left out (dB).
    runs : tuple of float
        The per-run values a median was taken of.

    Examples
    --------
    >>> c = Check("1dof u1->pitch PSD peak", 0.34, 0.33, "+-0.03 Hz", True, "Hz", seed=101)
    >>> c.to_dict()["achieved"], c.to_dict()["met"]
    (0.33, True)
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


class _Measured:
    """The protocols' runs by ``(config, excited input)`` and their averaged spectra by ``(config, channel)``,
    measured once (into ``spectra``)."""

    def __init__(
        self,
        records: Mapping[tuple[str, str], Record | list[Record]],
        spectra: dict[tuple[str, str], tuple[np.ndarray, np.ndarray, np.ndarray]],
    ) -> None:
        self.records, self.spectra = records, spectra

    def runs(self, config: str, u: str) -> list[Record] | None:
        got = self.records.get((config, u))
        return None if got is None else (got if isinstance(got, list) else [got])

    def channel(self, config: str, ch: str) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        u, y = parse_channel(ch, config)
        recs = self.runs(config, u)
        if recs is None:
            return None
        if (config, ch) not in self.spectra:
            self.spectra[(config, ch)] = averaged_spectra(recs, y)
        return self.spectra[(config, ch)]


def _peak_checks(measured_spectra: _Measured, targets: Targets, seed: int | None) -> list[Check]:
    """Each peak target among the channel's main peaks (one more than the channel's targets)."""
    checks = []
    per_channel: dict[tuple[str, str], int] = {}
    for t in targets.peaks:
        per_channel[(t.config, t.channel)] = per_channel.get((t.config, t.channel), 0) + 1
    for t in targets.peaks:
        measured = measured_spectra.channel(t.config, t.channel)
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
    return checks


def _coherence_checks(measured_spectra: _Measured, targets: Targets, seed: int | None) -> list[Check]:
    """Each coherence target: the median coherence in its band against its threshold."""
    checks = []
    for c in targets.coherences:
        measured = measured_spectra.channel(c.config, c.channel)
        if measured is None:
            continue
        f, _, coh = measured
        level = float(np.median(coh[(f >= c.band_hz[0]) & (f <= c.band_hz[1])]))
        miss = level - c.threshold if c.level == "low" else c.threshold - level
        bound = f"{'<=' if c.level == 'low' else '>='} {c.threshold:g}"
        checks.append(Check(c.name, c.threshold, level, bound, bool(miss <= 0), "", max(0.0, miss) / 0.1, seed))
    return checks


def _ratio_checks(measured_spectra: _Measured, targets: Targets, seed: int | None) -> list[Check]:
    """Each ratio target: the RMS of a channel against that of its reference channel."""
    checks = []
    for r in targets.ratios:
        (u, y), (u_ref, y_ref) = parse_channel(r.channel, r.config), parse_channel(r.reference, r.config)
        recs, refs = measured_spectra.runs(r.config, u), measured_spectra.runs(r.config, u_ref)
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


def _movement_checks(measured_spectra: _Measured, targets: Targets, seed: int | None) -> list[Check]:
    """Each movement target: the hover RMS in encoder counts (where the records have encoders)."""
    checks = []
    for mv in targets.movements:
        u, y = parse_channel(mv.channel, mv.config)
        recs = measured_spectra.runs(mv.config, u)
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


def spectral_checks(
    records: Mapping[tuple[str, str], Record | list[Record]],
    targets: Targets,
    spectra: dict[tuple[str, str], tuple[np.ndarray, np.ndarray, np.ndarray]] | None = None,
    seed: int | None = None,
) -> list[Check]:
    """Check the peak, coherence and ratio targets that ``records`` ((config, excited input) -> Record) cover.

    A list of Records (repeats of one protocol) is measured on its averaged spectra.

    Parameters
    ----------
    records : mapping of (str, str) to Record or list of Record
        ``(config, excited input)`` to the protocol's runs (volts in, radians out).
    targets : Targets
        Its peak, coherence, ratio and movement targets are checked where ``records`` cover them.
    spectra : dict, optional
        Collects ``(f (Hz), PSD (rad^2/Hz), coherence)`` of each ``(config, channel)`` measured.
    seed : int, optional
        The verification seed the checks are labelled with.

    Returns
    -------
    list of Check

    Examples
    --------
    >>> from trms.measurement.protocol import Protocol, repeated_records
    >>> from trms.calibration.target_kinds import PeakTarget
    >>> from trms.calibration.targets import Targets
    >>> from trms.twin import load_spec
    >>> runs = repeated_records(load_spec(), Protocol("1dof", "u1", 5.0, 30.0, 0.05), seeds=(0,))
    >>> checks = spectral_checks({("1dof", "u1"): runs}, Targets([PeakTarget("1dof", "u1->pitch", 0.34, 0.1)]))
    >>> [(c.name, c.unit) for c in checks]
    [('1dof u1->pitch PSD peak', 'Hz')]
    """
    measured = _Measured(records, {} if spectra is None else spectra)
    return [
        *_peak_checks(measured, targets, seed),
        *_coherence_checks(measured, targets, seed),
        *_ratio_checks(measured, targets, seed),
        *_movement_checks(measured, targets, seed),
    ]


def phase_difference_deg(system, reference_system, band_hz: tuple[float, float], n: int = 60) -> float:
    """Largest ``|phase(system) - phase(reference)|`` (deg) over ``band_hz``, both discrete at the same ``dt``.

    Parameters
    ----------
    system, reference_system : control.LTI
        Discrete SISO models at the same sample time (s).
    band_hz : (float, float)
        The band (Hz), cut at 0.999 of the Nyquist frequency.
    n : int
        Frequencies compared, log-spaced.

    Returns
    -------
    float
        The largest phase difference (deg).

    Examples
    --------
    >>> import control
    >>> g = control.tf([0.1], [1.0, -0.9], 0.2)
    >>> round(phase_difference_deg(g, g, (0.02, 1.0)), 6), round(phase_difference_deg(g * g, g, (0.02, 0.03)), 1)
    (0.0, 20.8)
    """
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
    disturbed run from deciding, as the thesis repeated runs until one was undisturbed.

    Parameters
    ----------
    records : Record or sequence of Record
        1-DOF protocol runs (volts in, radians out), at a sample time dividing the target's.
    mt : ModelTarget
        The model target (its system, its tolerances).
    seed : int, optional
        The verification seed the checks are labelled with.

    Returns
    -------
    (list of Check, PolynomialModel)
        The mode (Hz), damping ratio, DC gain (rad/V) and phase (deg) checks, and the first record's model.

    Examples
    --------
    >>> from trms.measurement.protocol import Protocol, repeated_records
    >>> from trms.calibration.target_kinds import ModelTarget
    >>> from trms.reference import eq_3_11
    >>> from trms.twin import load_spec
    >>> runs = repeated_records(load_spec(), Protocol("1dof", "u1", 5.0, 30.0, 0.05), seeds=(0,))
    >>> checks, model = model_checks(runs, ModelTarget(eq_3_11()))
    >>> [c.unit for c in checks], model.sample_time
    (['Hz', '', 'rad/V', 'deg'], 0.2)
    """
    ref = mt.system
    runs = [records] if isinstance(records, Record) else list(records)
    if not runs:
        raise InputError("model_checks needs at least one 1-DOF record")
    models = [identify_protocol_record(r, decimate=max(1, int(round(ref.dt / r.sample_time)))) for r in runs]
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
    """The step targets on a mean step per volt (:func:`~trms.measurement.protocol.mean_step`), read as
    ``mt.system``'s own step is: tangent dead time and time constant, and the NRMSE fit to it.

    Parameters
    ----------
    time : numpy.ndarray
        Sample times from the step (s), at ``mt.system``'s sample time.
    response : numpy.ndarray
        The step response per volt (rad/V).
    mt : ModelTarget
        The model target.
    seed : int, optional
        The verification seed the checks are labelled with.

    Returns
    -------
    list of Check
        Dead time (s), time constant (s) and fit (%).

    Examples
    --------
    The target's own step meets every step target:

    >>> from trms.measurement.step_response import system_step
    >>> from trms.calibration.target_kinds import ModelTarget
    >>> from trms.reference import eq_3_11
    >>> mt = ModelTarget(eq_3_11())
    >>> [(c.unit, c.met) for c in step_checks(*system_step(mt.system, 40.0), mt)]
    [('s', True), ('s', True), ('%', True)]
    """
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
    """The rig at rest: hover pitch RMS within its range, and Table 5.1's ARMAX residual variance.

    Parameters
    ----------
    hover : list of Record
        2-DOF runs with the inputs held at trim (radians out).
    residual : Record
        A 1-DOF run of ch. 5's training experiment (:data:`~trms.measurement.protocol.RESIDUAL_PROTOCOL`).
    target : AmbientTarget
        The hover RMS range (rad) and the residual variance (rad^2).
    seed : int, optional
        The verification seed the checks are labelled with.

    Returns
    -------
    list of Check
        The hover pitch RMS (rad) and the residual variance (rad^2).

    Examples
    --------
    >>> import dataclasses
    >>> from trms.measurement.protocol import HOVER_PROTOCOL, RESIDUAL_PROTOCOL, protocol_records
    >>> from trms.calibration.target_kinds import AmbientTarget
    >>> from trms.twin import load_spec
    >>> hover = protocol_records([load_spec()], dataclasses.replace(HOVER_PROTOCOL, duration_s=20.0))
    >>> residual = protocol_records([load_spec()], dataclasses.replace(RESIDUAL_PROTOCOL, duration_s=30.0))[0]
    >>> [c.unit for c in ambient_checks(hover, residual, AmbientTarget((0.002, 0.01), 1e-5))]
    ['rad', 'rad^2']
    """
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
    """The gyroscopic coupling (pitch torque per yaw rate at hover) against ``targets.coupling``.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The model.
    targets : Targets
        Its ``coupling`` target (N m s/rad); none: no check.

    Returns
    -------
    list of Check

    Examples
    --------
    >>> from trms.calibration.target_kinds import CouplingTarget
    >>> from trms.calibration.targets import Targets
    >>> from trms.twin import load_spec
    >>> [(c.unit, c.met) for c in coupling_checks(load_spec(), Targets(coupling=CouplingTarget(1.0, 0.01)))]
    [('N m s/rad', False)]
    """
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
    """The 2-DOF rest pose with the rotors off against ``targets.rest``.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The model.
    targets : Targets
        Its ``rest`` target (rad); none: no check.

    Returns
    -------
    list of Check
        The rest pitch and yaw (rad), seedless.

    Examples
    --------
    >>> from trms.calibration.target_kinds import RestTarget
    >>> from trms.calibration.targets import Targets
    >>> from trms.twin import load_spec
    >>> [(c.name, c.unit) for c in rest_checks(load_spec(), Targets(rest=RestTarget(-0.6, 3.0)))]
    [('2dof rest pitch, rotors off', 'rad'), ('2dof rest yaw, rotors off', 'rad')]
    """
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
