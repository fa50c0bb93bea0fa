"""Starting worker processes: forked only where that is safe, Ctrl-C held back while they start."""

import signal
import sys
import threading

import pytest

from trms import processes
from trms.twin import render


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="no signal masks on this platform")
def test_interrupts_are_held_in_the_block_only():
    with processes.interrupts_held():
        assert signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, set())
    assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, set())


@pytest.mark.skipif(
    not sys.platform.startswith("linux") or sys.version_info >= (3, 12), reason="forked on Linux before 3.12 only"
)
def test_a_process_that_drew_or_runs_another_thread_spawns(monkeypatch):
    monkeypatch.setattr(render, "_CONTEXTS", {"created": False})
    with monkeypatch.context() as alone:  # as if no other test had left a thread running in this process
        alone.setattr(processes.threading, "active_count", lambda: 1)
        assert processes.start_method().get_start_method() == "fork"
        monkeypatch.setattr(render, "_CONTEXTS", {"created": True})  # an OpenGL context was created here
        assert processes.start_method().get_start_method() == "spawn"
    monkeypatch.setattr(render, "_CONTEXTS", {"created": False})
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    try:
        assert processes.start_method().get_start_method() == "spawn"
    finally:
        stop.set()
        other.join()
