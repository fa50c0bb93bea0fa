"""Many closed loops of the twin at once: stacked controllers, one ``mujoco.rollout`` per control interval.

B twins (each with its own physical parameters, seed, gusts and pushes) and B controllers
advance together. Per control interval ``k``:

1. the stacked controller (:mod:`trms.batch.controllers`) computes every loop's input from
   its (prefiltered) reference and measurement in one vectorised update;
2. each twin turns its input into rotor controls with its own thrust curves and saturation,
   and its gust and push torques into ``qfrc_applied`` for every physics step of the interval
   (:meth:`trms.twin.Twin.interval_controls`, the code :meth:`~trms.twin.Twin.step` runs);
3. one call of a persistent :class:`mujoco.rollout.Rollout` thread pool advances all B
   models ``nsub`` physics steps from their full-physics states (actuator activations and,
   when the model has them, delay buffers included);
4. each twin takes its new state back and measures it with its own encoder
   (:meth:`~trms.twin.Twin.finish_interval`).

Each twin's random streams (noise, gusts) are its own, and rollout steps a model exactly as
``mj_step`` does, so every Record is bit-identical to :func:`trms.control.loop.closed_loop`
on that twin alone. One limit: the constraint solver's warm start is not part of a MuJoCo
state, so at an interval that starts with the beam on a mechanical stop the two agree to
solver tolerance instead of to the bit (such a run has failed: it hit the stops).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
from mujoco import rollout

from trms.batch.controllers import StackedDiagonal, StackedLoops, StackedLQG, stack_controllers
from trms.control.loop import Controller, check_loop_sample_time, loop_metadata, loop_record, prepare_reference
from trms.control.shaping.filters import Prefilter
from trms.errors import DivergenceError, InputError
from trms.plant import history_record
from trms.record import Record, RowBuffer
from trms.twin import Twin

__all__ = ["BatchResult", "PreparedBatch", "assemble_records", "batch_closed_loop", "prepare_batch"]

_FULL = mujoco.mjtState.mjSTATE_FULLPHYSICS
#: What rollout takes per physics step: the rotor controls and the generalised applied forces.
CONTROL_SPEC = mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_QFRC_APPLIED


@dataclass
class BatchResult:
    """The outcome of every loop of a batch.

    Attributes
    ----------
    records : list of Record or None
        One per loop, as :func:`~trms.control.loop.closed_loop` returns it; None where it diverged.
    errors : list of DivergenceError or None
        Why a loop stopped (None where it ran to the end).
    """

    records: list[Record | None]
    errors: list[DivergenceError | None]


def _cores() -> int:
    """Cores this process may run on (its CPU affinity where the system has one)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def _estimate(stacked: StackedLQG | StackedDiagonal | StackedLoops) -> np.ndarray | None:
    """The stacked controllers' state estimates ``(B, n)``, or None when they have none (as closed_loop records)."""
    return None if isinstance(stacked, StackedDiagonal) else stacked.estimate


def _per_loop(value: object, n: int, what: str) -> list:
    if isinstance(value, (list, tuple)):
        if len(value) != n:
            raise InputError(f"{what}: need one per loop ({n}), got {len(value)}")
        return list(value)
    return [value] * n


@dataclass
class PreparedBatch:
    """A checked batch: the loops' parts, one per loop, and the stacked controller (reset)."""

    twins: list[Twin]
    controllers: list[Controller]
    prefilters: list[Prefilter | None]
    seeds: list[int | None]
    metadata: list[Mapping[str, Any] | None]
    references: list[tuple[np.ndarray, np.ndarray]]
    shaped: np.ndarray
    stacked: StackedLQG | StackedDiagonal | StackedLoops


def prepare_batch(
    twins: Sequence[Twin],
    controllers: Sequence[Controller],
    reference: object,
    prefilters: object = None,
    seeds: Sequence[int | None] | None = None,
    metadata: object = None,
) -> PreparedBatch:
    """Check a batch's parts (see :func:`batch_closed_loop`) and stack its controllers; reset the controllers.

    Raises
    ------
    InputError, ConfigurationError
    """
    twins = list(twins)
    if not twins:
        raise InputError("batch_closed_loop needs at least one twin")
    n_loops = len(twins)
    ctrls = _per_loop(list(controllers), n_loops, "controllers")
    first = twins[0]
    for t in twins:
        if not isinstance(t, Twin):
            raise InputError(f"batch_closed_loop runs Twin plants, got {type(t).__name__}")
        if t.configuration != first.configuration or t.sample_time != first.sample_time:
            raise InputError("all twins of a batch must share one configuration and sample time")
    refs = reference if isinstance(reference, (list, tuple)) else None
    refs = _per_loop(reference if refs is not None else [reference] * n_loops, n_loops, "reference")
    pfs = _per_loop(
        prefilters if isinstance(prefilters, (list, tuple)) else [prefilters] * n_loops, n_loops, "prefilters"
    )
    seeds_ = _per_loop(list(seeds) if seeds is not None else [None] * n_loops, n_loops, "seeds")
    metas = _per_loop(metadata if isinstance(metadata, (list, tuple)) else [metadata] * n_loops, n_loops, "metadata")
    for t, c, p in zip(twins, ctrls, pfs):
        check_loop_sample_time("controller", c.sample_time, t)
        if p is not None:
            check_loop_sample_time("prefilter", p.sample_time, t)
    prepared = [prepare_reference(c, r, p) for c, r, p in zip(ctrls, refs, pfs)]
    if any(r.shape != prepared[0][0].shape for r, _ in prepared):
        raise InputError("every loop's reference must have the same shape")
    shaped = np.stack([s for _, s in prepared])

    stacked = stack_controllers(ctrls)
    stacked.reset()
    for c in ctrls:
        c.reset()
    return PreparedBatch(twins, ctrls, pfs, seeds_, metas, prepared, shaped, stacked)


def batch_closed_loop(
    twins: Sequence[Twin],
    controllers: Sequence[Controller],
    reference: object,
    prefilters: Prefilter | Sequence[Prefilter | None] | None = None,
    seeds: Sequence[int | None] | None = None,
    metadata: Mapping[str, Any] | Sequence[Mapping[str, Any]] | None = None,
    threads: int | None = None,
) -> BatchResult:
    """Run ``twins[b]`` under ``controllers[b]`` for every ``b`` at once (see the module docstring).

    Parameters
    ----------
    twins : sequence of Twin
        One configuration, one sample time; parameters, seeds, gusts and pushes may differ.
    controllers : sequence of Controller
        One per twin (:func:`~trms.batch.controllers.stack_controllers`): all
        :class:`~trms.control.lqg.LQGController` or all :class:`~trms.control.loop.DiagonalController`
        (vectorised), or any controllers, one object per twin, each updated on its own.
    reference : array_like or list of array_like
        Reference deviations (rad), ``(N,)`` or ``(N, p_t)``: one for all loops, or one per loop
        (same ``N``).
    prefilters : Prefilter or sequence, optional
        Command prefilter (CSAS) of all loops or of each loop.
    seeds : sequence of int, optional
        Reset seed of each twin (default: each twin's own).
    metadata : mapping or sequence of mappings, optional
        Merged into every Record's (or each Record's) metadata.
    threads : int, optional
        Rollout threads (default: the machine's cores, at most B).

    Returns
    -------
    BatchResult

    Raises
    ------
    InputError, ConfigurationError
        Mixed configurations or sample times, mismatched sizes, a bad reference.

    Examples
    --------
    >>> from trms.control.lqg import LQGController, design_lqg
    >>> from trms.worlds import design_model
    >>> twins = [Twin("1dof", 0.2, seed=s) for s in (0, 1)]
    >>> ctrl = [LQGController(design_lqg(design_model("1dof"), R=75.0)) for _ in twins]
    >>> res = batch_closed_loop(twins, ctrl, np.full(20, 0.1), threads=1)
    >>> [r.outputs.shape for r in res.records]
    [(20, 1), (20, 1)]
    """
    batch = prepare_batch(twins, controllers, reference, prefilters, seeds, metadata)
    twins, seeds_, shaped = batch.twins, batch.seeds, batch.shaped
    n_loops, n, first = len(twins), shaped.shape[1], twins[0]
    stacked = batch.stacked

    y = np.stack([t.reset(s) for t, s in zip(twins, seeds_)])
    y_trim = np.stack([t.operating_point.outputs for t in twins])
    u_trim = np.stack([t.operating_point.inputs for t in twins])
    m_in, p_out = u_trim.shape[1], y_trim.shape[1]
    inputs, applied, control = (np.empty((n_loops, n, m_in)) for _ in range(3))
    outputs = np.empty((n_loops, n, p_out))
    estimate0 = _estimate(stacked)
    estimates = None if estimate0 is None else np.empty((n_loops, n) + estimate0.shape[1:])
    channels = [RowBuffer(n) for _ in twins]
    errors: list[DivergenceError | None] = [None] * n_loops
    alive = np.ones(n_loops, bool)

    model0 = first.model
    nsub = int(round(first.sample_time / model0.opt.timestep))
    nstate = mujoco.mj_stateSize(model0, _FULL)
    nctrl = mujoco.mj_stateSize(model0, CONTROL_SPEC)
    state0 = np.empty((n_loops, nstate))
    warm = np.empty((n_loops, model0.nv))
    ctrl = np.empty((n_loops, nsub, nctrl))
    states = np.empty((n_loops, nsub, nstate))
    nthread = max(1, min(n_loops, threads or _cores()))
    datas = [mujoco.MjData(model0) for _ in range(nthread)]
    models = [t.model for t in twins]

    with rollout.Rollout(nthread=nthread if nthread > 1 else 0) as pool:
        for k in range(n):
            outputs[:, k] = y
            for i in np.flatnonzero(alive).tolist():
                channels[i].put(k, twins[i].channels())
            u = stacked.update(shaped[:, k], y - y_trim)
            control[:, k] = u
            if estimates is not None:
                estimates[:, k] = _estimate(stacked)
            inputs[:, k] = u + u_trim
            live = np.flatnonzero(alive)
            for b in live:
                ctrl[b], state0[b], warm[b] = twins[b].interval_controls(inputs[b, k])
            if live.size == n_loops:
                pool.rollout(
                    models,
                    datas,
                    state0,
                    ctrl,
                    control_spec=CONTROL_SPEC,
                    nstep=nsub,
                    initial_warmstart=warm,
                    state=states,
                    skip_checks=True,
                )
            else:
                sub = np.empty((live.size, nsub, nstate))
                pool.rollout(
                    [models[b] for b in live],
                    datas,
                    state0[live],
                    ctrl[live],
                    control_spec=CONTROL_SPEC,
                    nstep=nsub,
                    initial_warmstart=warm[live],
                    state=sub,
                    skip_checks=True,
                )
                states[live] = sub
            for b in live:
                try:
                    y[b] = twins[b].finish_interval(states[b, -1], state0[b])
                    applied[b, k] = twins[b].applied_input
                except DivergenceError as exc:
                    errors[b] = exc
                    alive[b] = False
            if not alive.any():
                break

    stacked_channels = [ch.arrays() if errors[b] is None else {} for b, ch in enumerate(channels)]
    return assemble_records(batch, inputs, outputs, applied, control, estimates, stacked_channels, errors)


def assemble_records(
    batch: PreparedBatch,
    inputs: np.ndarray,
    outputs: np.ndarray,
    applied: np.ndarray,
    control: np.ndarray,
    estimates: np.ndarray | None,
    channels: Sequence[Mapping[str, np.ndarray]],
    errors: Sequence[DivergenceError | None],
) -> BatchResult:
    """Every loop's Record, as :func:`~trms.control.loop.closed_loop` builds it, from the batch's stacked histories.

    Parameters
    ----------
    batch : PreparedBatch
    inputs, outputs, applied, control : numpy.ndarray
        ``(B, N, .)``: commanded absolute inputs (V), measurements (rad), applied inputs (V),
        commanded deviations (V).
    estimates : numpy.ndarray or None
        ``(B, N, n)`` controller estimates (LQG) or None.
    channels : sequence of mapping
        Each twin's channels stacked over the run.
    errors : sequence of DivergenceError or None
        A loop with an error gets no Record.
    """
    records: list[Record | None] = []
    for b, twin in enumerate(batch.twins):
        if errors[b] is not None:
            records.append(None)
            continue
        plant_record = history_record(
            twin,
            inputs[b],
            outputs[b],
            applied[b],
            channels[b],
            batch.seeds[b],
            loop_metadata(batch.controllers[b], batch.prefilters[b], batch.metadata[b]),
        )
        ref, shaped = batch.references[b]
        records.append(loop_record(plant_record, ref, shaped, control[b], None if estimates is None else estimates[b]))
    return BatchResult(records, list(errors))
