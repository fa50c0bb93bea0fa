"""Open-loop runs of many twins at once with ``mujoco.rollout`` (native, multi-threaded).

Each twin of a batch may carry different physical parameters (a calibration's
candidates, a Monte Carlo spread) but all must share one configuration. The voltages
go through each twin's own thrust curves once per control interval (zero-order hold),
exactly as :meth:`trms.twin.Twin.step` does, and the encoder is applied to the sampled
angles, so a batch run reproduces ``Twin.run`` without gusts or pushes bit for bit.
"""

from __future__ import annotations

import os
from typing import Sequence

import mujoco
import numpy as np
from mujoco import rollout

from ..errors import DivergenceError, InputError, SimulationError, as_finite_array
from .twin import _DIVERGENCE_WARNINGS, Twin, raised_warnings

__all__ = ["run_open_loop_batch"]


def run_open_loop_batch(twins: Sequence[Twin], inputs: np.ndarray, threads: int | None = None) -> np.ndarray:
    """Run every twin from its hover trim under its own input sequence; return the encoder angles.

    Parameters
    ----------
    twins : sequence of Twin
        Same configuration and sample time; no gusts or pushes (they are closed-form only
        in :meth:`Twin.step`).
    inputs : numpy.ndarray
        Absolute voltages (V), shape ``(n_twins, N, n_inputs)`` or ``(N, n_inputs)`` for all.
    threads : int, optional
        Worker threads (default: the machine's cores, at most the batch size).

    Returns
    -------
    numpy.ndarray
        Measured angles (rad), shape ``(n_twins, N, n_outputs)``; row k is the sample at
        ``t_k`` (before ``u_k`` acts), as in a :class:`~trms.plant.Record`.

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
        if t.gust.std or t.pushes:
            raise InputError("batch runs do not model gusts or pushes; use Twin.run for those")
    n_in = len(first.input_names)
    u = np.asarray(inputs, dtype=float)
    if u.ndim == 2:
        u = np.broadcast_to(u, (len(twins),) + u.shape)
    u = as_finite_array("inputs (V)", u, (len(twins), None, n_in))
    n = u.shape[1]
    nsub = int(round(first.sample_time / first.model.opt.timestep))

    ctrl = np.empty((len(twins), n, first.model.nu))
    state0 = np.empty((len(twins), mujoco.mj_stateSize(first.model, mujoco.mjtState.mjSTATE_FULLPHYSICS)))
    for b, twin in enumerate(twins):
        lo, hi = twin.input_limits
        volts = np.tile(twin.trim.voltages, (n, 1))
        volts[:, twin.input_rotors] = np.clip(u[b], lo, hi)
        ctrl[b] = np.column_stack([c.thrust(volts[:, i]) for i, c in enumerate(twin.curves)])
        twin.reset()
        mujoco.mj_getState(twin.model, twin.data, state0[b], mujoco.mjtState.mjSTATE_FULLPHYSICS)
    ctrl = np.repeat(ctrl, nsub, axis=1)
    nthread = min(len(twins), threads or os.cpu_count() or 1)
    datas = [mujoco.MjData(first.model) for _ in range(nthread)]
    states, _ = rollout.rollout([t.model for t in twins], datas, state0, ctrl)
    _check_batch(datas, states)
    # State layout of mjSTATE_FULLPHYSICS: time, qpos, qvel, act, ...; keep the angles at each sample.
    qpos = states[:, nsub - 1 :: nsub, 1 : 1 + first.model.nq]
    out = np.empty((len(twins), n, len(first.output_names)))
    for b, twin in enumerate(twins):
        angles = np.concatenate([twin.trim.qpos[None, twin.output_qpos], qpos[b, : n - 1][:, twin.output_qpos]])
        out[b] = twin.encoder.measure(angles, np.random.default_rng(np.random.SeedSequence(twin.seed).spawn(2)[0]))
    return out


def _check_batch(datas: Sequence[mujoco.MjData], states: np.ndarray) -> None:
    """Raise if any worker's MuJoCo warning counter moved or any twin's state is not finite."""
    raised = sorted({w for d in datas for w in raised_warnings(d, np.zeros_like(d.warning.number))})
    bad = [int(b) for b in np.flatnonzero(~np.isfinite(states).all(axis=(1, 2)))]
    if not raised and not bad:
        return
    diverged = bool(bad) or bool(set(raised) & set(_DIVERGENCE_WARNINGS))
    error = DivergenceError if diverged else SimulationError
    raise error(f"batch run {'diverged' if diverged else 'raised MuJoCo warnings'}: warnings "
                f"{', '.join(w.removeprefix('mjWARN_') for w in raised) or 'none'}; twins with a non-finite state: "
                f"{bad or 'none'} (MuJoCo resets a twin whose accelerations blow up, so its samples after that are void)")
