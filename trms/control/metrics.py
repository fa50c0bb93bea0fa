"""Performance measures of closed-loop and shaped responses (thesis Table 6.1 and Tables 4.2-4.3).

Per step of a (square-wave) reference, on deviations from the operating point:

* rise time: from the first crossing of 10 % of the step to the first crossing of 90 %
  (s), crossings interpolated linearly between samples;
* settling time: from the step to the last entry into the band ``target +- 2 %`` of the
  step size (s), interpolated; ``nan`` if the output is outside the band at the end of the
  step's interval;
* overshoot: largest excursion beyond the target, in % of the step size;
* peak and RMS of the commanded control (deviation V), time spent saturated (s),
  the control's total variation ``sum |u(k+1) - u(k)|`` (V; smaller is smoother), and its largest
  move ``max |u(k) - u(k-1)|`` from the sample before the step on (V: the "voltage jump" a step causes).

Settling against the noise (:func:`noise_band`): a plant that is never still (the twin in moving air, the rig)
wobbles under control at rest; a band narrower than that wobble cannot be held, however good the loop. The band
is then ``max(2 % of the step, 3 standard deviations of the same loop's measured output at rest)``
(:data:`NOISE_SIGMAS`), and :func:`square_wave_metrics` takes that standard deviation (``rest_std``), one value or
one per step target (the wobble at rest differs between hover and a tilted beam).

Steps are the samples where the *raw* reference changes (the sample at ``t = 0`` counts
when the reference starts away from rest, 0), so a prefiltered (CSAS) run is measured
against the command the pilot gave, as in the thesis.

Spectral attenuation at modes (ch. 4): the output PSDs of the unshaped and the shaped
runs are compared by :func:`trms.identification.spectral.attenuation_db`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, replace

import numpy as np

from trms.errors import InputError, as_finite_array, check_in_range
from trms.identification.spectral import attenuation_db, psd
from trms.record import Record

#: The thesis's settling band (fraction of the step).
NARROW_BAND = 0.02
#: The wider band every table gives beside it (fraction of the step).
WIDE_BAND = 0.05
#: Standard deviations of the loop's output at rest that the settling band must contain.
NOISE_SIGMAS = 3.0


def noise_band(step: float, rest_std: float, narrow: float = NARROW_BAND, sigmas: float = NOISE_SIGMAS) -> float:
    """The settling band (fraction of the step) a noisy loop can hold: ``max(narrow, sigmas rest_std / |step|)``.

    Parameters
    ----------
    step : float
        Step size (rad), non-zero.
    rest_std : float
        Standard deviation (rad) of the same loop's measured output at rest, ``>= 0``.
    narrow : float
        The band without noise (fraction), in ``(0, 1)``.
    sigmas : float
        Standard deviations the band must contain, ``>= 0``.

    Examples
    --------
    A 0.4 rad step: 2 % is 8 mrad; a loop wobbling 4 mrad (std) at rest needs 12 mrad, 3 %:

    >>> noise_band(0.4, 0.0), round(noise_band(0.4, 0.004), 6)
    (0.02, 0.03)
    """
    step = check_in_range("step", abs(float(step)), 0.0, np.inf, unit=" rad", low_open=True)
    rest = check_in_range("rest_std", rest_std, 0.0, np.inf, unit=" rad")
    narrow = check_in_range("narrow", narrow, 0.0, 1.0, low_open=True)
    sigmas = check_in_range("sigmas", sigmas, 0.0, 100.0)
    return float(max(narrow, sigmas * rest / step))


__all__ = [
    "NARROW_BAND",
    "WIDE_BAND",
    "NOISE_SIGMAS",
    "noise_band",
    "StepMetrics",
    "step_edges",
    "step_metrics",
    "square_wave_metrics",
    "total_variation",
    "mode_attenuation",
]


@dataclass(frozen=True)
class StepMetrics:
    """Measures of the response to one reference step (see the module docstring for definitions).

    Attributes
    ----------
    start_time : float
        Time of the step (s).
    initial, target : float
        Reference before and after the step (deviation rad).
    rise_time, settling_time : float
        10-90 % rise time and 2 % settling time (s); ``nan`` when not reached.
    overshoot : float
        Largest excursion beyond the target (% of the step).
    peak_control, rms_control : float
        Largest and RMS commanded control (deviation V).
    saturated_time : float
        Time with at least one input saturated (s).
    total_variation : float
        ``sum |u(k+1) - u(k)|`` of the control (V).
    largest_move : float
        ``max |u(k) - u(k-1)|`` of the control from the sample before the step (V; NaN when that sample is not
        given).

    Examples
    --------
    >>> t = np.arange(0.0, 10.0, 0.001)
    >>> m = step_metrics(t, 1.0 - np.exp(-t), np.full(t.size, 0.5), 0.0, 1.0)
    >>> m.target, m.overshoot, m.peak_control, m.as_dict()["rms_control"]
    (1.0, 0.0, 0.5, 0.5)
    """

    start_time: float
    initial: float
    target: float
    rise_time: float
    settling_time: float
    overshoot: float
    peak_control: float
    rms_control: float
    saturated_time: float
    total_variation: float
    largest_move: float = float("nan")

    def as_dict(self) -> dict[str, float]:
        """Plain dict (for tables and JSON).

        Examples
        --------
        >>> t = np.arange(0.0, 2.0, 0.1)
        >>> list(step_metrics(t, np.ones(t.size), np.zeros(t.size), 0.0, 1.0).as_dict())[:4]
        ['start_time', 'initial', 'target', 'rise_time']
        """
        return asdict(self)


def total_variation(u: object) -> float:
    """Total variation ``sum_k |u(k+1) - u(k)|`` of a signal (its unit), summed over columns.

    Parameters
    ----------
    u : array_like
        Samples along axis 0, shape ``(N,)`` or ``(N, m)`` (e.g. deviation V).

    Returns
    -------
    float
        0 for fewer than two samples.

    Examples
    --------
    >>> total_variation([0.0, 1.0, 0.5]), total_variation([[0.0, 0.0], [1.0, -2.0]])
    (1.5, 3.0)
    """
    arr = as_finite_array("u", u)
    if arr.ndim == 0 or arr.shape[0] < 2:
        return 0.0
    return float(np.abs(np.diff(arr, axis=0)).sum())


def step_edges(reference: object, rest: float = 0.0) -> np.ndarray:
    """Indices where a sampled reference steps (``r[k] != r[k-1]``; ``0`` if ``r[0] != rest``).

    Parameters
    ----------
    reference : array_like
        Shape ``(N,)``.
    rest : float
        Value before the first sample.

    Returns
    -------
    numpy.ndarray
        Sample indices (int), increasing.

    Examples
    --------
    >>> step_edges([0.0, 0.0, 1.0, 1.0, -1.0]).tolist(), step_edges([1.0, 1.0]).tolist()
    ([2, 4], [0])
    """
    r = as_finite_array("reference", reference, (None,))
    prev = np.concatenate([[check_in_range("rest", rest, -np.inf, np.inf)], r[:-1]])
    return np.flatnonzero(r != prev)


def _first_crossing(t: np.ndarray, s: np.ndarray, level: float) -> float:
    """Time at which ``s`` (a signed progress) first reaches ``level``, interpolated; nan if never."""
    hit = np.flatnonzero(s >= level)
    if hit.size == 0:
        return float("nan")
    k = int(hit[0])
    if k == 0:
        return float(t[0])
    frac = (level - s[k - 1]) / (s[k] - s[k - 1])
    return float(t[k - 1] + frac * (t[k] - t[k - 1]))


def step_metrics(
    time: object,
    output: object,
    control: object,
    initial: float,
    target: float,
    saturated: object | None = None,
    band: float = 0.02,
    previous_control: object | None = None,
) -> StepMetrics:
    """Measures of one step response over one interval (from the step to the next one).

    Parameters
    ----------
    time : array_like
        Sample times (s), shape ``(M,)``; ``time[0]`` is the step instant.
    output : array_like
        Output deviation (rad), shape ``(M,)``.
    control : array_like
        Commanded control deviation (V), shape ``(M,)`` or ``(M, m)``.
    initial, target : float
        Reference before and after the step (rad); they must differ.
    saturated : array_like of bool, optional
        Per-sample (or per-sample-and-input) saturation flags.
    band : float
        Settling band as a fraction of the step size, in (0, 1).
    previous_control : array_like, optional
        The commanded control at the sample before the step (V), so that the step's own jump counts in
        ``largest_move``.

    Returns
    -------
    StepMetrics

    Raises
    ------
    InputError
        Arrays of mismatched length or not finite, a time that does not increase, ``initial == target``, a bad
        band or saturation flags that are not booleans.

    Examples
    --------
    A first-order response ``1 - exp(-t)`` rises from 10 % to 90 % in ``ln 9`` and settles to 2 % in
    ``ln 50`` seconds, without overshoot:

    >>> import math
    >>> t = np.arange(0.0, 10.0, 0.001)
    >>> m = step_metrics(t, 1.0 - np.exp(-t), np.zeros(t.size), 0.0, 1.0)
    >>> round(m.rise_time, 4), round(math.log(9), 4), round(m.settling_time, 4), round(math.log(50), 4), m.overshoot
    (2.1972, 2.1972, 3.912, 3.912, 0.0)

    A second-order step of damping 0.5 overshoots by ``100 exp(-pi 0.5 / sqrt(0.75))`` = 16.3 %:

    >>> import control
    >>> _, y = control.step_response(control.tf([1.0], [1.0, 1.0, 1.0]), T=np.arange(0.0, 20.0, 0.001))
    >>> round(step_metrics(np.arange(0.0, 20.0, 0.001), y, np.zeros(y.size), 0.0, 1.0).overshoot, 2)
    16.3
    """
    t = as_finite_array("time", time, (None,))
    y = as_finite_array("output", output, (t.size,))
    u = as_finite_array("control", control)
    if u.shape[:1] != (t.size,):
        raise InputError(f"control must have {t.size} rows, got shape {u.shape}")
    if t.size < 2:
        raise InputError(f"a step interval needs at least 2 samples, got {t.size}")
    if np.any(np.diff(t) <= 0):
        k = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise InputError(
            f"time must increase strictly; time[{k + 1}] = {float(t[k + 1])!r} s follows time[{k}] = {float(t[k])!r} s"
        )
    b = check_in_range("band", band, 0.0, 1.0, low_open=True)
    initial = check_in_range("initial", initial, -np.inf, np.inf, unit=" rad")
    target = check_in_range("target", target, -np.inf, np.inf, unit=" rad")
    size = target - initial
    if size == 0.0:
        raise InputError(f"initial and target must differ to define a step, both are {target!r}")
    progress = (y - float(initial)) / size
    rise = _first_crossing(t, progress, 0.9) - _first_crossing(t, progress, 0.1)
    err = np.abs(y - float(target)) / abs(size)
    outside = np.flatnonzero(err > b)
    if outside.size == 0:
        settle = 0.0
    elif outside[-1] == t.size - 1:
        settle = float("nan")
    else:
        k = int(outside[-1])
        frac = (err[k] - b) / (err[k] - err[k + 1])
        settle = float(t[k] + frac * (t[k + 1] - t[k]) - t[0])
    overshoot = max(0.0, float(np.max((y - float(target)) * np.sign(size))) / abs(size) * 100.0)
    mag = np.abs(u.reshape(t.size, -1))
    dt = float(t[1] - t[0])
    sat = 0.0
    if saturated is not None:
        flags = np.asarray(saturated)
        binary = flags.dtype.kind == "b" or (flags.dtype.kind in "iuf" and bool(np.isin(flags, (0, 1)).all()))
        if not binary or flags.shape[:1] != (t.size,) or flags.ndim > 2:
            raise InputError(
                f"saturated must be flags (booleans or 0/1) of shape ({t.size},) or ({t.size}, m), "
                f"got dtype {flags.dtype} and shape {flags.shape}"
            )
        sat = float(np.count_nonzero(flags.reshape(t.size, -1).astype(bool).any(axis=1)) * dt)
    return StepMetrics(
        start_time=float(t[0]),
        initial=float(initial),
        target=float(target),
        rise_time=float(rise),
        settling_time=settle,
        overshoot=overshoot,
        peak_control=float(mag.max()),
        rms_control=float(np.sqrt(np.mean(mag**2))),
        saturated_time=sat,
        total_variation=total_variation(u),
        largest_move=_largest_move(u, previous_control),
    )


def _largest_move(u: np.ndarray, previous: object | None) -> float:
    """``max |u(k) - u(k-1)|`` over the interval, from ``previous`` (the sample before it) when given; NaN without."""
    if previous is None:
        return float("nan")
    before = as_finite_array("previous_control", previous).reshape(1, -1)
    rows = u.reshape(u.shape[0], -1)
    if before.shape[1] != rows.shape[1]:
        raise InputError(f"previous_control must have {rows.shape[1]} values, got {before.shape[1]}")
    return float(np.abs(np.diff(np.vstack([before, rows]), axis=0)).max())


def square_wave_metrics(
    record: Record, output: int | str = 0, band: float = NARROW_BAND, rest_std: float | Mapping[float, float] = 0.0
) -> list[StepMetrics]:
    """Measures of every step of a closed-loop run's raw reference.

    Parameters
    ----------
    record : Record
        From :func:`trms.control.loop.closed_loop` (needs the ``reference`` and ``control``
        extras; ``saturated`` is used when present).
    output : int or str
        Tracked output (index into the reference columns, or output name of the first).
    band : float
        Settling band (fraction of the step) without noise.
    rest_std : float or mapping
        Standard deviation of the loop's measured output at rest (rad), or a mapping from each step's target
        (deviation rad) to the standard deviation at rest there: each step's band is :func:`noise_band`
        ``(step, rest_std, band)``. 0 (the default) keeps ``band``.

    Returns
    -------
    list of StepMetrics
        One per step, in time order; each interval runs to the next step or the record's end; ``largest_move``
        counts the jump from the sample before the step (0 V before the first sample).

    Raises
    ------
    InputError
        A record without the loop's extras, an output that is not tracked.

    Examples
    --------
    A PI loop on a lag follows a +-0.1 rad square wave of period 10 s: four steps in 20 s, each measured the
    same (the loop is linear and settles within each half period):

    >>> import control
    >>> from trms.control.loop import closed_loop
    >>> from trms.control.pid import PIDController, PIDGains
    >>> from trms.plant import LinearPlant
    >>> from trms.signals import square_wave
    >>> plant = LinearPlant(control.ss([[0.5]], [[0.5]], [[1.0]], [[0.0]], 0.1))
    >>> pi = PIDController(PIDGains(kp=0.5, ki=5.0, kd=0.0), 0.1)
    >>> steps = square_wave_metrics(closed_loop(plant, pi, square_wave(20.0, 0.1, 10.0, 0.1)))
    >>> [(s.start_time, s.target) for s in steps]
    [(0.0, 0.1), (5.0, -0.1), (10.0, 0.1), (15.0, -0.1)]
    >>> sorted({round(s.overshoot, 3) for s in steps}), sorted({round(s.settling_time, 3) for s in steps})
    ([11.157], [0.944])
    """
    if "reference" not in record.extras or "control" not in record.extras:
        raise InputError("record has no 'reference'/'control' extras; run it with trms.control.loop.closed_loop")
    names = record.output_names
    j = names.index(output) if isinstance(output, str) and output in names else output
    if not isinstance(j, (int, np.integer)) or not 0 <= j < record.extras["reference"].shape[1]:
        raise InputError(
            f"output {output!r} is not a tracked output; "
            f"allowed: 0..{record.extras['reference'].shape[1] - 1} or {names}"
        )
    ref = record.extras["reference"][:, j]
    _, dy = record.deviations()
    y = dy[:, j]
    u = record.extras["control"]
    sat = record.extras.get("saturated")
    edges = step_edges(ref)
    bounds = list(edges) + [len(record)]
    out = []
    for a, b in zip(bounds[:-1], bounds[1:]):
        if b - a < 2:
            continue
        before = ref[a - 1] if a > 0 else 0.0
        previous = u[a - 1] if a > 0 else np.zeros(u.shape[1:])
        rest = rest_std.get(float(ref[a]), 0.0) if isinstance(rest_std, Mapping) else rest_std
        step_band = noise_band(ref[a] - before, rest, band) if rest else band
        m = step_metrics(
            record.time[a:b],
            y[a:b],
            u[a:b],
            before,
            ref[a],
            None if sat is None else sat[a:b],
            min(step_band, 1.0),
            previous,
        )
        if step_band >= 1.0:  # a loop that wobbles at rest by more than the step cannot be said to settle on it
            m = replace(m, settling_time=float("nan"))
        out.append(m)
    return out


def mode_attenuation(
    reference_output: object,
    shaped_output: object,
    sample_time: float,
    modes: Sequence[float],
    nperseg: int | None = None,
    halfwidth: float = 0.0,
) -> np.ndarray:
    """Attenuation (dB, positive = reduction) of the output PSD at each mode, shaped vs unshaped.

    Parameters
    ----------
    reference_output, shaped_output : array_like
        Output deviations (rad) of the unshaped and of the shaped run, shape ``(N,)`` each.
    sample_time : float
        Sample time (s).
    modes : sequence of float
        Mode frequencies (Hz).
    nperseg : int, optional
        Welch segment length (samples); see :func:`trms.identification.spectral.psd`.
    halfwidth : float
        Passed to :func:`trms.identification.spectral.attenuation_db`.

    Returns
    -------
    numpy.ndarray
        One value per mode (dB).

    Raises
    ------
    InputError
        Outputs that are not finite 1-D arrays, a bad sample time, segment length or mode.

    Examples
    --------
    Halving the 0.25 Hz component and keeping the 1 Hz one: ``20 log10(2)`` = 6.02 dB and 0 dB:

    >>> t = np.arange(4000) * 0.1
    >>> unshaped = np.sin(2 * np.pi * 0.25 * t) + np.sin(2 * np.pi * 1.0 * t)
    >>> shaped = 0.5 * np.sin(2 * np.pi * 0.25 * t) + np.sin(2 * np.pi * 1.0 * t)
    >>> np.round(mode_attenuation(unshaped, shaped, 0.1, [0.25, 1.0], nperseg=400), 2).tolist()
    [6.02, 0.0]
    """
    f, p_ref = psd(reference_output, sample_time, nperseg)
    _, p_shp = psd(shaped_output, sample_time, nperseg)
    return attenuation_db(f, p_ref, p_shp, modes, halfwidth)
