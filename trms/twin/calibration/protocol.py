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

from dataclasses import dataclass

import mujoco
import numpy as np

from ...identification import signals, spectral
from ...identification.linear import armax
from ...identification.polynomial import modes_of_poles
from ...plant import Record
from ..batch import run_open_loop_batch
from ..twin import Twin

__all__ = ["Protocol", "THESIS_PROTOCOLS", "protocol_records", "channel_spectra", "peaks_of", "lightly_damped",
           "step_figures", "identify_1dof"]

#: Spectra: 256-sample Hann segments at 10 Hz (0.039 Hz bins, 4-8 averages).
NPERSEG = 256


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
        n = signals.sample_count(self.duration_s, self.sample_time)
        u = np.tile(twin.operating_point.inputs, (n, 1))
        k = twin.input_names.index(self.excited)
        u[:, k] = signals.random_binary(self.duration_s, self.sample_time, self.bandwidth_hz, self.amplitude_v,
                               offset=float(u[0, k]), seed=self.seed)
        return u


#: The thesis's protocols. It prints no amplitudes ("small enough to stay linear"; the 2-DOF PRBS "of smaller
#: amplitude", the same signal on either input, fig. 3.19): 0.05 V keeps the calibrated twin's pitch within
#: about +-0.2 rad (standard deviation ~0.07 rad) and its yaw within about +-0.3 rad.
THESIS_PROTOCOLS = (
    Protocol("1dof", "u1", 5.0, 60.0, 0.05),
    Protocol("2dof", "u1", 2.0, 120.0, 0.05),
    Protocol("2dof", "u2", 2.0, 120.0, 0.05),
)


def protocol_records(specs: list[mujoco.MjSpec], protocol: Protocol, counts_per_rev: int | None = None) -> list[Record]:
    """Run one protocol on twins built from ``specs`` (one batch); return one Record each.

    Parameters
    ----------
    specs : list of mujoco.MjSpec
        Parameter sets (same structure).
    protocol : Protocol
    counts_per_rev : int, optional
        Encoder resolution (default: the twin's default).
    """
    kwargs = {} if counts_per_rev is None else {"counts_per_rev": counts_per_rev}
    twins = [Twin(protocol.config, protocol.sample_time, seed=protocol.seed, spec=s, **kwargs) for s in specs]
    inputs = np.stack([protocol.inputs(t) for t in twins])
    outputs = run_open_loop_batch(twins, inputs)
    time = np.arange(inputs.shape[1]) * protocol.sample_time
    return [
        Record(time, inputs[b], outputs[b], t.input_names, t.output_names, {},
               {"sample_time": protocol.sample_time, "config": protocol.config, "seed": protocol.seed,
                "operating_point": t.operating_point.to_dict(), "excited": protocol.excited})
        for b, t in enumerate(twins)
    ]


def channel_spectra(record: Record, channel_output: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(f, PSD of the output deviation, coherence with the excited input)`` of one protocol record."""
    du, dy = record.deviations()
    k = record.input_names.index(record.metadata["excited"])
    j = record.output_names.index(channel_output)
    nper = min(NPERSEG, len(record) // 2)
    f, p = spectral.psd(dy[:, j], record.sample_time, nperseg=nper)
    if np.ptp(dy[:, j]) == 0:  # the encoder never moved: no linear relation can be measured
        return f, p, np.zeros_like(f)
    _, c = spectral.coherence(du[:, k], dy[:, j], record.sample_time, nperseg=nper)
    return f, p, c


def peaks_of(f: np.ndarray, p: np.ndarray, band: tuple[float, float] = (0.02, 1.0)) -> list[float]:
    """Peak frequencies (Hz) of a PSD in a band (at least 1 dB prominent), interpolated inside the bin."""
    return [pk.frequency for pk in spectral.find_modes(f, p, band, min_prominence_db=1.0)]


def lightly_damped(poles: np.ndarray, sample_time: float, near_hz: float | None = None) -> tuple[float, float]:
    """Frequency (Hz) and damping ratio of the least damped complex pole pair of a discrete model.

    With ``near_hz``, the pair closest to that frequency instead (``nan`` when there is none).
    """
    modes = [m for m in modes_of_poles(np.asarray(poles), sample_time) if m.damping < 0.5 and m.pole.imag > 0]
    if not modes:
        return float("nan"), float("nan")
    m = min(modes, key=(lambda x: abs(x.frequency - near_hz)) if near_hz is not None else (lambda x: x.damping))
    return m.frequency, m.damping


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


def identify_1dof(record: Record, decimate: int = 2):
    """4th-order ARMAX (eq. 3.2, nk = 1) of a 1-DOF protocol record at ``decimate`` times its sample time."""
    du, dy = record.deviations()
    return armax(dy[::decimate, 0], du[::decimate, 0], na=4, nb=4, nc=4, nk=1, sample_time=record.sample_time * decimate)
