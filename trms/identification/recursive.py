"""Recursive (online) ARX and ARMAX: recursive least squares with exponential forgetting.

Each sample ``t`` updates the parameter estimate ``theta`` (layout of
:attr:`~trms.identification.polynomial.PolynomialModel.parameters`: ``[a1..a_na, b1..b_nb, c1..c_nc]``)
and the scaled covariance ``P`` from the regressor ``phi(t)``:

``e(t) = y(t) - phi(t)^T theta(t-1)`` (a-priori prediction error),
``K(t) = P(t-1) phi(t) / (lambda + phi(t)^T P(t-1) phi(t))``,
``theta(t) = theta(t-1) + K(t) e(t)``,
``P(t) = (P(t-1) - K(t) phi(t)^T P(t-1)) / lambda``.

* ARX: ``phi(t) = [-y(t-1)..-y(t-na), u(t-nk)..u(t-nk-nb+1)]`` (recursive least squares).
* ARMAX: the regressor also holds the past a-posteriori residuals
  ``eps(s) = y(s) - phi(s)^T theta(s)``, ``s = t-1 .. t-nc``, in place of the unknown
  innovations (recursive extended least squares, RELS, also called recursive
  pseudo-linear regression). It converges to the true ``A, B, C`` when
  ``1 / C(e^{jw}) - 1/2`` is strictly positive real (e.g. the roots of ``C`` well inside the unit circle).

Forgetting ``lambda`` in ``(0, 1]`` (default 1.0: no forgetting, every sample weighs the same)
discounts a sample ``k`` steps old by ``lambda^k``: the estimate remembers about
``1 / (1 - lambda)`` samples (50 for 0.98), so it tracks parameters that change at that scale.
The initial covariance is ``P(0) = p0 I`` with ``p0`` = ``initial_covariance`` (default
``1e4``), the initial parameters zero unless given. With ``lambda = 1`` the estimate is the
regularised least-squares solution ``(Phi^T Phi + I / p0)^-1 (Phi^T y + theta0 / p0)``, so for
large ``p0`` recursive ARX ends at batch :func:`~trms.identification.linear.arx`.

As in the batch estimators, no update is made before sample ``start = max(na, nk + nb - 1)``
(the first sample whose regressor needs no value before the record); the trajectory holds
the initial parameters until then.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trms.errors import InputError, as_finite_array, check_in_range, check_int
from trms.identification.data import siso_data
from trms.identification.polynomial import PolynomialModel
from trms.identification.regression import arx_regressors
from trms.record import Record

__all__ = ["RecursiveResult", "RecursiveEstimator", "recursive_arx", "recursive_armax", "DEFAULT_INITIAL_COVARIANCE"]

#: Default ``p0`` of the initial covariance ``P(0) = p0 I``.
DEFAULT_INITIAL_COVARIANCE = 1e4


@dataclass(frozen=True)
class RecursiveResult:
    """What :func:`recursive_arx` and :func:`recursive_armax` return.

    Attributes
    ----------
    trajectory : numpy.ndarray
        Parameter estimate after each sample, shape ``(N, p)`` (row ``t`` is ``theta(t)``).
    prediction_errors : numpy.ndarray
        A-priori one-step prediction errors ``y(t) - phi(t)^T theta(t-1)`` (output unit), shape
        ``(N,)``, zero before ``start``.
    covariance : numpy.ndarray
        The final scaled covariance ``P(N-1)``, shape ``(p, p)``.
    model : PolynomialModel
        The final estimate as a model (``method`` ``"recursive-arx"`` or ``"recursive-armax"``).
    """

    trajectory: np.ndarray
    prediction_errors: np.ndarray
    covariance: np.ndarray
    model: PolynomialModel


def _check_settings(
    na: object, nb: object, nc: object, nk: object, forgetting: object, initial_covariance: object
) -> tuple[int, int, int, int, float, float]:
    orders = check_int("na", na, 0), check_int("nb", nb, 1), check_int("nc", nc, 0), check_int("nk", nk, 0)
    lam = check_in_range("forgetting", forgetting, 0.0, 1.0, low_open=True)
    p0 = check_in_range("initial_covariance", initial_covariance, 0.0, np.inf, low_open=True)
    return (*orders, lam, p0)


def _initial(initial_parameters: object | None, p: int) -> np.ndarray:
    if initial_parameters is None:
        return np.zeros(p)
    return as_finite_array("initial_parameters", initial_parameters, (p,))


def _rls_step(
    theta: np.ndarray, cov: np.ndarray, phi: np.ndarray, y: float, lam: float
) -> tuple[np.ndarray, np.ndarray, float]:
    """One update: new ``theta`` and ``P`` and the a-priori error (``P`` kept symmetric)."""
    p_phi = cov @ phi
    gain = p_phi / (lam + phi @ p_phi)
    err = y - phi @ theta
    cov = (cov - np.outer(gain, p_phi)) / lam
    return theta + gain * err, 0.5 * (cov + cov.T), float(err)


def _model(
    theta: np.ndarray,
    cov: np.ndarray,
    products: np.ndarray,
    orders: tuple[int, int, int, int],
    sample_time: float,
    lam: float,
    names: tuple[str, str],
) -> PolynomialModel:
    """The final estimate: noise variance from ``products`` (a-priori times a-posteriori errors), covariance
    ``sigma^2 P``.

    With ``lambda = 1`` the sum of the products is the least-squares loss of the final estimate
    (the recursion of the loss), so ``sigma^2`` is the batch estimate's.
    """
    na, nb, nc, nk = orders
    n_eff, p = products.size, theta.size
    sse = float(np.sum(products))
    sigma2 = sse / (n_eff - p) if n_eff > p else float("nan")
    return PolynomialModel.from_parameters(
        theta,
        na,
        nb,
        nc,
        nk,
        sample_time,
        noise_variance=sigma2,
        covariance=sigma2 * cov if np.isfinite(sigma2) else None,
        n_samples=n_eff,
        loss=sse / n_eff if n_eff else float("nan"),
        method="recursive-armax" if nc else "recursive-arx",
        input_name=names[0],
        output_name=names[1],
        info={"forgetting": lam},
    )


def _recursive(
    data: Record | object,
    u: object | None,
    na: int,
    nb: int,
    nc: int,
    nk: int,
    forgetting: float,
    initial_covariance: float,
    initial_parameters: object | None,
    sample_time: float | None,
    input: str | None,
    output: str | None,
) -> RecursiveResult:
    """:func:`recursive_arx` / :func:`recursive_armax`: the known regressors at once, one loop for the rest."""
    na, nb, nc, nk, lam, p0 = _check_settings(na, nb, nc, nk, forgetting, initial_covariance)
    d = siso_data(data, u, sample_time=sample_time, input=input, output=output)
    n, p = len(d), na + nb + nc
    start = max(na, nk + nb - 1)
    if n <= start:
        raise InputError(f"the data have {n} samples; orders na={na}, nb={nb}, nk={nk} need more than {start}")
    theta = _initial(initial_parameters, p)
    cov = p0 * np.eye(p)
    known = arx_regressors(d, na, nb, nk, 0)
    trajectory = np.empty((n, p))
    trajectory[:start] = theta
    errors = np.zeros(n)
    residuals = np.zeros(n + nc)  # nc leading zeros: residuals before start are taken as zero
    phi = np.zeros(p)
    m = na + nb
    for t in range(start, n):
        phi[:m] = known[t]
        if nc:
            phi[m:] = residuals[t : t + nc][::-1]
        theta, cov, errors[t] = _rls_step(theta, cov, phi, d.y[t], lam)
        residuals[t + nc] = d.y[t] - phi @ theta
        trajectory[t] = theta
    products = errors[start:] * residuals[nc + start :]
    model = _model(theta, cov, products, (na, nb, nc, nk), d.sample_time, lam, (d.input_name, d.output_name))
    return RecursiveResult(trajectory, errors, cov, model)


def recursive_arx(
    data: Record | object,
    u: object | None = None,
    na: int = 4,
    nb: int = 4,
    nk: int = 1,
    *,
    forgetting: float = 1.0,
    initial_covariance: float = DEFAULT_INITIAL_COVARIANCE,
    initial_parameters: object | None = None,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
) -> RecursiveResult:
    """Recursive least-squares ARX ``A y = B u + e`` with exponential forgetting, over a whole record.

    Parameters
    ----------
    data : Record, Dataset or array_like
        A Record (deviations are used), a one-experiment
        :class:`~trms.identification.dataset.Dataset`, or the output ``y`` (shape ``(N,)``).
    u : array_like, optional
        Input (shape ``(N,)``) with an array ``y``.
    na, nb, nk : int
        Orders (``na >= 0``, ``nb >= 1``) and input delay ``nk >= 0`` (samples).
    forgetting : float
        ``lambda`` in ``(0, 1]``; 1.0 (default) forgets nothing, 0.98 remembers about 50 samples.
    initial_covariance : float
        ``p0 > 0`` of ``P(0) = p0 I`` (default ``1e4``): large means little trust in the initial parameters.
    initial_parameters : array_like, optional
        ``theta(0)``, shape ``(na + nb,)``; default zeros.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.

    Returns
    -------
    RecursiveResult
        The trajectory ``(N, na + nb)``, the a-priori errors, the final ``P`` and the final model
        (``noise_variance`` from the sum of the a-priori times the a-posteriori errors after
        ``start``, which with ``lambda = 1`` is the least-squares loss; covariance
        ``noise_variance * P``: the least-squares covariance when ``lambda = 1``).

    Raises
    ------
    InputError
        Bad data, orders, ``forgetting`` outside ``(0, 1]``, ``initial_covariance <= 0``.

    Examples
    --------
    >>> import scipy.signal
    >>> u = np.sign(np.random.default_rng(0).standard_normal(400))
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.8], u)
    >>> res = recursive_arx(y, u, na=1, nb=1, sample_time=0.1)
    >>> res.trajectory.shape, np.round(res.model.parameters, 4)
    ((400, 2), array([-0.8,  0.5]))
    """
    return _recursive(
        data, u, na, nb, 0, nk, forgetting, initial_covariance, initial_parameters, sample_time, input, output
    )


def recursive_armax(
    data: Record | object,
    u: object | None = None,
    na: int = 4,
    nb: int = 4,
    nc: int = 4,
    nk: int = 1,
    *,
    forgetting: float = 1.0,
    initial_covariance: float = DEFAULT_INITIAL_COVARIANCE,
    initial_parameters: object | None = None,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
) -> RecursiveResult:
    """Recursive extended least squares ARMAX ``A y = B u + C e`` with exponential forgetting.

    The innovations in the regressor are replaced by the a-posteriori residuals (see the module
    docstring); ``nc = 0`` is :func:`recursive_arx`.

    Parameters
    ----------
    data : Record, Dataset or array_like
        A Record (deviations are used), a one-experiment
        :class:`~trms.identification.dataset.Dataset`, or the output ``y`` (shape ``(N,)``).
    u : array_like, optional
        Input (shape ``(N,)``) with an array ``y``.
    na, nb, nc, nk : int
        Orders (``na >= 0``, ``nb >= 1``, ``nc >= 0``) and input delay ``nk >= 0`` (samples).
    forgetting : float
        ``lambda`` in ``(0, 1]``; default 1.0.
    initial_covariance : float
        ``p0 > 0`` of ``P(0) = p0 I`` (default ``1e4``).
    initial_parameters : array_like, optional
        ``theta(0)``, shape ``(na + nb + nc,)``; default zeros.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.

    Returns
    -------
    RecursiveResult
        As :func:`recursive_arx`, with ``p = na + nb + nc``.

    Raises
    ------
    InputError
        Bad data, orders, ``forgetting`` outside ``(0, 1]``, ``initial_covariance <= 0``.

    Examples
    --------
    >>> import scipy.signal
    >>> rng = np.random.default_rng(1)
    >>> u, e = np.sign(rng.standard_normal(6000)), 0.2 * rng.standard_normal(6000)
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.8], u) + scipy.signal.lfilter([1, 0.4], [1, -0.8], e)
    >>> np.round(recursive_armax(y, u, na=1, nb=1, nc=1, sample_time=0.1).model.parameters, 1)
    array([-0.8,  0.5,  0.4])
    """
    return _recursive(
        data, u, na, nb, nc, nk, forgetting, initial_covariance, initial_parameters, sample_time, input, output
    )


class RecursiveEstimator:
    """Online recursive ARX (``nc = 0``) or ARMAX (RELS) estimator, fed one sample at a time.

    Fed the samples of a record in order, it gives exactly the trajectory of
    :func:`recursive_arx` / :func:`recursive_armax` (the first update at sample ``start``).

    Parameters
    ----------
    na, nb, nc, nk : int
        Orders (``na >= 0``, ``nb >= 1``, ``nc >= 0``) and input delay ``nk >= 0`` (samples).
    sample_time : float
        Seconds per sample (for :meth:`model`).
    forgetting : float
        ``lambda`` in ``(0, 1]``; default 1.0.
    initial_covariance : float
        ``p0 > 0`` of ``P(0) = p0 I`` (default ``1e4``).
    initial_parameters : array_like, optional
        ``theta(0)``, shape ``(na + nb + nc,)``; default zeros.

    Examples
    --------
    >>> est = RecursiveEstimator(na=1, nb=1, sample_time=0.1)
    >>> y = 0.0
    >>> for u in np.sign(np.random.default_rng(0).standard_normal(200)):
    ...     theta = est.update(y, u)
    ...     y = 0.8 * y + 0.5 * u  # the plant's next output
    >>> np.round(theta, 4), est.n_samples
    (array([-0.8,  0.5]), 200)
    """

    def __init__(
        self,
        na: int = 4,
        nb: int = 4,
        nc: int = 0,
        nk: int = 1,
        *,
        sample_time: float,
        forgetting: float = 1.0,
        initial_covariance: float = DEFAULT_INITIAL_COVARIANCE,
        initial_parameters: object | None = None,
    ) -> None:
        na, nb, nc, nk, lam, p0 = _check_settings(na, nb, nc, nk, forgetting, initial_covariance)
        self.sample_time = check_in_range("sample_time", sample_time, 0.0, np.inf, unit=" s", low_open=True)
        self.orders = (na, nb, nc, nk)
        self.forgetting = lam
        p = na + nb + nc
        self._theta = _initial(initial_parameters, p)
        self._cov = p0 * np.eye(p)
        self._start = max(na, nk + nb - 1)
        # the regressor [-y(t-1)..-y(t-na), u(t-nk)..u(t-nk-nb+1), eps(t-1)..eps(t-nc)], shifted in place,
        # and the inputs u(t)..u(t-nk-nb+1), newest first
        self._phi = np.zeros(p)
        self._u = np.zeros(nk + nb)
        self._products: list[float] = []
        self.n_samples = 0
        self.prediction_error = 0.0

    @property
    def parameters(self) -> np.ndarray:
        """Current estimate ``[a1..a_na, b1..b_nb, c1..c_nc]`` (a copy)."""
        return self._theta.copy()

    @property
    def covariance(self) -> np.ndarray:
        """Current scaled covariance ``P`` (a copy), shape ``(p, p)``."""
        return self._cov.copy()

    def update(self, y: float, u: float) -> np.ndarray:
        """Take the output ``y(t)`` and input ``u(t)`` of the next sample; return the new estimate.

        Parameters
        ----------
        y : float
            Output at sample ``t`` (deviation, output unit).
        u : float
            Input at sample ``t`` (deviation, V); it enters the regressor from sample ``t + nk`` on.

        Returns
        -------
        numpy.ndarray
            ``theta(t)``, shape ``(p,)`` (a copy); unchanged before sample ``start``.

        Raises
        ------
        InputError
            A value that is not a finite real number (the estimator is left unchanged).
        """
        yv = check_in_range("y", y, -np.inf, np.inf)
        uv = check_in_range("u", u, -np.inf, np.inf)
        na, nb, nc, nk = self.orders
        m, phi, ub = na + nb, self._phi, self._u
        ub[1:] = ub[:-1]
        ub[0] = uv
        eps = 0.0
        if self.n_samples >= self._start:
            phi[na:m] = ub[nk:]
            self._theta, self._cov, self.prediction_error = _rls_step(self._theta, self._cov, phi, yv, self.forgetting)
            eps = yv - float(phi @ self._theta)
            self._products.append(eps * self.prediction_error)
        if na:
            phi[1:na] = phi[: na - 1]
            phi[0] = -yv
        if nc:
            phi[m + 1 :] = phi[m:-1]
            phi[m] = eps
        self.n_samples += 1
        return self._theta.copy()

    def model(self) -> PolynomialModel:
        """The current estimate as a :class:`~trms.identification.polynomial.PolynomialModel`.

        Noise variance and covariance as in :func:`recursive_arx` (NaN / None before more
        samples than parameters have been used).
        """
        products = np.asarray(self._products, float)
        return _model(self._theta, self._cov, products, self.orders, self.sample_time, self.forgetting, ("u", "y"))
