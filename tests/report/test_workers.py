"""The report's worker pool: thread counts and environment, interrupts held while workers start, outcomes through
files, and a stop that ends every worker at once and never keeps the command from exiting."""

import os
import subprocess
import sys
import time
from concurrent.futures import wait

import psutil
import pytest

from trms.report import workers as wk


def test_the_workers_blas_threads_are_one_unless_the_user_set_them(monkeypatch):
    for name in wk.ONE_THREAD:
        monkeypatch.delenv(name, raising=False)
    assert wk.blas_threads() == 1
    for name in wk.ONE_THREAD:  # any one of them: left to the libraries, which read their own first
        monkeypatch.setenv(name, "3")
        assert wk.blas_threads() is None
        monkeypatch.delenv(name)


def test_the_environment_is_set_for_the_block_and_a_users_value_kept(monkeypatch):
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "3")
    monkeypatch.delenv("OMP_NUM_THREADS", raising=False)
    with wk.environment(wk.ONE_THREAD):
        assert os.environ["OMP_NUM_THREADS"] == "1" and os.environ["OPENBLAS_NUM_THREADS"] == "3"
    assert "OMP_NUM_THREADS" not in os.environ and os.environ["OPENBLAS_NUM_THREADS"] == "3"


def _fails():
    raise ValueError("the job's own message")


def test_a_jobs_result_and_its_exception_come_back_through_the_file_and_the_folder_goes():
    with wk.ReportPool(2) as pool:
        ok, bad = pool.submit(divmod, 7, 2), pool.submit(_fails)
        assert pool.result(ok) == (3, 1)
        with pytest.raises(ValueError, match="the job's own message") as err:
            pool.result(bad)
        assert isinstance(err.value.__cause__, wk.WorkerTraceback) and "_fails" in str(err.value.__cause__)
        folder = pool.folder
    assert not os.path.exists(folder)


def test_stopping_the_pool_ends_its_workers_and_their_children_now():
    pool = wk.ReportPool(2)
    futures = [pool.submit(subprocess.run, ["sleep", "60"]) for _ in range(3)]  # each worker starts a child
    deadline = time.perf_counter() + 20
    while len(pool.worker_ids()) < 2 or not all(psutil.Process(p).children() for p in pool.worker_ids()):
        assert time.perf_counter() < deadline
        time.sleep(0.05)
    procs = [psutil.Process(p) for p in pool.worker_ids()]
    procs += [c for p in procs for c in p.children()]
    started = time.perf_counter()
    pool.stop()
    assert time.perf_counter() - started < 10 and not [p for p in procs if p.is_running() and p.status() != "zombie"]
    wait(futures, timeout=10)
    assert all(f.cancelled() or f.exception() is not None for f in futures)  # no job ran to its end
    pool.close()


#: A pool whose worker is stopped while it writes a 300 MB record; prints how many samples of its process saw it
#: writing (several: the stop came mid-record), then exits with status 130, as the interrupted command does.
_STOPPED_MID_RECORD = """
import sys, time
import psutil
from trms.report import workers as wk
pool = wk.ReportPool(1)
future = pool.submit(bytes, 300_000_000)
while not pool.worker_ids():
    time.sleep(0.001)
worker = psutil.Process(pool.worker_ids()[0])
writing, start = 0, time.perf_counter()
while writing < 3 and time.perf_counter() - start < 30:
    try:
        writing += worker.io_counters().write_bytes > 0 and worker.status() == psutil.STATUS_RUNNING
    except psutil.Error:
        break
    time.sleep(0.001)
pool.stop()
print(writing)
sys.exit(130)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the worker's I/O counters")
def test_a_worker_stopped_while_writing_its_record_does_not_keep_the_command_from_exiting():
    res = subprocess.run([sys.executable, "-c", _STOPPED_MID_RECORD], capture_output=True, text=True, timeout=60)
    assert res.returncode == 130, res.stderr
    assert int(res.stdout) >= 1  # it was stopped while writing
