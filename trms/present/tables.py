"""A table of computed values beside the thesis's, with notes, rendered as Markdown or HTML.

The report's tables put three value columns side by side -- ``thesis``, ``linear model``,
``twin`` -- and a ``notes`` column (:func:`side_by_side`); :meth:`ComparisonTable.missing`
lists the computed cells that are absent or not finite.
"""

from __future__ import annotations

import html
import math
import numbers
import re
from collections.abc import Callable
from dataclasses import dataclass, field

from trms.present.seeds import AGREES, DIFFERS, TOLERANCE, OverSeeds, agreeing, verdict

__all__ = [
    "ComparisonTable",
    "format_cell",
    "relative_difference",
    "side_by_side",
    "note_far_cells",
    "VALUE_COLUMNS",
    "SOURCE",
    "NOT_PRINTED",
    "EXPLAIN_ABOVE",
    "inline_html",
    "slug",
]

#: The value columns of a side-by-side table, in order.
VALUE_COLUMNS = ("thesis", "linear model", "twin")
#: The column saying where a thesis column's value comes from (:func:`side_by_side` with ``sources``).
SOURCE = "source"
#: The thesis cell of a quantity the thesis does not print.
NOT_PRINTED = "not printed"
#: Relative difference from the thesis beyond which a computed cell needs a note (a seed's tolerance).
EXPLAIN_ABOVE = TOLERANCE


def relative_difference(computed: float | None, thesis: object) -> float:
    """``|computed - thesis| / thesis``; a thesis range ``(lo, hi)`` counts 0 inside it, else from the nearer end.

    Returns ``nan`` when either value is missing (``nan``/``None``), the thesis value is not a number or a
    range (a status such as ``"high"``), or it is 0.
    """
    if computed is None or (isinstance(computed, float) and math.isnan(computed)):
        return float("nan")
    if isinstance(thesis, tuple):
        lo, hi = (float(v) for v in thesis)
    elif isinstance(thesis, numbers.Real):
        lo = hi = float(thesis)
    else:
        return float("nan")
    if computed < lo:
        ref = lo
    elif computed > hi:
        ref = hi
    else:
        return 0.0
    return abs(computed - ref) / abs(ref) if ref else float("nan")


def slug(title: str) -> str:
    """A link target for a table or section title: its part before the first ':', lower case, dashes.

    Examples
    --------
    >>> slug("Table 4.2 (1-DOF): attenuation of the pitch PSD")
    'table-4-2-1-dof'
    """
    return re.sub(r"-+", "-", "".join(c if c.isalnum() else "-" for c in title.split(":")[0].lower())).strip("-")


def inline_html(text: str) -> str:
    """``text`` escaped for HTML, with Markdown's inline code (`` `x` ``) as ``<code>`` and bold (``**x**``) as
    ``<b>``, the two marks the report's prose uses.

    Examples
    --------
    >>> inline_html("run `trms calibrate` if a < b; **then** read")
    'run <code>trms calibrate</code> if a &lt; b; <b>then</b> read'
    """
    out = re.sub(r"`([^`]+)`", r"<code>\1</code>", html.escape(text, quote=False))
    return re.sub(r"\*\*([^*]+)\*\*", r"<b>\1</b>", out)


_NOTE = re.compile(r"note (\d+)")
#: A cell pointing at another table's notes ends with that table's title in parentheses: "note 3 (Table 4.2 (1-DOF))".
_ELSEWHERE = re.compile(r"\((.+)\)$")


def _link_notes(cell: str, own: str) -> str:
    """An escaped cell whose "note N" references link to their notes (this table's, or the table its trailing
    parenthesis names)."""
    target = own
    found = _ELSEWHERE.search(cell)
    if found and _NOTE.search(cell[: found.start()]):
        target = slug(found.group(1))
    return _NOTE.sub(lambda m: f'<a href="#{target}-note-{m.group(1)}">note {m.group(1)}</a>', inline_html(cell))


def format_cell(v: object) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return "not reached" if math.isnan(v) else f"{v:.3g}"
    if isinstance(v, tuple):
        return "-".join(format_cell(x) for x in v) if v[0] != v[-1] else format_cell(v[0])
    return str(v)


@dataclass
class ComparisonTable:
    """Rows of computed and thesis values.

    Attributes
    ----------
    title : str
    columns : list of str
    rows : list of list
        Cells: floats (``nan`` = not reached), strings, tuples (ranges), ``None`` (empty).
    notes : list of str
        Settings, choices and the explanation of every cell off by more than 30 %.
    """

    title: str
    columns: list[str]
    rows: list[list[object]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def column(self, name: str) -> list[object]:
        """All cells of one column."""
        return [row[self.columns.index(name)] for row in self.rows]

    def _computed_columns(self) -> list[str]:
        if "linear model" in self.columns:
            return [c for c in ("linear model", "twin") if c in self.columns]
        return [c for c in self.columns if not c.startswith("thesis") and c != "notes"]

    def computed_cells(self) -> list[object]:
        """Every computed cell (see :meth:`missing` for which columns)."""
        return [row[self.columns.index(c)] for row in self.rows for c in self._computed_columns()]

    def missing(self) -> list[str]:
        """Computed cells (columns ``linear model`` and ``twin`` if present, else every column but the
        thesis's) that are empty or not finite, as ``"row i, column"`` strings."""
        cols = self._computed_columns()
        out = []
        for i, row in enumerate(self.rows):
            for c in cols:
                v = row[self.columns.index(c)]
                bad = v is None or (isinstance(v, str) and not v.strip())
                bad = bad or (isinstance(v, float) and not math.isfinite(v))
                if bad:
                    out.append(f"row {i + 1}, {c}")
        return out

    def to_dict(self) -> dict[str, object]:
        """JSON-serialisable form (non-finite floats become strings)."""

        def cell(v: object) -> object:
            if isinstance(v, OverSeeds):
                return v.to_dict()
            if isinstance(v, float) and not math.isfinite(v):
                return str(v)
            return list(v) if isinstance(v, tuple) else v

        return {
            "title": self.title,
            "columns": list(self.columns),
            "rows": [[cell(c) for c in row] for row in self.rows],
            "notes": list(self.notes),
        }

    def to_html(self) -> str:
        """The table and its notes as an HTML fragment: each numbered note has an anchor
        (``<table slug>-note-N``) and every "note N" in a cell links to it."""
        own = slug(self.title)
        parts = [
            f'<h3 id="{own}">{inline_html(self.title)}</h3>',
            "<table>",
            "<thead><tr>" + "".join(f"<th>{inline_html(c)}</th>" for c in self.columns) + "</tr></thead>",
            "<tbody>",
        ]
        parts += [
            "<tr>" + "".join(f"<td>{_link_notes(format_cell(c), own)}</td>" for c in row) + "</tr>" for row in self.rows
        ]
        parts.append("</tbody></table>")
        if self.notes:
            items = []
            for n in self.notes:
                number = re.match(r"note (\d+):", n)
                anchor = f' id="{own}-note-{number.group(1)}"' if number else ""
                items.append(f"<li{anchor}>{inline_html(n)}</li>")
            parts.append("<ul>" + "".join(items) + "</ul>")
        return "\n".join(parts) + "\n"

    def _repr_html_(self) -> str:
        return self.to_html()

    def __repr__(self) -> str:
        return (
            f"ComparisonTable({self.title!r}, {len(self.rows)} rows x {len(self.columns)} columns, "
            f"{len(self.notes)} notes)"
        )

    def to_markdown(self) -> str:
        """The table, then its notes, as Markdown."""
        lines = [f"### {self.title}", "", "| " + " | ".join(self.columns) + " |", "|" + "---|" * len(self.columns)]
        lines += ["| " + " | ".join(format_cell(c).replace("|", "/") for c in row) + " |" for row in self.rows]
        if self.notes:
            lines.append("")
            lines += [f"- {n}" for n in self.notes]
        return "\n".join(lines) + "\n"


def side_by_side(title: str, keys: list[str], notes: list[str] | None = None, sources: bool = False) -> ComparisonTable:
    """An empty table with columns ``keys + [thesis, linear model, twin, notes]``, and with ``sources`` a
    :data:`SOURCE` column after ``thesis``.

    Rows are ``[*key_cells, thesis, (source,) linear, twin, note]``; a thesis cell that the thesis does not
    print holds :data:`NOT_PRINTED`; the source cell says where the thesis column's value comes from
    (:data:`trms.reference.SOURCES`).

    Examples
    --------
    >>> side_by_side("T", ["quantity"], sources=True).columns
    ['quantity', 'thesis', 'source', 'linear model', 'twin', 'notes']
    """
    values = [VALUE_COLUMNS[0], SOURCE, *VALUE_COLUMNS[1:]] if sources else list(VALUE_COLUMNS)
    return ComparisonTable(title, [*keys, *values, "notes"], [], list(notes or []))


def note_far_cells(
    table: ComparisonTable, why: Callable[[list, str, object, object], str], above: float = EXPLAIN_ABOVE
) -> None:
    """Give every computed cell that does not agree with a numeric thesis cell a numbered note.

    A cell measured at several seeds (:class:`~trms.present.seeds.OverSeeds`) is judged over them
    (:func:`~trms.present.seeds.verdict`): one that differs at every seed gets ``why``'s note; one that agrees at
    some seeds only gets a note saying at how many ("inconclusive at N seeds"); one that agrees at every seed none.

    ``why(row, column, value, thesis)`` returns the note's text (computed from the run: what the difference comes
    from, or "not explained" with the measured context); ``value`` is the cell (a float, or the
    :class:`~trms.present.seeds.OverSeeds`). The note is appended to ``table.notes`` as ``"note n: ..."`` and the
    row's ``notes`` cell gets ``"note n"``.

    Examples
    --------
    >>> t = side_by_side("T", ["q"])
    >>> t.rows.append(["x", 1.0, 2.0, 1.1, ""])
    >>> note_far_cells(t, lambda row, col, v, th: f"{format_cell(v)} vs {th:g}; not explained")
    >>> t.notes, t.rows[0][-1]
    (['note 1: x, linear model: 2 vs 1; not explained'], 'note 1')
    >>> t = side_by_side("T", ["q"])
    >>> t.rows.append(["x", 1.0, 1.1, OverSeeds((1.1, 2.0), (0, 1000)), ""])
    >>> note_far_cells(t, lambda row, col, v, th: "not explained")
    >>> t.notes
    ['note 1: x, twin: 1.55 (1.1-2; 2 seeds) vs thesis 1: within 30% at 1 of 2 seeds: inconclusive at 2 seeds.']
    """
    i = table.columns.index("thesis")
    for row in table.rows:
        thesis = row[i]
        if isinstance(thesis, bool) or not isinstance(thesis, (int, float, tuple)):
            continue
        for col in ("linear model", "twin"):
            v = row[table.columns.index(col)]
            if isinstance(v, OverSeeds):
                judged = verdict(thesis, v, above)
                if judged == AGREES or judged is None:
                    continue
                if judged == DIFFERS:
                    text = why(row, col, v, thesis)
                else:
                    k, n = agreeing(thesis, v, above)
                    text = f"{v} vs thesis {format_cell(thesis)}: within {above:.0%} at {k} of {n} seeds: {judged}."
            elif isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                continue
            elif relative_difference(float(v), thesis) > above:
                text = why(row, col, float(v), thesis)
            else:
                continue
            table.notes.append(f"note {sum(n.startswith('note ') for n in table.notes) + 1}: {row[0]}, {col}: {text}")
            mark = table.notes[-1].split(":", 1)[0]
            row[-1] = f"{row[-1]}; {mark}" if row[-1] else mark
