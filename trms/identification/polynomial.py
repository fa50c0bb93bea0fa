"""The polynomial model of eq. (3.2), in MATLAB's general ``idpoly`` form, and what can be done with it.

``A(q) y(t) = B(q) / F(q) u(t) + C(q) / D(q) e(t)`` with, in the backward shift ``q^-1``,

* ``A = [1, a1, ..., a_na]``
* ``B = [0] * nk + [b1, ..., b_nb]`` (``b1`` multiplies ``u(t - nk)``)
* ``C = [1, c1, ..., c_nc]`` (``C = [1]`` for ARX)
* ``D = [1, d1, ..., d_nd]`` and ``F = [1, f1, ..., f_nf]`` (both ``[1]`` for ARX and ARMAX;
  output-error is ``A = C = D = 1``, Box-Jenkins ``A = 1``)

Prediction, simulation and residuals all run through ``scipy.signal.lfilter``. Data
before the first sample are unknown, so predictions are *conditional*: the input part
``w = B / F u`` is filtered from rest before sample 0, the first
``start = max(na + nf, nk + nb - 1)`` samples carry no prediction (their prediction error
is set to 0) and the noise filter ``D / C`` starts from rest at ``start``. This is exactly
the criterion the prediction-error estimators (:mod:`trms.identification.pem`) minimise.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import control
import numpy as np
import scipy.signal

from trms.display import html_table
from trms.errors import InputError, as_finite_array, check_in_range, check_int
from trms.identification.data import measured_signals, model_signals
from trms.modes import Mode

__all__ = ["PolynomialModel", "modes_of_poles"]


def modes_of_poles(poles: np.ndarray, sample_time: float) -> list[Mode]:
    """Natural frequency and damping of discrete poles via ``s = ln(z) / Ts`` (:class:`trms.modes.Mode`).

    One entry per real pole and per complex-conjugate pair (the pole with positive
    imaginary part is kept), sorted by frequency. A real pole ``0 < z < 1`` is a first-order
    lag with damping 1 and time constant ``1 / (2 pi f)``; a pole at ``z = 0`` (pure delay)
    has no continuous equivalent and is skipped.
    """
    ts = float(sample_time)
    out = []
    for p in np.asarray(poles, complex):
        if p.imag < -1e-12 or abs(p) < 1e-12:
            continue
        s = np.log(p) / ts
        wn = abs(s)
        out.append(Mode(float(wn / (2 * np.pi)), float(-s.real / wn) if wn > 0 else 1.0, complex(s)))
    return sorted(out, key=lambda m: m.frequency_hz)


def _poly(name: str, coeffs: object, monic: bool) -> np.ndarray:
    arr = as_finite_array(name, coeffs)
    if arr.ndim != 1 or arr.size < 1:
        raise InputError(f"{name} must be a 1-D coefficient array, got shape {arr.shape}")
    if monic and arr[0] != 1.0:
        raise InputError(f"{name} must be monic (leading coefficient 1), got {arr[0]!r}")
    return arr


@dataclass(frozen=True, eq=False)
class PolynomialModel:
    """A discrete SISO polynomial model ``A y = B u + C e`` (eq. 3.2).

    Parameters
    ----------
    A, B, C : array_like
        Coefficients in ascending powers of ``q^-1`` (see the module docstring); ``A`` and
        ``C`` monic. ``B``'s leading zeros are the input delay ``nk``.
    D, F : array_like
        Monic noise denominator and input denominator (default ``[1]``: ARX/ARMAX).
    sample_time : float
        Seconds per sample.
    noise_variance : float
        Variance of the innovations ``e`` (output unit squared).
    covariance : numpy.ndarray, optional
        Covariance of :attr:`parameters` (``[a1..a_na, b1..b_nb, c1..c_nc, d1..d_nd, f1..f_nf]``).
    n_samples : int
        Number of prediction errors the fit used (``N - start``).
    loss : float
        Mean squared one-step prediction error on the estimation data.
    method : str
        How the model was obtained (``"arx"``, ``"armax-pem"``, ``"oe-pem"``, ``"bj-pem"``, ``"given"``).
    input_name, output_name : str
        Channel names.
    info : dict
        Estimator details (iterations, initial estimate...).
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    sample_time: float
    noise_variance: float = 0.0
    covariance: np.ndarray | None = None
    n_samples: int = 0
    loss: float = float("nan")
    method: str = "given"
    input_name: str = "u"
    output_name: str = "y"
    info: dict[str, Any] = field(default_factory=dict)
    D: np.ndarray = field(default_factory=lambda: np.ones(1))
    F: np.ndarray = field(default_factory=lambda: np.ones(1))
    nk: int = field(init=False)

    def __post_init__(self) -> None:
        polys = {"A": True, "B": False, "C": True, "D": True, "F": True}
        for name, monic in polys.items():
            arr = _poly(name, getattr(self, name), monic)
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)
        nz = np.flatnonzero(self.B)
        object.__setattr__(self, "nk", int(nz[0]) if nz.size else 0)
        check_in_range("sample_time", self.sample_time, 0.0, np.inf, unit=" s", low_open=True)

    @classmethod
    def from_parameters(
        cls,
        theta: np.ndarray,
        na: int,
        nb: int,
        nc: int,
        nk: int,
        sample_time: float,
        nd: int = 0,
        nf: int = 0,
        **kwargs: Any,
    ) -> PolynomialModel:
        """Build from the stacked vector ``[a1..a_na, b1..b_nb, c1..c_nc, d1..d_nd, f1..f_nf]`` and the orders."""
        theta = np.asarray(theta, float)
        cuts = np.cumsum([na, nb, nc, nd, nf])
        a, b, c, d, f = np.split(theta[: cuts[-1]], cuts[:-1])
        one = np.ones(1)
        model = cls(
            np.concatenate([one, a]),
            np.concatenate([np.zeros(nk), b]),
            np.concatenate([one, c]),
            sample_time,
            D=np.concatenate([one, d]),
            F=np.concatenate([one, f]),
            **kwargs,
        )
        object.__setattr__(model, "nk", int(nk))
        return model

    # ------------------------------------------------------------ structure
    @property
    def na(self) -> int:
        """Order of ``A``."""
        return self.A.size - 1

    @property
    def nb(self) -> int:
        """Number of ``B`` coefficients after the delay."""
        return self.B.size - self.nk

    @property
    def nc(self) -> int:
        """Order of ``C``."""
        return self.C.size - 1

    @property
    def nd(self) -> int:
        """Order of ``D``."""
        return self.D.size - 1

    @property
    def nf(self) -> int:
        """Order of ``F``."""
        return self.F.size - 1

    @property
    def orders(self) -> tuple[int, int, int, int]:
        """``(na, nb, nc, nk)`` (see :attr:`nd`, :attr:`nf` for the rest of the general form)."""
        return self.na, self.nb, self.nc, self.nk

    @property
    def start(self) -> int:
        """First sample with a prediction: ``max(na + nf, nk + nb - 1)``."""
        return max(self.na + self.nf, self.nk + self.nb - 1)

    @property
    def parameters(self) -> np.ndarray:
        """``[a1..a_na, b1..b_nb, c1..c_nc, d1..d_nd, f1..f_nf]``."""
        return np.concatenate([self.A[1:], self.B[self.nk :], self.C[1:], self.D[1:], self.F[1:]])

    @property
    def parameter_names(self) -> list[str]:
        """Names matching :attr:`parameters` (``a1``, ``b1``, ``c1``, ``d1``, ``f1``...)."""
        counts = (("a", self.na), ("b", self.nb), ("c", self.nc), ("d", self.nd), ("f", self.nf))
        return [f"{p}{i}" for p, n in counts for i in range(1, n + 1)]

    @property
    def n_parameters(self) -> int:
        """Number of estimated parameters."""
        return self.na + self.nb + self.nc + self.nd + self.nf

    @property
    def std_errors(self) -> np.ndarray:
        """Standard deviations of :attr:`parameters` from :attr:`covariance` (refused where the estimator withheld
        its intervals: ``info["intervals_withheld"]`` says why)."""
        if self.info.get("intervals_withheld"):
            raise InputError(f"the intervals are withheld: {self.info['intervals_withheld']}")
        if self.covariance is None:
            raise InputError("this model carries no parameter covariance (it was not estimated)")
        return np.sqrt(np.diag(self.covariance))

    # ------------------------------------------------------------ criteria
    @property
    def fpe(self) -> float:
        """Akaike's final prediction error ``V (1 + p/N) / (1 - p/N)``."""
        p, n = self.n_parameters, self.n_samples
        return float(self.loss * (1 + p / n) / (1 - p / n)) if n > p else float("inf")

    @property
    def aic(self) -> float:
        """Akaike's information criterion ``N log V + 2 p``."""
        return float(self.n_samples * np.log(self.loss) + 2 * self.n_parameters)

    @property
    def bic(self) -> float:
        """Bayesian (Rissanen MDL) criterion ``N log V + p log N``."""
        return float(self.n_samples * np.log(self.loss) + self.n_parameters * np.log(self.n_samples))

    # ------------------------------------------------------------ time domain
    def _signals(self, y: object | None, u: object) -> tuple[np.ndarray | None, np.ndarray]:
        return model_signals(y, u, self.start)

    def residuals(self, y: object, u: object) -> np.ndarray:
        """One-step prediction errors ``eps = D / C (A y - B / F u)`` (eq. 3.5), conditional.

        Parameters
        ----------
        y, u : array_like
            Output and input deviations, shape ``(N,)``.

        Returns
        -------
        numpy.ndarray
            Shape ``(N,)``; the first :attr:`start` entries are 0 (no prediction).
        """
        ya, ua = measured_signals(y, u, self.start)
        return prediction_errors(self.A, self.B, self.C, ya, ua, self.start, D=self.D, F=self.F)

    def predict(self, y: object, u: object, horizon: int = 1) -> np.ndarray:
        """``horizon``-step-ahead prediction ``yhat(t | t - k)``.

        With ``H = C / (A D) = F_k + q^-k G_k / (A D)`` (``F_k`` the first ``k`` impulse-response terms
        of the noise model ``H``), the ``k``-step predictor is ``yhat = y - F_k eps`` where ``eps`` are the
        one-step prediction errors; ``k = 1`` is eq. (3.3).

        Parameters
        ----------
        y, u : array_like
            Measured output and input, shape ``(N,)``.
        horizon : int
            ``k >= 1`` samples ahead.

        Returns
        -------
        numpy.ndarray
            Shape ``(N,)``; equal to ``y`` for the first :attr:`start` samples.
        """
        k = check_int("horizon", horizon, 1, unit=" samples")
        ya, ua = measured_signals(y, u, self.start)
        eps = prediction_errors(self.A, self.B, self.C, ya, ua, self.start, D=self.D, F=self.F)
        impulse = np.zeros(k)
        impulse[0] = 1.0
        fk = scipy.signal.lfilter(self.C, np.convolve(self.A, self.D), impulse)
        return ya - scipy.signal.lfilter(fk, [1.0], eps)

    def simulate(self, u: object, y: object | None = None) -> np.ndarray:
        """Free-run (simulated) output ``B / (A F) u``, as MATLAB's ``compare`` with infinite horizon.

        Parameters
        ----------
        u : array_like
            Input deviations, shape ``(N,)``.
        y : array_like, optional
            Measured output: when given, its first :attr:`start` samples are the initial
            conditions (and are copied to the result); otherwise the model starts at rest.

        Returns
        -------
        numpy.ndarray
            Shape ``(N,)``.
        """
        ya, ua = self._signals(y, u)
        den = self.denominator
        if ya is None:
            return scipy.signal.lfilter(self.B, den, ua)
        n0 = self.start
        out = ya.copy()
        zi = scipy.signal.lfiltic(self.B, den, ya[:n0][::-1], ua[:n0][::-1])
        if zi.size == 0:
            return scipy.signal.lfilter(self.B, den, ua)
        out[n0:] = scipy.signal.lfilter(self.B, den, ua[n0:], zi=zi)[0]
        return out

    @property
    def denominator(self) -> np.ndarray:
        """``A F``: the denominator of the input-output transfer function ``G = B / (A F)``."""
        return np.convolve(self.A, self.F)

    # ------------------------------------------------------------ LTI views
    def _descending(self, num: np.ndarray, den: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        size = max(num.size, den.size)
        return np.pad(num, (0, size - num.size)), np.pad(den, (0, size - den.size))

    def to_tf(self) -> control.TransferFunction:
        """``G(z) = B(z^-1) / (A(z^-1) F(z^-1))`` as a python-control discrete TransferFunction."""
        num, den = self._descending(self.B, self.denominator)
        nz = np.flatnonzero(num)
        num = num[nz[0] :] if nz.size else np.zeros(1)
        return control.tf(num, den, self.sample_time, inputs=[self.input_name], outputs=[self.output_name])

    def to_ss(self) -> control.StateSpace:
        """The same system as a python-control discrete StateSpace (scipy's realisation, with or without slycot)."""
        return control.tf2ss(self.to_tf(), method="scipy")

    def noise_tf(self) -> control.TransferFunction:
        """The noise model ``H(z) = C(z^-1) / (A(z^-1) D(z^-1))`` (from ``e`` to ``y``)."""
        num, den = self._descending(self.C, np.convolve(self.A, self.D))
        return control.tf(num, den, self.sample_time)

    def poles(self) -> np.ndarray:
        """Roots of ``A F`` (the poles of ``G``) in the z-plane (z = 0 roots from a delay excluded)."""
        return np.roots(np.trim_zeros(self.denominator, "b"))

    def zeros(self) -> np.ndarray:
        """Finite zeros of ``G`` in the z-plane (roots of ``B`` without its delay)."""
        b = np.trim_zeros(np.trim_zeros(self.B, "f"), "b")
        return np.roots(b) if b.size > 1 else np.zeros(0, complex)

    def modes(self) -> list[Mode]:
        """Natural frequency (Hz) and damping of each pole (see :func:`modes_of_poles`)."""
        return modes_of_poles(self.poles(), self.sample_time)

    def dc_gain(self) -> float:
        """Steady-state gain ``B(1) / (A(1) F(1))`` (output unit per input unit); ``inf`` with an integrator."""
        a1 = float(np.sum(self.denominator))
        b1 = float(np.sum(self.B))
        if a1 == 0.0:
            return float(np.copysign(np.inf, b1)) if b1 else float("nan")
        return b1 / a1

    def is_stable(self) -> bool:
        """All poles strictly inside the unit circle."""
        p = self.poles()
        return bool(p.size == 0 or np.max(np.abs(p)) < 1.0)

    def _order_text(self) -> str:
        """The orders that define the structure: ``nb`` and ``nk`` always, ``na nc nd nf`` when not 0."""
        orders = {"na": self.na, "nb": self.nb, "nc": self.nc, "nd": self.nd, "nf": self.nf, "nk": self.nk}
        return " ".join(f"{k}={v}" for k, v in orders.items() if v or k in ("nb", "nk"))

    def __repr__(self) -> str:
        return (
            f"PolynomialModel({self.method}, {self.input_name} -> {self.output_name}, {self._order_text()}, "
            f"Ts={self.sample_time:g} s, N={self.n_samples}, noise variance {self.noise_variance:.3g}, "
            f"FPE {self.fpe:.3g})"
        )

    def _repr_html_(self) -> str:
        oscillatory = [m for m in self.modes() if m.damping < 1.0]
        modes = "; ".join(f"{m.frequency_hz:.3f} Hz, damping {m.damping:.3f}" for m in oscillatory) or "-"
        rows = [
            ("method", self.method),
            ("channel", f"{self.input_name} -> {self.output_name}"),
            ("orders", self._order_text()),
            ("sample time (s)", f"{self.sample_time:g}"),
            ("estimation samples", str(self.n_samples)),
            ("noise variance", f"{self.noise_variance:.4g}"),
            ("loss (mean squared one-step error)", f"{self.loss:.4g}"),
            ("FPE, AIC", f"{self.fpe:.4g}, {self.aic:.4g}"),
            ("DC gain", f"{self.dc_gain():.4g}"),
            ("oscillatory modes", modes),
            ("stable", "yes" if self.is_stable() else "no"),
        ]
        return html_table("PolynomialModel", rows)


def prediction_errors(
    A: np.ndarray,
    B: np.ndarray,
    C: np.ndarray,
    y: np.ndarray,
    u: np.ndarray,
    start: int,
    *,
    D: np.ndarray | None = None,
    F: np.ndarray | None = None,
) -> np.ndarray:
    """Conditional one-step prediction errors ``D / C (A y - B / F u)``, zero before ``start``.

    ``A y`` is exact from ``na`` on and ``B u`` from ``nk + nb - 1`` (no pre-sample data
    needed); ``1 / F`` runs from rest before sample 0 and the noise filter ``D / C`` from rest
    at ``start``.
    """
    w = scipy.signal.lfilter(B, [1.0] if F is None else F, u)
    v = scipy.signal.lfilter(A, [1.0], y) - w
    eps = np.zeros(y.size)
    num = np.ones(1) if D is None else D
    eps[start:] = scipy.signal.lfilter(num, C, v[start:]) if C.size > 1 or num.size > 1 else v[start:]
    return eps
