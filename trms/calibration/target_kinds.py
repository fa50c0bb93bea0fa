"""The kinds of target a calibration aims at, one figure each: a PSD peak, a coherence level, a model,
the rest pose, a response ratio, a movement, the ambient excitation, the gyroscopic coupling.

:class:`~trms.calibration.targets.Targets` collects them; :mod:`trms.calibration.checks` measures each.
"""

from __future__ import annotations

from dataclasses import dataclass

import control

from trms.errors import InputError, check_choice, check_in_range
from trms.twin.model import CONFIGURATIONS

__all__ = [
    "PeakTarget",
    "CoherenceTarget",
    "ModelTarget",
    "RestTarget",
    "RatioTarget",
    "MovementTarget",
    "AmbientTarget",
    "CouplingTarget",
    "parse_channel",
]


def parse_channel(channel: str, config: str) -> tuple[str, str]:
    """Split ``"u1->pitch"`` into (input, output), checking both exist in ``config``.

    Parameters
    ----------
    channel : str
        ``"INPUT->OUTPUT"``: an input (V) and an output (rad) of the configuration.
    config : {"1dof", "2dof", "yaw"}
        The rig configuration.

    Returns
    -------
    (str, str)
        The input's and the output's names.

    Raises
    ------
    InputError
        An unknown configuration, or a channel that is not one of its inputs and outputs.

    Examples
    --------
    >>> parse_channel("u2 -> yaw", "2dof")
    ('u2', 'yaw')
    """
    cfg = CONFIGURATIONS[check_choice("configuration", config, tuple(CONFIGURATIONS), error=InputError)]
    parts = [p.strip() for p in str(channel).split("->")]
    if len(parts) != 2 or parts[0] not in cfg.inputs or parts[1] not in cfg.outputs:
        raise InputError(
            f"channel {channel!r} is not 'INPUT->OUTPUT' of configuration {config!r} "
            f"(inputs {cfg.inputs}, outputs {cfg.outputs})"
        )
    return parts[0], parts[1]


@dataclass(frozen=True)
class PeakTarget:
    """A peak of an output's PSD when one input is excited: ``frequency_hz +- tolerance_hz``.

    Parameters
    ----------
    config : {"1dof", "2dof", "yaw"}
        The rig configuration of the run.
    channel : str
        ``"INPUT->OUTPUT"`` (:func:`parse_channel`).
    frequency_hz : float
        The peak's frequency (Hz), in (0, 5].
    tolerance_hz : float
        Half-width of the band it must fall in (Hz), in (0, 1].

    Examples
    --------
    >>> PeakTarget("1dof", "u1->pitch", 0.34).name
    '1dof u1->pitch PSD peak'
    """

    config: str
    channel: str
    frequency_hz: float
    tolerance_hz: float = 0.03

    def __post_init__(self) -> None:
        parse_channel(self.channel, self.config)
        check_in_range("peak target frequency_hz", self.frequency_hz, 0.0, 5.0, unit=" Hz", low_open=True)
        check_in_range("peak target tolerance_hz", self.tolerance_hz, 0.0, 1.0, unit=" Hz", low_open=True)

    @property
    def name(self) -> str:
        """A readable label."""
        return f"{self.config} {self.channel} PSD peak"


@dataclass(frozen=True)
class CoherenceTarget:
    """Median magnitude-squared coherence of a channel over a band: ``low`` (below) or ``high`` (above) a threshold.

    The median, not the mean: a Welch estimate dips at a lightly damped resonance narrower
    than its bins (the resolution bias the thesis notes, ch. 3.2.5), and one such notch
    should not decide whether a channel is coupled.

    Parameters
    ----------
    config : {"1dof", "2dof", "yaw"}
        The rig configuration of the run.
    channel : str
        ``"INPUT->OUTPUT"`` (:func:`parse_channel`).
    level : {"low", "high"}
        Whether the median must stay below or reach ``threshold``.
    threshold : float
        Magnitude-squared coherence, 0 to 1 (dimensionless).
    band_hz : (float, float)
        The band of the median (Hz), rising, within [0, 5].

    Examples
    --------
    >>> CoherenceTarget("2dof", "u2->pitch", "low", 0.3).name
    '2dof u2->pitch median coherence 0.02-1 Hz'
    """

    config: str
    channel: str
    level: str
    threshold: float
    band_hz: tuple[float, float] = (0.02, 1.0)

    def __post_init__(self) -> None:
        parse_channel(self.channel, self.config)
        check_choice("coherence level", self.level, ("low", "high"), error=InputError)
        check_in_range("coherence threshold", self.threshold, 0.0, 1.0)
        band = tuple(self.band_hz) if isinstance(self.band_hz, (tuple, list)) else ()
        if len(band) != 2:
            raise InputError(f"coherence band_hz must be two frequencies [low, high] in Hz, got {self.band_hz!r}")
        lo = check_in_range("coherence band_hz low", band[0], 0.0, 5.0, unit=" Hz")
        hi = check_in_range("coherence band_hz high", band[1], 0.0, 5.0, unit=" Hz")
        if not lo < hi:
            raise InputError(f"coherence band_hz {list(band)} Hz must rise: low < high")
        object.__setattr__(self, "band_hz", (lo, hi))

    @property
    def name(self) -> str:
        """A readable label."""
        return f"{self.config} {self.channel} median coherence {self.band_hz[0]:g}-{self.band_hz[1]:g} Hz"


@dataclass(frozen=True)
class ModelTarget:
    """A discrete SISO model of the 1-DOF ``u1 -> pitch`` channel that the twin should resemble.

    The fit matches the twin's linearised frequency response and step to ``system``'s; verification
    identifies an ARMAX model from the twin's data and compares the figures below with the same
    figures of ``system``, each within its tolerance, and reads the twin's mean step
    (:data:`~trms.measurement.protocol.STEP_PROTOCOL`) as ``system``'s own step is read.

    Attributes
    ----------
    system : control.TransferFunction
        Discrete, ``dt`` = the identification sample time (s).
    mode_tolerance_hz, gain_tolerance : float
        Tolerances on the identified model's lightly damped mode frequency (Hz) and DC gain (relative).
    dead_time_tolerance_s, time_constant_tolerance_s : float
        Tolerances on the step's dead time and time constant by the tangent construction (s,
        :func:`~trms.measurement.step_response.tangent_figures`).
    step_fit_percent : float
        Least NRMSE fit (%) of the twin's mean step to ``system``'s over the first
        :data:`~trms.measurement.step_response.STEP_FIT_WINDOW` s.
    damping_factor : float
        The damping ratio must lie within this factor of the target's.
    phase_tolerance_deg : float
        Largest phase difference from ``system`` over ``phase_band_hz`` (degrees).
    phase_band_hz : (float, float)
        The band of the phase comparison (Hz).

    Examples
    --------
    >>> from trms.reference import eq_3_11
    >>> target = ModelTarget(eq_3_11())
    >>> float(target.system.dt), target.mode_tolerance_hz
    (0.2, 0.01)
    """

    system: control.TransferFunction
    mode_tolerance_hz: float = 0.01
    damping_factor: float = 1.5
    gain_tolerance: float = 0.1
    dead_time_tolerance_s: float = 0.15
    time_constant_tolerance_s: float = 0.3
    step_fit_percent: float = 60.0
    phase_tolerance_deg: float = 30.0
    phase_band_hz: tuple[float, float] = (0.02, 1.0)

    def __post_init__(self) -> None:
        if not isinstance(self.system, control.TransferFunction) or not self.system.isdtime(strict=True):
            raise InputError("ModelTarget.system must be a discrete python-control TransferFunction")
        if self.system.ninputs != 1 or self.system.noutputs != 1:
            raise InputError("ModelTarget.system must be SISO (u1 -> pitch)")


@dataclass(frozen=True)
class RestTarget:
    """The 2-DOF beam's rest pose with the rotors off: ``pitch +- tolerance`` and ``|yaw| <= yaw_tolerance`` (rad).

    Parameters
    ----------
    pitch : float
        The rest pitch angle (rad; negative: the main rotor's end down).
    tolerance, yaw_tolerance : float
        Allowed miss of the pitch and of the yaw from 0 (rad).

    Examples
    --------
    >>> RestTarget(-0.62).tolerance
    0.05
    """

    pitch: float
    tolerance: float = 0.05
    yaw_tolerance: float = 0.05


@dataclass(frozen=True)
class RatioTarget:
    """An output's response to one input at most ``max_ratio`` of its response to another (RMS, same protocol).

    Parameters
    ----------
    config : {"1dof", "2dof", "yaw"}
        The rig configuration of the runs.
    channel, reference : str
        ``"INPUT->OUTPUT"`` channels (:func:`parse_channel`): the one bounded and the one it is compared with.
    max_ratio : float
        Largest ratio of their RMS responses (dimensionless), in (0, 10].

    Examples
    --------
    >>> RatioTarget("2dof", "u2->pitch", "u1->pitch", 0.1).name
    "2dof u2->pitch RMS over u1->pitch's"
    """

    config: str
    channel: str
    reference: str
    max_ratio: float

    def __post_init__(self) -> None:
        parse_channel(self.channel, self.config)
        parse_channel(self.reference, self.config)
        check_in_range("max_ratio", self.max_ratio, 0.0, 10.0, low_open=True)

    @property
    def name(self) -> str:
        """A readable label."""
        return f"{self.config} {self.channel} RMS over {self.reference}'s"


@dataclass(frozen=True)
class MovementTarget:
    """In the protocol that excites ``channel``'s input, its output must move: RMS of at least ``min_counts``
    encoder counts (a coherence or a ratio read off an encoder that does not move measures nothing).

    Parameters
    ----------
    config : {"1dof", "2dof", "yaw"}
        The rig configuration of the run.
    channel : str
        ``"INPUT->OUTPUT"`` (:func:`parse_channel`).
    min_counts : float
        Least RMS of the output (encoder counts), positive.

    Examples
    --------
    >>> MovementTarget("2dof", "u2->pitch").name
    '2dof u2->pitch RMS (encoder counts)'
    """

    config: str
    channel: str
    min_counts: float = 3.0

    def __post_init__(self) -> None:
        parse_channel(self.channel, self.config)
        check_in_range("min_counts", self.min_counts, 0.0, 1e6, low_open=True)

    @property
    def name(self) -> str:
        """A readable label."""
        return f"{self.config} {self.channel} RMS (encoder counts)"


@dataclass(frozen=True)
class AmbientTarget:
    """The rig's ambient excitation: its hover pitch RMS with constant inputs within ``hover_rms`` (rad), and
    the one-step residual variance of a 4th-order ARMAX on ch. 5's training experiment within ``tolerance``
    (relative) of ``residual_variance`` (rad^2).

    Parameters
    ----------
    hover_rms : (float, float)
        Rising range of the hover pitch RMS (rad).
    residual_variance : float
        Table 5.1's one-step residual variance (rad^2).
    tolerance : float
        Allowed relative miss of the residual variance, in (0, 1].

    Examples
    --------
    >>> AmbientTarget((0.002, 0.01), 1e-5).tolerance
    0.5
    """

    hover_rms: tuple[float, float]
    residual_variance: float
    tolerance: float = 0.5

    def __post_init__(self) -> None:
        lo, hi = (check_in_range("hover_rms", v, 0.0, 1.0, unit=" rad", low_open=True) for v in self.hover_rms)
        if lo >= hi:
            raise InputError(f"hover_rms = {self.hover_rms} must be an increasing (low, high) pair in rad")
        check_in_range("residual_variance", self.residual_variance, 0.0, 1.0, unit=" rad^2", low_open=True)
        check_in_range("residual variance tolerance", self.tolerance, 0.0, 1.0, low_open=True)


@dataclass(frozen=True)
class CouplingTarget:
    """The pitch torque per yaw rate at the flat hover (N m s/rad), within ``tolerance`` (relative) of ``value``.

    Parameters
    ----------
    value : float
        The coupling (N m s/rad), in (0, 10].
    tolerance : float
        Allowed relative miss, in (0, 1].

    Examples
    --------
    >>> CouplingTarget(0.02).tolerance
    0.3
    """

    value: float
    tolerance: float = 0.3

    def __post_init__(self) -> None:
        check_in_range("gyroscopic coupling", self.value, 0.0, 10.0, unit=" N m s/rad", low_open=True)
        check_in_range("gyroscopic coupling tolerance", self.tolerance, 0.0, 1.0, low_open=True)
