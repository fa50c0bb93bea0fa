"""Multi-input multi-output polynomial models: MIMO ARX by least squares, MIMO ARMAX by prediction error.

The model of ``p`` outputs and ``m`` inputs (MATLAB's multi-output ``arx`` and ``armax``) is

``A(q) y(t) = B(q) u(t) + C(q) e(t)``,

* ``A(q) = I + A_1 q^-1 + ...``, a ``p x p`` polynomial matrix whose entry ``(j, i)`` has ``na[j, i]``
  coefficients (``na[j, i] = 0`` off the diagonal: output ``j``'s equation holds no past of output ``i``);
* ``B(q)``, entry ``(j, l)`` ``q^-nk[j, l] (b_0 + b_1 q^-1 + ... )`` with ``nb[j, l]`` coefficients (every
  output's equation holds all inputs; ``nb[j, l] = 0`` leaves input ``l`` out of it);
* ``C(q) = diag(C_1(q), ..., C_p(q))``, each monic of order ``nc[j]`` (ARMAX; ARX has ``C = I``).

With ``C`` diagonal, output ``j``'s prediction error
``eps_j = (A_j(q) y - B_j(q) u) / C_j(q)`` (row ``j`` of ``A`` and ``B``) depends on that row's parameters
alone, so each output's equation is fitted on its own: ARX by least squares
(:func:`~trms.identification.linear.arx`'s column-scaled QR); ARMAX from a Hannan-Rissanen start (innovations of
a high-order MIMO ARX, then least squares on the regressors and those innovations, roots of ``C_j`` reflected
into the unit circle) by the damped Gauss-Newton search of :mod:`trms.identification.pem`, the gradient the
regressors and the lagged errors filtered by ``1 / C_j``. The joint criterion's minimiser for white noise of any
covariance is the same (each row's errors are its own); the innovation covariance ``Lambda = E^T E / N`` and
the loss ``det(Lambda)`` are reported.

A :class:`~trms.identification.dataset.Dataset` of several experiments is fitted together: regressors and
prediction errors are formed inside each experiment (the first ``start`` samples of each give no prediction).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import control
import numpy as np
import scipy.signal

from trms.errors import EstimationError, InputError, check_int
from trms.identification.data import SisoData, check_excitation, lag_matrix, record_deviations
from trms.identification.dataset import Dataset
from trms.identification.pem import MAX_ITER, check_search, covariance, max_root, minimise
from trms.identification.regression import check_sizes, solve_ls, stabilise
from trms.identification.subspace import io_arrays
from trms.identification.validation import fit_percent
from trms.record import Record

__all__ = ["MimoPolynomialModel", "arx_mimo", "armax_mimo"]


def _experiments(
    data: Record | object, u: object | None, sample_time: float | None
) -> tuple[list[tuple[np.ndarray, np.ndarray]], float, tuple[str, ...], tuple[str, ...]]:
    """``[(y (N, p), u (N, m)), ...]`` per experiment, the sample time and the channel names."""
    if isinstance(data, Dataset):
        if u is not None:
            raise InputError("pass either a Dataset or the arrays y and u, not both")
        if sample_time is not None and not np.isclose(float(sample_time), data.sample_time):
            raise InputError(f"sample_time = {sample_time!r} s differs from the dataset's {data.sample_time} s")
        exps = [(np.array(y, float), np.array(x, float)) for y, x in zip(data.outputs, data.inputs)]
        return exps, data.sample_time, data.input_names, data.output_names
    if isinstance(data, Record):
        record_deviations(data)  # refuses a record without an operating point
        y, ua, ts = io_arrays(data, u, sample_time)
        return [(y, ua)], ts, data.input_names, data.output_names
    y, ua, ts = io_arrays(data, u, sample_time)
    p, m = y.shape[1], ua.shape[1]
    names = tuple(f"u{i + 1}" for i in range(m)), tuple(f"y{j + 1}" for j in range(p))
    return [(y, ua)], ts, names[0], names[1]


def _orders(name: str, value: object, shape: tuple[int, ...], low: int) -> np.ndarray:
    """An order given as one int (every entry) or an array of ``shape``, each an int ``>= low``."""
    arr = np.asarray(value)
    if arr.ndim == 0:
        return np.full(shape, check_int(name, value, low), dtype=int)
    if arr.shape != shape:
        raise InputError(f"{name} must be an int or an array of shape {shape} (outputs x ...), got shape {arr.shape}")
    out = np.zeros(shape, dtype=int)
    for idx in np.ndindex(*shape):
        out[idx] = check_int(f"{name}[{', '.join(map(str, idx))}]", arr[idx].item(), low)
    return out


@dataclass
class _Row:
    """Output ``j``'s equation: orders and the regressors of every experiment (rows from ``start``)."""

    na: np.ndarray
    nb: np.ndarray
    nk: np.ndarray
    nc: int
    start: int
    phi: list[np.ndarray]
    target: list[np.ndarray]

    @property
    def n_ab(self) -> int:
        return int(self.na.sum() + self.nb.sum())


def _regressors(y: np.ndarray, u: np.ndarray, na: np.ndarray, nb: np.ndarray, nk: np.ndarray, start: int) -> np.ndarray:
    """``[-y_i(t-1..t-na_i) for each output i, u_l(t-nk_l .. t-nk_l-nb_l+1) for each input l]``, ``t >= start``."""
    cols = [-lag_matrix(y[:, i], range(1, na[i] + 1), start) for i in range(y.shape[1])]
    cols += [lag_matrix(u[:, i], range(nk[i], nk[i] + nb[i]), start) for i in range(u.shape[1])]
    return np.hstack(cols)


def _filter(c: np.ndarray, parts: Sequence[np.ndarray]) -> np.ndarray:
    """Each experiment's rows filtered by ``1 / c`` from rest, stacked."""
    if c.size == 1:
        return np.concatenate(list(parts))
    return np.concatenate([scipy.signal.lfilter([1.0], c, x, axis=0) for x in parts])


def _fit_row(
    row: _Row, hr: list[np.ndarray] | None, max_iter: int, tol: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(theta, eps, psi)`` of one output's equation: least squares, then (``nc > 0``) Gauss-Newton PEM."""
    phi, target = np.vstack(row.phi), np.concatenate(row.target)
    theta_ab = solve_ls(phi, target, "MIMO ARX least squares")
    if row.nc == 0:
        return theta_ab, target - phi @ theta_ab, phi
    lengths = [t.size for t in row.target]
    cuts = np.cumsum(lengths)[:-1]
    theta0 = np.concatenate([theta_ab, np.zeros(row.nc)])
    if hr is not None:
        with_e = np.hstack([phi, np.vstack([lag_matrix(e, range(1, row.nc + 1), row.start) for e in hr])])
        try:
            theta_hr = solve_ls(with_e, target, "initial MIMO ARMAX regression")
            theta0 = np.concatenate([theta_hr[: row.n_ab], stabilise(np.r_[1.0, theta_hr[row.n_ab :]])[1:]])
        except EstimationError:
            pass  # noise-free data: the ARX start with C = 1

    def errors(theta: np.ndarray) -> np.ndarray:
        v = target - phi @ theta[: row.n_ab]
        return _filter(np.r_[1.0, theta[row.n_ab :]], np.split(v, cuts))

    def gradient(theta: np.ndarray, eps: np.ndarray) -> np.ndarray:
        c = np.r_[1.0, theta[row.n_ab :]]
        lagged = [lag_matrix(e, range(1, row.nc + 1), 0) for e in np.split(eps, cuts)]
        return np.hstack([_filter(c, np.split(phi, cuts)), _filter(c, lagged)])

    exact = float((1e-10 * np.linalg.norm(target)) ** 2)
    best = minimise(
        errors,
        gradient,
        lambda th: max_root(np.r_[1.0, th[row.n_ab :]]) < 1.0,
        theta0,
        name="MIMO ARMAX PEM",
        orders=f"na={row.na.tolist()}, nb={row.nb.tolist()}, nc={row.nc}, nk={row.nk.tolist()}",
        max_iter=max_iter,
        tol=tol,
        exact=exact,
    )
    return best.theta, best.eps, best.psi


@dataclass
class MimoPolynomialModel:
    """A multi-output ``A(q) y = B(q) u + C(q) e`` model with diagonal ``C`` (:func:`arx_mimo`, :func:`armax_mimo`).

    Attributes
    ----------
    A : numpy.ndarray
        ``(p, p, na_max + 1)``: ``A[:, :, k]`` multiplies ``y(t - k)``; ``A[:, :, 0] = I``.
    B : numpy.ndarray
        ``(p, m, L)``: ``B[:, :, k]`` multiplies ``u(t - k)`` (leading zeros for the delays).
    C : numpy.ndarray
        ``(p, nc_max + 1)``: row ``j`` is the monic ``C_j`` (zero-padded).
    sample_time : float
        Seconds per sample.
    noise_covariance : numpy.ndarray
        Innovation covariance ``E^T E / N`` of the prediction errors, ``(p, p)`` (output units squared).
    loss : float
        ``det(noise_covariance)`` (the mean squared prediction error for one output).
    n_samples : int
        Predictions per output (all experiments together).
    parameters, covariances : list of numpy.ndarray
        Per output ``j``: ``[a (for each output i, na[j, i] coefficients), b (for each input l, nb[j, l]),
        c (nc[j])]`` and its covariance ``lambda_j (psi^T psi)^-1``.
    method : str
        ``"arx-mimo"`` or ``"armax-mimo"``.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    sample_time: float
    noise_covariance: np.ndarray
    loss: float
    n_samples: int
    parameters: list[np.ndarray]
    covariances: list[np.ndarray]
    method: str
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    info: dict[str, Any] = field(default_factory=dict)

    def to_ss(self) -> control.StateSpace:
        """A (non-minimal) discrete StateSpace of ``y = A^-1 B u``: the state holds the past outputs and inputs."""
        p, m, lb = self.B.shape
        na = self.A.shape[2] - 1
        h = np.hstack([-self.A[:, :, k] for k in range(1, na + 1)] + [self.B[:, :, k] for k in range(1, lb)])
        ny, n = p * na, p * na + m * (lb - 1)
        f, g = np.zeros((n, n)), np.zeros((n, m))
        if ny:
            f[:p], g[:p] = h, self.B[:, :, 0]
            f[p:ny, : ny - p] = np.eye(ny - p)
        if n > ny:
            g[ny : ny + m] = np.eye(m)
            f[ny + m :, ny : n - m] = np.eye(n - ny - m)
        return control.ss(f, g, h, self.B[:, :, 0], self.sample_time)

    def simulate(self, u: object) -> np.ndarray:
        """Free-run output ``(N, p)`` from rest for inputs ``u`` (shape ``(N, m)``, input units)."""
        ua = np.asarray(u, float)
        ua = ua[:, None] if ua.ndim == 1 else ua
        if ua.ndim != 2 or ua.shape[1] != self.B.shape[1] or not np.all(np.isfinite(ua)):
            raise InputError(f"u must be finite, shape (N, {self.B.shape[1]}), got shape {ua.shape}")
        if self.A.shape[2] == 1 and self.B.shape[2] == 1:
            return ua @ self.B[:, :, 0].T
        sys = self.to_ss()
        return scipy.signal.dlsim((sys.A, sys.B, sys.C, sys.D, self.sample_time), ua)[1]

    def fit(self, y: object, u: object) -> np.ndarray:
        """Free-run simulation fit (%) of each output on data ``y`` ``(N, p)``, ``u`` ``(N, m)``."""
        ya = np.asarray(y, float).reshape(-1, self.A.shape[0])
        sim = self.simulate(u)
        return np.array([fit_percent(ya[:, j], sim[:, j]) for j in range(ya.shape[1])])

    def __repr__(self) -> str:
        p, m = self.B.shape[:2]
        return (
            f"MimoPolynomialModel({self.method}, {m} in, {p} out, Ts={self.sample_time:g} s, N={self.n_samples}, "
            f"loss {self.loss:.4g})"
        )


def _fit(
    data: Record | object,
    u: object | None,
    na: object,
    nb: object,
    nc: object,
    nk: object,
    sample_time: float | None,
    max_iter: int,
    tol: float,
    method: str,
) -> MimoPolynomialModel:
    exps, ts, in_names, out_names = _experiments(data, u, sample_time)
    p, m = exps[0][0].shape[1], exps[0][1].shape[1]
    na_, nb_ = _orders("na", na, (p, p), 0), _orders("nb", nb, (p, m), 0)
    nk_, nc_ = _orders("nk", nk, (p, m), 0), _orders("nc", nc, (p,), 0)
    if np.any(nb_.sum(axis=1) == 0):
        raise InputError(f"nb = {nb_.tolist()}: every output's equation needs an input coefficient (a row sum >= 1)")
    start = int(max(na_.max(), (nk_ + nb_ - 1).max(), 0))
    for j in range(p):
        n_par = int(na_[j].sum() + nb_[j].sum() + nc_[j])
        check_sizes(tuple(SisoData(y[:, j], x[:, 0], ts) for y, x in exps), start, n_par, f"output {j + 1}")
    for i in range(m):
        check_excitation([x[:, i] for _, x in exps], int(nb_[:, i].max()), what=f"input {in_names[i]}")
    hr = _innovations(exps, start) if nc_.any() else None
    thetas, errs, covs = [], [], []
    for j in range(p):
        phis = [_regressors(y, x, na_[j], nb_[j], nk_[j], start) for y, x in exps]
        row = _Row(na_[j], nb_[j], nk_[j], int(nc_[j]), start, phis, [y[start:, j] for y, _ in exps])
        theta, eps, psi = _fit_row(row, None if hr is None else hr[j], max_iter, tol)
        thetas.append(theta)
        errs.append(eps)
        covs.append(covariance(psi, float(eps @ eps) / max(eps.size - theta.size, 1)))
    e = np.column_stack(errs)
    lam = e.T @ e / e.shape[0]
    a_poly, b_poly, c_poly = _polynomials(thetas, na_, nb_, nk_, nc_)
    return MimoPolynomialModel(
        A=a_poly,
        B=b_poly,
        C=c_poly,
        sample_time=ts,
        noise_covariance=(lam + lam.T) / 2,
        loss=float(np.linalg.det(lam)),
        n_samples=int(e.shape[0]),
        parameters=thetas,
        covariances=covs,
        method=method,
        input_names=in_names,
        output_names=out_names,
        info={"na": na_, "nb": nb_, "nc": nc_, "nk": nk_, "experiments": len(exps)},
    )


def _innovations(exps: list[tuple[np.ndarray, np.ndarray]], start: int) -> list[list[np.ndarray]]:
    """Per output, per experiment: the innovations estimated by a high-order MIMO ARX (zero before its start)."""
    p, m = exps[0][0].shape[1], exps[0][1].shape[1]
    total = sum(y.shape[0] for y, _ in exps)
    high = int(min(max(10, 3 * start), max(start + 1, total // (10 * (p + m)))))
    ones = np.ones(p, dtype=int)
    out: list[list[np.ndarray]] = [[] for _ in range(p)]
    for j in range(p):
        phis = [_regressors(y, x, high * ones, high * np.ones(m, int), np.ones(m, int), high) for y, x in exps]
        try:
            theta = solve_ls(np.vstack(phis), np.concatenate([y[high:, j] for y, _ in exps]), "high-order MIMO ARX")
        except EstimationError:
            theta = np.zeros(phis[0].shape[1])
        for (y, _), phi in zip(exps, phis):
            e = np.zeros(y.shape[0])
            e[high:] = y[high:, j] - phi @ theta
            out[j].append(e)
    return out


def _polynomials(
    thetas: list[np.ndarray], na: np.ndarray, nb: np.ndarray, nk: np.ndarray, nc: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``A (p, p, na_max + 1)``, ``B (p, m, L)``, ``C (p, nc_max + 1)`` from each output's parameters."""
    p, m = nb.shape
    a = np.zeros((p, p, int(na.max()) + 1))
    a[:, :, 0] = np.eye(p)
    b = np.zeros((p, m, int((nk + nb).max())))
    c = np.zeros((p, int(nc.max()) + 1))
    c[:, 0] = 1.0
    for j, theta in enumerate(thetas):
        pos = 0
        for i in range(p):
            a[j, i, 1 : na[j, i] + 1] = theta[pos : pos + na[j, i]]
            pos += na[j, i]
        for i in range(m):
            b[j, i, nk[j, i] : nk[j, i] + nb[j, i]] = theta[pos : pos + nb[j, i]]
            pos += nb[j, i]
        c[j, 1 : nc[j] + 1] = theta[pos:]
    return a, b, c


def arx_mimo(
    data: Record | object,
    u: object | None = None,
    na: object = 2,
    nb: object = 2,
    nk: object = 1,
    *,
    sample_time: float | None = None,
) -> MimoPolynomialModel:
    """Multi-output ARX model ``A(q) y = B(q) u + e`` by least squares, one output's equation at a time.

    Parameters
    ----------
    data : Record, Dataset or array_like
        A Record (deviations of all its channels), a :class:`~trms.identification.dataset.Dataset` (every
        experiment, none joined to the next) or the outputs ``y``, shape ``(N, p)`` (output units).
    u : array_like, optional
        Inputs with an array ``y``, shape ``(N, m)`` (input units, e.g. V).
    na : int or array_like
        Coefficients of ``A``'s entries, ``>= 0``: one int for every entry (MATLAB's convention) or a
        ``(p, p)`` array (``np.diag([2, 2])``: each output's own past only).
    nb, nk : int or array_like
        Coefficients (``>= 0``, at least one per output) and input delays (samples, ``>= 0``) of ``B``'s
        entries: one int or a ``(p, m)`` array.
    sample_time : float, optional
        Seconds per sample (required with arrays).

    Returns
    -------
    MimoPolynomialModel
        ``C = I``, ``method = "arx-mimo"``.

    Raises
    ------
    InputError
        Bad data, orders of the wrong shape or below 0, too few samples, an input that does not excite.
    EstimationError
        Linearly dependent regressors.

    Examples
    --------
    Two outputs, each driven by both inputs, noise-free:

    >>> import scipy.signal
    >>> u = np.sign(np.random.default_rng(0).standard_normal((400, 2)))
    >>> y1 = scipy.signal.lfilter([0, 1.0], [1, -0.5], u[:, 0]) + scipy.signal.lfilter([0, 0.3], [1, -0.5], u[:, 1])
    >>> y2 = scipy.signal.lfilter([0, 0.4], [1, 0.2], u[:, 0]) + scipy.signal.lfilter([0, 0.8], [1, 0.2], u[:, 1])
    >>> model = arx_mimo(np.column_stack([y1, y2]), u, np.diag([1, 1]), 1, 1, sample_time=0.1)
    >>> np.round(model.parameters[0], 6), np.round(model.parameters[1], 6)
    (array([-0.5,  1. ,  0.3]), array([0.2, 0.4, 0.8]))
    """
    return _fit(data, u, na, nb, 0, nk, sample_time, 1, 1.0, "arx-mimo")


def armax_mimo(
    data: Record | object,
    u: object | None = None,
    na: object = 2,
    nb: object = 2,
    nc: object = 1,
    nk: object = 1,
    *,
    sample_time: float | None = None,
    max_iter: int = MAX_ITER,
    tol: float = 1e-7,
) -> MimoPolynomialModel:
    """Multi-output ARMAX model ``A(q) y = B(q) u + C(q) e``, ``C`` diagonal, by the prediction-error method.

    Parameters
    ----------
    data, u, na, nb, nk, sample_time
        As for :func:`arx_mimo`.
    nc : int or array_like
        Order of each output's ``C_j``, ``>= 0``: one int or a ``(p,)`` array (``0``: that output's equation is ARX).
    max_iter : int
        Most Gauss-Newton iterations per output (default :data:`~trms.identification.pem.MAX_ITER`).
    tol : float
        Convergence: the Gauss-Newton step's predicted relative decrease of each output's loss, in ``(0, 1]``.

    Returns
    -------
    MimoPolynomialModel
        ``method = "armax-mimo"``; ``parameters[j]`` ends with ``C_j``'s coefficients.

    Raises
    ------
    InputError
        As for :func:`arx_mimo`; ``max_iter`` or ``tol`` out of range.
    EstimationError
        No convergence within ``max_iter``, linearly dependent regressors.

    Examples
    --------
    >>> import scipy.signal
    >>> rng = np.random.default_rng(1)
    >>> u, e = np.sign(rng.standard_normal((3000, 2))), 0.1 * rng.standard_normal((3000, 2))
    >>> y1 = (scipy.signal.lfilter([0, 1.0], [1, -0.5], u[:, 0]) + scipy.signal.lfilter([0, 0.3], [1, -0.5], u[:, 1])
    ...       + scipy.signal.lfilter([1, 0.6], [1, -0.5], e[:, 0]))
    >>> y2 = (scipy.signal.lfilter([0, 0.4], [1, 0.2], u[:, 0]) + scipy.signal.lfilter([0, 0.8], [1, 0.2], u[:, 1])
    ...       + scipy.signal.lfilter([1, -0.4], [1, 0.2], e[:, 1]))
    >>> model = armax_mimo(np.column_stack([y1, y2]), u, np.diag([1, 1]), 1, 1, 1, sample_time=0.1)
    >>> np.round(model.C, 1)
    array([[ 1. ,  0.6],
           [ 1. , -0.4]])
    """
    max_iter, tol = check_search(max_iter, tol)
    return _fit(data, u, na, nb, nc, nk, sample_time, max_iter, tol, "armax-mimo")
