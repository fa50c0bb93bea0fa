"""Sensors that record a twin's state at every physics step, for runs that read it off ``mujoco.rollout``.

A rollout copies out, per physics step, either the whole physics state (775 numbers a step for the rig, most of
them the rotors' delay lines) or the sensor data. So every twin's compiled model carries plain sensors of its state
(:func:`add_state_sensors`): the position and rate of every joint and the force of every actuator with an
activation, which for the rig's rotors (unit gain, no bias) is the activation itself. MuJoCo computes the sensors
at the start of each step, so the sensor data a rollout returns for step ``i`` is the state after step ``i - 1``,
bit for bit (:func:`state_columns` says where each value sits). Sensors change no physics.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

__all__ = ["PREFIX", "StateColumns", "add_state_sensors", "with_state_sensors", "state_columns"]

#: Name prefix of the sensors this module adds.
PREFIX = "trms_state_"
_SENS = mujoco.mjtSensor
_SLIDING = (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
_JOINTPOS, _JOINTVEL, _ACTUATORFRC = (
    int(t) for t in (_SENS.mjSENS_JOINTPOS, _SENS.mjSENS_JOINTVEL, _SENS.mjSENS_ACTUATORFRC)
)


def _plain(spec_sensor: mujoco.MjsSensor) -> bool:
    """Whether a sensor reports its value as it is: no cutoff, no delay, no interval, no history."""
    return (
        spec_sensor.cutoff == 0
        and spec_sensor.delay == 0
        and spec_sensor.nsample == 0
        and not np.any(np.asarray(spec_sensor.interval))
    )


def add_state_sensors(spec: mujoco.MjSpec) -> None:
    """Add (in place) a position and a rate sensor for every joint without a plain one, and a force sensor for every
    actuator with an activation; named ``trms_state_*``. Joints and actuators without a name get none (such a model
    then has no complete state in its sensors, and its runs are stepped).

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> spec = load_spec()
    >>> before = len(spec.sensors)
    >>> add_state_sensors(spec)
    >>> len(spec.sensors) - before > 0, spec.sensors[-1].name.startswith(PREFIX)
    (True, True)
    """
    have = {(int(s.type), s.objname) for s in spec.sensors if _plain(s)}
    for joint in spec.joints:
        if not joint.name or joint.type not in _SLIDING:
            continue
        for kind, tag in ((_SENS.mjSENS_JOINTPOS, "qpos"), (_SENS.mjSENS_JOINTVEL, "qvel")):
            if (int(kind), joint.name) not in have:
                spec.add_sensor(
                    name=f"{PREFIX}{tag}_{joint.name}",
                    type=kind,
                    objtype=mujoco.mjtObj.mjOBJ_JOINT,
                    objname=joint.name,
                )
    for actuator in spec.actuators:
        if actuator.name and actuator.dyntype != mujoco.mjtDyn.mjDYN_NONE:
            spec.add_sensor(
                name=f"{PREFIX}act_{actuator.name}",
                type=_SENS.mjSENS_ACTUATORFRC,
                objtype=mujoco.mjtObj.mjOBJ_ACTUATOR,
                objname=actuator.name,
            )


def with_state_sensors(spec: mujoco.MjSpec) -> mujoco.MjSpec:
    """A copy of ``spec`` with :func:`add_state_sensors`' sensors: what every twin's model is compiled from (its
    configuration then deletes a locked joint's sensors with the joint).

    Examples
    --------
    >>> from trms.twin import Twin, load_spec
    >>> from trms.twin.model import CONFIGURATIONS, build_model
    >>> model = build_model(with_state_sensors(load_spec()), CONFIGURATIONS["1dof"], timestep=0.005)
    >>> model.nsensordata == Twin("1dof").model.nsensordata
    True
    """
    out = spec.copy()
    add_state_sensors(out)
    return out


@dataclass(frozen=True)
class StateColumns:
    """Where a model's sensor data holds its state: the column of each ``qpos``, ``qvel`` and ``act`` entry."""

    qpos: np.ndarray
    qvel: np.ndarray
    act: np.ndarray


def state_columns(model: mujoco.MjModel) -> StateColumns | None:
    """The sensor data columns that hold ``model``'s joint positions, rates and activations, or None where its
    sensors do not hold them all exactly.

    Read from the model as it is now (a model changed in place is judged as changed): every joint a hinge or a
    slide, each value's sensor plain (no cutoff, delay or interval), and each actuator with an activation one whose
    force is that activation (fixed unit gain, no bias, no force limit, not acting early).

    Examples
    --------
    >>> from trms.twin import Twin
    >>> model = Twin("1dof").model
    >>> cols = state_columns(model)
    >>> cols is not None and cols.qpos.size == model.nq
    True
    >>> model.actuator_gainprm[0, 0] = 2.0  # a rotor whose force is twice its activation
    >>> state_columns(model) is None
    True
    """
    m = model
    if not np.all(np.isin(m.jnt_type, _SLIDING)):
        return None
    acts = np.flatnonzero(m.actuator_actadr >= 0)
    acts = acts[np.argsort(m.actuator_actadr[acts])]
    if not (
        np.all(m.actuator_actnum[acts] == 1)
        and np.all(m.actuator_gaintype[acts] == mujoco.mjtGain.mjGAIN_FIXED)
        and np.all(m.actuator_gainprm[acts, 0] == 1.0)
        and np.all(m.actuator_biastype[acts] == mujoco.mjtBias.mjBIAS_NONE)
        and not np.any(m.actuator_actearly[acts])
        and not np.any(m.actuator_forcelimited[acts])
    ):
        return None
    plain = (m.sensor_cutoff == 0) & (m.sensor_delay == 0) & ~np.any(m.sensor_interval != 0, axis=-1)
    plain &= m.sensor_dim == 1
    found: dict[tuple[int, int], int] = {}
    for i in np.flatnonzero(plain).tolist():
        found.setdefault((int(m.sensor_type[i]), int(m.sensor_objid[i])), int(m.sensor_adr[i]))
    try:
        qpos = [found[(_JOINTPOS, j)] for j in np.argsort(m.jnt_qposadr).tolist()]
        qvel = [found[(_JOINTVEL, j)] for j in np.argsort(m.jnt_dofadr).tolist()]
        act = [found[(_ACTUATORFRC, a)] for a in acts.tolist()]
    except KeyError:
        return None
    return StateColumns(*(np.array(c, dtype=int) for c in (qpos, qvel, act)))
