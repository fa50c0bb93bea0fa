"""State-space realisations of identified transfer functions, and model reduction by residualisation.

The LQG weights ``Q = I`` of the thesis act on the state of a particular realisation:
the one printed as eq. (6.33), the observer canonical form with ``y = x1``. The same
form of the strictly proper eq. (3.11) is built here, so a design on (3.11) weighs the
same kind of state as the thesis's design on (6.33).
"""

from __future__ import annotations

import control
import numpy as np
import scipy.linalg

from trms.control.arguments import finite_system, index_tuple, is_discrete_dt
from trms.errors import InputError, as_finite_array

__all__ = ["observer_canonical", "residualise", "continuous_jacobians"]


def observer_canonical(system: control.TransferFunction) -> control.StateSpace:
    """Observer canonical realisation of a SISO discrete transfer function.

    For ``G(z) = (b_0 z^n + b_1 z^(n-1) + ... + b_n) / (z^n + a_1 z^(n-1) + ... + a_n)``
    the realisation is ``A[:, 0] = -a``, ``A[i, i + 1] = 1``, ``B = b_{1..n} - b_0 a``,
    ``C = [1, 0, ..., 0]``, ``D = b_0``: the form of eq. (6.33).

    Parameters
    ----------
    system : control.TransferFunction
        SISO, proper, discrete-time (``dt > 0``).

    Returns
    -------
    control.StateSpace
        Same ``dt`` and signal names (and the units of ``system``: e.g. V in, rad out).

    Raises
    ------
    InputError
        Not a SISO discrete TransferFunction, improper, or without a pole.

    Examples
    --------
    ``G(z) = (0.5 z + 0.2) / (z^2 - 1.5 z + 0.7)``: ``a = [-1.5, 0.7]``, ``b = [0, 0.5, 0.2]``:

    >>> ss = observer_canonical(control.tf([0.5, 0.2], [1.0, -1.5, 0.7], 0.1))
    >>> ss.A.tolist(), ss.B.ravel().tolist(), ss.C.tolist(), ss.D.tolist()
    ([[1.5, 1.0], [-0.7, 0.0]], [0.5, 0.2], [[1.0, 0.0]], [[0.0]])
    """
    if not isinstance(system, control.TransferFunction):
        raise InputError(f"system must be a python-control TransferFunction, got {type(system).__name__}")
    if system.ninputs != 1 or system.noutputs != 1:
        raise InputError(f"observer_canonical needs a SISO system, got {system.noutputs}x{system.ninputs}")
    dt = system.dt
    if not is_discrete_dt(dt):
        raise InputError(f"system must be discrete-time with a finite numeric dt > 0 (s), got dt = {dt!r}")
    num = np.trim_zeros(as_finite_array("system numerator", np.asarray(system.num_array[0][0], float)), "f")
    den = np.trim_zeros(as_finite_array("system denominator", np.asarray(system.den_array[0][0], float)), "f")
    n = den.size - 1
    if num.size == 0:
        num = np.zeros(1)
    if n < 1 or num.size > den.size:
        raise InputError(
            f"system must be proper with at least one pole; numerator degree {num.size - 1}, denominator degree {n}"
        )
    num, den = num / den[0], den / den[0]
    b = np.concatenate([np.zeros(den.size - num.size), num])
    a = den[1:]
    A = np.zeros((n, n))
    A[:, 0] = -a
    A[: n - 1, 1:] = np.eye(n - 1)
    B = (b[1:] - b[0] * a)[:, None]
    C = np.zeros((1, n))
    C[0, 0] = 1.0
    D = np.array([[b[0]]])
    return control.ss(A, B, C, D, dt, inputs=system.input_labels, outputs=system.output_labels)


def residualise(system: control.StateSpace, keep: list[int] | tuple[int, ...]) -> control.StateSpace:
    """Singular-perturbation reduction of a continuous state space to the states ``keep``.

    The other states are taken as fast and at equilibrium (``dx2/dt = 0``):
    ``Ar = A11 - A12 A22^-1 A21``, ``Br = B1 - A12 A22^-1 B2``, ``Cr = C1 - C2 A22^-1 A21``,
    ``Dr = D - C2 A22^-1 B2``. The DC gain is kept exactly; the removed states' dynamics (e.g.
    the beam's bending modes, tens of Hz, against a rigid body below 1 Hz) are lost.

    Parameters
    ----------
    system : control.StateSpace
        Continuous-time (``dt = 0``).
    keep : sequence of int
        Indices of the states kept, in the order wanted.

    Returns
    -------
    control.StateSpace
        Continuous; same input and output names.

    Raises
    ------
    InputError
        Not a continuous StateSpace, bad indices, or a singular ``A22`` (a removed state
        with an integrator or a zero eigenvalue cannot be residualised).

    Examples
    --------
    A slow and a fast lag in parallel, ``1 / (s + 1) + 100 / (s + 100)``: keeping the slow state turns the fast
    one into its static gain, a direct term of 1, and the DC gain stays 2:

    >>> full = control.ss(np.diag([-1.0, -100.0]), [[1.0], [100.0]], [[1.0, 1.0]], [[0.0]])
    >>> slow = residualise(full, [0])
    >>> slow.A.tolist(), slow.D.tolist(), float(control.dcgain(full)), float(control.dcgain(slow))
    ([[-1.0]], [[1.0]], 2.0, 2.0)
    """
    if not isinstance(system, control.StateSpace) or not control.isctime(system, strict=True):
        raise InputError(f"system must be a continuous-time python-control StateSpace, got {system!r}")
    A, B, C, D = finite_system(system)
    n = A.shape[0]
    k = list(index_tuple("keep", keep, n, "state indices"))
    r = [i for i in range(n) if i not in set(k)]
    if not r:
        return control.ss(A, B, C, D, inputs=system.input_labels, outputs=system.output_labels)
    A11, A12, A21, A22 = A[np.ix_(k, k)], A[np.ix_(k, r)], A[np.ix_(r, k)], A[np.ix_(r, r)]
    if np.linalg.cond(A22) > 1e12:
        raise InputError("the removed states' matrix A22 is singular: a removed state has a zero eigenvalue")
    X = np.linalg.solve(A22, np.hstack([A21, B[r]]))
    Ar = A11 - A12 @ X[:, : len(k)]
    Br = B[k] - A12 @ X[:, len(k) :]
    Cr = C[:, k] - C[:, r] @ X[:, : len(k)]
    Dr = D - C[:, r] @ X[:, len(k) :]
    names = [system.state_labels[i] for i in k]
    return control.ss(Ar, Br, Cr, Dr, inputs=system.input_labels, outputs=system.output_labels, states=names)


def continuous_jacobians(A_d: np.ndarray, B_d: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Continuous ``(A_c, B_c)`` whose zero-order-hold discretisation at ``h`` is ``(A_d, B_d)``.

    Parameters
    ----------
    A_d, B_d : numpy.ndarray
        Discrete Jacobians of one step.
    h : float
        Step (s).

    Returns
    -------
    tuple of numpy.ndarray
        ``A_c = log(A_d) / h`` (principal matrix logarithm) and ``B_c = (int_0^h e^{A_c s} ds)^{-1} B_d``.

    Examples
    --------
    >>> A_c, B_c = continuous_jacobians(np.array([[np.exp(-0.1)]]), np.array([[1 - np.exp(-0.1)]]), 0.1)
    >>> round(float(A_c[0, 0]), 12), round(float(B_c[0, 0]), 12)
    (-1.0, 1.0)
    """
    A_c = np.real(scipy.linalg.logm(A_d)) / h
    n = A_c.shape[0]
    # int_0^h e^{A s} ds is the top-right block of expm([[A, I], [0, 0]] h).
    block = np.zeros((2 * n, 2 * n))
    block[:n, :n] = A_c
    block[:n, n:] = np.eye(n)
    gamma = scipy.linalg.expm(block * h)[:n, n:]
    B_c = np.linalg.solve(gamma, B_d)
    return A_c, B_c
