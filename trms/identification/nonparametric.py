"""Non-parametric estimates of a system's response: ``spa``, ``etfe`` and ``impulseest`` (as in MATLAB).

All three take what the parametric estimators take (a Record, as deviations; a one-experiment
:class:`~trms.identification.dataset.Dataset`; or arrays ``y``, ``u`` with ``sample_time``) and
do not remove means: the data are taken as deviations from the operating point.

* :func:`spa` -- Blackman-Tukey spectral analysis: the sample covariances ``R_u(tau)``,
  ``R_yu(tau) = 1/N sum_t y(t + tau) u(t)`` for ``|tau| <= M`` (one FFT each), weighted by
  the Hann lag window ``W(tau) = (1 + cos(pi tau / M)) / 2`` and transformed,
  ``G = Phi_yu / Phi_u``. ``M`` defaults to MATLAB's ``min(30, N // 10)``: a larger ``M``
  resolves sharper resonances (bias ~ ``1 / M^2``) at a larger variance (~ ``M / N``). The
  band is Ljung's asymptotic ``Var G = (1/N) sum_tau W(tau)^2 Phi_v / Phi_u`` with the
  noise spectrum ``Phi_v = Phi_y - |Phi_yu|^2 / Phi_u``, split equally between the real and
  imaginary parts (a circular complex normal estimate).
* :func:`etfe` -- the empirical transfer-function estimate ``Y(k) / U(k)`` on the DFT lines
  ``k / (N Ts)`` of the whole record, optionally smoothed over ``smoothing`` neighbouring
  lines by a Hann frequency window weighted by ``|U|^2`` (the weighted least-squares fit of a
  constant to the raw ratios). For a periodic input over whole periods in steady state the
  raw ratio is exact at the excited lines (see :func:`~trms.signals.multisine`).
* :func:`impulseest` -- a finite impulse response of ``n`` coefficients by least squares on
  ``y(t) = sum_k g_k u(t - nk - k) + v(t)``, plain or regularised by the TC ("tuned/correlated")
  kernel prior ``g ~ N(0, P)``, ``P_ij = c alpha^max(i, j)`` (smooth, exponentially decaying),
  with ``c`` and ``alpha`` maximising the marginal likelihood of the data and the noise variance
  fixed at the plain least-squares estimate's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft
import scipy.linalg
import scipy.optimize
import scipy.stats

from trms.errors import EstimationError, InputError, as_finite_array, check_choice, check_in_range, check_int
from trms.identification.data import SisoData, check_excitation, lag_matrix, siso_data
from trms.identification.frequency import FrequencyResponse
from trms.identification.pem import covariance as ls_covariance
from trms.identification.regression import check_size, solve_ls
from trms.record import Record

__all__ = ["spa", "etfe", "impulseest", "ImpulseResponse", "KERNELS", "SPA_FREQUENCIES"]

#: Regularisations of :func:`impulseest`.
KERNELS = ("tc", "none")

#: Frequencies of :func:`spa` by default: ``(1 .. 128) / 128`` of the Nyquist frequency (as MATLAB).
SPA_FREQUENCIES = 128

#: Lines of :func:`etfe` whose input power is below this fraction of the largest are not excited (dropped).
_UNEXCITED = 1e-10


def _data(
    data: Record | object, u: object | None, sample_time: float | None, input: str | None, output: str | None
) -> SisoData:
    d = siso_data(data, u, sample_time=sample_time, input=input, output=output)
    check_excitation(d.u, 1)
    return d


def _level(confidence: object) -> float:
    level = check_in_range("confidence", confidence, 0.0, 1.0, low_open=True)
    if level >= 1.0:
        raise InputError(f"confidence = {confidence!r} must be below 1")
    return level


def _with_bands(freq: np.ndarray, g: np.ndarray, variance: np.ndarray, level: float, method: str) -> FrequencyResponse:
    """A FrequencyResponse from ``G`` and the variance of the complex estimate (half in Re, half in Im)."""
    quant = float(scipy.stats.norm.ppf(0.5 + level / 2))
    mag = np.abs(g)
    sd = np.sqrt(np.maximum(variance, 0.0) / 2.0)
    sd_phase = np.degrees(sd / np.where(mag > 0, mag, np.inf))
    phase = np.degrees(np.unwrap(np.angle(g)))
    return FrequencyResponse(
        freq,
        g,
        mag,
        np.maximum(mag - quant * sd, 0.0),
        mag + quant * sd,
        phase,
        phase - quant * sd_phase,
        phase + quant * sd_phase,
        level,
        method,
    )


def spa(
    data: Record | object,
    u: object | None = None,
    window_size: int | None = None,
    frequency: object | None = None,
    *,
    confidence: float = 0.95,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
) -> FrequencyResponse:
    """Frequency response by Blackman-Tukey spectral analysis with a Hann lag window (MATLAB ``spa``).

    Parameters
    ----------
    data : Record, Dataset or array_like
        A Record (deviations are used), a one-experiment Dataset, or the output ``y`` (shape ``(N,)``).
    u : array_like, optional
        Input (shape ``(N,)``) with an array ``y``.
    window_size : int, optional
        Lag window size ``M`` (samples), in ``[2, N - 1]``; default ``min(30, N // 10)`` (at least 2).
    frequency : array_like, optional
        Frequencies (Hz) in ``[0, 1 / (2 Ts)]``; default ``(1 .. 128) / 128`` of the Nyquist frequency.
    confidence : float
        Level of the bands, in ``(0, 1)``.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.

    Returns
    -------
    FrequencyResponse
        ``method = "spa"``; bands from the asymptotic variance (module docstring).

    Raises
    ------
    InputError
        Bad data (a constant input included), window size or frequencies.

    Examples
    --------
    >>> import scipy.signal
    >>> u = np.random.default_rng(0).standard_normal(2000)
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.5], u)
    >>> fr = spa(y, u, frequency=[0.1, 1.0], sample_time=0.1)
    >>> np.round(fr.magnitude, 2)  # the truth: 1.00 and 0.75
    array([0.98, 0.75])
    """
    d = _data(data, u, sample_time, input, output)
    n = len(d)
    level = _level(confidence)
    m = max(2, min(30, n // 10)) if window_size is None else check_int("window_size", window_size, 2, " samples", n - 1)
    if m > n - 1:
        raise InputError(f"the data have {n} samples; spa needs at least 3")
    nyquist = 0.5 / d.sample_time
    if frequency is None:
        freq = nyquist * np.arange(1, SPA_FREQUENCIES + 1) / SPA_FREQUENCIES
    else:
        freq = np.atleast_1d(as_finite_array("frequency", frequency))
        if freq.ndim != 1 or np.any(freq < 0) or np.any(freq > nyquist * (1 + 1e-12)):
            raise InputError(
                f"frequency must be 1-D within [0, {nyquist:g}] Hz (the Nyquist frequency), "
                f"got values from {freq.min():g} to {freq.max():g} Hz"
            )
    nfft = scipy.fft.next_fast_len(n + m)
    yf, uf = scipy.fft.rfft(d.y, nfft), scipy.fft.rfft(d.u, nfft)
    cov = scipy.fft.irfft(np.stack([yf * uf.conj(), uf * uf.conj(), yf * yf.conj()]), nfft) / n
    lags = np.arange(-m, m + 1)
    window = 0.5 * (1.0 + np.cos(np.pi * lags / m))
    kernel = np.exp(-2j * np.pi * freq[:, None] * d.sample_time * lags[None, :]) * window  # (K, 2M + 1)
    phi_yu, phi_u, phi_y = (kernel @ cov[:, lags].T).T  # R(tau) at index tau, negative lags wrap from the end
    phi_u, phi_y = phi_u.real, phi_y.real
    if np.any(phi_u <= 0):
        raise InputError(
            "the input has no power at some of the frequencies (Phi_u <= 0): spa's ratio is undefined there; "
            "choose frequencies inside the input's band"
        )
    g = phi_yu / phi_u
    noise = np.maximum(phi_y - np.abs(phi_yu) ** 2 / phi_u, 0.0)
    variance = float(window @ window) / n * noise / phi_u
    return _with_bands(freq, g, variance, level, "spa")


def etfe(
    data: Record | object,
    u: object | None = None,
    smoothing: int | None = None,
    *,
    confidence: float = 0.95,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
) -> FrequencyResponse:
    """Empirical transfer-function estimate: the (smoothed) ratio of output and input DFTs (MATLAB ``etfe``).

    Parameters
    ----------
    data : Record, Dataset or array_like
        A Record (deviations are used), a one-experiment Dataset, or the output ``y`` (shape ``(N,)``).
    u : array_like, optional
        Input (shape ``(N,)``) with an array ``y``.
    smoothing : int, optional
        Width (DFT lines, odd, ``>= 3``) of the Hann frequency window; default none (the raw ratio).
    confidence : float
        Level of the bands, in ``(0, 1)``.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.

    Returns
    -------
    FrequencyResponse
        ``method = "etfe"``, on the excited DFT lines ``k / (N Ts)``, ``k = 0 .. N // 2`` (a line
        whose input power is below ``1e-10`` of the largest is dropped). With smoothing the band
        comes from the residual spectrum ``|Y - G U|^2`` smoothed by the same window; the raw ratio
        has no noise estimate, so its band is NaN.

    Raises
    ------
    InputError
        Bad data (a constant input included), a bad smoothing width.

    Examples
    --------
    One period of a multisine in steady state gives the exact response on its lines:

    >>> import scipy.signal
    >>> from trms.signals import multisine
    >>> u = multisine(20.0, 0.1, period=10.0, band=(0.0, 0.4)).signal
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.5], u)
    >>> fr = etfe(y[100:], u[100:], sample_time=0.1)
    >>> truth = 0.5 / (np.exp(2j * np.pi * fr.frequency * 0.1) - 0.5)
    >>> bool(np.max(np.abs(fr.response - truth)) < 1e-12)
    True
    """
    d = _data(data, u, sample_time, input, output)
    level = _level(confidence)
    n = len(d)
    yf, uf = scipy.fft.rfft(d.y), scipy.fft.rfft(d.u)
    power = np.abs(uf) ** 2
    if smoothing is None:
        keep = power > _UNEXCITED * power.max()
        g = yf[keep] / uf[keep]
        variance = np.full(g.size, np.nan)
    else:
        width = check_int("smoothing", smoothing, 3, " lines", 2 * (n // 2) + 1)
        if width % 2 == 0:
            raise InputError(f"smoothing = {width} lines must be odd (a window centred on each line)")
        window = np.hanning(width + 2)[1:-1]
        s_uu, s_yu, s_yy, s_1, s_w2 = (
            np.convolve(x, w, "same")
            for x, w in (
                (power, window),
                (yf * uf.conj(), window),
                (np.abs(yf) ** 2, window),
                (np.ones(power.size), window),
                (power, window**2),
            )
        )
        keep = s_uu > _UNEXCITED * s_uu.max()
        s_uu = s_uu[keep]
        g = s_yu[keep] / s_uu
        # the weighted residual sum over the window, divided by its expectation per unit noise power
        noise = (s_yy[keep].real - np.abs(g) ** 2 * s_uu) / (s_1[keep] - s_w2[keep] / s_uu)
        variance = np.maximum(noise, 0.0) * s_w2[keep] / s_uu**2
    freq = np.arange(power.size)[keep] / (n * d.sample_time)
    return _with_bands(freq, g, variance, level, "etfe")


@dataclass(frozen=True)
class ImpulseResponse:
    """A finite impulse response estimate (what :func:`impulseest` returns).

    Attributes
    ----------
    time : numpy.ndarray
        Time of each coefficient, ``(nk + k) Ts`` (s), shape ``(n,)``.
    coefficients : numpy.ndarray
        ``g_k``: the output (output unit) ``k + nk`` samples after a unit input pulse of one sample.
    std_errors : numpy.ndarray
        Standard deviation of each coefficient (posterior with the TC kernel).
    sample_time : float
        Seconds per sample.
    kernel : str
        ``"tc"`` or ``"none"``.
    noise_variance : float
        Variance of ``v`` (output unit squared), from the plain least-squares fit.
    hyperparameters : dict
        With the TC kernel, ``scale`` ``c`` and ``decay`` ``alpha``; empty otherwise.
    """

    time: np.ndarray
    coefficients: np.ndarray
    std_errors: np.ndarray
    sample_time: float
    kernel: str
    noise_variance: float
    hyperparameters: dict[str, float]

    @property
    def step(self) -> np.ndarray:
        """The step response (cumulative sum of :attr:`coefficients`, output unit per input unit)."""
        return np.cumsum(self.coefficients)


def _tc_kernel(n: int, scale: float, decay: float) -> np.ndarray:
    idx = np.arange(1, n + 1)
    return scale * decay ** np.maximum.outer(idx, idx)


def _tc_fit(
    gram: np.ndarray, proj: np.ndarray, sigma2: float, g_ls: np.ndarray
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """TC hyperparameters by marginal likelihood; the posterior mean and covariance.

    With ``X = sigma2 I + Phi^T Phi P``: ``-2 log p(y) = (y^T y - b^T P X^-1 b) / sigma2 + log det X``
    plus terms that do not depend on ``c``, ``alpha`` (Woodbury and Sylvester on the ``N x N`` covariance).
    """
    n = proj.size
    eye = np.eye(n)

    def cost(eta: np.ndarray) -> float:
        scale, decay = np.exp(eta[0]), 1.0 / (1.0 + np.exp(-eta[1]))
        prior = _tc_kernel(n, scale, decay)
        x = sigma2 * eye + gram @ prior
        try:
            lu = scipy.linalg.lu_factor(x, check_finite=False)
        except (ValueError, np.linalg.LinAlgError):
            return np.inf
        logdet = float(np.sum(np.log(np.abs(np.diag(lu[0])))))
        quad = float(proj @ (prior @ scipy.linalg.lu_solve(lu, proj, check_finite=False)))
        return -quad / sigma2 + logdet

    scale0 = float(np.log(max(np.max(g_ls**2), 1e-300)))
    starts = [np.array([scale0, np.log(a / (1 - a))]) for a in (0.5, 0.8, 0.9, 0.95, 0.98)]
    best = min(starts, key=cost)
    res = scipy.optimize.minimize(cost, best, method="Nelder-Mead", options={"xatol": 1e-6, "fatol": 1e-9})
    eta = res.x if res.fun <= cost(best) else best
    scale, decay = float(np.exp(eta[0])), float(1.0 / (1.0 + np.exp(-eta[1])))
    prior = _tc_kernel(n, scale, decay)
    x = sigma2 * eye + gram @ prior
    g = prior @ np.linalg.solve(x, proj)
    post = sigma2 * prior @ np.linalg.inv(x)
    return g, 0.5 * (post + post.T), scale, decay


def impulseest(
    data: Record | object,
    u: object | None = None,
    n_coefficients: int = 70,
    nk: int = 0,
    *,
    kernel: str = "tc",
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
) -> ImpulseResponse:
    """Finite impulse response by (regularised) least squares (MATLAB ``impulseest``).

    Parameters
    ----------
    data : Record, Dataset or array_like
        A Record (deviations are used), a one-experiment Dataset, or the output ``y`` (shape ``(N,)``).
    u : array_like, optional
        Input (shape ``(N,)``) with an array ``y``.
    n_coefficients : int
        FIR length ``n >= 1`` (default 70, as MATLAB); long enough for the response to have died out.
    nk : int
        Lag of the first coefficient (samples), ``>= 0``.
    kernel : {"tc", "none"}
        TC-kernel regularisation with marginal-likelihood hyperparameters, or plain least squares
        (which needs an input persistently exciting of order ``n``).
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.

    Returns
    -------
    ImpulseResponse

    Raises
    ------
    InputError
        Bad data, too few samples (``2 n + 1`` regression rows after the first ``nk + n - 1``
        samples), an input that does not excite the coefficients.
    EstimationError
        Linearly dependent regressors (plain least squares).

    Examples
    --------
    >>> import scipy.signal
    >>> rng = np.random.default_rng(0)
    >>> u = rng.standard_normal(1000)
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.5], u) + 0.05 * rng.standard_normal(1000)
    >>> np.round(impulseest(y, u, 20, sample_time=0.1).coefficients[:3], 2)  # the truth: 0, 0.5, 0.25
    array([0.  , 0.5 , 0.25])
    """
    choice = check_choice("kernel", kernel, KERNELS, error=InputError)
    n = check_int("n_coefficients", n_coefficients, 1)
    lag0 = check_int("nk", nk, 0, " samples")
    d = _data(data, u, sample_time, input, output)
    start = lag0 + n - 1
    check_size(len(d), start, n, f"n_coefficients={n}, nk={lag0}")
    if choice == "none":
        check_excitation(d.u, n)
    phi = lag_matrix(d.u, range(lag0, lag0 + n), start)
    target = d.y[start:]
    if choice == "none":
        g = solve_ls(phi, target, "FIR least squares")
    else:
        gram, proj = phi.T @ phi, phi.T @ target
        g = np.linalg.lstsq(gram, proj, rcond=None)[0]  # n x n: the normal equations, minimum norm if singular
    eps = target - phi @ g
    sigma2 = float(eps @ eps / (eps.size - n))
    hyper: dict[str, float] = {}
    if choice == "none":
        cov = ls_covariance(phi, sigma2)
    else:
        if sigma2 <= 0.0:
            raise EstimationError("the FIR fits the data exactly (no noise): the TC hyperparameters are undefined")
        g, cov, scale, decay = _tc_fit(gram, proj, sigma2, g)
        hyper = {"scale": scale, "decay": decay}
    std = np.sqrt(np.maximum(np.diag(cov), 0.0))
    time = (lag0 + np.arange(n)) * d.sample_time
    return ImpulseResponse(time, g, std, d.sample_time, choice, sigma2, hyper)
