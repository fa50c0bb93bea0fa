"""The twin's control tasks as native Gymnasium environments, registered on import.

Importing this module registers, in the ``trms`` namespace:

* ``trms/PitchTracking-v0`` -- 1-DOF rig (yaw locked): track pitch steps;
* ``trms/HoverGusts-v0`` -- 2-DOF rig: return to hover from a displacement and hold it under
  gusts and random pushes;
* ``trms/AttitudeTracking-v0`` -- 2-DOF rig: track pitch and yaw steps.

The tasks (reference, disturbances, observation, reward, termination) are those of
:mod:`trms.twin.tasks`, run by its :class:`~trms.twin.tasks.TaskRunner` (one
:meth:`Twin.step <trms.twin.Twin.step>` per environment step): the dm_env suite of
:mod:`trms.twin.env` is the same tasks behind the other API.

Spaces: the action is the absolute motor voltage of each driven rotor (V), a ``Box`` of
``[-10, 10]``; values beyond are saturated by the twin, and ``info["saturated"]`` says which
were. The observation is a ``Box`` whose entries are named by ``env.unwrapped.observation_names``
(encoder angles in rad, axis rates in rad/s, tachometer rotor states, the reference in rad;
bounds and units in :mod:`trms.twin.tasks`). ``render_mode="rgb_array"`` draws the rig with the
offscreen renderer of :mod:`trms.twin.render`.

Examples
--------
>>> import gymnasium
>>> import trms.twin.gym
>>> env = gymnasium.make("trms/PitchTracking-v0")
>>> obs, info = env.reset(seed=0)
>>> env.unwrapped.observation_names
['angle:pitch', 'rate:pitch', 'rotor_speed:u1', 'reference:pitch']
>>> env.close()
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from ..errors import InputError, check_choice
from .render import TwinRenderer
from .tasks import TASKS, TaskRunner

__all__ = ["TwinTaskEnv", "ENV_IDS", "register"]

#: Gymnasium id of each task.
ENV_IDS = {name: f"trms/{name}-v0" for name in TASKS}


class TwinTaskEnv(gymnasium.Env):
    """One task of :mod:`trms.twin.tasks` as a Gymnasium environment.

    Parameters
    ----------
    task : str
        A task name of :data:`trms.twin.tasks.TASKS`.
    render_mode : {None, "rgb_array"}
        ``"rgb_array"``: :meth:`render` returns a ``(height, width, 3)`` uint8 frame.
    width, height : int
        Frame size (pixels).
    camera : str
        A camera of the model (``"front"`` by default).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self, task: str, render_mode: str | None = None, width: int = 320, height: int = 240, camera: str = "front"
    ) -> None:
        check_choice("task", task, tuple(TASKS), error=InputError)
        if render_mode is not None:
            check_choice("render_mode", render_mode, tuple(self.metadata["render_modes"]), error=InputError)
        self.runner = TaskRunner(task)
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "render_fps": int(round(1.0 / self.runner.twin.sample_time))}
        r = self.runner
        self.action_space = spaces.Box(r.action_low, r.action_high, dtype=np.float64)
        self.observation_space = spaces.Box(r.observation_low, r.observation_high, dtype=np.float64)
        self.observation_names = list(r.observation_names)
        self._size, self._camera = (int(width), int(height)), camera
        self._renderer: TwinRenderer | None = None

    @property
    def twin(self) -> Any:
        """The live twin."""
        return self.runner.twin

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an episode; ``seed`` fixes it (reference, pushes, gusts), else the next of the sequence."""
        super().reset(seed=seed)
        obs = self.runner.reset(seed)
        return obs, {"reference": self.runner.current_reference.copy(), "time": 0.0}

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Hold the voltages ``action`` (V) for one control step."""
        return self.runner.step(action)

    def render(self) -> np.ndarray | None:
        """The current frame (``render_mode="rgb_array"``), else None."""
        if self.render_mode != "rgb_array":
            return None
        if self._renderer is None:
            self._renderer = TwinRenderer(self.twin.model, *self._size)
        return self._renderer.frame(data=self.twin.data, camera=self._camera)

    def close(self) -> None:
        """Free the renderer's GL context."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


def register() -> None:
    """Register every task of :data:`ENV_IDS` with Gymnasium (done on import; repeated calls are no-ops)."""
    for name, env_id in ENV_IDS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(
                id=env_id,
                entry_point="trms.twin.gym:TwinTaskEnv",
                kwargs={"task": name},
                max_episode_steps=TASKS[name].n_steps,
            )


register()
