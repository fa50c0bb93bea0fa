"""Linearisation of a MuJoCo model at a state, and its oscillatory modes.

The discrete transition Jacobians come from ``mujoco.mjd_transitionFD`` (central
differences) taken with a temporarily reduced time step and the ``implicitfast`` integrator, whatever the
model's own (with the twin's ``discrete`` integrator, whose step also takes the stiffness implicitly, the same
construction gave its 0.34 Hz pitch mode a damping ratio of 0.000 instead of 0.041: that step's O(h^2 K) term is
not small against a slow mode's damping in ``log(A_d) / h``), and are mapped to continuous time exactly:
``A_c = log(A_d) / h`` and ``B_c = (int_0^h e^{A_c s} ds)^{-1} B_d``. With ``h = 1e-4`` s the integrator's own
bias on the slowest and fastest modes of the twin is below 1e-4 relative (see the tests: a pendulum comes out
at ``sqrt(g/l)``).

State ordering: ``[dq (nv tangent of qpos), qvel (nv), act (na)]``.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np
import scipy.linalg

from trms.modes import Mode

if TYPE_CHECKING:
    import control

__all__ = ["Linearisation", "transition_jacobians", "oscillatory_modes", "state_names", "c2d_with_delay"]


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
    time step and integrator are restored). The step is taken with ``implicitfast`` (see the module docstring).

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
    saved = model.opt.timestep, model.opt.integrator
    try:
        model.opt.timestep = timestep
        model.opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
        mujoco.mj_forward(model, d)
        mujoco.mjd_transitionFD(model, d, eps, True, A, B, None, None)
    finally:
        model.opt.timestep, model.opt.integrator = saved
    return A, B, timestep


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


def c2d_with_delay(system: control.StateSpace, sample_time: float, delay: float) -> control.StateSpace:
    """Zero-order-hold discretisation of a continuous system whose inputs are delayed by ``delay`` s.

    The delay need not be a whole number of samples: with ``delay = n h + e`` (``0 <= e < h``)
    the held input switches ``e`` seconds into each interval, so
    ``x[k+1] = Phi x[k] + G0 u[k-n] + G1 u[k-n-1]`` with
    ``G0 = int_0^{h-e} e^{A s} ds B`` and ``G1 = e^{A (h-e)} int_0^e e^{A s} ds B``
    (the modified z-transform). The past inputs become extra states, appended after the
    system's own (newest first).

    Parameters
    ----------
    system : control.StateSpace
        Continuous, strictly proper.
    sample_time : float
        h (s).
    delay : float
        Input transport delay (s), >= 0.

    Returns
    -------
    control.StateSpace
        Discrete, same inputs and outputs.

    Examples
    --------
    >>> import control
    >>> g = control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]])
    >>> d = c2d_with_delay(g, 0.1, 0.25)
    >>> d.nstates, round(float(control.dcgain(d)), 12)
    (4, 1.0)
    """
    import control

    A = np.asarray(system.A, float)
    B = np.asarray(system.B, float)
    C = np.asarray(system.C, float)
    D = np.asarray(system.D, float)
    h = float(sample_time)
    if delay < 0 or not np.isfinite(delay):
        raise ValueError(f"delay = {delay!r} s must be finite and >= 0")
    n = int(np.floor(delay / h + 1e-9))
    e = max(0.0, delay - n * h)
    if e < 1e-9 * h:
        e = 0.0
    nx, nu = B.shape

    def integral(t: float) -> tuple[np.ndarray, np.ndarray]:
        block = np.zeros((nx + nu, nx + nu))
        block[:nx, :nx] = A * t
        block[:nx, nx:] = B * t
        m = scipy.linalg.expm(block)
        return m[:nx, :nx], m[:nx, nx:]

    phi, _ = integral(h)
    phi_rest, g0 = integral(h - e)
    _, g_e = integral(e)
    g1 = phi_rest @ g_e
    blocks = n + (1 if e > 0 else 0)  # stored inputs u[k-1] ... u[k-blocks]
    if blocks == 0:
        return control.ss(
            phi, g0, C, D, h, inputs=system.input_labels, outputs=system.output_labels, states=system.state_labels
        )
    N = nx + blocks * nu
    Ad = np.zeros((N, N))
    Bd = np.zeros((N, nu))
    Ad[:nx, :nx] = phi
    # u[k-n] enters with G0 and u[k-n-1] with G1; u[k-j] is stored block j-1 (j >= 1).
    if n == 0:
        Bd[:nx] = g0
    else:
        Ad[:nx, nx + (n - 1) * nu : nx + n * nu] = g0
    if e > 0:
        Ad[:nx, nx + n * nu : nx + (n + 1) * nu] = g1
    Bd[nx : nx + nu] = np.eye(nu)
    for j in range(1, blocks):
        Ad[nx + j * nu : nx + (j + 1) * nu, nx + (j - 1) * nu : nx + j * nu] = np.eye(nu)
    Cd = np.hstack([C, np.zeros((C.shape[0], blocks * nu))])
    Dd = D if n == 0 else np.zeros_like(D)
    past = [f"{name}[k-{j}]" for j in range(1, blocks + 1) for name in system.input_labels]
    return control.ss(
        Ad,
        Bd,
        Cd,
        Dd,
        h,
        inputs=system.input_labels,
        outputs=system.output_labels,
        states=[*system.state_labels, *past],
    )


@dataclass(frozen=True)
class Linearisation:
    """The twin linearised at its operating point, in deviation coordinates.

    Attributes
    ----------
    continuous : control.StateSpace
        ``dx/dt = A x + B du(t - input_delay)``, ``dy = C x``; inputs in V, outputs in rad.
        The transport delay is not part of it (a state space has none).
    discrete : control.StateSpace
        Zero-order-hold discretisation at the twin's sample time, the delay included exactly
        (past inputs appended as states: :func:`~trms.twin.linearise.c2d_with_delay`).
    state_names : list of str
        Names of the continuous states (the spin angles of the rotors, which nothing
        depends on, are left out).
    input_delay : float
        The rotors' transport delay (s).
    """

    continuous: control.StateSpace
    discrete: control.StateSpace
    state_names: list[str]
    input_delay: float = 0.0

    def discretise(self, sample_time: float) -> control.StateSpace:
        """The zero-order-hold model at ``sample_time`` (s), transport delay included."""
        return c2d_with_delay(self.continuous, sample_time, self.input_delay)
