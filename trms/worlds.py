"""The two worlds every experiment runs in: the linear model and the twin (thesis fig. 7.1).

``make_plant(world, config)`` builds a :class:`~trms.plant.Plant`:

* ``world="linear"``: for ``1dof``, eq. (3.11) in observer canonical form (the form of eq. 6.33,
  strictly proper), at ``Ts = 0.2 s`` or resampled exactly (same continuous dynamics under a
  zero-order hold) to another sample time; for ``2dof`` and ``yaw`` the thesis prints no model,
  so the twin's own linearisation at hover stands in (a :class:`~trms.plant.LinearPlant` of
  ``Twin(config).linearise().discrete``). Inputs saturate at the rig's +-10 V about the twin's
  hover trim, so both worlds share the same limits.
* ``world="twin"``: :class:`~trms.twin.Twin` with its encoder quantisation and +-10 V saturation,
  the rig's own ambient excitation (rotor-wash turbulence) and electronics noise, optional gusts,
  pushes and parameter changes.

Measurement noise: the twin's is its own (the calibrated electronics noise of the MJCF, with the
rotor-wash turbulence beside it); the linear model gets white noise of the same standard deviation,
:data:`NOISE_STD`, its only disturbance. Gusts (twin only, when asked): :data:`GUST`.

:func:`design_model` gives the model a controller is designed on: eq. (3.11) for 1-DOF (the
thesis's), and for 2-DOF the twin's linearisation reduced to its rigid-body and motor states
(the beam's bending states residualised, :func:`trms.control.realization.residualise`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import TYPE_CHECKING, Any, Literal, overload

import control
import numpy as np

from trms.control.inversion import InvertedInputs, StaticInputMap, linearised_limits
from trms.control.loop import Controller, deviation_limits
from trms.control.realization import observer_canonical, residualise
from trms.errors import ConfigurationError, check_choice, check_in_range
from trms.plant import LinearPlant, Plant

if TYPE_CHECKING:
    import mujoco

    from trms.twin import Push, Twin

from trms.reference import SAMPLE_TIME_1DOF, SAMPLE_TIME_2DOF, SAMPLE_TIME_RANGE, VOLTAGE_LIMIT, eq_3_11
from trms.twin.disturbances import MOVING_AIR

__all__ = [
    "WORLDS",
    "NOISE_STD",
    "GUST",
    "default_sample_time",
    "make_plant",
    "design_model",
    "resample",
    "rigid_states",
    "input_maps",
    "input_layer",
]


def _shipped_encoder_noise() -> float:
    from trms.twin.model import encoder_noise, load_spec

    return encoder_noise(load_spec())[0]


#: The two worlds, in the report's column order.
WORLDS = ("linear", "twin")
#: Measurement noise standard deviation of the linear world (rad): the twin's calibrated electronics noise on pitch
#: (the shipped MJCF's custom numeric ``encoder_noise``), so that both worlds' sensors agree.
NOISE_STD = _shipped_encoder_noise()
#: Gusts on the twin in the closed-loop experiments: stationary torque standard deviation (N m) and
#: correlation time (s), the twin's :data:`~trms.twin.disturbances.MOVING_AIR`.
GUST = (MOVING_AIR.std, MOVING_AIR.time_constant)


def default_sample_time(config: str) -> float:
    """The thesis's sample time for a configuration: 0.2 s for 1-DOF, 0.1 s for 2-DOF (and yaw)."""
    return SAMPLE_TIME_1DOF if config == "1dof" else SAMPLE_TIME_2DOF


def resample(system: control.StateSpace, sample_time: float) -> control.StateSpace:
    """The zero-order-hold model at another sample time with the same continuous dynamics.

    The continuous model whose ZOH discretisation is ``system`` is recovered exactly
    (matrix logarithm, :func:`trms.control.realization.continuous_jacobians`) and discretised again.

    Parameters
    ----------
    system : control.StateSpace
        Discrete, ``D = 0``, no eigenvalue on the closed negative real axis.
    sample_time : float
        New sample time (s).
    """
    from trms.control.realization import continuous_jacobians

    A_c, B_c = continuous_jacobians(np.asarray(system.A, float), np.asarray(system.B, float), float(system.dt))
    cont = control.ss(A_c, B_c, system.C, system.D, inputs=system.input_labels, outputs=system.output_labels)
    return control.c2d(cont, float(sample_time), method="zoh")


def rigid_states(state_names: list[str]) -> list[int]:
    """Indices of the rigid-body (pitch, yaw angles and rates) and motor (activation) states."""
    rigid = ("pitch", "yaw", "pitch_rate", "yaw_rate")
    return [i for i, n in enumerate(state_names) if n in rigid or n.endswith("_activation")]


def _twin(
    config: str,
    sample_time: float,
    seed: int,
    *,
    noise_std: float | None,
    gusts: bool,
    pushes: Iterable[Push],
    parameters: Mapping[str, float] | None,
    still_air: bool = False,
    spec: mujoco.MjSpec | None = None,
    quantised: bool = True,
) -> Twin:
    from trms.twin import DEFAULT_COUNTS_PER_REV, Gust, Twin, load_spec
    from trms.twin.parameters import with_parameters

    if parameters:
        spec = with_parameters(spec if spec is not None else load_spec(), dict(parameters))
    gust = Gust(*GUST) if gusts else None
    return Twin(
        config,
        sample_time,
        seed,
        counts_per_rev=DEFAULT_COUNTS_PER_REV if quantised else 0,
        spec=spec,
        noise_std=noise_std,
        gust=gust,
        pushes=tuple(pushes),
        still_air=still_air,
    )


@overload
def make_plant(
    world: Literal["twin"],
    config: str = "1dof",
    sample_time: float | None = None,
    *,
    seed: int = 0,
    noise_std: float | None = None,
    gusts: bool = False,
    pushes: Iterable[Push] = (),
    parameters: Mapping[str, float] | None = None,
    still_air: bool = False,
    spec: mujoco.MjSpec | None = None,
    quantised: bool = True,
) -> Twin: ...


@overload
def make_plant(
    world: str,
    config: str = "1dof",
    sample_time: float | None = None,
    *,
    seed: int = 0,
    noise_std: float | None = None,
    gusts: bool = False,
    pushes: Iterable[Push] = (),
    parameters: Mapping[str, float] | None = None,
    still_air: bool = False,
    spec: mujoco.MjSpec | None = None,
    quantised: bool = True,
) -> Plant: ...


def make_plant(
    world: str,
    config: str = "1dof",
    sample_time: float | None = None,
    *,
    seed: int = 0,
    noise_std: float | None = None,
    gusts: bool = False,
    pushes: Iterable[Push] = (),
    parameters: Mapping[str, float] | None = None,
    still_air: bool = False,
    spec: mujoco.MjSpec | None = None,
    quantised: bool = True,
) -> Plant:
    """A plant of one world (see the module docstring).

    Parameters
    ----------
    world : {"linear", "twin"}
    config : {"1dof", "2dof", "yaw"}
    sample_time : float, optional
        Seconds; default :func:`default_sample_time`.
    seed : int
        Noise (and gust) seed.
    noise_std : float, optional
        Measurement noise (rad); default: the twin's own electronics noise, :data:`NOISE_STD` for the
        linear model.
    gusts : bool
        Gust torques :data:`GUST` (twin only).
    pushes : iterable of trms.twin.Push
        Pushes on the beam (twin only).
    parameters : mapping, optional
        Physical parameter values (twin only), see :data:`trms.twin.parameters.PARAMETERS`.
    still_air : bool
        The twin without its ambient rotor-wash turbulence and electronics noise (twin only; moving air is the
        default, as on the rig).
    spec : mujoco.MjSpec, optional
        The twin's model (twin only; default the shipped one, :func:`trms.twin.load_spec`); ``parameters`` are
        set on a copy of it.
    quantised : bool
        The twin's encoders quantise (the default, as on the rig); False reads the angles exactly (twin only).

    Raises
    ------
    ConfigurationError
        Unknown world or configuration; disturbances, parameters or a model asked of the linear model.
    """
    check_choice("world", world, WORLDS)
    check_choice("configuration", config, ("1dof", "2dof", "yaw"))
    ts = (
        default_sample_time(config)
        if sample_time is None
        else check_in_range("sample_time", sample_time, *SAMPLE_TIME_RANGE[:2], unit=" s", error=ConfigurationError)
    )
    pushes = tuple(pushes)
    if world == "twin":
        return _twin(
            config,
            ts,
            seed,
            noise_std=noise_std,
            gusts=gusts,
            pushes=pushes,
            parameters=parameters,
            still_air=still_air,
            spec=spec,
            quantised=quantised,
        )
    if gusts or pushes or parameters or still_air or spec is not None or not quantised:
        raise ConfigurationError(
            "the linear model has no disturbance input, no physical parameters and no encoder; "
            "gusts, pushes, parameters, still air, a model file and quantised=False apply to the twin only"
        )
    twin = _twin(config, ts, seed, noise_std=0.0, gusts=False, pushes=(), parameters=None)
    noise_std = NOISE_STD if noise_std is None else noise_std
    op = twin.operating_point
    limits = (-VOLTAGE_LIMIT, VOLTAGE_LIMIT)
    if config == "1dof":
        model = observer_canonical(eq_3_11())
        if not np.isclose(ts, SAMPLE_TIME_1DOF):
            model = resample(model, ts)
        plant = LinearPlant(
            model,
            operating_point=op,
            input_names=op.input_names,
            output_names=op.output_names,
            input_limits=limits,
            noise_std=noise_std,
        )
    else:
        plant = LinearPlant(
            twin.linearise().discrete,
            operating_point=op,
            input_names=op.input_names,
            output_names=op.output_names,
            input_limits=limits,
            noise_std=noise_std,
        )
    plant.reset(seed)
    return plant


def design_model(config: str = "1dof", sample_time: float | None = None) -> control.StateSpace:
    """The model a controller is designed on (deviation V in, deviation rad out, ``D = 0``).

    ``1dof``: eq. (3.11) in observer canonical form (the thesis's design model), resampled if
    ``sample_time`` is not 0.2 s. ``2dof``: the twin's linearisation at hover reduced to its
    rigid-body and motor states (six: pitch, yaw, their rates, two rotor activations), the bending
    and rotor-spin states residualised, discretised by zero-order hold with the rotors' transport
    delay (its past inputs become states).
    """
    check_choice("configuration", config, ("1dof", "2dof"))
    ts = (
        default_sample_time(config)
        if sample_time is None
        else check_in_range("sample_time", sample_time, *SAMPLE_TIME_RANGE[:2], unit=" s", error=ConfigurationError)
    )
    if config == "1dof":
        model = observer_canonical(eq_3_11())
        return model if np.isclose(ts, SAMPLE_TIME_1DOF) else resample(model, ts)
    from trms.twin import Twin
    from trms.twin.linearise import c2d_with_delay

    lin = Twin("2dof", ts).linearise()
    reduced = residualise(lin.continuous, rigid_states(lin.state_names))
    return c2d_with_delay(reduced, ts, lin.input_delay)


def input_maps(plant: Plant) -> tuple[StaticInputMap, ...] | None:
    """The static input maps of a plant's actuators, one per input, for :class:`~trms.control.inversion.InvertedInputs`:
    the twin's calibrated thrust curves (main rotor for u1, tail rotor for u2; those of whatever MJCF it was built
    from, a rig owner's calibration included), or None for a plant without one (the linear model).

    Examples
    --------
    >>> input_maps(make_plant("linear", "1dof")) is None
    True
    >>> twin = make_plant("twin", "1dof")
    >>> [round(float(c.slope(u)), 3) for c, u in zip(input_maps(twin), twin.operating_point.inputs)]  # N/V at hover
    [1.846]
    """
    curves = getattr(plant, "curves", None)
    rotors = getattr(plant, "input_rotors", None)
    if curves is None or rotors is None:
        return None
    return tuple(curves[int(i)] for i in rotors)


def input_layer(plant: Plant, inversion: bool) -> tuple[tuple[np.ndarray, np.ndarray], Callable[[Any], Controller]]:
    """The input side a controller flies ``plant`` through: the limits to design its anti-windup for (deviation V, or
    linearised deviation V behind the thrust-curve inversion) and the wrapper that puts it behind that layer.

    Parameters
    ----------
    plant : Plant
    inversion : bool
        Invert the plant's static input maps (:func:`input_maps`; a plant without them is flown directly).

    Returns
    -------
    limits : tuple of numpy.ndarray
        ``(lower, upper)``, one per input.
    wrap : callable
        Controller -> the controller as it flies (:class:`~trms.control.inversion.InvertedInputs`, or itself).

    Examples
    --------
    >>> limits, wrap = input_layer(make_plant("linear", "1dof"), True)  # nothing to invert
    >>> [round(float(v[0]), 3) for v in limits], wrap("controller")
    ([-10.567, 9.433], 'controller')
    >>> limits, wrap = input_layer(make_plant("twin", "1dof"), True)
    >>> [round(float(v[0]), 2) for v in limits]  # the rotor's reach in hover-slope volts
    [-3.91, 5.51]
    """
    maps = input_maps(plant) if inversion else None
    if maps is None:
        return deviation_limits(plant), lambda c: c
    op = plant.operating_point
    limits = linearised_limits(maps, op.inputs, plant.input_limits)
    return limits, lambda c: InvertedInputs(c, maps, op.inputs, plant.input_limits)
