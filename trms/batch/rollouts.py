"""Open-loop runs of many twins at once, side by side on threads, each one native rollout of its whole record.

Each twin of a batch may carry different physical parameters (a calibration's candidates, a Monte Carlo spread) but
all must share one configuration. Each runs as :meth:`trms.twin.Twin.run` runs it (:meth:`Twin.open_loop
<trms.twin.Twin.open_loop>`: its disturbances and noise drawn beforehand, ``mujoco.rollout`` over the record, the GIL
released while MuJoCo steps), keeping only the measurements, so a batch run reproduces ``Twin.run`` bit for bit; while
one thread steps a twin natively, another prepares or reads out the next.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from trms.errors import InputError, as_finite_array
from trms.plant import simulate
from trms.twin.twin import Twin

__all__ = ["run_open_loop_batch"]


def run_open_loop_batch(twins: Sequence[Twin], inputs: np.ndarray, threads: int | None = None) -> np.ndarray:
    """Run every twin from its hover trim under its own input sequence; return the encoder angles.

    Parameters
    ----------
    twins : sequence of Twin
        Same configuration and sample time; each runs with its own gusts and pushes, as
        :meth:`Twin.run` does.
    inputs : numpy.ndarray
        Absolute voltages (V), shape ``(n_twins, N, n_inputs)`` or ``(N, n_inputs)`` for all.
    threads : int, optional
        Worker threads (default: the machine's cores, at most the batch size).

    Returns
    -------
    numpy.ndarray
        Measured angles (rad), shape ``(n_twins, N, n_outputs)``; row k is the sample at
        ``t_k`` (before ``u_k`` acts), as in a :class:`~trms.record.Record`.

    Raises
    ------
    DivergenceError
        A non-finite state, or MuJoCo's BADQACC/BADQPOS/BADQVEL warning, in any twin of the batch.
    SimulationError
        Any other MuJoCo warning during the batch (every counter of ``data.warning`` of every
        worker is checked after the batch).
    """
    if not twins:
        raise InputError("run_open_loop_batch needs at least one twin")
    first = twins[0]
    for t in twins:
        if t.configuration != first.configuration or t.sample_time != first.sample_time:
            raise InputError("all twins of a batch must share one configuration and sample time")
    n_in = len(first.input_names)
    u = np.asarray(inputs, dtype=float)
    if u.ndim == 2:
        u = np.broadcast_to(u, (len(twins),) + u.shape)
    u = as_finite_array("inputs (V)", u, (len(twins), None, n_in))
    nthread = min(len(twins), threads or os.cpu_count() or 1)
    # Each twin runs as its Twin.run does (native rollouts, the GIL released inside) but records only the
    # measurements, not every sample's channels; threads run twins side by side.
    with ThreadPoolExecutor(max_workers=nthread) as pool:
        runs = pool.map(lambda b: simulate(twins[b], u[b], twins[b].seed, channels=False), range(len(twins)))
        return np.stack([r.outputs for r in runs])
