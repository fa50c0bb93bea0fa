"""Output-error and Box-Jenkins models by the prediction-error method (MATLAB ``oe``, ``bj``).

* output-error (OE): ``y = B / F u + e``; the prediction error is the simulation error
  ``y - B / F u``, so the fit targets the input-output dynamics alone and stays unbiased
  under any (coloured) output disturbance, at the price of an unmodelled noise spectrum;
* Box-Jenkins (BJ): ``y = B / F u + C / D e``; independent dynamics for the plant and the
  disturbance (ARMAX forces them to share the poles ``A``). With coloured disturbances
  that do not share the plant's poles, ARMAX of the true order is biased; BJ is not.

Both minimise the same criterion as :func:`trms.identification.linear.armax` with the same
damped Gauss-Newton search (:mod:`trms.identification.pem`) and return the same
:class:`~trms.identification.polynomial.PolynomialModel` (with ``F`` and ``D``), its
parameter covariance ``lambda (psi^T psi)^-1`` and :meth:`~PolynomialModel.to_tf`.

Initial estimates
-----------------
* ``B, F``: Steiglitz-McBride iterations: refit ARX of orders ``(nf, nb, nk)`` to ``y`` and
  ``u`` both filtered by the last ``1 / F`` (roots of ``F`` reflected into the unit circle),
  which converges to the output-error estimate for white noise;
* ``C, D`` (BJ): Hannan-Rissanen on the output-error residual ``v = y - B / F u``: a
  high-order AR fit gives innovations ``e``, then ``v`` is regressed on its own past (``D``)
  and the past innovations (``C``).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import scipy.signal

from ..errors import EstimationError
from ..plant import Record
from .data import SisoData, check_excitation, check_int, lag_matrix, siso_data
from .linear import _check_size, _regressors, _solve_ls, _stabilise
from .pem import Structure, check_search, fit
from .polynomial import PolynomialModel

__all__ = ["oe", "bj"]

#: Most Steiglitz-McBride iterations for the initial ``B, F``.
_SM_ITERATIONS = 30


def _steiglitz_mcbride(d: SisoData, nb: int, nf: int, nk: int) -> np.ndarray:
    """Initial ``[b1..b_nb, f1..f_nf]``: ARX of ``(y, u)`` prefiltered by ``1 / F``, iterated."""
    start = max(nf, nk + nb - 1)
    f = np.ones(1)
    theta = np.zeros(nb + nf)
    for _ in range(_SM_ITERATIONS if nf else 1):
        yf, uf = scipy.signal.lfilter([1.0], f, d.y), scipy.signal.lfilter([1.0], f, d.u)
        phi = _regressors(SisoData(yf, uf, d.sample_time), nf, nb, nk, start)
        est = _solve_ls(phi, yf[start:], "initial Steiglitz-McBride ARX")
        f_new = _stabilise(np.concatenate([[1.0], est[:nf]]))
        theta_new = np.concatenate([est[nf:], f_new[1:]])
        done = np.allclose(theta_new, theta, rtol=1e-8, atol=1e-10)
        theta, f = theta_new, f_new
        if done:
            break
    return theta


def _hannan_rissanen_arma(v: np.ndarray, nc: int, nd: int) -> np.ndarray:
    """Initial ``[c1..c_nc, d1..d_nd]`` of ``D v = C e`` (noise-free ``v`` gives ``C = D = 1``)."""
    n = v.size
    high = int(min(max(20, 3 * max(nc, nd)), max(max(nc, nd) + 1, n // 10)))
    phi_hi = -lag_matrix(v, range(1, high + 1), high)
    if not np.any(phi_hi):
        return np.zeros(nc + nd)
    try:
        ar = _solve_ls(phi_hi, v[high:], f"initial high-order AR ({high}) of the noise")
    except EstimationError:
        return np.zeros(nc + nd)
    e_hat = np.zeros(n)
    e_hat[high:] = v[high:] - phi_hi @ ar
    s = high + nc
    phi = np.hstack([lag_matrix(e_hat, range(1, nc + 1), s), -lag_matrix(v, range(1, nd + 1), s)])
    try:
        cd = _solve_ls(phi, v[s:], "initial ARMA regression of the noise")
    except EstimationError:
        return np.zeros(nc + nd)
    c = _stabilise(np.concatenate([[1.0], cd[:nc]]))
    dd = _stabilise(np.concatenate([[1.0], cd[nc:]]))
    return np.concatenate([c[1:], dd[1:]])


def _prepare(
    data: Record | object,
    u: object | None,
    orders: Mapping[str, tuple[object, int]],
    sample_time: float | None,
    input: str | None,
    output: str | None,
    max_iter: object,
    tol: object,
) -> tuple[SisoData, dict[str, int], Structure, int, float]:
    """Data, checked orders (``nb nc nd nf nk``; absent ones 0), the structure and the search settings.

    Refuses orders the data cannot support and an input that does not excite ``nb + nf`` parameters.
    """
    d = siso_data(data, u, sample_time=sample_time, input=input, output=output)
    o = {"nc": 0, "nd": 0} | {name: check_int(name, value, low) for name, (value, low) in orders.items()}
    max_iter, tol = check_search(max_iter, tol)
    structure = Structure(0, o["nb"], o["nc"], o["nd"], o["nf"], o["nk"])
    _check_size(len(d), structure.start, structure.n_parameters, structure.describe())
    check_excitation(d.u, o["nb"] + o["nf"])
    return d, o, structure, max_iter, tol


def oe(
    data: Record | object,
    u: object | None = None,
    nb: int = 2,
    nf: int = 2,
    nk: int = 1,
    *,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
    max_iter: int = 200,
    tol: float = 1e-7,
) -> PolynomialModel:
    """Output-error model ``y = B / F u + e`` by the prediction-error method (MATLAB ``oe``).

    Parameters
    ----------
    data : Record or array_like
        A Record (deviations are used) or the output ``y`` (shape ``(N,)``, output unit).
    u : array_like, optional
        Input with an array ``y`` (shape ``(N,)``, input unit, e.g. V).
    nb, nf, nk : int
        ``nb >= 1`` numerator coefficients, ``nf >= 0`` poles, input delay ``nk >= 0`` samples.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.
    max_iter : int
        Most Gauss-Newton iterations.
    tol : float
        Convergence: the Gauss-Newton step's predicted relative decrease of the loss (as
        :func:`~trms.identification.linear.armax`).

    Returns
    -------
    PolynomialModel
        ``A = C = D = 1``, ``method = "oe-pem"``; the covariance of ``[b1..b_nb, f1..f_nf]``
        assumes white output noise (MATLAB's convention); ``info`` as for
        :func:`~trms.identification.pem.fit`.

    Raises
    ------
    InputError
        Bad data, orders too large for the data, an input that is not persistently exciting.
    EstimationError
        No convergence within ``max_iter`` or linearly dependent regressors.

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> u = np.sign(np.random.default_rng(0).standard_normal(500))
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.8], u) + 0.05 * np.random.default_rng(1).standard_normal(500)
    >>> model = oe(y, u, nb=1, nf=1, nk=1, sample_time=0.1)
    >>> bool(abs(model.F[1] + 0.8) < 0.01)
    True
    """
    orders = {"nb": (nb, 1), "nf": (nf, 0), "nk": (nk, 0)}
    d, o, structure, max_iter, tol = _prepare(data, u, orders, sample_time, input, output, max_iter, tol)
    theta0 = _steiglitz_mcbride(d, o["nb"], o["nf"], o["nk"])
    return fit(d, structure, theta0, name="OE PEM", method="oe-pem", max_iter=max_iter, tol=tol)


def bj(
    data: Record | object,
    u: object | None = None,
    nb: int = 2,
    nc: int = 2,
    nd: int = 2,
    nf: int = 2,
    nk: int = 1,
    *,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
    max_iter: int = 200,
    tol: float = 1e-7,
) -> PolynomialModel:
    """Box-Jenkins model ``y = B / F u + C / D e`` by the prediction-error method (MATLAB ``bj``).

    Parameters
    ----------
    data : Record or array_like
        A Record (deviations are used) or the output ``y`` (shape ``(N,)``, output unit).
    u : array_like, optional
        Input with an array ``y`` (shape ``(N,)``, input unit, e.g. V).
    nb, nc, nd, nf, nk : int
        MATLAB's order names: ``nb >= 1`` numerator coefficients, ``nc >= 0`` and ``nd >= 0``
        noise numerator and denominator orders, ``nf >= 0`` poles of the plant, input delay
        ``nk >= 0`` samples.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.
    max_iter : int
        Most Gauss-Newton iterations.
    tol : float
        Convergence: the Gauss-Newton step's predicted relative decrease of the loss.

    Returns
    -------
    PolynomialModel
        ``A = 1``, ``method = "bj-pem"``; the covariance covers ``[b, c, d, f]``; ``info`` as for
        :func:`~trms.identification.pem.fit`.

    Raises
    ------
    InputError
        Bad data, orders too large for the data, an input that is not persistently exciting.
    EstimationError
        No convergence within ``max_iter`` or linearly dependent regressors.

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> rng = np.random.default_rng(0)
    >>> u = np.sign(rng.standard_normal(2000))
    >>> noise = scipy.signal.lfilter([1, 0.3], [1, -0.9], 0.05 * rng.standard_normal(2000))
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.8], u) + noise
    >>> model = bj(y, u, nb=1, nc=1, nd=1, nf=1, nk=1, sample_time=0.1)
    >>> bool(abs(model.dc_gain() - 2.5) < 0.1)
    True
    """
    orders = {"nb": (nb, 1), "nc": (nc, 0), "nd": (nd, 0), "nf": (nf, 0), "nk": (nk, 0)}
    d, o, structure, max_iter, tol = _prepare(data, u, orders, sample_time, input, output, max_iter, tol)
    bf = _steiglitz_mcbride(d, o["nb"], o["nf"], o["nk"])
    b, f = np.concatenate([np.zeros(o["nk"]), bf[: o["nb"]]]), np.concatenate([[1.0], bf[o["nb"] :]])
    cd = _hannan_rissanen_arma(d.y - scipy.signal.lfilter(b, f, d.u), o["nc"], o["nd"])
    theta0 = np.concatenate([bf[: o["nb"]], cd, bf[o["nb"] :]])
    return fit(d, structure, theta0, name="BJ PEM", method="bj-pem", max_iter=max_iter, tol=tol)
