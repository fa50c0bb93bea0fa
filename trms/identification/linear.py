"""ARX by least squares and ARMAX by the prediction-error method (thesis ch. 3.3, eq. 3.2-3.10).

Both take a :class:`~trms.identification.dataset.Dataset` of several experiments: the regressors
are formed inside each experiment (the first ``start`` samples of every experiment carry no
prediction, exactly as at the start of one record) and stacked, so the least squares, the
prediction errors and the Gauss-Newton gradient never mix samples of two experiments; the
criterion is the sum over all experiments.

ARMAX follows the procedure the thesis summarises (ch. 3.3.3):

1. initial estimate: a high-order ARX model gives an estimate of the innovations
   ``e(t)``; regressing ``y`` on past ``y``, ``u`` and those innovations gives ``A``, ``B``,
   ``C`` (Hannan-Rissanen), with any root of ``C`` outside the unit circle reflected in;
2. minimise ``V_N = 1/2 sum eps^2`` (eq. 3.10) over the conditional prediction errors
   (eq. 3.5) by damped Gauss-Newton (Levenberg-Marquardt). The gradient of the
   prediction error is the pseudo-linear regressor of eq. (3.6) filtered by ``1 / C``
   (one ``lfilter`` call on the whole regressor matrix per iteration); a step that would
   move a root of ``C`` onto or outside the unit circle is refused (more damping), so the
   predictor stays stable;
3. stop when the Gauss-Newton step promises a relative decrease of ``V_N`` below ``tol``;
   the parameter covariance is ``lambda (psi^T psi)^-1`` with ``lambda`` the residual
   variance.

A fit that does not converge raises :class:`trms.errors.EstimationError`, never returns a
half-fitted model.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.linalg
import scipy.signal

from trms.errors import EstimationError, InputError, check_int
from trms.identification.data import SisoData, check_excitation, lag_matrix
from trms.identification.dataset import siso_experiments
from trms.identification.pem import MAX_ITER, Structure, check_search, covariance, fit
from trms.identification.polynomial import PolynomialModel
from trms.record import Record

__all__ = ["arx", "armax"]

#: The Gauss-Newton search's default settings (most iterations, relative decrease at which it stops).
_TOL = 1e-7

#: Smallest ratio of samples to estimated parameters accepted.
_SAMPLES_PER_PARAMETER = 2


def _check_orders(na: int, nb: int, nc: int, nk: int) -> tuple[int, int, int, int]:
    return check_int("na", na, 0), check_int("nb", nb, 1), check_int("nc", nc, 0), check_int("nk", nk, 0)


def _check_size(n: int, start: int, n_params: int, orders: str) -> None:
    need = start + _SAMPLES_PER_PARAMETER * n_params + 1
    if n < need:
        raise InputError(
            f"orders {orders} ({n_params} parameters, first prediction at sample {start}) need at least "
            f"{need} samples ({_SAMPLES_PER_PARAMETER} per parameter); the data have {n}"
        )


def _check_sizes(exps: tuple[SisoData, ...], start: int, n_params: int, orders: str) -> None:
    """:func:`_check_size` for one experiment; for several, each must reach ``start`` and together give the rows."""
    if len(exps) == 1:
        _check_size(len(exps[0]), start, n_params, orders)
        return
    for i, d in enumerate(exps):
        if len(d) <= start:
            raise InputError(
                f"experiment {i + 1} of {len(exps)} has {len(d)} samples; orders {orders} need more than "
                f"start = {start} in every experiment"
            )
    rows = sum(len(d) - start for d in exps)
    need = _SAMPLES_PER_PARAMETER * n_params + 1
    if rows < need:
        raise InputError(
            f"orders {orders} ({n_params} parameters) need at least {need} predictions "
            f"({_SAMPLES_PER_PARAMETER} per parameter); the {len(exps)} experiments give {rows}"
        )


def _regressors(d: SisoData, na: int, nb: int, nk: int, start: int) -> np.ndarray:
    """``[-y(t-1)..-y(t-na), u(t-nk)..u(t-nk-nb+1)]`` for ``t >= start`` (eq. 3.6 without the noise part)."""
    return np.hstack([-lag_matrix(d.y, range(1, na + 1), start), lag_matrix(d.u, range(nk, nk + nb), start)])


def _stacked(exps: tuple[SisoData, ...], na: int, nb: int, nk: int, start: int) -> tuple[np.ndarray, np.ndarray]:
    """ARX regressors and targets of every experiment, each formed inside its experiment, stacked."""
    if len(exps) == 1:
        return _regressors(exps[0], na, nb, nk, start), exps[0].y[start:]
    phi = np.vstack([_regressors(d, na, nb, nk, start) for d in exps])
    return phi, np.concatenate([d.y[start:] for d in exps])


def _experiment_info(exps: tuple[SisoData, ...]) -> dict[str, int]:
    """``{"experiments": k}`` for several experiments, nothing for one."""
    return {"experiments": len(exps)} if len(exps) > 1 else {}


def _solve_ls(phi: np.ndarray, target: np.ndarray, what: str) -> np.ndarray:
    """Least squares with column scaling; refuses (numerically) dependent regressors."""
    scale = np.linalg.norm(phi, axis=0)
    if np.any(scale == 0):
        raise EstimationError(f"{what}: a regressor column is identically zero (no excitation)")
    q, r = np.linalg.qr(phi / scale)
    diag = np.abs(np.diag(r))
    if diag.min() < 1e-10 * diag.max():
        raise EstimationError(
            f"{what}: the regressors are linearly dependent (condition > 1e10) -- orders too high for "
            "noise-free data (A and B share a factor) or an input that does not excite them"
        )
    return scipy.linalg.solve_triangular(r, q.T @ target) / scale


def arx(
    data: Record | object,
    u: object | None = None,
    na: int = 4,
    nb: int = 4,
    nk: int = 1,
    *,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
) -> PolynomialModel:
    """ARX model ``A y = B u + e`` by linear least squares.

    Parameters
    ----------
    data : Record, Dataset or array_like
        A Record (deviations are used), a :class:`~trms.identification.dataset.Dataset` (every
        experiment is used, none joined to the next: see the module docstring) or the output
        ``y`` (shape ``(N,)``).
    u : array_like, optional
        Input with an array ``y``.
    na, nb, nk : int
        Orders: ``na >= 0`` poles, ``nb >= 1`` input coefficients, input delay ``nk >= 0`` samples.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.

    Returns
    -------
    PolynomialModel
        With ``C = [1]``, the least-squares covariance and ``method = "arx"``; with several
        experiments ``info["experiments"]`` counts them and ``n_samples`` sums their predictions.

    Raises
    ------
    InputError
        Bad data, orders too large for the data, an input that is not persistently exciting.
    EstimationError
        Linearly dependent regressors.

    Examples
    --------
    Two experiments of a first-order system, each started from rest, fitted together:

    >>> rng = np.random.default_rng(0)
    >>> us = [np.sign(rng.standard_normal(n)) for n in (300, 200)]
    >>> ys = [scipy.signal.lfilter([0, 0.5], [1, -0.8], u) for u in us]
    >>> from trms.identification.dataset import Dataset
    >>> model = arx(Dataset(ys, us, 0.1), na=1, nb=1)
    >>> np.round(model.parameters, 6), model.info["experiments"], model.n_samples
    (array([-0.8,  0.5]), 2, 498)
    """
    exps = siso_experiments(data, u, sample_time=sample_time, input=input, output=output)
    na, nb, _, nk = _check_orders(na, nb, 0, nk)
    return _arx(exps, na, nb, nk)


def _arx(exps: tuple[SisoData, ...], na: int, nb: int, nk: int) -> PolynomialModel:
    """:func:`arx` on checked orders."""
    start = max(na, nk + nb - 1)
    _check_sizes(exps, start, na + nb, f"na={na}, nb={nb}, nk={nk}")
    check_excitation(exps[0].u if len(exps) == 1 else [d.u for d in exps], nb)
    phi, target = _stacked(exps, na, nb, nk, start)
    theta = _solve_ls(phi, target, "ARX least squares")
    eps = target - phi @ theta
    n_eff, p = eps.size, theta.size
    sigma2 = float(eps @ eps / (n_eff - p))
    d = exps[0]
    return PolynomialModel.from_parameters(
        theta,
        na,
        nb,
        0,
        nk,
        d.sample_time,
        noise_variance=sigma2,
        covariance=covariance(phi, sigma2),
        n_samples=n_eff,
        loss=float(eps @ eps / n_eff),
        method="arx",
        input_name=d.input_name,
        output_name=d.output_name,
        info=_experiment_info(exps),
    )


def _stabilise(c: np.ndarray, radius: float = 0.99) -> np.ndarray:
    """Reflect roots of the monic polynomial ``c`` outside the unit circle to ``1 / conj(r)``, cap at ``radius``."""
    if c.size <= 1:
        return c
    roots = np.roots(c)
    mag = np.abs(roots)
    if np.all(mag < radius):
        return c
    fixed = np.where(mag >= 1.0, roots / np.maximum(mag, 1.0) ** 2, roots)
    fixed = np.where(np.abs(fixed) > radius, fixed / np.maximum(np.abs(fixed), radius) * radius, fixed)
    return np.real(np.poly(fixed))


def _initial_armax(d: SisoData | tuple[SisoData, ...], na: int, nb: int, nc: int, nk: int, start: int) -> np.ndarray:
    """Hannan-Rissanen: innovations from a high-order ARX, then least squares on y, u and them.

    With several experiments both regressions stack the experiments (those shorter than the
    high-order ARX's start do not enter the initial estimate)."""
    exps = (d,) if isinstance(d, SisoData) else d
    n = sum(len(x) for x in exps)
    order = max(na, nk + nb - 1, nc)
    high = int(min(max(20, 3 * order), max(order + 1, (n - start) // 10)))
    hi_start = max(high, nk + high - 1)
    s = max(start, hi_start + nc)
    usable = tuple(x for x in exps if len(x) > s) or exps
    phis_hi = [_regressors(x, high, high, nk, hi_start) for x in usable]
    phi_hi = phis_hi[0] if len(usable) == 1 else np.vstack(phis_hi)
    target_hi = np.concatenate([x.y[hi_start:] for x in usable])
    theta_hi = _solve_ls(phi_hi, target_hi, f"initial high-order ARX ({high}, {high})")
    rows, targets = [], []
    for x, phi_x in zip(usable, phis_hi):
        e_hat = np.zeros(len(x))
        e_hat[hi_start:] = x.y[hi_start:] - phi_x @ theta_hi
        rows.append(np.hstack([_regressors(x, na, nb, nk, s), lag_matrix(e_hat, range(1, nc + 1), s)]))
        targets.append(x.y[s:])
    theta = _solve_ls(np.vstack(rows), np.concatenate(targets), "initial ARMAX regression")
    c = _stabilise(np.concatenate([[1.0], theta[na + nb :]]))
    theta[na + nb :] = c[1:]
    return theta


#: Relative one-step error of an ARX fit below which the data count as noise-free.
_NOISE_FREE = 1e-9


def _noise_free_armax(
    exps: tuple[SisoData, ...], na: int, nb: int, nc: int, nk: int, start: int
) -> PolynomialModel | None:
    """The exact model when ``y`` is an exact ARX output of orders ``(na, nb, nk)`` (no noise).

    Then ``e = 0`` and ``C`` is not identifiable; the ARX fit is the model, with ``C = 1`` (its
    ``nc`` coefficients 0, their covariance 0). Returns None for data with noise.
    """
    d = exps[0]
    phi, target = _stacked(exps, na, nb, nk, start)
    try:
        theta = _solve_ls(phi, target, "ARX least squares")
    except EstimationError:
        return None
    eps = target - phi @ theta
    if np.linalg.norm(eps) > _NOISE_FREE * np.linalg.norm(target):
        return None
    n_eff = eps.size
    sigma2 = float(eps @ eps / (n_eff - na - nb - nc))
    psi = np.hstack([phi, np.zeros((n_eff, nc))])
    return PolynomialModel.from_parameters(
        np.concatenate([theta, np.zeros(nc)]),
        na,
        nb,
        nc,
        nk,
        d.sample_time,
        noise_variance=sigma2,
        covariance=covariance(psi, sigma2),
        n_samples=n_eff,
        loss=float(eps @ eps / n_eff),
        method="armax-pem",
        input_name=d.input_name,
        output_name=d.output_name,
        info={"iterations": 0, "noise_free": True, **_experiment_info(exps)},
    )


def _pem(
    exps: tuple[SisoData, ...], structure: Structure, theta0: np.ndarray, *, name: str, method: str, **search: Any
) -> PolynomialModel:
    """:func:`~trms.identification.pem.fit` over one or several experiments (``info["experiments"]`` for several)."""
    return fit(
        exps[0] if len(exps) == 1 else exps,
        structure,
        theta0,
        name=name,
        method=method,
        info=_experiment_info(exps) or None,
        **search,
    )


def armax(
    data: Record | object,
    u: object | None = None,
    na: int = 4,
    nb: int = 4,
    nc: int = 4,
    nk: int = 1,
    *,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
    max_iter: int = MAX_ITER,
    tol: float = _TOL,
) -> PolynomialModel:
    """ARMAX model ``A y = B u + C e`` (eq. 3.2) by the prediction-error method (eq. 3.3-3.10).

    Parameters
    ----------
    data : Record, Dataset or array_like
        A Record (deviations are used), a :class:`~trms.identification.dataset.Dataset` of one or
        several experiments (each filtered from rest at its own start) or the output ``y`` (shape ``(N,)``).
    u : array_like, optional
        Input with an array ``y``.
    na, nb, nc, nk : int
        Orders and input delay (samples); the thesis's (3.11) is ``na = nb = 4``, ``nk = 1``.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.
    max_iter : int
        Most Gauss-Newton iterations (default :data:`~trms.identification.pem.MAX_ITER`).
    tol : float
        Convergence: the Gauss-Newton step's predicted relative decrease of the loss. A
        parameter ``k`` standard errors from the optimum costs a relative loss of about
        ``k^2 / N``, so the default ``1e-7`` stops within ~0.01 standard error for N < 10^4.

    Returns
    -------
    PolynomialModel
        ``method = "armax-pem"``; ``info`` holds ``iterations``, ``initial_parameters`` and
        ``expected_improvement``, and ``on_stability_boundary`` (True when the search stopped
        because every step that lowers the loss would put a root of ``C`` outside the unit circle:
        the optimum lies on the boundary of invertible noise models). Exactly noise-free data
        that an ARX model of orders ``(na, nb, nk)`` reproduces (relative one-step error below
        ``1e-9``) return that exact model with ``C = 1`` and ``info["noise_free"] = True``.

    Raises
    ------
    InputError
        Bad data, orders too large for the data, an input that is not persistently exciting.
    EstimationError
        No convergence within ``max_iter`` or linearly dependent regressors.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> u, e = np.sign(rng.standard_normal(3000)), 0.1 * rng.standard_normal(3000)
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.8], u) + scipy.signal.lfilter([1, 0.4], [1, -0.8], e)
    >>> from trms.identification.dataset import Dataset
    >>> model = armax(Dataset([y[:1800], y[1800:]], [u[:1800], u[1800:]], 0.1), na=1, nb=1, nc=1)
    >>> np.round(model.parameters, 1)
    array([-0.8,  0.5,  0.4])
    """
    exps = siso_experiments(data, u, sample_time=sample_time, input=input, output=output)
    na, nb, nc, nk = _check_orders(na, nb, nc, nk)
    max_iter, tol = check_search(max_iter, tol)
    return _armax(exps, na, nb, nc, nk, max_iter, tol)


def _armax(
    exps: tuple[SisoData, ...], na: int, nb: int, nc: int, nk: int, max_iter: int, tol: float
) -> PolynomialModel:
    """:func:`armax` on checked orders and search settings."""
    start = max(na, nk + nb - 1)
    p = na + nb + nc
    _check_sizes(exps, start, p, f"na={na}, nb={nb}, nc={nc}, nk={nk}")
    check_excitation(exps[0].u if len(exps) == 1 else [d.u for d in exps], nb)
    if nc == 0:
        return _arx(exps, na, nb, nk)
    try:
        theta0 = _initial_armax(exps, na, nb, nc, nk, start)
    except EstimationError:
        # noise-free data make the innovations regression singular: the exact ARX model, if it fits
        exact = _noise_free_armax(exps, na, nb, nc, nk, start)
        if exact is None:
            raise
        return exact
    model = _pem(
        exps, Structure(na, nb, nc, 0, 0, nk), theta0, name="ARMAX PEM", method="armax-pem", max_iter=max_iter, tol=tol
    )
    target_sq = sum(float(d.y[start:] @ d.y[start:]) for d in exps)
    if model.loss <= _NOISE_FREE**2 * target_sq / model.n_samples:
        # an exact fit: C is not identifiable from round-off innovations; return the exact ARX form
        exact = _noise_free_armax(exps, na, nb, nc, nk, start)
        if exact is not None:
            return exact
    return model
