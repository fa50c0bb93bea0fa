"""Forward selection of regressor columns by orthogonal least squares (error-reduction ratio).

The algorithm of Chen, Cowan and Grant (1991) on a candidate matrix given block by block, so that it is
never held whole beyond ``OLS_CACHE`` elements: its first columns are kept and orthogonalised in place, the
others are recomputed at every pass ``OLS_BLOCK`` elements at a time and projected out of the span of the
chosen columns (:func:`ols_select` on a dense matrix,
:func:`~trms.identification.rbf.narx_rbf` on the Gaussian responses).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from trms.errors import EstimationError

__all__ = ["OlsSelection", "ols_select"]

#: Elements (float64) of the candidate matrix made at once: the columns are computed and orthogonalised this many
#: at a time, and order statistics of the distances are sampled with this many values at most.
OLS_BLOCK = 2**17
#: Elements (float64) of the candidate matrix kept, orthogonalised, between OLS passes (the first columns); the
#: rest is recomputed at every pass, so memory stays ``O(N x centres)`` plus this constant whatever the candidates.
OLS_CACHE = 2**21


@dataclass(frozen=True)
class OlsSelection:
    """Result of :func:`ols_select`.

    Attributes
    ----------
    selected : numpy.ndarray
        Indices of the chosen columns, in the order chosen.
    err : numpy.ndarray
        Error-reduction ratio of each chosen column (fraction of ``d @ d``).
    """

    selected: np.ndarray
    err: np.ndarray

    @property
    def unexplained(self) -> float:
        """``1 - sum(err)``: the fraction of the target's energy left."""
        return float(1.0 - np.sum(self.err))


def ols_blocks(
    columns: Callable[[int, int], np.ndarray],
    n_columns: int,
    d: np.ndarray,
    max_terms: int,
    tolerance: float,
    forced: int | None,
) -> OlsSelection:
    """:func:`ols_select` on a candidate matrix given block by block: ``columns(j0, j1)``
    is ``P[:, j0:j1]``.

    The first ``OLS_CACHE // N`` columns are kept and orthogonalised in place against each chosen column (modified
    Gram-Schmidt); the others are recomputed at every pass, ``OLS_BLOCK // N`` at a time, and projected out of the
    span of the chosen columns (kept orthonormal, ``N x max_terms``) to give their norms and correlations with ``d``.
    """
    dd = float(d @ d)
    if dd == 0:
        raise EstimationError("the OLS target is identically zero")
    n = d.size
    per = max(1, OLS_BLOCK // n)
    kept = min(n_columns, OLS_CACHE // n)
    w = np.empty((n, kept))
    for j0 in range(0, kept, per):
        w[:, j0 : min(j0 + per, kept)] = columns(j0, min(j0 + per, kept))
    streamed = [(j0, min(j0 + per, n_columns)) for j0 in range(kept, n_columns, per)]
    basis = np.empty((n, max_terms))
    norms, g = np.empty(n_columns), np.empty(n_columns)
    norms0, alive = norms, np.ones(0, bool)
    selected: list[int] = []
    err: list[float] = []
    while len(selected) < max_terms:
        q = basis[:, : len(selected)]
        norms[:kept] = np.einsum("ij,ij->j", w, w)
        g[:kept] = w.T @ d
        for j0, j1 in streamed:
            b = columns(j0, j1)
            if selected:
                b = b - q @ (q.T @ b)
            norms[j0:j1] = np.einsum("ij,ij->j", b, b)
            g[j0:j1] = b.T @ d
        if not selected:
            norms0 = norms.copy()
            alive = norms0 > 0
        ok = alive & (norms > 1e-10 * norms0)
        if forced is not None and not selected:
            j = int(forced)
            wj = w[:, j] if j < kept else columns(j, j + 1)[:, 0]
            ratio = float((wj @ d) ** 2 / (norms[j] * dd))
        else:
            ratios = np.where(ok, g**2 / np.where(ok, norms, 1.0) / dd, -1.0)
            j = int(np.argmax(ratios))
            ratio = float(ratios[j])
            if ratio <= 0.0:
                break
            if j < kept:
                wj = w[:, j]
            else:  # recomputed, and projected out twice so that the basis stays orthonormal to rounding
                wj = columns(j, j + 1)[:, 0]
                for _ in range(2):
                    wj = wj - q @ (q.T @ wj)
        selected.append(j)
        err.append(ratio)
        alive[j] = False
        qj = basis[:, len(selected) - 1]
        qj[:] = wj / np.sqrt(norms[j] if j < kept else wj @ wj)
        r = qj @ w
        for j0 in range(0, kept, per):  # in blocks: no N x kept temporary
            w[:, j0 : j0 + per] -= np.outer(qj, r[j0 : j0 + per])
        if 1.0 - sum(err) < tolerance:
            break
    return OlsSelection(np.array(selected, dtype=int), np.array(err))


def ols_select(
    P: np.ndarray, d: np.ndarray, max_terms: int, tolerance: float, forced: int | None = None
) -> OlsSelection:
    """Forward selection of columns of ``P`` by orthogonal least squares (error-reduction ratio).

    Parameters
    ----------
    P : numpy.ndarray
        Candidate regressor columns, shape ``(N, M)``.
    d : numpy.ndarray
        Target, shape ``(N,)``, not identically zero.
    max_terms : int
        Most columns chosen (the forced one included).
    tolerance : float
        Stop once ``1 - sum(err) < tolerance``.
    forced : int, optional
        A column chosen first whatever its ERR (the bias).

    Returns
    -------
    OlsSelection

    Examples
    --------
    >>> import numpy as np
    >>> P = np.random.default_rng(0).standard_normal((100, 6))
    >>> sel = ols_select(P, 2.0 * P[:, 3] - P[:, 1], max_terms=4, tolerance=1e-12)
    >>> sel.selected.tolist(), bool(sel.unexplained < 1e-12)
    ([3, 1], True)
    """
    a = np.asarray(P, dtype=float)
    return ols_blocks(lambda j0, j1: a[:, j0:j1], a.shape[1], np.asarray(d, dtype=float), max_terms, tolerance, forced)
