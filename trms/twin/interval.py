"""Running one control interval of the twin in MuJoCo: torques, end stops, divergence.

:class:`IntervalPhysics` is the part of :class:`~trms.twin.twin.Twin` that drives MuJoCo through one
control interval: the rotor controls and the gust and push torques of each physics step, the ``at_stop``
channel (an interval that starts within reach of an end stop runs as native ``mujoco.rollout`` calls that
record the position at every physics step; one that only ends within reach is replayed so on scratch data),
and a failed interval's diagnosis (replayed one physics step at a time to find where it failed) with the
exact restore of the state before it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import mujoco
import numpy as np
from mujoco import rollout

from trms.errors import DivergenceError, SimulationError
from trms.twin.disturbances import Gust, Push, Turbulence
from trms.twin.rotors import ThrustCurve, rotor_control_values

__all__ = ["raised_warnings"]

AXES = ("pitch", "yaw")
#: A joint rate beyond this (rad/s) is taken as a diverging simulation.
MAX_RATE = 1e3
#: MuJoCo warnings that mean the state blew up (MuJoCo then resets the data itself).
_DIVERGENCE_WARNINGS = ("mjWARN_BADQACC", "mjWARN_BADQPOS", "mjWARN_BADQVEL")
#: The state saved before each interval: everything the integrator reads, warmstart included,
#: so a restore after a refused step is bit-exact.
SAVED_STATE = mujoco.mjtState.mjSTATE_INTEGRATION
#: The state ``mujoco.rollout`` starts from and returns, and what it takes per physics step.
FULL_STATE = mujoco.mjtState.mjSTATE_FULLPHYSICS
ROLLOUT_CONTROL = mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_QFRC_APPLIED
#: An interval is run recording every physics step's position when its start is nearer an end stop than this
#: many times the distance its rate and acceleration there reach in one interval (a second-order bound) ...
_STOP_RECORD_SAFETY = 4.0
#: ... and replayed so when either end is nearer than this many times the distance the larger of its two
#: endpoint rates and accelerations (the latter at least the mean one) reach.
_STOP_REPLAY_SAFETY = 2.0
#: Physics steps per rollout call of a recorded interval (bounds its recording buffer).
_RECORD_CHUNK = 256
#: ``at_stop`` of an interval that touched no stop (read-only, shared).
_NO_STOPS = np.zeros(len(AXES), bool)
_NO_STOPS.flags.writeable = False
#: Name of each entry of ``MjData.warning``.
_WARNING_NAMES = {int(v): k for k, v in mujoco.mjtWarning.__members__.items()}


class _Intervals:
    """A union of ranges ``[first, last]`` of control intervals, for ``k in ...``: a set of their indices when they
    are few (a lookup), else the ranges (a scan)."""

    __slots__ = ("_ranges", "_set")

    def __init__(self, ranges: list[tuple[int, int]]) -> None:
        self._ranges = ranges
        few = sum(last - first + 1 for first, last in ranges) <= 100_000
        self._set = {k for first, last in ranges for k in range(first, last + 1)} if few else None

    def __contains__(self, k: object) -> bool:
        if self._set is not None:
            return k in self._set
        return any(first <= k <= last for first, last in self._ranges)  # type: ignore[operator]


def raised_warnings(data: mujoco.MjData, before: np.ndarray | Sequence[int]) -> list[str]:
    """Names of the MuJoCo warnings whose counters moved since ``before`` (a copy of ``data.warning.number``)."""
    return [
        _WARNING_NAMES.get(int(i), f"warning {i}") for i in np.flatnonzero(data.warning.number != np.asarray(before))
    ]


class IntervalPhysics:
    """One control interval of the twin in MuJoCo (the base of :class:`~trms.twin.twin.Twin`, which sets every
    attribute declared here)."""

    model: mujoco.MjModel
    data: mujoco.MjData
    sample_time: float
    curves: tuple[ThrustCurve, ...]
    gust: Gust
    pushes: tuple[Push, ...]
    turbulence: Turbulence
    _nsub: int
    _physics_step: float
    _step_index: int
    _axis_qpos: dict[str, int]
    _axis_dof: dict[str, int]
    _state_buf: np.ndarray
    _gust_torque: np.ndarray
    _turbulence: np.ndarray
    _wash: np.ndarray
    _wash_list: list[int]
    _spinning: bool
    _free: np.ndarray
    _free_dof: np.ndarray
    _torque_slots: list[tuple[int, int]]
    _qfrc_applied: np.ndarray
    _ctrl: np.ndarray
    _qpos: np.ndarray
    _qvel: np.ndarray
    _act: np.ndarray

    def _index_stops(self) -> None:
        """Index the end stops of the free axes (rad) and MuJoCo's activation margin (a limit constraint is
        active when the distance to it is below the margin), for the ``at_stop`` channel."""
        m = self.model
        axes = [a for a in AXES if a in self._axis_qpos and m.jnt_limited[m.joint(a).id]]
        joints = [m.joint(a).id for a in axes]
        self._stop_axis = np.array([AXES.index(a) for a in axes], dtype=int)
        self._stop_qpos = np.array([self._axis_qpos[a] for a in axes], dtype=int)
        self._stop_lo, self._stop_hi = (m.jnt_range[joints, i].copy() for i in (0, 1))
        self._stop_margin = m.jnt_margin[joints].copy()

        def offset(spec: int, part: mujoco.mjtState) -> int:  # where ``part`` starts in a state of ``spec``
            return int(mujoco.mj_stateSize(m, int(spec) & (int(part) - 1)))

        # Per stopped axis, as plain numbers for the per-interval check: where its position, rate and warm-start
        # acceleration sit in the saved state, its qpos and dof index, its stops and margin.
        st = mujoco.mjtState
        q_at, v_at, a_at = (offset(SAVED_STATE, p) for p in (st.mjSTATE_QPOS, st.mjSTATE_QVEL, st.mjSTATE_WARMSTART))
        self._stop_probe = [
            (q_at + qi, v_at + di, a_at + di, qi, di, float(lo), float(hi), float(mg))
            for qi, di, lo, hi, mg in zip(
                self._stop_qpos.tolist(),
                [int(self._axis_dof[a]) for a in axes],
                self._stop_lo,
                self._stop_hi,
                self._stop_margin,
            )
        ]
        # What a rollout records per physics step, to read the positions from: the axes' joint-position sensors
        # (computed at the start of each step, a few numbers), else the full state after each step.
        sensors = {
            int(m.sensor_objid[i]): int(m.sensor_adr[i])
            for i in range(m.nsensor)
            if m.sensor_type[i] == mujoco.mjtSensor.mjSENS_JOINTPOS and m.sensor_cutoff[i] == 0
        }
        self._record_sensors = all(j in sensors for j in joints)
        if self._record_sensors:
            self._record_cols = np.array([sensors[j] for j in joints], dtype=int)
        else:
            self._record_cols = offset(FULL_STATE, st.mjSTATE_QPOS) + self._stop_qpos
        self._record_buf: np.ndarray | None = None  # allocated when first needed
        self._push_cache: tuple | None = None
        self._replay_data: mujoco.MjData | None = None
        self._interval_stops: np.ndarray | None = None  # at_stop over the last interval (None: none run yet)

    @property
    def time(self) -> float:
        """Simulated time since ``reset`` (s)."""
        return self._step_index * self.sample_time

    def _interval_rows(self, volts: np.ndarray) -> np.ndarray:
        """Per physics step of the coming interval, the rotor controls and ``qfrc_applied`` (rollout's layout)."""
        m = self.model
        controls = np.zeros((self._nsub, m.nu + m.nv))
        controls[:, : m.nu] = self._thrust(volts)
        if not (self.pushes or self.gust.std):  # no torque: qfrc_applied stays 0
            return controls
        free_dof = m.nu + self._free_dof
        row = 0
        for n_steps, torque in self._segments(self._step_index * self._nsub):
            controls[row : row + n_steps, free_dof] = torque[self._free]
            row += n_steps
        return controls

    def _thrust(self, volts: np.ndarray) -> np.ndarray:
        """The actuator controls for rotor voltages: thrusts (N), spin speeds (rad/s), and the interval's
        turbulence (N)."""
        values = rotor_control_values(self.curves, volts.tolist(), self.model.nu, self._spinning)
        if self._wash_list:
            for i, thrust in zip(self._wash_list, self._turbulence.tolist()):
                values[i] = thrust
        return np.array(values)

    def _restore(self, start_state: np.ndarray, volts: np.ndarray) -> DivergenceError:
        """Put the twin back at an interval's start after it diverged; return the error to raise."""
        m, d = self.model, self.data
        qpos, qvel = d.qpos.copy(), d.qvel.copy()
        mujoco.mj_setState(m, d, start_state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
        mujoco.mj_forward(m, d)
        return DivergenceError(
            f"simulation diverged between t = {self.time:.3f} s and {self.time + self.sample_time:.3f} s "
            f"(voltages {volts.tolist()} V): qpos = {np.array2string(qpos, precision=4)}, "
            f"qvel = {np.array2string(qvel, precision=4)}; the twin is left at t = {self.time:.3f} s"
        )

    def _push_ranges(self) -> list[tuple[int, int, tuple[float, float]]]:
        """Each push's physics steps ``[first, end)`` and torque (pitch, yaw; N m), computed once per set of pushes."""
        return self._push_plan()[0]

    def _pushed(self, k: int) -> bool:
        """Whether some push acts at some physics step of control interval ``k`` (counted from the reset)."""
        return k in self._push_plan()[1]

    def _push_plan(self) -> tuple[list[tuple[int, int, tuple[float, float]]], _Intervals]:
        """:meth:`_push_ranges`, and the control intervals in which some push acts, computed once per set of pushes."""
        pushes, dt, nsub = self.pushes, self._physics_step, self._nsub
        cached = self._push_cache
        if cached is None or cached[0] is not pushes or not isinstance(pushes, tuple):
            ranges = [(*p.steps(dt), p.torque) for p in pushes]
            pushed = _Intervals([(a // nsub, (b - 1) // nsub) for a, b, _ in ranges])
            cached = self._push_cache = (pushes, (ranges, pushed))
        return cached[1]

    def _push_torque(self, step: int) -> np.ndarray:
        """The pushes' torque (pitch, yaw; N m) at physics step ``step``: each acting push's, summed in order from 0."""
        pitch = yaw = 0.0
        for a, b, (tp, ty) in self._push_ranges() if self.pushes else ():
            if a <= step < b:
                pitch += tp
                yaw += ty
        return np.array([pitch, yaw])

    def _segments(self, start: int) -> list[tuple[int, np.ndarray]]:
        """Split the interval ``[start, start + nsub)`` (physics steps) where pushes start or end."""
        end = start + self._nsub
        ranges = self._push_ranges() if self.pushes else ()
        if not any(a < end and start < b for a, b, _ in ranges):  # no push acts in the interval: theirs is 0
            return [(self._nsub, self._gust_torque + 0.0 if ranges else self._gust_torque)]
        cuts = {start, end}
        for a, b, _ in ranges:
            cuts.update(c for c in (a, b) if start < c < end)
        edges = sorted(cuts)
        return [(b - a, self._gust_torque + self._push_torque(a)) for a, b in zip(edges[:-1], edges[1:])]

    def _against_stops(self, q: np.ndarray) -> np.ndarray:
        """Per axis (pitch, yaw), whether any row of ``q`` (positions of the stopped axes, rad) activates a limit."""
        at_stop = np.zeros(len(AXES), bool)
        # MuJoCo's rule: a limit is active when its distance is below the margin.
        near = (q - self._stop_lo < self._stop_margin) | (self._stop_hi - q < self._stop_margin)
        at_stop[self._stop_axis] = near.reshape(-1, self._stop_axis.size).any(axis=0)
        return at_stop

    def _stops_now(self) -> np.ndarray:
        return self._against_stops(self.data.qpos[self._stop_qpos])

    def _stop_start(self) -> list[tuple[float, float, float]]:
        """Each stopped axis' position, rate and warm-start acceleration in the state saved in ``_state_buf``."""
        saved = self._state_buf
        return [(saved.item(q), saved.item(v), saved.item(a)) for q, v, a, *_ in self._stop_probe]

    def _stop_ahead(self, start: list[tuple[float, float, float]]) -> bool:
        """Whether the interval from ``start`` (:meth:`_stop_start`) may reach an end stop: its start is nearer one
        than :data:`_STOP_RECORD_SAFETY` times the distance its rate and acceleration there cover in one interval. A
        few scalar operations per axis."""
        ts = self.sample_time
        for (q0, v0, a0), (_, _, _, _, _, lo, hi, margin) in zip(start, self._stop_probe):  # at most two axes
            reach = ts * (abs(v0) + 0.5 * ts * abs(a0))
            if min(q0 - lo, hi - q0) < margin + _STOP_RECORD_SAFETY * reach:
                return True
        return False

    def _stops_in_interval(
        self,
        volts: np.ndarray,
        qpos: list[float] | None = None,
        qvel: list[float] | None = None,
        start: list[tuple[float, float, float]] | None = None,
    ) -> np.ndarray:
        """Per axis, whether its limit constraint was active at any physics step of the interval just run (not
        recorded), from the state saved in ``_state_buf`` to the live data under ``volts`` (``qpos`` and ``qvel``:
        the data's as plain floats, and ``start``: :meth:`_stop_start` of the saved state, when at hand).

        When both ends are farther from every stop than :data:`_STOP_REPLAY_SAFETY` times the distance the axis
        covers at the larger endpoint rate and acceleration (the common case, a few scalar operations per axis),
        it was not. Otherwise the interval is replayed, recorded, on scratch data from the exact saved state;
        the twin's own data is not touched.
        """
        d, ts = self.data, self.sample_time
        qpos = d.qpos.tolist() if qpos is None else qpos
        qvel = d.qvel.tolist() if qvel is None else qvel
        if start is None:
            start = self._stop_start()
        for (q0, v0, a0), (_, _, _, qi, di, lo, hi, margin) in zip(start, self._stop_probe):
            q1, v1 = qpos[qi], qvel[di]
            reach = ts * (max(abs(v0), abs(v1)) + 0.5 * ts * max(abs(a0), abs(v1 - v0) / ts))
            if min(min(q0, q1) - lo, hi - max(q0, q1)) < margin + _STOP_REPLAY_SAFETY * reach:
                if self._replay_data is None:
                    self._replay_data = mujoco.MjData(self.model)
                return self._against_stops(self._run_recorded(self._replay_data, volts))
        return _NO_STOPS

    def _run_recorded(self, data: mujoco.MjData, volts: np.ndarray) -> np.ndarray:
        """Run the interval saved in ``_state_buf`` under ``volts`` on ``data`` (the twin's own, or scratch) in native
        ``mujoco.rollout`` calls (bit-identical to :meth:`step`'s ``mj_step``; the warning counters count the interval
        from zero, and stepping stops at a warning); return the positions (rad) of the stopped axes at every physics
        step, its start and end included (rows; a few appear twice)."""
        m, nsub = self.model, self._nsub
        rows = self._interval_rows(volts)
        mujoco.mj_setState(m, data, self._state_buf, SAVED_STATE)
        chunk = min(nsub, _RECORD_CHUNK)
        if self._record_buf is None:
            width = m.nsensordata if self._record_sensors else mujoco.mj_stateSize(m, FULL_STATE)
            self._record_buf = np.empty((1, chunk, width))
        out, start = self._record_buf, np.empty((1, mujoco.mj_stateSize(m, FULL_STATE)))
        positions = [data.qpos[self._stop_qpos][None]]
        for a in range(0, nsub, chunk):
            n = min(chunk, nsub - a)
            mujoco.mj_getState(m, data, start[0], FULL_STATE)
            rollout.rollout(
                [m],
                [data],
                start,
                rows[None, a : a + n],
                control_spec=ROLLOUT_CONTROL,
                nstep=n,
                initial_warmstart=data.qacc_warmstart[None].copy(),
                state=None if self._record_sensors else out[:, :n],
                sensordata=out[:, :n] if self._record_sensors else None,
                skip_checks=True,
            )
            positions.append(out[0, :n][:, self._record_cols])
            if data.warning.number.any():
                break
        positions.append(data.qpos[self._stop_qpos][None])
        return np.concatenate(positions)

    def _apply_torque(self, torque: np.ndarray, plus_zero: bool = False) -> None:
        """Hold ``torque`` (pitch, yaw; N m) on the free axes (``plus_zero``: ``torque + 0.0``, a push's sum of none,
        whose zeros are positive)."""
        values, qfrc = torque.tolist(), self._qfrc_applied
        for dof, axis in self._torque_slots:
            qfrc[dof] = values[axis] + 0.0 if plus_zero else values[axis]

    def _finite_state(self, qpos: list[float] | None = None, qvel: list[float] | None = None) -> bool:
        """Whether every position, rate and activation is finite and no rate beyond :data:`MAX_RATE` (``qpos`` and
        ``qvel``: the data's as plain floats, when at hand)."""
        d = self.data
        rates = d.qvel.tolist() if qvel is None else qvel
        # A sum is finite only when every term is (a NaN or an infinity makes it NaN or infinite; MuJoCo's own
        # bound on a state, 1e10, keeps a finite one's sum far from overflowing); then the largest rate is checked.
        positions = d.qpos.tolist() if qpos is None else qpos
        return math.isfinite(sum(positions) + sum(self._act.tolist()) + sum(rates)) and (
            max(map(abs, rates), default=0.0) <= MAX_RATE
        )

    def _refuse_interval(self, volts: np.ndarray, ctrl: np.ndarray, start: int, warnings: list[str]) -> None:
        """Locate what went wrong in the interval from ``start``, restore the saved state exactly, raise.

        Only runs after a failed interval: it replays the interval one physics step at a time to
        find the first bad step and the last finite state before it.
        """
        m, d = self.model, self.data
        mujoco.mj_setState(m, d, self._state_buf, SAVED_STATE)
        d.ctrl[:] = ctrl
        counts = d.warning.number.copy()
        last_q, last_v, bad_t, raised = d.qpos.copy(), d.qvel.copy(), float("nan"), []
        for k in range(start, start + self._nsub):
            self._apply_torque(self._gust_torque + self._push_torque(k))
            t0 = d.time
            mujoco.mj_step(m, d)
            raised = raised_warnings(d, counts)
            if raised or not self._finite_state() or d.time < t0 + 0.5 * m.opt.timestep:
                bad_t = t0 + m.opt.timestep
                break
            last_q, last_v = d.qpos.copy(), d.qvel.copy()
        d.qfrc_applied[:] = 0.0
        mujoco.mj_setState(m, d, self._state_buf, SAVED_STATE)
        mujoco.mj_forward(m, d)
        vec = lambda a: "[" + ", ".join(f"{x:.4g}" for x in a) + "]"  # noqa: E731
        names = ", ".join(w.removeprefix("mjWARN_") for w in warnings) or "none"
        diverged = bool(set(raised or warnings) & set(_DIVERGENCE_WARNINGS)) or not (raised or warnings)
        what = "simulation diverged" if diverged else "MuJoCo raised a warning"
        error = DivergenceError if diverged else SimulationError
        raise error(
            f"{what} at t = {bad_t:.3f} s (physics step of {m.opt.timestep} s; "
            f"MuJoCo warnings in the interval: {names}; voltages "
            f"{[round(v, 6) for v in volts.tolist()]} V); last finite state at t = {bad_t - m.opt.timestep:.3f} s: "
            f"qpos = {vec(last_q)} rad, qvel = {vec(last_v)} rad/s, |qvel| max {np.abs(last_v).max(initial=0.0):.3g} "
            f"rad/s; the twin is restored exactly to t = {self.time:.3f} s"
        )
