"""dm_control environments on the twin (dm_env interface, dm_control's Task conventions).

Two tasks:

* :func:`pitch_tracking` -- the 1-DOF rig (yaw locked): track a pitch target drawn at
  random each episode, from the hover trim.
* :func:`hover` -- the 2-DOF rig: hold the beam flat at zero yaw after a random
  initial displacement of both axes.

Actions are absolute motor voltages in [-10, 10] V (the rig's saturation), converted by
the thrust curves once per control step; one control step is one native
``mj_step(nstep)`` call. Observations are the encoder angles (quantised), the true axis
rates, the tachometer rotor states and, for tracking, the target.
"""

from __future__ import annotations

import collections

import numpy as np
from dm_control import mujoco as dm_mujoco
from dm_control.mujoco import wrapper
from dm_control.rl import control
from dm_control.suite import base
from dm_control.utils import rewards
from dm_env import specs

from .. import reference
from .rotors import rotor_controls
from .twin import Twin

__all__ = ["TwinPhysics", "PitchTracking", "Hover", "pitch_tracking", "hover"]


class TwinPhysics(dm_mujoco.Physics):
    """dm_control Physics of a twin configuration, with named accessors for the axes."""

    def axis_angles(self, axes: tuple[str, ...]) -> np.ndarray:
        """True joint angles of ``axes`` (rad)."""
        return np.array([self.named.data.qpos[a] for a in axes]).ravel()

    def axis_rates(self, axes: tuple[str, ...]) -> np.ndarray:
        """Joint rates of ``axes`` (rad/s)."""
        return np.array([self.named.data.qvel[a] for a in axes]).ravel()


class _TwinTask(base.Task):
    """Shared mechanics: voltage actions through the thrust curves, trim start, encoder observations."""

    def __init__(self, twin: Twin, random: int | np.random.RandomState | None = None) -> None:
        super().__init__(random=random)
        self.twin = twin
        self._axes = twin.output_names
        self._rotors = np.array([{"u1": 0, "u2": 1}[u] for u in twin.input_names])
        self._noise = np.random.default_rng(0)

    def action_spec(self, physics: TwinPhysics) -> specs.BoundedArray:
        n = len(self.twin.input_names)
        lim = self.twin.voltage_limit
        return specs.BoundedArray((n,), np.float64, np.full(n, -lim), np.full(n, lim), name=",".join(self.twin.input_names))

    def before_step(self, action: np.ndarray, physics: TwinPhysics) -> None:
        volts = self.twin.trim.voltages.copy()
        volts[self._rotors] = np.clip(np.asarray(action, float), -self.twin.voltage_limit, self.twin.voltage_limit)
        physics.data.ctrl[:] = rotor_controls(self.twin.curves, volts, physics.model.nu)

    def _start_at_trim(self, physics: TwinPhysics, displacement: np.ndarray) -> None:
        with physics.reset_context():
            self.twin.put_at_trim(physics.model.ptr, physics.data.ptr)
            for axis, dq in zip(self._axes, displacement):
                physics.named.data.qpos[axis] = dq
        self._noise = np.random.default_rng(self.random.randint(2**31))

    def _common_observation(self, physics: TwinPhysics) -> collections.OrderedDict:
        obs = collections.OrderedDict()
        obs["angles"] = self.twin.encoder.measure(physics.axis_angles(self._axes), self._noise)
        obs["rates"] = physics.axis_rates(self._axes)
        obs["rotor_speed"] = np.array([float(c.rotor_state(f)) for c, f in zip(self.twin.curves, physics.data.act)])
        return obs


class PitchTracking(_TwinTask):
    """Track a random pitch target (1-DOF rig). Reward 1 within 0.02 rad, Gaussian tail over 0.3 rad."""

    def __init__(self, twin: Twin, target_range: float = 0.3, random: int | np.random.RandomState | None = None) -> None:
        super().__init__(twin, random)
        self.target_range = float(target_range)
        self.target = 0.0

    def initialize_episode(self, physics: TwinPhysics) -> None:
        self._start_at_trim(physics, np.zeros(len(self._axes)))
        self.target = float(self.random.uniform(-self.target_range, self.target_range))
        super().initialize_episode(physics)

    def get_observation(self, physics: TwinPhysics) -> collections.OrderedDict:
        obs = self._common_observation(physics)
        obs["target"] = np.array([self.target])
        return obs

    def get_reward(self, physics: TwinPhysics) -> float:
        error = physics.axis_angles(("pitch",))[0] - self.target
        return float(rewards.tolerance(error, bounds=(-0.02, 0.02), margin=0.3, sigmoid="gaussian"))


class Hover(_TwinTask):
    """Hold the 2-DOF rig flat at zero yaw from a random displacement (up to 0.2 rad on each axis)."""

    def __init__(self, twin: Twin, displacement: float = 0.2, random: int | np.random.RandomState | None = None) -> None:
        super().__init__(twin, random)
        self.displacement = float(displacement)

    def initialize_episode(self, physics: TwinPhysics) -> None:
        self._start_at_trim(physics, self.random.uniform(-self.displacement, self.displacement, len(self._axes)))
        super().initialize_episode(physics)

    def get_observation(self, physics: TwinPhysics) -> collections.OrderedDict:
        return self._common_observation(physics)

    def get_reward(self, physics: TwinPhysics) -> float:
        err = np.linalg.norm(physics.axis_angles(self._axes))
        return float(rewards.tolerance(err, bounds=(0.0, 0.02), margin=0.3, sigmoid="gaussian"))


def _environment(twin: Twin, task: _TwinTask, time_limit: float) -> control.Environment:
    physics = TwinPhysics.from_model(wrapper.MjModel(twin.model))
    return control.Environment(physics, task, time_limit=time_limit, n_sub_steps=int(round(twin.sample_time / twin.model.opt.timestep)))


def pitch_tracking(
    time_limit: float = 20.0, sample_time: float = reference.SAMPLE_TIME_1DOF, random: int | np.random.RandomState | None = None
) -> control.Environment:
    """The 1-DOF pitch-tracking environment (control step ``sample_time`` s, default 0.2 s)."""
    twin = Twin("1dof", sample_time)
    return _environment(twin, PitchTracking(twin, random=random), time_limit)


def hover(
    time_limit: float = 20.0, sample_time: float = reference.SAMPLE_TIME_2DOF, random: int | np.random.RandomState | None = None
) -> control.Environment:
    """The 2-DOF hover environment (control step ``sample_time`` s, default 0.1 s)."""
    twin = Twin("2dof", sample_time)
    return _environment(twin, Hover(twin, random=random), time_limit)
