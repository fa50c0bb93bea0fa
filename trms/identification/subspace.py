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

All inputs may be excited at once (no one-at-a-time experiments needed). The result is the
deterministic part ``(A, B, C, D)`` as a python-control ``StateSpace`` (a :class:`SubspaceModel`, which
also keeps the horizon, the singular values and the fit on the estimation data); no noise model
(Kalman gain) is estimated.
"""

from __future__ import annotations

import control
import numpy as np
import scipy.signal

from ..display import html_table
from ..errors import InputError, as_finite_array, check_in_range
from ..plant import Record
from .data import check_int
from .validation import fit_percent

__all__ = ["n4sid", "SubspaceModel", "SubspaceOrder", "subspace_singular_values"]


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


class SubspaceOrder:
    """The singular values of the subspace step and the order they suggest.

    Attributes
    ----------
    singular_values : numpy.ndarray
        Singular values of ``L32`` (descending).
    noise_floor : float
        Median of the singular values beyond ``max_order`` (what noise alone produces), at
        least ``1e-9`` times the largest (round-off, for noise-free data).
    order : int
        The number of singular values (at most ``max_order``) above ``3`` times the noise
        floor; when fewer than 3 singular values lie beyond ``max_order`` (a short horizon),
        the order with the largest drop ``s[n - 1] / s[n]``.
    """

    def __init__(self, singular_values: np.ndarray, max_order: int) -> None:
        s = np.asarray(singular_values, float)
        self.singular_values = s
        top = min(max_order, s.size - 1)
        tail = s[top:]
        if tail.size >= _MIN_TAIL:
            self.noise_floor = max(float(np.median(tail)), _ROUND_OFF * float(s[0]))
            self.order = max(1, int(np.sum(s[:top] > _ABOVE_FLOOR * self.noise_floor)))
        else:
            self.noise_floor = float("nan")
            self.order = int(np.argmax(np.log(s[:top] / np.maximum(s[1 : top + 1], 1e-300))) + 1)


def _l32(y: np.ndarray, u: np.ndarray, horizon: int) -> np.ndarray:
    n, p = y.shape
    m = u.shape[1]
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
    low = r.T
    a, b = horizon * m, horizon * (2 * m + p)
    return low[b:, a:b]


def _check(y: np.ndarray, u: np.ndarray, horizon: int | None, max_order: int) -> int:
    n, p = y.shape
    m = u.shape[1]
    i = check_int("horizon", horizon, 1, unit=" samples") if horizon is not None else max(10, (2 * max_order) // p + 1)
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
        As for :func:`n4sid`.

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
    i = _check(y, ua, horizon, max_order)
    return SubspaceOrder(np.linalg.svd(_l32(y, ua, i), compute_uv=False), max_order)


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
    g = np.stack([scipy.signal.lfilter([0.0, 1.0], [1.0, -lv], u.astype(complex), axis=0) for lv in lam], axis=2)
    forced = np.einsum("pl,tjl,lr->tpjr", cv, g, vinv).real.reshape(n_t, p, m * n)
    direct = np.einsum("tj,pq->tpjq", u, np.eye(p)).reshape(n_t, p, p * m)
    phi = np.concatenate([obs, forced, direct], axis=2).reshape(n_t * p, -1)
    scale = np.linalg.norm(phi, axis=0)
    scale[scale == 0] = 1.0
    theta = np.linalg.lstsq(phi / scale, y.reshape(-1), rcond=None)[0] / scale
    x0 = theta[:n]
    b = theta[n : n + n * m].reshape(m, n).T
    d = theta[n + n * m :].reshape(m, p).T
    return b, d, x0, (phi @ theta).reshape(n_t, p)


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
    """

    horizon: int
    n_samples: int
    singular_values: np.ndarray
    fit: np.ndarray

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
            ("estimation samples", str(self.n_samples)),
            ("singular-value drop at the order", gap),
            ("largest pole radius |z|", f"{radius:.4g}"),
            ("estimation fit (%)", ", ".join(f"{f:.1f}" for f in self.fit)),
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
) -> SubspaceModel:
    """Discrete state-space model by subspace identification (PO-MOESP), MATLAB's ``n4sid``.

    Parameters
    ----------
    data : Record or array_like
        A Record (deviations of all its inputs and outputs are used) or the outputs ``y``,
        shape ``(N,)`` or ``(N, p)`` (output units).
    u : array_like, optional
        Inputs with an array ``y``, shape ``(N,)`` or ``(N, m)`` (input units, e.g. V); all
        inputs may be excited at the same time.
    order : int, optional
        State dimension; by default the number of singular values above the noise floor
        (:class:`SubspaceOrder`, :func:`subspace_singular_values`), at most ``max_order``.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    horizon : int, optional
        Block rows ``i`` of the past and future Hankel matrices (samples); default
        ``max(10, 2 max_order / p + 1)`` (so that the noise floor is seen). ``horizon * p``
        must exceed the order.
    max_order : int
        Largest order considered by the automatic choice.

    Returns
    -------
    SubspaceModel
        A :class:`control.StateSpace`: ``x(t+1) = A x(t) + B u(t)``, ``y(t) = C x(t) + D u(t)`` with
        ``dt = sample_time``; also its horizon, singular values and estimation fit.

    Raises
    ------
    InputError
        Bad data, too few samples for the horizon, a constant input, an order the horizon
        cannot reveal.

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> u = np.sign(np.random.default_rng(0).standard_normal(1000))
    >>> y = scipy.signal.lfilter([0, 1.0], [1, -1.5, 0.7], u)
    >>> sys = n4sid(y, u, sample_time=0.1)
    >>> sys.nstates, bool(np.allclose(np.sort(np.abs(sys.poles())), np.sqrt(0.7)))
    (2, True)
    """
    y, ua, ts = _arrays(data, u, sample_time)
    max_order = check_int("max_order", max_order, 1)
    if order is not None:
        max_order = max(max_order, check_int("order", order, 1))
    i = _check(y, ua, horizon, max_order)
    p = y.shape[1]
    left, sv, _ = np.linalg.svd(_l32(y, ua, i), full_matrices=False)
    n = SubspaceOrder(sv, max_order).order if order is None else int(order)
    gamma = left[:, :n] * np.sqrt(sv[:n])
    c = gamma[:p]
    a = np.linalg.lstsq(gamma[:-p], gamma[p:], rcond=None)[0]
    b, d, _x0, fitted = _b_d_x0(a, c, y, ua)
    model = SubspaceModel(a, b, c, d, ts)
    model.horizon, model.n_samples, model.singular_values = i, int(y.shape[0]), sv
    model.fit = np.array([_fit_or_nan(y[:, j], fitted[:, j]) for j in range(p)])
    return model
