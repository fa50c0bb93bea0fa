"""A vector environment's environments in shares, one share a process, their results in shared memory.

:class:`Slots` lays the rows of every environment (its action, observation, reward, flags and infos) out in one
shared-memory block; :class:`Share` steps and resets some of the environments, each exactly as the single
environment does (:meth:`TaskRunner.step_volts <trms.envs.tasks.TaskRunner.step_volts>` on its own twin), writing
into their rows; :func:`serve` is the loop of a worker process that owns a share; :class:`Worker` is the parent's
handle of one. A message is a byte or a pickled dict; a reply is empty, or the pickled messages of the environments
that diverged, or the text of an error.

Examples
--------
>>> import multiprocessing
>>> from trms.envs.tasks import TaskRunner
>>> slots = Slots(multiprocessing.RawArray("b", Slots.size(2, 1, 1, 4)), 2, 1, 1, 4)
>>> share = Share({0: TaskRunner("PitchTracking"), 1: TaskRunner("PitchTracking")}, slots)
>>> share.reset({0: 3, 1: 4})
>>> slots.actions[:] = share.runners[0].twin.operating_point.inputs
>>> share.step(), slots.kind.tolist(), slots.time.tolist()
({}, [0, 0], [0.2, 0.2])
"""

from __future__ import annotations

import multiprocessing
import os
import pickle
import signal
import time
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from multiprocessing.context import BaseContext
from typing import Any

import numpy as np

from trms.envs.tasks import TaskRunner

__all__ = ["STEPPED", "RESET", "DIVERGED", "Slots", "Share", "Assignment", "Worker", "WorkerError", "serve"]

#: What an environment's last call did (``Slots.kind``): stepped, reset (an autoreset), or diverged.
STEPPED, RESET, DIVERGED = 0, 1, 2
#: The messages to a worker besides a pickled reset: step every environment once, stop.
STEP, QUIT = b"s", b"q"
#: How long a process polls for a message before it sleeps until one comes (s), where every process has a core.
SPIN = 5e-4

#: Each row's fields: name, dtype, and the width from ``(inputs, outputs, observations)`` (None: one value). The
#: 8-byte ones first, so every field starts aligned.
_FIELDS: tuple[tuple[str, type, int | None], ...] = (
    ("actions", np.float64, 0),
    ("observations", np.float64, 2),
    ("rewards", np.float64, None),
    ("applied", np.float64, 0),
    ("true", np.float64, 1),
    ("time", np.float64, None),
    ("reference", np.float64, 1),
    ("autoreset", np.bool_, None),
    ("terminated", np.bool_, None),
    ("truncated", np.bool_, None),
    ("saturated", np.bool_, 0),
    ("kind", np.int8, None),
)


class WorkerError(RuntimeError):
    """A worker process of a vector environment failed (an error in it, or it ended)."""


class Slots:
    """The rows of ``n`` environments in a shared block (``multiprocessing.RawArray`` of :meth:`size` bytes).

    Attributes (arrays, one row per environment): ``actions`` (V), ``autoreset`` (reset instead of stepping),
    ``observations``, ``rewards``, ``terminated``, ``truncated``, ``kind`` (:data:`STEPPED`, :data:`RESET` or
    :data:`DIVERGED`), and the infos ``applied`` (V), ``saturated``, ``true`` (rad), ``time`` (s) and ``reference``
    (rad).
    """

    actions: np.ndarray
    observations: np.ndarray
    rewards: np.ndarray
    applied: np.ndarray
    true: np.ndarray
    time: np.ndarray
    reference: np.ndarray
    autoreset: np.ndarray
    terminated: np.ndarray
    truncated: np.ndarray
    saturated: np.ndarray
    kind: np.ndarray

    def __init__(self, block: Any, n: int, n_inputs: int, n_outputs: int, n_observations: int) -> None:
        offset, widths = 0, (n_inputs, n_outputs, n_observations)
        for name, dtype, width in _FIELDS:
            shape = (n,) if width is None else (n, widths[width])
            count = int(np.prod(shape))
            setattr(self, name, np.frombuffer(block, dtype, count, offset).reshape(shape))
            offset += count * np.dtype(dtype).itemsize

    @staticmethod
    def size(n: int, n_inputs: int, n_outputs: int, n_observations: int) -> int:
        """Bytes of the block for ``n`` environments of ``n_inputs`` inputs, ``n_outputs`` measured angles and
        ``n_observations`` observation entries.

        Examples
        --------
        >>> Slots.size(1, 1, 1, 4)  # 10 numbers of 8 bytes, 5 flags and kinds of 1
        85
        """
        widths = (n_inputs, n_outputs, n_observations)
        return sum(n * (1 if w is None else widths[w]) * np.dtype(t).itemsize for _, t, w in _FIELDS)


class Share:
    """Some environments of a vector environment (``runners``, by index), stepped and reset into their ``slots``."""

    def __init__(self, runners: dict[int, TaskRunner], slots: Slots) -> None:
        self.runners = runners
        self.slots = slots

    def step(self) -> dict[int, str]:
        """Step each environment once as the single environment steps (reset instead where ``autoreset``); return
        the message of each one that diverged."""
        s, diverged = self.slots, {}
        for i, runner in self.runners.items():
            if s.autoreset[i]:
                s.observations[i] = runner.reset()
                s.kind[i], s.rewards[i], s.terminated[i], s.truncated[i] = RESET, 0.0, False, False
                s.reference[i], s.time[i] = runner.current_reference, 0.0
                continue
            obs, s.rewards[i], s.terminated[i], s.truncated[i], info = runner.step_volts(s.actions[i].copy())
            s.observations[i], s.time[i] = obs, info["time"]
            if "diverged" in info:
                s.kind[i] = DIVERGED
                diverged[i] = info["diverged"]
            else:
                s.kind[i], s.applied[i], s.saturated[i], s.true[i] = (
                    STEPPED,
                    info["applied_volts"],
                    info["saturated"],
                    info["true_angles"],
                )
        return diverged

    def reset(self, seeds: dict[int, int | None]) -> None:
        """Start an episode in each environment of ``seeds`` (its seed, or None for its next one)."""
        s = self.slots
        for i, seed in seeds.items():
            s.observations[i] = self.runners[i].reset(seed)
            s.kind[i], s.reference[i], s.time[i] = RESET, self.runners[i].current_reference, 0.0


def receive(conn: Connection, gone: Any = None, spin: float = SPIN) -> bytes:
    """The next message on ``conn``: polled for up to ``spin`` s, the processor yielded to any other process that
    waits for it between polls (a process that sleeps in a read wakes tens of microseconds after the message, a tenth
    of a step), then waited for.

    Raises
    ------
    EOFError
        The other end is closed, or ``gone`` (a process sentinel, e.g. the parent's) is ready first.

    Examples
    --------
    >>> here, there = multiprocessing.Pipe()
    >>> there.send_bytes(STEP)
    >>> receive(here) == STEP
    True
    """
    if spin > 0.0 and not conn.poll(0.0):
        deadline = time.perf_counter() + spin
        while not conn.poll(0.0) and time.perf_counter() < deadline:
            os.sched_yield()
    if gone is not None and conn not in wait([conn, gone]):
        raise EOFError("the other process ended")
    return conn.recv_bytes()


@dataclass(frozen=True)
class Assignment:
    """What a worker process serves: the environments ``indices`` of ``task``, whose rows lie in the shared ``block``
    of :class:`Slots` ``dims`` (``n``, inputs, outputs, observations), each end polling ``spin`` s for a message
    (:func:`receive`) before it sleeps."""

    task: str
    indices: list[int]
    block: Any
    dims: tuple[int, int, int, int]
    spin: float = SPIN


def serve(conn: Connection, parent_end: Connection, assignment: Assignment) -> None:
    """A worker process's loop: build the share of ``assignment``, then step it or reset it at each message on
    ``conn`` until :data:`QUIT` or the parent is gone, however it ended (``parent_end``: the parent's end of the pipe,
    closed here where a fork inherited it). Ctrl-C is left to the parent, which stops its workers."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):  # started with it held back (trms.processes.interrupts_held)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    parent_end.close()
    parent = multiprocessing.parent_process()
    gone = parent.sentinel if parent is not None else None
    try:
        a = assignment
        share = Share({i: TaskRunner(a.task) for i in a.indices}, Slots(a.block, *a.dims))
    except Exception as exc:  # reported to the parent, which raises it
        conn.send_bytes(pickle.dumps(f"{type(exc).__name__}: {exc}"))
        return
    conn.send_bytes(b"")
    while True:
        try:
            message = receive(conn, gone, assignment.spin)
        except (EOFError, ConnectionError):  # the parent is gone
            return
        if message == QUIT:
            return
        try:
            if message == STEP:
                diverged = share.step()
                conn.send_bytes(pickle.dumps(diverged) if diverged else b"")
            else:
                share.reset(pickle.loads(message))
                conn.send_bytes(b"")
        except Exception as exc:
            conn.send_bytes(pickle.dumps(f"{type(exc).__name__}: {exc}"))


class Worker:
    """The parent's handle of one worker process serving ``assignment`` (started here; its first reply says it is
    ready)."""

    def __init__(self, context: BaseContext, assignment: Assignment) -> None:
        self.assignment = assignment
        self.indices = assignment.indices
        self.method = context.get_start_method()
        self.conn, child = context.Pipe()
        self.process = context.Process(  # type: ignore[attr-defined]
            target=serve,
            args=(child, self.conn, assignment),
            daemon=True,
            name=f"trms-vector-{assignment.indices[0]}",
        )
        self.process.start()
        child.close()
        self.unread = True  # the ready reply
        self.ready = False

    def send(self, message: bytes) -> None:
        """Send ``message`` (its reply is read by :meth:`receive`).

        Raises
        ------
        WorkerError
            The worker has ended.
        """
        try:
            self.conn.send_bytes(message)
        except (ConnectionError, EOFError):
            raise self._ended() from None
        self.unread = True

    def _ended(self) -> WorkerError:
        self.process.join(timeout=1.0)
        hint = ""
        if not self.ready and self.method != "fork":
            hint = (
                f" before it was ready; a {self.method}ed worker imports the main script again: build the vector "
                'environment under if __name__ == "__main__":'
            )
        return WorkerError(
            f"the worker process of environments {self.indices} ended (exit code {self.process.exitcode}){hint}"
        )

    def receive(self) -> dict[int, str]:
        """The reply to the last message: the messages of the environments that diverged.

        Raises
        ------
        WorkerError
            The worker reported an error, or ended.
        """
        try:
            data = receive(self.conn, self.process.sentinel, self.assignment.spin)
        except (EOFError, ConnectionError):
            self.unread = False
            raise self._ended() from None
        self.unread = False
        self.ready = True
        reply = pickle.loads(data) if data else {}
        if isinstance(reply, str):
            raise WorkerError(f"environments {self.indices}: {reply}")
        return reply

    def stop(self) -> None:
        """Ask the worker to stop (once any reply still due is read, a second at most), then end it if it has not
        within a second: terminated, then killed."""
        try:
            if self.unread and self.conn.poll(1.0):
                self.receive()
            if not self.unread:
                self.conn.send_bytes(QUIT)
        except (WorkerError, ConnectionError, EOFError):
            pass
        for end in (None, self.process.terminate, self.process.kill):
            if end is not None:
                end()
            self.process.join(timeout=1.0)
            if not self.process.is_alive():
                break
        self.conn.close()
