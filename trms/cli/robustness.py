"""``trms robustness``: Monte Carlo of the closed loops under a spread of the twin's parameters, as Dask tasks."""

from __future__ import annotations

import argparse

from trms.experiments.ch8 import robustness as rb

__all__ = ["NAME", "HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run"]

NAME = "robustness"
HELP = "Monte Carlo of the closed loops under a parameter spread (Dask)"
DESCRIPTION = (
    "Run both robustness loops on N seeded parameter samples of the twin as Dask tasks "
    "and write the success rates and metric distributions (JSON), histograms (PNG) and "
    "the worst cases as Records that `trms render` replays."
)
EPILOG = """examples:
  trms robustness --n 100 --out robustness               # 100 parameter samples on a local Dask cluster
  trms robustness --n 400 --workers 4 --spread 0.3 --out wide
  trms robustness --n 1000 --scheduler tcp://host:8786 --out big
  trms render robustness/worst_1_dof_csas_r_125_lpf_0_2_hz_1_sample17.npz --out worst.gif  # a worst case it wrote
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``trms robustness``."""
    p.add_argument("--n", type=int, default=100, help="samples (default 100)")
    p.add_argument("--seed", type=int, default=0, help="seed of the study (default 0)")
    p.add_argument("--spread", type=float, default=rb.SPREAD, help=f"relative parameter spread (default {rb.SPREAD})")
    p.add_argument("--backend", default="cpu", choices=list(rb.BACKENDS), help="physics: cpu (mujoco.rollout) or mjx")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=None, help="local Dask cluster of N worker processes (default 1)")
    where.add_argument("--scheduler", default=None, help="a running Dask scheduler, e.g. tcp://host:8786")
    p.add_argument("--chunk-size", type=int, default=None, help="samples per task (default 16)")
    p.add_argument("--worst", type=int, default=3, help="worst cases per loop saved as Records (default 3)")
    p.add_argument("--out", default="robustness", help="output folder (default ./robustness)")


def run(args: argparse.Namespace) -> int:
    """Run ``trms robustness``: the study, its files, the success rates; return the exit status."""
    from trms.experiments.ch8.robustness import run_study

    res = run_study(
        args.n,
        args.seed,
        args.out,
        backend=args.backend,
        workers=args.workers,
        scheduler=args.scheduler,
        spread=args.spread,
        worst=args.worst,
        chunk_size=args.chunk_size,
    )
    for name, loop in res["summary"]["loops"].items():
        print(f"{name}: success {loop['success_rate']:.1%} ({loop['status_counts']})")
    print(f"{args.n} samples in {res['seconds']:.1f} s ({args.backend})")
    for path in [res["json"], *res["histograms"], *res["records"]]:
        print(f"wrote {path}")
    return 0
