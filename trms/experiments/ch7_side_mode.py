"""The ch. 7 low-pass finding under the alternative the thesis names: a 0.25 Hz mode in the loop's plant.

On the rig the 0.3 Hz command prefilter gave a quicker rise "at the expense of greater overshoot and
longer settling time" than the 0.2 Hz one, for R = 75, 100 and 125 (ch. 7.3.2.1), and the thesis
names the cause: "the excitation of flexible modes in the 0-0.3 Hz bandwidth", that is the 0.25 Hz
mode of its 1-DOF pitch spectrum (Table 3.1; the reason it put the prefilter's cut-off below it,
ch. 6.9.2). The twin has no 0.25 Hz mode (the calibration report measures why:
:mod:`trms.calibration.elastic_modes`). This module measures what that absence does to the
finding, in the same run as the report:

* :func:`loop_plant` -- the twin's linearisation at hover (its small-signal model, with the rotors'
  transport delay, without its ambient excitation and nonlinearity) as a plant with the report's measurement
  noise, optionally with a 0.25 Hz mode added in parallel at the plant input (before the delay);
* :func:`side_mode_gain` -- the size of that mode, set from the thesis's own description and never
  from the finding: the thesis names 0.25 and 0.34 Hz together as "the main resonant modes"
  (ch. 6.9.3, Table 3.1), and Table 4.2 attenuates them by comparable amounts (5.83 against 7 dB by
  the low-pass doublet, 0.83 against 1.83 dB by the band-stop), so the mode's peak in the plant's
  frequency response is made equal to the 0.34 Hz peak; its damping is the one damping the thesis
  identified, eq. (3.11)'s lightly damped pair;
* :func:`prefilter_evidence` -- the LPF 0.2 and 0.3 Hz cases on both plants, with the prefilters'
  and the plants' gains at 0.25 Hz.

The tables (:func:`trms.experiments.ch7_findings.findings`) test the same criterion on each.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import control
import numpy as np
import scipy.optimize

from trms.control.shaping.filters import CommandFilter
from trms.errors import ConfigurationError, InputError, check_in_range
from trms.experiments.ch67_lqg import CaseResult, lqg_cases, prefilters
from trms.plant import LinearPlant
from trms.reference import PSD_MODES_1DOF, VOLTAGE_LIMIT, eq_3_11
from trms.worlds import NOISE_STD

__all__ = [
    "SIDE_MODE_HZ",
    "LPF_CASES",
    "VARIANTS",
    "thesis_damping",
    "mode_peaks",
    "side_mode_gain",
    "loop_plant",
    "SideModeEvidence",
    "prefilter_evidence",
]

#: The thesis's lowest flexible mode of the 1-DOF rig (Hz): Table 3.1, the first PSD peak.
SIDE_MODE_HZ = PSD_MODES_1DOF[0]
#: The two prefilter cases the finding compares: (the better one on the rig, the worse one).
LPF_CASES = ("CSAS LPF 0.2 Hz", "CSAS LPF 0.3 Hz")
#: The two plants of the evidence, in the report's order.
VARIANTS = ("the twin's linearisation", "the twin's linearisation with a 0.25 Hz mode")
#: Half width (Hz) of the windows in which each mode's peak is read.
_WINDOW_HZ = 0.04
_GRID = np.arange(0.02, 1.0, 2.5e-4)


def thesis_damping() -> tuple[float, float]:
    """Frequency (Hz) and damping ratio of eq. (3.11)'s lightly damped pole pair.

    Examples
    --------
    >>> f, zeta = thesis_damping()
    >>> round(f, 2), round(zeta, 3)
    (0.34, 0.041)
    """
    g = eq_3_11()
    s = np.log(np.asarray(control.poles(g), complex)) / g.dt
    osc = s[np.abs(s.imag) > 1e-9]
    if osc.size == 0:
        raise InputError("eq. (3.11) has no oscillatory pole pair")
    k = int(np.argmin(-osc.real / np.abs(osc)))
    return float(abs(osc[k].imag) / (2 * np.pi)), float(-osc[k].real / abs(osc[k]))


def _mode(gain: float, frequency_hz: float, damping: float) -> control.StateSpace:
    w0 = 2 * np.pi * frequency_hz
    return control.ss(control.tf([gain * w0**2], [1.0, 2 * damping * w0, w0**2]))


def _with_mode(system: control.StateSpace, gain: float, frequency_hz: float, damping: float) -> control.StateSpace:
    if gain == 0.0:
        return system
    return control.parallel(system, _mode(gain, frequency_hz, damping))


def mode_peaks(system: control.StateSpace, frequency_hz: float = SIDE_MODE_HZ) -> tuple[float, float, float]:
    """Peak magnitudes (rad/V) of a continuous SISO plant near ``frequency_hz`` and near its main mode.

    The main mode is eq. (3.11)'s (0.34 Hz); each peak is the largest ``|G(j 2 pi f)|`` within
    +-0.04 Hz of the mode's frequency.

    Returns
    -------
    tuple of float
        ``(peak near frequency_hz, peak near the main mode, frequency of the main peak in Hz)``.
    """
    main_hz, _ = thesis_damping()
    mag = np.abs(np.asarray(system(2j * np.pi * _GRID)).ravel())
    low = np.abs(_GRID - frequency_hz) <= _WINDOW_HZ
    high = np.abs(_GRID - main_hz) <= _WINDOW_HZ
    k = int(np.argmax(np.where(high, mag, -np.inf)))
    return float(mag[low].max()), float(mag[k]), float(_GRID[k])


def side_mode_gain(system: control.StateSpace, frequency_hz: float = SIDE_MODE_HZ) -> float:
    """The DC gain (rad/V) of the mode that makes the plant's peak at ``frequency_hz`` equal its 0.34 Hz peak.

    The mode ``g w0^2 / (s^2 + 2 zeta w0 s + w0^2)`` (``zeta`` from :func:`thesis_damping`) is added
    in parallel; ``g`` is found by root finding (see the module docstring for why equal peaks).

    Parameters
    ----------
    system : control.StateSpace
        Continuous SISO plant (V -> rad), without the transport delay (it does not change magnitudes).
    frequency_hz : float
        The mode's frequency, within (0.1, 0.3] Hz.

    Examples
    --------
    >>> from trms.twin import Twin
    >>> sys = Twin("1dof", 0.2).linearise().continuous
    >>> g = side_mode_gain(sys)
    >>> low, high, _ = mode_peaks(control.parallel(sys, _mode(g, SIDE_MODE_HZ, thesis_damping()[1])))
    >>> bool(abs(low / high - 1) < 1e-6)
    True
    """
    f = check_in_range("frequency_hz", frequency_hz, 0.1, 0.3, unit=" Hz", low_open=True)
    _, zeta = thesis_damping()

    def excess(g: float) -> float:
        low, high, _ = mode_peaks(_with_mode(system, g, f, zeta), f)
        return low - high

    if excess(0.0) >= 0.0:
        return 0.0  # the plant already peaks there as high as at its main mode
    hi = float(abs(control.dcgain(system))) or 1.0
    while excess(hi) < 0.0:
        hi *= 2.0
    return float(scipy.optimize.brentq(excess, 0.0, hi, xtol=1e-10, rtol=1e-12))


def loop_plant(
    twin, gain: float = 0.0, frequency_hz: float = SIDE_MODE_HZ, noise_std: float = NOISE_STD
) -> LinearPlant:
    """The twin's linearisation at hover as a plant, optionally with a mode of DC gain ``gain`` rad/V at its input.

    The mode is added to the continuous linearisation before the rotors' transport delay, so it sees
    the input when the rigid beam does; the sum is discretised with the delay
    (:func:`~trms.twin.linearise.c2d_with_delay`). Limits: the rig's +-10 V about the twin's trim.

    Parameters
    ----------
    twin : trms.twin.Twin
        A 1-DOF twin (its linearisation, operating point and sample time are used).
    gain : float
        DC gain of the added mode (rad/V), >= 0; 0 adds none.
    frequency_hz : float
        The mode's frequency (Hz); its damping is :func:`thesis_damping`'s.
    noise_std : float
        Measurement noise (rad).

    Examples
    --------
    >>> from trms.twin import Twin
    >>> twin = Twin("1dof", 0.2)
    >>> loop_plant(twin).system.nstates == twin.linearise().discrete.nstates
    True
    """
    from trms.twin.linearise import c2d_with_delay

    g = check_in_range("gain", gain, 0.0, np.inf, unit=" rad/V")
    lin = twin.linearise()
    system = _with_mode(lin.continuous, g, frequency_hz, thesis_damping()[1])
    op = twin.operating_point
    return LinearPlant(
        c2d_with_delay(system, twin.sample_time, lin.input_delay),
        operating_point=op,
        input_names=op.input_names,
        output_names=op.output_names,
        input_limits=(-VOLTAGE_LIMIT, VOLTAGE_LIMIT),
        noise_std=noise_std,
    )


@dataclass
class SideModeEvidence:
    """The LPF cases on the twin's linearisation without and with the 0.25 Hz mode.

    Attributes
    ----------
    frequency_hz, damping, gain : float
        The mode (Hz, ratio, DC gain rad/V).
    peaks : dict
        Per variant, ``(peak near 0.25 Hz, main peak, main peak frequency)`` (rad/V, rad/V, Hz).
    prefilter_db : dict
        Gain (dB) of each LPF prefilter at the mode's frequency.
    results : dict
        Per variant, :class:`~trms.experiments.ch67_lqg.CaseResult` by ``(R, case)``.
    still_air : dict
        The same cases on the nonlinear, quantised twin in still air (the report's twin has its rotor-wash
        turbulence), by ``(R, case)``: what separates the twin's ambient excitation from the rest of what it
        adds to its linearisation.
    """

    frequency_hz: float
    damping: float
    gain: float
    peaks: dict[str, tuple[float, float, float]]
    prefilter_db: dict[str, float]
    results: dict[str, dict[tuple[float, str], CaseResult]]
    still_air: dict[tuple[float, str], CaseResult] = field(default_factory=dict)


def _prefilter(filters: Mapping[str, CommandFilter | None], case: str) -> CommandFilter:
    """The prefilter of a CSAS case (every low-pass case has one)."""
    f = filters[case]
    if f is None:
        raise ConfigurationError(f"case {case!r} has no prefilter")
    return f


def prefilter_evidence(
    model: control.StateSpace, weights: Sequence[float], seed: int = 0, twin=None
) -> SideModeEvidence:
    """Run the LPF 0.2 and 0.3 Hz cases on the twin's linearisation, without and with the thesis-sized mode.

    Parameters
    ----------
    model : control.StateSpace
        The design model (eq. 3.11, :func:`trms.worlds.design_model`).
    weights : sequence of float
        ``R`` values (the rig's: 75, 100, 125).
    seed : int
        Noise seed of every run.
    twin : trms.twin.Twin, optional
        The 1-DOF twin to linearise; default ``Twin("1dof", model.dt)``.

    Examples
    --------
    >>> from trms.worlds import design_model
    >>> ev = prefilter_evidence(design_model("1dof"), [125.0])
    >>> sorted(ev.results) == sorted(VARIANTS) and ev.gain > 0
    True
    """
    from trms.twin import Twin

    twin = twin if twin is not None else Twin("1dof", float(model.dt))
    continuous = twin.linearise().continuous
    _, zeta = thesis_damping()
    gain = side_mode_gain(continuous)
    filters = prefilters(twin.sample_time)
    out = SideModeEvidence(
        SIDE_MODE_HZ,
        zeta,
        gain,
        {},
        {c: float(_prefilter(filters, c).gain_db([SIDE_MODE_HZ])[0]) for c in LPF_CASES},
        {},
    )
    for name, g in zip(VARIANTS, (0.0, gain)):
        out.peaks[name] = mode_peaks(_with_mode(continuous, g, SIDE_MODE_HZ, zeta))
        out.results[name] = lqg_cases(loop_plant(twin, g), model, weights, LPF_CASES, seed=seed)
    # The same rig in still air (no rotor-wash turbulence), its measurement noise kept.
    calm = Twin("1dof", twin.sample_time, seed, spec=twin.spec, noise_std=NOISE_STD, still_air=True)
    out.still_air = lqg_cases(calm, model, weights, LPF_CASES, seed=seed)
    return out
