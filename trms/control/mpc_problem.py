"""The MPC's problem (:mod:`trms.control.mpc`): the condensed prediction over the horizon, the QP's constraint rows,
and the offset-free estimator on the state and a constant input disturbance.
"""

from __future__ import annotations

import numpy as np

from trms.control.lq_design import current_estimator_gain
from trms.errors import check_in_range

__all__ = ["condensed_prediction", "constraint_rows", "disturbance_estimator"]


def condensed_prediction(A: np.ndarray, B: np.ndarray, horizon: int) -> tuple[np.ndarray, np.ndarray]:
    """The condensed prediction ``X = Phi x0 + Gam U`` of ``x(k+1) = A x(k) + B u(k)`` over ``horizon`` samples,
    ``X = [x_1; ..; x_N]``, ``U = [u_0; ..; u_{N-1}]``.

    Examples
    --------
    >>> Phi, Gam = condensed_prediction(np.array([[0.5]]), np.array([[1.0]]), 3)
    >>> Phi.ravel().tolist(), Gam.tolist()
    ([0.5, 0.25, 0.125], [[1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.25, 0.5, 1.0]])
    """
    n, m = B.shape
    Phi = np.vstack([np.linalg.matrix_power(A, k) for k in range(1, horizon + 1)])
    Gam = np.zeros((horizon * n, horizon * m))
    for k in range(horizon):
        AkB = np.linalg.matrix_power(A, k) @ B
        for j in range(horizon - k):
            Gam[(j + k) * n : (j + k + 1) * n, j * m : (j + 1) * m] = AkB
    return Phi, Gam


def constraint_rows(nu: int, m: int, CyGam: np.ndarray, ns: int) -> np.ndarray:
    """The QP's constraint matrix over ``[U; s]`` (``nu`` inputs over the horizon, ``m`` per sample, ``ns`` slacks):
    inputs, rates, the outputs' upper and lower sides ``CyGam U`` (with their slacks when soft), and ``s >= 0``.

    Examples
    --------
    >>> constraint_rows(2, 1, np.zeros((0, 2)), 0).tolist()  # two moves of one input: the moves, then the rates
    [[1.0, 0.0], [0.0, 1.0], [1.0, 0.0], [-1.0, 1.0]]
    """
    rows = [np.hstack([np.eye(nu), np.zeros((nu, ns))])]
    rows.append(np.hstack([np.eye(nu) - np.eye(nu, k=-m), np.zeros((nu, ns))]))
    if CyGam.shape[0]:
        slack = np.eye(ns) if ns else np.zeros((CyGam.shape[0], 0))
        rows.append(np.hstack([CyGam, -slack]))  # upper side: Cy X - s <= y_hi
        rows.append(np.hstack([CyGam, slack]))  # lower side: Cy X + s >= y_lo
    if ns:
        rows.append(np.hstack([np.zeros((ns, nu)), np.eye(ns)]))
    return np.vstack(rows)


def disturbance_estimator(
    A: np.ndarray, B: np.ndarray, C: np.ndarray, Qx: object, Qd: object, Re: object
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The current Kalman filter on ``[x; d]`` (:mod:`trms.control.mpc`), ``d`` a constant input disturbance: its
    ``A``, ``B``, ``C`` and gain ``L_c``, from the process covariances ``Qx`` (states), ``Qd`` (disturbance) and the
    measurement covariance ``Re``.

    Examples
    --------
    >>> A, B, C = np.array([[0.9]]), np.array([[0.1]]), np.array([[1.0]])
    >>> Ae, Be, Ce, Lc = disturbance_estimator(A, B, C, 1e-3, 1e-3, 1e-2)
    >>> Ae.tolist(), Ce.tolist(), Lc.shape
    ([[0.9, 0.1], [0.0, 1.0]], [[1.0, 0.0]], (2, 1))
    """
    n, m = B.shape
    p = C.shape[0]
    Ae = np.block([[A, B], [np.zeros((m, n)), np.eye(m)]])
    Ce = np.hstack([C, np.zeros((p, m))])
    Qe = np.diag(
        np.r_[
            np.full(n, check_in_range("Qx", Qx, 0.0, 1e6)),
            np.full(m, check_in_range("Qd", Qd, 0.0, 1e6, low_open=True)),
        ]
    )
    Rem = check_in_range("Re", Re, 0.0, 1e6, low_open=True) * np.eye(p)
    Lc = current_estimator_gain(Ae, Ce, np.eye(n + m), Qe, Rem)[0]
    return Ae, np.vstack([B, np.zeros((m, m))]), Ce, Lc
