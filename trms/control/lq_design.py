"""Linear-quadratic building blocks of the integral LQG (:mod:`trms.control.lqg`) and the MPC (:mod:`trms.control.mpc`).

Weight matrices (:func:`weight_matrix`) are checked symmetric, (semi-)definite and within the range the
double-precision Riccati solvers can honour (:data:`WEIGHT_RANGE`); :func:`unreachable_unstable_modes` is the
PBH test of stabilisability (and, transposed, detectability); :func:`augment_with_integrators` adds one
integral state per tracked output; :func:`current_estimator_gain` turns python-control's stationary Kalman
*predictor* gain into the *current* estimator's (the thesis's eq. 6.12-6.14): with the a-priori error
covariance ``Pe``, ``Lc = Pe C' (C Pe C' + Re)^-1`` and the predictor gain ``Lp = A Lc``.
"""

from __future__ import annotations

import control
import numpy as np

from trms.control.arguments import real_array
from trms.errors import DesignError, InputError, as_finite_array

__all__ = [
    "WEIGHT_RANGE",
    "weight_matrix",
    "unreachable_unstable_modes",
    "augment_with_integrators",
    "current_estimator_gain",
]

#: Relative tolerance for symmetry and definiteness checks of weight matrices.
_SYM_TOL = 1e-9
#: Magnitudes a weight entry may have (Q, R, Qe, Re; the lower bound for nonzero diagonal entries): the Riccati
#: solvers work in double precision.
WEIGHT_RANGE = (1e-12, 1e12)


def weight_matrix(name: str, value: object, size: int, definite: bool) -> np.ndarray:
    """A symmetric weight matrix from a scalar (times I), a diagonal or an array; PSD, or PD when ``definite``.

    Parameters
    ----------
    name : str
        Argument name for the message (``"Q"``, ``"R"``, ...).
    value : float or array_like
        A scalar, ``size`` diagonal entries, or a ``(size, size)`` matrix (in the weighted quantity's inverse
        unit squared, e.g. V^-2 for ``R``).
    size : int
        Rows and columns.
    definite : bool
        Require positive definite (``R``, ``Re``) rather than semi-definite (``Q``, ``Qe``).

    Returns
    -------
    numpy.ndarray
        ``(size, size)``, symmetrised.

    Raises
    ------
    InputError
        Not real numbers, or the wrong shape.
    DesignError
        Not symmetric, not (semi-)definite, or an entry beyond :data:`WEIGHT_RANGE`.

    Examples
    --------
    >>> weight_matrix("Q", 2.0, 2, definite=False).tolist(), weight_matrix("R", [1.0, 4.0], 2, definite=True).tolist()
    ([[2.0, 0.0], [0.0, 2.0]], [[1.0, 0.0], [0.0, 4.0]])
    >>> weight_matrix("R", 0.0, 1, definite=True)
    Traceback (most recent call last):
    ...
    trms.errors.DesignError: R must be positive definite; its smallest eigenvalue is 0 (allowed: > 0)
    """
    arr = real_array(name, value)
    if arr.ndim == 0:
        arr = arr * np.eye(size)
    elif arr.ndim == 1 and arr.shape == (size,):
        arr = np.diag(arr)
    mat = as_finite_array(name, arr, (size, size))
    big = float(np.max(np.abs(mat), initial=0.0))
    diagonal = np.abs(np.diag(mat))
    small = float(np.min(diagonal[diagonal != 0.0], initial=np.inf))
    if big > WEIGHT_RANGE[1] or small < WEIGHT_RANGE[0]:
        worst = big if big > WEIGHT_RANGE[1] else small
        raise DesignError(
            f"{name} has an entry of magnitude {worst:.3g}; allowed: 0 or {WEIGHT_RANGE[0]:g} .. {WEIGHT_RANGE[1]:g} "
            "(the Riccati solution loses every digit beyond; scale the weights together instead)"
        )
    scale = max(1.0, float(np.max(np.abs(mat))))
    if not np.allclose(mat, mat.T, rtol=0.0, atol=_SYM_TOL * scale):
        raise DesignError(f"{name} must be symmetric, got {mat.tolist()}")
    low = float(np.min(np.linalg.eigvalsh(0.5 * (mat + mat.T))))
    if definite and low <= _SYM_TOL * scale:
        raise DesignError(f"{name} must be positive definite; its smallest eigenvalue is {low:.6g} (allowed: > 0)")
    if not definite and low < -_SYM_TOL * scale:
        raise DesignError(
            f"{name} must be positive semi-definite; its smallest eigenvalue is {low:.6g} (allowed: >= 0)"
        )
    return 0.5 * (mat + mat.T)


def _square(name: str, value: object) -> np.ndarray:
    """A finite real square matrix."""
    mat = real_array(name, value, (None, None))
    if mat.shape[0] != mat.shape[1]:
        raise InputError(f"{name} must be a square matrix, got shape {mat.shape}")
    return mat


def unreachable_unstable_modes(A: np.ndarray, B: np.ndarray) -> list[complex]:
    """Eigenvalues of a discrete ``A`` with ``|z| >= 1`` that ``B`` cannot reach (PBH test).

    ``(A, B)`` is stabilisable when the list is empty; ``(A', C')`` gives the modes the outputs ``C`` cannot
    see (detectability).

    Parameters
    ----------
    A, B : numpy.ndarray
        ``(n, n)`` and ``(n, m)``, finite.

    Returns
    -------
    list of complex
        The unreachable eigenvalues on or outside the unit circle.

    Examples
    --------
    An integrator the input drives and a growing mode (``z = 1.2``) it does not:

    >>> unreachable_unstable_modes(np.diag([1.0, 1.2]), np.array([[1.0], [0.0]]))
    [(1.2+0j)]
    >>> unreachable_unstable_modes(np.eye(1), np.eye(1))
    []
    """
    n = A.shape[0]
    bad = []
    scale = max(1.0, float(np.linalg.norm(A, 2)), float(np.linalg.norm(B, 2)))
    for lam in np.linalg.eigvals(A):
        if abs(lam) < 1.0 - 1e-9:
            continue
        sv = np.linalg.svd(np.hstack([lam * np.eye(n) - A, B]), compute_uv=False)
        if sv[-1] <= 1e-9 * scale:
            bad.append(complex(lam))
    return bad


def augment_with_integrators(A: np.ndarray, B: np.ndarray, C_tracked: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The augmented pair ``Aa = [[A, 0], [-C_t, I]]``, ``Ba = [[B], [0]]`` of integral action.

    Parameters
    ----------
    A, B : numpy.ndarray
        Plant matrices, ``(n, n)`` and ``(n, m)``.
    C_tracked : numpy.ndarray
        Rows of ``C`` of the tracked outputs, ``(p_t, n)``.

    Returns
    -------
    tuple of numpy.ndarray
        ``Aa`` ``(n + p_t, n + p_t)`` and ``Ba`` ``(n + p_t, m)``.

    Raises
    ------
    InputError
        Matrices that are not real, finite and of matching shapes.

    Examples
    --------
    >>> Aa, Ba = augment_with_integrators(np.array([[0.5]]), np.array([[1.0]]), np.array([[1.0]]))
    >>> Aa.tolist(), Ba.tolist()
    ([[0.5, 0.0], [-1.0, 1.0]], [[1.0], [0.0]])
    """
    A = _square("A", A)
    n = A.shape[0]
    B = real_array("B", B, (n, None))
    C_tracked = real_array("C_tracked", C_tracked, (None, n))
    pt = C_tracked.shape[0]
    Aa = np.block([[A, np.zeros((n, pt))], [-C_tracked, np.eye(pt)]])
    Ba = np.vstack([B, np.zeros((pt, B.shape[1]))])
    return Aa, Ba


def current_estimator_gain(
    A: np.ndarray, C: np.ndarray, G: np.ndarray, Qe: np.ndarray, Re: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stationary Kalman gains of the current estimator and of the predictor (python-control ``dlqe``).

    Parameters
    ----------
    A, C : numpy.ndarray
        Plant matrices.
    G : numpy.ndarray
        Process-noise input matrix ``(n, q)``.
    Qe, Re : numpy.ndarray
        Process ``(q, q)`` and measurement ``(p, p)`` noise covariances.

    Returns
    -------
    Lc : numpy.ndarray
        Filter (current estimator) gain ``Pe C' (C Pe C' + Re)^-1``, ``(n, p)``.
    Lp : numpy.ndarray
        Predictor gain returned by ``dlqe``, equal to ``A Lc``.
    Pe : numpy.ndarray
        A-priori error covariance (the filter Riccati solution, eq. 6.22), in the output's unit squared.

    Raises
    ------
    InputError
        Matrices that are not real, finite and of matching shapes.
    DesignError
        The Riccati equation has no stabilising solution.

    Examples
    --------
    A random walk of unit process noise seen in unit measurement noise: ``Pe = Pe + 1 - Pe^2 / (Pe + 1)``, so
    ``Pe`` is the golden ratio ``(1 + sqrt 5) / 2`` and ``Lc = Pe / (Pe + 1) = Lp`` its inverse:

    >>> Lc, Lp, Pe = current_estimator_gain(*(np.eye(1),) * 5)
    >>> round(float(Pe[0, 0]), 9), round(float(Lc[0, 0]), 9), round(float(Lp[0, 0]), 9)
    (1.618033989, 0.618033989, 0.618033989)
    """
    A = _square("A", A)
    n = A.shape[0]
    C = real_array("C", C, (None, n))
    G = real_array("G", G, (n, None))
    Qe = real_array("Qe", Qe, (G.shape[1], G.shape[1]))
    Re = real_array("Re", Re, (C.shape[0], C.shape[0]))
    try:
        Lp, Pe, _ = control.dlqe(A, G, C, Qe, Re, method="scipy")  # the same numbers with or without slycot
    except Exception as exc:  # python-control raises several types for a failed Riccati solve
        raise DesignError(f"the estimator Riccati equation has no stabilising solution: {exc}") from exc
    Pe = np.asarray(Pe, float)
    S = C @ Pe @ C.T + Re
    Lc = np.linalg.solve(S.T, (Pe @ C.T).T).T
    return Lc, np.asarray(Lp, float), Pe
