"""Exact order statistics of a stream of values too many to hold, from a bounded sample of them.

:func:`order_statistics` gives the values of given ranks (as if all were sorted) in a few sweeps over the
blocks a generator yields, each sweep narrowing the bin that holds the ranks; the median distance of
:func:`~trms.identification.rbf.narx_rbf` (its default width) is found so.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

__all__: list[str] = []


class _Sample:
    """Every ``stride``-th value of a stream (``stride`` doubling whenever more than ``size`` are held)."""

    def __init__(self, size: int) -> None:
        self.size, self.stride, self.seen, self.count = size, 1, 0, 0
        self.parts: list[np.ndarray] = []
        self.low, self.high = np.inf, -np.inf

    def add(self, v: np.ndarray) -> None:
        if v.size:
            self.low, self.high = min(self.low, float(v.min())), max(self.high, float(v.max()))
            part = v[(-self.seen) % self.stride :: self.stride]
            self.parts.append(part.copy() if self.stride > 1 else part)  # a view would hold all of v
            self.count += int(self.parts[-1].size)
        self.seen += v.size
        if self.count > self.size:
            self.parts = [self.values()[::2]]
            self.count, self.stride = int(self.parts[0].size), 2 * self.stride

    def values(self) -> np.ndarray:
        return np.concatenate(self.parts) if self.parts else np.zeros(0)


def order_statistics(
    blocks: Callable[[], Iterator[np.ndarray]], total: int, ranks: list[int], guide: np.ndarray, keep: int
) -> list[float]:
    """Values of the 0-based ``ranks`` (ascending, adjacent) among the ``total`` values that ``blocks()`` yields.

    Exact, as if all were sorted, but holding at most about ``3 * keep`` of them at a time: each sweep over the blocks
    counts the values between two cuts taken from a sample (first ``guide``, then the sample the previous sweep
    kept) a few standard errors either side of the ranks' quantiles, and keeps the values, or every ``2^k``-th of
    them, in the bin holding the ranks. That bin holds fewer values every sweep; the sweep that keeps all of them
    ends it. ``keep`` must be 16 or more.
    """
    lo, hi, below, inside = -np.inf, np.inf, 0, total  # the ranks lie among the `inside` values in (lo, hi]
    sample = np.sort(guide)
    while True:
        cuts: list[float] = []
        if sample.size:
            half = min(3.0 / np.sqrt(sample.size), 0.25)  # at most a quarter: one cut at least, so the bins shrink
            i_a = int(np.floor(((ranks[0] - below) / inside - half) * sample.size))
            i_b = int(np.ceil(((ranks[-1] - below) / inside + half) * sample.size))
            b_cut = float(sample[i_b]) if i_b < sample.size else hi
            a_cut = float(sample[i_a]) if i_a >= 0 else lo
            if a_cut >= b_cut:  # the sample ties there: a bin for that one value
                a_cut = float(np.nextafter(b_cut, -np.inf))
            cuts = [c for c in (a_cut, b_cut) if lo < c < hi]
        samples = [_Sample(keep) for _ in range(len(cuts) + 1)]
        for block in blocks():
            v = block.ravel()
            if lo > -np.inf or hi < np.inf:
                v = v[(v > lo) & (v <= hi)]
            if not cuts:
                samples[0].add(v)
                continue
            where = np.searchsorted(cuts, v, side="left")
            for i, s in enumerate(samples):
                s.add(v[where == i])
        counts = np.cumsum([below] + [s.seen for s in samples])
        first = int(np.searchsorted(counts, ranks[0], side="right")) - 1
        last = int(np.searchsorted(counts, ranks[-1], side="right")) - 1
        if first != last:  # two ranks either side of a cut: the largest value below it and the smallest above
            return [samples[first].high, samples[last].low]
        part = samples[first]
        if part.low == part.high:
            return [part.low] * len(ranks)
        lo, hi, below, inside, sample = (
            float(np.nextafter(part.low, -np.inf)),
            part.high,
            int(counts[first]),
            part.seen,
            part.values(),
        )
        if part.stride == 1:
            return [float(v) for v in np.partition(sample, [r - below for r in ranks])[[r - below for r in ranks]]]
        sample.sort()
