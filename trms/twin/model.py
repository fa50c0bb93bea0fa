"""Loading the MJCF, the rig's configurations, and locking axes exactly.

A configuration names which axes are free, which voltages the plant takes and which
angles it measures. Locking deletes the joint (and every sensor that names it) from a
copy of the MjSpec, so the locked axis is exactly fixed -- no soft constraint.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from ..errors import ModelFileError, check_choice
from .rotors import ThrustCurve

__all__ = [
    "DEFAULT_MODEL_PATH",
    "Configuration",
    "CONFIGURATIONS",
    "ROTORS",
    "load_spec",
    "build_model",
    "configure_spec",
    "thrust_curves",
]

#: The shipped model (calibrated).
DEFAULT_MODEL_PATH = Path(__file__).resolve().parents[1] / "models" / "trms.xml"

#: Actuator names of the two rotors, in input order (u1 main, u2 tail).
ROTORS = ("main_rotor", "tail_rotor")
_REQUIRED = {
    "joint": ("pitch", "yaw"),
    "actuator": ROTORS,
    "numeric": ("main_thrust_curve", "tail_thrust_curve"),
}


@dataclass(frozen=True)
class Configuration:
    """One way the rig is set up.

    Attributes
    ----------
    name : str
    locked : tuple of str
        Joints removed from the model (their axes are fixed at 0 rad).
    inputs : tuple of str
        Plant inputs, a subset of ``("u1", "u2")``; an absent rotor is held at 0 V.
    outputs : tuple of str
        Measured angles (joint names).
    trim_inputs : tuple of str
        Inputs whose hover voltage the trim solves for; the other inputs trim at 0 V.
    description : str
    """

    name: str
    locked: tuple[str, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    trim_inputs: tuple[str, ...]
    description: str


#: The rig's configurations (thesis ch. 2: either axis can be locked by its screw).
CONFIGURATIONS: dict[str, Configuration] = {
    "1dof": Configuration("1dof", ("yaw",), ("u1",), ("pitch",), ("u1",), "yaw locked: SISO main rotor u1 -> pitch"),
    "2dof": Configuration("2dof", (), ("u1", "u2"), ("pitch", "yaw"), ("u1", "u2"), "both axes free: u1, u2 -> pitch, yaw"),
    "yaw": Configuration("yaw", ("pitch",), ("u1", "u2"), ("yaw",), ("u2",), "pitch locked flat: u1, u2 -> yaw (u1 trims at 0 V)"),
}


def get_configuration(name: str) -> Configuration:
    """Look up a configuration by name, refusing unknown names with the list of allowed ones."""
    check_choice("configuration", name, tuple(CONFIGURATIONS))
    return CONFIGURATIONS[name]


def load_spec(path: str | os.PathLike[str] | None = None) -> mujoco.MjSpec:
    """Parse an MJCF into an MjSpec and check it has what the twin needs.

    Parameters
    ----------
    path : path-like, optional
        MJCF file; the shipped ``trms/models/trms.xml`` by default.

    Raises
    ------
    ModelFileError
        If the file is missing, is not valid MJCF, or lacks a required joint,
        actuator or thrust-curve numeric.
    """
    path = Path(path) if path is not None else DEFAULT_MODEL_PATH
    if not path.is_file():
        raise ModelFileError(f"model file {str(path)!r} does not exist")
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except Exception as exc:  # mujoco raises ValueError with the parser's message
        raise ModelFileError(f"model file {str(path)!r} is not valid MJCF: {exc}") from exc
    have = {
        "joint": {j.name for j in spec.joints},
        "actuator": {a.name for a in spec.actuators},
        "numeric": {n.name for n in spec.numerics},
    }
    for kind, names in _REQUIRED.items():
        missing = [n for n in names if n not in have[kind]]
        if missing:
            raise ModelFileError(f"model file {str(path)!r} lacks required {kind}(s) {missing}")
    return spec


def thrust_curves(spec: mujoco.MjSpec) -> tuple[ThrustCurve, ThrustCurve]:
    """The main and tail thrust curves stored in the spec's custom numerics."""
    return tuple(ThrustCurve.from_array(spec.numeric(f"{r.split('_')[0]}_thrust_curve").data) for r in ROTORS)  # type: ignore[return-value]


def fixed_tendon_coefficients(tendon: mujoco.MjsTendon) -> dict[str, float]:
    """Joint name -> coefficient of a fixed tendon."""
    return {w.target.name: float(w.coef) for w in tendon.path}


def rebuild_fixed_tendon(spec: mujoco.MjSpec, tendon: mujoco.MjsTendon, coefficients: dict[str, float]) -> None:
    """Replace a fixed tendon by one with the same name and spring but new joint coefficients.

    MuJoCo's spec does not allow editing a wrap's coefficient, so the tendon is rebuilt;
    with no coefficient left, it is removed.
    """
    props = {k: np.array(getattr(tendon, k)) for k in ("stiffness", "damping", "springlength")}
    name = tendon.name
    spec.delete(tendon)
    if coefficients:
        new = spec.add_tendon(name=name)
        for key, value in props.items():
            setattr(new, key, value)
        for joint, coef in coefficients.items():
            new.wrap_joint(joint, coef)


def _drop_joint_from_tendon(spec: mujoco.MjSpec, tendon: mujoco.MjsTendon, joint_name: str) -> None:
    """Rebuild a fixed tendon without ``joint_name`` (the spring keeps acting on the other joints)."""
    coefs = fixed_tendon_coefficients(tendon)
    if joint_name in coefs:
        rebuild_fixed_tendon(spec, tendon, {j: c for j, c in coefs.items() if j != joint_name})


def build_model(spec: mujoco.MjSpec, configuration: Configuration, voltage_limit: float = 10.0) -> mujoco.MjModel:
    """Compile a model of one configuration from a copy of ``spec``.

    Locked joints and the sensors that name them are deleted from the copy (fixed tendons
    lose that joint and keep acting on the others); each rotor's
    control range is set to the thrust its curve gives at ``-voltage_limit`` and
    ``+voltage_limit``.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The parsed MJCF (not modified).
    configuration : Configuration
    voltage_limit : float
        Motor voltage limit (V).

    Returns
    -------
    mujoco.MjModel
    """
    s = configure_spec(spec, configuration, voltage_limit)
    try:
        return s.compile()
    except Exception as exc:
        raise ModelFileError(f"model does not compile in configuration {configuration.name!r}: {exc}") from exc


def configure_spec(spec: mujoco.MjSpec, configuration: Configuration, voltage_limit: float = 10.0) -> mujoco.MjSpec:
    """The uncompiled spec of one configuration: a copy of ``spec`` as :func:`build_model` compiles it.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The parsed MJCF (not modified).
    configuration : Configuration
    voltage_limit : float
        Motor voltage limit (V).

    Returns
    -------
    mujoco.MjSpec
    """
    s = spec.copy()
    for joint_name in configuration.locked:
        for sensor in list(s.sensors):
            if sensor.objname == joint_name or sensor.name in (joint_name, f"{joint_name}_rate"):
                s.delete(sensor)
        for tendon in list(s.tendons):
            _drop_joint_from_tendon(s, tendon, joint_name)
        s.delete(s.joint(joint_name))
    for actuator, curve in zip(ROTORS, thrust_curves(s)):
        act = s.actuator(actuator)
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        act.ctrlrange = np.sort(curve.thrust(np.array([-voltage_limit, voltage_limit])))
    return s
