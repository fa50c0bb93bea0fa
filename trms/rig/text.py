"""A rig's text export (CSV) as columns of numbers: its encoding, its delimiter (comma, semicolon, tab or
whitespace, found from the data), its header among title and comment lines, quoted fields and decimal commas."""

from __future__ import annotations

import csv
import re
from pathlib import Path
from typing import Any

import numpy as np

from trms.errors import InputError
from trms.rig.checks import ExportLayout
from trms.rig.mat import is_mat_header

__all__ = ["decode_export", "read_text_columns"]

#: Bytes that never occur in a text export (control characters other than tab, newlines, form feed, ^Z).
_BINARY = re.compile(rb"[\x00-\x08\x0e-\x19\x1b-\x1f\x7f]")
#: Candidate delimiters, in order of preference on a tie; ``None`` is a run of whitespace.
_DELIMITERS: tuple[str | None, ...] = (",", ";", "\t", None)
_DELIMITER_NAMES = {",": "comma", ";": "semicolon", "\t": "tab", None: "whitespace"}


def decode_export(raw: bytes, path: Path) -> tuple[str, str]:
    """The text of an export and its encoding (UTF-16 with a byte-order mark, UTF-8, else Latin-1).

    Raises
    ------
    InputError
        A zip archive (a saved Record), a MATLAB file, or binary data, in one line naming the file.

    Examples
    --------
    >>> decode_export("t,pitch [°]".encode("latin-1"), Path("rig.csv"))
    ('t,pitch [°]', 'latin-1')
    """
    if raw.startswith(b"PK\x03\x04"):
        raise InputError(
            f"{str(path)!r} is a zip archive (a saved Record .npz?), not a CSV export; "
            "a saved Record needs its .npz name, a rig's export is text (.csv) or MATLAB (.mat)"
        )
    if is_mat_header(raw):
        raise InputError(f"{str(path)!r} is a MATLAB file, not a CSV export; give it its .mat name")
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        try:
            return raw.decode("utf-16"), "utf-16"
        except UnicodeDecodeError:
            pass
    bad = _BINARY.search(raw)
    if bad is not None:
        raise InputError(
            f"{str(path)!r} is not a text export: byte 0x{raw[bad.start()]:02x} at offset {bad.start()} is "
            "binary data; expected a CSV with a header row and one row of numbers per sample"
        )
    try:
        return raw.decode("utf-8-sig"), "utf-8"
    except UnicodeDecodeError:
        return raw.decode("latin-1"), "latin-1"


def _fields(line: str, delimiter: str | None) -> list[str]:
    """The fields of a line, trailing empty ones (a delimiter at the end of the line) dropped."""
    cells = line.split() if delimiter is None else line.split(delimiter)
    while cells and not cells[-1].strip():
        cells.pop()
    return cells


def _is_number(cell: str, delimiter: str | None) -> bool:
    try:
        float(_number_text(cell, delimiter))
    except ValueError:
        return False
    return True


def _number_text(cell: str, delimiter: str | None) -> str:
    """A cell as Python reads numbers: stripped, a decimal comma read as a point where commas do not delimit."""
    cell = cell.strip().strip('"').strip()
    return cell.replace(",", ".") if delimiter != "," else cell


def _sniff(content: list[tuple[int, str]]) -> tuple[str | None, int | None]:
    """The delimiter and the index (into ``content``) of the first data row: the delimiter that gives the
    longest run of rows of the same number (at least 2) of numeric fields."""
    best: tuple[tuple[int, int], str | None, int | None] = ((-1, -1), ",", None)
    head = content[:400]
    for d in _DELIMITERS:
        start = nf = None
        for i, (_, text) in enumerate(head):
            cells = _fields(text, d)
            if len(cells) >= 2 and all(_is_number(c, d) for c in cells):
                start, nf = i, len(cells)
                break
        if start is None or nf is None:
            continue
        run = 1
        for _, text in head[start + 1 : start + 50]:
            cells = _fields(text, d)
            if len(cells) != nf or not all(_is_number(c, d) for c in cells):
                break
            run += 1
        if (run, nf) > best[0]:
            best = ((run, nf), d, start)
    if best[2] is None and content:  # no data row: the delimiter that splits the header most
        counts = [len(_fields(content[0][1], d)) for d in _DELIMITERS]
        return _DELIMITERS[int(np.argmax(counts))], None
    return best[1], best[2]


def _parse(lines: list[str], delimiter: str | None, first_line: list[int], path: Path) -> list[list[str]]:
    """Split ``lines`` into fields (quoted fields allowed); a field beyond the csv module's limit is one line."""
    if delimiter is None:
        return [[c.strip('"') for c in ln.split()] for ln in lines]
    reader = csv.reader(lines, delimiter=delimiter)
    try:
        return [row for row in reader]
    except csv.Error as exc:
        line = first_line[min(reader.line_num, len(first_line)) - 1] if first_line else 1
        raise InputError(
            f"line {line} of {str(path)!r} has a field longer than {csv.field_size_limit()} characters ({exc}); "
            "a rig's export holds column names and numbers"
        ) from None


def read_text_columns(path: Path, layout: ExportLayout) -> tuple[np.ndarray, list[int], list[str], dict[str, Any]]:
    """The wanted columns of a text export as floats, the file line of each row, the notes, and what was read.

    Returns
    -------
    data : ndarray, shape (rows, columns)
        The columns of ``layout.wanted`` (time, inputs, outputs), as written in the file.
    lines : list of int
        The file's line number of each row.
    notes : list of str
        Lines skipped (titles, comments), one note.
    read : dict
        ``format`` (``"text"``), ``encoding``, ``delimiter``.

    Raises
    ------
    InputError
        One line naming the file, line or column: unreadable, binary, empty, no header, a missing or repeated
        column, a cell that is not a finite number.

    Examples
    --------
    >>> import tempfile
    >>> p = Path(tempfile.mkdtemp()) / "rig.csv"
    >>> _ = p.write_text("Rig log\\nt;V;pitch\\n0;2,0;1\\n0,05;2,5;3\\n")
    >>> lay = ExportLayout("t", ("V",), ("pitch",), "deg", "s", False, ("V",), ("pitch",))
    >>> data, lines, notes, read = read_text_columns(p, lay)
    >>> data.tolist(), lines, read["delimiter"]
    ([[0.0, 2.0, 1.0], [0.05, 2.5, 3.0]], [3, 4], 'semicolon')
    """
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"CSV file {str(path)!r} cannot be read: {exc.strerror or exc}") from None
    text, encoding = decode_export(raw, path)
    content: list[tuple[int, str]] = []
    comments: list[int] = []
    for no, ln in enumerate(text.splitlines(), start=1):
        if not ln.strip():
            continue
        if ln.lstrip().startswith("#"):
            comments.append(no)
        else:
            content.append((no, ln))
    if not content:
        raise InputError(f"CSV file {str(path)!r} is empty")
    delimiter, start = _sniff(content)
    before = content if start is None else content[:start]
    if not before:
        raise InputError(
            f"{str(path)!r} has no header row: line {content[0][0]} is numbers already; the first line must name "
            "the columns (time, inputs, outputs)"
        )
    headers = _parse([t for _, t in before], delimiter, [n for n, _ in before], path)
    named = [i for i, h in enumerate(headers) if layout.time in (c.strip() for c in h)]
    h = named[-1] if named else len(before) - 1
    header = [c.strip() for c in headers[h]]
    notes = []
    skipped = [(n, t) for i, (n, t) in enumerate(before) if i != h]
    if skipped or comments:
        parts = [f"line {n} {_short(t)!r}" for n, t in skipped[:3]] + (["..."] if len(skipped) > 3 else [])
        if comments:
            parts.append(f"{len(comments)} comment line{'s' * (len(comments) > 1)} (#) from line {comments[0]}")
        notes.append(f"{str(path)!r}: skipped {', '.join(parts)} (its header is line {before[h][0]})")
    for col in layout.wanted:
        if col not in header:
            raise InputError(f"column {col!r} is missing from {str(path)!r}; it has {', '.join(header)}")
        at = [i + 1 for i, c in enumerate(header) if c == col]
        if len(at) > 1:
            raise InputError(
                f"column {col!r} is ambiguous: the header of {str(path)!r} has it twice (columns {at[0]} and "
                f"{at[1]}); rename one of them"
            )
    data_lines = [] if start is None else content[start:]
    rows = _parse([t for _, t in data_lines], delimiter, [n for n, _ in data_lines], path)
    line_of = [n for n, _ in data_lines]
    data = np.empty((len(rows), len(layout.wanted)))
    for j, col in enumerate(layout.wanted):
        k = header.index(col)
        cells = [_number_text(r[k], delimiter) if k < len(r) else "" for r in rows]
        try:
            data[:, j] = np.asarray(cells, dtype=float)
        except ValueError:
            i = next(i for i, c in enumerate(cells) if not _is_number(c, delimiter))
            raise InputError(f"row {line_of[i]}, column {col!r}: {cells[i]!r} is not a number") from None
        bad = np.flatnonzero(~np.isfinite(data[:, j]))
        if bad.size:
            raise InputError(f"row {line_of[bad[0]]}, column {col!r}: {cells[bad[0]]!r} is not a finite number")
    read = {"format": "text", "encoding": encoding, "delimiter": _DELIMITER_NAMES[delimiter]}
    return data, line_of, notes, read


def _short(text: str, n: int = 40) -> str:
    text = " ".join(text.split())
    return text if len(text) <= n else text[: n - 3] + "..."
