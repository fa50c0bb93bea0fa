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

Both inherit the assumptions of the covariance: for an output-error model it assumes white
output noise (MATLAB's convention), so under a coloured disturbance the bands of ``oe`` are
too narrow (use ``bj``, whose noise model makes them right).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.stats

from trms.errors import InputError, as_finite_array, check_choice, check_in_range, check_int
from trms.identification.polynomial import PolynomialModel
from trms.signals import make_rng

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["FrequencyResponse", "frequency_response", "plot_frequency_response", "METHODS"]

#: Ways to carry the parameter covariance to the response.
METHODS = ("delta", "monte-carlo")


@dataclass(frozen=True)
class FrequencyResponse:
    """A model's frequency response with pointwise confidence bands.

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
        ``"delta"`` or ``"monte-carlo"``.
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

    def contains(self, response: object) -> np.ndarray:
        """Whether another response (complex, shape ``(K,)``) lies inside both bands, per frequency.

        The phase of ``response`` is compared modulo 360 deg with the band around :attr:`phase`.
        """
        g = as_finite_array("response", response, (self.frequency.size,), dtype=complex)
        mag = np.abs(g)
        dphase = np.degrees(np.angle(g / self.response))
        return (
            (mag >= self.magnitude_low)
            & (mag <= self.magnitude_high)
            & (self.phase + dphase >= self.phase_low)
            & (self.phase + dphase <= self.phase_high)
        )


def _default_frequencies(sample_time: float, n: int = 200) -> np.ndarray:
    nyquist = 0.5 / sample_time
    return np.geomspace(nyquist * 1e-3, nyquist, n)


def _response_and_jacobian(model: PolynomialModel, theta: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``G(z)`` and ``dG/dtheta`` (shape ``(K, p)``) at ``theta`` (the model's parameter layout)."""
    na, nb, nc, nd, nf, nk = model.na, model.nb, model.nc, model.nd, model.nf, model.nk
    cuts = np.cumsum([na, nb, nc, nd, nf])
    a, b, _c, _d, f = np.split(theta, cuts[:-1])
    zinv = 1.0 / z
    a_val = 1.0 + sum(a[k] * zinv ** (k + 1) for k in range(na))
    f_val = 1.0 + sum(f[k] * zinv ** (k + 1) for k in range(nf))
    b_pow = np.stack([zinv ** (nk + k) for k in range(nb)], axis=1)
    g = (b_pow @ b) / (a_val * f_val)
    jac = np.zeros((z.size, theta.size), complex)
    for k in range(na):
        jac[:, k] = -(zinv ** (k + 1)) * g / a_val
    jac[:, na : na + nb] = b_pow / (a_val * f_val)[:, None]
    for k in range(nf):
        jac[:, cuts[3] + k] = -(zinv ** (k + 1)) * g / f_val
    return g, jac


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
    >>> bool(fr.magnitude_low[0] < 2.5 < fr.magnitude_high[0])
    True
    """
    if model.covariance is None:
        raise InputError("the model carries no parameter covariance: estimate it (arx, armax, oe, bj) first")
    check_choice("method", method, METHODS, error=InputError)
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
    z = np.exp(2j * np.pi * freq * ts)
    theta = model.parameters
    g, jac = _response_and_jacobian(model, theta, z)
    mag = np.abs(g)
    phase = np.degrees(np.unwrap(np.angle(g)))
    if method == "delta":
        quant = float(scipy.stats.norm.ppf(0.5 + level / 2))
        ri = np.stack([jac.real, jac.imag], axis=1)  # (K, 2, p)
        cov_ri = ri @ model.covariance @ np.transpose(ri, (0, 2, 1))  # (K, 2, 2)
        safe = np.where(mag > 0, mag, 1.0)
        grad_mag = np.stack([g.real, g.imag], axis=1) / safe[:, None]
        grad_phase = np.stack([-g.imag, g.real], axis=1) / safe[:, None] ** 2
        sd_mag = np.sqrt(np.maximum(np.einsum("ki,kij,kj->k", grad_mag, cov_ri, grad_mag), 0.0))
        sd_phase = np.degrees(np.sqrt(np.maximum(np.einsum("ki,kij,kj->k", grad_phase, cov_ri, grad_phase), 0.0)))
        mag_lo, mag_hi = np.maximum(mag - quant * sd_mag, 0.0), mag + quant * sd_mag
        ph_lo, ph_hi = phase - quant * sd_phase, phase + quant * sd_phase
    else:
        draws_n = check_int("n_draws", n_draws, 100)
        rng = make_rng(seed)
        draws = rng.multivariate_normal(theta, model.covariance, size=draws_n, method="eigh")
        gs = np.stack([_response_and_jacobian(model, th, z)[0] for th in draws])
        tail = 50.0 * (1.0 - level)
        mag_lo, mag_hi = np.percentile(np.abs(gs), [tail, 100.0 - tail], axis=0)
        dph = np.degrees(np.angle(gs / g))
        lo, hi = np.percentile(dph, [tail, 100.0 - tail], axis=0)
        ph_lo, ph_hi = phase + lo, phase + hi
    return FrequencyResponse(freq, g, mag, mag_lo, mag_hi, phase, ph_lo, ph_hi, level, method)


def plot_frequency_response(
    response: FrequencyResponse,
    ax: Sequence[Axes] | None = None,
    *,
    label: str = "model",
    truth: object | None = None,
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
        ax_mag.plot(f, np.abs(g), "k--", lw=1.0, label="truth")
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
