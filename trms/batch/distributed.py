"""Samples as tasks on a ``dask.distributed`` cluster: Monte Carlo, parameter sweeps, calibration candidates.

The work is a function of a chunk of sample indices, ``task(indices, *args) -> list`` (one
result per index). The chunks are submitted to a cluster: the one at ``scheduler``
(``tcp://host:8786``, any number of machines), or a :class:`dask.distributed.LocalCluster`
of ``workers`` workers started here. Every sample draws its random numbers from its own
:func:`sample_seed` (``numpy.random.SeedSequence`` of the study's seed and the sample's
index), never from a stream shared with other samples, so the results are identical
however the work is split: any chunk size, any number of workers, any machine.
"""

from __future__ import annotations

import logging
import sys
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from trms.errors import ConfigurationError, check_in_range

__all__ = ["sample_seed", "chunk_indices", "map_samples", "map_items"]

#: Samples per task unless told otherwise: enough to batch the physics, small enough to spread.
DEFAULT_CHUNK = 16


def sample_seed(seed: int, index: int) -> np.random.SeedSequence:
    """The seed sequence of sample ``index`` of a study seeded with ``seed``.

    Equal to ``numpy.random.SeedSequence(seed).spawn(n)[index]`` for any ``n > index``, and
    independent of every other sample's.

    Examples
    --------
    >>> a = sample_seed(7, 3).generate_state(2)
    >>> b = np.random.SeedSequence(7).spawn(5)[3].generate_state(2)
    >>> bool((a == b).all())
    True
    """
    return np.random.SeedSequence(entropy=int(seed), spawn_key=(int(index),))


def chunk_indices(n: int, chunk_size: int = DEFAULT_CHUNK) -> list[list[int]]:
    """Sample indices ``0 .. n - 1`` in consecutive chunks of at most ``chunk_size``.

    Examples
    --------
    >>> chunk_indices(5, 2)
    [[0, 1], [2, 3], [4]]
    """
    size = int(check_in_range("chunk_size", chunk_size, 1, 1e9))
    return [list(range(i, min(i + size, int(n)))) for i in range(0, int(n), size)]


def _client(workers: int | None, scheduler: str | None, processes: bool) -> tuple[Any, Any]:
    from dask.distributed import Client, LocalCluster

    if scheduler is not None and workers is not None:
        raise ConfigurationError("give either workers (a local cluster) or scheduler (an existing cluster), not both")
    if scheduler is not None:
        if not str(scheduler).startswith(("tcp://", "tls://", "inproc://", "ucx://")):
            raise ConfigurationError(f"scheduler = {scheduler!r} must be an address such as tcp://host:8786")
        return Client(scheduler), None
    n = int(check_in_range("workers", 1 if workers is None else workers, 1, 1024))
    # silence_logs: the workers log only errors (a cancelled task on Ctrl-C is no news to the user)
    cluster = LocalCluster(
        n_workers=n, threads_per_worker=1, processes=processes, dashboard_address=None, silence_logs=logging.ERROR
    )
    return Client(cluster), cluster


def map_samples(
    task: Callable[..., list],
    n: int,
    args: Sequence[object] = (),
    *,
    chunk_size: int = DEFAULT_CHUNK,
    workers: int | None = None,
    scheduler: str | None = None,
    processes: bool = True,
    progress: bool | None = None,
    label: str = "samples",
) -> list:
    """Run ``task(indices, *args)`` on every chunk of ``range(n)`` as Dask tasks; results in index order.

    Parameters
    ----------
    task : callable
        ``task(indices, *args) -> list`` with one result per index; importable (workers pickle it).
    n : int
        Number of samples.
    args : sequence
        Further arguments of every call.
    chunk_size : int
        Samples per task.
    workers : int, optional
        Workers of the local cluster (default 1); not with ``scheduler``.
    scheduler : str, optional
        Address of a running ``dask.distributed`` scheduler, e.g. ``tcp://host:8786``.
    processes : bool
        Local cluster of worker processes (default) or of threads in this process.
    progress : bool, optional
        Progress bar on stderr (default: only when stderr is a terminal).
    label : str
        What the progress bar counts.

    Returns
    -------
    list
        ``n`` results, sample 0 first.

    Raises
    ------
    ConfigurationError
        Both ``workers`` and ``scheduler``, or a scheduler that is not an address.

    Examples
    --------
    >>> from trms.batch.distributed import map_samples
    >>> map_samples(_squares, 5, chunk_size=2, processes=False, progress=False)
    [0, 1, 4, 9, 16]
    """
    count = int(check_in_range("n", n, 0, 1e9))
    chunks = chunk_indices(count, chunk_size)
    return _run(
        [(task, (c, *args)) for c in chunks], [len(c) for c in chunks], workers, scheduler, processes, progress, label
    )


def _run(
    calls: list[tuple[Callable[..., list], tuple]],
    sizes: list[int],
    workers: int | None,
    scheduler: str | None,
    processes: bool,
    progress: bool | None,
    label: str,
) -> list:
    """Submit every ``(function, args)`` call as a task; the concatenated results, in call order."""
    from dask.distributed import as_completed
    from tqdm import tqdm

    client, cluster = _client(workers, scheduler, processes)
    show = sys.stderr.isatty() if progress is None else bool(progress)
    try:
        futures = [client.submit(fn, *args, pure=False) for fn, args in calls]
        size = {f.key: k for f, k in zip(futures, sizes)}
        with tqdm(total=sum(sizes), unit=label, disable=not show, file=sys.stderr) as bar:
            for fut in as_completed(futures):
                bar.update(size[fut.key])
        results = client.gather(futures)
    except BaseException:  # Ctrl-C or a failed task: the cluster's own teardown warnings would bury the one line
        logging.getLogger("distributed").setLevel(logging.CRITICAL)
        raise
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    out = [r for chunk in results for r in chunk]
    if len(out) != sum(sizes):
        raise ConfigurationError(
            f"the tasks returned {len(out)} results for {sum(sizes)} samples; one per index is needed"
        )
    return out


def _apply(indices: Sequence[int], fn: Callable[[Any], Any], items: Sequence[Any], offset: int) -> list:
    """Apply ``fn`` to the chunk's items (``items`` holds only this chunk's, from ``offset``)."""
    return [fn(items[i - offset]) for i in indices]


def map_items(
    fn: Callable[[Any], Any],
    items: Sequence[Any],
    *,
    chunk_size: int = DEFAULT_CHUNK,
    workers: int | None = None,
    scheduler: str | None = None,
    processes: bool = True,
    progress: bool | None = None,
    label: str = "items",
) -> list:
    """``[fn(item) for item in items]`` as Dask tasks: parameter sweeps, calibration candidates.

    Each task receives only its chunk of ``items``. Options as :func:`map_samples`; ``fn`` must be
    importable by the workers.

    Examples
    --------
    >>> map_items(abs, [-2, 3, -4], chunk_size=2, processes=False, progress=False)
    [2, 3, 4]
    """
    items = list(items)
    chunks = chunk_indices(len(items), chunk_size)
    calls = [(_apply, (c, fn, items[c[0] : c[-1] + 1], c[0])) for c in chunks]
    return _run(calls, [len(c) for c in chunks], workers, scheduler, processes, progress, label)


def _squares(indices: Sequence[int]) -> list[int]:
    """A task for the examples: each index squared."""
    return [i * i for i in indices]
