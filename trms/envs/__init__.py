"""Control tasks on the twin as environments: the task definitions, the dm_env suite and Gymnasium.

Modules
-------
trms.envs.tasks  the tasks (what an episode is) and the one runner both APIs wrap
trms.envs.suite  dm_env environments (``load(name)``; ``env.physics`` for the dm_control viewer)
trms.envs.gym    Gymnasium environments (``import trms.envs.gym`` registers ``trms/<Task>-v0``)
trms.envs.vector a Gymnasium vector environment: N of one task, stepped side by side in one process a core
trms.envs.shares the vector environment's shares of environments, one a process, their rows in shared memory

Nothing is imported here, so ``import trms.envs`` loads neither MuJoCo's renderer nor Gymnasium.
"""

__all__: list[str] = []
