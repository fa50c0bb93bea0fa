"""Model validation: fit, residual correlation tests (eq. 3.9, 5.13), OSA and MPO (eq. 5.14).

Correlation tests
-----------------
Every test correlates two sequences with their means removed, normalised so that a
perfect correlation is 1 (the "normalised correlations" of ch. 5.5.2):

``phi_xe(tau) = sum_t x~(t - tau) e~(t) / sqrt(sum x~^2 sum e~^2)``

If the model is adequate, ``e`` (the residuals, or a function of them) is white and
independent of the past of ``x``; each ``phi_xe(tau)`` is then approximately normal with
variance ``1 / N``. Each test returns

* its curve (``lags``, ``values``) and the pointwise band ``+- z / sqrt(N)`` drawn in the
  thesis's figures (``z = 1.96`` at the default 95 % level), and
* a pass/fail from the joint (portmanteau) statistic ``N r^T R^-1 r`` over all the lags,
  ``R`` the correlation of the lagged ``x`` (``R = I`` for the residual autocorrelation,
  the Box-Pierce test), compared with the ``chi^2`` quantile at the same level. A curve
  of 40 lags under the null hypothesis has about two points outside a 95 % band, so
  "every point inside the band" would reject correct models; the joint test keeps the
  stated level. ``n_outside`` still reports the points outside the band.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.signal
import scipy.stats

from trms.errors import InputError, as_finite_array, check_choice, check_in_range, check_int, short_repr
from trms.identification.polynomial import PolynomialModel

__all__ = [
    "fit_percent",
    "CorrelationTest",
    "cross_correlation",
    "whiteness_test",
    "independence_test",
    "billings_voon_tests",
    "residual_tests",
    "residual_variance",
    "Comparison",
    "compare",
    "INITIAL",
    "PredictiveModel",
]


class PredictiveModel(Protocol):
    """What the validation helpers need of a model (polynomial or NARX-RBF)."""

    @property
    def start(self) -> int: ...

    def residuals(self, y: object, u: object) -> np.ndarray: ...

    def predict(self, y: object, u: object, horizon: int = 1) -> np.ndarray: ...

    def simulate(self, u: object, y: object | None = None) -> np.ndarray: ...


def fit_percent(y: object, yhat: object) -> float:
    """MATLAB's fit: ``100 (1 - ||y - yhat|| / ||y - mean(y)||)`` (%).

    100 is a perfect fit, 0 is no better than the mean, negative is worse.

    Parameters
    ----------
    y, yhat : array_like
        Measured and model output, same shape ``(N,)``.
    """
    ya, ha = as_finite_array("y", y), as_finite_array("yhat", yhat)
    if ya.shape != ha.shape or ya.ndim != 1:
        raise InputError(f"y and yhat must be 1-D of equal length, got shapes {ya.shape} and {ha.shape}")
    spread = np.linalg.norm(ya - ya.mean())
    if spread == 0:
        raise InputError("y is constant: the fit percentage is undefined")
    return float(100.0 * (1.0 - np.linalg.norm(ya - ha) / spread))


@dataclass(frozen=True)
class CorrelationTest:
    """One correlation test, ready to plot.

    Attributes
    ----------
    name : str
        ``"ee"``, ``"ue"``, ``"u2e"``, ``"u2e2"`` or ``"e(eu)"`` (eq. 5.13).
    lags : numpy.ndarray
        Lags ``tau`` (samples).
    values : numpy.ndarray
        Normalised correlation at each lag.
    bound : float
        Pointwise confidence band ``z / sqrt(N)``.
    confidence : float
        Level of the band and of the test (0.95 = 95 %).
    statistic, threshold : float
        Joint statistic and its ``chi^2`` quantile.
    passed : bool
        ``statistic <= threshold``.
    n_outside : int
        Number of lags outside the band.
    """

    name: str
    lags: np.ndarray
    values: np.ndarray
    bound: float
    confidence: float
    statistic: float
    threshold: float
    passed: bool
    n_outside: int


def _centred(name: str, x: np.ndarray) -> np.ndarray:
    xc = x - x.mean()
    if not np.any(xc):
        raise InputError(f"{name} is constant: its correlation is undefined")
    return xc


def cross_correlation(x: object, e: object, lags: np.ndarray) -> np.ndarray:
    """Normalised ``phi_xe(tau)`` (means removed) at integer ``lags`` (``x`` delayed by ``tau``).

    Parameters
    ----------
    x, e : array_like
        Equal-length sequences.
    lags : numpy.ndarray
        Integer lags, ``|tau| < N``.
    """
    xa, ea = _pair("x", x, "e", e)
    xc, ec = _centred("x", xa), _centred("e", ea)
    full = scipy.signal.correlate(ec, xc, mode="full")
    all_lags = scipy.signal.correlation_lags(ec.size, xc.size, mode="full")
    lags = np.asarray(lags, int)
    if np.any(np.abs(lags) >= xa.size):
        raise InputError(f"lags must be shorter than the data ({xa.size} samples), got up to {np.abs(lags).max()}")
    return full[lags - all_lags[0]] / np.sqrt((xc @ xc) * (ec @ ec))


def _pair(nx: str, x: object, ne: str, e: object) -> tuple[np.ndarray, np.ndarray]:
    xa, ea = as_finite_array(nx, x), as_finite_array(ne, e)
    if xa.ndim != 1 or xa.shape != ea.shape:
        raise InputError(f"{nx} and {ne} must be 1-D of equal length, got shapes {xa.shape} and {ea.shape}")
    return xa, ea


def _check_model(model: object, *needs: str) -> None:
    """Refuse anything but a fitted model (with ``start`` and the methods ``needs``) in one line."""
    if not all(hasattr(model, attr) for attr in ("start", *needs)):
        raise InputError(
            f"model = {short_repr(model)} is not a fitted model; allowed: a PolynomialModel or NarxRbf "
            "(trms.identification)"
        )


def _check_test_args(n: int, max_lag: int, confidence: float) -> tuple[int, float]:
    c = check_in_range("confidence", confidence, 0.0, 1.0, low_open=True)
    if c >= 1.0:
        raise InputError(f"confidence = {confidence!r} must be below 1")
    high = max(1, n // 4)
    if isinstance(max_lag, (int, np.integer)) and not isinstance(max_lag, bool) and max_lag > high:
        m = int(max_lag)
        raise InputError(
            f"the record is too short for correlation tests to max_lag = {m} samples: they need at least {4 * m} "
            f"samples (4 per lag), the data give {n}; a longer record, or a smaller max_lag"
        )
    return check_int("max_lag", max_lag, 1, unit=" samples", high=high), c


def _judge(
    name: str, x: np.ndarray, e: np.ndarray, lags: np.ndarray, shift: int, confidence: float, independent: bool
) -> CorrelationTest:
    """Correlate ``e(t)`` with ``x(t - lag - shift)`` over ``lags`` and test jointly."""
    values = cross_correlation(x, e, lags + shift)
    n = e.size
    if independent:
        stat = float(n * values @ values)
    else:
        rho = cross_correlation(x, x, np.arange(lags.size))
        corr = scipy.linalg.toeplitz(rho)
        stat = float(n * values @ np.linalg.lstsq(corr, values, rcond=1e-10)[0])
    threshold = float(scipy.stats.chi2.ppf(confidence, lags.size))
    bound = float(scipy.stats.norm.ppf(0.5 + confidence / 2) / np.sqrt(n))
    return CorrelationTest(
        name,
        lags,
        values,
        bound,
        confidence,
        stat,
        threshold,
        bool(stat <= threshold),
        int(np.sum(np.abs(values) > bound)),
    )


def whiteness_test(e: object, max_lag: int = 25, confidence: float = 0.95) -> CorrelationTest:
    """Residual autocorrelation ``phi_ee(tau)``, ``tau = 1 .. max_lag`` (eq. 3.9a): should be 0.

    Parameters
    ----------
    e : array_like
        Residuals, shape ``(N,)``.
    max_lag : int
        Largest lag (samples), at most ``N // 4``.
    confidence : float
        Level of the band and of the Box-Pierce test.
    """
    ea = as_finite_array("e", e)
    m, c = _check_test_args(ea.size, max_lag, confidence)
    return _judge("ee", ea, ea, np.arange(1, m + 1), 0, c, independent=True)


def independence_test(u: object, e: object, max_lag: int = 25, confidence: float = 0.95) -> CorrelationTest:
    """Input-residual cross-correlation ``phi_ue(tau)``, ``tau = -max_lag .. max_lag`` (eq. 3.9b).

    Parameters
    ----------
    u, e : array_like
        Input and residuals, same length ``N``.
    max_lag : int
        Largest lag (samples), at most ``N // 4``.
    confidence : float
        Level of the band and of the joint test.
    """
    ua, ea = _pair("u", u, "e", e)
    m, c = _check_test_args(ea.size, max_lag, confidence)
    return _judge("ue", ua, ea, np.arange(-m, m + 1), 0, c, independent=False)


def billings_voon_tests(u: object, e: object, max_lag: int = 20, confidence: float = 0.95) -> list[CorrelationTest]:
    """The five correlation tests of eq. (5.13) (Billings and Voon).

    ``phi_ee(tau)`` (``tau >= 1``), ``phi_ue``, ``phi_u2'e``, ``phi_u2'e2`` (``|tau| <= max_lag``,
    ``u2' = u^2 - mean(u^2)``) and ``phi_e(eu)(tau) = E[e(t) e(t-1-tau) u(t-1-tau)]``
    (``tau >= 0``). A model is adequate when all five pass.

    Parameters
    ----------
    u, e : array_like
        Input and residuals (one-step prediction errors), same length ``N``.
    max_lag : int
        Largest lag (samples), at most ``N // 4``.
    confidence : float
        Level of the bands and of the joint tests (the thesis: 95 %, ``+- 1.96 / sqrt(N)``).

    Returns
    -------
    list of CorrelationTest
        In the order of eq. (5.13).
    """
    ua, ea = _pair("u", u, "e", e)
    m, c = _check_test_args(ea.size, max_lag, confidence)
    both = np.arange(-m, m + 1)
    u2 = ua**2 - np.mean(ua**2)
    if _two_level(ua):
        raise InputError(
            "u^2 is constant (a two-level input such as a symmetric PRBS): the u^2 tests of eq. (5.13) "
            "are undefined; such an input cannot reveal even nonlinearities -- use multi-level excitation "
            "such as uniform noise (ch. 5.4), or only the linear tests (nonlinear=False)"
        )
    return [
        whiteness_test(ea, m, c),
        independence_test(ua, ea, m, c),
        _judge("u2e", u2, ea, both, 0, c, independent=False),
        _judge("u2e2", u2, ea**2, both, 0, c, independent=False),
        _judge("e(eu)", ea * ua, ea, np.arange(0, m + 1), 1, c, independent=False),
    ]


def residual_tests(
    model: PredictiveModel, y: object, u: object, max_lag: int = 20, confidence: float = 0.95, nonlinear: bool = True
) -> list[CorrelationTest]:
    """Correlation tests on a model's one-step residuals over data ``(y, u)``.

    The first ``model.start`` samples (no prediction) are left out.

    Parameters
    ----------
    model : PolynomialModel or NarxRbf
        Anything with ``residuals(y, u)`` and ``start``.
    y, u : array_like
        Output and input (deviations for a polynomial model).
    max_lag, confidence : see :func:`billings_voon_tests`.
    nonlinear : bool
        All five tests of eq. (5.13) (default) or only the linear pair of eq. (3.9). On a two-level input
        (``u^2`` constant, a symmetric PRBS) the u^2 tests are undefined: the linear pair is run, with a warning.

    Examples
    --------
    >>> import warnings
    >>> from trms.identification import arx
    >>> rng = np.random.default_rng(0)
    >>> u = rng.choice([-1.0, 1.0], 500)
    >>> y = np.r_[0.0, 0.5 * u[:-1]] + 0.01 * rng.standard_normal(500)
    >>> with warnings.catch_warnings(record=True) as said:
    ...     warnings.simplefilter("always")
    ...     tests = residual_tests(arx(y, u, 1, 1, 1, sample_time=0.1), y, u)
    >>> [t.name for t in tests], "two-level input" in str(said[0].message)
    (['ee', 'ue'], True)
    """
    _check_model(model, "residuals")
    ya, ua = _pair("y", y, "u", u)
    e = model.residuals(ya, ua)[model.start :]
    uu = ua[model.start :]
    if nonlinear and _two_level(uu):
        warnings.warn(
            "u is a two-level input (u^2 is constant, as for a symmetric PRBS): the u^2 tests of eq. (5.13) are "
            "undefined on it, so only the linear tests of eq. (3.9) were run (multi-level excitation, such as "
            "uniform noise, allows all five)",
            stacklevel=2,
        )
        nonlinear = False
    if nonlinear:
        return billings_voon_tests(uu, e, max_lag, confidence)
    return [whiteness_test(e, max_lag, confidence), independence_test(uu, e, max_lag, confidence)]


def _two_level(u: np.ndarray) -> bool:
    """Whether ``u^2`` is constant (a two-level input symmetric about 0): the u^2 tests are undefined on it."""
    return bool(np.ptp(u**2) <= 1e-12 * max(float(np.max(u**2)), 1e-300))


#: Initial conditions of the free run in :func:`compare`.
INITIAL = ("estimate", "zero", "measured")


@dataclass(frozen=True)
class Comparison:
    """Measured against model output (MATLAB ``compare``).

    Attributes
    ----------
    y, yhat : numpy.ndarray
        Measured and model output, shape ``(N,)``.
    horizon : int or None
        Prediction horizon (samples); ``None`` for the free run (MPO, eq. 5.14).
    start : int
        Samples before ``start`` are initial conditions, not predictions.
    fit : float
        :func:`fit_percent` over ``t >= start`` (%).
    initial : str
        How the free run's initial conditions were set (``"estimate"``, ``"zero"``,
        ``"measured"``); ``"measured"`` for predictions (``horizon`` given).
    """

    y: np.ndarray
    yhat: np.ndarray
    horizon: int | None
    start: int
    fit: float
    initial: str = "measured"


def residual_variance(model: PredictiveModel, y: object, u: object) -> float:
    """Variance of a model's one-step prediction errors on data (the thesis's Table 5.1 figure), the first
    :attr:`start` samples, which have no prediction, left out.

    Parameters
    ----------
    model : PredictiveModel
        A polynomial model or a NARX-RBF network.
    y, u : array_like
        Output and input deviations, shape ``(N,)``.

    Returns
    -------
    float
        In the output's unit squared (rad^2 for pitch).

    Examples
    --------
    >>> from trms.identification import arx
    >>> rng = np.random.default_rng(0)
    >>> u = rng.standard_normal(2000)
    >>> y = np.zeros(2000)
    >>> for k in range(1, 2000):
    ...     y[k] = 0.5 * y[k - 1] + u[k - 1] + 0.1 * rng.standard_normal()
    >>> round(residual_variance(arx(y, u, 1, 1, 1, sample_time=0.1), y, u), 3)
    0.01
    """
    _check_model(model, "residuals")
    return float(np.var(model.residuals(y, u)[model.start :]))


def _free_run_estimated(model: PredictiveModel, y: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Free run from the initial state that minimises the squared error over the whole record.

    A polynomial model's deterministic part ``B / (A F)`` is realised in state space by
    ``lfilter``'s transposed direct form II, whose state is ``zi``: the free run is the forced
    response from rest plus ``O x0``, ``O`` the free responses of the unit initial states (the
    extended observability matrix), and ``x0`` is one least-squares solve over every sample
    ``t >= 0`` (MATLAB's ``compare(..., 'InitialCondition', 'estimate')``). The output's first
    samples are therefore fitted to the data too and cannot run off to absorb the model's error
    later in the record. Any other model (NARX-RBF) has its state, its first ``start`` outputs,
    fitted the same way by ``scipy.optimize.least_squares``, starting from the measured values.
    """
    s = model.start
    if isinstance(model, PolynomialModel):
        b, den = model.B, model.denominator
        forced = scipy.signal.lfilter(b, den, u)
        n_state = max(b.size, den.size) - 1
        if n_state == 0:
            return forced
        free = scipy.signal.lfilter(b, den, np.zeros((n_state, u.size)), axis=-1, zi=np.eye(n_state))[0].T
        x0 = np.linalg.lstsq(free, y - forced, rcond=None)[0]
        return forced + free @ x0
    if s == 0:
        return model.simulate(u, y)

    def run(y0: np.ndarray) -> np.ndarray:
        start_values = y.copy()
        start_values[:s] = y0
        return model.simulate(u, start_values)

    return run(scipy.optimize.least_squares(lambda y0: run(y0) - y, y[:s]).x)


def compare(
    model: PredictiveModel, y: object, u: object, horizon: int | None = None, *, initial: str = "estimate"
) -> Comparison:
    """One-step-ahead (``horizon = 1``), ``k``-step, or free-run (``None``) output against ``y``.

    The free run (model predicted output, eq. 5.14) needs an initial state. As MATLAB's
    ``compare`` does by default (``initial="estimate"``), the initial state of a state-space
    realisation of the model's deterministic part ``B / (A F)`` is estimated by least squares
    so that the free run matches ``y`` best over the whole record, its first samples included:
    they are fitted like every other sample and so stay on the data's scale (a record that
    starts at rest gives a free run that starts near rest). A NARX-RBF network's state, its
    first ``start`` outputs, is fitted the same way. ``initial="measured"`` takes the first ``model.start`` outputs from
    ``y`` (the thesis's eq. 5.14), ``initial="zero"`` starts the model at rest (zero outputs
    and zero inputs before the first sample). Predictions (``horizon`` given) always use the
    measured outputs.

    Parameters
    ----------
    model : PolynomialModel or NarxRbf
        The model.
    y, u : array_like
        Validation output and input, same length.
    horizon : int, optional
        Samples ahead; ``None`` = infinite (simulation).
    initial : {"estimate", "zero", "measured"}
        Initial conditions of the free run.

    Returns
    -------
    Comparison
        The fit is over ``t >= model.start`` whatever ``initial`` is, so the three are comparable.

    Raises
    ------
    InputError
        Not a fitted model; data of different lengths, NaN/inf, fewer than ``model.start + 2`` samples, a
        constant ``y``.

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> from trms.identification import arx
    >>> u = np.sign(np.random.default_rng(0).standard_normal(400))
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.9], u) + 3.0 * 0.9 ** np.arange(400)
    >>> model = arx(y[200:], u[200:], 1, 1, 1, sample_time=0.1)
    >>> bool(compare(model, y, u).fit > compare(model, y, u, initial="zero").fit)
    True
    """
    check_choice("initial", initial, INITIAL, error=InputError)
    _check_model(model, "predict", "simulate")
    ya, ua = _pair("y", y, "u", u)
    s = model.start
    if ya.size < s + 2:
        raise InputError(
            f"the data have {ya.size} samples; compare needs at least {s + 2} (the fit is over the samples from "
            f"the model's start = {s} on, and needs 2 of them)"
        )
    if horizon is not None:
        yhat = model.predict(ya, ua, horizon)
        initial = "measured"
    elif initial == "measured":
        yhat = model.simulate(ua, ya)
    elif initial == "zero":
        yhat = model.simulate(ua)
    else:
        yhat = _free_run_estimated(model, ya, ua)
    return Comparison(ya, yhat, horizon, s, fit_percent(ya[s:], yhat[s:]), initial)
