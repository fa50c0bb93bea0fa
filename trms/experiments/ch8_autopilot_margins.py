"""Margins of chapter 8's 2-DOF autopilot at each plant input (:mod:`trms.experiments.ch8_mimo_lqg`).

The loop is designed on the reduced model and closed around the twin's full linearisation at hover (bending states
and transport delay included), broken at each plant input with the other loop closed; :data:`GAIN_MARGIN_DB` and
:data:`PHASE_MARGIN_DEG` are adequate. The scan (:func:`margin_scan`) reads them with the control weights scaled by
:data:`~trms.experiments.ch8_mimo_lqg.R_SCALES`.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass

import control
import numpy as np

from trms.control.lqg import LQGController
from trms.experiments.ch8_mimo_lqg import R_SCALES, AutopilotWeights, controllers

__all__ = ["GAIN_MARGIN_DB", "PHASE_MARGIN_DEG", "InputMargins", "input_margins", "margin_scan", "shipped_margin_scan"]

#: Adequate margins at each plant input: the classical gain margin (dB, a factor 2 up or down) and
#: phase margin (deg).
GAIN_MARGIN_DB = 6.0
PHASE_MARGIN_DEG = 30.0


@dataclass(frozen=True)
class InputMargins:
    """Margins of the MIMO LQG loop at each plant input for one scale of its control weights.

    Attributes
    ----------
    scale : float
        ``s`` of ``R = s diag(CONTROL_WEIGHTS)`` (1: the design).
    gain_margin_db, phase_margin_deg : tuple of float
        Per input (u1, u2), the loop broken there with the other loop closed: the smallest factor (dB),
        up or down, that takes the loop to -1 where it crosses the negative real axis, and the
        smallest distance (deg) of its phase from -180 deg where its gain crosses 1 (``inf`` where
        it never does).
    stable : bool
        The nominal closed loop is stable.
    """

    scale: float
    gain_margin_db: tuple[float, float]
    phase_margin_deg: tuple[float, float]
    stable: bool

    @property
    def adequate(self) -> bool:
        """Stable, with :data:`GAIN_MARGIN_DB` and :data:`PHASE_MARGIN_DEG` at both inputs.

        Examples
        --------
        >>> InputMargins(1.0, (7.0, 9.0), (35.0, 60.0), True).adequate
        True
        """
        return (
            self.stable
            and min(self.gain_margin_db) >= GAIN_MARGIN_DB
            and min(self.phase_margin_deg) >= PHASE_MARGIN_DEG
        )


def _siso_margins(loop: control.StateSpace) -> tuple[float, float]:
    """Gain margin (dB, up or down) and phase margin (deg) of a discrete SISO loop.

    The loop is evaluated on a log grid up to the Nyquist frequency; each crossing (of ``|L| = 1``, or
    of the real axis) is located by linear interpolation between the two grid points around it.
    """
    w = np.geomspace(1e-4, np.pi / loop.dt, 4000)
    h = np.asarray(loop(np.exp(1j * w * loop.dt))).ravel()

    def at(k: int, x: np.ndarray) -> complex:  # the loop where x crosses zero between k and k + 1
        t = x[k] / (x[k] - x[k + 1])
        return complex(h[k] + t * (h[k + 1] - h[k]))

    log_mag = np.log(np.abs(h))
    gain_cross = [at(int(k), log_mag) for k in np.flatnonzero(np.diff(np.sign(log_mag)) != 0)]
    real_axis = [at(int(k), h.imag) for k in np.flatnonzero(np.diff(np.sign(h.imag)) != 0)]
    if h.imag[-1] == 0.0 or abs(h.imag[-1]) < 1e-12 * abs(h[-1]):  # at Nyquist a discrete loop is real
        real_axis.append(complex(h[-1]))
    pm = min((180.0 - abs(np.degrees(np.angle(c))) for c in gain_cross), default=float("inf"))
    gm = min((abs(20.0 * np.log10(abs(c.real))) for c in real_axis if c.real < 0), default=float("inf"))
    return float(gm), float(pm)


def input_margins(
    plant_model: control.StateSpace,
    design_model: control.StateSpace,
    scale: float = 1.0,
    gains: AutopilotWeights | None = None,
) -> InputMargins:
    """Break the MIMO LQG loop at each plant input in turn (the other loop closed) and read its margins.

    The compensator (:meth:`trms.control.lqg.LQGController.compensator`) maps both measurements to
    both inputs; the loop at the plant inputs is ``L = -C_y(z) G(z)`` (2 x 2).

    Parameters
    ----------
    plant_model : control.StateSpace
        Discrete 2-DOF plant the loop is closed around (the twin's linearisation), same sample time.
    design_model : control.StateSpace
        The model the LQG is designed on (:func:`trms.worlds.design_model`).
    scale : float
        ``R = scale diag(CONTROL_WEIGHTS)``.
    gains : AutopilotWeights, optional
        Other weights than the shipped ones.

    Examples
    --------
    >>> from trms.worlds import design_model
    >>> m = design_model("2dof")
    >>> input_margins(m, m).adequate
    True
    """
    ctrl = controllers(design_model, scale, gains=gains)["MIMO LQG"]
    assert isinstance(ctrl, LQGController)
    comp = ctrl.compensator()
    n_ref = comp.ninputs - plant_model.noutputs
    c_y = control.ss(comp.A, comp.B[:, n_ref:], comp.C, comp.D[:, n_ref:], comp.dt)
    plant = control.ss(plant_model.A, plant_model.B, plant_model.C, plant_model.D, plant_model.dt)
    loop = control.series(plant, -c_y)
    closed = control.feedback(loop, np.eye(2), sign=-1)
    stable = bool(np.all(np.abs(control.poles(closed)) < 1.0))
    gms, pms = [], []
    for i in range(2):
        other = np.zeros((2, 2))
        other[1 - i, 1 - i] = 1.0
        half = control.feedback(loop, other, sign=-1)
        gm, pm = _siso_margins(control.ss(half.A, half.B[:, [i]], half.C[[i]], half.D[[i]][:, [i]], half.dt))
        gms.append(gm)
        pms.append(pm)
    return InputMargins(float(scale), (gms[0], gms[1]), (pms[0], pms[1]), stable)


def margin_scan(
    plant_model: control.StateSpace, design_model: control.StateSpace, scales: Sequence[float] = R_SCALES
) -> list[InputMargins]:
    """:func:`input_margins` for every scale of ``scales``.

    Examples
    --------
    >>> from trms.worlds import design_model
    >>> m = design_model("2dof")
    >>> [s.scale for s in margin_scan(m, m, (1.0, 3.0))]
    [1.0, 3.0]
    """
    return [input_margins(plant_model, design_model, s) for s in scales]


@functools.lru_cache(maxsize=4)
def shipped_margin_scan(sample_time: float = 0.1) -> tuple[InputMargins, ...]:
    """:func:`margin_scan` over :data:`R_SCALES` of the loop designed on ``design_model("2dof", sample_time)`` and
    closed around the shipped twin's ``Twin("2dof", sample_time).linearise().discrete`` (computed once per process
    and sample time)."""
    from trms.twin import Twin
    from trms.worlds import design_model

    plant = Twin("2dof", sample_time).linearise().discrete
    return tuple(margin_scan(plant, design_model("2dof", sample_time)))
