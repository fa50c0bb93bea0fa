"""The thesis's identification protocols, run on twins, and what is measured from them.

* 1-DOF (ch. 3.2): PRBS of 5 Hz bandwidth on u1, 60 s, recorded at 10 Hz (the thesis's
  coherence rate); the model is identified at 5 Hz (every other sample: the 5 Hz PRBS
  is constant over each pair, so nothing aliases).
* 2-DOF (ch. 3.4): PRBS of 2 Hz band limit and smaller amplitude, 120 s at 10 Hz, one input
  at a time, the other held at trim.
* The rig at rest (:data:`HOVER_PROTOCOL`): 2-DOF, both inputs held at trim for 120 s at 10 Hz; what
  moves is the rig's ambient excitation (the thesis: "a minor oscillatory tendency even in steady state").
* Ch. 5's training experiment (:data:`RESIDUAL_PROTOCOL`): 1-DOF, uniformly distributed noise of a 2 Hz
  clock on u1, 60 s at 5 Hz; a 4th-order ARMAX's one-step residual variance is Table 5.1's figure.
* The step (:data:`STEP_PROTOCOL`): 1-DOF, u1 stepped from hover by ``+A`` and by ``-A`` at t = 0, 60 s at 5 Hz;
  the mean of ``(y+ - y-) / 2A`` over the runs is the rig's small-signal step per volt (the two signs cancel
  the thrust curve's curvature, the runs the ambient excitation), read by :func:`tangent_figures` as
  eq. (3.11)'s own step is.

Runs go through :func:`trms.batch.rollouts.run_open_loop_batch` (``mujoco.rollout``), so many
parameter sets are simulated in one native, multi-threaded call.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from trms import signals
from trms.batch.rollouts import run_open_loop_batch
from trms.errors import InputError, check_choice
from trms.identification import spectral
from trms.identification.linear import armax
from trms.identification.polynomial import PolynomialModel, modes_of_poles
from trms.identification.validation import residual_variance
from trms.modes import oscillatory
from trms.record import Record
from trms.twin.disturbances import Gust
from trms.twin.sensors import DEFAULT_COUNTS_PER_REV
from trms.twin.twin import Twin

__all__ = [
    "Protocol",
    "THESIS_PROTOCOLS",
    "FIT_SEEDS",
    "VERIFY_SEEDS",
    "VERIFY_REPEATS",
    "HOVER_PROTOCOL",
    "RESIDUAL_PROTOCOL",
    "STEP_PROTOCOL",
    "protocol_records",
    "repeated_records",
    "hover_rms",
    "armax_residual_variance",
    "mean_step",
    "tangent_figures",
    "system_step",
    "step_fit_percent",
    "STEP_FIT_WINDOW",
    "channel_spectra",
    "averaged_spectra",
    "COHERENCE_NPERSEG",
    "psd_nperseg",
    "coherence_nperseg",
    "coherence_floor",
    "peaks_of",
    "main_peaks",
    "ranked_peaks",
    "lightly_damped",
    "step_figures",
    "crossing_figures",
    "identify_1dof",
    "armax_1dof",
    "ARMAX_ORDERS",
]

#: Seeds (PRBS realisation and encoder noise) whose runs score calibration candidates, their spectra averaged as
#: the thesis repeated runs until one was undisturbed: as many runs as one verification experiment
#: (:data:`VERIFY_REPEATS`), so that the fit reads the spectra as verification does (an average of two 120 s runs
#: can split the 2-DOF pitch resonance into ripples: seeds 0 and 1 read it at 0.317 Hz).
FIT_SEEDS = (0, 1, 2)
#: Seeds verification runs on: none of them is ever seen by a fit. Each is one experiment of
#: :data:`VERIFY_REPEATS` runs (seeds ``s, s + 1000, ...``) whose spectra are averaged, as the thesis repeated runs.
VERIFY_SEEDS = tuple(range(101, 111))
VERIFY_REPEATS = 3

#: Spectra: 256-sample Hann segments at 10 Hz (0.039 Hz bins) for the 60 s 1-DOF records; 512 (0.0195 Hz bins)
#: for the 120 s 2-DOF ones, whose 0.1 Hz yaw mode is a peak narrower than a 0.039 Hz bin (damping about 0.04:
#: half-power width 0.008 Hz) and would fall between two bins' centres (0.078 and 0.117 Hz).
NPERSEG = 256
NPERSEG_LONG = 512
#: Coherence, whatever the record length: 256-sample segments. Coherence needs averages more than resolution: for
#: signals with no relation at all, the estimate's median over 0.02-1 Hz is about ``1 / K`` for ``K`` segments, which
#: 512-sample segments of a 120 s record (3 segments) put at the 'low' threshold itself (:func:`coherence_floor`).
COHERENCE_NPERSEG = 256


def psd_nperseg(n_samples: int) -> int:
    """Welch segment length (samples) of a protocol record's PSD: 512 when the record holds two, else 256."""
    return NPERSEG_LONG if n_samples >= 2 * NPERSEG_LONG else min(NPERSEG, n_samples // 2)


def coherence_nperseg(n_samples: int) -> int:
    """Welch segment length (samples) of a protocol record's coherence (:data:`COHERENCE_NPERSEG`)."""
    return min(COHERENCE_NPERSEG, n_samples // 2)


def coherence_floor(
    n_samples: int,
    nperseg: int,
    repeats: int = VERIFY_REPEATS,
    band_hz: tuple[float, float] = (0.02, 1.0),
    sample_time: float = 0.1,
    trials: int = 200,
    seed: int = 0,
) -> tuple[float, float]:
    """What the coherence estimate reads for two unrelated signals: the median over ``band_hz`` of the
    coherence averaged over ``repeats`` runs, as :func:`averaged_spectra` and the targets measure it.

    Parameters
    ----------
    n_samples : int
        Record length (samples).
    nperseg : int
        Welch segment length (samples).
    repeats : int
        Runs whose coherence is averaged bin by bin.
    band_hz : (float, float)
        Band of the median (Hz).
    sample_time : float
        Sample time (s).
    trials : int
        Monte Carlo trials (independent white signals, seeded).
    seed : int

    Returns
    -------
    (float, float)
        Mean and 95th percentile over the trials (dimensionless).

    Examples
    --------
    >>> mean, p95 = coherence_floor(1200, 256, trials=50)
    >>> 0.05 < mean < p95 < 0.2
    True
    """
    rng = np.random.default_rng(seed)
    levels = np.empty(trials)
    for i in range(trials):
        runs = []
        for _ in range(repeats):
            x, y = rng.standard_normal((2, n_samples))
            f, c = spectral.coherence(x, y, sample_time, nperseg=nperseg)
            runs.append(c)
        band = (f >= band_hz[0]) & (f <= band_hz[1])
        levels[i] = np.median(np.mean(runs, axis=0)[band])
    return float(levels.mean()), float(np.percentile(levels, 95))


#: The signals a protocol may drive its input with.
SIGNALS = ("prbs", "uniform", "hold", "step")


@dataclass(frozen=True)
class Protocol:
    """One experiment on the rig around hover: a signal on one input, the others held at trim.

    Attributes
    ----------
    config : str
    excited : str
        The input excited ("u1" or "u2").
    bandwidth_hz : float
        Clock of the PRBS or of the uniform noise (Hz); unused by ``hold`` and ``step``.
    duration_s : float
    amplitude_v : float
        PRBS amplitude, half-width of the uniform noise, or the step (signed), around the hover voltage (V).
    sample_time : float
        Recording sample time (s).
    seed : int
    signal : {"prbs", "uniform", "hold", "step"}
        Random binary (:func:`~trms.signals.random_binary`), uniform noise
        (:func:`~trms.signals.uniform_noise`), the trim held, or a step at t = 0.
    """

    config: str
    excited: str
    bandwidth_hz: float
    duration_s: float
    amplitude_v: float
    sample_time: float = 0.1
    seed: int = 0
    signal: str = "prbs"

    def __post_init__(self) -> None:
        check_choice("protocol signal", self.signal, SIGNALS)

    def deviation(self) -> np.ndarray:
        """The excited input's deviation from trim (V), shape ``(N,)``.

        Examples
        --------
        >>> Protocol("1dof", "u1", 0.0, 1.0, -0.1, 0.2, signal="step").deviation().tolist()
        [-0.1, -0.1, -0.1, -0.1, -0.1]
        """
        n = int(round(self.duration_s / self.sample_time))
        if self.signal == "hold":
            return np.zeros(n)
        if self.signal == "step":
            return np.full(n, float(self.amplitude_v))
        make = signals.random_binary if self.signal == "prbs" else signals.uniform_noise
        return make(self.duration_s, self.sample_time, self.bandwidth_hz, self.amplitude_v, seed=self.seed)

    def inputs(self, twin: Twin) -> np.ndarray:
        """Absolute voltages (V), shape ``(N, n_inputs)``: the signal on the excited input, trim on the rest."""
        return twin.operating_point.with_signal(self.deviation(), self.excited)


#: The thesis's protocols. It prints no amplitudes ("small enough to stay linear"; the 2-DOF PRBS "of smaller
#: amplitude", the same signal on either input, fig. 3.19): 0.05 V keeps the calibrated twin's pitch within
#: about +-0.2 rad (standard deviation ~0.07 rad) and its yaw within about +-0.3 rad.
THESIS_PROTOCOLS = (
    Protocol("1dof", "u1", 5.0, 60.0, 0.05),
    Protocol("2dof", "u1", 2.0, 120.0, 0.05),
    Protocol("2dof", "u2", 2.0, 120.0, 0.05),
)
#: The rig left at hover, both inputs at trim (2-DOF, 120 s at 10 Hz): its ambient motion.
HOVER_PROTOCOL = Protocol("2dof", "u1", 0.0, 120.0, 0.0, 0.1, signal="hold")
#: Ch. 5's training experiment (1-DOF, 5 Hz, 300 samples): uniform noise of a 2 Hz clock and 0.15 V half-width
#: (the thesis prints no amplitude: this project's choice, within the linear range around hover).
RESIDUAL_PROTOCOL = Protocol("1dof", "u1", 2.0, 60.0, 0.15, 0.2, signal="uniform")
#: The small-signal step (1-DOF, 5 Hz, eq. (3.11)'s sample time): +0.1 V, run beside its mirror -0.1 V, for 40 s
#: (the 0.34 Hz ringing has decayed to a few per cent by the last 10 s, whose mean is the final value).
STEP_PROTOCOL = Protocol("1dof", "u1", 0.0, 40.0, 0.1, 0.2, signal="step")


def protocol_records(
    specs: list[mujoco.MjSpec],
    protocol: Protocol,
    counts_per_rev: int | None = None,
    seed: int | None = None,
    gust: Gust | None = None,
) -> list[Record]:
    """Run one protocol on twins built from ``specs`` (one batch); return one Record each.

    Parameters
    ----------
    specs : list of mujoco.MjSpec
        Parameter sets (same structure).
    protocol : Protocol
    counts_per_rev : int, optional
        Encoder resolution (default: the twin's default).
    seed : int, optional
        Overrides the protocol's seed (PRBS realisation, encoder noise and gusts).
    gust : Gust, optional
        Ambient gust torques during the runs (default: still air, as the calibration's protocols).
    """
    s = protocol.seed if seed is None else int(seed)
    return _run_batch([(spec, s) for spec in specs], protocol, counts_per_rev, gust)


def repeated_records(
    spec: mujoco.MjSpec,
    protocol: Protocol,
    seeds: Sequence[int],
    counts_per_rev: int | None = None,
    gust: Gust | None = None,
) -> list[Record]:
    """Run one protocol on one twin at each of ``seeds`` (one batch, the runs side by side on the cores).

    Each run equals ``protocol_records([spec], protocol, seed=s)[0]`` bit for bit.

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> p = Protocol("1dof", "u1", 5.0, 2.0, 0.05)
    >>> a, b = repeated_records(load_spec(), p, seeds=(3, 4))
    >>> (a.metadata["seed"], b.metadata["seed"])
    (3, 4)
    """
    return _run_batch([(spec, int(s)) for s in seeds], protocol, counts_per_rev, gust)


def _run_batch(
    runs: list[tuple[mujoco.MjSpec, int]], protocol: Protocol, counts_per_rev: int | None, gust: Gust | None
) -> list[Record]:
    """One Record per ``(spec, seed)``, all run in one :func:`run_open_loop_batch` call."""
    counts = DEFAULT_COUNTS_PER_REV if counts_per_rev is None else counts_per_rev
    protocols = [dataclasses.replace(protocol, seed=seed) for _, seed in runs]
    twins = [
        Twin(p.config, p.sample_time, seed=p.seed, spec=spec, counts_per_rev=counts, gust=gust)
        for p, (spec, _) in zip(protocols, runs)
    ]
    inputs = np.stack([p.inputs(t) for p, t in zip(protocols, twins)])
    outputs = run_open_loop_batch(twins, inputs)
    time = np.arange(inputs.shape[1]) * protocol.sample_time
    return [
        Record(
            time,
            inputs[b],
            outputs[b],
            t.input_names,
            t.output_names,
            {},
            {
                "sample_time": p.sample_time,
                "config": p.config,
                "seed": p.seed,
                "operating_point": t.operating_point.to_dict(),
                "excited": p.excited,
                "signal": p.signal,
                "counts_per_rev": t.encoder.counts_per_rev,
                "gust": {"std": t.gust.std, "time_constant": t.gust.time_constant},
            },
        )
        for b, (p, t) in enumerate(zip(protocols, twins))
    ]


def hover_rms(records: Sequence[Record], output: str) -> float:
    """RMS (rad) of ``output``'s deviation from its mean, averaged over ``records`` (runs of one protocol)."""
    return float(np.mean([np.std(r.outputs[:, r.output_names.index(output)]) for r in records]))


def armax_residual_variance(record: Record) -> float:
    """Table 5.1's figure: the variance (rad^2) of the one-step residuals of a 4th-order ARMAX (eq. 3.2) fitted to
    a 1-DOF record at its own sample time."""
    du, dy = record.deviations()
    model = armax_1dof(dy[:, 0], du[:, 0], record.sample_time)
    return residual_variance(model, dy[:, 0], du[:, 0])


def mean_step(plus: Sequence[Record], minus: Sequence[Record]) -> tuple[np.ndarray, np.ndarray]:
    """The small-signal step per volt: the mean over pairs of ``(y+ - y-) / (A+ - A-)`` (rad/V).

    Parameters
    ----------
    plus, minus : sequence of Record
        Runs of a step up and of the mirror step down (same length and sample time); a run's step is
        its first input deviation.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Time (s) and the mean response per volt (rad/V), the first sample at the step.
    """
    if not plus or len(plus) != len(minus):
        raise InputError(f"mean_step needs as many up as down steps (at least one), got {len(plus)} and {len(minus)}")
    per_volt = []
    for up, down in zip(plus, minus):
        (du_up, dy_up), (du_dn, dy_dn) = up.deviations(), down.deviations()
        per_volt.append((dy_up[:, 0] - dy_dn[:, 0]) / (du_up[0, 0] - du_dn[0, 0]))
    return plus[0].time - plus[0].time[0], np.mean(per_volt, axis=0)


#: The window of the step fit (s), from the step: eq. (3.11)'s first three periods of its 0.34 Hz mode and more.
STEP_FIT_WINDOW = 15.0


def tangent_figures(time: np.ndarray, response: np.ndarray, final_window: float = 10.0) -> tuple[float, float]:
    """Dead time and time constant (s) of a step response by the tangent (maximum-slope) construction.

    The tangent at the steepest point of the first rise crosses the start level at the dead time and the
    final value (the mean of the last ``final_window`` s) one time constant later. The same function reads
    eq. (3.11)'s step and the twin's mean step.

    Parameters
    ----------
    time : numpy.ndarray
        Sample times from the step (s).
    response : numpy.ndarray
        The response (any unit), starting from 0 at the step.
    final_window : float
        Length (s) of the end of the record that gives the final value.

    Returns
    -------
    (float, float)
        Dead time and time constant (s); NaN when the response has no final value of its own sign.

    Examples
    --------
    >>> t = np.arange(0.0, 60.0, 0.05)
    >>> y = np.where(t > 1.0, 1.0 - np.exp(-(t - 1.0) / 2.0), 0.0)  # a delay of 1 s and a lag of 2 s
    >>> [round(x, 1) for x in tangent_figures(t, y)]
    [1.0, 2.0]
    """
    t, y = np.asarray(time, float), np.asarray(response, float)
    final = float(np.mean(y[t >= t[-1] - final_window]))
    if final == 0 or not np.isfinite(final):
        return float("nan"), float("nan")
    slope = np.diff(y) / np.diff(t) * np.sign(final)
    # The first rise: up to the first crossing of the final value, or the whole record.
    first = int(np.argmax(np.sign(final) * y >= abs(final))) or y.size - 1
    i = int(np.argmax(slope[: max(first, 1)]))
    if slope[i] <= 0:
        return float("nan"), float("nan")
    t_mid, y_mid = 0.5 * (t[i] + t[i + 1]), 0.5 * (y[i] + y[i + 1]) * np.sign(final)
    return float(t_mid - y_mid / slope[i]), float(abs(final) / slope[i])


def system_step(system, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """Time (s) and unit-step response of a discrete LTI model over ``duration`` s, at its own sample time.

    Examples
    --------
    >>> import control
    >>> t, y = system_step(control.tf([0.5], [1.0, -0.5], 0.2), 1.0)
    >>> t.round(3).tolist(), y.round(3).tolist()
    ([0.0, 0.2, 0.4, 0.6, 0.8], [0.0, 0.5, 0.75, 0.875, 0.938])
    """
    import control

    t = np.arange(int(round(duration / float(system.dt)))) * float(system.dt)
    if isinstance(system, control.TransferFunction):  # scipy's realisation, the same bits with or without slycot
        system = control.tf2ss(system, method="scipy")
    _, y = control.step_response(system, T=t)
    return t, np.ravel(y)


def step_fit_percent(
    time: np.ndarray, response: np.ndarray, reference: np.ndarray, window: float = STEP_FIT_WINDOW
) -> float:
    """NRMSE fit (%) of a step response to a reference one over the first ``window`` s:
    ``100 (1 - ||y - r|| / ||r - mean(r)||)``, 100 for a perfect match.

    Examples
    --------
    >>> t = np.arange(0.0, 20.0, 0.2)
    >>> r = 1.0 - np.exp(-t)
    >>> step_fit_percent(t, r, r), round(step_fit_percent(t, 0.9 * r, r), 1)
    (100.0, 49.2)
    """
    keep = np.asarray(time) <= window
    y, r = np.asarray(response, float)[keep], np.asarray(reference, float)[keep]
    return float(100.0 * (1.0 - np.linalg.norm(y - r) / np.linalg.norm(r - r.mean())))


def channel_spectra(
    record: Record, channel_output: str, psd_segment: int | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(f, PSD of the output deviation, coherence with the excited input)`` of one protocol record.

    The PSD uses :func:`psd_nperseg` segments (or ``psd_segment`` samples), the coherence
    :func:`coherence_nperseg` ones, given on the PSD's frequencies (linear interpolation).
    """
    du, dy = record.deviations()
    k = record.input_names.index(record.metadata["excited"])
    j = record.output_names.index(channel_output)
    nper = psd_nperseg(len(record)) if psd_segment is None else min(psd_segment, len(record) // 2)
    f, p = spectral.psd(dy[:, j], record.sample_time, nperseg=nper)
    if np.ptp(dy[:, j]) == 0:  # the encoder never moved: no linear relation can be measured
        return f, p, np.zeros_like(f)
    fc, c = spectral.coherence(du[:, k], dy[:, j], record.sample_time, nperseg=coherence_nperseg(len(record)))
    return f, p, np.interp(f, fc, c)


def averaged_spectra(
    records: list[Record], channel_output: str, psd_segment: int | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`channel_spectra` averaged over repeated runs of one protocol (PSD and coherence, bin by bin)."""
    spectra = [channel_spectra(r, channel_output, psd_segment) for r in records]
    f = spectra[0][0]
    return f, np.mean([s[1] for s in spectra], axis=0), np.mean([s[2] for s in spectra], axis=0)


def peaks_of(f: np.ndarray, p: np.ndarray, band: tuple[float, float] = (0.02, 1.0)) -> list[float]:
    """Peak frequencies (Hz) of a PSD in a band (at least 1 dB prominent), interpolated inside the bin."""
    return [pk.frequency for pk in spectral.find_modes(f, p, band, min_prominence_db=1.0)]


def ranked_peaks(f: np.ndarray, p: np.ndarray, band: tuple[float, float] = (0.02, 1.0)) -> list[tuple[float, float]]:
    """Every peak of a PSD in a band at least 1 dB prominent, as ``(frequency (Hz), prominence (dB))``, the most
    prominent first; frequencies interpolated inside the bin.

    Examples
    --------
    >>> f = np.linspace(0.0, 1.0, 101)
    >>> p = 1.0 + 9.0 * np.exp(-(((f - 0.3) / 0.02) ** 2)) + 2.0 * np.exp(-(((f - 0.7) / 0.02) ** 2))
    >>> [(round(a, 2), round(b, 1)) for a, b in ranked_peaks(f, p)]
    [(0.3, 10.0), (0.7, 4.8)]
    """
    import scipy.signal

    level = 10.0 * np.log10(np.maximum(p, np.max(p) * 1e-30 if np.max(p) > 0 else 1e-300))
    idx, props = scipy.signal.find_peaks(level, prominence=1.0)
    inside = (f[idx] >= band[0]) & (f[idx] <= band[1])
    idx, prom = idx[inside], props["prominences"][inside]
    order = np.argsort(-prom, kind="stable")
    refined = peaks_of(f, p, band)  # the same peaks, their frequencies interpolated inside the bin
    return [(min(refined, key=lambda x: abs(x - f[idx[k]])), float(prom[k])) for k in order]


def main_peaks(f: np.ndarray, p: np.ndarray, n: int, band: tuple[float, float] = (0.02, 1.0)) -> list[float]:
    """The ``n`` most prominent peaks (Hz) of a PSD in a band, each at least 1 dB prominent.

    "Among the channel's main peaks": a target counts as met only if a peak this
    prominent sits near it, not any ripple of a lightly averaged spectrum.
    """
    return sorted(freq for freq, _ in ranked_peaks(f, p, band)[:n])


def lightly_damped(poles: np.ndarray, sample_time: float, near_hz: float | None = None) -> tuple[float, float]:
    """Frequency (Hz) and damping ratio of the least damped complex pole pair of a discrete model.

    With ``near_hz``, the pair closest to that frequency instead (``nan`` when there is none).
    """
    modes = [m for m in oscillatory(modes_of_poles(np.asarray(poles), sample_time), sample_time) if m.damping < 0.5]
    if not modes:
        return float("nan"), float("nan")
    m = min(modes, key=(lambda x: abs(x.frequency_hz - near_hz)) if near_hz is not None else (lambda x: x.damping))
    return m.frequency_hz, m.damping


def step_figures(system) -> tuple[float, float]:
    """Delay (time to 5 % of the final value) and time constant (5 % to 63 %) of a discrete model's step (s): the
    crossing figures (:func:`crossing_figures`) of its 60 s step, the final value its DC gain."""
    import control

    final = float(np.ravel(control.dcgain(system))[0])
    return crossing_figures(*system_step(system, 60.0), final=final)


def crossing_figures(time: np.ndarray, response: np.ndarray, final: float | None = None) -> tuple[float, float]:
    """Delay (time to 5 % of the final value) and time constant (5 % to 63 %) of a step response (s).

    Parameters
    ----------
    time, response : numpy.ndarray
        The step response from the step (s; any unit).
    final : float, optional
        Its final value; default: the mean of its last 10 s (as :func:`tangent_figures`).

    Examples
    --------
    >>> t = np.arange(0.0, 60.0, 0.05)
    >>> y = np.where(t > 1.0, 1.0 - np.exp(-(t - 1.0) / 2.0), 0.0)
    >>> [round(x, 2) for x in crossing_figures(t, y)]
    [1.1, 1.89]
    """
    t, y = np.asarray(time, float), np.asarray(response, float)
    final = float(np.mean(y[t >= t[-1] - 10.0])) if final is None else final
    if final == 0 or not np.isfinite(final):
        return float("nan"), float("nan")
    frac = y / final

    def crossing(level: float) -> float:
        i = int(np.argmax(frac >= level))
        if frac[i] < level:
            return float("nan")
        if i == 0:
            return 0.0
        return float(t[i - 1] + (level - frac[i - 1]) / (frac[i] - frac[i - 1]) * (t[i] - t[i - 1]))

    d = crossing(0.05)
    return d, crossing(0.63) - d


#: The thesis's ARMAX orders (na, nb, nc, nk), as eq. (3.11).
ARMAX_ORDERS = (4, 4, 4, 1)
#: Gauss-Newton iterations allowed to the 1-DOF ARMAX: on ch. 5's uniform-noise records of the rig (with its ambient
#: excitation) the default 200 can end a few iterations short of the tolerance.
ARMAX_MAX_ITER = 1000


def armax_1dof(
    y: np.ndarray, u: np.ndarray, sample_time: float, input: str = "u1", output: str = "pitch"
) -> PolynomialModel:
    """The thesis's 4th-order ARMAX (eq. 3.2, :data:`ARMAX_ORDERS`) of deviations ``y`` (rad) on ``u`` (V).

    Every 1-DOF ARMAX of the project is fitted here: chapters 3 and 5, the calibration's model target and
    Table 5.1's residual variance.
    """
    na, nb, nc, nk = ARMAX_ORDERS
    return armax(y, u, na, nb, nc, nk, sample_time=sample_time, input=input, output=output, max_iter=ARMAX_MAX_ITER)


def identify_1dof(record: Record, decimate: int = 2) -> PolynomialModel:
    """4th-order ARMAX (eq. 3.2, nk = 1) of a 1-DOF protocol record at ``decimate`` times its sample time."""
    du, dy = record.deviations()
    return armax_1dof(dy[::decimate, 0], du[::decimate, 0], record.sample_time * decimate)
