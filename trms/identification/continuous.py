"""Continuous-time transfer functions and process models from sampled data (MATLAB ``tfest``, ``procest``).

The model is ``y(t) = G(s) u(t - tau) + e``, ``G = (b_nz s^nz + ... + b_0) / (s^np + a_(np-1) s^(np-1) + ... + a_0)``
strictly proper (``nz < np``), with an input delay ``tau >= 0`` (s). The input is held over each sample
(the Record convention: ``u_k`` over ``[k Ts, (k + 1) Ts)``), so the sampled output is exactly the output of the
zero-order-hold discretisation of ``G`` with a fractional delay: with ``tau = d Ts + eps``, ``0 <= eps < Ts``,

``x_(k+1) = Phi x_k + Gamma_a u_(k-d-1) + Gamma_b u_(k-d)``, ``Phi = e^(A Ts)``,
``Gamma_b = int_0^(Ts-eps) e^(A s) ds B``, ``Gamma_a = e^(A (Ts - eps)) int_0^eps e^(A s) ds B``,

continuous in ``tau`` (the model at ``eps -> Ts`` is the model at ``d + 1``, ``eps = 0``).

Method: the output-error fit of that discretisation (not SRIVC): the sum of squared simulation errors (from
rest) is minimised over the denominator and the delay by ``scipy.optimize.least_squares`` (trust-region
reflective, delay bounded), the numerator, which enters linearly, solved by least squares at every step
(variable projection). Consistent for any output disturbance independent of the input; minimum variance for
white output noise.

Start: the integer delay whose ARX model ``(np, np + 1, d + 1)`` simulates the data best, a discrete
output-error model (:func:`~trms.identification.oe_bj.oe`) at that delay, its poles mapped by ``s = ln(z) / Ts``,
and the delay on a quarter-sample grid around it. Process models (:func:`procest`) start from :func:`tfest`
of their pole and zero counts and are refined in their own parameters (gain, time constants, damping, delay).

The parameter covariance is ``sigma^2 (J^T J)^-1`` (:func:`~trms.identification.pem.covariance`) with the
Jacobian (central differences) of the simulation errors in the model's named parameters.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import control
import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.signal

from trms.errors import InputError, check_in_range, check_int
from trms.identification.data import SisoData, check_excitation, lag_matrix, model_signals, siso_data
from trms.identification.oe_bj import oe
from trms.identification.pem import covariance
from trms.identification.regression import arx_regressors, solve_ls
from trms.identification.validation import fit_percent
from trms.modes import Mode, mode_of_eigenvalue
from trms.record import Record

__all__ = ["ContinuousModel", "tfest", "procest"]

#: Default largest delay searched (samples), at most a quarter of the record.
_DEFAULT_MAX_DELAY = 20
#: Shortest time constant of a process model, as a fraction of the sample time.
_SHORTEST = 1e-3
#: Fewest samples per estimated parameter (after the longest delay searched).
_SAMPLES_PER_PARAMETER = 10
#: Grid spacing (samples) of the start's delay search around the best integer delay.
_GRID = 0.25


def _basis(den: np.ndarray, tau: float, u: np.ndarray, ts: float, count: int) -> np.ndarray:
    """Sampled responses ``(N, count)`` of ``s^i / den(s)`` (``i < count``), delayed by ``tau``, to the held ``u``."""
    n = den.size - 1
    aug = np.zeros((n + 1, n + 1))  # [[A, B], [0, 0]] of the controllable form: state i is s^i / den u
    aug[: n - 1, 1:n] = np.eye(n - 1)
    aug[n - 1, :n] = -den[::-1][:n]
    aug[n - 1, n] = 1.0
    d = int(np.floor(tau / ts + 1e-9))
    eps = max(tau - d * ts, 0.0)
    late, early = scipy.linalg.expm(aug * (ts - eps)), scipy.linalg.expm(aug * eps)
    phi = late[:n, :n] @ early[:n, :n]
    gam_b, gam_a = late[:n, n:], late[:n, :n] @ early[:n, n:]
    rows, zero = np.eye(n)[:count], np.zeros((count, 1))
    num_b, den_d = scipy.signal.ss2tf(phi, gam_b, rows, zero)
    num_a, _ = scipy.signal.ss2tf(phi, gam_a, rows, zero)
    taps = np.zeros((count, d + n + 2))
    taps[:, d : d + n + 1] += num_b
    taps[:, d + 1 :] += num_a
    filtered = scipy.signal.lfilter([1.0], np.real(den_d), u)
    return lag_matrix(filtered, range(taps.shape[1]), 0) @ taps.T


@dataclass
class ContinuousModel:
    """A continuous-time model ``y = num(s) / den(s) e^(-delay s) u + e`` fitted to sampled data.

    Attributes
    ----------
    num, den : numpy.ndarray
        Numerator and monic denominator, descending powers of ``s`` (output unit per input unit, 1/s).
    delay : float
        Input delay ``tau`` (s).
    sample_time : float
        Seconds per sample of the estimation data (the input held over each sample).
    loss : float
        Mean squared simulation error on the estimation data (output unit squared).
    fit : float
        Simulation fit (%) on the estimation data.
    n_samples : int
        Samples of the estimation data.
    parameters : dict of str to float
        The named parameters: ``a0 .. a(np-1), b0 .. b(nz), tau`` for :func:`tfest`; MATLAB's ``K, Tp1, Tp2,
        Tp3, Tw, Zeta, Tz, Td`` (those of the kind) for :func:`procest`.
    covariance : numpy.ndarray
        Their covariance (order of ``parameters``; the delay's row and column are zero where it was fixed).
    method : str
        ``"tfest"`` or ``"procest"``.
    kind : str
        ``"np=2, nz=0"`` or the process kind (e.g. ``"P2DU"``).
    """

    num: np.ndarray
    den: np.ndarray
    delay: float
    sample_time: float
    loss: float
    fit: float
    n_samples: int
    parameters: dict[str, float]
    covariance: np.ndarray
    method: str
    kind: str
    input_name: str = "u"
    output_name: str = "y"
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def std_errors(self) -> dict[str, float]:
        """Standard error of each named parameter."""
        sd = np.sqrt(np.maximum(np.diag(self.covariance), 0.0))
        return dict(zip(self.parameters, (float(s) for s in sd)))

    def to_tf(self) -> control.TransferFunction:
        """``num(s) / den(s)`` as a continuous python-control TransferFunction (the delay is :attr:`delay`)."""
        return control.tf(self.num, self.den, inputs=[self.input_name], outputs=[self.output_name])

    def poles(self) -> np.ndarray:
        """Roots of ``den`` (1/s)."""
        return np.roots(self.den)

    def modes(self) -> list[Mode]:
        """Natural frequency (Hz) and damping of each real pole and complex pair, by frequency."""
        return sorted((mode_of_eigenvalue(p) for p in self.poles() if p.imag >= 0), key=lambda m: m.frequency_hz)

    def dc_gain(self) -> float:
        """``num(0) / den(0)`` (output unit per input unit); ``inf`` with an integrator."""
        return float(self.num[-1] / self.den[-1]) if self.den[-1] != 0 else float("inf")

    def simulate(self, u: object) -> np.ndarray:
        """Sampled output from rest for a held input sequence ``u`` (shape ``(N,)``, this model's sample time)."""
        _, ua = model_signals(None, u, 0)
        count = self.num.size
        return _basis(self.den, self.delay, ua, self.sample_time, count) @ self.num[::-1]

    def __repr__(self) -> str:
        named = ", ".join(f"{k}={v:.4g}" for k, v in self.parameters.items())
        return f"ContinuousModel({self.method} {self.kind}: {named}; fit {self.fit:.1f} %, N={self.n_samples})"


# ---------------------------------------------------------------- the shared fit


def _simulation_errors(d: SisoData, den: np.ndarray, tau: float, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Errors of the best numerator for ``den`` and ``tau`` (variable projection) and that numerator (ascending)."""
    x = _basis(den, tau, d.u, d.sample_time, count)
    beta = np.linalg.lstsq(x, d.y, rcond=None)[0]
    return d.y - x @ beta, beta


def _check_delays(d: SisoData, delay: object, max_delay: object) -> tuple[float | None, float]:
    """Checked fixed ``delay`` (None: estimated) and the largest delay searched (s)."""
    ts, n = d.sample_time, len(d)
    longest = (n // 2) * ts
    if delay is not None:
        fixed = check_in_range("delay", delay, 0.0, longest, unit=" s")
        return fixed, fixed
    if max_delay is None:
        return None, min(_DEFAULT_MAX_DELAY, n // 4) * ts
    return None, check_in_range("max_delay", max_delay, 0.0, longest, unit=" s")


def _start(d: SisoData, n_poles: int, delay: float | None, max_delay: float) -> tuple[np.ndarray, int]:
    """Initial monic denominator (continuous) and integer delay (samples): ARX delay scan, then discrete OE."""
    ts = d.sample_time
    if delay is not None:
        best = int(np.floor(delay / ts + 1e-9))
    else:
        losses = []
        for k in range(int(np.floor(max_delay / ts + 1e-9)) + 1):
            start = max(n_poles, k + n_poles + 1)
            theta = solve_ls(arx_regressors(d, n_poles, n_poles + 1, k + 1, start), d.y[start:], "delay scan ARX")
            a = np.concatenate([[1.0], theta[:n_poles]])
            sim = scipy.signal.lfilter(np.concatenate([np.zeros(k + 1), theta[n_poles:]]), a, d.u)
            bad = np.max(np.abs(np.roots(a)), initial=0.0) >= 1.0 or not np.all(np.isfinite(sim))
            losses.append(np.inf if bad else float(np.sum((d.y - sim) ** 2)))
        best = int(np.argmin(losses))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = oe(d.y, d.u, n_poles + 1, n_poles, best + 1, sample_time=ts, starts=2).F
    z = np.roots(f).astype(complex)
    z = np.where((np.abs(z.imag) < 1e-9) & (z.real <= 1e-3), 1e-3, z)  # no continuous equivalent: a fast pole
    return np.real(np.poly(np.log(z) / ts)), best


def _refine(
    d: SisoData,
    to_den: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    count: int,
) -> np.ndarray:
    """Least squares over ``x = [denominator parameters, tau]`` with the numerator projected out."""

    def errors(x: np.ndarray) -> np.ndarray:
        return _simulation_errors(d, to_den(x[:-1]), float(x[-1]), count)[0]

    x0 = np.clip(x0, lower, upper)
    same = lower == upper  # a fixed delay: bounds must differ for least_squares
    if same.any():
        fixed = x0[same]

        def errors_free(xf: np.ndarray) -> np.ndarray:
            return errors(np.concatenate([xf, fixed]))

        res = scipy.optimize.least_squares(
            errors_free, x0[~same], bounds=(lower[~same], upper[~same]), x_scale="jac", ftol=1e-12, xtol=1e-12
        )
        return np.concatenate([res.x, fixed])
    res = scipy.optimize.least_squares(errors, x0, bounds=(lower, upper), x_scale="jac", ftol=1e-12, xtol=1e-12)
    return np.asarray(res.x)


def _delay_grid(d: SisoData, den: np.ndarray, best: int, max_delay: float, count: int) -> float:
    """The delay (s) on a quarter-sample grid within a sample of ``best`` with the least projected error."""
    ts = d.sample_time
    grid = np.clip((best + np.arange(-1.0, 1.0 + 1e-9, _GRID)) * ts, 0.0, max_delay)
    sse = [float(np.sum(_simulation_errors(d, den, float(t), count)[0] ** 2)) for t in np.unique(grid)]
    return float(np.unique(grid)[int(np.argmin(sse))])


def _finish(
    d: SisoData,
    full: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, float]],
    params: np.ndarray,
    names: list[str],
    fixed_delay: bool,
    method: str,
    kind: str,
) -> ContinuousModel:
    """The model of the named ``params`` (``full`` gives num, den, tau), with the Jacobian covariance."""
    num, den, tau = full(params)

    def errors(p: np.ndarray) -> np.ndarray:
        n_, d_, t_ = full(p)
        return d.y - _basis(d_, t_, d.u, d.sample_time, n_.size) @ n_[::-1]

    eps = errors(params)
    free = np.array([not (fixed_delay and name in ("tau", "Td")) for name in names])
    step = 1e-6 * np.maximum(np.abs(params), 1e-3)
    jac = np.zeros((eps.size, params.size))
    for i in np.flatnonzero(free):
        dp = np.zeros(params.size)
        dp[i] = step[i]
        jac[:, i] = (errors(params + dp) - errors(params - dp)) / (2 * step[i])
    sigma2 = float(eps @ eps) / max(eps.size - int(free.sum()), 1)
    cov = np.zeros((params.size, params.size))
    cov[np.ix_(free, free)] = covariance(jac[:, free], sigma2)
    return ContinuousModel(
        num=num,
        den=den,
        delay=tau,
        sample_time=d.sample_time,
        loss=float(eps @ eps) / eps.size,
        fit=fit_percent(d.y, d.y - eps),
        n_samples=len(d),
        parameters={k: float(v) for k, v in zip(names, params)},
        covariance=cov,
        method=method,
        kind=kind,
        input_name=d.input_name,
        output_name=d.output_name,
    )


def _prepared(
    data: Record | object,
    u: object | None,
    sample_time: float | None,
    input: str | None,
    output: str | None,
    n_poles: int,
    n_params: int,
    delay: object,
    max_delay: object,
    orders: str,
) -> tuple[SisoData, float | None, float]:
    d = siso_data(data, u, sample_time=sample_time, input=input, output=output)
    fixed, longest = _check_delays(d, delay, max_delay)
    start = int(np.ceil(longest / d.sample_time)) + n_poles + 1
    need = start + _SAMPLES_PER_PARAMETER * n_params
    if len(d) < need:
        raise InputError(
            f"{orders} ({n_params} parameters, delays up to {longest:g} s) need at least {need} samples "
            f"({_SAMPLES_PER_PARAMETER} per parameter after the longest delay); the data have {len(d)}"
        )
    check_excitation(d.u, n_poles + 1)
    return d, fixed, longest


def _fit_tf(d: SisoData, n_poles: int, n_zeros: int, fixed: float | None, longest: float) -> np.ndarray:
    """``[a0 .. a(np-1), b0 .. b(nz), tau]`` of the output-error optimum."""
    den0, best = _start(d, n_poles, fixed, longest)
    count = n_zeros + 1
    tau0 = fixed if fixed is not None else _delay_grid(d, den0, best, longest, count)
    lower = np.concatenate([np.full(n_poles, -np.inf), [tau0 if fixed is not None else 0.0]])
    upper = np.concatenate([np.full(n_poles, np.inf), [tau0 if fixed is not None else longest]])
    x = _refine(d, lambda a: np.concatenate([[1.0], a]), np.concatenate([den0[1:], [tau0]]), lower, upper, count)
    den = np.concatenate([[1.0], x[:-1]])
    beta = _simulation_errors(d, den, float(x[-1]), count)[1]
    return np.concatenate([den[1:][::-1], beta, [x[-1]]])


def tfest(
    data: Record | object,
    u: object | None = None,
    np: int = 2,
    nz: int = 0,
    *,
    sample_time: float | None = None,
    delay: float | None = None,
    max_delay: float | None = None,
    input: str | None = None,
    output: str | None = None,
) -> ContinuousModel:
    """Continuous-time transfer function with an input delay from sampled data (MATLAB ``tfest``).

    The output-error fit of the model's exact zero-order-hold discretisation (module docstring).

    Parameters
    ----------
    data : Record, Dataset or array_like
        A Record (deviations), a Dataset of one experiment, or the output ``y`` (shape ``(N,)``, output unit).
    u : array_like, optional
        Input with an array ``y`` (shape ``(N,)``, input unit, e.g. V), held over each sample.
    np : int
        Poles, 1 to 8 (MATLAB's name).
    nz : int
        Zeros, ``0 <= nz < np`` (strictly proper).
    sample_time : float, optional
        Seconds per sample (required with arrays).
    delay : float, optional
        A known input delay (s), at most half the record; by default the delay is estimated.
    max_delay : float, optional
        Largest delay searched (s), at most half the record; default 20 samples (at most a quarter of the record).
    input, output : str, optional
        Channel names in a multi-channel Record.

    Returns
    -------
    ContinuousModel
        ``parameters`` ``a0 .. a(np-1)`` (denominator ``s^np + a(np-1) s^(np-1) + ... + a0``), ``b0 .. b(nz)``
        (numerator ``b(nz) s^nz + ... + b0``) and ``tau`` (s), with their covariance.

    Raises
    ------
    InputError
        Bad data, orders or delays out of range, too few samples, an input that is not persistently exciting.
    EstimationError
        Linearly dependent regressors of the start (an input that excites too little).

    Examples
    --------
    A first-order lag ``2 / (s + 1)`` (time constant 1 s) with a 0.3 s delay, sampled at 0.1 s:

    >>> g = control.c2d(control.tf([2.0], [1.0, 1.0]), 0.1)
    >>> u = np.repeat(np.sign(np.random.default_rng(0).standard_normal(100)), 5)
    >>> y = control.forced_response(g, U=np.concatenate([np.zeros(3), u[:-3]])).outputs
    >>> model = tfest(y, u, 1, 0, sample_time=0.1)
    >>> {k: round(v, 4) for k, v in model.parameters.items()}
    {'a0': 1.0, 'b0': 2.0, 'tau': 0.3}
    """
    return _tfest(data, u, np, nz, sample_time, delay, max_delay, input, output)


def _tfest(
    data: Record | object,
    u: object | None,
    n_poles_in: object,
    n_zeros_in: object,
    sample_time: float | None,
    delay: object,
    max_delay: object,
    input: str | None,
    output: str | None,
) -> ContinuousModel:
    n_poles = check_int("np", n_poles_in, 1, high=8)
    n_zeros = check_int("nz", n_zeros_in, 0, high=n_poles - 1)
    orders = f"np={n_poles}, nz={n_zeros}"
    n_params = n_poles + n_zeros + 1 + (delay is None)
    d, fixed, longest = _prepared(data, u, sample_time, input, output, n_poles, n_params, delay, max_delay, orders)
    params = _fit_tf(d, n_poles, n_zeros, fixed, longest)
    names = [f"a{i}" for i in range(n_poles)] + [f"b{i}" for i in range(n_zeros + 1)] + ["tau"]

    def full(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        return p[n_poles:-1][::-1], np.concatenate([[1.0], p[:n_poles][::-1]]), float(p[-1])

    return _finish(d, full, params, names, fixed is not None, "tfest", orders)


_KIND = re.compile(r"P([123])([DZIU]*)")


def _parse_kind(kind: object) -> tuple[int, bool, bool, bool, bool]:
    """Poles and the flags delay, zero, integrator, underdamped of a process kind such as ``"P2DU"``."""
    match = _KIND.fullmatch(kind) if isinstance(kind, str) else None
    letters = match.group(2) if match else ""
    poles = int(match.group(1)) if match else 0
    if match is None or len(set(letters)) != len(letters) or ("U" in letters and poles < 2):
        raise InputError(
            f"kind = {kind!r} is not a process model: 'P' with 1, 2 or 3 poles, then any of D (delay), Z (zero), "
            "I (integrator), U (underdamped pair, 2 or 3 poles), each at most once, e.g. 'P1D', 'P2DU', 'P2DIZ'"
        )
    return poles, "D" in letters, "Z" in letters, "I" in letters, "U" in letters


def _process_den(poles: int, integrator: bool, under: bool) -> Callable[[np.ndarray], np.ndarray]:
    """Monic denominator from ``[Tp.., (Tw, Zeta)]`` (s): ``prod (s + 1 / Tp) (s^2 + 2 Zeta / Tw s + 1 / Tw^2) s^I``."""

    def den(x: np.ndarray) -> np.ndarray:
        out = np.ones(1)
        n_real = poles - 2 * under
        for t in x[:n_real]:
            out = np.convolve(out, [1.0, 1.0 / t])
        if under:
            tw, zeta = x[n_real], x[n_real + 1]
            out = np.convolve(out, [1.0, 2.0 * zeta / tw, 1.0 / tw**2])
        return np.convolve(out, [1.0, 0.0]) if integrator else out

    return den


def _process_start(tf_params: np.ndarray, n_den: int, poles: int, integrator: bool, under: bool) -> np.ndarray:
    """``[Tp.., (Tw, Zeta)]`` from the poles of a transfer-function fit (the slowest pole is the integrator)."""
    roots = np.roots(np.concatenate([[1.0], tf_params[:n_den][::-1]]))
    if integrator:
        roots = np.delete(roots, int(np.argmin(np.abs(roots))))
    roots = roots[np.argsort(np.abs(roots))]
    out = []
    if under:
        pair = roots[np.argsort(-np.abs(roots.imag))][:2]  # the complex pair, else the two most oscillatory
        wn = float(np.sqrt(np.abs(pair[0] * pair[1])))
        rest = [r for r in roots if not np.any(np.isclose(r, pair))][: poles - 2]
        out = [1.0 / max(abs(r), 1e-9) for r in rest] + [1.0 / wn, float(np.clip(-np.sum(pair).real / (2 * wn), 0, 10))]
    else:
        out = [1.0 / max(abs(r), 1e-9) for r in roots[:poles]]
    return np.array(out)


def procest(
    data: Record | object,
    u: object | None = None,
    kind: str = "P2DU",
    *,
    sample_time: float | None = None,
    max_delay: float | None = None,
    input: str | None = None,
    output: str | None = None,
) -> ContinuousModel:
    """Continuous-time process model from sampled data (MATLAB ``procest``), delay estimated.

    ``G(s) = K (1 + Tz s) / ((1 + Tp1 s)(1 + Tp2 s)(1 + Tp3 s)) e^(-Td s)``, or with the underdamped pair
    ``1 + 2 Zeta Tw s + (Tw s)^2`` for two of the poles, and ``1 / s`` for an integrator; fitted by output error
    of the exact zero-order-hold discretisation (module docstring), started from :func:`tfest`.

    Parameters
    ----------
    data : Record, Dataset or array_like
        A Record (deviations), a Dataset of one experiment, or the output ``y`` (shape ``(N,)``, output unit).
    u : array_like, optional
        Input with an array ``y`` (shape ``(N,)``, input unit), held over each sample.
    kind : str
        ``"P"``, the number of poles (1 to 3), then any of ``D`` (a delay ``Td``, estimated), ``Z`` (a zero
        ``Tz``), ``I`` (an integrator), ``U`` (an underdamped pair ``Tw``, ``Zeta``; 2 or 3 poles), e.g.
        ``"P1D"``, ``"P2DU"``, ``"P1DI"``.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    max_delay : float, optional
        Largest ``Td`` searched (s), at most half the record; default 20 samples (at most a quarter of the record).
    input, output : str, optional
        Channel names in a multi-channel Record.

    Returns
    -------
    ContinuousModel
        ``parameters`` (those of the kind, in this order): ``K`` (output unit per input unit, per second with an
        integrator), ``Tp1 >= Tp2 >= Tp3`` (s), ``Tw`` (s, ``1 / Tw`` the natural frequency in rad/s), ``Zeta``,
        ``Tz`` (s), ``Td`` (s); time constants are at least ``1e-3`` sample times, ``Zeta >= 0``.

    Raises
    ------
    InputError
        An unknown kind, bad data, a ``max_delay`` out of range, too few samples, an input that does not excite.

    Examples
    --------
    >>> g = control.c2d(control.tf([2.0], [1.0, 1.0]), 0.1)
    >>> u = np.repeat(np.sign(np.random.default_rng(0).standard_normal(100)), 5)
    >>> y = control.forced_response(g, U=np.concatenate([np.zeros(3), u[:-3]])).outputs
    >>> {k: round(v, 4) for k, v in procest(y, u, "P1D", sample_time=0.1).parameters.items()}
    {'K': 2.0, 'Tp1': 1.0, 'Td': 0.3}
    """
    poles, has_delay, zero, integrator, under = _parse_kind(kind)
    n_den, count = poles + integrator, 1 + zero
    n_params = poles + count + has_delay
    d, _, longest = _prepared(
        data, u, sample_time, input, output, n_den, n_params, None if has_delay else 0.0, max_delay, str(kind)
    )
    fixed = None if has_delay else 0.0
    tf_params = _fit_tf(d, n_den, zero, fixed, longest)
    den_of = _process_den(poles, integrator, under)
    x0 = np.concatenate([_process_start(tf_params, n_den, poles, integrator, under), [tf_params[-1]]])
    shortest = _SHORTEST * d.sample_time
    lower = np.full(x0.size, shortest)
    upper = np.full(x0.size, np.inf)
    if under:
        lower[-2] = 0.0
    lower[-1], upper[-1] = (0.0, longest) if has_delay else (0.0, 0.0)
    x = _refine(d, den_of, x0, lower, upper, count)
    n_real = poles - 2 * under
    x[:n_real] = np.sort(x[:n_real])[::-1]  # the slowest first
    beta = _simulation_errors(d, den_of(x[:-1]), float(x[-1]), count)[1]
    scale = float(np.prod(x[:n_real])) * (x[n_real] ** 2 if under else 1.0)  # 1 / den(0) without the integrator
    names = ["K"] + [f"Tp{i + 1}" for i in range(n_real)] + (["Tw", "Zeta"] if under else []) + (["Tz"] if zero else [])
    params = np.concatenate([[beta[0] * scale], x[:-1], [beta[1] / beta[0]] if zero else []])
    if has_delay:
        names.append("Td")
        params = np.concatenate([params, [x[-1]]])

    def full(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        den = den_of(p[1 : 1 + poles])
        k = p[0] / (float(np.prod(p[1 : 1 + n_real])) * (p[1 + n_real] ** 2 if under else 1.0))
        num = np.array([k * p[1 + poles], k]) if zero else np.array([k])
        return num, den, float(p[-1]) if has_delay else 0.0

    return _finish(d, full, params, names, False, "procest", str(kind))
