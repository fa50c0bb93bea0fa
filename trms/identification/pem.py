"""The prediction-error method for the general polynomial model, shared by ARMAX, OE and BJ.

The model is ``A y = B / F u + C / D e`` (see :mod:`trms.identification.polynomial`). Its
one-step prediction error is

``eps = D / C (A y - w)``,  ``w = B / F u``,

conditional as :func:`trms.identification.polynomial.prediction_errors` defines it (``1 / F``
from rest before sample 0, ``D / C`` from rest at ``start``). The gradient
``psi = -d eps / d theta`` of eq. (3.6), generalised, is one ``lfilter`` per signal and lag
matrices of the filtered signals:

* ``a_k``:  ``-D/C q^-k y``
* ``b_k``:  ``D/(C F) q^-(nk+k-1) u``
* ``c_k``:  ``1/C q^-k eps``
* ``d_k``:  ``-1/C q^-k v`` with ``v = A y - w``
* ``f_k``:  ``-D/(C F) q^-k w``

:func:`minimise` is the damped Gauss-Newton (Levenberg-Marquardt) search of ch. 3.3.3 for
any such error function: Gauss-Newton step halved up to 10 times, then growing
Levenberg-Marquardt damping; a step that moves a root of ``C`` or ``F`` onto or outside
the unit circle is refused (the predictor filters ``1 / C`` and ``1 / F`` must stay
stable); it stops when the Gauss-Newton step promises a relative decrease below ``tol``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg
import scipy.signal

from trms.errors import EstimationError, check_in_range
from trms.identification.data import SisoData, lag_matrix
from trms.identification.polynomial import PolynomialModel

__all__ = [
    "MAX_ITER",
    "Structure",
    "Minimum",
    "minimise",
    "fit",
    "covariance",
    "search_steps",
    "max_root",
    "check_search",
    "sandwich_covariance",
    "SANDWICH_MAX_ORDER",
]

#: Gauss-Newton iterations a prediction-error fit is allowed by default. An over-parameterised model (the thesis's
#: 4th-order ARMAX of a plant with one lightly damped mode, whose extra poles and zeros nearly cancel) creeps along a
#: flat valley: a 60 s PRBS record of the 1-DOF twin (``trms simulate --config 1dof``) needs 203 iterations to
#: reach the default tolerance, and ch. 5's uniform-noise records of the rig a few more than 200.
MAX_ITER = 1000


def covariance(psi: np.ndarray, sigma2: float) -> np.ndarray:
    """Parameter covariance ``sigma2 (psi^T psi)^-1`` (column-scaled; a zero column gets variance 0).

    Parameters
    ----------
    psi : numpy.ndarray
        Gradient of the prediction errors, shape ``(N, p)``.
    sigma2 : float
        Innovations variance (output unit squared).

    Returns
    -------
    numpy.ndarray
        Shape ``(p, p)``.

    Examples
    --------
    >>> covariance(np.column_stack([np.ones(100), np.zeros(100)]), 4.0)
    array([[0.04, 0.  ],
           [0.  , 0.  ]])
    """
    scale = np.linalg.norm(psi, axis=0)
    scale[scale == 0] = 1.0
    info = (psi / scale).T @ (psi / scale)
    return sigma2 * np.linalg.pinv(info, hermitian=True) / np.outer(scale, scale)


#: Largest order of the AR model of the residuals in :func:`sandwich_covariance` (and at most a twentieth of N).
SANDWICH_MAX_ORDER = 30


def sandwich_covariance(
    psi: np.ndarray, eps: np.ndarray, max_order: int = SANDWICH_MAX_ORDER
) -> tuple[np.ndarray, int, float]:
    """Parameter covariance that holds for coloured prediction errors, the AR order it used and the effective
    number of independent samples.

    A least-squares estimate whose errors ``eps`` are not white (an output-error fit under a coloured
    disturbance) has the covariance ``J^-1 psi' R psi J^-1``, ``J = psi' psi``, ``R`` the errors' autocovariance
    (Toeplitz) -- not ``lambda J^-1``, which assumes ``R = lambda I``. ``R`` is taken from an AR model of ``eps``
    (least squares, which unlike Yule-Walker is not biased towards white noise on a short record; the order
    ``k <= max_order`` by the Bayesian information criterion): with ``1 / A_k`` the
    noise filter and ``s^2`` its innovations variance, ``R = s^2 H H'`` (``H`` the lower-triangular Toeplitz
    matrix of the impulse response of ``1 / A_k``), so ``psi' R psi = s^2 phi' phi`` with ``phi = H' psi``: ``psi``
    filtered by ``1 / A_k`` backwards in time. White errors give ``k = 0`` and ``lambda J^-1``. The effective
    sample count is ``N`` over the errors' long-run variance ratio ``(s^2 / A_k(1)^2) / var(eps)`` (``N`` for white
    errors, about ``N (1 - a) / (1 + a)`` for an AR(1) pole ``a``): how many independent samples the record is worth.

    Parameters
    ----------
    psi : numpy.ndarray
        Gradient ``-d eps / d theta``, shape ``(N, p)``.
    eps : numpy.ndarray
        The errors, shape ``(N,)`` (output unit).
    max_order : int
        Largest AR order tried (at most ``N // 20``).

    Returns
    -------
    tuple
        The covariance ``(p, p)``, the AR order ``k`` and the effective sample count.

    Examples
    --------
    White errors: the AR order is 0 and the covariance the usual one (with the errors' mean square as ``lambda``):

    >>> rng = np.random.default_rng(0)
    >>> psi, eps = rng.standard_normal((2000, 2)), rng.standard_normal(2000)
    >>> cov, k, effective = sandwich_covariance(psi, eps)
    >>> k, effective, bool(np.allclose(cov, covariance(psi, float(eps @ eps) / eps.size), rtol=1e-12))
    (0, 2000.0, True)
    """
    n = eps.size
    top = int(min(max_order, n // 20))
    # least squares of eps(t) on its past, every order from one QR factorisation: the residual sum of squares of
    # order k is |eps|^2 less the first k squared entries of Q' eps (the regressors are nested)
    target = eps[top:]
    lags = -np.column_stack([eps[top - j : n - j] for j in range(1, top + 1)]) if top else np.zeros((target.size, 0))
    q, r = np.linalg.qr(lags)
    proj = q.T @ target
    rss = float(target @ target) - np.concatenate([[0.0], np.cumsum(proj**2)])
    size = target.size
    bic = np.log(np.maximum(rss, 1e-300) / size) + np.arange(top + 1) * np.log(size) / size
    order = int(np.argmin(bic))
    a, s2 = np.ones(1), float(eps @ eps) / n
    if order:
        ar = scipy.linalg.solve_triangular(r[:order, :order], proj[:order])
        a, s2 = np.concatenate([[1.0], ar]), float(rss[order]) / size
        if max_root(a) >= 1.0:  # no stationary AR model of that order: the white one rather than a diverging filter
            order, a, s2 = 0, np.ones(1), float(eps @ eps) / n
    phi = scipy.signal.lfilter([1.0], a, psi[::-1], axis=0)[::-1] if order else psi
    scale = np.linalg.norm(psi, axis=0)
    scale[scale == 0] = 1.0
    j_inv = np.linalg.pinv((psi / scale).T @ (psi / scale), hermitian=True)
    middle = s2 * (phi / scale).T @ (phi / scale)
    cov = j_inv @ middle @ j_inv / np.outer(scale, scale)
    effective = float(n) if not order else float(eps @ eps) / (s2 / float(np.sum(a)) ** 2)
    return (cov + cov.T) / 2, order, effective


def max_root(c: np.ndarray) -> float:
    """Largest root magnitude of the polynomial ``c`` (0 for a constant)."""
    return float(np.max(np.abs(np.roots(c)))) if c.size > 1 else 0.0


def search_steps(h: np.ndarray, g: np.ndarray, scale: np.ndarray, gn: np.ndarray) -> Iterable[np.ndarray]:
    """Candidate steps: the Gauss-Newton step, halved up to 10 times, then Levenberg-Marquardt
    steps of growing damping (``h`` and ``g`` are in the column-scaled coordinates)."""
    for k in range(11):
        yield gn * 0.5**k / scale
    damping = np.diag(np.diag(h))
    for lam in 10.0 ** np.arange(-3, 11):
        yield np.linalg.solve(h + lam * damping, g) / scale


def check_search(max_iter: object, tol: object) -> tuple[int, float]:
    """The Gauss-Newton search's settings, checked: ``max_iter >= 1`` iterations, ``0 < tol <= 1``.

    Examples
    --------
    >>> check_search(200, 1e-7)
    (200, 1e-07)
    """
    return int(check_in_range("max_iter", max_iter, 1, np.inf)), check_in_range("tol", tol, 0.0, 1.0, low_open=True)


@dataclass(frozen=True)
class Minimum:
    """Where :func:`minimise` stopped.

    Attributes
    ----------
    theta : numpy.ndarray
        Parameters.
    eps : numpy.ndarray
        Prediction errors at ``theta``.
    psi : numpy.ndarray
        Their gradient ``-d eps / d theta`` at ``theta`` (rows as ``eps``).
    iterations : int
        Gauss-Newton iterations used.
    expected_improvement : float
        Relative loss decrease the last Gauss-Newton step promised.
    on_boundary : bool
        True when every step lowering the loss was refused for stability.
    """

    theta: np.ndarray
    eps: np.ndarray
    psi: np.ndarray
    iterations: int
    expected_improvement: float
    on_boundary: bool

    @property
    def sse(self) -> float:
        """Sum of squared prediction errors."""
        return float(self.eps @ self.eps)


def minimise(
    errors: Callable[[np.ndarray], np.ndarray],
    gradient: Callable[[np.ndarray, np.ndarray], np.ndarray],
    stable: Callable[[np.ndarray], bool],
    theta0: np.ndarray,
    *,
    name: str,
    orders: str,
    max_iter: int,
    tol: float,
    exact: float = 0.0,
) -> Minimum:
    """Damped Gauss-Newton minimisation of ``sum eps(theta)^2`` (see the module docstring).

    Parameters
    ----------
    errors : callable
        ``theta -> eps``.
    gradient : callable
        ``(theta, eps) -> psi = -d eps / d theta``, shape ``(eps.size, theta.size)``.
    stable : callable
        ``theta -> bool``: whether the predictor of ``theta`` is stable.
    theta0 : numpy.ndarray
        Starting point (stable).
    name, orders : str
        For the error messages (e.g. ``"ARMAX PEM"``, ``"na=4, nb=4, nc=2, nk=1"``).
    max_iter : int
        Most iterations.
    tol : float
        Stop when the Gauss-Newton step predicts a relative decrease below it.
    exact : float
        A sum of squared errors at or below it is an exact fit (noise-free data, round-off
        level): stop there.

    Returns
    -------
    Minimum

    Raises
    ------
    EstimationError
        No convergence in ``max_iter``, a stalled search or a singular Gauss-Newton matrix.

    Examples
    --------
    A first-order output-error fit written by hand (``eps = y - b / (1 + f q^-1) u``):

    >>> import scipy.signal
    >>> u = np.sign(np.random.default_rng(0).standard_normal(300))
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.8], u)
    >>> err = lambda th: y - scipy.signal.lfilter([0, th[0]], [1, th[1]], u)
    >>> def grad(th, e):
    ...     step = 1e-7
    ...     return np.column_stack([(e - err(th + step * np.eye(2)[k])) / step for k in range(2)])
    >>> best = minimise(err, grad, lambda th: abs(th[1]) < 1, np.array([0.3, -0.5]), name="demo",
    ...                 orders="nb=1, nf=1", max_iter=50, tol=1e-12, exact=1e-20)
    >>> np.round(best.theta, 6)
    array([ 0.5, -0.8])
    """
    theta = np.array(theta0, float)
    eps = errors(theta)
    v_now = float(eps @ eps)
    expected = np.inf
    on_boundary = False
    for iteration in range(1, max_iter + 1):
        if v_now <= exact:
            break
        psi = gradient(theta, eps)
        scale = np.linalg.norm(psi, axis=0)
        scale[scale == 0] = 1.0
        js = psi / scale
        g = js.T @ eps
        h = js.T @ js
        try:
            gn = np.linalg.solve(h, g)
        except np.linalg.LinAlgError as exc:
            raise EstimationError(f"{name}: singular Gauss-Newton matrix at iteration {iteration}") from exc
        expected = float(g @ gn) / v_now if v_now > 0 else 0.0
        if expected < tol:
            break
        accepted = False
        blocked = False
        for step in search_steps(h, g, scale, gn):
            cand = theta + step
            if not stable(cand):
                blocked = True
                continue
            eps_c = errors(cand)
            v_c = float(eps_c @ eps_c)
            if np.isfinite(v_c) and v_c < v_now:
                theta, eps, v_now = cand, eps_c, v_c
                accepted = True
                break
        if not accepted:
            if expected < 1e3 * tol:
                break
            if blocked:
                # The loss keeps falling toward a predictor polynomial with a root on the unit circle
                # (e.g. white measurement noise on a lightly damped plant, where C tends to A): stop at
                # the stability boundary, the best stable predictor.
                on_boundary = True
                break
            raise EstimationError(
                f"{name} stalled at iteration {iteration}: no step along the search direction lowers the "
                f"loss {v_now / eps.size:.6g}, yet the Gauss-Newton step predicts a relative decrease of "
                f"{expected:.3g} (tol {tol:g}); the data may not fit orders {orders}"
            )
    else:
        raise EstimationError(
            f"{name} did not converge in max_iter = {max_iter} iterations: the last Gauss-Newton step "
            f"predicts a relative decrease of {expected:.3g} > tol = {tol:g}; raise max_iter or check the "
            f"orders ({orders}) and the data"
        )
    return Minimum(theta, eps, gradient(theta, eps), iteration, expected, on_boundary)


@dataclass(frozen=True)
class Structure:
    """Orders of ``A y = B / F u + C / D e`` and the prediction errors and gradient of that structure.

    Attributes
    ----------
    na, nb, nc, nd, nf, nk : int
        Orders (``nb >= 1``) and input delay (samples).
    """

    na: int
    nb: int
    nc: int
    nd: int
    nf: int
    nk: int

    @property
    def start(self) -> int:
        """First sample with a prediction: ``max(na + nf, nk + nb - 1)``."""
        return max(self.na + self.nf, self.nk + self.nb - 1)

    @property
    def n_parameters(self) -> int:
        """Length of ``theta = [a, b, c, d, f]``."""
        return self.na + self.nb + self.nc + self.nd + self.nf

    def polynomials(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``A, B, C, D, F`` (ascending powers of ``q^-1``) of ``theta``."""
        one = np.ones(1)
        cuts = np.cumsum([self.na, self.nb, self.nc, self.nd, self.nf])
        a, b, c, d, f = np.split(np.asarray(theta, float)[: cuts[-1]], cuts[:-1])
        return (
            np.concatenate([one, a]),
            np.concatenate([np.zeros(self.nk), b]),
            np.concatenate([one, c]),
            np.concatenate([one, d]),
            np.concatenate([one, f]),
        )

    def stable(self, theta: np.ndarray) -> bool:
        """Whether the predictor's filters ``1 / C`` and ``1 / F`` are stable."""
        _, _, c, _, f = self.polynomials(theta)
        return max_root(c) < 1.0 and max_root(f) < 1.0

    def describe(self) -> str:
        """The orders as ``"na=.., nb=.., ..."`` (only the polynomials in the structure)."""
        names = ("na", "nb", "nc", "nd", "nf", "nk")
        return ", ".join(f"{n}={getattr(self, n)}" for n in names if getattr(self, n) or n in ("nb", "nk"))

    def _signals(self, theta: np.ndarray, d: SisoData) -> tuple[np.ndarray, ...]:
        a, b, c, dd, f = self.polynomials(theta)
        w = scipy.signal.lfilter(b, f, d.u)
        v = scipy.signal.lfilter(a, [1.0], d.y) - w
        return a, b, c, dd, f, w, v

    def errors(self, theta: np.ndarray, d: SisoData) -> np.ndarray:
        """Prediction errors ``eps(t)`` for ``t >= start`` (shape ``(N - start,)``)."""
        *_, c, dd, _f, _w, v = self._signals(theta, d)
        return scipy.signal.lfilter(dd, c, v[self.start :])

    def gradient(self, theta: np.ndarray, eps: np.ndarray, d: SisoData) -> np.ndarray:
        """``psi = -d eps / d theta`` (module docstring), shape ``(N - start, n_parameters)``."""
        s = self.start
        _a, _b, c, dd, f, w, v = self._signals(theta, d)
        cols = [-lag_matrix(d.y, range(1, self.na + 1), s)]
        uf = scipy.signal.lfilter([1.0], f, d.u) if self.nf else d.u
        cols.append(lag_matrix(uf, range(self.nk, self.nk + self.nb), s))
        noise_part = [lag_matrix(eps, range(1, self.nc + 1), 0)]
        v_tail = v[s:]
        noise_part.append(-lag_matrix(v_tail, range(1, self.nd + 1), 0))
        if self.nf:
            cols.append(-lag_matrix(scipy.signal.lfilter([1.0], f, w), range(1, self.nf + 1), s))
        model_part = np.hstack(cols)
        if c.size > 1 or dd.size > 1:
            model_part = scipy.signal.lfilter(dd, c, model_part, axis=0)
        noise = np.hstack(noise_part)
        if noise.shape[1]:
            noise = scipy.signal.lfilter([1.0], c, noise, axis=0)
        na_nb = self.na + self.nb
        return np.hstack([model_part[:, :na_nb], noise, model_part[:, na_nb:]])


#: Relative prediction error (against ``||y||``) below which a fit is exact (noise-free data).
_EXACT = 1e-10


def fit(
    d: SisoData | Sequence[SisoData],
    structure: Structure,
    theta0: np.ndarray,
    *,
    name: str,
    method: str,
    max_iter: int,
    tol: float,
    info: dict[str, Any] | None = None,
    coloured: bool = False,
) -> PolynomialModel:
    """Minimise the prediction errors of ``structure`` on ``d`` from ``theta0`` and build the model.

    The covariance is ``lambda (psi^T psi)^-1`` with ``lambda`` the residual variance
    (``SSE / (N - start - p)``), or with ``coloured`` the one that holds for coloured errors
    (:func:`sandwich_covariance`, its AR order and effective sample count in ``info["noise_ar_order"]`` and
    ``info["effective_samples"]``; one experiment).

    Parameters
    ----------
    d : SisoData or sequence of SisoData
        Estimation data (output and input deviations, sample time in s); several experiments are fitted
        together, each filtered from rest at its own ``start``, their errors and gradients concatenated
        (never mixing two experiments), the criterion the sum over all of them.
    structure : Structure
        Orders of the model.
    theta0 : numpy.ndarray
        Initial parameters ``[a, b, c, d, f]`` with a stable predictor.
    name, method : str
        Name in error messages and the model's ``method``.
    max_iter, tol : int, float
        As for :func:`minimise`.
    info : dict, optional
        Further entries for the model's ``info``.

    Returns
    -------
    PolynomialModel
        ``method`` as given; ``info`` holds ``iterations``, ``initial_parameters``,
        ``expected_improvement`` and ``on_stability_boundary`` (and ``info``'s entries).

    Examples
    --------
    An ARMAX(1, 1, 1, 1) fit, the structure :func:`~trms.identification.linear.armax` uses:

    >>> import scipy.signal
    >>> rng = np.random.default_rng(0)
    >>> u, e = np.sign(rng.standard_normal(2000)), 0.1 * rng.standard_normal(2000)
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.8], u) + scipy.signal.lfilter([1, 0.4], [1, -0.8], e)
    >>> m = fit(SisoData(y, u, 0.1), Structure(1, 1, 1, 0, 0, 1), np.array([-0.5, 0.3, 0.0]),
    ...         name="ARMAX PEM", method="armax-pem", max_iter=50, tol=1e-7)
    >>> np.round(m.parameters, 1)
    array([-0.8,  0.5,  0.4])
    """
    s = structure
    exps = (d,) if isinstance(d, SisoData) else tuple(d)
    if len(exps) == 1:
        one = exps[0]
        errors: Callable[[np.ndarray], np.ndarray] = lambda th: s.errors(th, one)  # noqa: E731
        gradient: Callable[[np.ndarray, np.ndarray], np.ndarray] = lambda th, e: s.gradient(th, e, one)  # noqa: E731
        exact = float((_EXACT * np.linalg.norm(one.y)) ** 2)
    else:
        cuts = np.cumsum([len(x) - s.start for x in exps])[:-1]
        errors = lambda th: np.concatenate([s.errors(th, x) for x in exps])  # noqa: E731
        gradient = lambda th, e: np.vstack(  # noqa: E731
            [s.gradient(th, part, x) for part, x in zip(np.split(e, cuts), exps)]
        )
        exact = float(_EXACT**2 * sum(float(x.y @ x.y) for x in exps))
    best = minimise(
        errors,
        gradient,
        s.stable,
        theta0,
        name=name,
        orders=s.describe(),
        max_iter=max_iter,
        tol=tol,
        exact=exact,
    )
    n_eff, p = best.eps.size, s.n_parameters
    sigma2 = best.sse / (n_eff - p)
    cov = covariance(best.psi, sigma2)
    extra: dict[str, Any] = {}
    if coloured:
        cov, extra["noise_ar_order"], extra["effective_samples"] = sandwich_covariance(best.psi, best.eps)
        cov *= n_eff / (n_eff - p)  # the same degrees-of-freedom correction as lambda's
    d = exps[0]
    return PolynomialModel.from_parameters(
        best.theta,
        s.na,
        s.nb,
        s.nc,
        s.nk,
        d.sample_time,
        nd=s.nd,
        nf=s.nf,
        noise_variance=sigma2,
        covariance=cov,
        n_samples=n_eff,
        loss=best.sse / n_eff,
        method=method,
        input_name=d.input_name,
        output_name=d.output_name,
        info={
            "iterations": best.iterations,
            "initial_parameters": np.asarray(theta0, float),
            "expected_improvement": best.expected_improvement,
            "on_stability_boundary": best.on_boundary,
            **extra,
            **(info or {}),
        },
    )
