"""The hover trim: voltages and elastic deflections that hold the beam flat and still.

Unknowns: the configuration's input voltages and the angles of every elastic (non-axis)
joint. Conditions: every generalised acceleration is zero with the free axes at 0 rad
(or at the angles asked for: the static equilibrium that a voltage holds there),
all velocities zero and each rotor's lagged thrust equal to its steady thrust
``F(V)``. Solved by Levenberg-Marquardt on the accelerations (``scipy.optimize.least_squares``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import mujoco
import numpy as np
import scipy.optimize

from trms.errors import DesignError, InputError
from trms.twin.model import spin_dofs, spinning
from trms.twin.rotors import ThrustCurve, rotor_controls

__all__ = ["Trim", "solve_trim", "rest_pose"]


@dataclass(frozen=True)
class Trim:
    """A trimmed state.

    Attributes
    ----------
    voltages : numpy.ndarray
        Voltage of every rotor (V), main then tail (held rotors included).
    qpos : numpy.ndarray
        Joint positions (rad).
    act : numpy.ndarray
        Actuator activations = steady thrusts (N).
    qvel : numpy.ndarray
        Joint velocities (rad/s): zero but for the spinning rotors.
    ctrl : numpy.ndarray
        Actuator controls that hold the trim (thrusts, N, and rotor speeds, rad/s).
    residual : float
        Largest remaining generalised acceleration (rad/s2).
    """

    voltages: np.ndarray
    qpos: np.ndarray
    act: np.ndarray
    qvel: np.ndarray
    ctrl: np.ndarray
    residual: float


def solve_trim(
    model: mujoco.MjModel,
    curves: tuple[ThrustCurve, ...],
    free_rotors: tuple[int, ...],
    axis_joints: tuple[str, ...],
    voltage_limit: float = 10.0,
    tol: float = 1e-10,
    axis_angles: Mapping[str, float] | None = None,
) -> Trim:
    """Solve the hover trim of ``model``, or the voltages that hold its axes still at other angles.

    Parameters
    ----------
    model : mujoco.MjModel
        A compiled configuration.
    curves : tuple of ThrustCurve
        Thrust curve per actuator (actuator order).
    free_rotors : tuple of int
        Actuators whose voltage is a trim unknown; the others are held at 0 V.
    axis_joints : tuple of str
        Joints held at 0 rad (the rig's free axes); every other joint is solved for.
    voltage_limit : float
        Trim voltages must lie within +-this (V).
    tol : float
        Acceptable largest acceleration (rad/s2).
    axis_angles : mapping of str to float, optional
        Angles (rad) some of ``axis_joints`` are held at instead of 0 (the flat beam).

    Returns
    -------
    Trim

    Raises
    ------
    DesignError
        If no trim within the voltage limits holds the axes there.
    InputError
        An ``axis_angles`` name that is not among the model's ``axis_joints``.

    Examples
    --------
    The 1-DOF twin's main-rotor voltage that holds the beam 0.2 rad above flat is above the hover voltage:

    >>> from trms.twin import load_spec
    >>> from trms.twin.model import build_model, CONFIGURATIONS, thrust_curves
    >>> spec = load_spec()
    >>> m = build_model(spec, CONFIGURATIONS["1dof"], delay=False, scene=False)
    >>> flat = solve_trim(m, thrust_curves(spec), (0,), ("pitch",))
    >>> raised = solve_trim(m, thrust_curves(spec), (0,), ("pitch",), axis_angles={"pitch": 0.2})
    >>> bool(raised.voltages[0] > flat.voltages[0]), round(float(raised.qpos[m.joint("pitch").qposadr[0]]), 3)
    (True, 0.2)
    """
    data = mujoco.MjData(model)
    names = _joint_names(model)
    fixed = {model.jnt_qposadr[model.joint(n).id] for n in axis_joints if n in names}
    held = np.zeros(model.nq)
    for name, angle in (axis_angles or {}).items():
        if name not in axis_joints or name not in names:
            raise InputError(
                f"axis_angles names {name!r}; the held axes of this model are {sorted(set(axis_joints) & names)}"
            )
        held[model.jnt_qposadr[model.joint(name).id]] = float(angle)
    spins = spin_dofs(model)
    fixed |= {model.jnt_qposadr[model.dof_jntid[i]] for i in spins}  # spin angles are cyclic: held at 0
    free_q = np.array([i for i in range(model.nq) if i not in fixed], dtype=int)
    n_u = len(free_rotors)

    def apply(z: np.ndarray) -> np.ndarray:
        volts = np.zeros(len(curves))
        volts[list(free_rotors)] = z[:n_u]
        data.qpos[:] = held
        data.qpos[free_q] = z[n_u:]
        data.ctrl[:] = rotor_controls(curves, volts[: len(curves)], model.nu, spinning(model))
        data.act[:] = data.ctrl[: model.na]
        data.qvel[:] = 0.0
        data.qvel[spins] = data.ctrl[len(curves) : len(curves) + spins.size]
        mujoco.mj_forward(model, data)
        return volts

    def residual(z: np.ndarray) -> np.ndarray:
        apply(z)
        return data.qacc.copy()

    z0 = np.zeros(n_u + free_q.size)
    z0[:n_u] = min(1.0, 0.5 * voltage_limit)  # inside the bounds for any voltage limit
    bounds = (
        np.r_[np.full(n_u, -voltage_limit), np.full(free_q.size, -np.pi)],
        np.r_[np.full(n_u, voltage_limit), np.full(free_q.size, np.pi)],
    )
    sol = scipy.optimize.least_squares(residual, z0, bounds=bounds, xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=500)
    volts = apply(sol.x)
    worst = float(np.max(np.abs(data.qacc))) if model.nv else 0.0
    if worst > tol:
        raise DesignError(
            f"no hover trim within +-{voltage_limit} V: best voltages {volts.tolist()} leave accelerations "
            f"up to {worst:.3g} rad/s2 (tolerance {tol})"
        )
    return Trim(volts, data.qpos.copy(), data.act.copy(), data.qvel.copy(), data.ctrl.copy(), worst)


def _joint_names(model: mujoco.MjModel) -> set[str]:
    return {model.joint(i).name for i in range(model.njnt)}


def rest_pose(model: mujoco.MjModel, tol: float = 1e-9) -> np.ndarray:
    """The joint angles (rad) where the rig rests with both rotors off: every acceleration zero at rest.

    Parameters
    ----------
    model : mujoco.MjModel
        A compiled configuration (without transport delay, so the controls act at once).
    tol : float
        Acceptable largest acceleration (rad/s2).

    Returns
    -------
    numpy.ndarray
        ``qpos`` at rest (spin angles 0).

    Raises
    ------
    DesignError
        If no rest pose inside the joint ranges is found.

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> from trms.twin.model import build_model, CONFIGURATIONS
    >>> m = build_model(load_spec(), CONFIGURATIONS["1dof"], delay=False)
    >>> float(rest_pose(m)[m.jnt_qposadr[m.joint("pitch").id]]) < -0.3
    True
    """
    data = mujoco.MjData(model)
    spins = {model.jnt_qposadr[model.dof_jntid[i]] for i in spin_dofs(model)}
    free = np.array([i for i in range(model.nq) if i not in spins], dtype=int)

    def residual(z: np.ndarray) -> np.ndarray:
        data.qpos[:] = 0.0
        data.qpos[free] = z
        data.qvel[:] = 0.0
        data.ctrl[:] = 0.0
        data.act[:] = 0.0
        mujoco.mj_forward(model, data)
        return data.qacc.copy()

    sol = scipy.optimize.least_squares(residual, np.zeros(free.size), xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=500)
    worst = float(np.max(np.abs(residual(sol.x))))
    if worst > tol:
        raise DesignError(f"no rest pose found: accelerations up to {worst:.3g} rad/s2 remain (tolerance {tol})")
    return data.qpos.copy()
