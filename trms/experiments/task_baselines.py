"""Baseline returns of the twin's control tasks (:mod:`trms.envs.tasks`): doing nothing, the controllers, random.

Seven policies on every task, each given the observation vector and returning absolute volts:

* ``zero volts`` -- the zero action (actions are absolute volts): both motors off;
* ``hold trim`` -- doing nothing: the hover trim voltages at every step;
* ``LQG`` -- the shipped integral LQG as chapter 8 flies it: on the 1-DOF task the thesis's design on eq. (3.11)
  (``R`` = 75, :func:`trms.experiments.ch8_designs.controllers_for`); on the 2-DOF tasks the MIMO LQG autopilot
  (:func:`trms.experiments.ch8_mimo_lqg.autopilot_controllers`, its per-channel weights), the same controllers the
  report runs. It reads only the encoder angles and the reference from the observation;
* ``PID``, ``MPC``, ``H-infinity`` -- chapter 8's comparison's designs (:mod:`trms.experiments.ch8_designs`: the PID
  with its measurement filter, the constrained MPC, the H-infinity design with the robust weight) on the 1-DOF
  task, their MIMO versions (:mod:`trms.experiments.ch8_controllers_mimo`) on the 2-DOF tasks, at the task's sample
  time, reading the observation as the LQG does (MPC and H-infinity need the control extra).

Every controller flies as in the comparison: behind the twin's thrust-curve inversion, following the reference
through the comparison's prefilter one sample at a time (:class:`~trms.control.loop.Prefiltered`);
* ``random`` -- volts drawn uniformly within +-10 V (seeded).

:func:`task_table` runs them over seeded episodes (seeds 1000, 1001, ...: no policy is tuned on
them) and returns the mean episode return of each.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from trms.control.loop import Controller, Prefiltered
from trms.envs.tasks import TASKS, TaskRunner
from trms.errors import ConfigurationError, InputError, check_choice, check_in_range

__all__ = [
    "POLICIES",
    "EVALUATION_SEED",
    "Policy",
    "zero_volts",
    "hold_trim",
    "lqg",
    "CONTROLLER_POLICIES",
    "comparison_policy",
    "ControllerPolicy",
    "random_policy",
    "episode_return",
    "TaskReturns",
    "task_table",
    "format_table",
]

#: Policy names, in the table's column order.
POLICIES = ("zero volts", "hold trim", "LQG", "PID", "MPC", "H-infinity", "random")
#: The comparison's controllers behind the policies of the same name: 1-DOF design, 2-DOF design.
CONTROLLER_POLICIES = {
    "PID": ("PID", "MIMO PID"),
    "MPC": ("MPC", "MIMO MPC"),
    "H-infinity": ("H-infinity, robust weight", "MIMO H-infinity"),
}
#: First evaluation seed: episodes use ``EVALUATION_SEED + i``.
EVALUATION_SEED = 1000

Policy = Callable[[np.ndarray], np.ndarray]


def zero_volts(runner: TaskRunner) -> Policy:
    """The zero action: 0 V on every driven rotor."""
    volts = np.zeros(len(runner.twin.input_names))
    return lambda obs: volts


def hold_trim(runner: TaskRunner) -> Policy:
    """Doing nothing: the hover trim voltages (V) whatever the observation."""
    volts = runner.twin.operating_point.inputs.copy()
    return lambda obs: volts


def random_policy(runner: TaskRunner, seed: int = 0) -> Policy:
    """Uniform volts within the action bounds, from a generator seeded with ``seed``."""
    rng = np.random.default_rng(seed)
    lo, hi = runner.action_low, runner.action_high
    return lambda obs: rng.uniform(lo, hi)


def _controller(runner: TaskRunner) -> Controller:
    from trms.experiments.ch8_designs import controllers_for, designs_at
    from trms.experiments.ch8_mimo_lqg import autopilot_controllers
    from trms.worlds import design_model

    twin = runner.twin
    if runner.task.config == "1dof":
        return _as_flown(controllers_for(designs_at(twin.sample_time), twin)[0]["LQG"], twin.sample_time)
    return _as_flown(autopilot_controllers(design_model("2dof", twin.sample_time), twin)["MIMO LQG"], twin.sample_time)


def _as_flown(controller: Controller, sample_time: float) -> Controller:
    """The controller behind the comparison's reference prefilter, filtered sample by sample."""
    from trms.experiments.ch8_designs import reference_prefilter

    return Prefiltered(controller, reference_prefilter(sample_time))


def lqg(runner: TaskRunner) -> Policy:
    """The shipped LQG (see the module docstring), reset at the start of each episode by :func:`episode_return`."""
    return ControllerPolicy(runner, _controller(runner))


def comparison_policy(runner: TaskRunner, name: str) -> Policy:
    """Policy ``name`` of :data:`CONTROLLER_POLICIES`: chapter 8's design for the task's rig (module docstring).

    Raises
    ------
    InputError
        An unknown name.
    ConfigurationError
        The controller needs an extra that is not installed (MPC: osqp; H-infinity: slycot).

    Examples
    --------
    >>> comparison_policy(TaskRunner("PitchTracking"), "PID").controller.sample_time
    0.2
    """
    from trms.experiments import ch8_controllers_mimo as mimo
    from trms.experiments import ch8_designs as siso

    check_choice("policy", name, tuple(CONTROLLER_POLICIES), error=InputError)
    twin = runner.twin
    one_dof = runner.task.config == "1dof"
    if one_dof:
        made, missing = siso.controllers_for(siso.designs_at(twin.sample_time), twin)
    else:
        made, missing = mimo.controllers_for_mimo(mimo.design_controllers_mimo(twin.sample_time), twin)
    key = CONTROLLER_POLICIES[name][0 if one_dof else 1]
    if key in missing:
        raise ConfigurationError(missing[key])
    return ControllerPolicy(runner, _as_flown(made[key], twin.sample_time))


class ControllerPolicy:
    """A controller of the closed-loop runners as a policy: observation in, absolute volts out; ``reset`` starts an
    episode. It reads the encoder angles and the references from the observation.

    Parameters
    ----------
    runner : TaskRunner
    controller : Controller
        Deviation in, deviation out, at the task's sample time.

    Examples
    --------
    >>> runner = TaskRunner("PitchTracking")
    >>> policy = lqg(runner)
    >>> policy(runner.reset(0)).shape
    (1,)
    """

    def __init__(self, runner: TaskRunner, controller: Controller) -> None:
        self.controller = controller
        names = runner.observation_names
        self.angles = [names.index(f"angle:{a}") for a in runner.twin.output_names]
        self.targets = [names.index(f"reference:{a}") for a in runner.twin.output_names]
        self.operating_point = runner.twin.operating_point

    def reset(self) -> None:
        """Reset the controller's state."""
        self.controller.reset()

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        op = self.operating_point
        du = self.controller.update(obs[self.targets], op.output_deviation(obs[self.angles]))
        return op.absolute_input(du)


def episode_return(runner: TaskRunner, policy: Policy, seed: int) -> float:
    """Undiscounted return of one episode of ``runner``'s task under ``policy``, episode seed ``seed``."""
    obs = runner.reset(seed)
    if hasattr(policy, "reset"):
        policy.reset()
    total, done = 0.0, False
    while not done:
        obs, reward, terminated, truncated, _ = runner.step(policy(obs))
        total += reward
        done = terminated or truncated
    return total


@dataclass(frozen=True)
class TaskReturns:
    """Mean episode return of each policy on one task.

    Attributes
    ----------
    task : str
    steps : int
        Steps per episode (the largest possible return).
    returns : dict
        Policy name -> mean return over the episodes (NaN for a policy not run).
    not_run : dict
        Policy name -> why it was not run (the missing extra, named).
    """

    task: str
    steps: int
    returns: dict[str, float]
    not_run: dict[str, str] = field(default_factory=dict)


def _comparison_policy_of(name: str, runner: TaskRunner) -> Policy:
    return comparison_policy(runner, name)


def task_table(
    tasks: Sequence[str] = tuple(TASKS),
    episodes: int = 3,
    seed: int = EVALUATION_SEED,
    policies: Sequence[str] = POLICIES,
) -> list[TaskReturns]:
    """Mean return of every policy of ``policies`` (:data:`POLICIES`) on each task over ``episodes`` seeded episodes.

    A controller whose extra is missing is not run: NaN, and the reason (naming the extra) in ``not_run``.
    """
    if isinstance(tasks, str) or isinstance(policies, str):
        raise InputError("tasks and policies must be sequences of names, not a string (e.g. ['PitchTracking'])")
    episodes = int(check_in_range("episodes", episodes, 1, 10_000))
    names = [check_choice("policy", p, POLICIES, error=InputError) for p in policies]
    for task in tasks:
        check_choice("task", task, tuple(TASKS), error=InputError)
    rows = []
    for name in tasks:
        runner = TaskRunner(name)
        makers: dict[str, Callable[[TaskRunner], Policy]] = {
            "zero volts": zero_volts,
            "hold trim": hold_trim,
            "LQG": lqg,
            "random": lambda r: random_policy(r, seed),
        }
        for policy_name in CONTROLLER_POLICIES:
            makers[policy_name] = functools.partial(_comparison_policy_of, policy_name)
        returns, not_run = {}, {}
        for policy_name in names:
            try:
                policy = makers[policy_name](runner)
            except ConfigurationError as exc:
                returns[policy_name], not_run[policy_name] = float("nan"), " ".join(str(exc).split())
                continue
            returns[policy_name] = float(np.mean([episode_return(runner, policy, seed + i) for i in range(episodes)]))
        rows.append(TaskReturns(name, runner.task.n_steps, returns, not_run))
    return rows


def format_table(rows: Sequence[TaskReturns]) -> str:
    """The task table as Markdown: task, steps, and each policy's mean return; a policy not run says so, and why
    (the missing extra) under the table.

    Examples
    --------
    >>> row = TaskReturns("PitchTracking", 300, {"LQG": 250.0, "MPC": float("nan")}, {"MPC": "needs osqp"})
    >>> print(format_table([row]))
    | task | steps | LQG return | MPC return |
    |---|---:|---:|---:|
    | trms/PitchTracking-v0 | 300 | 250.0 | not run |
    <BLANKLINE>
    not run: MPC: needs osqp
    """
    names = [p for p in POLICIES if any(p in r.returns for r in rows)]
    lines = [
        "| task | steps | " + " | ".join(f"{p} return" for p in names) + " |",
        "|---|---:|" + "---:|" * len(names),
    ]
    why: dict[str, str] = {}
    for r in rows:
        cells = ["not run" if p in r.not_run else f"{r.returns[p]:.1f}" if p in r.returns else "-" for p in names]
        lines.append(f"| trms/{r.task}-v0 | {r.steps} | " + " | ".join(cells) + " |")
        why.update(r.not_run)
    if why:
        lines += [""] + [f"not run: {p}: {reason}" for p, reason in why.items()]
    return "\n".join(lines)
