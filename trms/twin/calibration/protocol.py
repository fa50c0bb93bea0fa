"""The thesis's identification protocols, run on twins, and what is measured from them.

* 1-DOF (ch. 3.2): PRBS of 5 Hz bandwidth on u1, 60 s, recorded at 10 Hz (the thesis's
  coherence rate); the model is identified at 5 Hz (every other sample: the 5 Hz PRBS
  is constant over each pair, so nothing aliases).
* 2-DOF (ch. 3.4): PRBS of 2 Hz band limit and smaller amplitude, 120 s at 10 Hz, one input
  at a time, the other held at trim.

Runs go through :func:`trms.twin.batch.run_open_loop_batch` (``mujoco.rollout``), so many
parameter sets are simulated in one native, multi-threaded call.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from ...identification import signals, spectral
from ...identification.linear import armax
from ...identification.polynomial import PolynomialModel, modes_of_poles
from ...modes import oscillatory
from ...plant import Record
from ..batch import run_open_loop_batch
from ..disturbances import Gust
from ..sensors import DEFAULT_COUNTS_PER_REV
from ..twin import Twin

__all__ = [
    "Protocol",
    "THESIS_PROTOCOLS",
    "FIT_SEEDS",
    "VERIFY_SEEDS",
    "VERIFY_REPEATS",
    "protocol_records",
    "repeated_records",
    "channel_spectra",
    "averaged_spectra",
    "COHERENCE_NPERSEG",
    "psd_nperseg",
    "coherence_nperseg",
    "coherence_floor",
    "peaks_of",
    "main_peaks",
    "lightly_damped",
    "step_figures",
    "identify_1dof",
]

#: Seeds (PRBS realisation and encoder noise) whose runs score calibration candidates, their spectra averaged as
#: the thesis repeated runs until one was undisturbed: as many runs as one verification experiment
#: (:data:`VERIFY_REPEATS`), so that the fit reads the spectra as verification does (an average of two 120 s runs
#: can split the 2-DOF pitch resonance into ripples: seeds 0 and 1 read it at 0.317 Hz).
FIT_SEEDS = (0, 1, 2)
#: Seeds verification runs on: none of them is ever seen by a fit. Each is one experiment of
#: :data:`VERIFY_REPEATS` runs (seeds ``s, s + 1000, ...``) whose spectra are averaged, as the thesis repeated runs.
VERIFY_SEEDS = (101, 102, 103, 104, 105)
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


@dataclass(frozen=True)
class Protocol:
    """One identification experiment: a PRBS on one input around hover.

    Attributes
    ----------
    config : str
    excited : str
        The input excited ("u1" or "u2").
    bandwidth_hz : float
        PRBS clock (Hz).
    duration_s : float
    amplitude_v : float
        PRBS amplitude around the hover voltage (V).
    sample_time : float
        Recording sample time (s).
    seed : int
    """

    config: str
    excited: str
    bandwidth_hz: float
    duration_s: float
    amplitude_v: float
    sample_time: float = 0.1
    seed: int = 0

    def inputs(self, twin: Twin) -> np.ndarray:
        """Absolute voltages (V), shape ``(N, n_inputs)``: the PRBS on the excited input, trim on the rest."""
        return twin.operating_point.with_signal(
            signals.random_binary(
                self.duration_s, self.sample_time, self.bandwidth_hz, self.amplitude_v, seed=self.seed
            ),
            self.excited,
        )


#: The thesis's protocols. It prints no amplitudes ("small enough to stay linear"; the 2-DOF PRBS "of smaller
#: amplitude", the same signal on either input, fig. 3.19): 0.05 V keeps the calibrated twin's pitch within
#: about +-0.2 rad (standard deviation ~0.07 rad) and its yaw within about +-0.3 rad.
THESIS_PROTOCOLS = (
    Protocol("1dof", "u1", 5.0, 60.0, 0.05),
    Protocol("2dof", "u1", 2.0, 120.0, 0.05),
    Protocol("2dof", "u2", 2.0, 120.0, 0.05),
)


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
                "gust": {"std": t.gust.std, "time_constant": t.gust.time_constant},
            },
        )
        for b, (p, t) in enumerate(zip(protocols, twins))
    ]


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


def main_peaks(f: np.ndarray, p: np.ndarray, n: int, band: tuple[float, float] = (0.02, 1.0)) -> list[float]:
    """The ``n`` most prominent peaks (Hz) of a PSD in a band, each at least 1 dB prominent.

    "Among the channel's main peaks": a target counts as met only if a peak this
    prominent sits near it, not any ripple of a lightly averaged spectrum.
    """
    import scipy.signal

    level = 10.0 * np.log10(np.maximum(p, np.max(p) * 1e-30 if np.max(p) > 0 else 1e-300))
    idx, props = scipy.signal.find_peaks(level, prominence=1.0)
    inside = (f[idx] >= band[0]) & (f[idx] <= band[1])
    idx, prom = idx[inside], props["prominences"][inside]
    chosen = idx[np.argsort(-prom)[:n]]
    refined = peaks_of(f, p, band)  # the same peaks, their frequencies interpolated inside the bin
    return sorted(min(refined, key=lambda x: abs(x - f[i])) for i in chosen)


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
    """Delay (time to 5 % of the final value) and time constant (5 % to 63 %) of a discrete model's step (s)."""
    import control

    dt = float(system.dt)
    t = np.arange(0.0, 60.0, dt)
    _, y = control.step_response(system, T=t)
    y = np.ravel(y)
    final = float(np.ravel(control.dcgain(system))[0])
    if final == 0 or not np.isfinite(final):
        return float("nan"), float("nan")
    frac = y / final

    def crossing(level: float) -> float:
        i = int(np.argmax(frac >= level))
        if frac[i] < level:
            return float("nan")
        if i == 0:
            return 0.0
        return float(t[i - 1] + (level - frac[i - 1]) / (frac[i] - frac[i - 1]) * dt)

    d = crossing(0.05)
    return d, crossing(0.63) - d


def identify_1dof(record: Record, decimate: int = 2) -> PolynomialModel:
    """4th-order ARMAX (eq. 3.2, nk = 1) of a 1-DOF protocol record at ``decimate`` times its sample time."""
    du, dy = record.deviations()
    return armax(
        dy[::decimate, 0], du[::decimate, 0], na=4, nb=4, nc=4, nk=1, sample_time=record.sample_time * decimate
    )
