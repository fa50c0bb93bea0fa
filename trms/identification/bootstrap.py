"""Parametric bootstrap of ARX, ARMAX, OE and BJ fits: parameter intervals, a joint region and frequency bands.

The covariance ``lambda (psi^T psi)^-1`` of the prediction-error estimate is asymptotic: at a few hundred
samples, and for nonlinear functions of the parameters (the magnitude at a resonance, the phase where
``|G|`` is small against its uncertainty), intervals built from it with normal quantiles cover less than
their level. The bootstrap replaces the normal approximation by the estimator's own spread:

1. simulate ``n_boot`` data sets from the fitted model, on the measured input ``u``:
   ``y* = B / (A F) u + C / (A D) e*``, the input part from rest, the noise part after a burn-in long
   enough for its slowest pole to forget the rest; the innovations ``e*`` are the model's residuals,
   centred, inflated by ``sqrt(N / (N - p))`` and resampled with replacement (``"residual"``), or
   Gaussian with the model's noise variance (``"gaussian"``);
2. refit each data set with the same structure by the same estimator, each search started from the
   estimate (the truth of the simulated world): ARX by least squares, ARMAX, OE and BJ by the damped
   Gauss-Newton search of :mod:`trms.identification.pem`; a search that fails falls back to the full
   estimator (its multistart), and a data set on which that fails too is counted in ``failed``;
3. read the intervals off the refits, in one of two ways (``kind``):

   * ``"studentized"`` (default; bootstrap-t): each refit also gives its own covariance
     ``lambda (psi^T psi)^-1``, so each refit's deviation from the estimate can be measured in its own
     standard errors. Per parameter: ``[theta_hat - t_hi se, theta_hat - t_lo se]`` with ``t_lo, t_hi``
     the quantiles ``(1 -+ level) / 2`` of ``(theta_b - theta_hat) / se_b`` and ``se`` the estimate's
     standard errors. Jointly: ``(theta - theta_hat)^T P^-1 (theta - theta_hat) <= r`` with ``P`` the
     estimate's covariance and ``r`` the level's quantile of the refits' ``(theta_b - theta_hat)^T
     P_b^-1 (theta_b - theta_hat)`` (the bootstrap's Mahalanobis quantile in place of the chi-square
     one). The frequency response: Fieller's region of ``G = N / D`` calibrated the same way, and its
     projections as the magnitude and phase bands
     (:func:`~trms.identification.frequency.response_from_samples`);
   * ``"percentile"``: the quantiles ``(1 -+ level) / 2`` of the refitted parameters; the joint region
     with the refits' sample covariance and the level's quantile of their distances; percentile bands of
     ``|G|`` and of the phase measured from the estimate's, and Fieller's region with the refits' covariance.

:meth:`~trms.identification.frequency.FrequencyResponse.contains` of either is pointwise, or simultaneous
over the frequencies with ``simultaneous=True``.

Cost: a refit is one Gauss-Newton search from the estimate, a few iterations (``seconds_per_refit``
reports it; on the order of a millisecond for a few hundred samples and four to six parameters, a tenth
of that for ARX), far below a fit from scratch with its multistart.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.signal

from trms.errors import (
    EstimationError,
    InputError,
    as_finite_array,
    check_choice,
    check_in_range,
    check_int,
    check_seed,
)
from trms.identification.data import SisoData, siso_data
from trms.identification.frequency import FrequencyResponse, response_from_samples
from trms.identification.linear import armax
from trms.identification.oe_bj import bj, oe
from trms.identification.pem import MAX_ITER, Structure, covariance, max_root, minimise
from trms.identification.polynomial import PolynomialModel
from trms.identification.regression import arx_regressors, solve_ls

__all__ = ["Bootstrap", "bootstrap", "INNOVATIONS", "KINDS"]

#: How the innovations of the simulated data sets are drawn.
INNOVATIONS = ("residual", "gaussian")

#: How the intervals are read off the refits: bootstrap-t, or percentiles of the samples.
KINDS = ("studentized", "percentile")

#: The estimators a model must come from (its ``method``).
_METHODS = ("arx", "armax-pem", "oe-pem", "bj-pem")

#: Fewest refits accepted.
_MIN_BOOT = 10

#: The search's tolerance of a refit (the estimators' default; its iterations: theirs, MAX_ITER).
_TOL = 1e-7


@dataclass(frozen=True)
class Bootstrap:
    """Refitted parameters of a bootstrap and the intervals read off them (module docstring).

    Every method takes ``kind``: ``"studentized"`` (default; bootstrap-t, each refit's own covariance) or
    ``"percentile"`` (the samples alone).

    Attributes
    ----------
    model : PolynomialModel
        The estimate the data sets were simulated from.
    samples : numpy.ndarray
        Refitted parameters, shape ``(S, p)`` (``S = n_boot - failed``), layout of ``model.parameters``.
    covariances : numpy.ndarray
        Each refit's parameter covariance ``lambda (psi^T psi)^-1``, shape ``(S, p, p)``.
    innovations : str
        ``"residual"`` or ``"gaussian"``.
    seed : int
        Seed of the simulated innovations.
    failed : int
        Data sets on which no refit converged (left out of :attr:`samples`).
    seconds_per_refit : float
        Mean wall time of one simulation and refit (s).

    Examples
    --------
    >>> import scipy.signal
    >>> from trms.identification import arx
    >>> rng = np.random.default_rng(3)
    >>> u = rng.standard_normal(300)
    >>> y = scipy.signal.lfilter([0.0, 0.5], [1.0, -0.8], u) + 0.1 * rng.standard_normal(300)
    >>> boot = bootstrap(arx(y, u, 1, 1, 1, sample_time=0.1), u, y, n_boot=200, seed=2)
    >>> bool(boot.distance([-0.8, 0.5]) <= boot.joint_radius()), 4.0 < boot.joint_radius() < 9.0
    (True, True)
    >>> fr = boot.frequency_response([0.0, 1.0])
    >>> zinv = np.exp(-2j * np.pi * fr.frequency * 0.1)
    >>> fr.contains(0.5 * zinv / (1 - 0.8 * zinv)).tolist(), fr.method
    ([True, True], 'bootstrap')
    """

    model: PolynomialModel
    samples: np.ndarray
    covariances: np.ndarray
    innovations: str
    seed: int
    failed: int
    seconds_per_refit: float

    @property
    def covariance(self) -> np.ndarray:
        """Sample covariance of :attr:`samples`, shape ``(p, p)`` (parameter units squared)."""
        return np.atleast_2d(np.cov(self.samples, rowvar=False))

    def intervals(self, confidence: float = 0.95, *, kind: str = "studentized") -> tuple[np.ndarray, np.ndarray]:
        """Intervals, one per parameter: lower and upper ends, each shape ``(p,)`` (module docstring).

        Examples
        --------
        >>> import scipy.signal
        >>> from trms.identification import arx
        >>> rng = np.random.default_rng(0)
        >>> u = rng.standard_normal(300)
        >>> y = scipy.signal.lfilter([0.0, 0.5], [1.0, -0.8], u) + 0.1 * rng.standard_normal(300)
        >>> boot = bootstrap(arx(y, u, 1, 1, 1, sample_time=0.1), u, y, n_boot=100)
        >>> low, high = boot.intervals()
        >>> bool(np.all(low < [-0.8, 0.5]) and np.all([-0.8, 0.5] < high)), boot.joint_contains([-0.8, 0.5])
        (True, True)
        >>> boot.joint_contains([-0.75, 0.5]), bool(np.all(boot.intervals(kind="percentile")[0] < [-0.8, 0.5]))
        (False, True)
        """
        level, kind = _level(confidence), _kind(kind)
        tail = 0.5 * (1.0 - level)
        if kind == "percentile":
            low, high = np.quantile(self.samples, [tail, 1.0 - tail], axis=0)
            return low, high
        theta, se = self.model.parameters, self.model.std_errors
        se_b = np.sqrt(np.maximum(np.diagonal(self.covariances, axis1=1, axis2=2), 0.0))
        t = np.divide(self.samples - theta, se_b, out=np.zeros_like(se_b), where=se_b > 0)
        q_low, q_high = np.quantile(t, [tail, 1.0 - tail], axis=0)
        return theta - q_high * se, theta - q_low * se

    def _distances(self, kind: str) -> tuple[np.ndarray, np.ndarray]:
        """The samples' squared distances from the estimate and the inverse covariance the data's is measured with."""
        x = self.samples - self.model.parameters
        if kind == "percentile":
            inverse = np.linalg.pinv(self.covariance, hermitian=True)
            return np.einsum("si,ij,sj->s", x, inverse, x), inverse
        assert self.model.covariance is not None
        own = np.linalg.pinv(self.covariances, hermitian=True)
        return np.einsum("si,sij,sj->s", x, own, x), np.linalg.pinv(self.model.covariance, hermitian=True)

    def distance(self, theta: object, *, kind: str = "studentized") -> float:
        """Squared distance ``(theta - theta_hat)^T S^-1 (theta - theta_hat)``: ``S`` the model's covariance
        (``"studentized"``) or :attr:`covariance` (``"percentile"``)."""
        x = as_finite_array("theta", theta, (self.model.n_parameters,)) - self.model.parameters
        return float(x @ self._distances(_kind(kind))[1] @ x)

    def joint_radius(self, confidence: float = 0.95, *, kind: str = "studentized") -> float:
        """The level's quantile of the samples' own squared distances (each with its own covariance when
        studentized): the joint region's threshold, in place of the chi-square quantile."""
        level = _level(confidence)
        return float(np.quantile(self._distances(_kind(kind))[0], level))

    def joint_contains(self, theta: object, confidence: float = 0.95, *, kind: str = "studentized") -> bool:
        """Whether a parameter vector (shape ``(p,)``) lies in the joint region at the level."""
        return self.distance(theta, kind=kind) <= self.joint_radius(confidence, kind=kind)

    def frequency_response(
        self, frequency: object | None = None, *, confidence: float = 0.95, kind: str = "studentized"
    ) -> FrequencyResponse:
        """Bootstrap bands and region of ``G = B / (A F)`` (see :func:`response_from_samples`).

        Parameters
        ----------
        frequency : array_like, optional
            Frequencies (Hz) in ``[0, 1 / (2 Ts)]``.
        confidence : float
            Level in ``(0, 1)``.
        kind : {"studentized", "percentile"}
            Bootstrap-t bands and region, or percentile bands and the samples' covariance.

        Returns
        -------
        FrequencyResponse
            ``method = "bootstrap"``.
        """
        covs = self.covariances if _kind(kind) == "studentized" else None
        return response_from_samples(
            self.model, self.samples, frequency, covariances=covs, confidence=confidence, method="bootstrap"
        )


def _kind(kind: object) -> str:
    return check_choice("kind", kind, KINDS, error=InputError)


def _level(confidence: object) -> float:
    level = check_in_range("confidence", confidence, 0.0, 1.0, low_open=True)
    if level >= 1.0:
        raise InputError(f"confidence = {confidence!r} must be below 1")
    return level


def _structure(model: PolynomialModel) -> Structure:
    return Structure(model.na, model.nb, model.nc, model.nd, model.nf, model.nk)


def _check_model(model: object) -> PolynomialModel:
    """The model, if :func:`bootstrap` can refit it: one of its estimators', stable, from one experiment."""
    if not isinstance(model, PolynomialModel):
        raise InputError(f"model must be a PolynomialModel fitted by arx, armax, oe or bj, got {type(model).__name__}")
    if model.method not in _METHODS:
        raise InputError(
            f"model.method = {model.method!r}: the bootstrap refits models of arx, armax, oe or bj "
            f"(method {', '.join(repr(m) for m in _METHODS)})"
        )
    if "experiments" in model.info:
        raise InputError(f"the model was fitted to {model.info['experiments']} experiments; the bootstrap takes one")
    for name, poly in (("A F", model.denominator), ("A D", np.convolve(model.A, model.D))):
        if max_root(poly) >= 1.0:
            raise InputError(
                f"the model's {name} has a root at |z| = {max_root(poly):.4f}: the bootstrap simulates the model, "
                "which needs every root inside the unit circle"
            )
    return model


def _check_data(model: PolynomialModel, u: object, y: object) -> tuple[SisoData, np.ndarray]:
    """The data and their residuals; refused unless they are the data the model was fitted to."""
    d = siso_data(y, u, sample_time=model.sample_time)
    if len(d) - model.start != model.n_samples:
        raise InputError(
            f"y and u have {len(d)} samples; the model was fitted to {model.n_samples + model.start} "
            "(pass the data of the fit)"
        )
    eps = model.residuals(d.y, d.u)[model.start :]
    loss = float(eps @ eps) / eps.size
    if not np.isclose(loss, model.loss, rtol=1e-6, atol=1e-12 * float(d.y @ d.y) / len(d)):
        raise InputError(
            f"the residuals of y, u have mean square {loss:.6g}, the model's loss is {model.loss:.6g}: these are "
            "not the data the model was fitted to (or y and u are swapped: the order is u, y)"
        )
    return d, eps


def _burn_in(model: PolynomialModel, n: int) -> int:
    """Samples for the noise filter ``C / (A D)`` to forget its rest: its slowest pole decays by 1e-6."""
    r = max_root(np.convolve(model.A, model.D))
    return 0 if r == 0.0 else int(min(np.ceil(np.log(1e-6) / np.log(r)), 10 * n))


def _refit(model: PolynomialModel, structure: Structure, d: SisoData) -> tuple[np.ndarray, np.ndarray]:
    """Parameters and their covariance on one simulated data set, the search started from the estimate."""
    p = model.n_parameters
    if model.method == "arx":
        phi = arx_regressors(d, model.na, model.nb, model.nk, model.start)
        theta = solve_ls(phi, d.y[model.start :], "bootstrap ARX refit")
        eps = d.y[model.start :] - phi @ theta
        return theta, covariance(phi, float(eps @ eps) / (eps.size - p))
    try:
        best = minimise(
            lambda th: structure.errors(th, d),
            lambda th, e: structure.gradient(th, e, d),
            structure.stable,
            model.parameters,
            name="bootstrap refit",
            orders=structure.describe(),
            max_iter=MAX_ITER,
            tol=_TOL,
            exact=float((1e-10 * np.linalg.norm(d.y)) ** 2),
        )
        return best.theta, covariance(best.psi, best.sse / (best.eps.size - p))
    except EstimationError:
        s = structure
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if model.method == "armax-pem":
                m = armax(d.y, d.u, s.na, s.nb, s.nc, s.nk, sample_time=d.sample_time)
            elif model.method == "oe-pem":
                m = oe(d.y, d.u, s.nb, s.nf, s.nk, sample_time=d.sample_time)
            else:
                m = bj(d.y, d.u, s.nb, s.nc, s.nd, s.nf, s.nk, sample_time=d.sample_time)
        assert m.covariance is not None
        return m.parameters, m.covariance


def bootstrap(
    model: PolynomialModel,
    u: object,
    y: object,
    *,
    n_boot: int = 200,
    seed: int = 0,
    innovations: str = "residual",
) -> Bootstrap:
    """Parametric bootstrap of an ARX, ARMAX, OE or BJ fit (module docstring).

    Parameters
    ----------
    model : PolynomialModel
        A fit of :func:`~trms.identification.linear.arx`, :func:`~trms.identification.linear.armax`,
        :func:`~trms.identification.oe_bj.oe` or :func:`~trms.identification.oe_bj.bj` to ``u, y``
        (one experiment, a stable model).
    u, y : array_like
        The input (input unit) and output (output unit) of the fit, shape ``(N,)`` each.
    n_boot : int
        Simulated data sets, ``>= 10`` (a few hundred for 95 % intervals).
    seed : int
        Seed of the innovations; the same seed gives the same samples, bit for bit.
    innovations : {"residual", "gaussian"}
        Resampled residuals or Gaussian innovations with the model's noise variance.

    Returns
    -------
    Bootstrap
        The refitted parameters, with :meth:`~Bootstrap.intervals`, :meth:`~Bootstrap.joint_contains`
        and :meth:`~Bootstrap.frequency_response`.

    Raises
    ------
    InputError
        ``n_boot < 10``, a model of another estimator, of several experiments or unstable, data other
        than those of the fit.
    EstimationError
        More than half the refits failed.

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> from trms.identification import arx
    >>> rng = np.random.default_rng(0)
    >>> u = np.sign(rng.standard_normal(400))
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.8], u) + 0.1 * rng.standard_normal(400)
    >>> model = arx(y, u, 1, 1, 1, sample_time=0.1)
    >>> boot = bootstrap(model, u, y, n_boot=100, seed=1)
    >>> low, high = boot.intervals()
    >>> boot.samples.shape, boot.failed, bool(np.all(low < model.parameters) and np.all(model.parameters < high))
    ((100, 2), 0, True)
    >>> boot.joint_contains([-0.8, 0.5]), boot.joint_contains([-0.7, 0.5])
    (True, False)
    """
    model = _check_model(model)
    n_boot = check_int("n_boot", n_boot, _MIN_BOOT, high=100_000)
    seed_int = check_seed("seed", seed, allow_none=False)
    assert seed_int is not None
    kind = check_choice("innovations", innovations, INNOVATIONS, error=InputError)
    d, eps = _check_data(model, u, y)
    n, p = len(d), model.n_parameters
    burn = _burn_in(model, n)
    rng = np.random.default_rng(seed_int)
    if kind == "residual":
        pool = (eps - eps.mean()) * np.sqrt(eps.size / max(eps.size - p, 1))
        e_all = rng.choice(pool, size=(n_boot, burn + n))
    else:
        e_all = np.sqrt(model.noise_variance) * rng.standard_normal((n_boot, burn + n))
    plant = scipy.signal.lfilter(model.B, model.denominator, d.u)
    noise = scipy.signal.lfilter(model.C, np.convolve(model.A, model.D), e_all, axis=1)[:, burn:]
    structure = _structure(model)
    refits, failed = [], 0
    tic = time.perf_counter()
    for k in range(n_boot):
        try:
            refits.append(_refit(model, structure, SisoData(plant + noise[k], d.u, d.sample_time)))
        except EstimationError:
            failed += 1
    seconds = (time.perf_counter() - tic) / n_boot
    if 2 * failed > n_boot:
        raise EstimationError(f"bootstrap: {failed} of {n_boot} refits failed; the model cannot be bootstrapped")
    samples = np.array([theta for theta, _ in refits])
    return Bootstrap(model, samples, np.array([cov for _, cov in refits]), kind, seed_int, failed, seconds)
