"""Chapters 6 and 7 run on a plant: the integral-LQG cases, the push, and the loops' stability margins.

Set-up (thesis ch. 6.7-6.9 and 7.3-7.4, with the choices the thesis leaves open stated)
-----------------------------------------------------------------------------------------
* Design model: eq. (3.11) in the observer canonical form of eq. (6.33), ``Ts = 0.2 s``
  (:func:`pitch_plant` wraps it as a :class:`~trms.plant.LinearPlant` with absolute limits
  ``+-10 V`` about a trim input).
* Controller: integral LQG, ``Q = I``, ``R`` from :data:`trms.reference.LQG_WEIGHTS_R`;
  estimator ``Qe = I``, ``Re = 1`` (:data:`ESTIMATOR_QE`, :data:`ESTIMATOR_RE`: the thesis prints
  only "estimator faster than the regulator"); compensator on the tracking error (fig. 6.5),
  conditional-integration anti-windup.
* Command: square wave of :data:`DEFAULT_AMPLITUDE` rad, period :data:`DEFAULT_PERIOD` s, for
  :data:`DEFAULT_DURATION` s, starting high at t = 0 (the thesis prints neither amplitude nor
  period). Prefilters (:func:`prefilters`): Butterworth order 2 low-pass and band-stop filters of
  Table 6.1 and ch. 7.
* Measures per step (:mod:`trms.control.metrics`): 10-90 % rise time, settling time; each run is
  summarised (:func:`summarise`) over its full-swing steps (:func:`full_swing`), with the
  alternative definitions a table note may need computed from the same record (the rise timed from
  the command edge, the first step from rest, the wide band) and the run's measured steady-state
  wander (:func:`wander`), which decides the settling band (:func:`settling_band`).

:func:`lqg_cases` runs every ``(R, case)`` on a plant and judges each run (:func:`judge`);
:func:`push_rejection` holds hover and pushes the beam (ch. 7.4); :func:`loop_margins` breaks each
LQG loop at the plant input and reads its gain, phase and delay margins. The tables are built from
these results in :mod:`trms.experiments.ch67_tables`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import control
import numpy as np

from trms.control.loop import closed_loop, deviation_limits
from trms.control.lqg import LQGController, design_lqg
from trms.control.margins import classical_margins
from trms.control.metrics import NARROW_BAND, WIDE_BAND, StepMetrics, square_wave_metrics
from trms.control.realization import observer_canonical
from trms.control.shaping import CommandFilter, bands_around, butterworth_lowpass, multiband_bandstop
from trms.errors import ConfigurationError, DivergenceError, InputError, check_in_range
from trms.plant import LinearPlant, Plant
from trms.record import OperatingPoint, Record
from trms.reference import (
    CHAPTER_7_PREFILTERS,
    LQG_WEIGHTS_R,
    PUSH_WEIGHTS_R,
    SAMPLE_TIME_1DOF,
    TABLE_6_1_PREFILTERS,
    VOLTAGE_LIMIT,
    eq_3_11,
)
from trms.signals import square_wave

__all__ = [
    "CASES",
    "ALL_CASES",
    "PUSH",
    "STOP_ANGLE",
    "NARROW_BAND",
    "WIDE_BAND",
    "case_setup",
    "WANDER_WINDOW",
    "RECOVERY_BAND",
    "DEFAULT_AMPLITUDE",
    "DEFAULT_PERIOD",
    "DEFAULT_DURATION",
    "ESTIMATOR_QE",
    "ESTIMATOR_SPEEDS",
    "PCI_LIMIT",
    "ESTIMATOR_RE",
    "STATUSES",
    "CaseResult",
    "PushResult",
    "Margins",
    "pitch_plant",
    "prefilters",
    "design",
    "run_case",
    "worst",
    "full_swing",
    "wander",
    "settling_band",
    "summarise",
    "judge",
    "without_records",
    "lqg_cases",
    "push_rejection",
    "loop_margins",
]

#: The four control structures of Table 6.1, in its column order.
CASES = ("SAS", "CSAS LPF 0.2 Hz", "CSAS LPF 0.3 Hz", "CSAS BSF 0.25 & 0.34 Hz")
#: Every (R, case) run on the rig (ch. 7): Table 6.1's cases plus the LPF 0.1 Hz and the BSF 0.34 Hz.
ALL_CASES = CASES + tuple(CHAPTER_7_PREFILTERS)
#: The push of ch. 7.4: time (s), angular impulse about pitch (N m s), duration (s); this project's
#: choice of size (the thesis pushed by hand "around 18-20 s").
PUSH = (19.0, 0.02, 0.2)
#: Pitch (rad) beyond which a run counts as having hit the mechanical stops (the twin's are at 1.1 rad).
STOP_ANGLE = 1.0
#: The absolute actuator limit of Feedback's 33-949 PCI set-up (V), beside the thesis's +-10 V: Table 6.1's
#: control column is read at both.
PCI_LIMIT = 2.5
#: Scales of the estimator's ``Qe`` (:func:`design`) under which Table 6.1's control is re-measured: a slower and
#: a faster estimator than the thesis's.
ESTIMATOR_SPEEDS = (0.1, 10.0)
#: Window (s) at the end of each half period over which the steady-state wander is measured.
WANDER_WINDOW = 5.0
#: Band (rad) the pitch must stay within after a push to count as recovered.
RECOVERY_BAND = 0.02
#: Square-wave amplitude (rad): this project's choice (the thesis does not print it).
DEFAULT_AMPLITUDE = 0.2
#: Square-wave period (s): long enough for the slowest case of Table 6.1 to settle per half.
DEFAULT_PERIOD = 40.0
#: Run length (s): two periods.
DEFAULT_DURATION = 80.0
#: Estimator process-noise covariance (times I) and measurement-noise covariance: this project's choice.
ESTIMATOR_QE = 1.0
ESTIMATOR_RE = 1.0
#: The named statuses of a run, in order of severity.
STATUSES = ("settled", "not settled", "hit the stops", "diverged")


def pitch_plant(trim: float = 0.0, limit: float = VOLTAGE_LIMIT, noise_std: float = 0.0) -> LinearPlant:
    """Eq. (3.11) in observer canonical form as a plant with absolute limits ``+-limit`` about ``trim``.

    Parameters
    ----------
    trim : float
        Trim input (V, absolute) at the hover operating point; pitch trim 0 rad.
    limit : float
        Absolute actuator limit (V), > ``|trim|``.
    noise_std : float
        Measurement noise (rad), >= 0.

    Examples
    --------
    >>> pitch_plant().sample_time
    0.2
    """
    lim = check_in_range("limit", limit, 0.0, np.inf, unit=" V", low_open=True)
    u0 = check_in_range("trim", trim, -lim, lim, unit=" V")
    if abs(u0) >= lim:
        raise InputError(f"trim = {trim!r} V must lie strictly inside the limits +-{lim} V")
    model = observer_canonical(eq_3_11())
    op = OperatingPoint(np.array([u0]), np.array([0.0]), ("u1",), ("pitch",))
    return LinearPlant(
        model,
        operating_point=op,
        input_names=op.input_names,
        output_names=op.output_names,
        input_limits=(-lim, lim),
        noise_std=noise_std,
    )


def prefilters(sample_time: float = SAMPLE_TIME_1DOF) -> dict[str, CommandFilter | None]:
    """Every case's prefilter (``None`` for SAS), chapters 6 and 7, designed at ``sample_time``."""
    out: dict[str, CommandFilter | None] = {"SAS": None}
    for name, (kind, order, freqs, bandwidth) in {**TABLE_6_1_PREFILTERS, **CHAPTER_7_PREFILTERS}.items():
        if kind == "lowpass":
            out[name] = butterworth_lowpass(order, freqs[0], sample_time)
        elif bandwidth is None:
            raise ConfigurationError(f"prefilter {name!r}: a band-stop needs a bandwidth (Hz), got None")
        else:
            out[name] = multiband_bandstop(order, bands_around(freqs, bandwidth), sample_time)
    return out


def design(model: control.StateSpace, r_weight: float, estimator: float = 1.0):
    """The integral LQG of chapters 6/7 for ``R = r_weight`` (``Q = I``, :data:`ESTIMATOR_QE`, :data:`ESTIMATOR_RE`).

    ``estimator`` scales the process noise covariance ``Qe``: above 1 a faster estimator (it trusts the
    measurement more), below 1 a slower one.
    """
    return design_lqg(model, Q=1.0, R=r_weight, Qe=ESTIMATOR_QE * estimator, Re=ESTIMATOR_RE)


def run_case(
    plant: Plant,
    r_weight: float,
    case: str,
    amplitude: float = DEFAULT_AMPLITUDE,
    period: float = DEFAULT_PERIOD,
    duration: float = DEFAULT_DURATION,
    seed: int | None = 0,
    model: control.StateSpace | None = None,
    estimator: float = 1.0,
) -> tuple[Record, list[StepMetrics]]:
    """Design the LQG for ``R = r_weight`` and run one case of Table 6.1 (or ch. 7) on ``plant``.

    Parameters
    ----------
    plant : Plant
        Any 1-DOF plant (e.g. :func:`pitch_plant` or the twin).
    r_weight : float
        Control weight ``R`` (``Q = I``).
    case : str
        One of :data:`ALL_CASES`.
    amplitude, period, duration : float
        Square-wave command (rad, s, s).
    seed : int, optional
        Plant reset seed (noise, gusts).
    model : control.StateSpace, optional
        Design model; default the plant's own ``system`` (a :class:`~trms.plant.LinearPlant`).
    estimator : float
        Scale of the estimator's ``Qe`` (:func:`design`).

    Returns
    -------
    Record, list of StepMetrics
        The run and its steps measured at the :data:`NARROW_BAND`.

    Raises
    ------
    DivergenceError
        The plant's simulation blew up (an unstable loop on the twin).

    Examples
    --------
    >>> rec, steps = run_case(pitch_plant(), 75.0, "SAS", duration=40.0)
    >>> len(steps)
    2
    """
    controller, ref, prefilter, meta = case_setup(plant, r_weight, case, amplitude, period, duration, model, estimator)
    record = closed_loop(plant, controller, ref, prefilter=prefilter, seed=seed, metadata=meta)
    return record, square_wave_metrics(record, band=NARROW_BAND)


def case_setup(
    plant: Plant,
    r_weight: float,
    case: str,
    amplitude: float = DEFAULT_AMPLITUDE,
    period: float = DEFAULT_PERIOD,
    duration: float = DEFAULT_DURATION,
    model: control.StateSpace | None = None,
    estimator: float = 1.0,
) -> tuple[LQGController, np.ndarray, CommandFilter | None, dict[str, object]]:
    """The loop of one case (see :func:`run_case`): controller, square-wave reference, prefilter, metadata.

    Examples
    --------
    >>> c, ref, pf, meta = case_setup(pitch_plant(), 75.0, "SAS", duration=4.0)
    >>> ref.shape, pf, meta["case"]
    ((20,), None, 'SAS')
    """
    if case not in ALL_CASES:
        raise InputError(f"unknown case {case!r}; allowed: {', '.join(repr(c) for c in ALL_CASES)}")
    if model is None:
        if not isinstance(plant, LinearPlant):
            raise InputError("a design model is needed for a plant that is not a LinearPlant")
        model = plant.system
    controller = LQGController(design(model, r_weight, estimator), deviation_limits(plant))
    ref = square_wave(duration, plant.sample_time, period, amplitude)
    meta: dict[str, object] = {
        "R": float(r_weight),
        "case": case,
        "amplitude_rad": float(amplitude),
        "estimator_scale": float(estimator),
    }
    return controller, ref, prefilters(plant.sample_time)[case], meta


def worst(values: Sequence[float]) -> float:
    """The largest of per-step values, ``nan`` if any is ``nan`` (a step that never settled)."""
    arr = np.asarray(values, float)
    return float("nan") if np.any(np.isnan(arr)) else float(arr.max())


def full_swing(steps: Sequence[StepMetrics]) -> list[StepMetrics]:
    """The steps of a square wave that span its whole swing (``-A`` to ``+A``).

    The first step, from rest to ``+A``, is half as large and its band half as wide; the tables
    report it separately (:func:`summarise`, ``"TR first"``/``"TS first"``).
    """
    swing = max(abs(m.target - m.initial) for m in steps)
    return [m for m in steps if abs(m.target - m.initial) >= 0.99 * swing]


def wander(record: Record, steps: Sequence[StepMetrics], window: float = WANDER_WINDOW) -> float:
    """Steady-state wander (rad): the largest ``|y - target|`` over the last ``window`` s of each full-swing step.

    This is how far gusts, noise and quantisation keep the output from the command once the
    transient is over; a settling band narrower than it cannot be held.
    """
    _, dy = record.deviations()
    y, t = dy[:, 0], record.time
    ends = [m.start_time for m in steps[1:]] + [float(t[-1]) + record.sample_time]
    out = 0.0
    for m, end in zip(steps, ends):
        if m not in full_swing(steps):
            continue
        keep = (t >= end - window) & (t < end)
        if keep.any():
            out = max(out, float(np.max(np.abs(y[keep] - m.target))))
    return out


def settling_band(wander_rad: float, step_rad: float) -> float:
    """:data:`NARROW_BAND` when the measured wander fits inside it, else :data:`WIDE_BAND` (fractions of the step)."""
    return NARROW_BAND if wander_rad < NARROW_BAND * step_rad else WIDE_BAND


def _edge_rise(record: Record, steps: Sequence[StepMetrics]) -> list[float]:
    """Per step: time from the command edge to the first 90 % crossing (s), ``nan`` if never."""
    _, dy = record.deviations()
    y, t = dy[:, 0], record.time
    out = []
    ends = [m.start_time for m in steps[1:]] + [np.inf]
    for m, end in zip(steps, ends):
        level = m.initial + 0.9 * (m.target - m.initial)
        sign = np.sign(m.target - m.initial)
        idx = np.flatnonzero((t >= m.start_time) & (t < end) & (sign * (y - level) >= 0))
        out.append(float(t[idx[0]] - m.start_time) if idx.size else float("nan"))
    return out


def summarise(record: Record, limits: tuple[np.ndarray, np.ndarray]) -> dict[str, float | str]:
    """One run's measures: the table's cells and the alternative definitions its notes compare.

    Returns
    -------
    dict
        ``TR``, ``TS`` (s; largest over the full-swing steps, ``TS`` at the band :func:`settling_band`
        picks from the measured ``wander``), ``band`` (fraction), ``TS narrow``/``TS wide`` (s, at
        :data:`NARROW_BAND`/:data:`WIDE_BAND`), ``TR edge`` (s, command edge to 90 %), ``TR first``/
        ``TS first`` (s, the first step from rest, narrow band), ``wander`` (rad), ``step`` (rad),
        ``overshoot`` (%), ``peak`` (V), ``control`` ("ok"/"high"), ``saturated`` (s), ``TV`` (V),
        ``excursion`` (rad, the largest |pitch| deviation, the true angle where the record has it).
    """
    narrow = square_wave_metrics(record, band=NARROW_BAND)
    wide = square_wave_metrics(record, band=WIDE_BAND)
    full_n, full_w = full_swing(narrow), full_swing(wide)
    step = abs(full_n[0].target - full_n[0].initial)
    wand = wander(record, narrow)
    band = settling_band(wand, step)
    u = record.extras["control"]
    high = bool(np.any(u < limits[0]) or np.any(u > limits[1]))
    edge = _edge_rise(record, narrow)
    full_idx = [i for i, m in enumerate(narrow) if m in full_n]
    ts_n, ts_w = worst([m.settling_time for m in full_n]), worst([m.settling_time for m in full_w])
    return {
        "TR": worst([m.rise_time for m in full_n]),
        "TS": ts_n if band == NARROW_BAND else ts_w,
        "band": band,
        "TS narrow": ts_n,
        "TS wide": ts_w,
        "TR edge": worst([edge[i] for i in full_idx]),
        "TR first": float(narrow[0].rise_time),
        "TS first": float(narrow[0].settling_time),
        "wander": wand,
        "step": step,
        "overshoot": max(m.overshoot for m in narrow),
        "peak": float(np.abs(u).max()),
        "limit": float(min(-np.max(limits[0]), np.min(limits[1]))),
        "control": "high" if high else "ok",
        "saturated": float(sum(m.saturated_time for m in narrow)),
        "TV": float(sum(m.total_variation for m in narrow)),
        "excursion": _excursion(record),
    }


def _excursion(record: Record) -> float:
    """The largest |pitch| of a run (rad), read as :func:`judge` reads the stops."""
    angles = record.extras.get("true_angles")
    pitch = angles[:, 0] if angles is not None else record.deviations()[1][:, 0]
    return float(np.max(np.abs(pitch)))


@dataclass
class CaseResult:
    """One closed-loop run of chapter 6/7 on one plant.

    Attributes
    ----------
    status : str
        One of :data:`STATUSES`: ``"settled"``, ``"not settled"`` (the last step never entered its
        band), ``"hit the stops"`` (pitch beyond :data:`STOP_ANGLE`) or ``"diverged"`` (the simulation
        blew up).
    summary : dict
        :func:`summarise`; empty when diverged.
    record : Record or None
        The run (None when diverged).
    """

    status: str
    summary: dict[str, float | str]
    record: Record | None


def without_records(cases: Mapping[tuple[float, str], CaseResult]) -> dict[tuple[float, str], CaseResult]:
    """The runs' statuses and summaries without their records (what a run's other seeds hand back: small).

    Examples
    --------
    >>> without_records({(75.0, "SAS"): CaseResult("settled", {"TR": 3.0}, None)})[(75.0, "SAS")].summary
    {'TR': 3.0}
    """
    return {k: CaseResult(c.status, c.summary, None) for k, c in cases.items()}


def judge(record: Record, steps: list[StepMetrics]) -> str:
    """Status of a closed-loop run: settled, not settled, or hit the stops (see :class:`CaseResult`).

    ``steps`` are the run's step measures at the band that decides "settled"."""
    angles = record.extras.get("true_angles")
    pitch = np.abs(angles[:, 0]) if angles is not None else np.abs(record.deviations()[1][:, 0])
    if np.max(pitch) >= STOP_ANGLE:
        return "hit the stops"
    if not steps or not np.isfinite(steps[-1].settling_time):
        return "not settled"
    return "settled"


def lqg_cases(
    plant: Plant,
    model: control.StateSpace,
    weights: Sequence[float] = LQG_WEIGHTS_R,
    cases: Sequence[str] = ALL_CASES,
    amplitude: float = DEFAULT_AMPLITUDE,
    seed: int = 0,
    estimator: float = 1.0,
) -> dict[tuple[float, str], CaseResult]:
    """Every ``(R, case)`` closed around ``plant`` with controllers designed on ``model``.

    Parameters
    ----------
    plant : Plant
        The linear model or the twin (1-DOF, 0.2 s).
    model : control.StateSpace
        Design model (the thesis's: eq. 3.11, :func:`trms.worlds.design_model`).
    weights, cases : sequences
        ``R`` values and case names.
    amplitude : float
        Square-wave amplitude (rad).
    seed : int
        Plant seed (noise, turbulence, gusts) of every run.
    estimator : float
        Scale of the estimator's ``Qe`` (:func:`design`).

    Returns
    -------
    dict
        :class:`CaseResult` by ``(R, case)``.

    Examples
    --------
    >>> res = lqg_cases(pitch_plant(), pitch_plant().system, [75.0], ["SAS"])
    >>> res[(75.0, "SAS")].status
    'settled'
    """
    limits = deviation_limits(plant)
    out = {}
    for r in weights:
        for case in cases:
            try:
                record, _ = run_case(plant, r, case, amplitude, seed=seed, model=model, estimator=estimator)
            except DivergenceError:
                out[(float(r), case)] = CaseResult("diverged", {}, None)
                continue
            summary = summarise(record, limits)
            steps = square_wave_metrics(record, band=float(summary["band"]))
            out[(float(r), case)] = CaseResult(judge(record, steps), summary, record)
    return out


@dataclass
class PushResult:
    """Push rejection on one plant: peak pitch deviation after the push (rad), recovery time (s, nan if never)."""

    status: str
    peak: float
    recovery: float
    record: Record | None


def push_rejection(
    make: Callable[[list], Plant],
    model: control.StateSpace,
    weights: Sequence[float] = PUSH_WEIGHTS_R,
    duration: float = 40.0,
    seed: int = 0,
) -> dict[float, PushResult]:
    """Hold hover under SAS and push the beam (ch. 7.4): :data:`PUSH` about pitch.

    Parameters
    ----------
    make : callable
        ``make(pushes) -> Plant``: builds the plant with the given pushes (the twin; the linear
        model has no torque input).
    model : control.StateSpace
        Design model.
    weights : sequence of float
        ``R`` values (the thesis: 75, 100, 125).
    duration : float
        Run length (s).
    seed : int
        Plant seed.
    """
    from trms.twin import Push

    t_push, impulse, width = PUSH
    plant = make([Push.impulse(t_push, impulse, width, "pitch")])
    n = int(round(duration / plant.sample_time))
    out = {}
    for r in weights:
        controller = LQGController(design(model, r), deviation_limits(plant))
        try:
            rec = closed_loop(plant, controller, np.zeros(n), seed=seed, metadata={"R": float(r), "push": list(PUSH)})
        except DivergenceError:
            out[float(r)] = PushResult("diverged", float("nan"), float("nan"), None)
            continue
        y = rec.deviations()[1][:, 0]
        after = rec.time >= t_push
        outside = np.flatnonzero(after & (np.abs(y) > RECOVERY_BAND))
        if outside.size == 0:
            recovery = 0.0
        elif outside[-1] == len(y) - 1:
            recovery = float("nan")
        else:
            recovery = float(rec.time[outside[-1] + 1] - t_push)
        status = "recovered" if np.isfinite(recovery) else "not recovered"
        out[float(r)] = PushResult(status, float(np.max(np.abs(y[after]))), recovery, rec)
    return out


# ------------------------------------------------------------------------------ stability margins
@dataclass(frozen=True)
class Margins:
    """Stability margins of one LQG loop broken at the plant input.

    Attributes
    ----------
    gain_margin_db : float
        Gain margin (dB); ``inf`` when the loop's phase never crosses -180 deg.
    phase_margin_deg : float
        Phase margin (deg); ``inf`` when the loop gain never crosses 1.
    delay_margin_s : float
        Extra pure delay (s) the loop tolerates: the smallest phase margin / crossover frequency over
        every gain crossover (negative when the loop is unstable).
    stable : bool
        The closed loop is stable.
    stable_with_delay : bool
        It stays stable with one more sample of computation delay (``z^-1`` in the loop).
    """

    gain_margin_db: float
    phase_margin_deg: float
    delay_margin_s: float
    stable: bool
    stable_with_delay: bool


def _stable(loop: control.StateSpace) -> bool:
    closed = control.feedback(loop, 1, sign=-1)
    poles = control.poles(closed)
    return bool(np.all(np.abs(poles) < 1.0))


def loop_margins(plant_model: control.LTI, design_model: control.StateSpace, r_weight: float) -> Margins:
    """Break the chapters 6/7 LQG loop at the plant input and read its margins (python-control).

    The compensator (:meth:`trms.control.lqg.LQGController.compensator`) maps the measurement to the
    control; the loop transfer at the plant input is ``L = -C_y(z) G(z)`` for unity negative feedback.

    Parameters
    ----------
    plant_model : control.LTI
        Discrete SISO model of the plant the loop is closed around (e.g. eq. 3.11, or the twin's
        linearisation), same sample time as the design.
    design_model : control.StateSpace
        The model the LQG is designed on.
    r_weight : float
        Control weight ``R``.

    Returns
    -------
    Margins

    Examples
    --------
    >>> m = loop_margins(pitch_plant().system, pitch_plant().system, 75.0)
    >>> m.stable
    True
    """
    controller = LQGController(design(design_model, r_weight))
    comp = controller.compensator()
    c_y = control.ss(comp.A, comp.B[:, 1:2], comp.C, comp.D[:, 1:2], comp.dt)
    plant = control.ss(plant_model)
    loop = control.series(plant, -c_y)
    # Margins from the loop's exact response (not from its transfer-function polynomials: the twin's linearised
    # loop is of high order, and the crossings found from its polynomials were wrong, a phase margin of -88 deg for
    # a loop with a 66 deg one, and changed with the library that converted the state space into them).
    m = classical_margins(loop)
    delay = control.ss([[0.0]], [[1.0]], [[1.0]], [[0.0]], loop.dt)
    return Margins(
        m.gain_margin_db, m.phase_margin_deg, m.delay_margin_s, _stable(loop), _stable(control.series(delay, loop))
    )
