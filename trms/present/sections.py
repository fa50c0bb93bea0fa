"""A report section: text, side-by-side tables and figures, rendered as Markdown or HTML."""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from pathlib import Path

from trms.present.tables import ComparisonTable, inline_html

__all__ = ["FigureRef", "Section", "finite_or"]


def finite_or(value: float, text: str = "not reached") -> float | str:
    """``value`` if it is a finite number, else ``text`` (a table cell that says what happened)."""
    v = float(value)
    return v if v == v and abs(v) != float("inf") else text


@dataclass(frozen=True)
class FigureRef:
    """A figure file and its caption.

    Attributes
    ----------
    path : pathlib.Path
        The file (PNG or GIF).
    caption : str
    """

    path: Path
    caption: str


@dataclass
class Section:
    """One chapter's results.

    Attributes
    ----------
    title : str
    paragraphs : list of str
        Set-up and findings, in prose.
    tables : list of ComparisonTable
    figures : list of FigureRef
    conclusion : list of str
        What the twin reproduces, what it does not and why, computed from the run's measurements.
    seconds : float
        Wall time the section took (s).
    """

    title: str
    paragraphs: list[str] = field(default_factory=list)
    tables: list[ComparisonTable] = field(default_factory=list)
    figures: list[FigureRef] = field(default_factory=list)
    conclusion: list[str] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def anchor(self) -> str:
        """The section's link target in the rendered documents."""
        return "".join(c if c.isalnum() else "-" for c in self.title.lower()).strip("-")

    def to_markdown(self, root: Path) -> str:
        """Markdown, with figure paths relative to the report folder ``root``."""
        out = [f'<a id="{self.anchor}"></a>', "", f"## {self.title}", ""]
        if self.conclusion:
            out += ["**In short.** " + " ".join(self.conclusion), ""]
        for p in self.paragraphs:
            out += [p, ""]
        for t in self.tables:
            out += [t.to_markdown(), ""]
        for f in self.figures:
            out += [f"![{f.caption}]({_relative(f.path, root)})", "", f"*{f.caption}*", ""]
        return "\n".join(out)

    def to_html(self, root: Path) -> str:
        """An HTML fragment, with figure paths relative to ``root``."""
        esc = html.escape
        out = [f'<h2 id="{esc(self.anchor)}">{esc(self.title)}</h2>']
        if self.conclusion:
            out.append(f"<p><b>In short.</b> {inline_html(' '.join(self.conclusion))}</p>")
        out += [f"<p>{inline_html(p)}</p>" for p in self.paragraphs]
        out += [t.to_html() for t in self.tables]
        out += [
            f'<figure><img src="{esc(_relative(f.path, root))}" alt="{esc(f.caption)}">'
            f"<figcaption>{esc(f.caption)}</figcaption></figure>"
            for f in self.figures
        ]
        return "\n".join(out) + "\n"


def _relative(path: Path, root: Path) -> str:
    try:
        return Path(path).resolve().relative_to(Path(root).resolve()).as_posix()
    except ValueError:
        return Path(path).as_posix()
