"""Confidence intervals of a least-squares fit whose residuals are correlated in time.

``mujoco.sysid.calculate_intervals`` gives ``s^2 (J'J)^-1``: right when the residuals are
white. A twin driven by gusts is not: its output error follows the gusts through the
rig's dynamics, correlated over seconds, and the white intervals are far too narrow.

The sandwich (heteroscedasticity- and autocorrelation-consistent, Newey & West 1987)
covariance keeps the fit's Jacobian ``J`` and replaces ``s^2 J'J`` by the long-run
covariance of the score ``g_t = sum_j J_tj r_tj`` (one score a sample, summed over the
outputs, so their correlation is kept):

    cov = (J'J)^-1 Omega (J'J)^-1,   Omega = sum_records [G_0 + sum_{l=1..L} (1 - l/(L+1)) (G_l + G_l')],

``G_l = sum_t g_t g_{t-l}'`` within one record (records are independent: no cross terms).

The bandwidth is the whole record, ``L = T - 1`` (``b = L / T -> 1``: Kiefer, Vogelsang &
Bunzel 2000), with the fixed-``b`` critical value of Kiefer & Vogelsang (2005) for the
Bartlett kernel (:func:`fixed_b_critical_value`, 4.81 at ``b = 1``), which accounts for a
long-run covariance estimated from few effectively independent stretches. A rig's output
error is not a simple decay: ambient turbulence rings the lightly damped pitch and yaw
modes, on top of white encoder noise. Andrews' (1991) AR(1) plug-in bandwidth
(:func:`bartlett_bandwidth`, still available through ``bandwidth``) reads such scores as
nearly white -- the noise hides the ringing at lag 1 -- and picks a few dozen samples where
the correlation lasts hundreds: on a resonance plus white noise its 95 % intervals cover
60 to 80 % of the time, and on a faked rig (the shipped twin with four parameters changed,
turbulence and encoder noise on) the pitch damping fell 2 half-widths outside. ``b = 1``
needs no model of the correlation and covers 96 % there (tests/calibration/test_intervals.py).
On white errors it costs width: 1.2 times the white-noise interval for one record; with
several independent records it is on the safe side (the critical value is the one for one
record), about twice as wide.

Every estimate from the residuals alone misses what the fit absorbed. When the error is a
lightly damped mode rung by turbulence and the parameters shape that mode, that is much of
it: on the faked rig at +-0.12 V the sandwich (and a block jackknife alike) came out about half
the width that the true error process gives. :func:`disturbance_intervals` therefore
simulates the error process -- seeded draws of the model's own turbulence, rolled out through
the fitted model -- scales it to the residuals' autocovariance, and propagates it through the
fit's linearisation (the calibration reports the wider of the two).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = [
    "INTERVAL_NAME",
    "bartlett_bandwidth",
    "disturbance_intervals",
    "fixed_b_critical_value",
    "long_run_covariance",
    "record_scores",
    "sandwich_intervals",
]

#: What the calibration calls the intervals it reports (the wider of :func:`sandwich_intervals` and
#: :func:`disturbance_intervals`, parameter by parameter), in its table, ``calibration.json`` and the
#: HTML report alike.
INTERVAL_NAME = "95 % interval, sandwich or disturbance"


def record_scores(residuals: Sequence[np.ndarray], jacobian: np.ndarray, n_outputs: int) -> list[np.ndarray]:
    """Per-sample scores ``g_t = sum_j J[t, j, :] r[t, j]`` of each record.

    Parameters
    ----------
    residuals : sequence of numpy.ndarray
        One flat residual array a record, sample-major (``mujoco.sysid``'s layout:
        ``(n_samples * n_outputs,)``).
    jacobian : numpy.ndarray
        Shape ``(sum of the residuals' sizes, n_params)``, rows in the same order.
    n_outputs : int
        Outputs per sample.

    Returns
    -------
    list of numpy.ndarray
        One ``(n_samples, n_params)`` array a record.

    Examples
    --------
    >>> record_scores([np.ones(4)], np.ones((4, 1)), 2)[0].ravel()
    array([2., 2.])
    """
    jac = np.asarray(jacobian, float)
    flat = [np.asarray(r, float).ravel() for r in residuals]
    total = sum(r.size for r in flat)
    if total != jac.shape[0]:
        raise ValueError(f"the residuals have {total} entries, the Jacobian {jac.shape[0]} rows")
    out, row = [], 0
    for r in flat:
        j = jac[row : row + r.size]
        row += r.size
        out.append(np.einsum("tjp,tj->tp", j.reshape(-1, n_outputs, jac.shape[1]), r.reshape(-1, n_outputs)))
    return out


def bartlett_bandwidth(scores: Sequence[np.ndarray]) -> int:
    """Andrews' (1991, eq. 6.4) AR(1) plug-in bandwidth of the Bartlett kernel (samples).

    Each score column (standardised) is fitted an AR(1) ``rho_a`` pooled over the records;
    ``alpha = sum 4 rho^2 s^4 / ((1 - rho)^6 (1 + rho)^2) / sum s^4 / (1 - rho)^4`` with
    ``s^2 = 1 - rho^2`` the innovation variance, and ``L = 1.1447 (alpha T)^(1/3)``, ``T``
    the samples of the longest record, capped at ``T - 1``.

    Parameters
    ----------
    scores : sequence of numpy.ndarray
        ``(n_samples, n_params)`` per record (:func:`record_scores`).

    Returns
    -------
    int

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> bartlett_bandwidth([rng.standard_normal((1000, 2))]) <= 3
    True
    """
    num = den = 0.0
    t_max = max(len(g) for g in scores)
    for a in range(scores[0].shape[1]):
        cols = [g[:, a] - g[:, a].mean() for g in scores]
        sxx = sum(float(c[:-1] @ c[:-1]) for c in cols)
        if sxx <= 0:
            continue
        rho = float(np.clip(sum(float(c[1:] @ c[:-1]) for c in cols) / sxx, -0.999, 0.999))
        s4 = (1.0 - rho**2) ** 2
        num += 4.0 * rho**2 * s4 / ((1.0 - rho) ** 6 * (1.0 + rho) ** 2)
        den += s4 / (1.0 - rho) ** 4
    alpha = num / den if den > 0 else 0.0
    return int(min(max(np.ceil(1.1447 * (alpha * t_max) ** (1.0 / 3.0)), 0), t_max - 1))


def long_run_covariance(scores: Sequence[np.ndarray], bandwidth: int) -> np.ndarray:
    """Bartlett-weighted long-run covariance of the scores, summed over independent records.

    The lagged products of every lag come from one FFT a record (zero-padded: no wrap-around),
    so a bandwidth of the whole record costs no more than a short one.

    Parameters
    ----------
    scores : sequence of numpy.ndarray
        ``(n_samples, n_params)`` per record.
    bandwidth : int
        Bartlett bandwidth ``L`` (samples; 0 is the white-noise ``sum g g'``).

    Returns
    -------
    numpy.ndarray
        ``(n_params, n_params)``, symmetric positive semi-definite.

    Examples
    --------
    >>> g = np.array([[1.0], [1.0], [-1.0]])
    >>> long_run_covariance([g], 0), long_run_covariance([g], 1)
    (array([[3.]]), array([[3.]]))
    """
    p = scores[0].shape[1]
    omega = np.zeros((p, p))
    for g in scores:
        g = np.asarray(g, float)
        n = len(g)
        top = min(int(bandwidth), n - 1)
        if top < 1:
            omega += g.T @ g
            continue
        nfft = 1 << int(np.ceil(np.log2(2 * n)))
        spec = np.fft.rfft(g, n=nfft, axis=0)
        # corr[l, a, b] = sum_t g[t + l, a] g[t, b]: lag l >= 0 at index l, lag -l at nfft - l
        corr = np.fft.irfft(spec[:, :, None] * np.conj(spec[:, None, :]), n=nfft, axis=0)
        lags = np.arange(1, top + 1)
        w = 1.0 - lags / (bandwidth + 1.0)
        omega += corr[0] + np.einsum("l,lab->ab", w, corr[lags] + corr[nfft - lags])
    return 0.5 * (omega + omega.T)


def fixed_b_critical_value(b: float) -> float:
    """Two-sided 95 % critical value of a Bartlett-kernel t statistic at bandwidth ratio ``b = L / T``.

    Kiefer & Vogelsang (2005), their cubic fit for the Bartlett kernel:
    ``1.96 + 2.9694 b + 0.4160 b^2 - 0.5324 b^3``, ``b`` in ``[0, 1]``.

    Examples
    --------
    >>> fixed_b_critical_value(0.0), round(fixed_b_critical_value(1.0), 3)
    (1.96, 4.813)
    """
    b = float(np.clip(b, 0.0, 1.0))
    return 1.96 + 2.9694 * b + 0.4160 * b**2 - 0.5324 * b**3


def sandwich_intervals(
    residuals: Sequence[np.ndarray],
    jacobian: np.ndarray,
    inverse_hessian: np.ndarray,
    n_outputs: int,
    *,
    bandwidth: int | None = None,
) -> tuple[np.ndarray, np.ndarray, int]:
    """Half-widths of the 95 % intervals from the sandwich covariance and the fixed-``b`` critical value.

    Parameters
    ----------
    residuals : sequence of numpy.ndarray
        Residuals at the optimum, one flat array a record (sample-major).
    jacobian : numpy.ndarray
        Jacobian at the optimum, rows as the concatenated residuals.
    inverse_hessian : numpy.ndarray
        ``(J'J)^-1`` (a pseudo-inverse where ``J'J`` is singular).
    n_outputs : int
        Outputs per sample.
    bandwidth : int, optional
        Bartlett bandwidth (samples); default the longest record's length less one
        (``b = 1``; :func:`bartlett_bandwidth` gives Andrews' plug-in instead).

    Returns
    -------
    half : numpy.ndarray
        Half-widths (units of the parameters).
    cov : numpy.ndarray
        The sandwich covariance.
    bandwidth : int
        The bandwidth used.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> x = rng.standard_normal((500, 1))
    >>> r = rng.standard_normal(500)
    >>> half, _, lag = sandwich_intervals([r], x, np.linalg.inv(x.T @ x), 1)
    >>> bool(0.05 < half[0] < 0.2), lag
    (True, 499)
    """
    scores = record_scores(residuals, jacobian, n_outputs)
    lag = max(len(g) for g in scores) - 1 if bandwidth is None else int(bandwidth)
    omega = long_run_covariance(scores, lag)
    inv_h = np.asarray(inverse_hessian, float)
    cov = inv_h @ omega @ inv_h
    crit = fixed_b_critical_value(lag / max(len(g) for g in scores))
    return crit * np.sqrt(np.clip(np.diag(cov), 0.0, None)), cov, lag


def _lag_power(residuals: Sequence[np.ndarray], n_outputs: int, lags: int) -> float:
    """Sum over records and outputs of the residuals' autocovariance (sum of lagged products) at lags 1..``lags``."""
    total = 0.0
    for r in residuals:
        y = np.asarray(r, float).reshape(-1, n_outputs)
        top = min(int(lags), len(y) - 1)
        total += sum(float(np.sum(y[k:] * y[:-k])) for k in range(1, top + 1))
    return total


def disturbance_intervals(
    residuals: Sequence[np.ndarray],
    jacobian: np.ndarray,
    disturbed: np.ndarray,
    n_outputs: int,
    lags: int,
) -> tuple[np.ndarray, np.ndarray, float]:
    """Half-widths of the 95 % intervals from simulated disturbance responses, scaled to the residuals.

    A fit's residuals are what its parameters could not absorb. When the output error is a
    lightly damped mode rung by turbulence, the parameters that shape that mode absorb much of
    it: the residuals, and every interval estimated from them alone (white, sandwich or
    jackknife), then understate the estimate's scatter severalfold. Here the error process is
    simulated instead: ``disturbed[m]`` is the change of the residual when the fitted model is
    driven, on the same records, by the ``m``-th seeded draw of its own disturbance model. The
    fit's linearised response to it is ``(J'J)^-1 J' e_m``; the draws are scaled by ``s^2``, the
    ratio of the residuals' autocovariance at lags 1..``lags`` (white encoder noise has none) to
    that of the simulated errors after the same projection the fit applies, and the covariance
    takes ``s^2`` at its upper 95 % bound (``s^2`` over the 5 % quantile of the same ratio among
    the draws: one realisation tells the scale only so well). What the scaled draws
    leave of each output's residual variance is taken as white noise, and its covariance
    ``(J'J)^-1 J' diag(sigma^2) J (J'J)^-1`` is added.

    Parameters
    ----------
    residuals : sequence of numpy.ndarray
        Residuals at the optimum, one flat array a record (sample-major).
    jacobian : numpy.ndarray
        Jacobian at the optimum, ``(R, p)``, rows as the concatenated residuals.
    disturbed : numpy.ndarray
        ``(M, R)``: simulated disturbance responses, in the residuals' layout.
    n_outputs : int
        Outputs per sample.
    lags : int
        Lags (samples) over which the scale is matched.

    Returns
    -------
    half : numpy.ndarray
        Half-widths (units of the parameters), ``1.96`` standard deviations.
    cov : numpy.ndarray
        The covariance, ``(p, p)``.
    scale : float
        ``s^2`` (0 when the residuals show no correlated error).

    Examples
    --------
    A constant fitted to an AR(1) error: the projection removes the mean the constant absorbs.

    >>> import scipy.signal
    >>> rng = np.random.default_rng(2)
    >>> ar = lambda n: scipy.signal.lfilter([1.0], [1.0, -0.95], rng.standard_normal(n))
    >>> j = np.ones((400, 1))
    >>> e = ar(400)
    >>> r = e - e.mean()
    >>> half, _, s2 = disturbance_intervals([r], j, np.array([ar(400) for _ in range(200)]), 1, 20)
    >>> bool(0.5 < s2 < 2.0), bool(half[0] > 1.96 * r.std() / 20)
    (True, True)
    """
    jac = np.asarray(jacobian, float)
    sims = np.atleast_2d(np.asarray(disturbed, float))
    pinv = np.linalg.pinv(jac)  # (J'J)^+ J'
    deltas = sims @ pinv.T  # (M, p): the fit's linearised response to each draw
    projected = sims - deltas @ jac.T
    sizes = np.cumsum([np.asarray(r).size for r in residuals])[:-1]
    observed = _lag_power(residuals, n_outputs, lags)
    powers = np.array([_lag_power(np.split(e, sizes), n_outputs, lags) for e in projected])
    simulated = float(np.mean(powers))
    scale = max(observed / simulated, 0.0) if simulated > 0 else 0.0
    # the scale is read off one realisation: the draws' own spread of the same ratio gives its
    # sampling distribution, and the covariance takes its upper 95 % bound
    low = float(np.quantile(powers / simulated, 0.05)) if simulated > 0 else 1.0
    cov = scale / max(low, 0.05) * (deltas.T @ deltas) / len(sims)
    # the white rest (encoder noise and quantisation), output by output: what the scaled draws leave of lag 0
    flat = np.concatenate([np.asarray(r, float).ravel() for r in residuals])
    inv = np.linalg.pinv(jac.T @ jac)
    middle = np.zeros_like(inv)
    for j in range(n_outputs):
        rows = slice(j, None, n_outputs)
        white = float(flat[rows] @ flat[rows]) - scale * float(np.mean(np.sum(projected[:, rows] ** 2, axis=1)))
        middle += max(white, 0.0) / flat[rows].size * (jac[rows].T @ jac[rows])
    cov = cov + inv @ middle @ inv
    return 1.96 * np.sqrt(np.clip(np.diag(cov), 0.0, None)), cov, scale
