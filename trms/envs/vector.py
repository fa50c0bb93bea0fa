"""N copies of one task as a Gymnasium vector environment, their twins stepped together by ``mujoco.rollout``.

:class:`TwinVectorEnv` is a :class:`gymnasium.vector.VectorEnv` over ``num_envs`` runners of one task of
:mod:`trms.envs.tasks` (each its own twin, seeds and episodes), with the semantics of Gymnasium's own
``SyncVectorEnv`` of :class:`~trms.envs.gym.TwinTaskEnv`: next-step autoreset (the step after an episode ended
resets that environment, ignoring its action, and returns its first observation with reward 0), ``reset(seed=s)``
seeding environment ``i`` with ``s + i`` (or one seed each from a list), ``options={"reset_mask": mask}`` resetting
some, and the infos batched with a ``_key`` mask per key. Spaces are those of :class:`~trms.envs.gym.TwinTaskEnv`
(``normalised=True`` for float32 ones).

Per :meth:`~TwinVectorEnv.step`, each stepping environment's twin says what its interval feeds MuJoCo
(:meth:`Twin.interval_controls <trms.twin.Twin.interval_controls>`: controls and torques of every physics step, its
state), one call of a persistent :class:`mujoco.rollout.Rollout` advances all of them on every core (the GIL
released), and each twin takes its new state back (:meth:`Twin.finish_interval <trms.twin.Twin.finish_interval>`).
Each environment then equals a single :class:`~trms.envs.gym.TwinTaskEnv` of the same seed bit for bit, except after
an interval that starts against an end stop: the constraint solver's warm start is not part of a MuJoCo state, so
there the two agree to the solver's tolerance (as :func:`trms.batch.loop.batch_closed_loop` does).

``import trms.envs.gym`` registers it as the tasks' vector entry point: ``gymnasium.make_vec("trms/HoverGusts-v0",
num_envs=8)`` builds one.

Examples
--------
>>> envs = TwinVectorEnv("PitchTracking", num_envs=3)
>>> obs, info = envs.reset(seed=0)
>>> obs.shape, envs.action_space.shape
((3, 4), (3, 1))
>>> obs, reward, terminated, truncated, info = envs.step(np.tile(envs.runners[0].twin.operating_point.inputs, (3, 1)))
>>> reward.shape, bool(info["_time"].all())
((3,), True)
>>> envs.close()
"""

from __future__ import annotations

import os
from typing import Any

import mujoco
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from mujoco import rollout

from trms.envs.gym import InvalidActionError, TwinTaskEnv
from trms.envs.tasks import TASKS, TaskRunner
from trms.errors import DivergenceError, InputError, check_choice, short_repr

__all__ = ["TwinVectorEnv"]

_CONTROL = mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_QFRC_APPLIED
_FULL = mujoco.mjtState.mjSTATE_FULLPHYSICS


def _cores() -> int:
    """Cores this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


class TwinVectorEnv(VectorEnv):
    """``num_envs`` environments of one task, stepped together (see the module docstring).

    Parameters
    ----------
    task : str
        A task name of :data:`trms.envs.tasks.TASKS`.
    num_envs : int
        Number of environments, at least 1.
    normalised : bool
        Actions float32 in [-1, 1] and float32 observations, as :class:`~trms.envs.gym.TwinTaskEnv` has them.
    threads : int, optional
        Rollout threads (default: the cores this process may use, at most ``num_envs``).
    max_episode_steps : int, optional
        The task's episode length in steps (what ``gymnasium.make_vec`` passes; no other is accepted).

    Attributes
    ----------
    runners : list of TaskRunner
        The environments' task engines (each ``runner.twin`` is a live twin).
    """

    def __init__(
        self,
        task: str,
        num_envs: int,
        normalised: bool = False,
        threads: int | None = None,
        max_episode_steps: int | None = None,
    ) -> None:
        check_choice("task", task, tuple(TASKS), error=InputError)
        if max_episode_steps is not None and max_episode_steps != TASKS[task].n_steps:
            raise InputError(
                f"max_episode_steps = {short_repr(max_episode_steps)}: a {task} episode is {TASKS[task].n_steps} "
                "steps (leave it out)"
            )
        for name, value, low in (("num_envs", num_envs, 1), ("threads", threads, 1)):
            if value is None and name == "threads":
                continue
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < low:
                raise InputError(f"{name} = {short_repr(value)} must be a whole number >= {low}")
        single = TwinTaskEnv(task, normalised=normalised)
        self.num_envs = int(num_envs)
        self.normalised = single.normalised
        self.single_action_space = single.action_space
        self.single_observation_space = single.observation_space
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.metadata = {**single.metadata, "autoreset_mode": AutoresetMode.NEXT_STEP}
        self.render_mode = None
        self.observation_names = single.observation_names
        self.runners = [single.runner] + [TaskRunner(task) for _ in range(self.num_envs - 1)]
        self._dtype = single.observation_space.dtype
        twin = single.runner.twin
        self._nsub = int(round(twin.sample_time / twin.model.opt.timestep))
        nthread = min(self.num_envs, int(threads) if threads is not None else _cores())
        self._pool: rollout.Rollout | None = rollout.Rollout(nthread=nthread if nthread > 1 else 0)
        self._datas = [mujoco.MjData(twin.model) for _ in range(max(nthread, 1))]
        n, nstate = self.num_envs, mujoco.mj_stateSize(twin.model, _FULL)
        self._state0 = np.empty((n, nstate))
        self._warm = np.empty((n, twin.model.nv))
        self._controls = np.empty((n, self._nsub, mujoco.mj_stateSize(twin.model, _CONTROL)))
        self._states = np.empty((n, self._nsub, nstate))
        self._observations = np.zeros((n, len(self.observation_names)), self._dtype)
        self._rewards = np.zeros(n)
        self._terminations = np.zeros(n, bool)
        self._truncations = np.zeros(n, bool)
        self._autoreset = np.zeros(n, bool)
        self._started = False

    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an episode in every environment (or in those of ``options["reset_mask"]``).

        ``seed``: None (each environment's next episode), an int ``s`` (environment ``i`` gets ``s + i``) or one seed
        (or None) per environment.

        Raises
        ------
        InputError
            A seed list of the wrong length, a bad seed, an unknown option or a reset mask that is not a boolean
            array of ``num_envs`` with one True.
        """
        n = self.num_envs
        seeds: list[int | None]
        if seed is None:
            seeds = [None] * n
        elif isinstance(seed, (int, np.integer)) and not isinstance(seed, (bool, np.bool_)):
            seeds = [int(seed) + i for i in range(n)]
        elif isinstance(seed, (list, tuple)) and len(seed) == n:
            seeds = list(seed)
        else:
            raise InputError(f"seed = {short_repr(seed)} must be None, an int or a list of {n} seeds (int or None)")
        mask = np.ones(n, bool)
        options = dict(options or {})
        if "reset_mask" in options:
            mask = options.pop("reset_mask")
            if not (isinstance(mask, np.ndarray) and mask.dtype == np.bool_ and mask.shape == (n,) and mask.any()):
                raise InputError(
                    f"reset_mask = {short_repr(mask)} must be a numpy bool array of shape ({n},) with a True"
                )
        if options:
            raise InputError(f"unknown reset option {', '.join(map(repr, options))}; allowed: 'reset_mask'")
        env_infos: list[dict[str, Any]] = [{}] * n
        for i in np.flatnonzero(mask).tolist():
            self._observations[i] = self.runners[i].reset(seeds[i])
            env_infos[i] = self._reset_info(i)
        infos = self._batch_infos(env_infos)
        self._terminations[mask] = self._truncations[mask] = self._autoreset[mask] = False
        self._started = True
        return self._observations.copy(), infos

    def _batch_infos(self, env_infos: list[dict[str, Any]]) -> dict[str, Any]:
        """The environments' infos batched as ``VectorEnv._add_info`` batches them one by one (an array per key, its
        dtype the first value's, and a ``_key`` mask of the environments that have it), key by key at once."""
        infos: dict[str, Any] = {}
        keys = dict.fromkeys(key for info in env_infos for key in info)
        for key in keys:
            present = [i for i, info in enumerate(env_infos) if key in info]
            first = env_infos[present[0]][key]
            if type(first) in (int, float, bool) or isinstance(first, np.number):
                array = np.zeros(self.num_envs, dtype=type(first))
            elif isinstance(first, np.ndarray):
                array = np.zeros((self.num_envs, *first.shape), dtype=first.dtype)
            else:
                array = np.full(self.num_envs, fill_value=None, dtype=object)
            for i in present:
                array[i] = env_infos[i][key]
            mask = np.zeros(self.num_envs, dtype=np.bool_)
            mask[present] = True
            infos[key], infos[f"_{key}"] = array, mask
        return infos

    def _reset_info(self, i: int) -> dict[str, Any]:
        return {"reference": self.runners[i].current_reference.copy(), "time": 0.0}

    def step(self, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Step every environment once: those whose episode ended at the last step are reset instead (their action
        ignored, reward 0), the others hold their action's voltages for one control step.

        Raises
        ------
        gymnasium.error.ResetNeeded
            Before the first :meth:`reset`.
        InvalidActionError
            Actions that are not ``(num_envs, n_inputs)`` numbers, or a malformed row (nothing changes).
        """
        if not self._started:
            import gymnasium

            raise gymnasium.error.ResetNeeded("Cannot call step() before calling reset()")
        n = self.num_envs
        shape = self.action_space.shape
        try:
            rows = np.asarray(actions)
            if rows.shape != shape:
                raise InputError(f"actions must have shape {shape} (one row per environment), got {rows.shape}")
            if rows.dtype.kind == "f":
                rows = rows.astype(np.float64)  # real numbers: each row then takes the per-sample check
            volts = [self.runners[i].volts(rows[i], self.normalised) for i in range(n)]
        except (InputError, ValueError, TypeError) as exc:
            raise InvalidActionError(str(exc).splitlines()[0]) from None
        stepping = np.flatnonzero(~self._autoreset)
        starts = []
        for j, i in enumerate(stepping.tolist()):
            controls, start, warm = self.runners[i].twin.interval_controls(volts[i])
            self._controls[j], self._state0[j], self._warm[j] = controls, start, warm
            starts.append(start)
        k = stepping.size
        if k:
            assert self._pool is not None, "the environment is closed"
            self._pool.rollout(
                [self.runners[i].twin.model for i in stepping.tolist()],
                self._datas,
                self._state0[:k],
                self._controls[:k],
                control_spec=_CONTROL,
                nstep=self._nsub,
                initial_warmstart=self._warm[:k],
                state=self._states[:k],
                skip_checks=True,
            )
        env_infos: list[dict[str, Any]] = [{}] * n
        for j, i in enumerate(stepping.tolist()):
            runner = self.runners[i]
            try:
                measured = runner.twin.finish_interval(self._states[j, -1], starts[j])
            except DivergenceError as exc:
                result = runner.diverged(exc)
            else:
                result = runner.stepped(volts[i], measured)
            obs, self._rewards[i], self._terminations[i], self._truncations[i], env_infos[i] = result
            self._observations[i] = obs
        for i in np.flatnonzero(self._autoreset).tolist():
            self._observations[i] = self.runners[i].reset()
            self._rewards[i], self._terminations[i], self._truncations[i] = 0.0, False, False
            env_infos[i] = self._reset_info(i)
        infos = self._batch_infos(env_infos)
        self._autoreset = self._terminations | self._truncations
        return (
            self._observations.copy(),
            self._rewards.copy(),
            self._terminations.copy(),
            self._truncations.copy(),
            infos,
        )

    def close_extras(self, **kwargs: Any) -> None:
        """Stop the rollout threads."""
        if self._pool is not None:
            self._pool.close()
            self._pool = None
