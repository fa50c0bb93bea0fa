"""Fieller's confidence region of a frequency response ``G = N / D`` (see :mod:`trms.identification.frequency`).

``N = B(z)`` and ``D = A(z) F(z)`` are linear in the parameters of a polynomial model, so they are nearly normal
where ``G`` is not; a response ``g`` is inside the region where ``T(g) = r^T Sigma_r^-1 r <= c`` with
``r = N - g D`` and ``Sigma_r`` its covariance. Helpers of :mod:`trms.identification.frequency`.
"""

from __future__ import annotations

import numpy as np

__all__: list[str] = []


def _regularised(cov: np.ndarray) -> np.ndarray:
    """Each ``(4, 4)`` covariance plus ``1e-9`` of its mean variance on the diagonal: invertible where it is
    singular (``Im = 0`` at 0 Hz and at the Nyquist frequency for every parameter vector, or a zero covariance)."""
    scale = np.maximum(np.trace(cov, axis1=-2, axis2=-1) / 4, 1e-300)
    return cov + 1e-9 * scale[..., None, None] * np.eye(4)


def fieller(num: np.ndarray, den: np.ndarray, g: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """``T = r^T Sigma_r^-1 r`` with ``r = num - g den`` (real and imaginary parts) and ``Sigma_r`` its
    covariance from ``cov`` (shape ``(K, 4, 4)``, of ``(Re num, Im num, Re den, Im den)``).

    ``num`` and ``den`` have shape ``(K,)`` or ``(S, K)``; ``g`` shape ``(K,)``. ``Sigma_r`` is kept
    invertible where it is singular (``Im = 0`` at 0 Hz and at the Nyquist frequency for every parameter vector).
    """
    cov = _regularised(cov)
    lin = np.zeros((g.size, 2, 4))
    lin[:, 0, 0] = lin[:, 1, 1] = 1.0
    lin[:, 0, 2], lin[:, 0, 3], lin[:, 1, 2], lin[:, 1, 3] = -g.real, g.imag, -g.imag, -g.real
    inverse = np.linalg.inv(lin @ cov @ np.transpose(lin, (0, 2, 1)))
    r = num - g * den
    x = np.stack([r.real, r.imag], axis=-1)
    return np.einsum("...ki,kij,...kj->...k", x, inverse, x)


def _multiplier(x: np.ndarray) -> np.ndarray:
    """The real ``(2, 2)`` matrix of multiplication by each complex ``x``: shape ``x.shape + (2, 2)``."""
    return np.stack([np.stack([x.real, -x.imag], axis=-1), np.stack([x.imag, x.real], axis=-1)], axis=-2)


def projected_bands(
    num: np.ndarray, den: np.ndarray, cov: np.ndarray, c: np.ndarray, directions: int = 360
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Magnitude band and phase band (deg, from the estimate's phase) of the region ``T(g) <= c``.

    Along each of ``directions`` rays ``g = G + t w`` from the estimate ``G = num / den``, ``r = -t w den`` and
    ``Sigma_r`` is quadratic in ``t``, so the boundary ``T = c`` is the smallest positive root of the quartic
    ``c det(Sigma_r(t)) - t^2 v^T adj(Sigma_r(t)) v``; no root: the region is unbounded that way. The bands are
    the ranges of ``|g|`` and of the phase over the boundary (0 and +-180 deg where the region holds ``g = 0``;
    ``inf`` and +-180 deg where it is unbounded).
    """
    g = num / den
    w = np.exp(2j * np.pi * np.arange(directions) / directions)
    v = real_imag(w[None, :] * den[:, None])  # (K, J, 2)
    eye = np.broadcast_to(np.eye(2), g.shape + (2, 2))
    lin0 = np.concatenate([eye, -_multiplier(g)], axis=-1)[:, None]  # (K, 1, 2, 4)
    lin1 = np.concatenate([np.zeros((directions, 2, 2)), -_multiplier(w)], axis=-1)[None]  # (1, J, 2, 4)
    s = _regularised(cov)[:, None]
    p0 = lin0 @ s @ np.swapaxes(lin0, -1, -2)
    cross = lin0 @ s @ np.swapaxes(lin1, -1, -2)
    mats = np.broadcast_arrays(p0, cross + np.swapaxes(cross, -1, -2), lin1 @ s @ np.swapaxes(lin1, -1, -2))
    a, b, d = (np.stack([m[..., i, j] for m in mats], axis=-1) for i, j in ((0, 0), (0, 1), (1, 1)))
    q = v[..., :1] ** 2 * d - 2 * v[..., :1] * v[..., 1:] * b + v[..., 1:] ** 2 * a  # (K, J, 3), ascending in t
    h = np.zeros(a.shape[:-1] + (5,))
    for i in range(3):
        for j in range(3):
            h[..., i + j] += c[:, None] * (a[..., i] * d[..., j] - b[..., i] * b[..., j])
    h[..., 2:] -= q
    # the roots of the reversed quartic in s = 1 / t (its leading coefficient c det(Sigma_r(0)) > 0)
    companion = np.zeros(h.shape[:-1] + (4, 4))
    companion[..., 0, :] = -h[..., 1:] / h[..., :1]
    companion[..., 1, 0] = companion[..., 2, 1] = companion[..., 3, 2] = 1.0
    roots = np.linalg.eigvals(companion)
    real = (np.abs(roots.imag) <= 1e-7 * np.abs(roots)) & (roots.real > 0)
    s_max = np.max(np.where(real, roots.real, 0.0), axis=-1)  # (K, J)
    bounded = s_max > 0
    edge = g[:, None] + np.where(bounded, 1.0 / np.where(bounded, s_max, 1.0), 0.0) * w[None, :]
    holds_zero = fieller(num, den, np.zeros_like(g), cov) <= c
    unbounded = ~np.all(bounded, axis=1)
    mag = np.abs(edge)
    rel = np.degrees(np.angle(edge / np.where(g == 0, 1.0, g)[:, None]))
    full = holds_zero | unbounded
    return (
        np.where(holds_zero, 0.0, mag.min(axis=1)),
        np.where(unbounded, np.inf, mag.max(axis=1)),
        np.where(full, -180.0, rel.min(axis=1)),
        np.where(full, 180.0, rel.max(axis=1)),
    )


def real_imag(x: np.ndarray) -> np.ndarray:
    """Complex ``(..., K)`` as real ``(..., K, 2)``."""
    return np.stack([x.real, x.imag], axis=-1)


def calibrated_radii(stat: np.ndarray, level: float) -> tuple[np.ndarray, np.ndarray]:
    """Pointwise radius (the level's quantile of ``stat``, shape ``(S, K)``, per frequency) and the simultaneous
    one (that times the level's quantile of each row's largest ratio to it, at least 1)."""
    radius = np.quantile(stat, level, axis=0)
    stretch = float(np.quantile(np.max(stat / np.maximum(radius, 1e-300), axis=1), level))
    return radius, max(stretch, 1.0) * radius
