"""The twin's control tasks as native Gymnasium environments, registered on import.

Importing this module registers, in the ``trms`` namespace:

* ``trms/PitchTracking-v0`` -- 1-DOF rig (yaw locked): track pitch steps;
* ``trms/HoverGusts-v0`` -- 2-DOF rig: return to hover from a displacement and hold it under
  gusts and random pushes;
* ``trms/AttitudeTracking-v0`` -- 2-DOF rig: track pitch and yaw steps.

The tasks (reference, disturbances, observation, reward, termination) are those of
:mod:`trms.envs.tasks`, run by its :class:`~trms.envs.tasks.TaskRunner` (one
:meth:`Twin.step <trms.twin.Twin.step>` per environment step): the dm_env suite of
:mod:`trms.envs.suite` is the same tasks behind the other API.

Spaces: by default the action is the absolute motor voltage of each driven rotor (V), a float64
``Box`` of ``[-10, 10]``; values beyond are saturated by the twin, and ``info["saturated"]`` says
which were. The observation is a float64 ``Box`` whose entries are named by
``env.unwrapped.observation_names`` (encoder angles in rad, axis rates in rad/s, tachometer rotor
states, the reference in rad; bounds and units in :mod:`trms.envs.tasks`).

For learning, make the environment with ``normalised=True``: actions are float32 in ``[-1, 1]``,
mapped linearly onto the voltage range (-1 is -10 V, 1 is +10 V), and observations are float32, the
spaces Gymnasium's environment checker and most learning libraries expect
(``gymnasium.make("trms/HoverGusts-v0", normalised=True)``). ``info["applied_volts"]`` is in volts
either way. ``render_mode="rgb_array"`` draws the rig with the offscreen renderer of
:mod:`trms.twin.render` (OpenGL backend: ``MUJOCO_GL``, else OSMesa, chosen at the first render).

Misuse is refused as Gymnasium's own wrappers refuse it: ``step`` before the first ``reset``, or
after the episode terminated or was truncated, raises :class:`gymnasium.error.ResetNeeded`; a
malformed action (text, complex, NaN, wrong shape) raises :class:`InvalidActionError` (a
:class:`gymnasium.error.InvalidAction` and an :class:`~trms.errors.InputError`) in one line; a bad
seed raises :class:`InvalidSeedError` (Gymnasium's :class:`gymnasium.error.Error` and an
:class:`~trms.errors.InputError`) in one line naming it; reset options are refused (none exist).
``gymnasium.make(..., render_mode="human")`` shows the frames in a window through Gymnasium's
``HumanRendering`` (it needs pygame: without it the make is refused in one line, :func:`make_env`).

Examples
--------
>>> import gymnasium
>>> import trms.envs.gym
>>> env = gymnasium.make("trms/PitchTracking-v0", normalised=True)
>>> obs, info = env.reset(seed=0)
>>> env.unwrapped.observation_names
['angle:pitch', 'rate:pitch', 'rotor_speed:u1', 'reference:pitch']
>>> obs.dtype, env.action_space
(dtype('float32'), Box(-1.0, 1.0, (1,), float32))
>>> obs, reward, terminated, truncated, info = env.step(env.action_space.high)
>>> info["applied_volts"]
array([10.])
>>> env.close()
"""

from __future__ import annotations

import importlib.util
from typing import Any, TypeGuard

import gymnasium
import numpy as np
from gymnasium import spaces

from trms.envs.tasks import TASKS, TaskRunner
from trms.errors import InputError, check_choice, short_repr
from trms.twin.render import TwinRenderer

__all__ = [
    "TwinTaskEnv",
    "ENV_IDS",
    "RESET_OPTIONS",
    "InvalidActionError",
    "InvalidSeedError",
    "is_reset_seed",
    "make_env",
    "register",
]

#: The keys ``reset(options=...)`` accepts: none (an episode is fixed by its seed).
RESET_OPTIONS: tuple[str, ...] = ()


class InvalidActionError(InputError, gymnasium.error.InvalidAction):
    """A malformed action (text, complex, non-finite, wrong shape): Gymnasium's ``InvalidAction``, and an
    :class:`~trms.errors.InputError`."""


class InvalidSeedError(InputError, gymnasium.error.Error):
    """A reset seed that is not None or an int >= 0: Gymnasium's ``Error``, and an :class:`~trms.errors.InputError`."""


def is_reset_seed(value: object) -> TypeGuard[int | np.integer]:
    """Whether ``value`` is a reset seed: a whole number >= 0 (a Python or numpy int, not a bool).

    Examples
    --------
    >>> is_reset_seed(3), is_reset_seed(np.int64(3)), is_reset_seed(-1), is_reset_seed(True), is_reset_seed(2.0)
    (True, True, False, False, False)
    """
    return not isinstance(value, (bool, np.bool_)) and isinstance(value, (int, np.integer)) and bool(value >= 0)


#: Gymnasium id of each task.
ENV_IDS = {name: f"trms/{name}-v0" for name in TASKS}


class TwinTaskEnv(gymnasium.Env):
    """One task of :mod:`trms.envs.tasks` as a Gymnasium environment.

    Parameters
    ----------
    task : str
        A task name of :data:`trms.envs.tasks.TASKS`.
    render_mode : {None, "rgb_array"}
        ``"rgb_array"``: :meth:`render` returns a ``(height, width, 3)`` uint8 frame.
    width, height : int
        Frame size (pixels).
    camera : str
        A camera of the model (``"front"`` by default).
    normalised : bool
        Actions float32 in [-1, 1] mapped onto the voltage range, observations float32 (for learning
        libraries); by default actions are volts and both spaces float64.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self,
        task: str,
        render_mode: str | None = None,
        width: int = 320,
        height: int = 240,
        camera: str = "front",
        normalised: bool = False,
    ) -> None:
        check_choice("task", task, tuple(TASKS), error=InputError)
        if render_mode == "human":
            raise InputError(
                "render_mode='human' needs a window, and this environment draws offscreen: use render_mode='rgb_array' "
                "(frames as arrays), or gymnasium.make(..., render_mode='human') with pygame installed"
            )
        if render_mode is not None:
            check_choice("render_mode", render_mode, tuple(self.metadata["render_modes"]), error=InputError)
        if not isinstance(normalised, (bool, np.bool_)):
            raise InputError(f"normalised = {normalised!r} must be True or False")
        self.runner = TaskRunner(task)
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "render_fps": int(round(1.0 / self.runner.twin.sample_time))}
        r = self.runner
        self.normalised = bool(normalised)
        self._dtype = np.float32 if self.normalised else np.float64
        if self.normalised:
            ones = np.ones(r.action_low.shape, np.float32)
            self.action_space = spaces.Box(-ones, ones, dtype=np.float32)
        else:
            self.action_space = spaces.Box(r.action_low, r.action_high, dtype=np.float64)
        self.observation_space = spaces.Box(
            r.observation_low.astype(self._dtype), r.observation_high.astype(self._dtype), dtype=self._dtype
        )
        self.observation_names = list(r.observation_names)
        for name, value in (("width", width), ("height", height)):
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
                raise InputError(f"{name} = {short_repr(value)} must be a whole number of pixels (int)")
        self._size, self._camera = (int(width), int(height)), camera
        self._renderer: TwinRenderer | None = None
        self._started = False

    @property
    def twin(self) -> Any:
        """The live twin."""
        return self.runner.twin

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an episode; ``seed`` fixes it (reference, pushes, gusts), else the next of the sequence.

        Raises
        ------
        InvalidSeedError
            ``seed`` is not None or a whole number >= 0 (a Gymnasium ``Error``); nothing changes.
        InputError
            ``options`` has a key outside :data:`RESET_OPTIONS` (or is not a dict).
        """
        if options is not None:
            if not isinstance(options, dict):
                raise InputError(f"reset options must be a dict or None, got {type(options).__name__}")
            unknown = sorted(map(repr, set(options) - set(RESET_OPTIONS)))
            if unknown:
                allowed = ", ".join(map(repr, RESET_OPTIONS)) or "none (an episode is fixed by its seed)"
                raise InputError(f"unknown reset option {', '.join(unknown)}; allowed keys: {allowed}")
        if seed is not None and not is_reset_seed(seed):
            raise InvalidSeedError(
                f"reset seed = {short_repr(seed)} ({type(seed).__name__}); allowed: None or a whole number >= 0 (int)"
            )
        seed = None if seed is None else int(seed)
        super().reset(seed=seed)
        obs = self.runner.reset(seed)
        self._started = True
        return obs.astype(self._dtype), {"reference": self.runner.current_reference.copy(), "time": 0.0}

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Hold the voltages ``action`` asks for (V, or normalised: see :attr:`normalised`) for one control step.

        Raises
        ------
        gymnasium.error.ResetNeeded
            No episode is running: before the first ``reset``, or after it terminated or was truncated.
        InvalidActionError
            A malformed action (nothing changes).
        """
        if self.runner.episode_over:
            if not self._started:
                raise gymnasium.error.ResetNeeded("Cannot call env.step() before calling env.reset()")
            raise gymnasium.error.ResetNeeded(
                f"Cannot call env.step() after the episode ended (terminated or truncated at t = "
                f"{self.twin.time:.3f} s) before calling env.reset()"
            )
        try:
            volts = self.runner.volts(action, self.normalised)
        except InputError as exc:
            raise InvalidActionError(str(exc)) from None
        obs, reward, terminated, truncated, info = self.runner.step_volts(volts)
        return obs.astype(self._dtype, copy=False), reward, terminated, truncated, info  # obs is a new array

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


def make_env(task: str, render_mode: str | None = None, **kwargs: Any) -> gymnasium.Env:
    """Gymnasium's entry point of the tasks: :class:`TwinTaskEnv`, or with ``render_mode="human"`` the same showing its
    frames in a window through Gymnasium's ``HumanRendering`` (pygame).

    Raises
    ------
    InputError
        ``render_mode="human"`` without pygame (checked here, not at the first ``reset``).

    Examples
    --------
    >>> make_env("PitchTracking").render_mode is None
    True
    """
    if render_mode != "human":
        return TwinTaskEnv(task, render_mode, **kwargs)
    if importlib.util.find_spec("pygame") is None:
        raise InputError(
            "render_mode='human' shows the frames in a window with pygame, which is not installed "
            "(pip install pygame); render_mode='rgb_array' gives them as arrays"
        )
    return gymnasium.wrappers.HumanRendering(TwinTaskEnv(task, "rgb_array", **kwargs))


#: What Gymnasium reads of the entry point: "human" is handled by :func:`make_env`, not by a wrapper Gymnasium adds.
make_env.metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 10}  # type: ignore[attr-defined]


def register() -> None:
    """Register every task of :data:`ENV_IDS` with Gymnasium (done on import; repeated calls are no-ops), with
    :class:`trms.envs.vector.TwinVectorEnv` as its vector entry point (``gymnasium.make_vec``)."""
    for name, env_id in ENV_IDS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(
                id=env_id,
                entry_point="trms.envs.gym:make_env",
                vector_entry_point="trms.envs.vector:TwinVectorEnv",
                kwargs={"task": name},
                max_episode_steps=TASKS[name].n_steps,
            )


register()
