"""A table of computed values beside the thesis's, with notes, rendered as Markdown."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

__all__ = ["ComparisonTable", "format_cell", "relative_difference"]


def relative_difference(computed: float, thesis: float | tuple[float, float]) -> float:
    """``|computed - thesis| / thesis``; a thesis range ``(lo, hi)`` counts 0 inside it, else from the nearer end.

    Returns ``nan`` when either value is missing (``nan``/``None``) or the thesis value is 0.
    """
    if computed is None or thesis is None or (isinstance(computed, float) and math.isnan(computed)):
        return float("nan")
    lo, hi = (thesis, thesis) if not isinstance(thesis, tuple) else thesis
    if computed < lo:
        ref = lo
    elif computed > hi:
        ref = hi
    else:
        return 0.0
    return abs(computed - ref) / abs(ref) if ref else float("nan")


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

    def to_markdown(self) -> str:
        """The table, then its notes, as Markdown."""
        lines = [f"### {self.title}", "", "| " + " | ".join(self.columns) + " |", "|" + "---|" * len(self.columns)]
        lines += ["| " + " | ".join(format_cell(c) for c in row) + " |" for row in self.rows]
        if self.notes:
            lines.append("")
            lines += [f"- {n}" for n in self.notes]
        return "\n".join(lines) + "\n"
