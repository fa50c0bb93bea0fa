"""Chapter 3 on a plant: 1-DOF and 2-DOF linear identification with the thesis's protocols.

1-DOF (ch. 3.2-3.3), ``Ts = 0.2 s``
    A 5 Hz PRBS of 60 s around hover drives ``u1``; the pitch PSD's peaks in 0-1 Hz are the
    modes; a 4th-order ARMAX (PEM) is fitted; its residuals get the whiteness and independence
    tests (eq. 3.9); it is cross-validated in free run on a 3211 multistep and a doublet (time
    domain) and by the PSD of its output against the plant's (frequency domain). The coherence
    (eq. 3.1) is computed at 5 Hz and again on a 10 Hz run of the same protocol (fig. 3.5).
2-DOF (ch. 3.4-3.5), ``Ts = 0.1 s``
    A 2 Hz PRBS of 120 s, smaller amplitude, on one input at a time (the other held at trim);
    coherence of every channel (fig. 3.14); a 4th-order ARMAX per coupled channel on the first
    600 samples (means removed, :func:`trms.identification.mimo.identify_mimo`); a doublet on
    each input for validation; PSD modes per channel (Table 3.1).

Amplitudes (the thesis prints none, only that they keep the rig in its linear range near hover):
the calibration's protocols (:data:`trms.calibration.THESIS_PROTOCOLS`), 0.05 V for both, so
that chapter 3 and the calibration identify the same experiment; validation signals of the same
amplitudes, 3211 unit step 1 s, doublet pulse 2 s, first edge at 2 s. This project's choices.
Modes are read from the model identified on the same run: its lightly damped modes, each named where the output's
PSD peaks within the Welch window's main lobe of it (:func:`confirmed_modes`); the PSD's other peaks come from the
input's own spectrum (a PRBS realisation's spectrum is not flat) and from the noise, and the linear model shows them
as well.

:func:`identify_1dof` and :func:`identify_2dof` are functions of a Plant; :mod:`trms.experiments.ch3_tables` puts the
linear model's and the twin's results beside the thesis's.
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

from trms.identification import (
    Comparison,
    CorrelationTest,
    MimoIdentification,
    Peak,
    PolynomialModel,
    coherence,
    compare,
    find_modes,
    identify_mimo,
    psd,
    residual_tests,
    siso_data,
)
from trms.measurement.protocol import ARMAX_ORDERS, THESIS_PROTOCOLS, armax_1dof
from trms.modes import oscillatory
from trms.plant import LinearPlant, Plant, simulate
from trms.record import Record
from trms.signals import doublet, multistep_3211, random_binary
from trms.twin import Twin

__all__ = [
    "PRBS_1DOF",
    "PRBS_2DOF",
    "Siso1Dof",
    "Mimo2Dof",
    "excite",
    "head",
    "validation_signals",
    "identify_1dof",
    "identify_2dof",
    "step_delay",
    "correlation_verdict",
    "LIGHT_DAMPING",
    "identified_modes",
    "confirmed_modes",
    "other_peaks",
    "bin_1dof",
    "bin_2dof",
    "response_peaks",
]

#: 1-DOF PRBS: duration (s), clock (Hz), amplitude (V): the calibration's 1-DOF protocol.
PRBS_1DOF = (THESIS_PROTOCOLS[0].duration_s, THESIS_PROTOCOLS[0].bandwidth_hz, THESIS_PROTOCOLS[0].amplitude_v)
#: 2-DOF PRBS: duration (s), clock (Hz), amplitude (V): the calibration's 2-DOF protocols.
PRBS_2DOF = (THESIS_PROTOCOLS[1].duration_s, THESIS_PROTOCOLS[1].bandwidth_hz, THESIS_PROTOCOLS[1].amplitude_v)
#: Samples used for the 2-DOF estimation (the thesis: 600).
ESTIMATION_SAMPLES_2DOF = 600
#: Welch segment of the 1-DOF spectra (samples): 25.6 s at 5 Hz, three averaged segments in 60 s.
PSD_SEGMENT_1DOF = 128
#: Welch segment of the 2-DOF coherence (samples): 25.6 s, long against the lightly damped modes'
#: decay (the resolution bias the thesis warns of, ch. 3.4.4), with about 8 averaged segments.
COHERENCE_SEGMENT_2DOF = 256
#: ARMAX orders (na, nb, nc, nk), as eq. (3.11).
ORDERS = ARMAX_ORDERS
#: Band (Hz) holding the significant modes (ch. 3.2.2).
MODE_BAND = (0.03, 1.0)
#: Damping ratio below which an identified pole pair is a mode a spectrum shows (the ch. 4 shapers' bound).
LIGHT_DAMPING = 0.5
#: How close an identified mode must lie to a PSD peak for the spectrum to show it: within this fraction of its
#: frequency, or within the Hann window's main-lobe half width (:data:`MAIN_LOBE_BINS` Welch bins), where the
#: estimate of one resonance can put its peak.
CONFIRM_WITHIN = 0.1
MAIN_LOBE_BINS = 2.0


@dataclass
class Siso1Dof:
    """One plant's 1-DOF identification (see the module docstring).

    ``peaks`` are every peak of the pitch PSD in :data:`MODE_BAND` (1 dB prominence, highest first), ``modes`` the
    lightly damped modes of ``model`` the PSD shows (:func:`confirmed_modes`: the model's frequency, the PSD peak's
    height). Without validation (a run's other seeds)
    ``validation`` and ``fits`` are empty.
    """

    estimation: Record
    validation: dict[str, Record]
    model: PolynomialModel
    peaks: list[Peak]
    spectra: dict[str, tuple[np.ndarray, np.ndarray]]
    coherence: dict[str, tuple[np.ndarray, np.ndarray]]
    tests: list[CorrelationTest]
    fits: dict[str, Comparison]
    modes: list[Peak]


@dataclass
class Mimo2Dof:
    """One plant's 2-DOF identification (see the module docstring).

    ``peaks`` are each channel's PSD peaks in :data:`MODE_BAND`, ``modes`` its identified model's modes the PSD
    shows (:func:`confirmed_modes`; none for a channel without a model), ``response`` the peaks of each channel of
    the plant's own linear model (its linearisation; empty without validation), ``validation`` and ``fits`` empty
    without validation.
    """

    experiments: dict[str, Record]
    validation: dict[str, Record]
    identification: MimoIdentification
    coherence: dict[tuple[str, str], tuple[np.ndarray, np.ndarray]]
    peaks: dict[tuple[str, str], list[Peak]]
    fits: dict[tuple[str, str], Comparison]
    modes: dict[tuple[str, str], list[Peak]]
    response: dict[tuple[str, str], list[Peak]]


def excite(plant: Plant, signal: np.ndarray, input_index: int = 0, seed: int = 0) -> Record:
    """Run ``plant`` with ``signal`` (deviation V) on one input, the others held at trim."""
    return simulate(plant, plant.operating_point.with_signal(signal, input_index), seed=seed)


def head(record: Record, n: int) -> Record:
    """The first ``n`` samples of a record."""
    extras = {k: v[:n] for k, v in record.extras.items()}
    return Record(
        record.time[:n],
        record.inputs[:n],
        record.outputs[:n],
        record.input_names,
        record.output_names,
        extras,
        dict(record.metadata),
    )


def step_delay(model: PolynomialModel, fraction: float = 0.05) -> float:
    """Apparent pure delay of a model's step response: the time (s) to reach ``fraction`` of its final value."""
    n = 400
    y = model.simulate(np.ones(n))
    final = y[-1]
    k = int(np.argmax(np.sign(final) * y >= fraction * abs(final)))
    if k == 0:
        return 0.0
    lo, hi = y[k - 1], y[k]
    frac = (fraction * final - lo) / (hi - lo)
    return float((k - 1 + frac) * model.sample_time)


def validation_signals(ts: float, amplitude: float, duration: float) -> dict[str, np.ndarray]:
    """The cross-validation inputs (deviation V): a 3211 (unit step 1 s) and a doublet (pulse 2 s), from 2 s."""
    return {
        "3211": multistep_3211(ts, 1.0, amplitude, start=2.0, duration=duration),
        "doublet": doublet(ts, 2.0, amplitude, start=2.0, duration=duration),
    }


def identified_modes(model: PolynomialModel, band: tuple[float, float] = MODE_BAND) -> list[float]:
    """The frequencies (Hz) of a model's lightly damped oscillatory modes (damping below :data:`LIGHT_DAMPING`)
    inside ``band``, rising.

    Examples
    --------
    >>> from trms.reference import EQ_3_11_DEN, EQ_3_11_NUM
    >>> g = PolynomialModel(np.array(EQ_3_11_DEN), np.array([0.0, *EQ_3_11_NUM]), np.array([1.0]), 0.2)
    >>> [round(f, 3) for f in identified_modes(g)]
    [0.342]
    """
    modes = oscillatory(model.modes(), model.sample_time)
    return sorted(m.frequency_hz for m in modes if m.damping < LIGHT_DAMPING and band[0] <= m.frequency_hz <= band[1])


def confirmed_modes(peaks: list[Peak], modes: list[float], bin_hz: float = 0.0) -> list[Peak]:
    """The identified modes an output's PSD shows: each mode (Hz) with a PSD peak within :data:`CONFIRM_WITHIN` of it
    (relative) or :data:`MAIN_LOBE_BINS` bins of ``bin_hz``, as ``Peak(mode, height of that PSD peak)``, highest first.

    The frequency is the model's: a lightly averaged Welch estimate puts one resonance's peak anywhere in its window's
    main lobe. A PSD peak no mode is near is not named a mode: it comes from the input's own spectrum or from the
    noise (the linear model, with one mode, shows such peaks too).

    Examples
    --------
    >>> confirmed_modes([Peak(0.10, 1.0), Peak(0.29, 9.0), Peak(0.99, 0.1)], [0.342], bin_hz=0.039)
    [Peak(frequency=0.342, height=9.0)]
    >>> confirmed_modes([Peak(0.10, 1.0)], [0.342], bin_hz=0.039)
    []
    """
    out = []
    for m in modes:
        near = [p for p in peaks if abs(p.frequency - m) <= max(CONFIRM_WITHIN * m, MAIN_LOBE_BINS * bin_hz)]
        if near:
            out.append(Peak(m, max(p.height for p in near)))
    return sorted(out, key=lambda p: -p.height)


def other_peaks(peaks: list[Peak], modes: list[Peak], bin_hz: float = 0.0) -> list[Peak]:
    """The PSD peaks no confirmed mode accounts for (:func:`confirmed_modes`'s window): not modes.

    Examples
    --------
    >>> other_peaks([Peak(0.10, 1.0), Peak(0.29, 9.0)], [Peak(0.342, 9.0)], bin_hz=0.039)
    [Peak(frequency=0.1, height=1.0)]
    """
    return [p for p in peaks if not confirmed_modes([p], [m.frequency for m in modes], bin_hz)]


def response_peaks(plant: Plant, band: tuple[float, float] = MODE_BAND) -> dict[tuple[str, str], list[Peak]]:
    """The peaks (1 dB prominence) of every channel's frequency-response magnitude of a plant's own linear model:
    a :class:`~trms.plant.LinearPlant`'s system, the twin's linearisation at hover; empty for any other plant.

    Examples
    --------
    >>> from trms.worlds import make_plant
    >>> [round(p.frequency, 2) for p in response_peaks(make_plant("linear", "1dof"))[("u1", "pitch")]]
    [0.34]
    """
    if isinstance(plant, LinearPlant):
        system = control.ss(plant.system)
    elif isinstance(plant, Twin):
        system = control.ss(plant.linearise().discrete)
    else:
        return {}
    ts = float(system.dt)
    f = np.arange(band[0], band[1] + 1e-9, 0.0025)
    z = np.exp(2j * np.pi * f * ts)
    n = system.A.shape[0]
    x = np.linalg.solve(
        z[:, None, None] * np.eye(n) - system.A, np.broadcast_to(system.B.astype(complex), (z.size,) + system.B.shape)
    )
    h = np.abs(system.C @ x + system.D)  # (frequency, output, input)
    return {
        (u, y): find_modes(f, h[:, j, i], band, quantity="amplitude")
        for i, u in enumerate(plant.input_names)
        for j, y in enumerate(plant.output_names)
    }


def _bin(ts: float, nperseg: int) -> float:
    return 1.0 / (ts * nperseg)


def bin_1dof(ts: float = 0.2) -> float:
    """The Welch bin (Hz) of the 1-DOF pitch PSD (:data:`PSD_SEGMENT_1DOF` samples at ``ts``)."""
    return _bin(ts, PSD_SEGMENT_1DOF)


def bin_2dof(n: int, ts: float = 0.1) -> float:
    """The Welch bin (Hz) of a 2-DOF output PSD of ``n`` samples at ``ts`` (:func:`~trms.identification.psd`'s
    default segment)."""
    f, _ = psd(np.zeros(n), ts)
    return float(f[1] - f[0])


def identify_1dof(plant: Plant, fast_plant: Plant | None = None, seed: int = 0, validate: bool = True) -> Siso1Dof:
    """The 1-DOF identification of ch. 3.2-3.3 on ``plant`` (``Ts = 0.2 s``).

    Parameters
    ----------
    plant : Plant
        SISO ``u1 -> pitch``.
    fast_plant : Plant, optional
        The same rig at ``Ts = 0.1 s`` for the 10 Hz coherence (fig. 3.5b); skipped if absent.
    seed : int
        Seed of the excitation and the plant's noise.
    validate : bool
        Run the 3211 and doublet validation (False: the estimation run, the model, its modes and residual tests
        only, what a cell carrying a verdict reads at a run's other seeds).
    """
    duration, clock, amp = PRBS_1DOF
    ts = plant.sample_time
    est = excite(plant, random_binary(duration, ts, clock, amp, seed=seed), seed=seed)
    d = siso_data(est)
    model = armax_1dof(d.y, d.u, ts, input=d.input_name, output=d.output_name)
    f, p = psd(d.y, ts, PSD_SEGMENT_1DOF)
    peaks = sorted(find_modes(f, p, MODE_BAND), key=lambda k: -k.height)
    modes = confirmed_modes(peaks, identified_modes(model), bin_1dof(ts))
    f_model, p_model = psd(model.simulate(d.u, d.y), ts, PSD_SEGMENT_1DOF)
    coh = {"5 Hz": coherence(d.u, d.y, ts)}
    if fast_plant is not None:
        fast = excite(fast_plant, random_binary(duration, fast_plant.sample_time, clock, amp, seed=seed), seed=seed)
        df = siso_data(fast)
        coh["10 Hz"] = coherence(df.u, df.y, fast_plant.sample_time)
    validation, fits = {}, {}
    for i, (name, sig) in enumerate(validation_signals(ts, amp, 30.0).items() if validate else ()):
        validation[name] = excite(plant, sig, seed=seed + 1 + i)
        dv = siso_data(validation[name])
        fits[name] = compare(model, dv.y, dv.u, initial="measured")
    tests = residual_tests(model, d.y, d.u, nonlinear=False)
    spectra = {"plant": (f, p), "model": (f_model, p_model)}
    return Siso1Dof(est, validation, model, peaks, spectra, coh, tests, fits, modes)


def identify_2dof(plant: Plant, seed: int = 0, validate: bool = True) -> Mimo2Dof:
    """The 2-DOF identification of ch. 3.4-3.5 on ``plant`` (inputs u1, u2; outputs pitch, yaw; ``Ts = 0.1 s``).

    ``validate`` False skips the doublets and the plant's own response (a run's other seeds).
    """
    duration, clock, amp = PRBS_2DOF
    ts = plant.sample_time
    experiments, validation = {}, {}
    for j, name in enumerate(plant.input_names):
        experiments[name] = excite(
            plant, random_binary(duration, ts, clock, amp, seed=seed + 10 * j), j, seed=seed + 10 * j
        )
        if validate:
            validation[name] = excite(plant, doublet(ts, 2.0, amp, start=2.0, duration=40.0), j, seed=seed + 10 * j + 1)
    mimo = identify_mimo(
        list(experiments.values()),
        *ORDERS,
        band=(0.0, 1.0),
        nperseg=COHERENCE_SEGMENT_2DOF,
        estimation_samples=ESTIMATION_SAMPLES_2DOF,
    )
    coh, peaks, fits, modes = {}, {}, {}, {}
    for name_in, rec in experiments.items():
        du, dy = rec.deviations()
        for i, name_out in enumerate(rec.output_names):
            y = dy[:, i] - dy[:, i].mean()
            ch = mimo.channels[(name_in, name_out)]
            coh[(name_in, name_out)] = (ch.frequencies, ch.coherence)
            f, p = psd(y, ts)
            peaks[(name_in, name_out)] = find_modes(f, p, MODE_BAND)
            found = identified_modes(ch.model) if ch.model is not None else []
            modes[(name_in, name_out)] = confirmed_modes(peaks[(name_in, name_out)], found, bin_2dof(len(y), ts))
            if ch.model is not None and name_in in validation:
                dv = siso_data(validation[name_in], input=name_in, output=name_out)
                fits[(name_in, name_out)] = compare(ch.model, dv.y, dv.u, initial="measured")
    response = response_peaks(plant) if validate else {}
    return Mimo2Dof(experiments, validation, mimo, coh, peaks, fits, modes, response)


def correlation_verdict(t: CorrelationTest) -> str:
    """``"pass"``, or ``"fail (k of n lags outside)"``, for a table cell."""
    return "pass" if t.passed else f"fail ({t.n_outside} of {t.lags.size} lags outside)"
