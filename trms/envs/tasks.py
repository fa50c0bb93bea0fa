"""Control tasks on the twin, shared by the dm_env suite (:mod:`trms.envs.suite`) and Gymnasium (:mod:`trms.envs.gym`).

A task is a :class:`TaskDefinition` (what the episode is: configuration, disturbances, the
reference drawn each episode, the observation, the reward and the termination) run by one
:class:`TaskRunner` (one :meth:`Twin.step <trms.twin.Twin.step>` per environment step). Both
APIs wrap the same runner, so a task behaves identically behind either.

Units: actions are absolute motor voltages (V) within the rig's +-10 V (values beyond are
saturated by the twin, and the saturation is reported), or, normalised (:meth:`TaskRunner.volts`),
numbers in [-1, 1] mapped linearly onto that range; angles in rad, rates in rad/s.

Observation (a flat vector; :meth:`TaskDefinition.observation_names` names each entry):

* ``angle:<axis>`` -- the encoder reading of each free axis (rad, quantised), bounded by the
  axis' end stops (pitch) or +-pi (yaw);
* ``rate:<axis>`` -- the true axis rate (rad/s), clipped to +-:data:`RATE_BOUND`;
* ``rotor_speed:<input>`` -- the tachometer reading of each driven rotor (rotor state, the
  units of volts times the motor gain), clipped to the rotor's full speed;
* ``reference:<axis>`` -- the angle to hold at this step (rad).

Reward per step (in [0, 1]): the product over the tracked axes of dm_control's Gaussian
``tolerance`` of the true angle's error: 1 within ``bounds`` of the reference, 0.1 at
``bounds + margin``. Holding the hover trim voltages is far from the reference most of the time
(references are drawn away from the trim, gusts and pushes move the beam), so it scores poorly.

An episode ends (``terminated``) when the simulation diverges (the twin refuses the step);
otherwise it is cut (``truncated``) at the task's duration. A new one starts with ``reset``; stepping
an episode that is over (or before the first ``reset``) is refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np

from trms import reference as ref
from trms.errors import DivergenceError, InputError, check_choice, check_seed
from trms.plant import check_input_vector
from trms.twin.disturbances import MOVING_AIR, Gust, Push
from trms.twin.twin import Twin

__all__ = ["RATE_BOUND", "TaskDefinition", "TaskRunner", "TASKS", "get_task", "gaussian_tolerance", "clipped"]

#: Bound of the axis rates in the observation (rad/s): rates beyond it are clipped.
RATE_BOUND = 5.0


@dataclass(frozen=True)
class TaskDefinition:
    """One control task on the twin.

    Parameters
    ----------
    name : str
        Task name (``PitchTracking``, ``HoverGusts``, ``AttitudeTracking``).
    config : {"1dof", "2dof"}
        Twin configuration.
    sample_time : float
        Control step (s).
    duration : float
        Episode length (s).
    hold : float
        How long each reference value is held (s).
    amplitudes : dict
        Per axis, ``(low, high)`` magnitudes (rad) of the reference values, drawn uniformly with a
        random sign; an axis absent holds 0.
    tolerance : tuple of float
        ``(bounds, margin)`` of the reward (rad).
    gust : Gust
        Gust torques of every episode.
    pushes : int
        Number of pushes per episode, at times drawn uniformly over the episode.
    push_impulse : tuple of float
        ``(low, high)`` magnitude of each push's angular impulse (N m s), random sign and axis.
    push_duration : float
        Length of each push (s).
    displacement : dict
        Per axis, ``(low, high)`` magnitude (rad) of the initial displacement from the trim, drawn
        uniformly with a random sign; an axis absent starts at the trim.
    description : str
        One line for the registries.
    """

    name: str
    config: str
    sample_time: float
    duration: float
    hold: float
    amplitudes: dict[str, tuple[float, float]] = field(default_factory=dict)
    tolerance: tuple[float, float] = (0.02, 0.1)
    gust: Gust = field(default_factory=Gust)
    pushes: int = 0
    push_impulse: tuple[float, float] = (0.0, 0.0)
    push_duration: float = 0.2
    displacement: dict[str, tuple[float, float]] = field(default_factory=dict)
    description: str = ""

    @property
    def n_steps(self) -> int:
        """Steps per episode."""
        return int(round(self.duration / self.sample_time))

    def make_twin(self, seed: int = 0) -> Twin:
        """The twin this task runs on (default encoder, the task's gusts)."""
        return Twin(self.config, self.sample_time, seed, gust=self.gust)

    def draw_episode(self, twin: Twin, rng: np.random.Generator) -> tuple[np.ndarray, tuple[Push, ...], np.ndarray]:
        """Draw one episode: the reference ``(n_steps, n_outputs)`` (rad), pushes, initial displacement (rad)."""
        n, axes = self.n_steps, twin.output_names
        start = np.zeros(len(axes))
        for j, axis in enumerate(axes):
            if axis in self.displacement:
                start[j] = rng.uniform(*self.displacement[axis]) * rng.choice((-1.0, 1.0))
        per_hold = max(1, int(round(self.hold / self.sample_time)))
        n_holds = -(-n // per_hold)
        reference = np.zeros((n, len(axes)))
        for j, axis in enumerate(axes):
            if axis in self.amplitudes:
                lo, hi = self.amplitudes[axis]
                values = rng.uniform(lo, hi, n_holds) * rng.choice((-1.0, 1.0), n_holds)
                reference[:, j] = np.repeat(values, per_hold)[:n]
        pushes = []
        for _ in range(self.pushes):
            time = float(np.round(rng.uniform(0.1 * self.duration, 0.9 * self.duration), 3))
            impulse = float(rng.uniform(*self.push_impulse)) * float(rng.choice((-1.0, 1.0)))
            axis = str(rng.choice(axes))
            pushes.append(Push.impulse(time, impulse, self.push_duration, axis))
        return reference, tuple(pushes), start

    def observation_names(self, twin: Twin) -> list[str]:
        """Name of each observation entry (see the module docstring)."""
        axes, inputs = twin.output_names, twin.input_names
        return (
            [f"angle:{a}" for a in axes]
            + [f"rate:{a}" for a in axes]
            + [f"rotor_speed:{u}" for u in inputs]
            + [f"reference:{a}" for a in axes]
        )

    def observation_bounds(self, twin: Twin) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds of the observation (rad, rad/s, rotor state, rad)."""
        m = twin.model
        angle = []
        for a in twin.output_names:
            j = m.joint(a).id
            angle.append(m.jnt_range[j].copy() if m.jnt_limited[j] else np.array([-np.pi, np.pi]))
        angle_lo, angle_hi = np.array(angle).T
        speed = np.array(
            [min(c.tau_max, c.k * twin.voltage_limit) for c in (twin.curves[i] for i in twin.input_rotors)]
        )
        rate = np.full(len(twin.output_names), RATE_BOUND)
        lo = np.concatenate([angle_lo, -rate, -speed, angle_lo])
        hi = np.concatenate([angle_hi, rate, speed, angle_hi])
        return lo, hi

    def observation(
        self,
        twin: Twin,
        measured: np.ndarray,
        reference: np.ndarray,
        readings: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
        bounds: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> np.ndarray:
        """The observation vector after a step: encoder angles ``measured`` (rad) and ``reference`` (rad).

        ``readings`` (:meth:`Twin.readings <trms.twin.Twin.readings>`, now) and ``bounds``
        (:meth:`observation_bounds`) are read from the twin when not given.
        """
        _, rates, speed = twin.readings() if readings is None else readings
        lo, hi = self.observation_bounds(twin) if bounds is None else bounds
        obs = np.concatenate([measured, rates, speed, reference])
        return clipped(obs.tolist(), *(np.broadcast_to(b, obs.shape).tolist() for b in (lo, hi)))

    def reward(self, true_angles: np.ndarray, reference: np.ndarray) -> float | np.ndarray:
        """Reward (in [0, 1]) of true angles (rad) against the reference (rad): one step's (a float), or, for
        ``(N, n_outputs)`` arrays, each row's (an array).

        The product over the axes of dm_control's Gaussian ``tolerance`` of each error (:func:`gaussian_tolerance`).
        """
        one_step = type(true_angles) is np.ndarray and type(reference) is np.ndarray and true_angles.ndim == 1
        if one_step and true_angles.shape == reference.shape:  # one step's errors, as floats
            return self.step_reward([t - r for t, r in zip(true_angles.tolist(), reference.tolist())])
        err = np.asarray(true_angles, float) - np.asarray(reference, float)
        if err.ndim != 1:
            return np.prod(gaussian_tolerance(err, *self.tolerance), axis=-1)
        return self.step_reward(err.tolist())

    def step_reward(self, errors: list[float]) -> float:
        """:meth:`reward` of one step's errors (true angle minus reference, rad) as plain floats: the same
        arithmetic with numpy's exp, a few microseconds.

        Examples
        --------
        >>> task = TASKS["AttitudeTracking"]
        >>> task.step_reward([0.01, -0.3]) == task.reward(np.array([0.01, -0.3]), np.zeros(2))
        True
        """
        bounds, margin = self.tolerance
        reward = 1.0
        for e in errors:
            if not -bounds <= e <= bounds:
                distance = (-bounds - e if e < -bounds else e - bounds) / margin * _GAUSSIAN_SCALE
                reward *= float(np.exp(-0.5 * (distance * distance)))
        return reward


#: dm_control's ``tolerance`` default value at the margin, and the scale of its Gaussian there.
_VALUE_AT_MARGIN = 0.1
_GAUSSIAN_SCALE = float(np.sqrt(-2 * np.log(_VALUE_AT_MARGIN)))


def clipped(values: list[float], low: list[float], high: list[float]) -> np.ndarray:
    """``np.clip(values, low, high)`` of plain floats, element by element: the same bits, a NaN value or bound giving
    NaN and a value equal to a bound giving the bound (its sign of zero).

    Raises
    ------
    ValueError
        The three lists differ in length.

    Examples
    --------
    >>> clipped([-2.0, 0.5, 3.0], [-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]).tolist()
    [-1.0, 0.5, 1.0]
    """
    out = []
    for v, lo, hi in zip(values, low, high, strict=True):
        v = v if v > lo or v != v else lo  # numpy's rule: the bound unless the value exceeds it or is NaN
        out.append(v if v < hi or v != v else hi)
    return np.array(out)


def gaussian_tolerance(error: np.ndarray, bounds: float, margin: float) -> np.ndarray:
    """dm_control's ``rewards.tolerance(error, bounds=(-bounds, bounds), margin=margin, sigmoid="gaussian")`` of an
    array of any shape, element by element, the same bits, without its per-call checks: 1 within ``bounds``
    (rad), 0.1 at ``bounds + margin``.

    Examples
    --------
    >>> from dm_control.utils import rewards
    >>> err = np.array([[0.0, 0.05], [-0.3, 0.021]])
    >>> same = gaussian_tolerance(err, 0.02, 0.1) == rewards.tolerance(err, (-0.02, 0.02), 0.1, "gaussian")
    >>> bool(same.all()), gaussian_tolerance(err, 0.02, 0.1)[0, 0]
    (True, np.float64(1.0))
    """
    lower, upper = -bounds, bounds
    inside = np.logical_and(lower <= error, error <= upper)
    distance = np.where(error < lower, lower - error, error - upper) / margin
    return np.where(inside, 1.0, np.exp(-0.5 * (distance * _GAUSSIAN_SCALE) ** 2))


#: The tasks, by name.
TASKS: dict[str, TaskDefinition] = {
    t.name: t
    for t in (
        TaskDefinition(
            "PitchTracking",
            "1dof",
            ref.SAMPLE_TIME_1DOF,
            40.0,
            10.0,
            {"pitch": (0.1, 0.3)},
            (0.02, 0.1),
            description="1-DOF rig (yaw locked): track pitch steps of 0.1-0.3 rad held 10 s each",
        ),
        TaskDefinition(
            # Gusts of moving air (the closed-loop experiments' level); pushes of chapter 7.4's size.
            "HoverGusts",
            "2dof",
            ref.SAMPLE_TIME_2DOF,
            30.0,
            30.0,
            {},
            (0.02, 0.1),
            MOVING_AIR,
            3,
            (0.02, 0.04),
            displacement={"pitch": (0.1, 0.2), "yaw": (0.3, 0.5)},
            description=(
                "2-DOF rig: return to hover from a displacement and hold it under gusts and three random pushes"
            ),
        ),
        TaskDefinition(
            "AttitudeTracking",
            "2dof",
            ref.SAMPLE_TIME_2DOF,
            40.0,
            10.0,
            {"pitch": (0.05, 0.2), "yaw": (0.1, 0.4)},
            (0.03, 0.15),
            description="2-DOF rig: track pitch and yaw steps held 10 s each",
        ),
    )
}


def get_task(name: str) -> TaskDefinition:
    """The task called ``name`` (one of :data:`TASKS`).

    Examples
    --------
    >>> get_task("PitchTracking").config
    '1dof'
    """
    check_choice("task", name, tuple(TASKS), error=InputError)
    return TASKS[name]


class TaskRunner:
    """Runs episodes of one task on one twin: the engine behind both environment APIs.

    Parameters
    ----------
    task : TaskDefinition or str
        The task (or its name).
    seed : int
        Seed of the first episode; each later ``reset()`` without a seed draws the next one.
    """

    def __init__(self, task: TaskDefinition | str, seed: int = 0) -> None:
        self.task = get_task(task) if isinstance(task, str) else task
        self.twin = self.task.make_twin(seed)
        self.observation_names = self.task.observation_names(self.twin)
        self._bounds = self.task.observation_bounds(self.twin)
        self.observation_low, self.observation_high = (b.copy() for b in self._bounds)
        self._bound_values = (self._bounds[0].tolist(), self._bounds[1].tolist())
        self.action_low, self.action_high = self.twin.input_limits
        names = ", ".join(self.twin.input_names)
        self._action_labels = (f"action ({names}) in V", f"action ({names}) in [-1, 1]")
        self._seeds = np.random.SeedSequence(check_seed("seed", seed, allow_none=False))
        self._k = 0
        self.reference = np.zeros((self.task.n_steps, len(self.twin.output_names)))
        #: True before the first :meth:`reset` and once an episode has terminated or been truncated.
        self.episode_over = True

    def reset(self, seed: int | None = None) -> np.ndarray:
        """Start an episode at the hover trim; return the first observation.

        Parameters
        ----------
        seed : int, optional
            Seed of this episode (reference, pushes, gusts, encoder noise); by default the
            next seed of the runner's own sequence.

        Raises
        ------
        InputError
            ``seed`` is not a non-negative integer (nothing changes).
        """
        if seed is not None:
            self._seeds = np.random.SeedSequence(check_seed("seed", seed))
        episode_seq = self._seeds.spawn(1)[0]
        rng = np.random.default_rng(episode_seq)
        self.reference, self.twin.pushes, start = self.task.draw_episode(self.twin, rng)
        measured = self.twin.reset(int(rng.integers(2**31)))
        if np.any(start):  # displaced from the trim, at rest
            twin = self.twin
            twin.data.qpos[twin.output_qpos] += start
            mujoco.mj_forward(twin.model, twin.data)
            measured = twin.encoder.measure(twin.data.qpos[twin.output_qpos], rng)
        self._k = 0
        self.episode_over = False
        return self.task.observation(self.twin, measured, self.reference[0], bounds=self._bounds)

    @property
    def current_reference(self) -> np.ndarray:
        """The reference (rad) of the current step."""
        return self.reference[min(self._k, len(self.reference) - 1)]

    def volts(self, action: object, normalised: bool = False) -> np.ndarray:
        """The motor voltages (V) an action asks for.

        Parameters
        ----------
        action : array_like
            One number per input (a scalar too with one input): absolute voltages (V), or with
            ``normalised`` numbers in [-1, 1] mapped linearly onto ``[action_low, action_high]``
            (beyond that range the twin saturates them, as it does volts).
        normalised : bool
            Read ``action`` as normalised.

        Returns
        -------
        numpy.ndarray
            The voltages (V), float64, shape ``(n_inputs,)``.

        Raises
        ------
        InputError
            Text, complex, non-finite values or the wrong shape, in one line.

        Examples
        --------
        >>> runner = TaskRunner("HoverGusts")
        >>> runner.volts([0.5, -1.0], normalised=True)
        array([  5., -10.])
        """
        n = len(self.twin.input_names)
        return self._scaled(
            check_input_vector(action, n, self.twin.input_names, self._action_labels[bool(normalised)]), normalised
        )

    def volts_rows(self, actions: np.ndarray, normalised: bool = False) -> np.ndarray:
        """:meth:`volts` of each row of ``actions`` (``(N, n_inputs)``; the same checks, messages and bits), at once
        where every row is finite float64.

        Examples
        --------
        >>> runner = TaskRunner("HoverGusts")
        >>> runner.volts_rows(np.array([[0.5, -1.0], [0.0, 0.25]]), normalised=True).tolist()
        [[5.0, -10.0], [0.0, 2.5]]
        """
        n = len(self.twin.input_names)
        fast = type(actions) is np.ndarray and actions.dtype == np.float64 and actions.shape[1:] == (n,)
        if fast and actions.ndim == 2 and math.isfinite(float(actions.sum())):  # a finite sum: every value finite
            return self._scaled(actions.copy(), normalised)
        rows = []
        for i, row in enumerate(actions):  # each row's own check, its message naming the row
            try:
                rows.append(self.volts(row, normalised))
            except InputError as exc:
                raise InputError(f"actions[{i}]: {str(exc).splitlines()[0]}") from None
        return np.array(rows).reshape(len(actions), n)

    def _scaled(self, arr: np.ndarray, normalised: bool) -> np.ndarray:
        """Checked actions ``arr`` as voltages (V): mapped from [-1, 1] onto the limits when ``normalised``."""
        if normalised:
            arr = 0.5 * (self.action_high + self.action_low) + 0.5 * (self.action_high - self.action_low) * arr
        return arr

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Apply absolute voltages ``action`` (V) for one control step.

        Returns
        -------
        observation, reward, terminated, truncated, info
            ``info`` holds ``applied_volts`` (after saturation, V), ``saturated`` (per input),
            ``true_angles`` (rad) and ``time`` (s); ``diverged`` when the twin refused the step.

        Raises
        ------
        InputError
            A malformed action (see :meth:`volts`), or no episode running (before the first
            :meth:`reset`, or after the episode ended); nothing changes.
        """
        return self.step_volts(self.volts(action))

    def step_volts(self, volts: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """:meth:`step` for voltages already read by :meth:`volts` (V): what the environments call.

        Raises
        ------
        InputError
            No episode running (before the first :meth:`reset`, or after the episode ended).
        """
        if self.episode_over:
            raise InputError(
                f"no episode is running (the last one ended at t = {self.twin.time:.3f} s, or none was started): "
                "call reset() before step()"
            )
        try:
            measured = self.twin.step_checked(volts)
        except DivergenceError as exc:
            return self.diverged(exc)
        return self.stepped(volts, measured)

    def stepped(self, volts: np.ndarray, measured: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Close a step the twin took under ``volts`` (V) that ended in the encoder reading ``measured`` (rad):
        the observation, reward, termination and info of :meth:`step`."""
        k, reference, twin, task = self._k, self.reference, self.twin, self.task
        self._k = k = k + 1
        true, rates, speed = twin.reading_values()
        reward = task.step_reward([t - r for t, r in zip(true, reference[k - 1].tolist())])
        applied = twin.applied_input
        info: dict[str, Any] = {
            "applied_volts": applied,
            "saturated": applied != volts,  # beyond the limits: the twin held the limit instead
            "true_angles": np.array(true),
            "time": twin.time,
        }
        truncated = k >= len(reference)  # the episode's steps (n_steps)
        self.episode_over = truncated
        obs = clipped(measured.tolist() + rates + speed + self.current_reference.tolist(), *self._bound_values)
        return obs, reward, False, truncated, info

    def diverged(self, error: DivergenceError) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """End the episode the twin refused a step of (``error``): :meth:`step`'s result then (reward 0,
        terminated)."""
        target = self.reference[self._k]
        self.episode_over = True
        readings = self.twin.readings()
        obs = self.task.observation(self.twin, readings[0], target, readings, self._bounds)
        return obs, 0.0, True, False, {"diverged": str(error), "time": self.twin.time}
