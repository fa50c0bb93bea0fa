"""Polynomial NARX models by forward regression orthogonal least squares (FROLS), beside the thesis's NARX-RBF.

The model (Billings 2013, ch. 3) is a sum of monomials of the lagged output and input,

``y(t) = sum_i theta_i p_i(y(t-1), ..., y(t-ny), u(t-nk), ..., u(t-nk-nu+1)) + e(t)``,

each ``p_i`` a product of at most ``degree`` of those lagged values (the constant is the empty product). Every
monomial up to ``degree`` is a candidate; FROLS chooses them one at a time by their error-reduction ratio (the
share of the output's energy each explains once orthogonalised against those already chosen, the OLS engine of
:func:`~trms.identification.ols.ols_select`), and stops when the unexplained share falls below ``tolerance`` or
``max_terms`` are chosen. The coefficients are the least-squares ones of the chosen terms. Unlike the Gaussian
network, a polynomial truth is recovered term for term, and the model reads as an equation
(:meth:`PolynomialNarx.equation`).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from trms.display import html_table
from trms.errors import EstimationError, check_in_range, check_int
from trms.identification.data import check_excitation, lag_matrix, measured_signals, model_signals, siso_data
from trms.identification.ols import ols_select
from trms.record import Record

__all__ = ["PolynomialNarx", "narx_poly", "candidate_terms"]

#: A term: the lagged values it multiplies, each ``("y", lag)`` or ``("u", lag)``; ``()`` is the constant.
Term = tuple[tuple[str, int], ...]


def candidate_terms(ny: int, nu: int, nk: int, degree: int) -> list[Term]:
    """Every monomial of the lagged output and input up to ``degree``, the constant first.

    Examples
    --------
    >>> [" ".join(f"{s}(t-{k})" for s, k in t) or "1" for t in candidate_terms(1, 1, 1, 2)]
    ['1', 'y(t-1)', 'u(t-1)', 'y(t-1) y(t-1)', 'y(t-1) u(t-1)', 'u(t-1) u(t-1)']
    """
    variables = [("y", k) for k in range(1, ny + 1)] + [("u", k) for k in range(nk, nk + nu)]
    out: list[Term] = [()]
    for d in range(1, degree + 1):
        out += [tuple(c) for c in itertools.combinations_with_replacement(variables, d)]
    return out


def _columns(terms: list[Term], ylags: dict[int, np.ndarray], ulags: dict[int, np.ndarray], n: int) -> np.ndarray:
    """The regressor matrix ``(n, len(terms))`` of the terms, from the lagged signals."""
    out = np.ones((n, len(terms)))
    for j, term in enumerate(terms):
        for signal, lag in term:
            out[:, j] *= ylags[lag] if signal == "y" else ulags[lag]
    return out


@dataclass
class PolynomialNarx:
    """A polynomial NARX model chosen by FROLS (see the module docstring).

    Attributes
    ----------
    ny, nu, nk, degree : int
        Output lags, input lags, input delay (samples) and the largest degree of a term.
    terms : list of tuple
        The chosen terms, in the order chosen (:data:`Term`).
    coefficients : numpy.ndarray
        Their least-squares coefficients (output units per product of the factors' units).
    err : numpy.ndarray
        Error-reduction ratio of each chosen term (fraction of the output's energy).
    sample_time : float
        Seconds per sample.
    n_samples : int
        Training targets used.
    """

    ny: int
    nu: int
    nk: int
    degree: int
    terms: list[Term]
    coefficients: np.ndarray
    err: np.ndarray
    sample_time: float
    n_samples: int = 0
    y_range: tuple[float, float] = field(default=(-np.inf, np.inf))

    @property
    def start(self) -> int:
        """First sample with every lag available: ``max(ny, nk + nu - 1)``."""
        return max(self.ny, self.nk + self.nu - 1)

    @property
    def n_terms(self) -> int:
        """Number of chosen terms."""
        return len(self.terms)

    def term_names(self) -> list[str]:
        """Each chosen term as text, e.g. ``"y(t-1) u(t-2)"`` (``"1"`` for the constant)."""
        return [" ".join(f"{s}(t-{k})" for s, k in t) or "1" for t in self.terms]

    def equation(self, digits: int = 4) -> str:
        """The model as an equation, terms in the order chosen.

        Examples
        --------
        >>> u = np.random.default_rng(0).uniform(-1, 1, 400)
        >>> y = np.zeros(400)
        >>> for t in range(1, 400):
        ...     y[t] = 0.5 * y[t - 1] + 0.8 * u[t - 1]
        >>> narx_poly(y, u, ny=1, nu=1, sample_time=0.1).equation()
        'y(t) = 0.8 u(t-1) + 0.5 y(t-1)'
        """
        digits = check_int("digits", digits, 1, high=17)
        pieces = []
        for i, (c, name) in enumerate(zip(self.coefficients, self.term_names())):
            body = f"{abs(c):.{digits}g}" + ("" if name == "1" else f" {name}")
            sign = "- " if c < 0 else ("" if i == 0 else "+ ")
            pieces.append(sign + body)
        return "y(t) = " + " ".join(pieces)

    def __repr__(self) -> str:
        return (
            f"PolynomialNarx(ny={self.ny}, nu={self.nu}, nk={self.nk}, degree {self.degree}, {self.n_terms} terms "
            f"of {len(candidate_terms(self.ny, self.nu, self.nk, self.degree))}, Ts={self.sample_time:g} s)"
        )

    def _repr_html_(self) -> str:
        rows = [("lags ny, nu, delay nk", f"{self.ny}, {self.nu}, {self.nk}"), ("degree", str(self.degree))]
        rows += [(n, f"{c:.6g} (ERR {e:.3g})") for n, c, e in zip(self.term_names(), self.coefficients, self.err)]
        return html_table("PolynomialNarx (FROLS)", rows)

    def _regressors(self, y: np.ndarray, u: np.ndarray) -> np.ndarray:
        s = self.start
        ylags = {k: lag_matrix(y, [k], s)[:, 0] for k in range(1, self.ny + 1)}
        ulags = {k: lag_matrix(u, [k], s)[:, 0] for k in range(self.nk, self.nk + self.nu)}
        return _columns(self.terms, ylags, ulags, y.size - s)

    def predict(self, y: object, u: object, horizon: int = 1) -> np.ndarray:
        """``horizon``-step-ahead prediction (``1``: one step ahead, OSA); the first :attr:`start` samples are ``y``.

        Returns
        -------
        numpy.ndarray
            Shape ``(N,)``, output units.
        """
        k = check_int("horizon", horizon, 1, unit=" samples")
        ya, ua = measured_signals(y, u, self.start)
        step = ya.copy()
        for _ in range(min(k, ya.size)):
            nxt = ya.copy()
            nxt[self.start :] = self._regressors(step, ua) @ self.coefficients
            step = nxt
        return step

    def residuals(self, y: object, u: object) -> np.ndarray:
        """One-step prediction errors ``y - yhat`` (output units); 0 for the first :attr:`start` samples."""
        ya, _ = measured_signals(y, u, self.start)
        return ya - self.predict(ya, u, 1)

    def simulate(self, u: object, y: object | None = None) -> np.ndarray:
        """Model predicted output (the model fed back its own outputs), from ``y``'s first samples or from 0.

        Returns
        -------
        numpy.ndarray
            Shape ``(N,)``, output units; ``inf`` or ``nan`` past a point where the model diverged.
        """
        ya, ua = model_signals(y, u, self.start)
        n, s = ua.size, self.start
        out = np.zeros(n) if ya is None else ya.copy()
        factors = [[(0 if sig == "y" else 1, lag) for sig, lag in t] for t in self.terms]
        with np.errstate(over="ignore", invalid="ignore"):
            for t in range(s, n):  # a recursion: each output feeds the next (not a physics loop)
                total = 0.0
                for c, term in zip(self.coefficients, factors):
                    v = c
                    for which, lag in term:
                        v *= out[t - lag] if which == 0 else ua[t - lag]
                    total += v
                out[t] = total
        return out


def narx_poly(
    data: Record | object,
    u: object | None = None,
    ny: int = 2,
    nu: int = 2,
    nk: int = 1,
    *,
    degree: int = 2,
    max_terms: int = 10,
    tolerance: float = 1e-4,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
) -> PolynomialNarx:
    """Fit a polynomial NARX model by FROLS (see the module docstring).

    Parameters
    ----------
    data : Record or array_like
        A Record (deviations are used) or the output ``y``.
    u : array_like, optional
        Input with an array ``y``.
    ny, nu, nk : int
        Output lags >= 1, input lags >= 1, input delay >= 0 (samples).
    degree : int
        Largest degree of a term, 1 to 4 (1: a linear ARX model chosen term by term).
    max_terms : int
        Most terms chosen (the constant included if chosen).
    tolerance : float
        Stop when the unexplained fraction of the output's energy ``1 - sum ERR`` is below it.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.

    Returns
    -------
    PolynomialNarx

    Raises
    ------
    InputError
        Bad data or settings (one line), an input constant in every sample.
    EstimationError
        Too few samples for the candidates, or an output with no energy.

    Examples
    --------
    A polynomial truth with a bilinear and a squared input term is recovered term for term:

    >>> rng = np.random.default_rng(1)
    >>> u = rng.uniform(-1, 1, 800)
    >>> y = np.zeros(800)
    >>> for t in range(2, 800):
    ...     y[t] = 0.5 * y[t - 1] + 0.3 * u[t - 1] + 0.2 * y[t - 1] * u[t - 1] - 0.1 * u[t - 2] ** 2
    >>> model = narx_poly(y, u, ny=2, nu=2, degree=2, sample_time=0.1)
    >>> sorted(model.term_names())
    ['u(t-1)', 'u(t-2) u(t-2)', 'y(t-1)', 'y(t-1) u(t-1)']
    >>> np.round(sorted(model.coefficients), 3).tolist()
    [-0.1, 0.2, 0.3, 0.5]
    """
    d = siso_data(data, u, sample_time=sample_time, input=input, output=output)
    check_excitation(d.u, 1, f"input {d.input_name}")  # a zero or constant input: no input term to find
    ny = check_int("ny", ny, 1)
    nu = check_int("nu", nu, 1)
    nk = check_int("nk", nk, 0)
    degree = check_int("degree", degree, 1, high=4)
    max_terms = check_int("max_terms", max_terms, 1)
    tol = check_in_range("tolerance", tolerance, 0.0, 1.0)
    start = max(ny, nk + nu - 1)
    terms = candidate_terms(ny, nu, nk, degree)
    n = d.y.size - start
    if n < 2 * len(terms):
        raise EstimationError(
            f"{d.y.size} samples give {n} targets for {len(terms)} candidate terms; at least {2 * len(terms)} needed "
            "(lower the lags or the degree, or give more data)"
        )
    target = d.y[start:]
    if not np.any(target):
        raise EstimationError("the output is zero at every sample: there is nothing to explain")
    ylags = {k: lag_matrix(d.y, [k], start)[:, 0] for k in range(1, ny + 1)}
    ulags = {k: lag_matrix(d.u, [k], start)[:, 0] for k in range(nk, nk + nu)}
    P = _columns(terms, ylags, ulags, n)
    sel = ols_select(P, target, min(max_terms, len(terms)), tol)
    chosen = [terms[i] for i in sel.selected]
    coef, *_ = np.linalg.lstsq(P[:, sel.selected], target, rcond=None)
    return PolynomialNarx(
        ny,
        nu,
        nk,
        degree,
        chosen,
        np.asarray(coef, float),
        np.asarray(sel.err, float),
        d.sample_time,
        n,
        (float(d.y.min()), float(d.y.max())),
    )
