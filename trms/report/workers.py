"""The report's worker processes: a standard :class:`concurrent.futures.ProcessPoolExecutor`, used through its public
API only, with the settings the report's jobs need and a stop that never leaves the command waiting.

* Start: forked where that is safe (:func:`trms.processes.start_method`), each worker's BLAS held to one thread
  unless the user set a thread count (:func:`blas_threads`), Ctrl-C held back while the workers start
  (:func:`trms.processes.interrupts_held`) so that the parent alone answers it.
* Results: each job's outcome (its record, or the exception it raised) is written by the worker to a file of a
  private folder, and only that file's name crosses the executor's result pipe (:func:`run_to_file`). A message that
  short is written to the pipe in one system call, so a worker stopped at any moment never leaves half a message
  there, on which the executor's own thread would wait for ever and keep the command from exiting.
* Stop (:meth:`ReportPool.stop`): the queued jobs cancelled (``shutdown(wait=False, cancel_futures=True)``), then
  the workers (each wrote its process id into the pool's folder as it started) and their own children terminated
  (:mod:`psutil`), any still there 5 s later killed.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import tempfile
import traceback
from collections.abc import Callable, Iterator, Mapping
from concurrent.futures import Future, ProcessPoolExecutor
from pathlib import Path
from typing import Any

import psutil  # type: ignore[import-untyped]
from threadpoolctl import threadpool_limits

from trms.processes import start_method

__all__ = [
    "ONE_THREAD",
    "WorkerTraceback",
    "blas_threads",
    "environment",
    "run_to_file",
    "read_outcome",
    "ReportPool",
]

#: Thread counts of the numerical libraries in the report's worker processes (a variable the user set is kept).
ONE_THREAD = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


class WorkerTraceback(Exception):
    """The traceback of an exception a job raised in a worker, as text (the cause of the exception re-raised here)."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


def blas_threads() -> int | None:
    """BLAS threads per process while the report's workers run: one, or ``None`` (left as the libraries set them)
    when the user set ``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS`` or ``MKL_NUM_THREADS``.

    n workers of a multi-threaded BLAS on n cores oversubscribe them; a forked worker inherits this process's
    thread count, and the quick report ran 32.6 s that way against 25.4 s with one thread a worker. This process
    builds sections meanwhile, so it is held to the same count. A user's setting is the libraries' to read (each
    reads its own variable before ``OMP_NUM_THREADS``): it is kept, never replaced by one number for all.

    Examples
    --------
    >>> blas_threads() in (1, None)
    True
    """
    return None if any(os.environ.get(name) for name in ONE_THREAD) else 1


@contextlib.contextmanager
def environment(values: Mapping[str, str]) -> Iterator[None]:
    """Set the environment variables ``values`` that are not set already, for the block; then restore them.

    Examples
    --------
    >>> with environment({"TRMS_EXAMPLE_VARIABLE": "1"}):
    ...     os.environ["TRMS_EXAMPLE_VARIABLE"]
    '1'
    >>> "TRMS_EXAMPLE_VARIABLE" in os.environ
    False
    """
    added = {k: v for k, v in values.items() if k not in os.environ}
    os.environ.update(added)
    try:
        yield
    finally:
        for k in added:
            os.environ.pop(k, None)


def _start_worker(folder: str, threads: int | None) -> None:
    """A worker's start: its process id written into the pool's folder, its BLAS held to ``threads``."""
    Path(folder, f"{os.getpid()}.pid").touch()
    threadpool_limits(threads)


def run_to_file(folder: str, index: int, run: Callable[..., Any], args: tuple) -> str:
    """Run ``run(*args)`` and write its outcome, ``(True, result)`` or ``(False, (exception, traceback text))``, to
    a file of ``folder`` (written under another name, then renamed: a stopped worker leaves no partial file under
    the one returned); return that file's path, the only thing sent back through the pool.

    Examples
    --------
    >>> with tempfile.TemporaryDirectory() as d:
    ...     read_outcome(run_to_file(d, 0, divmod, (7, 2)))
    (3, 1)
    """
    path = os.path.join(folder, f"{index}.outcome")
    try:
        outcome: tuple[bool, Any] = (True, run(*args))
    except Exception as exc:  # a failed job: the parent re-raises it, with this traceback as its cause
        outcome = (False, (exc, traceback.format_exc()))
    with open(path + ".part", "wb") as f:
        pickle.dump(outcome, f, protocol=pickle.HIGHEST_PROTOCOL)
    os.replace(path + ".part", path)
    return path


def read_outcome(path: str) -> Any:
    """The result a worker wrote (:func:`run_to_file`), or the exception its job raised, raised here; the file is
    removed.

    Raises
    ------
    Exception
        The job's own, caused by a :class:`WorkerTraceback` holding the worker's traceback.
    """
    with open(path, "rb") as f:
        ok, value = pickle.load(f)  # a file this process's own worker wrote into its private folder
    os.remove(path)
    if ok:
        return value
    exc, text = value
    raise exc from WorkerTraceback(text)


class ReportPool:
    """A process pool whose jobs send their outcomes back through files (module docstring).

    Parameters
    ----------
    workers : int
        Worker processes.

    Examples
    --------
    >>> with ReportPool(1) as pool:
    ...     pool.result(pool.submit(divmod, 7, 2))
    (3, 1)
    """

    def __init__(self, workers: int) -> None:
        self.folder = tempfile.mkdtemp(prefix="trms-report-")
        self._count = 0
        start = (self.folder, blas_threads())
        self.executor = ProcessPoolExecutor(
            max_workers=workers, mp_context=start_method(), initializer=_start_worker, initargs=start
        )

    def submit(self, run: Callable[..., Any], *args: Any) -> Future[str]:
        """Start ``run(*args)`` in a worker; the future's result is the file holding its outcome."""
        self._count += 1
        return self.executor.submit(run_to_file, self.folder, self._count, run, args)

    @staticmethod
    def result(future: Future[str]) -> Any:
        """The job's result (or its exception, raised here) once ``future`` is done."""
        return read_outcome(future.result())

    def worker_ids(self) -> list[int]:
        """Process ids of the workers started so far."""
        return sorted(int(p.stem) for p in Path(self.folder).glob("*.pid"))

    def stop(self, grace: float = 5.0) -> None:
        """Cancel the queued jobs and terminate the workers and their own children now; a process still there
        ``grace`` s later is killed, so that nothing is left holding the command's output or its exit."""
        self.executor.shutdown(wait=False, cancel_futures=True)
        workers, children = [], []
        for pid in self.worker_ids():
            with contextlib.suppress(psutil.Error):
                worker = psutil.Process(pid)
                children += worker.children(recursive=True)
                workers.append(worker)
        procs = workers + children  # the workers first: a job whose child ended first could still finish
        for proc in procs:
            with contextlib.suppress(psutil.Error):
                proc.terminate()
        _, alive = psutil.wait_procs(procs, timeout=grace)
        for proc in alive:
            with contextlib.suppress(psutil.Error):
                proc.kill()
        psutil.wait_procs(alive, timeout=grace)

    def close(self) -> None:
        """Wait for the workers to exit and remove the pool's folder."""
        self.executor.shutdown()
        for p in Path(self.folder).iterdir():
            p.unlink()
        os.rmdir(self.folder)

    def __enter__(self) -> ReportPool:
        return self

    def __exit__(self, kind: object, *_: object) -> None:
        if kind is not None:
            self.stop()
        self.close()
