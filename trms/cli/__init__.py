"""The ``trms`` command: argument parsing and printing only; the work lives in the package.

Subcommands
-----------
reproduce
    The main job: every experiment of the thesis on the linear model and on the twin, written as a
    report folder (Markdown, HTML, PNG figures, a GIF render, tables as JSON).
simulate
    A configuration and an input signal (generated or read from a file) -> a Record.
identify
    A Record -> an ARMAX model (JSON), residual tests, spectra and validation figures.
design
    Integral LQG gains, estimator and prefilter for given weights (JSON).
run
    A closed loop (SAS/CSAS, or the 2-DOF autopilot) on the twin or the linear model.
render
    A twin Record -> PNG (last frame), GIF or MP4.
robustness
    Monte Carlo of the closed loops under a spread of the twin's parameters, as Dask tasks.
import
    A rig's CSV export (time column, named columns, degrees or radians) -> a Record with its operating point.
calibrate
    Fit the twin's physical parameters to the thesis's targets, or to your rig's records in the time
    domain, and write them into a new MJCF.
demo
    Trim the rig at hover, print its modes, excite it with a small PRBS, write a record and renders.

Every subcommand writes files, prints a summary, and exits with status 2 and a one-line message
on stderr on any failure (a missing file, a wrong shape, an unknown option, a simulation that
diverged); ``--debug`` shows the traceback instead. Output files are written only once the work
has succeeded, each atomically (:mod:`trms.files`). Durations and amplitudes are capped
(:data:`~trms.cli.options.MAX_DURATION`, :data:`~trms.cli.options.MAX_AMPLITUDE_V`,
:data:`~trms.cli.options.MAX_AMPLITUDE_RAD`); ``--max-duration`` and ``--max-amplitude`` raise the caps.

One module per command (:mod:`trms.cli.simulate`, ...) holds its options (``add_arguments``) and its run
(``run``); :mod:`trms.cli.parser` builds the one parser from them and :mod:`trms.cli.command` runs it.

Ctrl-C ends every command with one line (``trms COMMAND: interrupted``) and status 130, from the first instant:
this module imports nothing heavy, and :func:`main` loads numpy, MuJoCo and the commands inside its guard.
"""

from __future__ import annotations

import os
import signal
import sys

from trms.cli.interrupt import INTERRUPTED, command_name, interrupted, on_sigint

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing (type checkers take this name as true)
if TYPE_CHECKING:
    from collections.abc import Sequence

__all__ = ["main", "MAX_DURATION", "MAX_AMPLITUDE_V", "MAX_AMPLITUDE_RAD", "DEMO_AMPLITUDE"]


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``trms`` command (the console script and ``python -m trms.cli``); returns the exit status.

    Every failure ends as one line on stderr and status 2 (:func:`trms.cli.command.run_command`); Ctrl-C as one
    line and status 130 at any moment, the imports of numpy and MuJoCo included: this module imports nothing but
    ``os``, ``signal`` and ``sys``, the interrupt handler is in place before anything else loads, and the
    interrupt is caught here. Files are written atomically, so none is left half-written, and the workers of a
    parallel run stop with the command (their ``finally`` blocks have run when the interrupt gets here).

    A command line's own run (``argv`` None, in the main thread) then ends the process at once (``os._exit``):
    an interrupted import can leave an extension module that crashes the interpreter's shutdown, and an interrupt
    inside code that Python ran from a string (a dataclass, a named tuple) makes it end by SIGINT instead of 130.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments (default: the process's command line).

    Examples
    --------
    >>> main(["design", "--q", "-1"])  # doctest: +SKIP
    2
    """
    args = list(sys.argv[1:] if argv is None else argv)
    console = False
    if argv is None and signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        try:
            signal.signal(signal.SIGINT, on_sigint)  # (a job started with Ctrl-C ignored keeps it ignored)
            console = True
        except ValueError:  # not the main thread: no handler of its own
            pass
    try:
        from trms.cli.command import run_command  # numpy, MuJoCo and every command's module load here

        status = run_command(args)
        if console and status != INTERRUPTED:  # the work is done and written: a press from here on, while the
            signal.signal(signal.SIGINT, signal.SIG_IGN)  # interpreter shuts down, changes nothing (no SIGINT death)
    except BaseException as exc:
        if not (isinstance(exc, KeyboardInterrupt) or interrupted()):
            raise
        status = INTERRUPTED
    if status == INTERRUPTED or interrupted():
        if console:  # a further press while the line is printed changes nothing
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        print(f"trms {command_name(args)}: interrupted", file=sys.stderr)
        if console:
            for stream in (sys.stdout, sys.stderr):
                try:
                    stream.flush()
                except (OSError, ValueError):  # a closed pipe: nothing more to say
                    pass
            os._exit(INTERRUPTED)
        return INTERRUPTED
    return status


def __getattr__(name: str) -> object:
    """The caps of :mod:`trms.cli.options`, loaded on first use (this module stays light for :func:`main`)."""
    if name in ("MAX_DURATION", "MAX_AMPLITUDE_V", "MAX_AMPLITUDE_RAD", "DEMO_AMPLITUDE"):
        from trms.cli import options

        return getattr(options, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
