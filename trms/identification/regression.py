"""The least-squares core of the linear estimators: ARX regressors formed inside each experiment, a column-scaled
QR solve that refuses dependent regressors, the size checks (samples per parameter) and the reflection of a
polynomial's roots into the unit circle.

:mod:`trms.identification.linear` (ARX, ARMAX's initial estimate), :mod:`~trms.identification.oe_bj`,
:mod:`~trms.identification.bootstrap`, :mod:`~trms.identification.continuous`,
:mod:`~trms.identification.nonparametric`, :mod:`~trms.identification.recursive` and
:mod:`~trms.identification.mimo_pem` build on it.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from trms.errors import EstimationError, InputError, check_int
from trms.identification.data import SisoData, lag_matrix

__all__ = [
    "SAMPLES_PER_PARAMETER",
    "check_orders",
    "check_size",
    "check_sizes",
    "arx_regressors",
    "stacked_regressors",
    "solve_ls",
    "stabilise",
]

#: Smallest ratio of samples to estimated parameters accepted.
SAMPLES_PER_PARAMETER = 2


def check_orders(na: int, nb: int, nc: int, nk: int) -> tuple[int, int, int, int]:
    return check_int("na", na, 0), check_int("nb", nb, 1), check_int("nc", nc, 0), check_int("nk", nk, 0)


def check_size(n: int, start: int, n_params: int, orders: str) -> None:
    need = start + SAMPLES_PER_PARAMETER * n_params + 1
    if n < need:
        raise InputError(
            f"orders {orders} ({n_params} parameters, first prediction at sample {start}) need at least "
            f"{need} samples ({SAMPLES_PER_PARAMETER} per parameter); the data have {n}"
        )


def check_sizes(exps: tuple[SisoData, ...], start: int, n_params: int, orders: str) -> None:
    """:func:`check_size` for one experiment; for several, each must reach ``start`` and together give the rows."""
    if len(exps) == 1:
        check_size(len(exps[0]), start, n_params, orders)
        return
    for i, d in enumerate(exps):
        if len(d) <= start:
            raise InputError(
                f"experiment {i + 1} of {len(exps)} has {len(d)} samples; orders {orders} need more than "
                f"start = {start} in every experiment"
            )
    rows = sum(len(d) - start for d in exps)
    need = SAMPLES_PER_PARAMETER * n_params + 1
    if rows < need:
        raise InputError(
            f"orders {orders} ({n_params} parameters) need at least {need} predictions "
            f"({SAMPLES_PER_PARAMETER} per parameter); the {len(exps)} experiments give {rows}"
        )


def arx_regressors(d: SisoData, na: int, nb: int, nk: int, start: int) -> np.ndarray:
    """``[-y(t-1)..-y(t-na), u(t-nk)..u(t-nk-nb+1)]`` for ``t >= start`` (eq. 3.6 without the noise part)."""
    return np.hstack([-lag_matrix(d.y, range(1, na + 1), start), lag_matrix(d.u, range(nk, nk + nb), start)])


def stacked_regressors(
    exps: tuple[SisoData, ...], na: int, nb: int, nk: int, start: int
) -> tuple[np.ndarray, np.ndarray]:
    """ARX regressors and targets of every experiment, each formed inside its experiment, stacked."""
    if len(exps) == 1:
        return arx_regressors(exps[0], na, nb, nk, start), exps[0].y[start:]
    phi = np.vstack([arx_regressors(d, na, nb, nk, start) for d in exps])
    return phi, np.concatenate([d.y[start:] for d in exps])


def solve_ls(phi: np.ndarray, target: np.ndarray, what: str) -> np.ndarray:
    """Least squares with column scaling; refuses (numerically) dependent regressors."""
    scale = np.linalg.norm(phi, axis=0)
    if np.any(scale == 0):
        raise EstimationError(f"{what}: a regressor column is identically zero (no excitation)")
    q, r = np.linalg.qr(phi / scale)
    diag = np.abs(np.diag(r))
    if diag.min() < 1e-10 * diag.max():
        raise EstimationError(
            f"{what}: the regressors are linearly dependent (condition > 1e10) -- orders too high for "
            "noise-free data (A and B share a factor) or an input that does not excite them"
        )
    return scipy.linalg.solve_triangular(r, q.T @ target) / scale


def stabilise(c: np.ndarray, radius: float = 0.99) -> np.ndarray:
    """Reflect roots of the monic polynomial ``c`` outside the unit circle to ``1 / conj(r)``, cap at ``radius``."""
    if c.size <= 1:
        return c
    roots = np.roots(c)
    mag = np.abs(roots)
    if np.all(mag < radius):
        return c
    fixed = np.where(mag >= 1.0, roots / np.maximum(mag, 1.0) ** 2, roots)
    fixed = np.where(np.abs(fixed) > radius, fixed / np.maximum(np.abs(fixed), radius) * radius, fixed)
    return np.real(np.poly(fixed))
