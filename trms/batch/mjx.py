"""The batched closed loop on a GPU: MJX physics, the loop around it in JAX (optional extra ``trms[mjx]``).

Same loops, same Records as :func:`trms.batch.batch_closed_loop`, with the whole horizon one
``jax.jit`` of a ``lax.scan`` over control intervals (each a ``lax.fori_loop`` of ``nsub``
``mjx.step`` calls) and ``jax.vmap`` over the batch. In JAX: the stacked LQG or decentralised
controllers (with clipping and anti-windup), saturation, the rotor controls (thrust curves and spin
speeds, :func:`trms.twin.rotors.rotor_controls`), the transport delay (below), the rotor-wash
turbulence and the gust torques (the Ornstein-Uhlenbeck recursion of :class:`trms.twin.Turbulence`
and :class:`trms.twin.Gust`), pushes, and the encoders' noise and quantisation. The motor lag is the
model's own actuator activation, stepped by MJX.
The random numbers come from each twin's own generators (drawn on the host after
:meth:`~trms.twin.Twin.reset`), so gusts and noise are the same realisations the CPU path uses.

MJX 3.17 steps the ``euler``, ``rk4`` and ``implicitfast`` integrators, not the ``discrete`` one the shipped model
runs at its 5 ms step (which takes the beam's stiff hinges implicitly): an MJX batch runs twins built from
:func:`mjx_spec`, the same model with ``implicitfast`` at 2 ms (explicit in the stiffness, and stable there: the
beam's fastest mode, 107 Hz, at omega dt = 1.35), which meets every one of the thesis's targets by the
verification's rule, two of them (the u1 -> yaw coherence and Table 5.1's residual variance) at 9 of the 10 seeds
where the shipped physics meets them at 10 (``benchmarks/bench_timestep.py --finer 0.002``). MJX runs in float32
(JAX's default), so the runs are close to, not bit-identical with, the CPU path on the same twins;
``tests/batch/test_mjx.py`` bounds the difference. Physical parameters may differ between twins: every model array
that differs is stacked along the batch axis.
MJX 3.17 has no actuator delay (its Model carries no ``actuator_delay``: a delayed actuator
would act at once), so MJX gets a copy of each model without it (:func:`without_delay`) and
the transport delay is applied here, exactly as MuJoCo applies it: at a
physics step that starts at time ``t`` a delayed actuator reads, by zero-order hold, the
control written at the latest earlier physics step whose time is ``<= t - delay`` (the control
of a step is written into the history after the step's forward pass, stamped with the step's
start time). The controls are held over each control interval, so what an actuator reads
inside interval ``k`` is the control of one of two consecutive past intervals, switching at
one physics step: :func:`delay_schedule` finds both, per interval and actuator, on the host
from the same float64 time stamps MuJoCo forms (the sum of the timesteps, rounding included,
so the switch matches the CPU twin to the physics step), and the loop keeps the last intervals'
controls in a ring buffer started, like the twin's delay lines, at the trim controls.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from typing import Any

import mujoco
import numpy as np

from trms.batch.controllers import StackedDiagonal, StackedLoops, StackedLQG
from trms.batch.loop import BatchResult, PreparedBatch, assemble_records, prepare_batch
from trms.control.loop import Controller
from trms.control.shaping.filters import Prefilter
from trms.errors import ConfigurationError, DivergenceError
from trms.twin import Twin

__all__ = ["MJX_TIMESTEP", "mjx_closed_loop", "mjx_spec", "stack_models", "delay_schedule", "without_delay"]

#: The physics step (s) of an MJX batch's twins (:func:`mjx_spec`).
MJX_TIMESTEP = 0.002
#: The integrators MJX 3.17 steps.
_MJX_INTEGRATORS = {
    int(mujoco.mjtIntegrator.mjINT_EULER),
    int(mujoco.mjtIntegrator.mjINT_RK4),
    int(mujoco.mjtIntegrator.mjINT_IMPLICITFAST),
}

#: A joint rate beyond this (rad/s) is taken as a diverging simulation (as in the Twin).
MAX_RATE = 1e3
#: MuJoCo's tolerance on history time stamps (``mjMINVAL``, s).
_MINVAL = 1e-15
#: Model fields every twin of a batch shares by construction (options, statistics, names, layout).
_SHARED = ("opt", "stat", "names", "signature", "_sizes", "_impl")


def _jax() -> tuple[Any, Any, Any]:
    try:
        import jax
        import jax.numpy as jnp
        from mujoco import mjx
    except ImportError as exc:  # the optional extra is not installed
        raise ConfigurationError(
            "the MJX backend needs the optional extra trms[mjx] (mujoco-mjx and jax): pip install 'trms[mjx]'"
        ) from exc
    return jax, jnp, mjx


def stack_models(models: Sequence[mujoco.MjModel]) -> tuple[Any, Any]:
    """One MJX model for a batch of models that differ only in array values (physical parameters).

    The models' actuator delays are left out (:func:`without_delay`): the loop applies them
    (:func:`delay_schedule`).

    Returns
    -------
    model : mujoco.mjx.Model
        The first model on the device, each differing array replaced by its stack ``(B, ...)``.
    in_axes : pytree
        ``jax.vmap`` axes of ``model``: 0 on the stacked arrays, None elsewhere.

    Raises
    ------
    ConfigurationError
        Models with an interpolating actuator delay, or that differ in options or structure.

    Examples
    --------
    >>> from trms.twin import Twin  # doctest: +SKIP
    >>> model, axes = stack_models([Twin("1dof").model] * 2)  # doctest: +SKIP
    """
    models = [without_delay(m) for m in models]
    m0 = models[0]
    for m in models:
        if m.opt.timestep != m0.opt.timestep or m.opt.integrator != m0.opt.integrator or m.nq != m0.nq or m.nv != m0.nv:
            raise ConfigurationError("the models of an MJX batch must share options and structure")
    jax, jnp, mjx = _jax()
    mx = mjx.put_model(m0)
    stacked = {}
    for name in mx.__dataclass_fields__:
        ref = getattr(m0, name, None)
        if name in _SHARED or not isinstance(ref, np.ndarray):
            continue
        values = [getattr(m, name) for m in models]
        if any(not np.array_equal(ref, v) for v in values[1:]):
            current = getattr(mx, name)
            if tuple(current.shape) != ref.shape:
                raise ConfigurationError(f"model field {name} differs between twins but MJX stores it reshaped")
            stacked[name] = jnp.asarray(np.stack(values), dtype=current.dtype)
    in_axes = jax.tree_util.tree_map(lambda _: None, mx).replace(**{k: 0 for k in stacked})
    return mx.replace(**stacked), in_axes


def mjx_spec(spec: mujoco.MjSpec | None = None) -> mujoco.MjSpec:
    """A copy of ``spec`` (default the shipped model) that MJX can step: ``implicitfast`` at :data:`MJX_TIMESTEP`.

    Build an MJX batch's twins from it (``Twin(..., spec=mjx_spec())`` or ``make_plant(..., spec=mjx_spec())``);
    the transport delay's history is sized for the new step when the twin is built.

    Examples
    --------
    >>> s = mjx_spec()
    >>> s.option.timestep, s.option.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    (0.002, True)
    """
    from trms.twin import load_spec

    out = spec.copy() if spec is not None else load_spec()
    out.option.timestep = MJX_TIMESTEP
    out.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    return out


def without_delay(model: mujoco.MjModel) -> mujoco.MjModel:
    """A copy of ``model`` whose actuators act at once (``actuator_delay`` 0), for MJX.

    Raises
    ------
    ConfigurationError
        An integrator MJX does not step (build the twins from :func:`mjx_spec`), or a delayed actuator that
        interpolates its history (only zero-order hold is applied by the MJX loop: the controls are held over
        each control interval).

    Examples
    --------
    >>> from trms.twin import Twin
    >>> float(without_delay(Twin("1dof", 0.1, spec=mjx_spec()).model).actuator_delay.max())
    0.0
    >>> without_delay(Twin("1dof", 0.1).model)
    Traceback (most recent call last):
    trms.errors.ConfigurationError: the model's integrator is discrete, which MJX does not step ...
    """
    integrator = int(model.opt.integrator)
    if integrator not in _MJX_INTEGRATORS:
        name = mujoco.mjtIntegrator(integrator).name.removeprefix("mjINT_").lower()
        raise ConfigurationError(
            f"the model's integrator is {name}, which MJX does not step (allowed: euler, rk4, implicitfast): "
            "build the twins from trms.batch.mjx.mjx_spec()"
        )
    interp = model.actuator_history[:, 1]
    bad = (model.actuator_delay > 0) & (interp != 0)
    if np.any(bad):
        raise ConfigurationError(
            f"the MJX backend applies zero-order-hold actuator delay only (actuator interp = {interp.tolist()}, "
            "allowed 0)"
        )
    out = copy.deepcopy(model)
    out.actuator_delay[:] = 0.0
    return out


def delay_schedule(model: mujoco.MjModel, n: int, nsub: int, t0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Which interval's control each actuator reads at each physics step, under its transport delay.

    The controls are held for ``nsub`` physics steps per control interval from time ``t0``
    (s); MuJoCo's delay (module docstring) makes the actuators read past intervals' controls.
    Inside interval ``k`` actuator ``a`` reads the control of interval ``k - lag[k, a] - 1``
    during its first ``switch[k, a]`` physics steps and that of interval ``k - lag[k, a]``
    after them; a negative interval is before the start (the delay lines hold the trim).

    Parameters
    ----------
    model : mujoco.MjModel
        Actuator delays (s), history sizes and the physics timestep (s) are read.
    n : int
        Control intervals.
    nsub : int
        Physics steps per interval.
    t0 : float
        Time at the start (s): MuJoCo stamps step ``s`` with ``t0`` plus ``s`` timesteps summed
        in float64, and the schedule uses the same stamps.

    Returns
    -------
    lag : numpy.ndarray
        ``(n, nu)`` intervals (int32, >= 0; 0 and no switch for an actuator without delay).
    switch : numpy.ndarray
        ``(n, nu)`` physics steps (int32, ``0 <= switch < nsub``).

    Examples
    --------
    >>> from trms.twin import Twin
    >>> lag, switch = delay_schedule(Twin("1dof", 0.1).model, 20, 100)
    >>> lag.shape, bool((switch < 100).all())
    ((20, 6), True)
    """
    dt = float(model.opt.timestep)
    total = n * nsub
    stamps = np.add.accumulate(np.concatenate([[float(t0)], np.full(total, dt)]))[:total]
    steps = np.arange(total)
    lag = np.zeros((n, model.nu), np.int32)
    switch = np.zeros((n, model.nu), np.int32)
    for a in range(model.nu):
        delay, nsample = float(model.actuator_delay[a]), int(model.actuator_history[a, 0])
        if delay <= 0 or nsample == 0:
            continue
        t = stamps - delay
        # mju_historyRead, zero-order hold: the newest earlier sample stamped < t + mjMINVAL, the newest when
        # t >= its stamp - mjMINVAL, the oldest held sample at most (before the start: the trim, index -1)
        src = np.searchsorted(stamps, t + _MINVAL, side="left") - 1
        src = np.minimum(src, steps - 1)
        newest = np.zeros(total, bool)
        newest[1:] = t[1:] >= stamps[:-1] - _MINVAL
        src = np.where(newest, steps - 1, src)
        src = np.maximum(src, np.where(steps >= nsample, steps - nsample, -1))
        read = np.floor_divide(src, nsub).reshape(n, nsub)  # -1: before the start
        last = read[:, -1]
        if np.any(read < (last - 1)[:, None]):
            raise ConfigurationError(
                f"actuator {a}: a delay of {delay} s spans more than two control intervals "
                f"within one interval of {nsub} steps"
            )
        lag[:, a] = np.arange(n) - last
        switch[:, a] = np.sum(read < last[:, None], axis=1)
    return lag, switch


def _lqg_arrays(s: StackedLQG) -> dict[str, np.ndarray]:
    return {
        "A": s._A,
        "B": s._B,
        "C": s._C,
        "Lc": s._Lc,
        "Kx": s._Kx,
        "Ki": s._Ki,
        "lower": s._lower,
        "upper": s._upper,
    }


def _controller_parts(
    stacked: StackedLQG | StackedDiagonal | StackedLoops,
) -> tuple[list[dict[str, np.ndarray]], list[tuple]]:
    """Per loop: the stacked matrices and (tracked, inject, outputs, inputs, reference slice).

    A MIMO LQG is one loop.
    """
    if isinstance(stacked, StackedLoops):
        raise ConfigurationError("the MJX backend runs LQG controllers (integral or decentralised) only")
    if isinstance(stacked, StackedLQG):
        m = stacked._B.shape[2]
        p = stacked._C.shape[1]
        pt = stacked._tracked.size
        return [_lqg_arrays(stacked)], [
            (tuple(stacked._tracked.tolist()), stacked._inject, tuple(range(p)), tuple(range(m)), (0, pt))
        ]
    arrays, static = [], []
    for j, (c, o, i) in enumerate(zip(stacked.loops, stacked.outputs, stacked.inputs)):
        if not isinstance(c, StackedLQG):
            raise ConfigurationError("the MJX backend runs decentralised loops of LQG controllers only")
        arrays.append(_lqg_arrays(c))
        static.append((tuple(c._tracked.tolist()), c._inject, (o,), (i,), (j, 1)))
    return arrays, static


def _host_inputs(batch: PreparedBatch, n: int) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Reset every twin; gather its start state, limits, curves, disturbances and random draws."""
    twins = batch.twins
    y0 = np.stack([t.reset(s) for t, s in zip(twins, batch.seeds)])
    p_out = y0.shape[1]
    dt = twins[0].model.opt.timestep
    n_push = max(len(t.pushes) for t in twins)
    per: dict[str, list] = {
        k: []
        for k in (
            "qpos",
            "qvel",
            "act",
            "time",
            "ctrl",
            "volts",
            "gust",
            "gust_noise",
            "turb",
            "turb_noise",
            "turb_a",
            "turb_s",
            "enc_noise",
            "res",
            "noise_std",
            "curves",
            "gust_a",
            "gust_s",
            "push_a",
            "push_b",
            "push_tq",
            "u_trim",
            "y_trim",
            "lower",
            "upper",
        )
    }
    for t in twins:
        d = t.data
        per["qpos"].append(d.qpos.copy())
        per["qvel"].append(d.qvel.copy())
        per["act"].append(d.act.copy())
        per["time"].append(float(d.time))
        per["ctrl"].append(d.ctrl.copy())
        per["volts"].append(t._volts.copy())
        per["gust"].append(t._gust_torque.copy())
        per["gust_noise"].append(t._gust_rng.standard_normal((n, 2)) if t.gust.std else np.zeros((n, 2)))
        turb = t.turbulence
        per["turb"].append(t._turbulence.copy())
        per["turb_noise"].append(t._turbulence_rng.standard_normal((n, 2)) if turb.active else np.zeros((n, 2)))
        a_t = float(np.exp(-t.sample_time / turb.time_constant))
        per["turb_a"].append(a_t if turb.active else 0.0)
        per["turb_s"].append(np.asarray(turb.std) * np.sqrt(1.0 - a_t * a_t))
        per["enc_noise"].append(t._noise_rng.standard_normal((n, p_out)) if t.encoder.noisy else np.zeros((n, p_out)))
        per["res"].append(t.encoder.resolution)
        per["noise_std"].append(np.broadcast_to(np.asarray(t.encoder.noise_std, float), (p_out,)))
        per["curves"].append(np.stack([c.to_array() for c in t.curves]))
        a = float(np.exp(-t.sample_time / t.gust.time_constant)) if t.gust.std else 0.0
        per["gust_a"].append(a)
        per["gust_s"].append(t.gust.std * np.sqrt(1.0 - a * a) if t.gust.std else 0.0)
        windows = [p.steps(dt) for p in t.pushes] + [(0, 0)] * (n_push - len(t.pushes))
        per["push_a"].append([w[0] for w in windows])
        per["push_b"].append([w[1] for w in windows])
        per["push_tq"].append([list(p.torque) for p in t.pushes] + [[0.0, 0.0]] * (n_push - len(t.pushes)))
        per["u_trim"].append(t.operating_point.inputs)
        per["y_trim"].append(t.operating_point.outputs)
        per["lower"].append(t.input_limits[0])
        per["upper"].append(t.input_limits[1])
    out = {k: np.asarray(v, dtype=np.int32 if k in ("push_a", "push_b") else float) for k, v in per.items()}
    out["push_tq"] = out["push_tq"].reshape(len(twins), n_push, 2)
    nsub = int(round(twins[0].sample_time / dt))
    schedules: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}
    lags, switches = [], []
    for t, t_start in zip(twins, per["time"]):
        m = t.model
        key = (t_start, m.opt.timestep, m.actuator_delay.tobytes(), m.actuator_history.tobytes())
        if key not in schedules:
            schedules[key] = delay_schedule(m, n, nsub, t_start)
        lags.append(schedules[key][0])
        switches.append(schedules[key][1])
    out["delay_lag"], out["delay_switch"] = np.stack(lags), np.stack(switches)
    return out, y0


def _simulate(batch: PreparedBatch, n: int) -> tuple[dict[str, np.ndarray], np.ndarray]:
    jax, jnp, mjx = _jax()
    from jax import lax

    twins = batch.twins
    t0 = twins[0]
    host, y0 = _host_inputs(batch, n)
    mx, model_axes = stack_models([t.model for t in twins])
    ctrl_arrays, ctrl_static = _controller_parts(batch.stacked)
    nsub = int(round(t0.sample_time / t0.model.opt.timestep))
    nv = t0.model.nv
    axes = [i for i, a in enumerate(("pitch", "yaw")) if a in t0._axis_dof]
    dofs = jnp.asarray([t0._axis_dof[a] for a in ("pitch", "yaw") if a in t0._axis_dof], dtype=jnp.int32)
    in_rot = jnp.asarray(t0.input_rotors, dtype=jnp.int32)
    out_qpos = jnp.asarray(t0.output_qpos, dtype=jnp.int32)
    actuators = jnp.arange(t0.model.nu)
    wash = jnp.asarray(t0._wash, dtype=jnp.int32)
    spinning = t0._spinning

    nu = t0.model.nu
    ring = int(host["delay_lag"].max()) + 2  # intervals of controls kept: the oldest one read, to the current one

    def rotor_controls(curves: Any, volts: Any, turbulence: Any) -> Any:
        """:func:`trms.twin.rotors.rotor_controls` in JAX: thrusts (N), then spin speeds (rad/s) if modelled, then
        the turbulence actuators' thrust fluctuations (N)."""
        k, a_pos, b_pos, a_neg, b_neg, tau_max, w_per_state = (curves[:, i] for i in range(7))
        tau = jnp.clip(k * volts, -tau_max, tau_max)
        pos = tau >= 0
        a, b = jnp.where(pos, a_pos, a_neg), jnp.where(pos, b_pos, b_neg)
        f = a * tau * jnp.abs(tau) + b * tau
        cols = jnp.concatenate([f, w_per_state * tau]) if spinning else f
        ctrl = jnp.zeros(nu).at[: cols.shape[0]].set(cols)
        return ctrl.at[wash].set(turbulence) if t0._wash.size else ctrl

    def push(p: Mapping[str, Any], step: Any) -> Any:
        on = (p["push_a"] <= step) & (step < p["push_b"])
        return jnp.sum(jnp.where(on[:, None], p["push_tq"], 0.0), axis=0)

    def control(cp: list, cs: list, r: Any, dy: Any) -> tuple[list, Any, Any]:
        m_in = host["u_trim"].shape[1]
        u = jnp.zeros(m_in)
        new_states, x_hats = [], []
        for arr, (tracked, inject, outs, ins, (r0, nr)), (x_bar, xi) in zip(cp, ctrl_static, cs):
            tr = jnp.asarray(tracked)
            ref = r[r0 : r0 + nr]
            y = dy[jnp.asarray(outs)]
            y_est = y.at[tr].add(-inject * ref)
            x_hat = x_bar + arr["Lc"] @ (y_est - arr["C"] @ x_bar)
            uu = -(arr["Kx"] @ x_hat) - arr["Ki"] @ xi
            held = jnp.minimum(jnp.maximum(uu, arr["lower"]), arr["upper"])
            over, under = uu > arr["upper"], uu < arr["lower"]
            error = ref - y[tr]
            du = -(arr["Ki"] @ error)
            hold = jnp.any(over & (du > 0)) | jnp.any(under & (du < 0))
            error = jnp.where(hold, 0.0, error)
            new_states.append((arr["A"] @ x_hat + arr["B"] @ held, xi + error))
            x_hats.append(x_hat)
            u = u.at[jnp.asarray(ins)].set(uu)
        return new_states, u, jnp.concatenate(x_hats)

    def run_one(m: Any, p: Mapping[str, Any], cp: list, shaped: Any, y_first: Any) -> tuple[dict, Any]:
        d = mjx.make_data(m).replace(qpos=p["qpos"], qvel=p["qvel"], act=p["act"], time=p["time"], ctrl=p["ctrl"])
        cs = [(jnp.zeros(arr["A"].shape[0]), jnp.zeros(len(st[0]))) for arr, st in zip(cp, ctrl_static)]

        def interval(carry: tuple, xs: tuple) -> tuple[tuple, dict]:
            d, cs, g, turb, volts, y, dead, history = carry
            k, r_k, w_k, v_k, e_k, lag_k, switch_k = xs
            start = k * nsub
            out = {
                "y": y,
                "qpos": d.qpos,
                "qvel": d.qvel,
                "act": d.act,
                "dist": g + push(p, start),
                "turb": turb,
                "dead": dead,
            }
            cs, u, x_hat = control(cp, cs, r_k, y - p["y_trim"])
            applied = jnp.clip(u + p["u_trim"], p["lower"], p["upper"])
            volts = volts.at[in_rot].set(applied)
            history = history.at[k % ring].set(rotor_controls(p["curves"], volts, turb))
            late = history[(k - lag_k - 1) % ring, actuators]  # the interval read before the switch
            held = history[(k - lag_k) % ring, actuators]  # and after it

            def phys(i: Any, dd: Any) -> Any:
                torque = g + push(p, start + i)
                qfrc = jnp.zeros(nv).at[dofs].set(torque[jnp.asarray(axes)])
                return mjx.step(m, dd.replace(ctrl=jnp.where(i < switch_k, late, held), qfrc_applied=qfrc))

            d_new = lax.fori_loop(0, nsub, phys, d)
            ok = (
                jnp.all(jnp.isfinite(d_new.qpos))
                & jnp.all(jnp.isfinite(d_new.act))
                & (jnp.max(jnp.abs(d_new.qvel)) <= MAX_RATE)
            )
            dead_new = dead | ~ok
            d = jax.tree_util.tree_map(lambda a, b: jnp.where(dead_new, b, a), d_new, d)
            g = p["gust_a"] * g + p["gust_s"] * w_k
            turb = p["turb_a"] * turb + p["turb_s"] * v_k
            q = d.qpos[out_qpos] + p["noise_std"] * e_k
            res = p["res"]
            y = jnp.where(res > 0, jnp.round(q / jnp.where(res > 0, res, 1.0)) * res, q)
            out.update(u=u, applied=applied, x_hat=x_hat)
            return (d, cs, g, turb, volts, y, dead_new, history), out

        xs = (
            jnp.arange(n),
            shaped,
            p["gust_noise"],
            p["turb_noise"],
            p["enc_noise"],
            p["delay_lag"],
            p["delay_switch"],
        )
        history = jnp.broadcast_to(p["ctrl"], (ring, nu))  # the delay lines at the trim (Twin.put_at_trim)
        carry = (d, cs, p["gust"], p["turb"], p["volts"], y_first, jnp.asarray(False), history)
        (_, _, _, _, _, _, dead, _), outs = lax.scan(interval, carry, xs)
        return outs, dead

    per = {k: jnp.asarray(v) for k, v in host.items()}
    cp = [{k: jnp.asarray(v) for k, v in arr.items()} for arr in ctrl_arrays]
    run = jax.jit(jax.vmap(run_one, in_axes=(model_axes, 0, 0, 0, 0)))
    outs, dead = run(mx, per, cp, jnp.asarray(batch.shaped), jnp.asarray(y0))
    outs = {k: np.asarray(v, dtype=bool if k == "dead" else float) for k, v in outs.items()}
    return outs, np.asarray(dead)


def mjx_closed_loop(
    twins: Sequence[Twin],
    controllers: Sequence[Controller],
    reference: object,
    prefilters: Prefilter | Sequence[Prefilter | None] | None = None,
    seeds: Sequence[int | None] | None = None,
    metadata: Mapping[str, Any] | Sequence[Mapping[str, Any]] | None = None,
) -> BatchResult:
    """:func:`trms.batch.batch_closed_loop` with MJX physics and the loop in JAX (module docstring).

    Parameters and result as :func:`trms.batch.batch_closed_loop`; the Records carry
    ``metadata["physics"] = "mjx float32"``.

    Raises
    ------
    ConfigurationError
        JAX or MJX not installed (the ``trms[mjx]`` extra), or a model MJX cannot run here.

    Examples
    --------
    >>> from trms.control.lqg import LQGController, design_lqg  # doctest: +SKIP
    >>> from trms.worlds import design_model  # doctest: +SKIP
    >>> twins = [Twin("1dof", 0.2, seed=s) for s in (0, 1)]  # doctest: +SKIP
    >>> ctrl = [LQGController(design_lqg(design_model("1dof"), R=75.0)) for _ in twins]  # doctest: +SKIP
    >>> mjx_closed_loop(twins, ctrl, np.full(20, 0.1)).records[0].outputs.shape  # doctest: +SKIP
    (20, 1)
    """
    _jax()
    given = [metadata] * len(twins) if metadata is None or isinstance(metadata, Mapping) else list(metadata)
    metas = [dict(m or {}, physics="mjx float32") for m in given]
    batch = prepare_batch(twins, controllers, reference, prefilters, seeds, metas)
    n = batch.shaped.shape[1]
    outs, dead = _simulate(batch, n)
    u_trim = np.stack([t.operating_point.inputs for t in batch.twins])
    control = outs["u"]
    channels: list[dict[str, np.ndarray]] = []
    errors: list[DivergenceError | None] = []
    for b, t in enumerate(batch.twins):
        if dead[b]:
            k = int(np.argmax(outs["dead"][b])) if outs["dead"][b].any() else n
            errors.append(
                DivergenceError(f"simulation diverged (MJX) in loop {b} before t = {k * t.sample_time:.3f} s")
            )
            channels.append({})
            continue
        errors.append(None)
        qpos, qvel, act = outs["qpos"][b], outs["qvel"][b], outs["act"][b]
        zero = np.zeros(n)
        channels.append(
            {
                "true_angles": np.column_stack(
                    [qpos[:, t._axis_qpos[a]] if a in t._axis_qpos else zero for a in ("pitch", "yaw")]
                ),
                "rates": np.column_stack(
                    [qvel[:, t._axis_dof[a]] if a in t._axis_dof else zero for a in ("pitch", "yaw")]
                ),
                "rotor_thrust": act,
                "rotor_speed": np.column_stack([c.rotor_state(act[:, i]) for i, c in enumerate(t.curves)]),
                "disturbance": outs["dist"][b],
                "turbulence": outs["turb"][b],
                "qpos": qpos,
            }
        )
    estimates = outs["x_hat"] if isinstance(batch.stacked, StackedLQG) else None
    return assemble_records(
        batch, control + u_trim[:, None, :], outs["y"], outs["applied"], control, estimates, channels, errors
    )
