"""The ``trms`` command once its modules are loaded: the one place every failure becomes one line.

:func:`trms.cli.main` (the console script) imports this module inside its Ctrl-C guard: numpy, MuJoCo and the
commands' modules load here, and an interrupt while they do is one line too.
"""

from __future__ import annotations

import contextlib
import errno
import os
import sys
import traceback
import warnings
from collections.abc import Iterator, Sequence

from trms.cli.interrupt import command_name, interrupted
from trms.cli.parser import UsageError, build_parser
from trms.errors import InputError, TrmsError

__all__ = ["run_command"]


@contextlib.contextmanager
def _quiet_mujoco() -> Iterator[None]:
    """Silence MuJoCo's printed warnings during a command: the twin checks every warning counter
    after each interval and raises (one line), so the printout would only add lines to stderr."""
    import mujoco

    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: None)
    try:
        yield
    finally:
        mujoco.set_mju_user_warning(previous)


def _one_line(command: str, exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or "(no message)"
    if isinstance(exc, TrmsError):
        return f"trms {command}: error: {text}"
    if isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, errno.EDQUOT):
        where = f" writing {str(exc.filename)!r}" if exc.filename else ""
        return f"trms {command}: error: no space left on the device{where}; nothing was written, old files are kept"
    if isinstance(exc, (OSError, ValueError)):  # a file or a value the command could not use
        return f"trms {command}: error: {type(exc).__name__}: {text}"
    return f"trms {command}: internal error: {type(exc).__name__}: {text} (rerun with --debug for the traceback)"


def run_command(argv: Sequence[str]) -> int:
    """Parse ``argv`` and run the command; returns the exit status.

    Every failure -- a refused argument, a bad file, a diverged simulation, an unexpected error --
    ends as one line on stderr and status 2; ``--debug`` prints the traceback too. Python warnings
    of a successful command are printed after it, one line each. Ctrl-C (``KeyboardInterrupt``) is
    left to :func:`trms.cli.main`, which guards the imports too.

    Examples
    --------
    >>> run_command(["design", "--q", "-1"])  # doctest: +SKIP
    2
    """
    argv = list(argv)
    debug = "--debug" in argv[: argv.index("--")] if "--" in argv else "--debug" in argv
    command = command_name(argv)
    try:
        args = build_parser().parse_args(argv)
        command = args.command
        for option in ("out", "mjcf"):  # an empty name would write into the current folder
            if getattr(args, option, None) == "":
                raise InputError(f"--{option} is an empty name; give a file or folder name")
        with warnings.catch_warnings(record=True) as caught, _quiet_mujoco():
            warnings.simplefilter("always")
            status = int(args.func(args))
        for w in caught:
            print(f"trms {command}: warning: {' '.join(str(w.message).split())}", file=sys.stderr)
        sys.stdout.flush()
        return status
    except BrokenPipeError:
        # The reader of stdout went away (`trms ... | head -1`): stop quietly. Python would flush stdout
        # again at exit and complain, so point stdout at devnull first (the Python docs' SIGPIPE recipe).
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1
    except UsageError as exc:
        print(str(exc), file=sys.stderr)
        return 2
    except Exception as exc:  # noqa: BLE001 -- the one place every failure becomes one line
        if interrupted():  # Ctrl-C, become another error on its way (an interrupted import): one line, 130
            raise KeyboardInterrupt from exc
        if debug:
            traceback.print_exc()
        print(_one_line(command, exc), file=sys.stderr)
        return 2
