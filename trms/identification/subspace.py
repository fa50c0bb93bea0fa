"""Subspace identification of a discrete state-space model (MATLAB ``n4sid``), MIMO.

The algorithm is PO-MOESP (Verhaegen 1994), one of the N4SID family:

1. block Hankel matrices of ``i`` past and ``i`` future samples of the inputs and outputs,
   ``U_p, U_f, Y_p, Y_f``; the past ``W_p = [U_p; Y_p]`` is the instrument;
2. one LQ factorisation of ``[U_f; W_p; Y_f]``; the block ``L32`` is the part of the future
   outputs explained by the past once the future inputs are projected out, and its column
   space is that of the extended observability matrix ``Gamma_i`` (process and measurement
   noise uncorrelated with the past do not bias it);
3. the SVD of ``L32``: the singular values reveal the order (the number of
   singular values that stand above the noise floor, when ``order`` is None; see
   :class:`SubspaceOrder`), the leading left singular vectors
   give ``Gamma_i``, whence ``C`` (first block row) and ``A`` (shift invariance, least
   squares);
4. ``B``, ``D`` and the initial state by linear least squares on the measured outputs
   (``y(t) = C A^t x0 + sum C A^(t-1-k) B u(k) + D u(t)`` is linear in them).

5. the noise model: the state sequence ``X_i = Gamma_i^+ O_i`` from the oblique projection
   ``O_i = L32 L22^+ W_p`` of the future outputs on the past along the future inputs; the
   residuals of the state and output equations ``[X_(t+1); y(t)] = [A B; C D] [X_t; u(t)] + [w; v]``
   give the covariances ``Q, S, R``, and the discrete Riccati equation gives the steady-state
   Kalman gain ``K`` and the innovation covariance (the innovations form
   ``x(t+1) = A x + B u + K e``, ``y = C x + D u + e``).

6. the refinement (default): the subspace model is the start of a prediction-error fit of ``A, B, C, D`` and the
   initial state with ``K = 0`` (the simulation error; :mod:`trms.identification.ss_predictor`), then of ``K``
   with that plant held. The subspace estimate is consistent, not efficient: under coloured output noise its
   lightly damped modes' damping can be off by more than 100 % where the refined model's is within about 10 %
   (``benchmarks/bench_identification_mc.py``). The weighting of step 3 may also be canonical variate analysis
   (CVA), which weights the rows of ``L32`` by the inverse square root of the future outputs' covariance.

All inputs may be excited at once (no one-at-a-time experiments needed). The result is a
python-control ``StateSpace`` (a :class:`SubspaceModel`, which also keeps the horizon, the
singular values, the fit on the estimation data, the Kalman gain and the innovation covariance).

The default horizon adapts to the slowest mode (:func:`n4sid`); the order may be 0 (a static
gain, ``y = D u + e``); a model with a pole outside the unit circle is returned with an
:class:`UnstableModelWarning` that names the pole.
"""

from __future__ import annotations

import math
import warnings

import control
import numpy as np
import scipy.linalg
import scipy.signal

from trms.display import html_table
from trms.errors import InputError, as_finite_array, check_choice, check_in_range, check_int
from trms.identification.ss_predictor import _predictor_output, _refine_simulation
from trms.identification.validation import fit_percent
from trms.record import Record

__all__ = ["n4sid", "SubspaceModel", "SubspaceOrder", "UnstableModelWarning", "subspace_singular_values"]


class UnstableModelWarning(UserWarning):
    """The identified model has a pole outside the unit circle (the message names it)."""


def _arrays(data: Record | object, u: object | None, sample_time: float | None) -> tuple[np.ndarray, np.ndarray, float]:
    if isinstance(data, Record):
        if u is not None:
            raise InputError("pass either a Record or the arrays y and u, not both")
        du, dy = data.deviations()
        ts = data.sample_time
        if sample_time is not None and not np.isclose(float(sample_time), ts):
            raise InputError(f"sample_time = {sample_time!r} s differs from the record's {ts} s")
        return np.asarray(dy, float), np.asarray(du, float), ts
    if u is None:
        raise InputError("with an output array y, the input array u is required")
    if sample_time is None:
        raise InputError("sample_time (s) is required when y and u are arrays")
    ya, ua = as_finite_array("y", data), as_finite_array("u", u)
    ya = ya[:, None] if ya.ndim == 1 else ya
    ua = ua[:, None] if ua.ndim == 1 else ua
    if ya.ndim != 2 or ua.ndim != 2 or ya.shape[0] != ua.shape[0]:
        raise InputError(f"y and u must be (N,) or (N, channels) with the same N, got shapes {ya.shape} and {ua.shape}")
    ts = check_in_range("sample_time", sample_time, 0.0, np.inf, unit=" s", low_open=True)
    return ya, ua, ts


def _hankel(x: np.ndarray, first: int, rows: int, cols: int) -> np.ndarray:
    """Block Hankel matrix: block row ``k`` holds ``x[first + k : first + k + cols].T``."""
    return np.vstack([x[first + k : first + k + cols].T for k in range(rows)])


#: Singular values beyond ``max_order`` needed to estimate the noise floor.
_MIN_TAIL = 3
#: Relative size of singular values that are round-off (noise-free data).
_ROUND_OFF = 1e-9
#: A singular value counts as a state when it exceeds the noise floor by this factor.
_ABOVE_FLOOR = 3.0
#: ... and the largest singular value that white noise alone gives ``L32`` by this factor.
_ABOVE_NOISE = 1.5
#: The default horizon covers this fraction of the slowest mode's period.
_PERIOD_FRACTION = 1.0 / 3.0
#: The adapted horizon keeps at least this many Hankel columns per stacked row ...
_COLUMNS_PER_ROW = 5
#: ... and at most this many block rows (samples).
_MAX_HORIZON = 100
#: The simulation refinement's most Levenberg-Marquardt iterations and tolerance per search.
_REFINE_ITER, _REFINE_TOL = 100, 1e-8
#: Refinements of the default horizon (each one a new identification) ...
_REFINEMENTS = 2
#: ... the second one only when it lengthens the horizon by more than this factor.
_REGROW = 1.25


class SubspaceOrder:
    """The singular values of the subspace step and the order they suggest.

    Parameters
    ----------
    singular_values : array_like
        Singular values of ``L32`` (descending).
    max_order : int
        Largest order considered.
    noise_bound : float
        The largest singular value that white noise alone gives ``L32`` (same units as the
        singular values); 0 to ignore it.

    Attributes
    ----------
    singular_values : numpy.ndarray
        Singular values of ``L32`` (descending).
    noise_floor : float
        Median of the singular values beyond ``max_order`` (what noise alone produces), at
        least ``1e-9`` times the largest (round-off, for noise-free data).
    noise_bound : float
        The largest singular value of a matrix of the shape of ``L32`` filled with white noise of
        the largest residual variance of a future output (a row of the ``L33`` block), times
        ``1.5``; a singular value at or below it is noise, whatever the drop before it.
    order : int
        The number of singular values (at most ``max_order``) above both ``3`` times the noise
        floor and the noise bound; when fewer than 3 singular values lie beyond ``max_order``
        (a short horizon), the order with the largest drop ``s[n - 1] / s[n]`` among those above
        the noise bound. 0 when none stands above the noise (a static gain, ``y = D u + e``).

    Examples
    --------
    >>> SubspaceOrder([5.0, 4.0, 0.1, 0.09, 0.1, 0.08], max_order=3).order
    2
    >>> SubspaceOrder([5.0, 4.0, 0.1, 0.09, 0.1, 0.08], max_order=3, noise_bound=6.0).order
    0
    """

    def __init__(self, singular_values: object, max_order: int, noise_bound: float = 0.0) -> None:
        s = np.asarray(singular_values, float)
        self.singular_values = s
        self.noise_bound = float(noise_bound)
        top = min(max_order, s.size - 1)
        tail = s[top:]
        signal = int(np.sum(s[:top] > self.noise_bound))
        if tail.size >= _MIN_TAIL:
            self.noise_floor = max(float(np.median(tail)), _ROUND_OFF * float(s[0]))
            self.order = min(signal, int(np.sum(s[:top] > _ABOVE_FLOOR * self.noise_floor)))
        else:
            self.noise_floor = float("nan")
            drop = np.log(s[:signal] / np.maximum(s[1 : signal + 1], 1e-300))
            self.order = int(np.argmax(drop)) + 1 if signal else 0


def _default_horizon(max_order: int, p: int) -> int:
    return max(10, (2 * max_order) // p + 1)


def _lq(y: np.ndarray, u: np.ndarray, horizon: int) -> np.ndarray:
    """Lower factor ``L`` of the LQ factorisation of ``[U_f; U_p; Y_p; Y_f] / sqrt(columns)``."""
    n = y.shape[0]
    cols = n - 2 * horizon + 1
    stack = np.vstack(
        [
            _hankel(u, horizon, horizon, cols),
            _hankel(u, 0, horizon, cols),
            _hankel(y, 0, horizon, cols),
            _hankel(y, horizon, horizon, cols),
        ]
    )
    # numpy's stubs type every mode as returning QRResult; mode="r" returns the array R alone.
    r: np.ndarray = np.linalg.qr(stack.T / np.sqrt(cols), mode="r")  # type: ignore[assignment]
    return r.T


class _Step:
    """The subspace step at one horizon: ``L``, the SVD of ``L32``, the order and ``A``, ``C``."""

    def __init__(
        self, y: np.ndarray, u: np.ndarray, horizon: int, order: int | None, max_order: int, weighting: str = "moesp"
    ) -> None:
        n_t, p = y.shape
        m = u.shape[1]
        self.horizon = i = horizon
        self.low = low = _lq(y, u, i)
        a, b = i * m, i * (2 * m + p)
        self.left, self.sv, self.right = np.linalg.svd(low[b:, a:b], full_matrices=False)
        self.order_sv = self.sv  # the order is read from the MOESP singular values whatever the weighting
        # white noise of the largest residual variance of a row of Y_f (a row of L33, corrected for the
        # b regressors it was fitted on) spread over an (i p) x (i (m + p)) block
        cols = n_t - 2 * i + 1
        sigma = np.sqrt(np.max(np.sum(low[b:, b:] ** 2, axis=1)) * cols / (cols - b))
        bound = _ABOVE_NOISE * sigma * (np.sqrt(i * p) + np.sqrt(i * (m + p))) / np.sqrt(cols)
        self.choice = SubspaceOrder(self.sv, max_order, bound)
        self.n = n = self.choice.order if order is None else order
        scale = np.eye(i * p)
        if weighting == "cva":  # W1 = (Y_f Pi_Uf^perp Y_f')^(-1/2): the SVD of W1 L32 holds the canonical correlations
            vals, vecs = np.linalg.eigh(low[b:, a:b] @ low[b:, a:b].T + low[b:, b:] @ low[b:, b:].T)
            vals = np.maximum(vals, _ROUND_OFF * vals[-1])
            scale = (vecs * np.sqrt(vals)) @ vecs.T
            weighted = (vecs / np.sqrt(vals)) @ vecs.T @ low[b:, a:b]
            self.left, self.sv, self.right = np.linalg.svd(weighted, full_matrices=False)
        gamma = scale @ self.left[:, :n] * np.sqrt(self.sv[:n])
        self.c = gamma[:p]
        self.a = np.linalg.lstsq(gamma[:-p], gamma[p:], rcond=None)[0]

    def slowest_period(self) -> float:
        """Period (samples) ``2 pi / |ln z|`` of the slowest pole ``z`` of ``A``; inf without a pole."""
        lam = np.linalg.eigvals(self.a).astype(complex)  # complex: a negative real pole has a log too
        lam = lam[lam != 0]
        return float(2 * np.pi / np.min(np.abs(np.log(lam)))) if lam.size else math.inf


def _check(y: np.ndarray, u: np.ndarray, horizon: int | None, max_order: int) -> int:
    n, p = y.shape
    m = u.shape[1]
    i = check_int("horizon", horizon, 1, unit=" samples") if horizon is not None else _default_horizon(max_order, p)
    if i * p <= max_order:
        raise InputError(
            f"horizon = {i} samples with {p} outputs reveals at most order {i * p - 1}; "
            f"raise it above {max_order // p} for orders up to {max_order}"
        )
    cols = n - 2 * i + 1
    if cols < 2 * i * (m + p):
        raise InputError(
            f"horizon = {i} samples needs at least {2 * i * (m + p) + 2 * i - 1} samples for "
            f"{m} inputs and {p} outputs; the data have {n}"
        )
    for j in range(m):
        if np.ptp(u[:, j]) == 0:
            raise InputError(f"input {j} is constant: it excites nothing")
    return i


def _identify(
    y: np.ndarray, u: np.ndarray, horizon: int | None, order: int | None, max_order: int, weighting: str = "moesp"
) -> _Step:
    """The subspace step at the given horizon, or at the default horizon adapted to the slowest mode."""
    i = _check(y, u, horizon, max_order)
    step = _Step(y, u, i, order, max_order, weighting)
    if horizon is not None:
        return step
    n_t, p = y.shape
    cap = max(i, min(_MAX_HORIZON, (n_t + 1) // (2 * _COLUMNS_PER_ROW * (u.shape[1] + p) + 2)))
    for k in range(_REFINEMENTS):
        period = step.slowest_period()
        want = min(cap, math.ceil(_PERIOD_FRACTION * period)) if math.isfinite(period) else i
        if want <= step.horizon * (1.0 if k == 0 else _REGROW):
            break
        step = _Step(y, u, want, order, max_order, weighting)
    return step


def subspace_singular_values(
    data: Record | object,
    u: object | None = None,
    *,
    sample_time: float | None = None,
    horizon: int | None = None,
    max_order: int = 10,
) -> SubspaceOrder:
    """Singular values of the PO-MOESP step and the order they suggest (MATLAB's ``n4sid`` order plot).

    Parameters
    ----------
    data, u, sample_time, horizon, max_order
        As for :func:`n4sid` (the same default horizon, adapted to the slowest mode).

    Returns
    -------
    SubspaceOrder

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> u = np.sign(np.random.default_rng(0).standard_normal(1000))
    >>> y = scipy.signal.lfilter([0, 1.0], [1, -1.5, 0.7], u)
    >>> subspace_singular_values(y, u, sample_time=0.1).order
    2
    """
    y, ua, _ = _arrays(data, u, sample_time)
    max_order = check_int("max_order", max_order, 1)
    return _identify(y, ua, horizon, None, max_order).choice


def _noise_model(
    step: _Step, y: np.ndarray, u: np.ndarray, a: np.ndarray, c: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Kalman gain ``K`` ``(n, p)`` and innovation covariance ``(p, p)`` from the subspace residuals.

    States ``X = Gamma^+ L32 L22^+ W_p = S_n^(1/2) V_n^T L22^+ W_p`` (column ``j`` is the state at
    sample ``i + j``); the residuals of ``[X_(t+1); y(t)]`` regressed on ``[X_t; u(t)]`` give
    ``Q, S, R``, and ``P`` solves the filter Riccati equation, ``K = (A P C^T + S)(C P C^T + R)^-1``.
    Where the Riccati equation has no stabilising solution, ``K = S R^+`` and ``R``.
    """
    n_t, p = y.shape
    m, n, i = u.shape[1], step.n, step.horizon
    cols = n_t - 2 * i + 1
    a0, b0 = i * m, i * (2 * m + p)
    weights = np.sqrt(step.sv[:n])[:, None] * step.right[:n]
    proj = np.linalg.lstsq(step.low[a0:b0, a0:b0].T, weights.T, rcond=1e-10)[0].T  # S^(1/2) V^T L22^+
    x = proj @ np.vstack([_hankel(u, 0, i, cols), _hankel(y, 0, i, cols)])
    now = np.vstack([x[:, :-1], u[i : i + cols - 1].T])
    after = np.vstack([x[:, 1:], y[i : i + cols - 1].T])
    rho = after - np.linalg.lstsq(now.T, after.T, rcond=None)[0].T @ now
    cov = rho @ rho.T / rho.shape[1]
    q, s, r = cov[:n, :n], cov[:n, n:], cov[n:, n:]
    if n == 0:
        return np.zeros((0, p)), r
    try:
        pp = scipy.linalg.solve_discrete_are(a.T, c.T, q, r, s=s)
        re = c @ pp @ c.T + r
        return np.linalg.solve(re.T, (a @ pp @ c.T + s).T).T, (re + re.T) / 2
    except (np.linalg.LinAlgError, ValueError):
        return s @ np.linalg.pinv(r), r


def _b_d_x0(
    a: np.ndarray, c: np.ndarray, y: np.ndarray, u: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Least squares of ``y(t) = C A^t x0 + sum_k C A^(t-1-k) B u(k) + D u(t)`` for ``x0, B, D``.

    Returns ``B``, ``D``, ``x0`` and the fitted output (the model's simulation from ``x0``), ``(N, p)``.

    With ``A = V diag(lambda) V^-1`` every regressor is a first-order recursion per eigenvalue
    (one ``lfilter`` over all inputs for each ``lambda``), so no loop runs over the samples.
    """
    n_t, p = y.shape
    m, n = u.shape[1], a.shape[0]
    lam, vec = np.linalg.eig(a)
    cv, vinv = c @ vec, np.linalg.inv(vec)
    powers = lam[None, :] ** np.arange(n_t)[:, None]  # (t, l)
    obs = np.einsum("pl,tl,lr->tpr", cv, powers, vinv).real
    if n:
        g = np.stack([scipy.signal.lfilter([0.0, 1.0], [1.0, -lv], u.astype(complex), axis=0) for lv in lam], axis=2)
        forced = np.einsum("pl,tjl,lr->tpjr", cv, g, vinv).real.reshape(n_t, p, m * n)
    else:  # a static gain
        forced = np.zeros((n_t, p, 0))
    direct = np.einsum("tj,pq->tpjq", u, np.eye(p)).reshape(n_t, p, p * m)
    phi = np.concatenate([obs, forced, direct], axis=2).reshape(n_t * p, -1)
    scale = np.linalg.norm(phi, axis=0)
    scale[scale == 0] = 1.0
    theta = np.linalg.lstsq(phi / scale, y.reshape(-1), rcond=None)[0] / scale
    x0 = theta[:n]
    b = theta[n : n + n * m].reshape(m, n).T
    d = theta[n + n * m :].reshape(m, p).T
    return b, d, x0, (phi @ theta).reshape(n_t, p)


def _simulate(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray, x0: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The model's output ``(N, p)`` simulated from ``x0`` (the predictor with ``K = 0``)."""
    p = c.shape[0]
    return _predictor_output(a, b, c, d, np.zeros((a.shape[0], p)), np.zeros((u.shape[0], p)), u, x0)


class SubspaceModel(control.StateSpace):
    """The discrete state-space model :func:`n4sid` returns: a :class:`control.StateSpace` that also keeps
    how it was identified, shown compactly (no matrices) by ``repr`` and in notebooks.

    Attributes
    ----------
    horizon : int
        Block rows of the past and future Hankel matrices (samples).
    n_samples : int
        Samples of the estimation data.
    singular_values : numpy.ndarray
        Singular values of ``L32`` (descending) that the order was read from.
    fit : numpy.ndarray
        Fit (%, :func:`~trms.identification.fit_percent`) of each output on the estimation data, the model
        simulated from its estimated initial state.
    kalman_gain : numpy.ndarray
        Steady-state Kalman gain ``K``, shape ``(states, outputs)`` (state units per output unit), of the
        innovations form ``x(t+1) = A x(t) + B u(t) + K e(t)``, ``y(t) = C x(t) + D u(t) + e(t)``.
    innovation_covariance : numpy.ndarray
        Covariance of the innovations ``e``, shape ``(outputs, outputs)`` (output units squared).
    info : dict
        ``weighting``, ``refined`` (whether the simulation refinement was kept) and, when it was,
        ``subspace_simulation_loss`` and ``simulation_loss`` (``det`` of the simulation-error covariance before and
        after), ``passes`` and ``evaluations``.
    """

    horizon: int
    n_samples: int
    singular_values: np.ndarray
    fit: np.ndarray
    kalman_gain: np.ndarray
    innovation_covariance: np.ndarray
    info: dict

    def _summary(self) -> list[tuple[str, str]]:
        sv = self.singular_values
        n = self.nstates
        gap = f"{sv[n - 1] / sv[n]:.3g}" if 0 < n < sv.size and sv[n] > 0 else "-"
        radius = float(np.max(np.abs(self.poles()), initial=0.0))
        return [
            ("order (states)", str(n)),
            ("inputs, outputs", f"{self.ninputs}, {self.noutputs}"),
            ("sample time (s)", f"{self.dt:g}"),
            ("horizon (samples)", str(self.horizon)),
            (
                "weighting, simulation refinement",
                f"{self.info['weighting']}, {'kept' if self.info['refined'] else 'none'}",
            ),
            ("estimation samples", str(self.n_samples)),
            ("singular-value drop at the order", gap),
            ("largest pole radius |z|", f"{radius:.4g}"),
            ("estimation fit (%)", ", ".join(f"{f:.1f}" for f in self.fit)),
            ("innovation std", ", ".join(f"{s:.3g}" for s in np.sqrt(np.diag(self.innovation_covariance)))),
        ]

    def __repr__(self) -> str:
        fit = ", ".join(f"{f:.1f}" for f in self.fit)
        return (
            f"SubspaceModel(order {self.nstates}, {self.ninputs} in, {self.noutputs} out, Ts={self.dt:g} s, "
            f"horizon {self.horizon}, N={self.n_samples}, estimation fit {fit} %)"
        )

    def _repr_html_(self) -> str:
        return html_table("SubspaceModel (n4sid)", self._summary())


def _fit_or_nan(y: np.ndarray, yhat: np.ndarray) -> float:
    try:
        return fit_percent(y, yhat)
    except InputError:  # a constant output: the fit is undefined
        return float("nan")


def n4sid(
    data: Record | object,
    u: object | None = None,
    order: int | None = None,
    *,
    sample_time: float | None = None,
    horizon: int | None = None,
    max_order: int = 10,
    weighting: str = "moesp",
    refine: str = "simulation",
) -> SubspaceModel:
    """Discrete state-space model by subspace identification (PO-MOESP), MATLAB's ``n4sid``, refined by the
    simulation error.

    Parameters
    ----------
    data : Record or array_like
        A Record (deviations of all its inputs and outputs are used) or the outputs ``y``,
        shape ``(N,)`` or ``(N, p)`` (output units).
    u : array_like, optional
        Inputs with an array ``y``, shape ``(N,)`` or ``(N, m)`` (input units, e.g. V); all
        inputs may be excited at the same time.
    order : int, optional
        State dimension, 0 for a static gain ``y = D u + e``; by default the number of singular
        values above the noise (:class:`SubspaceOrder`, :func:`subspace_singular_values`), at
        most ``max_order``.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    horizon : int, optional
        Block rows ``i`` of the past and future Hankel matrices (samples). By default it adapts
        to the slowest mode: it starts at ``i0 = max(10, 2 max_order / p + 1)`` samples (so that
        the noise floor is seen); a model identified at ``i0`` gives the period of its slowest
        pole ``z``, ``T = 2 pi / |ln z|`` samples (``2 pi`` time constants for a real pole), and
        the horizon becomes ``ceil(T / 3)`` samples (a third of that period) when this exceeds
        ``i0``, repeated once more on the new model when this lengthens the horizon by more than
        a quarter; it never exceeds 100 samples nor the
        horizon for which the Hankel matrices have 5 columns per row,
        ``(N + 1) // (10 (m + p) + 2)``, nor falls below ``i0``. For a mode slower than 300
        samples per period, decimate the data. ``horizon * p`` must exceed the order.
    max_order : int
        Largest order considered by the automatic choice.
    weighting : {"moesp", "cva"}
        The row weighting of the subspace step (module docstring): MOESP (the SVD of ``L32``) or canonical
        variate analysis (``L32`` weighted by ``(Y_f Pi_Uf^perp Y_f')^(-1/2)``). The order is read from the MOESP
        singular values either way.
    refine : {"simulation", "none"}
        ``"simulation"`` (default): the subspace model's ``A, B, C, D`` and initial state refined by the
        prediction-error method with ``K = 0`` (the simulation error, an output-error fit, unbiased under any
        output disturbance independent of the input), then its Kalman gain fitted by the one-step prediction
        errors with that plant held; kept only where it lowers the simulation error (a stable subspace model
        only). The default is chosen by ``benchmarks/bench_identification_mc.py``: on two lightly damped
        modes (0.1 and 0.34 Hz) under AR(1) output noise it brings the 0.1 Hz mode's median damping error from
        above 100 % (either weighting) to about 10 %. ``"none"``: the subspace model.

    Returns
    -------
    SubspaceModel
        A :class:`control.StateSpace`: ``x(t+1) = A x(t) + B u(t)``, ``y(t) = C x(t) + D u(t)`` with
        ``dt = sample_time``; also its horizon, singular values, estimation fit, and the noise model
        (``kalman_gain`` ``K`` and ``innovation_covariance`` of the innovations form
        ``x(t+1) = A x + B u + K e``, ``y = C x + D u + e``).

    Raises
    ------
    InputError
        Bad data, too few samples for the horizon, a constant input, an order the horizon
        cannot reveal.

    Warns
    -----
    UnstableModelWarning
        The model has a pole outside the unit circle (named in the message, with its radius).

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> u = np.sign(np.random.default_rng(0).standard_normal(1000))
    >>> y = scipy.signal.lfilter([0, 1.0], [1, -1.5, 0.7], u)
    >>> sys = n4sid(y, u, sample_time=0.1)
    >>> sys.nstates, bool(np.allclose(np.sort(np.abs(sys.poles())), np.sqrt(0.7)))
    (2, True)

    A static gain with white output noise has order 0:

    >>> e = 0.1 * np.random.default_rng(1).standard_normal(1000)
    >>> static = n4sid(2.0 * u + e, u, sample_time=0.1)
    >>> static.nstates, round(float(static.D[0, 0]), 2), round(float(static.innovation_covariance[0, 0]), 3)
    (0, 2.0, 0.01)
    """
    y, ua, ts = _arrays(data, u, sample_time)
    max_order = check_int("max_order", max_order, 1)
    weighting = check_choice("weighting", weighting, ("moesp", "cva"), error=InputError)
    refine = check_choice("refine", refine, ("simulation", "none"), error=InputError)
    if order is not None:
        max_order = max(max_order, check_int("order", order, 0))
    step = _identify(y, ua, horizon, order, max_order, weighting)
    p = y.shape[1]
    a, c = step.a, step.c
    b, d, x0, fitted = _b_d_x0(a, c, y, ua)
    k, innovations = _noise_model(step, y, ua, a, c)
    info: dict[str, object] = {"weighting": weighting, "refined": False}
    refined = _refine_simulation(a, b, c, d, x0, y, ua, _REFINE_ITER, _REFINE_TOL) if refine == "simulation" else None
    if refined is not None:
        (a, b, c, d, x0), k, innovations, found = refined
        fitted = _simulate(a, b, c, d, x0, ua)
        info.update(refined=True, **found)
    model = SubspaceModel(a, b, c, d, ts)
    model.horizon, model.n_samples, model.singular_values = step.horizon, int(y.shape[0]), step.order_sv
    model.fit = np.array([_fit_or_nan(y[:, j], fitted[:, j]) for j in range(p)])
    model.kalman_gain, model.innovation_covariance, model.info = k, innovations, info
    poles = np.linalg.eigvals(a)
    if poles.size and np.max(np.abs(poles)) > 1.0:
        worst = poles[np.argmax(np.abs(poles))]
        warnings.warn(
            f"n4sid: the model has a pole at z = {worst:.4g} (|z| = {abs(worst):.4f}) outside the unit circle "
            f"(order {step.n}, horizon {step.horizon} samples); lower the order or lengthen the horizon",
            UnstableModelWarning,
            stacklevel=2,
        )
    return model
