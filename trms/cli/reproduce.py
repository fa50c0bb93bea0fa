"""``trms reproduce``: the main job -- every experiment of the thesis on the linear model and on the twin, written
as a report folder (Markdown, HTML, PNG figures, a GIF render, tables as JSON)."""

from __future__ import annotations

import argparse
import sys

from trms.cli.options import say

__all__ = ["NAME", "HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run"]

NAME = "reproduce"
HELP = "run every experiment and write the report (the main job)"
DESCRIPTION = (
    "Run every experiment of the thesis on the linear model and on the twin and write a report folder: "
    "report.md and report.html (thesis | linear model | twin | notes), PNG figures, a GIF render, tables.json."
)
EPILOG = """examples:
  trms reproduce                       # full report into ./report
  trms reproduce --quick --out /tmp/r  # reduced run, under a minute

The report folder is built aside and swapped in whole at the end: an interrupted or killed run leaves the
previous report as it was.
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``trms reproduce``."""
    p.add_argument(
        "--out",
        default="report",
        help="report folder (default: ./report), replaced whole when the run has succeeded; one holding files no "
        "trms run wrote is refused (named) unless --force",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="write into a --out folder that holds files no trms run wrote (kept beside the report, but for those "
        "the report writes itself)",
    )
    p.add_argument("--quick", action="store_true", help="reduced run (under a minute), every table still filled")
    p.add_argument("--seed", type=int, default=0, help="seed of everything random (default 0)")
    p.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")


def run(args: argparse.Namespace) -> int:
    """Run ``trms reproduce``; return the exit status (1 when a cell of the report is missing)."""
    from trms.report import reproduce

    report = reproduce(args.out, quick=args.quick, seed=args.seed, workers=args.workers, progress=say, force=args.force)
    print()
    for line in report.sections[0].paragraphs[:2]:  # the twin at a glance: hover voltages and modes per configuration
        print(line)
    print()
    print(report.headline.to_markdown())
    print(f"wall time {report.seconds:.1f} s ({'quick' if args.quick else 'full'} run)")
    for path in report.files.values():
        print(f"wrote {path}")
    missing = report.missing()
    if missing:
        print("incomplete cells: " + "; ".join(missing), file=sys.stderr)
        return 1
    return 0
