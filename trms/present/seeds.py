"""A twin cell measured at several seeds, and its verdict against the thesis's value over them.

One seed is one realisation of the twin's ambient excitation, noise and excitation signal, not a finding. A cell
that carries a verdict is measured at every seed of the run (:class:`OverSeeds`: the median, the range, each seed's
value) and judged by :func:`verdict`: it **agrees** with the thesis when every seed's value lies within the
tolerance of the thesis's (the seeds' whole range inside the thesis's value widened by the tolerance), it
**differs** when every seed's value lies outside, and otherwise it is **inconclusive at N seeds**.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Generic, TypeVar

import numpy as np

__all__ = [
    "AGREES",
    "DIFFERS",
    "TOLERANCE",
    "OverSeeds",
    "inconclusive",
    "seed_agrees",
    "verdict",
    "over_seeds",
    "Seeded",
    "seeded",
    "agreeing",
]

T = TypeVar("T")

#: The two verdicts a cell can have beside "inconclusive at N seeds".
AGREES, DIFFERS = "agrees", "differs"
#: Relative difference from the thesis within which a seed's value agrees (a printed range counts 0 inside).
TOLERANCE = 0.30


def inconclusive(n: int) -> str:
    """The verdict of a cell that agrees at some seeds and not at others.

    Examples
    --------
    >>> inconclusive(5)
    'inconclusive at 5 seeds'
    """
    return f"inconclusive at {n} seeds"


def _number(v: object) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _fmt(v: float) -> str:
    return f"{v:.3g}"


@dataclass(frozen=True)
class OverSeeds:
    """One quantity of the twin measured at several seeds.

    Attributes
    ----------
    values : tuple
        The cell at each seed (a number, or a word such as ``"hit the stops"`` where the run gave no number),
        in the order of ``seeds``; the first is the run's own seed, the one its figures show.
    seeds : tuple of int
        The seeds.

    Examples
    --------
    >>> c = OverSeeds((30.1, 34.0, 28.2), (0, 1000, 2000))
    >>> str(c), c.median, c.range
    ('30.1 (28.2-34; 3 seeds)', 30.1, (28.2, 34.0))
    >>> str(OverSeeds(("hit the stops", 5.5, "hit the stops"), (0, 1, 2)))
    '5.5 (5.5-5.5; 3 seeds; hit the stops at 2)'
    >>> str(OverSeeds(("0.10, 0.34", "0.34"), (0, 1))), str(OverSeeds(("none", "none"), (0, 1)))
    ('0.10, 0.34 | 0.34 (2 seeds)', 'none (2 seeds)')
    """

    values: tuple[object, ...]
    seeds: tuple[int, ...]

    def __post_init__(self) -> None:
        if len(self.values) != len(self.seeds) or not self.values:
            raise ValueError(f"one value per seed: {len(self.values)} values, {len(self.seeds)} seeds")

    @property
    def numbers(self) -> list[float]:
        """The seeds' finite numbers."""
        return [float(v) for v in self.values if _number(v) and math.isfinite(float(v))]  # type: ignore[arg-type]

    @property
    def words(self) -> dict[str, int]:
        """How many seeds gave each non-number (a status, or "nan" for a number that was not reached)."""
        out: dict[str, int] = {}
        for v in self.values:
            if not (_number(v) and math.isfinite(float(v))):  # type: ignore[arg-type]
                key = "not reached" if _number(v) else str(v)
                out[key] = out.get(key, 0) + 1
        return out

    @property
    def median(self) -> float:
        """Median of the seeds' numbers (``nan`` without any)."""
        got = self.numbers
        return float(np.median(got)) if got else float("nan")

    @property
    def range(self) -> tuple[float, float]:
        """Smallest and largest of the seeds' numbers (``nan`` without any)."""
        got = self.numbers
        return (min(got), max(got)) if got else (float("nan"), float("nan"))

    def __str__(self) -> str:
        n = len(self.values)
        words = "; ".join(f"{w} at {k}" for w, k in self.words.items())
        if not self.numbers:
            if len(self.words) == 1:
                return f"{next(iter(self.words))} ({n} seeds)"
            if all(_modes(v) for v in self.values):  # lists of modes: seed by seed
                return " | ".join(str(v) for v in self.values) + f" ({n} seeds)"
            return f"{words} ({n} seeds)"
        lo, hi = self.range
        sep = " to " if lo < 0 else "-"
        return f"{_fmt(self.median)} ({_fmt(lo)}{sep}{_fmt(hi)}; {n} seeds" + (f"; {words})" if words else ")")

    def to_dict(self) -> dict[str, object]:
        """JSON form: the median, the range, every seed's value.

        Examples
        --------
        >>> OverSeeds((1.0, 3.0), (0, 1000)).to_dict()["range"]
        [1.0, 3.0]
        """

        def cell(v: object) -> object:
            return str(v) if _number(v) and not math.isfinite(float(v)) else v  # type: ignore[arg-type]

        return {
            "median": cell(self.median),
            "range": [cell(x) for x in self.range],
            "values": [cell(v) for v in self.values],
            "seeds": list(self.seeds),
        }


def over_seeds(values: Sequence[object], seeds: Sequence[int]) -> OverSeeds | object:
    """The cell of a quantity measured at ``seeds``: an :class:`OverSeeds`, or the value itself at one seed.

    Examples
    --------
    >>> over_seeds([2.0], [0]), str(over_seeds([2.0, 4.0], [0, 1]))
    (2.0, '3 (2-4; 2 seeds)')
    """
    if len(values) == 1:
        return values[0]
    return OverSeeds(tuple(values), tuple(int(s) for s in seeds))


@dataclass(frozen=True)
class Seeded(Generic[T]):
    """One world's results of an experiment at each seed of a run.

    Attributes
    ----------
    seeds : tuple of int
        The seeds, the run's own first.
    results : tuple
        The experiment's result at each seed: the first complete (its figures and every row), the others holding
        at least what the cells that carry a verdict read.

    Examples
    --------
    >>> runs = Seeded((0, 1000), ({"gain": 1.5}, {"gain": 1.7}))
    >>> runs.first, str(runs.cell(lambda r: r["gain"]))
    ({'gain': 1.5}, '1.6 (1.5-1.7; 2 seeds)')
    """

    seeds: tuple[int, ...]
    results: tuple[T, ...]

    def __post_init__(self) -> None:
        if len(self.seeds) != len(self.results) or not self.seeds:
            raise ValueError(f"one result per seed: {len(self.results)} results, {len(self.seeds)} seeds")

    @property
    def first(self) -> T:
        """The result at the run's own seed."""
        return self.results[0]

    def cell(self, read: Callable[[T], object]) -> OverSeeds | object:
        """The cell ``read`` gives at every seed (:func:`over_seeds`: the value itself at one seed)."""
        return over_seeds([read(r) for r in self.results], self.seeds)


def seeded(value: Seeded[T] | T) -> Seeded[T]:
    """``value`` as results by seed: itself when it is :class:`Seeded`, else one result at one seed.

    Examples
    --------
    >>> seeded(2.0).results, seeded(Seeded((3,), (2.0,))).seeds
    ((2.0,), (3,))
    """
    return value if isinstance(value, Seeded) else Seeded((0,), (value,))


def agreeing(thesis: object, cell: object, tolerance: float = TOLERANCE) -> tuple[int, int]:
    """How many of a cell's seeds agree with the thesis's value (:func:`seed_agrees`), and how many seeds it has.

    Examples
    --------
    >>> agreeing(6.42e-6, OverSeeds((7.86e-6, 1.66e-5, 1.1e-5), (0, 1, 3)))
    (1, 3)
    """
    values = cell.values if isinstance(cell, OverSeeds) else (cell,)
    return sum(bool(seed_agrees(thesis, v, tolerance)) for v in values), len(values)


def _modes(cell: object) -> list[float]:
    """The frequencies a cell lists ("0.10, 0.34"); empty when it holds anything else."""
    if not isinstance(cell, str):
        return []
    try:
        return [float(x) for x in cell.split(",")]
    except ValueError:
        return []


def _relative(value: float, thesis: object) -> float:
    if isinstance(thesis, tuple):
        lo, hi = (float(v) for v in thesis)
    else:
        lo = hi = float(thesis)  # type: ignore[arg-type]
    ref = lo if value < lo else hi if value > hi else None
    return 0.0 if ref is None else abs(value - ref) / abs(ref) if ref else float("inf")


def seed_agrees(thesis: object, value: object, tolerance: float = TOLERANCE) -> bool | None:
    """Whether one seed's cell agrees with the thesis's; ``None`` when the thesis prints nothing to compare with.

    A printed number or range agrees with a number within ``tolerance`` of it (relative; 0 inside a range) and
    never with a word (a run that "hit the stops"); a printed list of modes agrees with a list holding each of them
    within ``tolerance``; the thesis's "rejected" (a push) with a number (the time the run took to recover).

    Examples
    --------
    >>> seed_agrees(3.0, 3.4), seed_agrees((5.0, 6.0), 9.0), seed_agrees(7.0, "hit the stops")
    (True, False, False)
    >>> seed_agrees("0.1, 0.34", "0.10, 0.33"), seed_agrees("0.1", "0.25"), seed_agrees("high", 1.0)
    (True, False, None)
    """
    if _number(thesis) or isinstance(thesis, tuple):
        if not _number(value) or not math.isfinite(float(value)):  # type: ignore[arg-type]
            return False
        return _relative(float(value), thesis) <= tolerance  # type: ignore[arg-type]
    printed, found = _modes(thesis), _modes(value)
    if printed:
        return bool(found) and all(any(_relative(f, m) <= tolerance for f in found) for m in printed)
    if thesis == "rejected":
        return _number(value) and math.isfinite(float(value))  # type: ignore[arg-type]
    return None


def verdict(thesis: object, cell: object, tolerance: float = TOLERANCE) -> str | None:
    """The verdict of a cell against the thesis's value over every seed it was measured at.

    Parameters
    ----------
    thesis : object
        The thesis's value: a number, a range ``(lo, hi)``, a list of modes ("0.1, 0.34") or "rejected".
    cell : OverSeeds or object
        The cell at every seed, or at one.
    tolerance : float
        Relative tolerance of one seed's agreement (:func:`seed_agrees`).

    Returns
    -------
    str or None
        :data:`AGREES` when every seed agrees, :data:`DIFFERS` when none does, :func:`inconclusive` otherwise;
        ``None`` when the thesis prints nothing comparable.

    Examples
    --------
    >>> verdict(6.42e-6, OverSeeds((7.86e-6, 1.66e-5, 1.1e-5), (0, 1, 3)))  # agrees at one seed of three
    'inconclusive at 3 seeds'
    >>> verdict(7.0, OverSeeds((34.0, 28.2, 30.1), (0, 1, 3))), verdict(3.0, OverSeeds((3.4, 3.5), (0, 1)))
    ('differs', 'agrees')
    >>> verdict(3.0, 3.4), verdict("-", 1.0) is None
    ('agrees', True)
    """
    values = cell.values if isinstance(cell, OverSeeds) else (cell,)
    each = [seed_agrees(thesis, v, tolerance) for v in values]
    if any(e is None for e in each):
        return None
    if all(each):
        return AGREES
    if not any(each):
        return DIFFERS
    return inconclusive(len(values))
