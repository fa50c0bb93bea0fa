"""N copies of one task as a Gymnasium vector environment, their twins stepped side by side on every core.

:class:`TwinVectorEnv` is a :class:`gymnasium.vector.VectorEnv` over ``num_envs`` runners of one task of
:mod:`trms.envs.tasks` (each its own twin, seeds and episodes), with the semantics of Gymnasium's own
``SyncVectorEnv`` of :class:`~trms.envs.gym.TwinTaskEnv`: next-step autoreset (the step after an episode ended
resets that environment, ignoring its action, and returns its first observation with reward 0), ``reset(seed=s)``
seeding environment ``i`` with ``s + i`` (or one seed each from a list), ``options={"reset_mask": mask}`` resetting
some, and the infos batched with a ``_key`` mask per key. Spaces are those of :class:`~trms.envs.gym.TwinTaskEnv`
(``normalised=True`` for float32 ones).

Per :meth:`~TwinVectorEnv.step`, one thread per core steps its share of the environments, each as the single
environment steps (:meth:`TaskRunner.step_volts <trms.envs.tasks.TaskRunner.step_volts>`: one native
``mj_step(nstep)`` per interval on the twin's own data, which MuJoCo runs with the GIL released). So one
environment's Python (its voltages, disturbances and encoders before and after the physics, its observation and
reward) runs while another's physics does, and each environment equals a single
:class:`~trms.envs.gym.TwinTaskEnv` of the same seed bit for bit, end stops included (its own data keeps the
constraint solver's warm start). One ``mujoco.rollout`` call over every twin would run their physics side by side
too, but then every environment's Python would run before and after it, one environment after another, while no
physics runs; and a rollout hands back states without the solver's warm start.

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
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from trms.envs.gym import InvalidActionError, InvalidSeedError, TwinTaskEnv, is_reset_seed
from trms.envs.tasks import TASKS, TaskRunner
from trms.errors import InputError, check_choice, short_repr

__all__ = ["TwinVectorEnv"]


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
        Threads that step the environments (default: the cores this process may use, at most ``num_envs``).
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
        n = self.num_envs
        nthread = min(n, int(threads) if threads is not None else _cores())
        # Contiguous shares, one a thread; this thread steps the first, the pool's threads the others.
        self._shares = [share.tolist() for share in np.array_split(np.arange(n), nthread)]
        self._pool = ThreadPoolExecutor(nthread - 1) if nthread > 1 else None
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
        InvalidSeedError
            A seed that is not None, a whole number >= 0 or a list of ``num_envs`` of them (a Gymnasium ``Error``
            and an :class:`~trms.errors.InputError`); no environment changes.
        InputError
            An unknown option or a reset mask that is not a boolean array of ``num_envs`` with one True; no
            environment changes.
        """
        n = self.num_envs
        seeds = self._seeds(seed)
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

    def _seeds(self, seed: object) -> list[int | None]:
        """Each environment's reset seed (see :meth:`reset`), every one checked before any environment resets."""
        n = self.num_envs
        allowed = "allowed: None or a whole number >= 0 (int)"
        if isinstance(seed, (list, tuple)):
            if len(seed) != n:
                raise InvalidSeedError(
                    f"reset seed = {short_repr(seed)} has {len(seed)} seeds; allowed: one per environment ({n})"
                )
            for i, value in enumerate(seed):
                if value is not None and not is_reset_seed(value):
                    raise InvalidSeedError(f"reset seed[{i}] = {short_repr(value)} ({type(value).__name__}); {allowed}")
            return [None if value is None else int(value) for value in seed]
        if seed is not None and not is_reset_seed(seed):
            raise InvalidSeedError(
                f"reset seed = {short_repr(seed)} ({type(seed).__name__}); {allowed}, or a list of {n} of them"
            )
        return [None] * n if seed is None else [int(seed) + i for i in range(n)]

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

    def _step_share(self, share: list[int], volts: list[np.ndarray], results: list[Any]) -> None:
        """Step environments ``share`` as each single environment steps (reset instead where its episode ended)."""
        for i in share:
            runner = self.runners[i]
            if self._autoreset[i]:
                results[i] = (runner.reset(), 0.0, False, False, self._reset_info(i))
            else:
                results[i] = runner.step_volts(volts[i])

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
        results: list[Any] = [None] * n
        pool = self._pool
        if pool is None and len(self._shares) > 1:
            raise InputError("this vector environment is closed")
        pending = [pool.submit(self._step_share, s, volts, results) for s in self._shares[1:]] if pool else []
        try:
            self._step_share(self._shares[0], volts, results)
        finally:  # every share finished (an error raised once all are)
            for future in pending:
                future.result()
        env_infos: list[dict[str, Any]] = []
        for i, result in enumerate(results):
            obs, self._rewards[i], self._terminations[i], self._truncations[i], info = result
            self._observations[i] = obs
            env_infos.append(info)
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
        """Stop the threads."""
        if self._pool is not None:
            self._pool.shutdown()
            self._pool = None
