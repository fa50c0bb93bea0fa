"""Feedback's published (simplified) nonlinear TRMS model, the reference the twin's large signals are held to.

The equations and parameters are those of PHYSICS.md (Feedback Instruments' simplified
model, as reproduced in the public TRMS literature): two rigid axes, first-order motor
lags, the quadratic asymmetric thrust ``a tau|tau| + b tau`` (a torque, N m), gravity
``Mg sin(psi)``, friction, the gyroscopic term and the lead-lag reaction torque. Pitch
``psi`` is measured from the rotors-off rest, so the flat beam sits at ``psi = asin(M1/Mg)``
for the hover torque ``M1``; :func:`pitch_step` reports angles from the flat beam.

Integrated with ``scipy.integrate.solve_ivp``, interval by interval (zero-order hold).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.optimize
from scipy.integrate import solve_ivp

__all__ = [
    "PUBLISHED",
    "REST_PITCH",
    "feedback_rhs",
    "hover",
    "gyroscopic_coupling",
    "main_thrust_torque",
    "static_pitch",
    "static_gain",
    "pitch_step",
    "StepResponse",
]

#: The rig's rest pose with the rotors off, from the flat beam (rad): Rotondo, Nejjari and Puig 2013.
REST_PITCH = -0.619

#: The published parameters (PHYSICS.md).
PUBLISHED: dict[str, float] = dict(
    I1=0.068,
    I2=0.02,
    a1=0.0135,
    b1=0.0924,
    a2=0.02,
    b2=0.09,
    Mg=0.32,
    B1psi=6e-3,
    B2psi=1e-3,
    B1phi=0.1,
    B2phi=0.01,
    Kgy=0.05,
    k1=1.1,
    k2=0.8,
    T11=1.1,
    T10=1.0,
    T21=1.0,
    T20=1.0,
    Tp=2.0,
    T0=3.5,
    kc=-0.2,
)


def _smooth_sign(v: float) -> float:
    """``sign(v)`` smoothed over 1e-3 rad/s: Coulomb friction without the chattering that stalls the integrator."""
    return float(np.tanh(v / 1e-3))


def feedback_rhs(
    t: float,
    x: np.ndarray,
    u_of_t: Callable[[float], np.ndarray],
    p: dict[str, float] = PUBLISHED,
    yaw_free: bool = True,
) -> np.ndarray:
    """Right-hand side of the published model; ``x = [psi, dpsi, phi, dphi, tau1, tau2, mr_state]``.

    With ``yaw_free=False`` the yaw axis is locked (1-DOF rig).

    Examples
    --------
    >>> x = np.zeros(7)
    >>> feedback_rhs(0.0, x, lambda t: np.zeros(2)).tolist()
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    """
    psi, dpsi, phi, dphi, tau1, tau2, mr_state = x
    u1, u2 = u_of_t(t)
    f1 = p["a1"] * tau1 * abs(tau1) + p["b1"] * tau1
    f2 = p["a2"] * tau2 * abs(tau2) + p["b2"] * tau2
    # MR = kc (T0 s + 1)/(Tp s + 1) tau1, realised as mr_state' = (tau1 - mr_state)/Tp.
    mr = p["kc"] * (p["T0"] / p["Tp"] * tau1 + (1 - p["T0"] / p["Tp"]) * mr_state)
    ddpsi = (
        f1
        - p["Mg"] * np.sin(psi)
        - p["B1psi"] * dpsi
        - p["B2psi"] * _smooth_sign(dpsi)
        - p["Kgy"] * f1 * dphi * np.cos(psi)
    ) / p["I1"]
    ddphi = (f2 - p["B1phi"] * dphi - p["B2phi"] * _smooth_sign(dphi) - mr) / p["I2"] if yaw_free else 0.0
    return np.array(
        [
            dpsi,
            ddpsi,
            dphi if yaw_free else 0.0,
            ddphi,
            (p["k1"] * u1 - p["T10"] * tau1) / p["T11"],
            (p["k2"] * u2 - p["T20"] * tau2) / p["T21"],
            (tau1 - mr_state) / p["Tp"],
        ]
    )


def hover(p: dict[str, float] = PUBLISHED) -> tuple[float, float]:
    """Main-rotor hover voltage (V) and the flat beam's pitch from rest (rad) of the 1-DOF published model.

    The flat beam is where the rotors-off pendulum is balanced by the hover thrust; its
    angle from rest is the published rest pose (0.619 rad for these parameters:
    Rotondo et al.'s -0.619 rad).
    """
    rest_angle = -REST_PITCH
    torque = p["Mg"] * np.sin(rest_angle)

    def residual(v: float) -> float:
        return float(main_thrust_torque(p["k1"] * v / p["T10"], p)) - torque

    volts = float(scipy.optimize.brentq(residual, 0.0, 10.0))
    return volts, rest_angle


def gyroscopic_coupling(p: dict[str, float] = PUBLISHED) -> float:
    """The published model's pitch torque per yaw rate at the flat hover (N m s/rad).

    Its gyroscopic term ``Kgy f1 dphi cos(psi)``, with the hover thrust torque ``f1`` and the flat beam's
    pitch from rest (:func:`hover`): ``Kgy f1 cos(psi)``.

    Examples
    --------
    >>> round(gyroscopic_coupling(), 4)
    0.0076
    """
    volts, psi = hover(p)
    return float(p["Kgy"] * main_thrust_torque(p["k1"] * volts / p["T10"], p) * np.cos(psi))


def main_thrust_torque(tau: np.ndarray | float, p: dict[str, float] = PUBLISHED) -> np.ndarray:
    """The main rotor's pitch torque ``a1 tau|tau| + b1 tau`` (N m) at the rotor state ``tau`` (``k1 V / T10`` at rest).

    Examples
    --------
    >>> round(float(main_thrust_torque(1.1 * 10.0)), 3)  # full voltage
    2.65
    """
    tau = np.asarray(tau, float)
    return p["a1"] * tau * np.abs(tau) + p["b1"] * tau


def static_pitch(delta_volts: np.ndarray | float, p: dict[str, float] = PUBLISHED) -> np.ndarray:
    """The published 1-DOF model's pitch at rest (rad from the flat beam) under a main-rotor voltage ``delta_volts``
    from its hover voltage (V).

    At rest the thrust torque balances gravity, ``f1 = Mg sin(psi)`` (the friction terms vanish): the pitch from
    the flat beam is ``asin(f1 / Mg) - psi_flat``. NaN past the fold, where the thrust torque exceeds ``Mg``: no
    pitch holds it (the beam swings up to the rig's stop).

    Parameters
    ----------
    delta_volts : float or array_like
        Offsets from the hover voltage (V).
    p : dict
        The model's parameters.

    Returns
    -------
    numpy.ndarray
        Pitch (rad), the shape of ``delta_volts``.

    Examples
    --------
    >>> static_pitch([-0.5, 0.5, 3.0]).round(3).tolist(), bool(abs(static_pitch(0.0)) < 1e-12)
    ([-0.252, 0.355, nan], True)
    """
    volts, flat = hover(p)
    ratio = main_thrust_torque(p["k1"] * (volts + np.asarray(delta_volts, float)) / p["T10"], p) / p["Mg"]
    with np.errstate(invalid="ignore"):
        return np.where(np.abs(ratio) < 1.0, np.arcsin(np.clip(ratio, -1.0, 1.0)) - flat, np.nan)


def static_gain(delta_volts: np.ndarray | float, p: dict[str, float] = PUBLISHED) -> np.ndarray:
    """The local slope (rad/V) of :func:`static_pitch`: ``f1'(tau) k1 / T10 / sqrt(Mg^2 - f1^2)``; NaN past the fold.

    Examples
    --------
    >>> round(float(static_gain(0.0)), 3)  # the published model's DC gain u1 -> pitch
    0.575
    """
    volts, _ = hover(p)
    tau = p["k1"] * (volts + np.asarray(delta_volts, float)) / p["T10"]
    f1 = main_thrust_torque(tau, p)
    with np.errstate(invalid="ignore"):
        room = np.sqrt(np.where(np.abs(f1) < p["Mg"], p["Mg"] ** 2 - f1**2, np.nan))
    return (2.0 * p["a1"] * np.abs(tau) + p["b1"]) * p["k1"] / p["T10"] / room


@dataclass(frozen=True)
class StepResponse:
    """A 1-DOF pitch response from hover (angles from the flat beam, rad; time s)."""

    time: np.ndarray
    pitch: np.ndarray

    def time_to_pass(self, angle: float) -> float:
        """First time (s) the pitch passes ``angle`` (rad, signed), linearly interpolated; NaN if never."""
        s = np.sign(angle)
        above = s * self.pitch >= abs(angle)
        if not above.any():
            return float("nan")
        i = int(np.argmax(above))
        if i == 0:
            return float(self.time[0])
        y0, y1 = s * self.pitch[i - 1], s * self.pitch[i]
        return float(self.time[i - 1] + (abs(angle) - y0) / (y1 - y0) * (self.time[i] - self.time[i - 1]))

    @property
    def peak(self) -> float:
        """Largest excursion (signed, rad)."""
        return float(self.pitch[np.argmax(np.abs(self.pitch))])

    @property
    def final(self) -> float:
        """Mean of the last 10 % of the record (rad)."""
        return float(np.mean(self.pitch[-max(1, self.pitch.size // 10) :]))


def pitch_step(
    delta_volts: float, duration: float = 20.0, sample_time: float = 0.01, p: dict[str, float] = PUBLISHED
) -> StepResponse:
    """The published 1-DOF model's pitch after a main-rotor voltage step of ``delta_volts`` from hover.

    The voltage saturates at +-10 V, as the rig's does.

    Examples
    --------
    >>> r = pitch_step(0.5)
    >>> 0.3 < r.final < 0.4
    True
    """
    v_hover, flat = hover(p)
    tau0 = p["k1"] * v_hover / p["T10"]
    x = np.array([flat, 0.0, 0.0, 0.0, tau0, 0.0, tau0])
    u = np.array([float(np.clip(v_hover + delta_volts, -10.0, 10.0)), 0.0])
    t = np.arange(0.0, duration + sample_time / 2, sample_time)
    sol = solve_ivp(feedback_rhs, (0.0, t[-1]), x, t_eval=t, args=(lambda _t: u, p, False), rtol=1e-7, atol=1e-9)
    return StepResponse(sol.t, sol.y[0] - flat)
