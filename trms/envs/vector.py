"""N copies of one task as a Gymnasium vector environment, their twins stepped side by side in processes on every core.

:class:`TwinVectorEnv` is a :class:`gymnasium.vector.VectorEnv` over ``num_envs`` runners of one task of
:mod:`trms.envs.tasks` (each its own twin, seeds and episodes), with the semantics of Gymnasium's own
``SyncVectorEnv`` of :class:`~trms.envs.gym.TwinTaskEnv`: next-step autoreset (the step after an episode ended
resets that environment, ignoring its action, and returns its first observation with reward 0), ``reset(seed=s)``
seeding environment ``i`` with ``s + i`` (or one seed each from a list), ``options={"reset_mask": mask}`` resetting
some, and the infos batched with a ``_key`` mask per key. Spaces are those of :class:`~trms.envs.gym.TwinTaskEnv`
(``normalised=True`` for float32 ones).

The environments are split in contiguous shares (:mod:`trms.envs.shares`), one a process: this process steps the
first, and one worker process each of the others (``workers``, by default one per core this process may use). Per
:meth:`~TwinVectorEnv.step` the actions are checked here, written to shared memory with every environment's row, and
each process steps its share as the single environment steps (one native ``mj_step(nstep)`` per interval on the
twin's own data), so each environment equals a single :class:`~trms.envs.gym.TwinTaskEnv` of the same seed bit for
bit, end stops included (its own data keeps the constraint solver's warm start). Processes, not threads: an
environment's step is a third Python (its voltages, disturbances, encoders, observation and reward) beside its
physics, and threads run that Python one at a time. One ``mujoco.rollout`` call over every twin would run their
physics side by side too, but every environment's Python would then run before and after it, one environment after
another, and a rollout hands back states without the solver's warm start.

A worker ignores Ctrl-C: an interrupted call finishes the workers' share of it, and the next call then asks for a
reset (the environments are no longer at one step). :meth:`~TwinVectorEnv.close` (or the end of a ``with`` block)
stops the workers, ending one that does not answer; a worker ends by itself when this process ends, however it
ends. A worker that fails or ends raises :class:`~trms.envs.shares.WorkerError` in one line, and the vector
environment closes.

``import trms.envs.gym`` registers it as the tasks' vector entry point: ``gymnasium.make_vec("trms/HoverGusts-v0",
num_envs=8)`` builds one.

Examples
--------
>>> envs = TwinVectorEnv("PitchTracking", num_envs=3)
>>> obs, info = envs.reset(seed=0)
>>> obs.shape, envs.action_space.shape
((3, 4), (3, 1))
>>> obs, reward, terminated, truncated, info = envs.step(np.tile(envs.operating_inputs, (3, 1)))
>>> reward.shape, bool(info["_time"].all())
((3,), True)
>>> envs.close()
"""

from __future__ import annotations

import multiprocessing
import os
import pickle
from typing import Any

import gymnasium
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from trms.envs.gym import InvalidActionError, InvalidSeedError, TwinTaskEnv, is_reset_seed
from trms.envs.shares import DIVERGED, RESET, SPIN, STEP, STEPPED, Assignment, Share, Slots, Worker, WorkerError
from trms.envs.tasks import TASKS, TaskRunner
from trms.errors import InputError, check_choice, short_repr
from trms.processes import interrupts_held, start_method

__all__ = ["TwinVectorEnv", "ClosedEnvironmentError", "START_METHODS"]

#: The ways a worker process may start (``multiprocessing``'s start methods this platform has).
START_METHODS = tuple(multiprocessing.get_all_start_methods())


def _cores() -> int:
    """Cores this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def _context(method: str | None) -> multiprocessing.context.BaseContext:
    """The multiprocessing context of ``method`` (default: :func:`trms.processes.start_method`'s, forked where that
    is safe, else spawned); a fork server imports the tasks once, before it forks the workers."""
    context = start_method() if method is None else multiprocessing.get_context(method)
    if context.get_start_method() == "forkserver":
        context.set_forkserver_preload(["trms.envs.shares"])
    return context


class ClosedEnvironmentError(InputError, gymnasium.error.ClosedEnvironmentError):
    """A call on a closed vector environment: Gymnasium's ``ClosedEnvironmentError``, and an
    :class:`~trms.errors.InputError`."""


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
    workers : int, optional
        Processes that step the environments, this one included (default: the cores this process may use), at most
        ``num_envs`` (more are not started); 1 steps them all here.
    start_method : str, optional
        How the worker processes start, one of :data:`START_METHODS` (default: forked where that is safe, else
        spawned: :func:`trms.processes.start_method`). A spawned worker, or one from a fork server, imports the main
        script again, so a script builds the environment under ``if __name__ == "__main__":``, as Python's
        ``multiprocessing`` asks.
    max_episode_steps : int, optional
        The task's episode length in steps (what ``gymnasium.make_vec`` passes; no other is accepted: Gymnasium's
        ``SyncVectorEnv`` of the single environments, ``vectorization_mode="sync"``, takes a shorter one).
    render_mode : None
        Refused unless None: the vector environment draws nothing (a single environment does).

    Attributes
    ----------
    runners : list of TaskRunner
        The task engines of the environments this process steps (the first share; each ``runner.twin`` is a live
        twin).
    operating_inputs : numpy.ndarray
        The task's hover trim voltages (V): an action that holds the beam flat.
    """

    def __init__(
        self,
        task: str,
        num_envs: int,
        normalised: bool = False,
        workers: int | None = None,
        start_method: str | None = None,
        max_episode_steps: int | None = None,
        render_mode: str | None = None,
    ) -> None:
        self.closed = True  # until the workers are up
        self._workers: list[Worker] = []
        check_choice("task", task, tuple(TASKS), error=InputError)
        if render_mode is not None:
            raise InputError(
                f"render_mode = {short_repr(render_mode)}: the vector environment draws nothing; render a single "
                "environment (gymnasium.make(..., render_mode='rgb_array'))"
            )
        if start_method is not None:
            check_choice("start_method", start_method, START_METHODS, error=InputError)
        if max_episode_steps is not None and max_episode_steps != TASKS[task].n_steps:
            raise InputError(
                f"max_episode_steps = {short_repr(max_episode_steps)}: a {task} episode is {TASKS[task].n_steps} "
                "steps (leave it out)"
            )
        for name, value in (("num_envs", num_envs), ("workers", workers)):
            if value is None and name == "workers":
                continue
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < 1:
                raise InputError(f"{name} = {short_repr(value)} must be a whole number >= 1")
        n = self.num_envs = int(num_envs)
        processes = min(n, int(workers) if workers is not None else _cores())
        context = _context(start_method) if processes > 1 else None
        single = TwinTaskEnv(task, normalised=normalised)
        self.normalised = single.normalised
        self.single_action_space = single.action_space
        self.single_observation_space = single.observation_space
        self.action_space = batch_space(self.single_action_space, n)
        self.observation_space = batch_space(self.single_observation_space, n)
        self.metadata = {**single.metadata, "render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}
        self.render_mode = None
        self.observation_names = single.observation_names
        self.operating_inputs = single.twin.operating_point.inputs.copy()
        self._dtype = single.observation_space.dtype
        twin = single.twin
        dims = (n, len(twin.input_names), len(twin.output_names), len(self.observation_names))
        self._block = multiprocessing.RawArray("b", Slots.size(*dims))
        self._slots = Slots(self._block, *dims)
        shares = [share.tolist() for share in np.array_split(np.arange(n), processes)]
        self.runners = [single.runner] + [TaskRunner(task) for _ in shares[0][1:]]
        self._share = Share(dict(zip(shares[0], self.runners)), self._slots)
        try:
            with interrupts_held():  # a worker ignores Ctrl-C before it lets it through
                spin = SPIN if processes <= _cores() else 0.0  # more processes than cores: a poll takes one's time
                for indices in shares[1:]:
                    assert context is not None
                    self._workers.append(Worker(context, Assignment(task, indices, self._block, dims, spin)))
            for worker in self._workers:
                worker.receive()  # ready
        except BaseException:
            self._stop_workers()
            raise
        self._started = np.zeros(n, bool)  # per environment: reset at least once
        self._interrupted = False
        self.closed = False

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
            Options that are not a dict, an unknown option or a reset mask that is not a boolean array of
            ``num_envs`` with one True; no environment changes.
        ClosedEnvironmentError
            The vector environment is closed.
        """
        n = self.num_envs
        seeds = self._seeds(seed)
        mask = np.ones(n, bool)
        if options is not None and not isinstance(options, dict):
            raise InputError(f"reset options = {short_repr(options)} must be a dict or None")
        options = dict(options or {})
        if "reset_mask" in options:
            mask = options.pop("reset_mask")
            if not (isinstance(mask, np.ndarray) and mask.dtype == np.bool_ and mask.shape == (n,) and mask.any()):
                raise InputError(
                    f"reset_mask = {short_repr(mask)} must be a numpy bool array of shape ({n},) with a True"
                )
        if options:
            raise InputError(f"unknown reset option {', '.join(map(repr, options))}; allowed: 'reset_mask'")
        self._check_open()
        chosen = {i: seeds[i] for i in np.flatnonzero(mask).tolist()}
        own = {i: chosen[i] for i in self._share.runners if i in chosen}
        self._exchange(
            [pickle.dumps({i: chosen[i] for i in w.indices if i in chosen}) for w in self._workers],
            lambda: self._share.reset(own),
        )
        s = self._slots
        infos = self._batch_infos([self._reset_info(i) if mask[i] else {} for i in range(n)])
        s.terminated[mask] = s.truncated[mask] = s.autoreset[mask] = False
        self._started |= mask
        self._interrupted = False
        return s.observations.astype(self._dtype), infos

    def _seeds(self, seed: object) -> list[int | None]:
        """Each environment's reset seed (see :meth:`reset`), every one checked before any environment resets."""
        n = self.num_envs
        allowed = "allowed: None or a whole number >= 0 (int)"
        if isinstance(seed, np.ndarray) and seed.ndim == 1 and seed.dtype.kind in "iu":  # one each, as integers
            seed = seed.tolist()
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

    def _reset_info(self, i: int) -> dict[str, Any]:
        return {"reference": self._slots.reference[i].copy(), "time": 0.0}

    def _step_info(self, i: int, diverged: dict[int, str]) -> dict[str, Any]:
        """Environment ``i``'s info of the last step, as the single environment gives it."""
        s = self._slots
        kind = s.kind[i]
        if kind == RESET:
            return self._reset_info(i)
        if kind == DIVERGED:
            return {"diverged": diverged[i], "time": float(s.time[i])}
        return {
            "applied_volts": s.applied[i].copy(),
            "saturated": s.saturated[i].copy(),
            "true_angles": s.true[i].copy(),
            "time": float(s.time[i]),
        }

    def _step_infos(self, diverged: dict[int, str]) -> dict[str, Any]:
        """The batched infos of the last step (every environment stepped: its arrays at once)."""
        s = self._slots
        if not (s.kind == STEPPED).all():
            return self._batch_infos([self._step_info(i, diverged) for i in range(self.num_envs)])
        every = np.ones(self.num_envs, dtype=np.bool_)
        infos: dict[str, Any] = {}
        for key, values in (
            ("applied_volts", s.applied),
            ("saturated", s.saturated),
            ("true_angles", s.true),
            ("time", s.time),
        ):
            infos[key], infos[f"_{key}"] = values.copy(), every.copy()
        return infos

    def step(self, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Step every environment once: those whose episode ended at the last step are reset instead (their action
        ignored, reward 0), the others hold their action's voltages for one control step.

        Raises
        ------
        gymnasium.error.ResetNeeded
            Before every environment was reset once, or after a step that was interrupted (Ctrl-C).
        InvalidActionError
            Actions that are not ``(num_envs, n_inputs)`` numbers, or a malformed row (nothing changes).
        ClosedEnvironmentError
            The vector environment is closed.
        """
        self._check_open()
        if not self._started.all():
            never = np.flatnonzero(~self._started).tolist()
            raise gymnasium.error.ResetNeeded(
                "Cannot call step() before calling reset()"
                if len(never) == self.num_envs
                else f"environments {never} were never reset (a reset_mask left them out): call reset() for them"
            )
        if self._interrupted:
            raise gymnasium.error.ResetNeeded(
                "the last step() was interrupted, leaving the environments at different steps: call reset()"
            )
        shape = self.action_space.shape
        checker = self.runners[0]
        try:
            rows = np.asarray(actions)
            if rows.shape != shape:
                raise InputError(f"actions must have shape {shape} (one row per environment), got {rows.shape}")
            if rows.dtype.kind == "f":
                rows = rows.astype(np.float64)  # real numbers: the rows' check then takes them at once
            volts = checker.volts_rows(rows, self.normalised)
        except (InputError, ValueError, TypeError) as exc:
            raise InvalidActionError(str(exc).splitlines()[0]) from None
        s = self._slots
        s.actions[:] = volts
        diverged = self._exchange([STEP] * len(self._workers), self._share.step)
        infos = self._step_infos(diverged)
        np.logical_or(s.terminated, s.truncated, out=s.autoreset)
        return (
            s.observations.astype(self._dtype),
            s.rewards.copy(),
            s.terminated.copy(),
            s.truncated.copy(),
            infos,
        )

    def _exchange(self, messages: list[bytes], local: Any) -> dict[int, str]:
        """Send each worker its message, run ``local()`` (this process's share), and gather every reply (the
        diverged environments' messages); an error is raised once every share has finished."""
        self._interrupted = True  # until every share has finished
        replies: dict[int, str] = {}
        try:
            for worker in self._workers:
                if worker.unread:  # a reply left by an interrupted call
                    worker.receive()
            try:
                for worker, message in zip(self._workers, messages):
                    worker.send(message)
                replies.update(local() or {})
            finally:
                for worker in self._workers:
                    if worker.unread:
                        replies.update(worker.receive())
        except WorkerError as exc:  # a worker failed or ended: its environments are lost, so are the others'
            self.close()
            raise WorkerError(f"{exc}; the vector environment is closed") from None
        self._interrupted = False
        return replies

    @property
    def processes(self) -> list[int]:
        """The process ids of the worker processes (this process, which steps the first share, not included)."""
        return [worker.process.pid for worker in self._workers if worker.process.pid is not None]

    def _check_open(self) -> None:
        if self.closed:
            raise ClosedEnvironmentError("this vector environment is closed")

    def _stop_workers(self) -> None:
        for worker in self.__dict__.get("_workers", []):  # none where the constructor failed early
            worker.stop()
        self._workers = []

    def close_extras(self, **kwargs: Any) -> None:
        """Stop the worker processes."""
        self._stop_workers()

    def __enter__(self) -> TwinVectorEnv:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        if "_workers" in self.__dict__ and not self.closed:
            self.close()
