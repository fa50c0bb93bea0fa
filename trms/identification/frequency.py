"""Frequency response of an estimated polynomial model with confidence bands from its covariance.

``G(e^{j w Ts}) = B / (A F)`` evaluated on the unit circle, with the uncertainty that the
parameter covariance of the estimate (``PolynomialModel.covariance``) implies. Two ways to
carry the covariance to the response, selected by ``method``:

* ``"delta"`` (default; MATLAB's ``bode``/``showConfidence`` convention): linearise
  ``G`` in the parameters, ``dG/da_k = -z^-k G / A``, ``dG/db_k = z^-(nk+k-1) / (A F)``,
  ``dG/df_k = -z^-k G / F`` (``C``, ``D`` do not enter ``G``), propagate the covariance to
  the real and imaginary parts, then to magnitude (gradient ``(Re G, Im G) / |G|``) and
  phase (gradient ``(-Im G, Re G) / |G|^2``); the band is ``+- z sigma`` with ``z`` the normal
  quantile of the level. Exact to first order; where ``|G|`` is small against its standard
  deviation the magnitude band is clipped at 0.
* ``"monte-carlo"``: draw ``n_draws`` parameter vectors from ``N(theta, covariance)``
  (seeded), evaluate ``G`` for each, and take the pointwise percentiles of magnitude and
  phase (the phase of each draw measured from the nominal phase, so wraps do not matter).
  Captures the nonlinearity of ``|G|`` near resonances at the price of sampling noise.

A third source is a set of parameter samples, e.g. a bootstrap (:mod:`trms.identification.bootstrap`):
:func:`response_from_samples` takes the same pointwise percentiles of those samples or, given each
sample's own covariance, calibrates the region below by them and projects it onto bands.

:meth:`FrequencyResponse.contains` tests a response against a confidence *region* of the complex
``G`` at each frequency (not against the two bands, whose intersection holds less than the level), by
Fieller's method for a ratio: ``G = N / D`` with ``N = B(z)`` and ``D = A(z) F(z)``, both linear in the
parameters (so nearly normal even where ``G`` is not: near a lightly damped resonance ``D`` is small
against its uncertainty). A response ``g`` is inside where ``T(g) = r^T Sigma_r^-1 r <= c`` with
``r = N_hat - g D_hat`` (real and imaginary parts) and ``Sigma_r`` its covariance (zero mean when ``g`` is
the truth). With ``"delta"`` the covariance of ``(N, D)`` is propagated from the parameters' and ``c`` is the
chi-square quantile with 2 degrees of freedom (1 at 0 Hz and at the Nyquist frequency, where ``G`` is real)
pointwise, or with ``p``, the parameters of ``B / (A F)``, simultaneously over all frequencies (the
projection of the parameters' ellipsoid, conservative). With samples (``"monte-carlo"``, a bootstrap) the
covariance is the samples' (or, given each sample's own covariance, the model's, each sample's statistic
computed with its own: bootstrap-t) and ``c`` the level's quantile of the samples' own statistics ``T`` at the
estimate (pointwise), or that times the level's quantile of each sample's largest ratio of ``T`` to it over
the frequencies (simultaneous). The region can be unbounded (where ``D`` is not significantly different
from 0, e.g. far above the bandwidth with poor data), as the data then allow. A response built without
``N, D`` (the non-parametric :func:`~trms.identification.nonparametric.spa`, ``etfe``) uses ``N = G``,
``D = 1`` and a standard deviation per component of the magnitude band's half-width over the normal quantile
(a circle), and for the simultaneous test the chi-square quantile at ``level^(1/K)`` (independent
frequencies, Sidak).

Both inherit the assumptions of the covariance: that of ``oe`` holds for a coloured output error
(:func:`~trms.identification.pem.sandwich_covariance`), and where the error's correlation leaves too few
effective samples per parameter ``oe`` withholds it and the bands are refused with that reason.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.stats

from trms.errors import InputError, as_finite_array, check_choice, check_in_range, check_int
from trms.identification.fieller import _calibrated, _fieller, _projected_bands, _real_imag
from trms.identification.polynomial import PolynomialModel
from trms.signals import make_rng

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["FrequencyResponse", "frequency_response", "response_from_samples", "plot_frequency_response", "METHODS"]

#: Ways to carry the parameter covariance to the response.
METHODS = ("delta", "monte-carlo")


@dataclass(frozen=True)
class FrequencyResponse:
    """A model's frequency response with pointwise confidence bands and a confidence region.

    Attributes
    ----------
    frequency : numpy.ndarray
        Frequencies (Hz), shape ``(K,)``.
    response : numpy.ndarray
        Complex response ``G(e^{j 2 pi f Ts})`` (output unit per input unit), shape ``(K,)``.
    magnitude, magnitude_low, magnitude_high : numpy.ndarray
        ``|G|`` and its band (output unit per input unit).
    phase, phase_low, phase_high : numpy.ndarray
        Unwrapped phase of ``G`` and its band (deg).
    confidence : float
        Level of the bands (0.95 = 95 %).
    method : str
        ``"delta"``, ``"monte-carlo"``, ``"bootstrap"`` or a non-parametric estimator's name.
    region_parts : numpy.ndarray or None
        ``[N, D]`` per frequency, shape ``(K, 2)`` complex: the estimate's numerator ``B(z)`` and denominator
        ``A(z) F(z)`` (``G = N / D``), the centre of the region of :meth:`contains` (module docstring).
    region_covariance : numpy.ndarray or None
        Covariance of ``(Re N, Im N, Re D, Im D)``, shape ``(K, 4, 4)``.
    region_radius, simultaneous_radius : numpy.ndarray or None
        Thresholds of Fieller's statistic, shape ``(K,)``: pointwise and simultaneous over the frequencies.
    """

    frequency: np.ndarray
    response: np.ndarray
    magnitude: np.ndarray
    magnitude_low: np.ndarray
    magnitude_high: np.ndarray
    phase: np.ndarray
    phase_low: np.ndarray
    phase_high: np.ndarray
    confidence: float
    method: str
    region_parts: np.ndarray | None = None
    region_covariance: np.ndarray | None = None
    region_radius: np.ndarray | None = None
    simultaneous_radius: np.ndarray | None = None

    def distance(self, response: object) -> np.ndarray:
        """Fieller's statistic ``T(g)`` of a response (complex, shape ``(K,)``) per frequency (module docstring).

        Examples
        --------
        >>> fr = FrequencyResponse(np.array([1.0]), np.array([1.0 + 0j]), np.array([1.0]), np.array([0.8]),
        ...                        np.array([1.2]), np.zeros(1), np.array([-10.0]), np.array([10.0]), 0.95, "given")
        >>> np.round(fr.distance([1.1 + 0j]), 3)
        array([0.96])
        """
        g = as_finite_array("response", response, (self.frequency.size,), dtype=complex)
        parts, cov, _, _ = self._region()
        return _fieller(parts[:, 0], parts[:, 1], g, cov)

    def contains(self, response: object, *, simultaneous: bool = False) -> np.ndarray:
        """Whether another response (complex, shape ``(K,)``) lies inside the confidence region, per frequency.

        Parameters
        ----------
        response : array_like
            Complex response at :attr:`frequency` (output unit per input unit).
        simultaneous : bool
            False: each entry is a test at the level on its own (a true response is inside at a given
            frequency with probability :attr:`confidence`). True: the simultaneous region, so that
            ``contains(g, simultaneous=True).all()`` holds for the true response with probability at least
            :attr:`confidence` (module docstring: how each method calibrates it).

        Returns
        -------
        numpy.ndarray
            Booleans, shape ``(K,)``.

        Examples
        --------
        >>> fr = FrequencyResponse(np.array([1.0]), np.array([1.0 + 0j]), np.array([1.0]), np.array([0.8]),
        ...                        np.array([1.2]), np.zeros(1), np.array([-10.0]), np.array([10.0]), 0.95, "given")
        >>> fr.contains([1.1 + 0.05j]), fr.contains([1.5 + 0j])
        (array([ True]), array([False]))
        """
        _, _, pointwise, joint = self._region()
        return self.distance(response) <= (joint if simultaneous else pointwise)

    def _region(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Numerator and denominator, their covariance, the pointwise and the simultaneous radius; for a
        response built without them, ``G`` over 1 with a circle from the magnitude band (module docstring)."""
        if self.region_parts is not None and self.region_covariance is not None:
            assert self.region_radius is not None and self.simultaneous_radius is not None
            return self.region_parts, self.region_covariance, self.region_radius, self.simultaneous_radius
        k = self.frequency.size
        sd = (self.magnitude_high - self.magnitude) / float(scipy.stats.norm.ppf(0.5 + self.confidence / 2))
        cov = np.zeros((k, 4, 4))
        cov[:, 0, 0] = cov[:, 1, 1] = sd**2
        parts = np.stack([self.response, np.ones(k, complex)], axis=1)
        pointwise = np.full(k, scipy.stats.chi2.ppf(self.confidence, 2))
        return parts, cov, pointwise, np.full(k, scipy.stats.chi2.ppf(self.confidence ** (1.0 / k), 2))


def _default_frequencies(sample_time: float, n: int = 200) -> np.ndarray:
    nyquist = 0.5 / sample_time
    return np.geomspace(nyquist * 1e-3, nyquist, n)


def _frequencies(model: PolynomialModel, frequency: object | None, confidence: object) -> tuple[np.ndarray, float]:
    """The checked frequencies (Hz, within ``[0, Nyquist]``) and level of the bands."""
    level = check_in_range("confidence", confidence, 0.0, 1.0, low_open=True)
    if level >= 1.0:
        raise InputError(f"confidence = {confidence!r} must be below 1")
    ts = model.sample_time
    nyquist = 0.5 / ts
    freq = _default_frequencies(ts) if frequency is None else as_finite_array("frequency", frequency)
    freq = np.atleast_1d(freq)
    if freq.ndim != 1 or np.any(freq < 0) or np.any(freq > nyquist * (1 + 1e-12)):
        raise InputError(
            f"frequency must be 1-D within [0, {nyquist:g}] Hz (the Nyquist frequency), "
            f"got values from {freq.min():g} to {freq.max():g} Hz"
        )
    return freq, level


def _powers(n: int, first: int, zinv: np.ndarray) -> np.ndarray:
    """``z^-(first + k)`` for ``k < n``, shape ``(n, K)``."""
    return zinv[None, :] ** (first + np.arange(n))[:, None]


def _parts(model: PolynomialModel, thetas: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``B(z)`` and ``A(z) F(z)`` for each row of ``thetas`` (the model's parameter layout), each shape ``(S, K)``."""
    na, nb, nf = model.na, model.nb, model.nf
    cuts = np.cumsum([na, nb, model.nc, model.nd, nf])
    zinv = 1.0 / z
    a_val = 1.0 + thetas[:, :na] @ _powers(na, 1, zinv)
    f_val = 1.0 + thetas[:, cuts[3] : cuts[4]] @ _powers(nf, 1, zinv)
    return thetas[:, na : cuts[1]] @ _powers(nb, model.nk, zinv), a_val * f_val


def _parts_jacobian(model: PolynomialModel, theta: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, ...]:
    """``N = B(z)``, ``D = A(z) F(z)`` (shape ``(K,)``) and ``dN/dtheta``, ``dD/dtheta`` (shape ``(K, p)``)."""
    na, nb, nf = model.na, model.nb, model.nf
    cuts = np.cumsum([na, nb, model.nc, model.nd, nf])
    zinv = 1.0 / z
    a_val = 1.0 + theta[:na] @ _powers(na, 1, zinv)
    f_val = 1.0 + theta[cuts[3] : cuts[4]] @ _powers(nf, 1, zinv)
    b_pow = _powers(nb, model.nk, zinv).T
    d_num = np.zeros((z.size, theta.size), complex)
    d_den = np.zeros((z.size, theta.size), complex)
    d_num[:, na : cuts[1]] = b_pow
    d_den[:, :na] = _powers(na, 1, zinv).T * f_val[:, None]
    d_den[:, cuts[3] : cuts[4]] = _powers(nf, 1, zinv).T * a_val[:, None]
    return b_pow @ theta[na : cuts[1]], a_val * f_val, d_num, d_den


def _delta(
    model: PolynomialModel, theta: np.ndarray, cov: np.ndarray, z: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """At ``theta`` with covariance ``cov``: ``N``, ``D`` (shape ``(K,)``), the covariance of
    ``(Re N, Im N, Re D, Im D)`` (``(K, 4, 4)``) and the standard deviations of ``|G|`` and of its phase
    (rad) to first order (each ``(K,)``)."""
    num, den, d_num, d_den = _parts_jacobian(model, theta, z)
    g = num / den
    jac = (d_num - g[:, None] * d_den) / den[:, None]  # dG/dtheta
    ri = np.stack([jac.real, jac.imag], axis=1)  # (K, 2, p)
    cov_ri = ri @ cov @ np.transpose(ri, (0, 2, 1))  # (K, 2, 2)
    mag = np.abs(g)
    safe = np.where(mag > 0, mag, 1.0)
    grad_mag = np.stack([g.real, g.imag], axis=1) / safe[:, None]
    grad_phase = np.stack([-g.imag, g.real], axis=1) / safe[:, None] ** 2
    sd_mag = np.sqrt(np.maximum(np.einsum("ki,kij,kj->k", grad_mag, cov_ri, grad_mag), 0.0))
    sd_phase = np.sqrt(np.maximum(np.einsum("ki,kij,kj->k", grad_phase, cov_ri, grad_phase), 0.0))
    parts_jac = np.stack([d_num.real, d_num.imag, d_den.real, d_den.imag], axis=1)  # (K, 4, p)
    return num, den, parts_jac @ cov @ np.transpose(parts_jac, (0, 2, 1)), sd_mag, sd_phase


def _sampled(
    freq: np.ndarray,
    parts: tuple[np.ndarray, np.ndarray],
    samples: tuple[np.ndarray, np.ndarray],
    level: float,
    method: str,
) -> FrequencyResponse:
    """Percentile bands and the sample-calibrated region of :meth:`FrequencyResponse.contains` from the
    estimate's numerator and denominator ``parts`` (each shape ``(K,)``) and sampled ones (each ``(S, K)``)."""
    num, den = parts
    g, gs = num / den, samples[0] / samples[1]
    phase = np.degrees(np.unwrap(np.angle(g)))
    tail = 50.0 * (1.0 - level)
    mag_lo, mag_hi = np.percentile(np.abs(gs), [tail, 100.0 - tail], axis=0)
    ratio = gs / np.where(g == 0, 1.0, g)
    lo, hi = np.percentile(np.degrees(np.angle(ratio)), [tail, 100.0 - tail], axis=0)
    x = np.concatenate([_real_imag(samples[0]), _real_imag(samples[1])], axis=2)  # (S, K, 4)
    centred = x - x.mean(axis=0)
    cov = np.einsum("ski,skj->kij", centred, centred) / max(x.shape[0] - 1, 1)
    radius, joint = _calibrated(_fieller(samples[0], samples[1], g, cov), level)
    return FrequencyResponse(
        freq,
        g,
        np.abs(g),
        mag_lo,
        mag_hi,
        phase,
        phase + lo,
        phase + hi,
        level,
        method,
        np.stack([num, den], axis=1),
        cov,
        radius,
        joint,
    )


def _studentized(
    model: PolynomialModel,
    thetas: np.ndarray,
    covariances: np.ndarray,
    freq: np.ndarray,
    level: float,
    method: str,
) -> FrequencyResponse:
    """Fieller's region with the model's covariance, its radius calibrated by the samples' statistics (each
    with its own covariance), and the bands its projections (module docstring)."""
    z = np.exp(2j * np.pi * freq * model.sample_time)
    assert model.covariance is not None
    num, den, cov, _, _ = _delta(model, model.parameters, model.covariance, z)
    g = num / den
    stat = []
    for theta, cov_b in zip(thetas, covariances):
        num_b, den_b, cov_parts_b, _, _ = _delta(model, theta, cov_b, z)
        stat.append(_fieller(num_b, den_b, g, cov_parts_b))
    radius, joint = _calibrated(np.array(stat), level)
    mag_lo, mag_hi, lo, hi = _projected_bands(num, den, cov, radius)
    phase = np.degrees(np.unwrap(np.angle(g)))
    return FrequencyResponse(
        freq,
        g,
        np.abs(g),
        mag_lo,
        mag_hi,
        phase,
        phase + lo,
        phase + hi,
        level,
        method,
        np.stack([num, den], axis=1),
        cov,
        radius,
        joint,
    )


def frequency_response(
    model: PolynomialModel,
    frequency: object | None = None,
    *,
    confidence: float = 0.95,
    method: str = "delta",
    n_draws: int = 2000,
    seed: int | np.random.Generator | None = 0,
) -> FrequencyResponse:
    """Magnitude and phase of ``G = B / (A F)`` with confidence bands from the parameter covariance.

    Parameters
    ----------
    model : PolynomialModel
        An estimated model (with ``covariance``).
    frequency : array_like, optional
        Frequencies (Hz), each in ``[0, 1 / (2 Ts)]``; default 200 log-spaced points from
        ``1e-3`` of the Nyquist frequency to the Nyquist frequency.
    confidence : float
        Level of the bands, in ``(0, 1)``.
    method : {"delta", "monte-carlo"}
        Linearised propagation or pointwise percentiles of draws (see the module docstring).
    n_draws : int
        Parameter draws for ``"monte-carlo"`` (>= 100).
    seed : int, numpy.random.Generator or None
        Randomness of the draws; the same seed gives the same band.

    Returns
    -------
    FrequencyResponse
        With the region of :meth:`FrequencyResponse.contains` (module docstring).

    Raises
    ------
    InputError
        A model without covariance, frequencies outside ``[0, Nyquist]``, a bad level.

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> from trms.identification import arx
    >>> rng = np.random.default_rng(0)
    >>> u = np.sign(rng.standard_normal(800))
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.8], u) + 0.05 * rng.standard_normal(800)
    >>> fr = frequency_response(arx(y, u, 1, 1, 1, sample_time=0.1), [0.0, 1.0])
    >>> zinv = np.exp(-2j * np.pi * fr.frequency * 0.1)
    >>> bool(fr.magnitude_low[0] < 2.5 < fr.magnitude_high[0]), fr.contains(0.5 * zinv / (1 - 0.8 * zinv)).tolist()
    (True, [True, True])
    """
    if model.info.get("intervals_withheld"):
        raise InputError(f"the intervals are withheld: {model.info['intervals_withheld']}")
    if model.covariance is None:
        raise InputError("the model carries no parameter covariance: estimate it (arx, armax, oe, bj) first")
    check_choice("method", method, METHODS, error=InputError)
    freq, level = _frequencies(model, frequency, confidence)
    z = np.exp(2j * np.pi * freq * model.sample_time)
    theta = model.parameters
    if method == "monte-carlo":
        draws_n = check_int("n_draws", n_draws, 100)
        draws = make_rng(seed).multivariate_normal(theta, model.covariance, size=draws_n, method="eigh")
        num, den = _parts(model, theta[None, :], z)
        return _sampled(freq, (num[0], den[0]), _parts(model, draws, z), level, method)
    num, den, cov, sd_mag, sd_phase = _delta(model, theta, model.covariance, z)
    g = num / den
    mag = np.abs(g)
    phase = np.degrees(np.unwrap(np.angle(g)))
    quant = float(scipy.stats.norm.ppf(0.5 + level / 2))
    n_plant = model.na + model.nb + model.nf
    real = (freq == 0) | (freq >= 0.5 / model.sample_time)  # G is real there: one degree of freedom
    return FrequencyResponse(
        freq,
        g,
        mag,
        np.maximum(mag - quant * sd_mag, 0.0),
        mag + quant * sd_mag,
        phase,
        phase - quant * np.degrees(sd_phase),
        phase + quant * np.degrees(sd_phase),
        level,
        method,
        np.stack([num, den], axis=1),
        cov,
        scipy.stats.chi2.ppf(level, np.where(real, 1, 2)),
        np.full(freq.size, scipy.stats.chi2.ppf(level, max(n_plant, 2))),
    )


def response_from_samples(
    model: PolynomialModel,
    samples: object,
    frequency: object | None = None,
    *,
    covariances: object | None = None,
    confidence: float = 0.95,
    method: str = "samples",
) -> FrequencyResponse:
    """Frequency response of ``model`` with bands and region from parameter samples (e.g. a bootstrap).

    Without ``covariances``: pointwise percentile bands of ``|G|`` and of the phase measured from the
    estimate's, and Fieller's region with the samples' covariance, calibrated by the samples. With each
    sample's own covariance (a bootstrap's refits, "studentized"): Fieller's region with the model's
    covariance, its radius the level's quantile of the samples' statistics each computed with its own
    covariance (nearly pivotal: its spread hardly depends on the parameters), and as bands the region's
    projections, the ranges of ``|g|`` and of the phase over it (so they hold the truth at least as often
    as the region; a region that holds ``g = 0`` or is unbounded gives a magnitude band from 0 or to
    ``inf`` and a phase band of +-180 deg: the data do not determine more).

    Parameters
    ----------
    model : PolynomialModel
        The estimate (its parameters give the response the bands surround).
    samples : array_like
        Parameter vectors in the layout of ``model.parameters``, shape ``(S, p)``, ``S >= 10``.
    frequency : array_like, optional
        Frequencies (Hz) as for :func:`frequency_response`.
    covariances : array_like, optional
        Covariance of each sample, shape ``(S, p, p)`` (the model needs its own ``covariance`` then).
    confidence : float
        Level in ``(0, 1)``.
    method : str
        The label stored in the result.

    Returns
    -------
    FrequencyResponse
        Bands (magnitude in output unit per input unit, phase in deg) and the region of
        :meth:`FrequencyResponse.contains`.

    Raises
    ------
    InputError
        Samples or covariances of the wrong shape, fewer than 10 samples, bad frequencies or level.

    Examples
    --------
    >>> from trms.identification.polynomial import PolynomialModel
    >>> model = PolynomialModel([1.0, -0.8], [0.0, 0.5], [1.0], 0.1)
    >>> draws = model.parameters + 0.01 * np.random.default_rng(0).standard_normal((500, 2))
    >>> fr = response_from_samples(model, draws, [0.0])
    >>> bool(fr.magnitude_low[0] < 2.5 < fr.magnitude_high[0]), bool(fr.contains([2.5])[0])
    (True, True)
    """
    thetas = as_finite_array("samples", samples, (None, model.n_parameters))
    if thetas.shape[0] < 10:
        raise InputError(f"samples must hold at least 10 parameter vectors, got {thetas.shape[0]}")
    freq, level = _frequencies(model, frequency, confidence)
    if covariances is not None:
        p = model.n_parameters
        covs = as_finite_array("covariances", covariances, (thetas.shape[0], p, p))
        if model.covariance is None:
            raise InputError("the model carries no parameter covariance: estimate it (arx, armax, oe, bj) first")
        return _studentized(model, thetas, covs, freq, level, method)
    z = np.exp(2j * np.pi * freq * model.sample_time)
    num, den = _parts(model, model.parameters[None, :], z)
    return _sampled(freq, (num[0], den[0]), _parts(model, thetas, z), level, method)


def plot_frequency_response(
    response: FrequencyResponse,
    ax: Sequence[Axes] | None = None,
    *,
    label: str = "model",
    truth: object | None = None,
    truth_label: str = "truth",
) -> Figure:
    """Bode plot of a :class:`FrequencyResponse` with its bands shaded.

    Parameters
    ----------
    response : FrequencyResponse
        What :func:`frequency_response` returned.
    ax : pair of matplotlib Axes, optional
        Magnitude and phase axes to draw on; by default a new two-panel Figure (Agg canvas,
        no pyplot state touched).
    label : str
        Legend entry of the estimate.
    truth : array_like, optional
        A reference complex response at the same frequencies, drawn dashed.
    truth_label : str
        Its legend entry: ``"truth"`` for the system that made the data, else what it is (a published model).

    Returns
    -------
    matplotlib.figure.Figure
        The figure holding the axes.

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> from trms.identification import arx
    >>> rng = np.random.default_rng(0)
    >>> u = np.sign(rng.standard_normal(800))
    >>> y = scipy.signal.lfilter([0, 0.5], [1, -0.8], u) + 0.05 * rng.standard_normal(800)
    >>> fig = plot_frequency_response(frequency_response(arx(y, u, 1, 1, 1, sample_time=0.1)))
    >>> len(fig.axes)
    2
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    if ax is None:
        fig = Figure(figsize=(7.0, 6.0), dpi=100)
        FigureCanvasAgg(fig)
        ax_mag, ax_ph = fig.subplots(2, 1, sharex=True)
    else:
        if len(ax) != 2:
            raise InputError(f"ax must be a pair (magnitude, phase) of Axes, got {len(ax)}")
        ax_mag, ax_ph = ax
        root = ax_mag.get_figure(root=True)
        if root is None:
            raise InputError("ax must be Axes drawn on a figure")
        fig = root
    f = response.frequency
    pct = f"{100 * response.confidence:g} %"
    ax_mag.fill_between(
        f, response.magnitude_low, response.magnitude_high, alpha=0.3, label=f"{pct} band ({response.method})"
    )
    ax_mag.plot(f, response.magnitude, lw=1.2, label=label)
    ax_ph.fill_between(f, response.phase_low, response.phase_high, alpha=0.3)
    ax_ph.plot(f, response.phase, lw=1.2)
    if truth is not None:
        g = as_finite_array("truth", truth, (f.size,), dtype=complex)
        ax_mag.plot(f, np.abs(g), "k--", lw=1.0, label=truth_label)
        ax_ph.plot(f, response.phase + np.degrees(np.angle(g / response.response)), "k--", lw=1.0)
    positive = f > 0
    if np.all(positive):
        ax_mag.set_xscale("log")
    if np.all(response.magnitude_low[positive] > 0):
        ax_mag.set_yscale("log")
    ax_mag.set_ylabel("magnitude (output / input)")
    ax_ph.set_ylabel("phase (deg)")
    ax_ph.set_xlabel("frequency (Hz)")
    ax_mag.legend(loc="best", fontsize=8)
    ax_mag.grid(True, which="both", alpha=0.3)
    ax_ph.grid(True, which="both", alpha=0.3)
    return fig
