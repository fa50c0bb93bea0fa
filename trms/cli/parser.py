"""The one parser of the ``trms`` command, built from each command module's ``add_arguments``."""

from __future__ import annotations

import argparse
from types import ModuleType
from typing import NoReturn

from trms.cli.options import add_debug_option

__all__ = ["UsageError", "Parser", "commands", "build_parser"]


class UsageError(Exception):
    """A command line argparse refused (reported as one line, exit 2)."""


class Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors become one line on stderr (through :func:`trms.cli.command.run_command`),
    not usage + message."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(f"{self.prog}: error: {' '.join(message.split())} (see {self.prog} --help)")


def commands() -> tuple[ModuleType, ...]:
    """The command modules, in the order ``trms --help`` lists them.

    Imported when the parser is built, inside :func:`trms.cli.command.run_command`: a Ctrl-C while they load is
    still one line.
    """
    from trms.cli import (
        calibrate,
        compare_controllers,
        demo,
        design,
        identify,
        import_,
        render,
        reproduce,
        robustness,
        run,
        simulate,
    )

    return (
        reproduce,
        simulate,
        identify,
        design,
        run,
        compare_controllers,
        render,
        import_,
        calibrate,
        robustness,
        demo,
    )


def build_parser() -> argparse.ArgumentParser:
    """The ``trms`` parser: one subcommand per module of :func:`commands`, each with ``--debug``."""
    from trms import __version__

    parser = Parser(
        prog="trms",
        description="TRMS digital twin: the thesis's experiments on the "
        "linear model and on the MuJoCo twin; simulate, identify, control, render.",
    )
    add_debug_option(parser)
    parser.add_argument("--version", action="version", version=f"trms {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for command in commands():
        p = sub.add_parser(
            command.NAME,
            help=command.HELP,
            description=command.DESCRIPTION,
            epilog=command.EPILOG,
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )
        p.set_defaults(func=command.run)
        add_debug_option(p)
        command.add_arguments(p)
    return parser
