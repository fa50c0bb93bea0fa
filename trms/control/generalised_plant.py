"""The generalised plant of the mixed-sensitivity H-infinity problem with a disturbance at the plant input.

:func:`trms.control.hinf.design_mixsyn` weights ``S``, ``K S`` and ``T`` (python-control's ``mixsyn``); with an
input-disturbance weight ``Wd`` it adds the blocks through which a disturbance at the plant input reaches the
weighted errors (:func:`disturbance_plant`), built here as one state space and solved by ``hinfsyn``.
"""

from __future__ import annotations

import control
import numpy as np

__all__ = ["disturbance_plant"]


def disturbance_plant(plant: control.StateSpace, W1: object, W2: object, W3: object, Wd: object) -> control.StateSpace:
    """The generalised plant of the mixed-sensitivity problem with an input-disturbance channel.

    Exogenous inputs ``[r, d]`` (the reference, ``p``, and the disturbance, ``m``), then the controls ``u``
    (``m``); outputs ``[z1, z2, z3]`` (``z3`` only with ``W3``), then the measured error ``e = r - y`` (``p``).
    The plant is driven by ``u + Wd d``; ``z1 = W1 e``, ``z2 = W2 u``, ``z3 = W3 y``. Its closed loop with
    ``u = K e`` maps ``r`` to ``[W1 S; W2 K S; W3 T]`` (the ``mixsyn`` problem) and ``d`` to
    ``[-W1 S G Wd; -W2 K S G Wd; W3 S G Wd]``: a controller that cancels a lightly damped plant pole leaves it in
    ``S G`` and pays for it in ``gamma``.

    Parameters
    ----------
    plant : control.StateSpace
        Continuous, ``p`` outputs and ``m = p`` inputs.
    W1, W2, W3, Wd : control.LTI or None
        Continuous, stable weights (``W1`` and ``Wd`` required), ``p x p`` each.

    Returns
    -------
    control.StateSpace
        Continuous, inputs ``2p + p``, outputs ``(2 or 3) p + p``.

    Examples
    --------
    With ``K = 0`` the disturbance reaches ``z1`` as ``-W1 G Wd``:

    >>> s = control.tf("s")
    >>> P = disturbance_plant(control.ss(1 / (s + 1)), control.tf([2.0], [1.0]), control.tf([0.1], [1.0]), None,
    ...                       control.tf([0.5], [1.0]))
    >>> P.ninputs, P.noutputs, round(float(control.dcgain(P)[0, 1]), 6)
    (3, 3, -1.0)
    """
    G = control.ss(plant)
    p, m = G.noutputs, G.ninputs
    parts = [control.ss(w) for w in (W1, W2, Wd)]
    w3 = None if W3 is None else control.ss(W3)
    blocks = [G] + parts + ([w3] if w3 is not None else [])
    sizes = [b.nstates for b in blocks]
    n = sum(sizes)
    off = np.cumsum([0] + sizes)
    g, w1, w2, wd = blocks[:4]
    nz = 2 * p + (p if w3 is not None else 0)
    A = np.zeros((n, n))
    B = np.zeros((n, p + m + m))  # [r, d, u]
    C = np.zeros((nz + p, n))
    D = np.zeros((nz + p, p + m + m))
    r_, d_, u_ = slice(0, p), slice(p, p + m), slice(p + m, p + 2 * m)
    sg, s1, s2, sd = (slice(off[i], off[i + 1]) for i in range(4))
    # disturbance filter: xd' = Ad xd + Bd d, dd = Cd xd + Dd d; plant input ug = u + dd
    A[sd, sd], B[sd, d_] = wd.A, wd.B
    ug_x = np.zeros((m, n))
    ug_x[:, sd] = wd.C
    ug_w = np.zeros((m, p + 2 * m))
    ug_w[:, d_], ug_w[:, u_] = wd.D, np.eye(m)
    # plant: xg' = Ag xg + Bg ug, y = Cg xg + Dg ug
    A[sg, sg] = g.A
    A[sg] += g.B @ ug_x
    B[sg] += g.B @ ug_w
    y_x = np.zeros((p, n))
    y_x[:, sg] = g.C
    y_x += g.D @ ug_x
    y_w = g.D @ ug_w
    e_x, e_w = -y_x, -y_w.copy()
    e_w[:, r_] += np.eye(p)
    # W1 on e, W2 on u, W3 on y
    A[s1] += w1.B @ e_x
    A[s1, s1] += w1.A
    B[s1] += w1.B @ e_w
    C[:p], D[:p] = w1.D @ e_x, w1.D @ e_w
    C[:p, s1] += w1.C
    A[s2, s2], B[s2, u_] = w2.A, w2.B
    C[p : 2 * p, s2], D[p : 2 * p, u_] = w2.C, w2.D
    if w3 is not None:
        s3 = slice(off[4], off[5])
        A[s3] += w3.B @ y_x
        A[s3, s3] += w3.A
        B[s3] += w3.B @ y_w
        C[2 * p : 3 * p], D[2 * p : 3 * p] = w3.D @ y_x, w3.D @ y_w
        C[2 * p : 3 * p, s3] += w3.C
    C[nz:], D[nz:] = e_x, e_w
    return control.ss(A, B, C, D)
