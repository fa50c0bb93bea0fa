"""Starting worker processes: how (forked where that is safe), and with Ctrl-C held back while they start.

The report's workers (:mod:`trms.report.workers`) and the vector environment's (:mod:`trms.envs.vector`) start this
way: forked, a worker starts at once with this process's modules imported (started fresh, each spent 1.7 s of CPU
importing them again); and a terminal's Ctrl-C, which reaches every process of its group, reaches a worker only once
it has set its own answer to it, so the parent alone answers it and stops its workers.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import signal
import sys
import threading
from collections.abc import Iterator

__all__ = ["start_method", "interrupts_held"]


def start_method() -> multiprocessing.context.BaseContext:
    """How the workers start: forked where that is safe, fresh interpreters (spawned) otherwise.

    Forked only on Linux, under Python 3.11 (later versions warn against forking a process with threads, and this
    one's BLAS has its own), while this process runs no other Python thread (a notebook's kernel does) and has drawn
    nothing (a forked child must not inherit a graphics library's state: :func:`trms.twin.render.has_rendered`, read
    from the module if it is loaded, never imported from here).

    Examples
    --------
    >>> start_method().get_start_method() in ("fork", "spawn")
    True
    """
    render = sys.modules.get("trms.twin.render")
    fork = (
        sys.platform.startswith("linux")
        and sys.version_info < (3, 12)
        and threading.active_count() == 1
        and not (render is not None and render.has_rendered())
    )
    return multiprocessing.get_context("fork" if fork else "spawn")


@contextlib.contextmanager
def interrupts_held() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) back for the block, then deliver it: processes started in the block inherit it blocked.

    A worker that a terminal's Ctrl-C reached while it was still starting would print its own traceback beside the
    parent's one-line message; a worker started in the block has it blocked from its first instruction, and keeps it
    so or sets its own answer before it lets it through.

    Examples
    --------
    >>> with interrupts_held():
    ...     signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, set())
    True
    """
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)
