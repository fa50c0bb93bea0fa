"""The twin's control tasks as dm_env environments, in a dm_control-style suite.

``SUITE`` maps each task name of :data:`trms.envs.tasks.TASKS` to a constructor, and :func:`load`
builds one by name, the way ``dm_control.suite.load`` does. The tasks (reference, disturbances,
observation, reward, termination) are those of :mod:`trms.envs.tasks`, run by its
:class:`~trms.envs.tasks.TaskRunner`: the Gymnasium environments of :mod:`trms.envs.gym` are the
same tasks behind the other API.

Observations are a dict of bounded arrays (``angles``, ``rates``, ``rotor_speed``, ``reference``;
units and bounds in :mod:`trms.envs.tasks`); actions are absolute motor voltages in +-10 V.
A diverged simulation ends the episode with reward 0 and discount 0.

As dm_env specifies, ``step`` before the first ``reset``, or after an episode's last step, starts a
new episode (its action is ignored); a malformed action (text, complex, non-finite, wrong shape) is
refused in one line (:class:`~trms.errors.InputError`) and changes nothing.

Like a dm_control environment, each one has a :attr:`~TwinEnvironment.physics` (a dm_control
``mujoco.Physics`` over the twin's live model and data), which dm_control's viewer reads and whose
``render`` draws the rig offscreen (OpenGL backend: ``MUJOCO_GL``, else OSMesa, chosen when the
physics is first asked for; see :mod:`trms.twin.render`).

Examples
--------
>>> env = load("PitchTracking", task_kwargs={"random": 0})
>>> sorted(env.observation_spec())
['angles', 'rates', 'reference', 'rotor_speed']
>>> frame = env.physics.render(48, 64, camera_id="front")
>>> frame.shape, bool(frame.std() > 0)
((48, 64, 3), True)
>>> env.close()
"""

from __future__ import annotations

import collections
from collections.abc import Callable, Mapping
from typing import Any

import dm_env
import numpy as np
from dm_env import specs

from trms.envs.tasks import TASKS, TaskRunner
from trms.errors import InputError, check_choice, check_seed, short_repr
from trms.twin.render import dm_control_physics

__all__ = ["TwinEnvironment", "SUITE", "load"]

#: Observation groups, by the prefix of the observation names of :mod:`trms.envs.tasks`.
_GROUPS = {"angle": "angles", "rate": "rates", "rotor_speed": "rotor_speed", "reference": "reference"}


class TwinEnvironment(dm_env.Environment):
    """One task of :mod:`trms.envs.tasks` as a dm_env environment.

    Parameters
    ----------
    task_name : str
        A name of :data:`SUITE`.
    random : int, optional
        Seed of the episode sequence (each reset draws the next episode); 0 by default.

    Attributes
    ----------
    runner : TaskRunner
        The task engine (its ``twin`` is the live plant).
    """

    def __init__(self, task_name: str, random: int | None = None) -> None:
        check_choice("task", task_name, tuple(TASKS), error=InputError)
        seed = check_seed("random", random)  # an int seed or None; a RandomState, float or text is refused
        self.runner = TaskRunner(task_name, 0 if seed is None else seed)
        names = self.runner.observation_names
        self._slices: dict[str, list[int]] = collections.defaultdict(list)
        for i, n in enumerate(names):
            self._slices[_GROUPS[n.split(":")[0]]].append(i)
        self._physics: Any = None

    @property
    def twin(self) -> Any:
        """The live twin."""
        return self.runner.twin

    @property
    def physics(self) -> Any:
        """A dm_control ``mujoco.Physics`` over the twin's live model and data (built on first use, shared).

        It follows every step and every reset (the twin's data is reset in place, so ``physics.data.ptr`` stays
        the same, which dm_control's viewer reads as "same physics"); ``physics.named.data.qpos["pitch"]`` is the
        beam's pitch (rad) and ``physics.render(height, width, camera_id="front")`` draws the rig. See
        :func:`trms.twin.render.dm_control_physics`.

        Examples
        --------
        >>> env = load("PitchTracking", {"random": 0})
        >>> _ = env.reset()
        >>> _ = env.step(np.array([9.0]))
        >>> pitch = env.physics.named.data.qpos["pitch"][0]
        >>> bool(pitch == env.twin.channels()["true_angles"][0] != 0.0)
        True
        >>> env.close()
        """
        if self._physics is None:
            self._physics = dm_control_physics(self.twin.data)
        return self._physics

    def close(self) -> None:
        """Free the physics' rendering contexts (if any were made)."""
        if self._physics is not None:
            self._physics.free()
            self._physics = None

    def _observation(self, flat: np.ndarray) -> collections.OrderedDict:
        return collections.OrderedDict((k, flat[idx].copy()) for k, idx in self._slices.items())

    def reset(self) -> dm_env.TimeStep:
        """Start the next episode of the sequence; its first time step."""
        return dm_env.restart(self._observation(self.runner.reset()))

    def step(self, action: np.ndarray) -> dm_env.TimeStep:
        """Hold the voltages ``action`` (V) for one control step (or start an episode if none is running).

        Raises
        ------
        InputError
            A malformed action (nothing changes).
        """
        if self.runner.episode_over:
            return self.reset()
        obs, reward, terminated, truncated, _ = self.runner.step(action)
        observation = self._observation(obs)
        if terminated:
            return dm_env.termination(reward, observation)
        if truncated:
            return dm_env.truncation(reward, observation)
        return dm_env.transition(reward, observation)

    def observation_spec(self) -> collections.OrderedDict:
        lo, hi, names = self.runner.observation_low, self.runner.observation_high, self.runner.observation_names
        return collections.OrderedDict(
            (k, specs.BoundedArray((len(idx),), np.float64, lo[idx], hi[idx], name=",".join(names[i] for i in idx)))
            for k, idx in self._slices.items()
        )

    def action_spec(self) -> specs.BoundedArray:
        r = self.runner
        return specs.BoundedArray(
            r.action_low.shape, np.float64, r.action_low, r.action_high, name=",".join(r.twin.input_names)
        )


def _constructor(name: str) -> Callable[..., TwinEnvironment]:
    def make(random: int | None = None) -> TwinEnvironment:
        return TwinEnvironment(name, random)

    make.__doc__ = f"{TASKS[name].description}."
    make.__name__ = name
    return make


#: Task name -> constructor (keyword ``random``: the episode seed), like a dm_control domain's ``SUITE``.
SUITE: dict[str, Callable[..., TwinEnvironment]] = {name: _constructor(name) for name in TASKS}


def load(task_name: str, task_kwargs: Mapping[str, Any] | None = None) -> TwinEnvironment:
    """The suite's environment ``task_name`` (see :data:`SUITE`), built with ``task_kwargs``.

    Raises
    ------
    InputError
        Unknown task name; ``task_kwargs`` not a mapping, with a key other than ``random``, or a ``random``
        that is not a non-negative int (or None).

    Examples
    --------
    >>> load("PitchTracking", {"foo": 1})
    Traceback (most recent call last):
    ...
    trms.errors.InputError: unknown task_kwargs key 'foo'; allowed: 'random'
    """
    check_choice("task", task_name, tuple(SUITE), error=InputError)
    if task_kwargs is None:
        task_kwargs = {}
    if not isinstance(task_kwargs, Mapping):
        raise InputError(f"task_kwargs = {short_repr(task_kwargs)} must be a dict such as {{'random': 0}}, or None")
    for key in task_kwargs:
        check_choice("task_kwargs key", key, ("random",), error=InputError)
    return SUITE[task_name](**task_kwargs)
