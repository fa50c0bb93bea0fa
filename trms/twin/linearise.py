"""Linearisation of a MuJoCo model at a state, and its oscillatory modes.

The discrete transition Jacobians come from ``mujoco.mjd_transitionFD`` (central
differences) taken with a temporarily reduced time step, and are mapped to continuous
time exactly: ``A_c = log(A_d) / h`` and ``B_c = (int_0^h e^{A_c s} ds)^{-1} B_d``. With
``h = 1e-4`` s the integrator's own bias on the slowest and fastest modes of the twin is
below 1e-4 relative (see the tests: a pendulum comes out at ``sqrt(g/l)``).

State ordering: ``[dq (nv tangent of qpos), qvel (nv), act (na)]``.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import mujoco
import numpy as np
import scipy.linalg

from ..modes import Mode

__all__ = ["Mode", "transition_jacobians", "continuous_jacobians", "oscillatory_modes", "state_names"]


def state_names(model: mujoco.MjModel) -> list[str]:
    """Names of the linearisation state: joint angles, joint rates, actuator activations."""
    dofs = []
    for i in range(model.nv):
        j = model.dof_jntid[i]
        dofs.append(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or f"dof{i}")
    acts = []
    for i in range(model.nu):
        if model.actuator_dyntype[i] != mujoco.mjtDyn.mjDYN_NONE:
            acts.append(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, i) or f"act{i}")
    return dofs + [f"{n}_rate" for n in dofs] + [f"{n}_activation" for n in acts]


def transition_jacobians(
    model: mujoco.MjModel, data: mujoco.MjData, timestep: float = 1e-4, eps: float = 1e-6
) -> tuple[np.ndarray, np.ndarray, float]:
    """Discrete-time Jacobians ``(A_d, B_d)`` of one step of length ``timestep`` at ``data``'s state.

    ``model`` and ``data`` are not modified (a copy of the data is used and the model's
    time step is restored).

    Returns
    -------
    A_d, B_d : numpy.ndarray
        Shapes ``(nx, nx)`` and ``(nx, nu)``, ``nx = 2 nv + na``.
    h : float
        The time step used (s).
    """
    d = copy.copy(data)
    nx = 2 * model.nv + model.na
    A = np.zeros((nx, nx))
    B = np.zeros((nx, model.nu))
    saved = model.opt.timestep
    try:
        model.opt.timestep = timestep
        mujoco.mj_forward(model, d)
        mujoco.mjd_transitionFD(model, d, eps, True, A, B, None, None)
    finally:
        model.opt.timestep = saved
    return A, B, timestep


def continuous_jacobians(A_d: np.ndarray, B_d: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Continuous ``(A_c, B_c)`` whose zero-order-hold discretisation at ``h`` is ``(A_d, B_d)``.

    Parameters
    ----------
    A_d, B_d : numpy.ndarray
        Discrete Jacobians of one step.
    h : float
        Step (s).
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


def oscillatory_modes(A_c: np.ndarray, names: list[str] | None = None, min_frequency_hz: float = 1e-4) -> list[Mode]:
    """The oscillatory modes (complex eigenvalue pairs) of ``A_c``, sorted by frequency.

    Parameters
    ----------
    A_c : numpy.ndarray
        Continuous state matrix.
    names : list of str, optional
        State names; the mode's ``dominant`` coordinate is taken from the first half of
        the position block (``nv`` entries) when given.
    min_frequency_hz : float
        Imaginary parts below this (Hz) count as real eigenvalues.
    """
    lam, vec = np.linalg.eig(A_c)
    modes = []
    for i in np.flatnonzero(lam.imag > 2 * np.pi * min_frequency_hz):
        wn = abs(lam[i])
        dominant = ""
        if names is not None:
            nv = sum(1 for n in names if not n.endswith("_rate") and not n.endswith("_activation"))
            shape = np.abs(vec[:nv, i])
            dominant = names[int(np.argmax(shape))]
        modes.append(Mode(float(wn / (2 * np.pi)), float(-lam[i].real / wn), complex(lam[i]), dominant))
    return sorted(modes, key=lambda m: m.frequency_hz)
