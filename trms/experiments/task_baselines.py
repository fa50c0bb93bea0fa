"""Baseline returns of the twin's control tasks (:mod:`trms.envs.tasks`): doing nothing, the shipped LQG, random.

Four policies on every task, each given the observation vector and returning absolute volts:

* ``zero volts`` -- the zero action (actions are absolute volts): both motors off;
* ``hold trim`` -- doing nothing: the hover trim voltages at every step;
* ``LQG`` -- the shipped integral LQG: on the 1-DOF task the design of chapters 6/7 on the thesis's
  model eq. (3.11) (:func:`trms.experiments.ch67_lqg.design`, ``R`` = the first of
  :data:`trms.reference.LQG_WEIGHTS_R`); on the 2-DOF tasks the MIMO LQG of chapter 8
  (:func:`trms.experiments.ch8_mimo_lqg.controllers`, its weights) at chapter 8's design choice of ``R``
  (:func:`trms.experiments.ch8_mimo_lqg.design_r_weight`: the smallest ``r`` of a scan whose loop on the
  twin's linearisation has adequate margins), the same controller the report runs.
  It reads only the encoder angles and the reference from the observation;
* ``random`` -- volts drawn uniformly within +-10 V (seeded).

:func:`task_table` runs them over seeded episodes (seeds 1000, 1001, ...: no policy is tuned on
them) and returns the mean episode return of each.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from trms.control.loop import deviation_limits
from trms.control.lqg import LQGController
from trms.envs.tasks import TASKS, TaskRunner
from trms.reference import LQG_WEIGHTS_R

__all__ = [
    "POLICIES",
    "EVALUATION_SEED",
    "Policy",
    "zero_volts",
    "hold_trim",
    "lqg",
    "random_policy",
    "episode_return",
    "TaskReturns",
    "task_table",
    "format_table",
]

#: Policy names, in the table's column order.
POLICIES = ("zero volts", "hold trim", "LQG", "random")
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


def _controller(runner: TaskRunner) -> LQGController:
    from trms.experiments import ch8_mimo_lqg as mimo_lqg_ch8
    from trms.experiments import ch67_lqg as lqg_cases
    from trms.worlds import design_model

    twin = runner.twin
    if runner.task.config == "1dof":
        model = design_model("1dof", twin.sample_time)
        lo, hi = deviation_limits(twin)
        return LQGController(lqg_cases.design(model, LQG_WEIGHTS_R[0]), (lo[0], hi[0]))
    ctrl = mimo_lqg_ch8.controllers(design_model("2dof", twin.sample_time), limits=deviation_limits(twin))["MIMO LQG"]
    assert isinstance(ctrl, LQGController)
    return ctrl


def lqg(runner: TaskRunner) -> Policy:
    """The shipped LQG (see the module docstring), reset at the start of each episode by :func:`episode_return`."""
    return _LqgPolicy(runner)


class _LqgPolicy:
    """The shipped LQG as a policy: observation in, absolute volts out; ``reset`` starts an episode."""

    def __init__(self, runner: TaskRunner) -> None:
        self.controller = _controller(runner)
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
        Policy name -> mean return over the episodes.
    """

    task: str
    steps: int
    returns: dict[str, float]


def task_table(
    tasks: Sequence[str] = tuple(TASKS), episodes: int = 3, seed: int = EVALUATION_SEED
) -> list[TaskReturns]:
    """Mean return of every policy of :data:`POLICIES` on each task over ``episodes`` seeded episodes."""
    rows = []
    for name in tasks:
        runner = TaskRunner(name)
        makers = {
            "zero volts": zero_volts,
            "hold trim": hold_trim,
            "LQG": lqg,
            "random": lambda r: random_policy(r, seed),
        }
        returns = {}
        for policy_name in POLICIES:
            policy = makers[policy_name](runner)
            returns[policy_name] = float(np.mean([episode_return(runner, policy, seed + i) for i in range(episodes)]))
        rows.append(TaskReturns(name, runner.task.n_steps, returns))
    return rows


def format_table(rows: Sequence[TaskReturns]) -> str:
    """The task table as Markdown: task, steps, and each policy's mean return."""
    lines = [
        "| task | steps | " + " | ".join(f"{p} return" for p in POLICIES) + " |",
        "|---|---:|" + "---:|" * len(POLICIES),
    ]
    for r in rows:
        lines.append(f"| trms/{r.task}-v0 | {r.steps} | " + " | ".join(f"{r.returns[p]:.1f}" for p in POLICIES) + " |")
    return "\n".join(lines)
