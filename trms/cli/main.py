"""The entry point of the ``trms`` command: the one place every failure becomes one line."""

from __future__ import annotations

import contextlib
import errno
import os
import sys
import traceback
import warnings
from collections.abc import Iterator, Sequence

from trms.cli.parser import UsageError, build_parser
from trms.errors import TrmsError

__all__ = ["main"]


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


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``trms`` command; returns the exit status.

    Every failure -- a refused argument, a bad file, a diverged simulation, an unexpected error --
    ends as one line on stderr and status 2; ``--debug`` prints the traceback too. Ctrl-C ends as one
    line and status 130. Python warnings
    of a successful command are printed after it, one line each.

    Examples
    --------
    >>> main(["design", "--q", "-1"])  # doctest: +SKIP
    2
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv[: argv.index("--")] if "--" in argv else "--debug" in argv
    command = next((a for a in argv if not a.startswith("-")), "?")  # named in a Ctrl-C during the parse
    try:
        args = build_parser().parse_args(argv)
        command = args.command
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
    except KeyboardInterrupt:
        # Ctrl-C: one line and the shell's status for SIGINT (128 + 2); files are written atomically, so none is
        # left half-written, and the workers of a parallel run stop with the parent.
        print(f"trms {command}: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # noqa: BLE001 -- the one place every failure becomes one line
        if debug:
            traceback.print_exc()
        print(_one_line(command, exc), file=sys.stderr)
        return 2
