"""The report's folder: one run's files and nothing else, built aside and swapped in whole.

A report folder holds one run: :func:`trms.report.reproduce` builds the new report beside the old one and swaps it in
at the end (:func:`trms.files.atomic_folder`), so a reader, a failure or a SIGKILL at any moment leaves the old
report or the new one, never figures of one beside the tables of the other. Each run lists its files in the
folder's manifest (:data:`MANIFEST`); a folder that holds files no trms run wrote -- someone's own ``report.md``,
their notes -- is refused, naming them (:func:`check_folder`), unless ``force``: they are then kept in the new
folder beside the report, except those the report itself writes.
"""

from __future__ import annotations

import json
import os
import shutil
import warnings
from pathlib import Path

from trms.errors import InputError
from trms.files import TEMP_SUFFIX, atomic_write

__all__ = ["MANIFEST", "TITLE", "check_folder", "keep_files", "write_manifest"]

#: The manifest of a report folder: the files its run wrote (JSON, names relative to the folder).
MANIFEST = ".trms-report.json"
#: The first line of every report.md a trms run writes (how a folder of a run before manifests is known).
TITLE = "# TRMS: the thesis on the linear model and on the twin"
#: The files a run wrote before the manifest existed (recognised by :data:`TITLE`).
_LEGACY = ("report.md", "report.html", "tables.json", "figures/")
#: Foreign files named in a message, at most.
_NAMED = 5


def _files(folder: Path) -> list[str]:
    """Every file under ``folder`` (relative, ``/``-separated), temporary files of interrupted writes left out."""
    out = []
    for path in sorted(folder.rglob("*")):
        if (path.is_file() or path.is_symlink()) and not path.name.endswith(TEMP_SUFFIX):
            out.append(path.relative_to(folder).as_posix())
    return out


def _written(folder: Path) -> set[str]:
    """The files of ``folder`` that a trms run wrote: its manifest's, or a run's before manifests existed."""
    manifest = folder / MANIFEST
    try:
        listed = json.loads(manifest.read_text())["files"]
        return {str(n) for n in listed} | {MANIFEST}
    except (OSError, ValueError, KeyError, TypeError):
        pass
    try:
        with open(folder / "report.md", encoding="utf-8") as fh:
            legacy = fh.readline().rstrip("\n") == TITLE
    except (OSError, UnicodeDecodeError):
        legacy = False
    return {f for f in _files(folder) if legacy and f.startswith(_LEGACY)}


def check_folder(out: str | os.PathLike[str], force: bool = False) -> list[str]:
    """Refuse a report folder the run cannot replace whole; return the files no trms run wrote (kept with ``force``).

    Parameters
    ----------
    out : path-like
        The report folder (need not exist).
    force : bool
        Accept a folder holding files no trms run wrote (they are kept beside the new report).

    Returns
    -------
    list of str
        The folder's files that no trms run wrote (relative names); empty without ``force``.

    Raises
    ------
    InputError
        An empty name, a file, the current folder or one that holds it, or (without ``force``) a folder holding
        files no trms run wrote, named.

    Examples
    --------
    >>> check_folder("")
    Traceback (most recent call last):
    ...
    trms.errors.InputError: the report folder's name is empty; give a folder, e.g. --out report
    """
    if not str(out):
        raise InputError("the report folder's name is empty; give a folder, e.g. --out report")
    folder = Path(out)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"report folder {str(folder)!r} is a file; give a folder for the report")
    if not folder.exists():
        return []
    here = Path.cwd().resolve()
    if here == folder.resolve() or folder.resolve() in here.parents:
        raise InputError(
            f"report folder {str(folder)!r} is the current folder or holds it, and the report replaces its folder "
            "whole; give a folder of its own, e.g. --out report"
        )
    foreign = [f for f in _files(folder) if f not in _written(folder)]
    if foreign and not force:
        more = f" and {len(foreign) - _NAMED} more" if len(foreign) > _NAMED else ""
        raise InputError(
            f"report folder {str(folder)!r} holds {len(foreign)} file(s) no trms run wrote: "
            f"{', '.join(foreign[:_NAMED])}{more}; the report replaces its folder whole: give another --out, or "
            "--force to write it there and keep them"
        )
    return foreign


def keep_files(foreign: list[str], old: Path, new: Path) -> list[str]:
    """Link (or copy) the files no trms run wrote from the ``old`` folder into the ``new`` one; return those kept.

    A file the new report writes itself replaces the old one (a warning names it).
    """
    kept, replaced = [], []
    for name in foreign:
        src, dst = old / name, new / name
        if dst.exists() or dst.is_symlink():
            replaced.append(name)
            continue
        dst.parent.mkdir(parents=True, exist_ok=True)
        try:
            os.link(src, dst, follow_symlinks=False)
        except OSError:  # a file system without hard links, or across devices
            shutil.copy2(src, dst, follow_symlinks=False)
        kept.append(name)
    if replaced:
        warnings.warn(
            f"--force: the report replaced {len(replaced)} file(s) no trms run wrote: {', '.join(replaced[:_NAMED])}",
            stacklevel=2,
        )
    return kept


def write_manifest(folder: Path, others: list[str]) -> Path:
    """List the run's files in ``folder``'s :data:`MANIFEST` (all its files but ``others``, which no run wrote)."""
    files = [f for f in _files(folder) if f not in set(others)]
    data = {"format": "trms.report-files/1", "files": files}
    return atomic_write(folder / MANIFEST, lambda fh: fh.write(json.dumps(data, indent=1)), binary=False)
