"""The control tasks' table: mean return of doing nothing, the shipped LQG, the other controllers and random volts
(run on demand); a controller whose extra is missing is not run, and the line under the table names the extra.

    python benchmarks/task_table.py [episodes]

Every task of ``trms.envs.tasks.TASKS`` (the Gymnasium ``trms/*-v0`` environments and the dm_env
suite), seeded episodes from ``trms.experiments.task_baselines.EVALUATION_SEED``.
"""

from __future__ import annotations

import sys

from trms.experiments.task_baselines import format_table, task_table


def main() -> None:
    episodes = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    print(f"mean return over {episodes} episodes")
    print(format_table(task_table(episodes=episodes)))


if __name__ == "__main__":
    main()
