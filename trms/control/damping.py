"""Does a design damp the plant's mode or cancel it? The closed-loop modes of a feedback design on its model.

A feedback ``u = -K_y y`` closed around a discrete model ``G`` moves the model's poles; a lightly damped plant mode
(eq. 3.11's 0.34 Hz pitch mode, damping 0.041) may be

* **damped**: the closed-loop pole that continues it has a larger damping ratio, so the mode rings less after any
  input (a reference step, the thrust curve's quadratic part, a push, turbulence);
* **cancelled**: the controller puts zeros on the plant's poles, so the closed loop keeps a pole *at* the plant's
  mode. A reference step does not excite it (the response looks perfect on the model) but an input disturbance
  does, and it rings as long as the open plant would: what mixed-sensitivity H-infinity designs do to lightly
  damped plants (Skogestad and Postlethwaite, *Multivariable feedback control*, 2005, ch. 3.8 and 9.3).

:func:`mode_damping` follows the plant's least damped oscillatory pole (or the one nearest a named frequency) in the
s-plane (``ln z / Ts``) as the feedback ``alpha K_y`` grows from ``alpha = 0`` to 1, and reports the damping of
the closed-loop pole it becomes beside the plant's own; :data:`MIN_DAMPING` is
the design rule every controller of the comparison meets (``>= 0.1`` on the design model).
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

from trms.control.arguments import finite_system, is_discrete_dt
from trms.errors import InputError, check_in_range
from trms.modes import Mode, mode_of_eigenvalue

__all__ = ["MIN_DAMPING", "ModeDamping", "closed_loop_modes", "discrete_modes", "mode_damping"]

#: Closed-loop damping ratio (-) a design must give the plant's lightly damped mode on its design model.
MIN_DAMPING = 0.1
#: Steps of the feedback gain along which :func:`mode_damping` follows the plant's mode.
_CONTINUATION_STEPS = 100


@dataclass(frozen=True)
class ModeDamping:
    """The plant's mode and the closed-loop mode that continues it.

    Attributes
    ----------
    plant : Mode
        The open-loop mode (of the design model).
    closed : Mode
        The closed-loop pole it becomes, followed as the feedback grows from 0 to the design's (damping 1 where the
        mode became a real pole).
    least : Mode
        The least damped pole of the whole closed loop (it may belong to another mode).

    Examples
    --------
    >>> from trms.modes import mode_of_eigenvalue
    >>> closed = mode_of_eigenvalue(-0.3 + 2.2j)
    >>> m = ModeDamping(mode_of_eigenvalue(-0.09 + 2.15j), closed, closed)
    >>> round(m.closed.damping, 3), m.meets()
    (0.135, True)
    """

    plant: Mode
    closed: Mode
    least: Mode

    def meets(self, minimum: float = MIN_DAMPING) -> bool:
        """Whether the closed-loop mode's damping ratio is at least ``minimum`` (-).

        Examples
        --------
        >>> from trms.modes import mode_of_eigenvalue
        >>> m = mode_of_eigenvalue(-0.09 + 2.15j)
        >>> ModeDamping(m, m, m).meets()  # a cancelled mode keeps the plant's damping
        False
        """
        return bool(self.closed.damping >= minimum)

    def to_dict(self) -> dict[str, float]:
        """Frequencies (Hz) and damping ratios (-) as a plain dict (for tables and JSON).

        Examples
        --------
        >>> from trms.modes import mode_of_eigenvalue
        >>> m = mode_of_eigenvalue(-0.09 + 2.15j)
        >>> sorted(ModeDamping(m, m, m).to_dict())
        ['closed_damping', 'closed_hz', 'least_damping', 'least_hz', 'plant_damping', 'plant_hz']
        """
        return {
            "plant_hz": self.plant.frequency_hz,
            "plant_damping": self.plant.damping,
            "closed_hz": self.closed.frequency_hz,
            "closed_damping": self.closed.damping,
            "least_hz": self.least.frequency_hz,
            "least_damping": self.least.damping,
        }


def discrete_modes(system: control.StateSpace) -> list[Mode]:
    """The oscillatory modes of a discrete system's poles (``s = ln z / Ts``), sorted by frequency.

    Poles on the negative real axis (``z < 0``) map to the Nyquist frequency and are listed as modes there.

    Parameters
    ----------
    system : control.StateSpace
        Discrete, ``dt > 0`` (s).

    Returns
    -------
    list of Mode

    Raises
    ------
    InputError
        Not a discrete StateSpace.

    Examples
    --------
    A 1 Hz mode of damping 0.05 sampled at 0.1 s comes back as such:

    >>> s = complex(-0.05 * 2 * np.pi, 2 * np.pi * np.sqrt(1 - 0.05**2))
    >>> z = np.exp(s * 0.1)
    >>> A = [[2 * z.real, -abs(z) ** 2], [1.0, 0.0]]
    >>> modes = discrete_modes(control.ss(A, [[1], [0]], [[0, 1]], 0, 0.1))
    >>> [(round(m.frequency_hz, 6), round(m.damping, 6)) for m in modes]
    [(1.0, 0.05)]
    """
    if not isinstance(system, control.StateSpace) or not is_discrete_dt(system.dt):
        raise InputError(f"system must be a discrete python-control StateSpace (dt > 0 s), got {system!r:.60}")
    return [m for m in _pole_modes(system) if m.eigenvalue.imag > 0.0]


def _pole_modes(system: control.StateSpace) -> list[Mode]:
    """Every pole of a discrete system with ``Im z >= 0`` and ``z != 0`` as a continuous :class:`Mode`, by frequency
    (a real positive pole has damping 1 and no imaginary part)."""
    A = finite_system(system, "system")[0]
    ts = float(system.dt)
    out = []
    for z in np.linalg.eigvals(A):
        if abs(z) == 0.0 or z.imag < 0.0:
            continue
        out.append(mode_of_eigenvalue(complex(np.log(complex(z))) / ts))
    return sorted(out, key=lambda m: m.frequency_hz)


def closed_loop_modes(model: control.StateSpace, feedback: control.StateSpace) -> list[Mode]:
    """The oscillatory modes of ``model`` under the negative feedback ``u = -feedback y``.

    Parameters
    ----------
    model : control.StateSpace
        Discrete design model (deviation V in, rad out), ``D = 0``.
    feedback : control.StateSpace or array_like
        The controller from the measured outputs to the inputs, ``K_y`` (``u = ... - K_y y``), at the model's sample
        time; a static gain (``m x p``) is allowed.

    Returns
    -------
    list of Mode

    Examples
    --------
    A static gain of 5 on a sampled oscillator ``1 / (s^2 + 0.2 s + 4)`` raises its frequency from
    ``sqrt(4) / 2 pi`` = 0.318 Hz to about ``sqrt(4 + 5) / 2 pi`` = 0.477 Hz (0.475 Hz under the sampling):

    >>> G = control.c2d(control.ss(control.tf([1.0], [1.0, 0.2, 4.0])), 0.1)
    >>> [round(m.frequency_hz, 3) for m in closed_loop_modes(G, control.ss([], [], [], [[5.0]], 0.1))]
    [0.475]
    """
    loop = control.feedback(model, feedback)
    return discrete_modes(loop)


def mode_damping(
    model: control.StateSpace, feedback: control.StateSpace, frequency_hz: float | None = None
) -> ModeDamping:
    """The plant's mode on ``model`` and the closed-loop mode that continues it (module docstring).

    Parameters
    ----------
    model : control.StateSpace
        Discrete design model, ``D = 0``.
    feedback : control.StateSpace
        ``K_y`` (``u = ... - K_y y``) at the model's sample time.
    frequency_hz : float, optional
        The plant mode to follow: the oscillatory open-loop mode nearest this frequency (Hz); default the least
        damped one.

    Returns
    -------
    ModeDamping

    Raises
    ------
    InputError
        A model without an oscillatory mode; a frequency outside ``(0, Nyquist]``.

    Examples
    --------
    Rate-like feedback damps a sampled oscillator of damping 0.05; a controller that cancels the mode leaves it:

    >>> G = control.c2d(control.ss(control.tf([1.0], [1.0, 0.2, 4.0])), 0.1)
    >>> d = mode_damping(G, control.ss(control.tf([10.0, -10.0], [1.0, 0.0], 0.1)))
    >>> round(d.plant.damping, 3), bool(d.closed.damping > 0.2)
    (0.05, True)
    """
    open_modes = discrete_modes(model)
    if not open_modes:
        raise InputError("model has no oscillatory mode to follow")
    if frequency_hz is None:
        plant = min(open_modes, key=lambda m: m.damping)
    else:
        f = check_in_range("frequency_hz", frequency_hz, 0.0, 0.5 / float(model.dt), unit=" Hz", low_open=True)
        plant = min(open_modes, key=lambda m: abs(m.frequency_hz - f))
    closed = _pole_modes(control.feedback(model, feedback))
    least = min(closed, key=lambda m: m.damping)
    return ModeDamping(plant, _follow(model, feedback, plant), least)


def _follow(model: control.StateSpace, feedback: control.StateSpace, plant: Mode) -> Mode:
    """The closed-loop pole the plant's mode becomes: followed along the feedback ``alpha K_y``, ``alpha`` from 0
    to 1 in :data:`_CONTINUATION_STEPS` steps, each step taking the pole nearest the last (a pole that merely lies
    nearest at ``alpha = 1`` may be another mode's)."""
    A, B, C, D = finite_system(model, "model")
    K = control.ss(feedback)
    Ak, Bk, Ck, Dk = (np.asarray(m, float) for m in (K.A, K.B, K.C, K.D))
    if np.any(D != 0):
        raise InputError("model must be strictly proper (D = 0) to follow its mode under feedback")
    ts = float(model.dt)
    current = plant.eigenvalue
    for alpha in np.linspace(0.0, 1.0, _CONTINUATION_STEPS + 1)[1:]:
        # u = -alpha (Ck xk + Dk y), xk+ = Ak xk + Bk y, y = C x
        Acl = np.block([[A - alpha * B @ Dk @ C, -alpha * B @ Ck], [Bk @ C, Ak]])
        z = np.linalg.eigvals(Acl)
        z = z[(z.imag >= 0.0) & (z != 0.0)]
        s = np.log(z.astype(complex)) / ts
        current = complex(s[np.argmin(np.abs(s - current))])
    return mode_of_eigenvalue(current)
