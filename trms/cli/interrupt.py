"""Ctrl-C in the ``trms`` command: the handler :func:`trms.cli.main` installs first, and what it has seen.

Light on purpose (``signal`` alone): it is imported before numpy and MuJoCo, so that an interrupt while they load
is caught too.
"""

from __future__ import annotations

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing (type checkers take this name as true)
if TYPE_CHECKING:
    from collections.abc import Sequence
    from types import FrameType

__all__ = ["INTERRUPTED", "command_name", "interrupted", "on_sigint"]

#: Status of a command ended by Ctrl-C: the shell's 128 + SIGINT.
INTERRUPTED = 130
#: Ctrl-C presses :func:`on_sigint` has received in this process (its own handler counts them).
_PRESSES: list[int] = []


def command_name(argv: Sequence[str]) -> str:
    """The subcommand ``argv`` names (its first word that is no option), for a message before it is parsed.

    Examples
    --------
    >>> command_name(["--debug", "simulate", "--out", "x.npz"])
    'simulate'
    """
    return next((a for a in argv if not a.startswith("-")), "?")


def interrupted() -> bool:
    """Whether the command was interrupted (Ctrl-C), even where the ``KeyboardInterrupt`` became another error.

    An extension module whose initialisation is interrupted (numpy, matplotlib) raises an ``ImportError`` instead:
    :func:`trms.cli.command.run_command` asks this before it reports an error.

    Examples
    --------
    >>> interrupted()
    False
    """
    return bool(_PRESSES)


def on_sigint(signum: int, frame: FrameType | None) -> None:
    """Python's own Ctrl-C handler (raise ``KeyboardInterrupt``), counting the press.

    Examples
    --------
    >>> try:
    ...     on_sigint(2, None)
    ... except KeyboardInterrupt:
    ...     print(interrupted())
    ...     _PRESSES.clear()
    True
    """
    _PRESSES.append(signum)
    raise KeyboardInterrupt
