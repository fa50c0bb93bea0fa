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

from trms.errors import EstimationError
from trms.identification.data import SisoData, check_excitation, lag_matrix
from trms.identification.dataset import siso_experiments
from trms.identification.pem import MAX_ITER, Structure, check_search, covariance, fit
from trms.identification.polynomial import PolynomialModel
from trms.identification.regression import (
    arx_regressors,
    check_orders,
    check_sizes,
    solve_ls,
    stabilise,
    stacked_regressors,
)
from trms.record import Record

__all__ = ["arx", "armax"]

#: The Gauss-Newton search's default settings (most iterations, relative decrease at which it stops).
PEM_TOL = 1e-7


def _experiment_info(exps: tuple[SisoData, ...]) -> dict[str, int]:
    """``{"experiments": k}`` for several experiments, nothing for one."""
    return {"experiments": len(exps)} if len(exps) > 1 else {}


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

    >>> import scipy.signal
    >>> rng = np.random.default_rng(0)
    >>> us = [np.sign(rng.standard_normal(n)) for n in (300, 200)]
    >>> ys = [scipy.signal.lfilter([0, 0.5], [1, -0.8], u) for u in us]
    >>> from trms.identification.dataset import Dataset
    >>> model = arx(Dataset(ys, us, 0.1), na=1, nb=1)
    >>> np.round(model.parameters, 6), model.info["experiments"], model.n_samples
    (array([-0.8,  0.5]), 2, 498)
    """
    exps = siso_experiments(data, u, sample_time=sample_time, input=input, output=output)
    na, nb, _, nk = check_orders(na, nb, 0, nk)
    return arx_experiments(exps, na, nb, nk)


def arx_experiments(exps: tuple[SisoData, ...], na: int, nb: int, nk: int) -> PolynomialModel:
    """:func:`arx` on checked orders."""
    start = max(na, nk + nb - 1)
    check_sizes(exps, start, na + nb, f"na={na}, nb={nb}, nk={nk}")
    check_excitation(exps[0].u if len(exps) == 1 else [d.u for d in exps], nb)
    phi, target = stacked_regressors(exps, na, nb, nk, start)
    theta = solve_ls(phi, target, "ARX least squares")
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


def initial_armax(d: SisoData | tuple[SisoData, ...], na: int, nb: int, nc: int, nk: int, start: int) -> np.ndarray:
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
    phis_hi = [arx_regressors(x, high, high, nk, hi_start) for x in usable]
    phi_hi = phis_hi[0] if len(usable) == 1 else np.vstack(phis_hi)
    target_hi = np.concatenate([x.y[hi_start:] for x in usable])
    theta_hi = solve_ls(phi_hi, target_hi, f"initial high-order ARX ({high}, {high})")
    rows, targets = [], []
    for x, phi_x in zip(usable, phis_hi):
        e_hat = np.zeros(len(x))
        e_hat[hi_start:] = x.y[hi_start:] - phi_x @ theta_hi
        rows.append(np.hstack([arx_regressors(x, na, nb, nk, s), lag_matrix(e_hat, range(1, nc + 1), s)]))
        targets.append(x.y[s:])
    theta = solve_ls(np.vstack(rows), np.concatenate(targets), "initial ARMAX regression")
    c = stabilise(np.concatenate([[1.0], theta[na + nb :]]))
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
    phi, target = stacked_regressors(exps, na, nb, nk, start)
    try:
        theta = solve_ls(phi, target, "ARX least squares")
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
    tol: float = PEM_TOL,
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
    >>> import scipy.signal
    >>> rng = np.random.default_rng(1)
    >>> u, e = np.sign(rng.standard_normal(3000)), 0.1 * rng.standard_normal(3000)
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.8], u) + scipy.signal.lfilter([1, 0.4], [1, -0.8], e)
    >>> from trms.identification.dataset import Dataset
    >>> model = armax(Dataset([y[:1800], y[1800:]], [u[:1800], u[1800:]], 0.1), na=1, nb=1, nc=1)
    >>> np.round(model.parameters, 1)
    array([-0.8,  0.5,  0.4])
    """
    exps = siso_experiments(data, u, sample_time=sample_time, input=input, output=output)
    na, nb, nc, nk = check_orders(na, nb, nc, nk)
    max_iter, tol = check_search(max_iter, tol)
    return armax_experiments(exps, na, nb, nc, nk, max_iter, tol)


def armax_experiments(
    exps: tuple[SisoData, ...], na: int, nb: int, nc: int, nk: int, max_iter: int, tol: float
) -> PolynomialModel:
    """:func:`armax` on checked orders and search settings."""
    start = max(na, nk + nb - 1)
    p = na + nb + nc
    check_sizes(exps, start, p, f"na={na}, nb={nb}, nc={nc}, nk={nk}")
    check_excitation(exps[0].u if len(exps) == 1 else [d.u for d in exps], nb)
    if nc == 0:
        return arx_experiments(exps, na, nb, nk)
    try:
        theta0 = initial_armax(exps, na, nb, nc, nk, start)
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
