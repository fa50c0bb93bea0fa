"""Notebook display: the small HTML tables that ``_repr_html_`` methods return.

Objects with many numbers (records, fitted models) show a one-line ``repr`` and, in a notebook, a two-column
table of their key figures instead of their arrays.
"""

from __future__ import annotations

import html
from collections.abc import Iterable

__all__ = ["html_table"]


def html_table(caption: str, rows: Iterable[tuple[str, str]]) -> str:
    """A two-column HTML table (name, value) with ``caption``; every cell is escaped.

    Parameters
    ----------
    caption : str
        The table's caption (usually the class name).
    rows : iterable of (str, str)
        The rows, in order.

    Returns
    -------
    str
        ``<table>`` markup.

    Examples
    --------
    >>> t = html_table("Model", [("order", "2"), ("a < b", "yes")])
    >>> t.startswith("<table><caption>Model</caption>"), "<td>2</td>" in t, "a &lt; b" in t
    (True, True, True)
    """
    body = "".join(
        f"<tr><th style='text-align:left'>{html.escape(k)}</th><td>{html.escape(v)}</td></tr>" for k, v in rows
    )
    return f"<table><caption>{html.escape(caption)}</caption>{body}</table>"
