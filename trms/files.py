"""Atomic file writes: a reader never sees a half-written file, a killed writer leaves nothing behind.

A whole folder (the report) is built aside and swapped in at once by :func:`atomic_folder`.

Every file :mod:`trms` writes goes through :func:`atomic_write`: the content is written to a
temporary file in the same folder, named for the target and the writing process
(``.NAME.PID.RANDOM.trms-tmp``), flushed to disk and renamed over the target with
``os.replace``. A writer killed by SIGKILL cannot remove its temporary file, so each write first
sweeps the folder's temporary files whose process is no longer alive. A write that fails -- a full
disk (``ENOSPC``, raised at once with the target's name, never retried) or any other error -- removes
its temporary file and keeps the old one; :func:`atomic_group` makes several files one change.
"""

from __future__ import annotations

import contextlib
import contextvars
import errno
import os
import secrets
import stat
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any

from trms.errors import InputError

__all__ = [
    "atomic_write",
    "atomic_group",
    "atomic_folder",
    "readable_file",
    "sweep_temporary_files",
    "TEMP_SUFFIX",
    "BUILDING_SUFFIX",
    "OLD_SUFFIX",
]

#: Suffix of the temporary files written by :func:`atomic_write`.
TEMP_SUFFIX = ".trms-tmp"
#: Errors of a full disk or quota: a write that failed for room, reported with the file it was for.
_NO_ROOM = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)
#: The writes of the innermost :func:`atomic_group`: (temporary file, target), renamed when the group ends.
_GROUP: contextvars.ContextVar[list[tuple[Path, Path]] | None] = contextvars.ContextVar(
    "trms_atomic_group", default=None
)


#: What a path that is no regular file is, by the kind :func:`os.stat` gives.
_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def readable_file(path: str | os.PathLike[str], what: str) -> Path:
    """``path`` as a :class:`~pathlib.Path` to a regular file this process may read, or one line saying why not.

    A folder, a FIFO, a device (``/dev/zero``), a loop of symbolic links or a file without read permission is
    named as what it is (a FIFO or a device would block a reader, or never end).

    Parameters
    ----------
    path : path-like
        The file.
    what : str
        What the file is for, starting the message (e.g. ``"record file"``).

    Returns
    -------
    pathlib.Path

    Raises
    ------
    trms.errors.InputError
        Missing, not a regular file, or not readable.

    Examples
    --------
    >>> readable_file("/dev/zero", "record file")
    Traceback (most recent call last):
    ...
    trms.errors.InputError: record file '/dev/zero' is a character device, not a regular file; allowed: a file
    """
    p = Path(path)
    name = repr(str(p))
    try:
        mode = os.stat(p).st_mode
    except FileNotFoundError:
        raise InputError(f"{what} {name} does not exist") from None
    except OSError as exc:
        reason = "a loop of symbolic links" if exc.errno == errno.ELOOP else (exc.strerror or str(exc)).lower()
        raise InputError(f"{what} {name} cannot be opened: {reason}") from None
    for test, kind in _KINDS:
        if test(mode):
            raise InputError(f"{what} {name} is {kind}, not a regular file; allowed: a file")
    try:
        with open(p, "rb"):
            pass
    except OSError as exc:
        raise InputError(f"{what} {name} cannot be read: {(exc.strerror or str(exc)).lower()}") from None
    return p


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

    Raises
    ------
    OSError
        Naming ``path``: an existing folder there (:class:`IsADirectoryError`), a folder that takes no new file,
        a full disk.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = atomic_write(pathlib.Path(tempfile.mkdtemp()) / "a.txt", lambda fh: fh.write("hi"), binary=False)
    >>> p.read_text()
    'hi'
    """
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "an existing folder, not a file (nothing was written)", str(path))
    path.parent.mkdir(parents=True, exist_ok=True)
    sweep_temporary_files(path.parent)
    tmp = path.parent / f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}{TEMP_SUFFIX}"
    group = _GROUP.get()
    try:
        handle: IO[Any] = open(tmp, "wb") if binary else open(tmp, "w", encoding="utf-8", newline="")
    except OSError as exc:  # the folder takes no new file: say so of the target, not of the temporary name
        folder = f"the folder {str(path.parent)!r} is not writable ({exc.strerror}); nothing was written"
        raise type(exc)(exc.errno, folder, str(path)) from exc
    try:
        with handle as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        if group is None:
            os.replace(tmp, path)
        else:
            group.append((tmp, path))
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        if exc.errno in _NO_ROOM and exc.filename is None:  # name the file that found no room, once
            raise OSError(exc.errno, os.strerror(exc.errno), str(path)) from exc
        raise
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


@contextlib.contextmanager
def atomic_group() -> Iterator[None]:
    """Make the :func:`atomic_write` calls inside the block one change: all files, or none.

    Each write fills its temporary file as usual; the targets are replaced (renamed over, which needs no
    room on the disk) only when the whole block has succeeded. If anything in the block fails (a full
    disk on the second file, an exception of the caller), every temporary file is removed and every old
    file is kept.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> with atomic_group():
    ...     _ = atomic_write(d / "a.txt", lambda fh: fh.write("a"), binary=False)
    ...     (d / "a.txt").exists()
    False
    >>> (d / "a.txt").read_text()
    'a'
    """
    pending: list[tuple[Path, Path]] = []
    token = _GROUP.set(pending)
    try:
        yield
    except BaseException:
        for tmp, _ in pending:
            tmp.unlink(missing_ok=True)
        raise
    finally:
        _GROUP.reset(token)
    for i, (tmp, path) in enumerate(pending):  # renames in one folder: no room is needed, nothing to retry
        try:
            os.replace(tmp, path)
        except BaseException:
            for rest, _ in pending[i:]:
                rest.unlink(missing_ok=True)
            raise


#: Suffixes of a folder being built aside (:func:`atomic_folder`) and of the old one it replaced, until removed.
BUILDING_SUFFIX = ".trms-building"
OLD_SUFFIX = ".trms-old"
#: ``renameat2``'s flag that swaps two paths in one step (Linux 3.15 and later).
_RENAME_EXCHANGE = 2


def _exchange(a: Path, b: Path) -> bool:
    """Swap the folders ``a`` and ``b`` in one step (``renameat2(RENAME_EXCHANGE)``); False where unavailable."""
    import ctypes
    import ctypes.util

    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):  # not Linux, or a C library without it
        return False
    at_cwd = -100
    if renameat2(at_cwd, os.fsencode(a), at_cwd, os.fsencode(b), _RENAME_EXCHANGE) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.ENOTSUP):  # a file system or kernel that cannot swap
        return False
    raise OSError(err, os.strerror(err), str(b))


def _sweep_folders(parent: Path, name: str) -> None:
    """Remove the folders of dead builders of ``name`` in ``parent`` (a SIGKILL leaves them behind)."""
    import shutil

    for suffix in (BUILDING_SUFFIX, OLD_SUFFIX):
        for p in parent.glob(f".{name}.*{suffix}"):
            parts = p.name[: -len(suffix)].rsplit(".", 2)
            if len(parts) == 3 and parts[1].isdigit() and not _alive(int(parts[1])):
                shutil.rmtree(p, ignore_errors=True)


@contextlib.contextmanager
def atomic_folder(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Build a folder aside and swap it in whole: a reader (or a SIGKILL) sees the old folder or the new one.

    The block fills a new folder beside ``path`` (``.NAME.PID.RANDOM.trms-building``); when it ends without an
    error, that folder replaces ``path`` in one step (Linux's ``renameat2(RENAME_EXCHANGE)``; elsewhere two
    renames, with an instant where ``path`` is missing) and the old folder is removed. If the block fails, the new
    folder is removed and ``path`` is untouched. Folders left by a killed builder are removed by the next one.

    Parameters
    ----------
    path : path-like
        The folder to replace (it need not exist; its parent is created).

    Yields
    ------
    pathlib.Path
        The folder to build in.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp()) / "out"
    >>> with atomic_folder(d) as new:
    ...     _ = (new / "a.txt").write_text("a")
    ...     d.exists()
    False
    >>> sorted(p.name for p in d.iterdir())
    ['a.txt']
    """
    import shutil

    target = Path(path)
    if target.exists() and not target.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, "an existing file, not a folder (nothing was written)", str(target))
    parent = target.parent
    parent.mkdir(parents=True, exist_ok=True)
    _sweep_folders(parent, target.name)
    stem = f".{target.name}.{os.getpid()}.{secrets.token_hex(4)}"
    new = parent / f"{stem}{BUILDING_SUFFIX}"
    new.mkdir()
    try:
        yield new
        if not target.exists():
            os.rename(new, target)
            return
        old = parent / f"{stem}{OLD_SUFFIX}"
        if _exchange(new, target):
            os.rename(new, old)  # the old folder, under a name the sweep knows
        else:
            os.rename(target, old)
            os.rename(new, target)
    except BaseException:
        shutil.rmtree(new, ignore_errors=True)
        raise
    shutil.rmtree(old, ignore_errors=True)
