"""Atomic file writes: a reader never sees a half-written file, a killed writer leaves nothing behind.

Every file :mod:`trms` writes goes through :func:`atomic_write`: the content is written to a
temporary file in the same folder, named for the target and the writing process
(``.NAME.PID.RANDOM.trms-tmp``), flushed to disk and renamed over the target with
``os.replace``. A writer killed by SIGKILL cannot remove its temporary file, so each write first
sweeps the folder's temporary files whose process is no longer alive.
"""

from __future__ import annotations

import os
import secrets
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

__all__ = ["atomic_write", "sweep_temporary_files", "TEMP_SUFFIX"]

#: Suffix of the temporary files written by :func:`atomic_write`.
TEMP_SUFFIX = ".trms-tmp"


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def sweep_temporary_files(folder: str | os.PathLike[str]) -> list[Path]:
    """Delete the temporary files of writers that died in ``folder``; return what was removed.

    Only files named by :func:`atomic_write` (``.NAME.PID.RANDOM.trms-tmp``) whose process ``PID``
    is not running are removed; files of live writers (in this or another process) are kept.

    Examples
    --------
    >>> import tempfile
    >>> sweep_temporary_files(tempfile.mkdtemp())
    []
    """
    removed = []
    for p in Path(folder).glob(f".*{TEMP_SUFFIX}"):
        parts = p.name[: -len(TEMP_SUFFIX)].rsplit(".", 2)
        if len(parts) != 3 or not parts[1].isdigit() or _alive(int(parts[1])):
            continue
        try:
            p.unlink()
            removed.append(p)
        except FileNotFoundError:  # another sweeper was faster
            pass
    return removed


def atomic_write(path: str | os.PathLike[str], write: Callable[[IO[Any]], object], *, binary: bool = True) -> Path:
    """Write ``path`` atomically: ``write(fh)`` fills a temporary file that then replaces ``path``.

    Parameters
    ----------
    path : path-like
        Target file; its folder is created if needed.
    write : callable
        ``write(fh)`` writes the whole content to the open file ``fh``.
    binary : bool
        Open the temporary file in binary (default) or text mode (UTF-8, ``newline=""``).

    Returns
    -------
    pathlib.Path
        ``path``. On any failure the old file (if any) is untouched and no temporary file is left.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = atomic_write(pathlib.Path(tempfile.mkdtemp()) / "a.txt", lambda fh: fh.write("hi"), binary=False)
    >>> p.read_text()
    'hi'
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    sweep_temporary_files(path.parent)
    tmp = path.parent / f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}{TEMP_SUFFIX}"
    try:
        handle: IO[Any] = open(tmp, "wb") if binary else open(tmp, "w", encoding="utf-8", newline="")
        with handle as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path
