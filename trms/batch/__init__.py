"""Many closed loops at once: stacked controllers and ``mujoco.rollout`` on every core, MJX on a GPU
(the optional ``trms[mjx]`` extra), and Monte Carlo studies as Dask tasks on one machine or many."""

from trms.batch.controllers import StackedDiagonal, StackedLoops, StackedLQG, stack_controllers
from trms.batch.loop import BatchResult, batch_closed_loop

__all__ = ["BatchResult", "StackedDiagonal", "StackedLoops", "StackedLQG", "batch_closed_loop", "stack_controllers"]
