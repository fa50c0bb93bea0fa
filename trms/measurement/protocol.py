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
  the thrust curve's curvature, the runs the ambient excitation), read by
  :func:`~trms.measurement.step_response.tangent_figures` as eq. (3.11)'s own step is.

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
    "lightly_damped",
    "identify_protocol_record",
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


#: The signals a protocol may drive its input with.
SIGNALS = ("prbs", "uniform", "hold", "step")


@dataclass(frozen=True)
class Protocol:
    """One experiment on the rig around hover: a signal on one input, the others held at trim.

    Attributes
    ----------
    config : str
        The rig configuration ("1dof", "2dof" or "yaw").
    excited : str
        The input excited ("u1" or "u2").
    bandwidth_hz : float
        Clock of the PRBS or of the uniform noise (Hz); unused by ``hold`` and ``step``.
    duration_s : float
        Length of the run (s).
    amplitude_v : float
        PRBS amplitude, half-width of the uniform noise, or the step (signed), around the hover voltage (V).
    sample_time : float
        Recording sample time (s).
    seed : int
        Seed of the signal (and of the twin's noise when run).
    signal : {"prbs", "uniform", "hold", "step"}
        Random binary (:func:`~trms.signals.random_binary`), uniform noise
        (:func:`~trms.signals.uniform_noise`), the trim held, or a step at t = 0.

    Examples
    --------
    >>> p = Protocol("1dof", "u1", 5.0, 60.0, 0.05)
    >>> p.deviation().shape, float(abs(p.deviation()).max())
    ((600,), 0.05)
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

    Returns
    -------
    list of Record
        One run per spec: absolute voltages (V) in, encoder angles (rad) out, metadata ``config``,
        ``seed``, ``excited``, ``signal``.

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> (rec,) = protocol_records([load_spec()], Protocol("1dof", "u1", 5.0, 2.0, 0.05), seed=7)
    >>> len(rec), rec.metadata["seed"], rec.output_names
    (20, 7, ('pitch',))
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
    """RMS (rad) of ``output``'s deviation from its mean, averaged over ``records`` (runs of one protocol).

    Parameters
    ----------
    records : sequence of Record
        Runs of one protocol (radians out).
    output : str
        The output's name.

    Returns
    -------
    float
        The mean of the runs' standard deviations (rad).

    Examples
    --------
    >>> from trms.record import Record
    >>> t = np.arange(4) * 0.1
    >>> runs = [Record(t, np.zeros((4, 1)), np.array([[a], [-a], [a], [-a]]), ("u1",), ("pitch",)) for a in (1, 3)]
    >>> hover_rms(runs, "pitch")
    2.0
    """
    return float(np.mean([np.std(r.outputs[:, r.output_names.index(output)]) for r in records]))


def armax_residual_variance(record: Record) -> float:
    """Table 5.1's figure: the variance (rad^2) of the one-step residuals of a 4th-order ARMAX (eq. 3.2) fitted to
    a 1-DOF record at its own sample time.

    Parameters
    ----------
    record : Record
        A 1-DOF run (volts in, radians out), e.g. of :data:`RESIDUAL_PROTOCOL`.

    Returns
    -------
    float
        The residual variance (rad^2).

    Examples
    --------
    >>> import dataclasses
    >>> from trms.twin import load_spec
    >>> (rec,) = protocol_records([load_spec()], dataclasses.replace(RESIDUAL_PROTOCOL, duration_s=30.0))
    >>> 0.0 < armax_residual_variance(rec) < 1e-3
    True
    """
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

    Examples
    --------
    >>> import dataclasses
    >>> from trms.twin import load_spec
    >>> short = dataclasses.replace(STEP_PROTOCOL, duration_s=4.0)
    >>> up = protocol_records([load_spec()], short)
    >>> down = protocol_records([load_spec()], dataclasses.replace(short, amplitude_v=-short.amplitude_v))
    >>> t, y = mean_step(up, down)
    >>> t[:3].round(2).tolist(), bool(y[-1] > 0)
    ([0.0, 0.2, 0.4], True)
    """
    if not plus or len(plus) != len(minus):
        raise InputError(f"mean_step needs as many up as down steps (at least one), got {len(plus)} and {len(minus)}")
    per_volt = []
    for up, down in zip(plus, minus):
        (du_up, dy_up), (du_dn, dy_dn) = up.deviations(), down.deviations()
        per_volt.append((dy_up[:, 0] - dy_dn[:, 0]) / (du_up[0, 0] - du_dn[0, 0]))
    return plus[0].time - plus[0].time[0], np.mean(per_volt, axis=0)


def lightly_damped(poles: np.ndarray, sample_time: float, near_hz: float | None = None) -> tuple[float, float]:
    """Frequency (Hz) and damping ratio of the least damped complex pole pair of a discrete model.

    With ``near_hz``, the pair closest to that frequency instead (``nan`` when there is none).

    Parameters
    ----------
    poles : numpy.ndarray
        Poles of a discrete model (z-plane).
    sample_time : float
        Its sample time (s).
    near_hz : float, optional
        Pick the pair nearest this frequency (Hz) instead of the least damped.

    Returns
    -------
    (float, float)
        Frequency (Hz) and damping ratio (dimensionless) of the pair with damping below 0.5.

    Examples
    --------
    >>> from trms.reference import eq_3_11
    >>> [round(x, 2) for x in lightly_damped(eq_3_11().poles(), 0.2)]
    [0.34, 0.04]
    """
    modes = [m for m in oscillatory(modes_of_poles(np.asarray(poles), sample_time), sample_time) if m.damping < 0.5]
    if not modes:
        return float("nan"), float("nan")
    m = min(modes, key=(lambda x: abs(x.frequency_hz - near_hz)) if near_hz is not None else (lambda x: x.damping))
    return m.frequency_hz, m.damping


#: The thesis's ARMAX orders (na, nb, nc, nk), as eq. (3.11).
ARMAX_ORDERS = (4, 4, 4, 1)


def armax_1dof(
    y: np.ndarray, u: np.ndarray, sample_time: float, input: str = "u1", output: str = "pitch"
) -> PolynomialModel:
    """The thesis's 4th-order ARMAX (eq. 3.2, :data:`ARMAX_ORDERS`) of deviations ``y`` (rad) on ``u`` (V).

    Every 1-DOF ARMAX of the project is fitted here: chapters 3 and 5, the calibration's model target and
    Table 5.1's residual variance.

    Parameters
    ----------
    y, u : numpy.ndarray
        Output (rad) and input (V) deviations, shape ``(N,)``.
    sample_time : float
        Their sample time (s).
    input, output : str
        The channel's names in the model.

    Returns
    -------
    PolynomialModel

    Examples
    --------
    >>> import scipy.signal
    >>> u = 0.1 * np.random.default_rng(0).standard_normal(400)
    >>> y = scipy.signal.lfilter([0.0, 0.05], [1.0, -0.9], u) + 1e-3 * np.random.default_rng(1).standard_normal(400)
    >>> armax_1dof(y, u, 0.2).A.size
    5
    """
    na, nb, nc, nk = ARMAX_ORDERS
    return armax(y, u, na, nb, nc, nk, sample_time=sample_time, input=input, output=output)


def identify_protocol_record(record: Record, decimate: int = 2) -> PolynomialModel:
    """4th-order ARMAX (eq. 3.2, nk = 1) of a 1-DOF protocol record at ``decimate`` times its sample time.

    Parameters
    ----------
    record : Record
        A 1-DOF run (volts in, radians out).
    decimate : int
        Keep every ``decimate``-th sample (the 5 Hz PRBS of a 10 Hz record: 2).

    Returns
    -------
    PolynomialModel
        Deviations in (V) to deviations out (rad), at ``decimate`` times the record's sample time (s).

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> (rec,) = protocol_records([load_spec()], Protocol("1dof", "u1", 5.0, 30.0, 0.05))
    >>> identify_protocol_record(rec).sample_time
    0.2
    """
    du, dy = record.deviations()
    return armax_1dof(dy[::decimate, 0], du[::decimate, 0], record.sample_time * decimate)
