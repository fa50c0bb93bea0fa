"""The ambient stage: the rig's rotor-wash turbulence and electronics noise, fitted to its motion at rest.

Two figures of the rig fix two parameters:

* the pitch RMS at hover with constant inputs (:data:`~trms.measurement.protocol.HOVER_PROTOCOL`) is set
  by the main rotor's turbulence: the twin is linear there, so the true pitch RMS is proportional to its
  standard deviation, and the measured RMS adds the electronics noise and the encoder's quantisation
  (``RMS^2 = alpha sigma^2 + noise^2 + q^2 / 12``);
* the one-step residual variance of a 4th-order ARMAX on ch. 5's training experiment
  (:data:`~trms.measurement.protocol.RESIDUAL_PROTOCOL`, Table 5.1) is set by the pitch electronics
  noise (the ARMAX's noise model absorbs a smooth turbulence; white noise it cannot), nearly linearly in its
  variance.

Each evaluation runs both protocols at the fit seeds (:data:`~trms.measurement.protocol.FIT_SEEDS`, the
same realisations every time, so the relations above hold run to run). The first two evaluations (the
current noise and none) give the residual variance's line in the noise variance, and every evaluation
gives ``alpha``; the solution of both relations is evaluated next, until both figures lie within
:data:`SOLVED` of their aims or :data:`MAX_EVALUATIONS` ran. The tail rotor's turbulence has no figure of its
own: the room air's fluctuation acts on each rotor's disc, so it is the main rotor's scaled by the ratio of the
two discs' areas (the shields' radii, geoms ``tail_shield`` and ``main_shield``).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from trms.calibration.target_kinds import AmbientTarget
from trms.measurement.protocol import (
    FIT_SEEDS,
    HOVER_PROTOCOL,
    RESIDUAL_PROTOCOL,
    armax_residual_variance,
    hover_rms,
    repeated_records,
)
from trms.twin.parameters import PARAMETERS, read_parameters, with_parameters
from trms.twin.twin import Twin

__all__ = ["AMBIENT_PARAMETERS", "AmbientFit", "fit_ambient", "measure_ambient", "tail_turbulence"]

#: The parameters of the ambient stage.
AMBIENT_PARAMETERS = ("main_turbulence", "tail_turbulence", "pitch_encoder_noise")
#: Largest relative miss of the hover RMS and of the residual variance from their aims for the stage to stop.
SOLVED = 0.05
#: Most evaluations (each runs both protocols at the fit seeds).
MAX_EVALUATIONS = 5


@dataclass
class AmbientFit:
    """Result of :func:`fit_ambient`.

    Attributes
    ----------
    values : dict of str to float
        The fitted :data:`AMBIENT_PARAMETERS`.
    hover_rms : float
        Measured pitch RMS at hover at the fit seeds (rad), with ``values``.
    residual_variance : float
        Measured ARMAX residual variance (rad^2), with ``values``.
    evaluations : int
        Runs of both protocols at the fit seeds.
    converged : bool
        Whether both figures came within :data:`SOLVED` of their aims.

    Examples
    --------
    >>> fit = AmbientFit({"main_turbulence": 0.02}, 0.0045, 8.9e-6, 3, True)
    >>> fit.converged, fit.hover_rms
    (True, 0.0045)
    """

    values: dict[str, float]
    hover_rms: float
    residual_variance: float
    evaluations: int
    converged: bool


def tail_turbulence(spec: mujoco.MjSpec, main: float) -> float:
    """The tail rotor's turbulence (N): ``main`` times the ratio of the tail to the main rotor's disc area (the
    shields' radii).

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> round(tail_turbulence(load_spec(), 1.0), 3)  # (0.10 / 0.155)^2
    0.416
    """
    main_r, tail_r = (float(np.ravel(spec.geom(g).size)[0]) for g in ("main_shield", "tail_shield"))
    return float(main * (tail_r / main_r) ** 2)


def measure_ambient(spec: mujoco.MjSpec, seeds: tuple[int, ...] = FIT_SEEDS) -> tuple[float, float]:
    """The hover pitch RMS (rad, averaged over the runs) and the ARMAX residual variance (rad^2, averaged) at
    ``seeds``.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The model.
    seeds : tuple of int
        Seeds of the runs of :data:`~trms.measurement.protocol.HOVER_PROTOCOL` and
        :data:`~trms.measurement.protocol.RESIDUAL_PROTOCOL`.

    Returns
    -------
    (float, float)
        Hover pitch RMS (rad) and one-step residual variance of the 4th-order ARMAX (rad^2).

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> rms, variance = measure_ambient(load_spec(), seeds=(0,))
    >>> 0.001 < rms < 0.01, 1e-6 < variance < 1e-4
    (True, True)
    """
    hover = repeated_records(spec, HOVER_PROTOCOL, seeds)
    residual = repeated_records(spec, RESIDUAL_PROTOCOL, seeds)
    return hover_rms(hover, "pitch"), float(np.mean([armax_residual_variance(r) for r in residual]))


def fit_ambient(spec: mujoco.MjSpec, target: AmbientTarget, seeds: tuple[int, ...] = FIT_SEEDS) -> AmbientFit:
    """Fit the main rotor's turbulence and the pitch electronics noise to ``target`` (module docstring).

    The hover RMS aims at the middle of its range, the residual variance at its value.

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> from trms import reference
    >>> fit = fit_ambient(load_spec(), AmbientTarget(reference.HOVER_PITCH_RMS, 8.93e-6))
    >>> 0.003 <= fit.hover_rms <= 0.006
    True
    """
    aim_rms, aim_var = 0.5 * sum(target.hover_rms), target.residual_variance
    q = 2 * np.pi / Twin("1dof", 0.1, spec=spec).encoder.counts_per_rev
    floor = q * q / 12.0
    lo_s, hi_s = PARAMETERS["main_turbulence"].bounds
    lo_n, hi_n = PARAMETERS["pitch_encoder_noise"].bounds
    values = read_parameters(spec, AMBIENT_PARAMETERS)
    sigma, noise = values["main_turbulence"] or 1e-3, values["pitch_encoder_noise"]
    seen: list[tuple[float, float, float]] = []  # (noise^2, residual variance), per evaluation

    def evaluate(sigma: float, noise: float, exact: dict[str, float] | None = None) -> tuple[float, float, dict]:
        vals = exact or {
            "main_turbulence": sigma,
            "tail_turbulence": tail_turbulence(spec, sigma),
            "pitch_encoder_noise": noise,
        }
        rms, var = measure_ambient(with_parameters(spec, vals), seeds)
        seen.append((noise * noise, var, rms))
        return rms, var, vals

    # The start as it is (its tail turbulence as stored, not recomputed to the last digit): a start that is solved
    # is returned unchanged, the same model.
    rms, var, vals = evaluate(sigma, noise, values if values["main_turbulence"] else None)
    converged = False
    while True:
        if abs(rms / aim_rms - 1) <= SOLVED and abs(var / aim_var - 1) <= SOLVED:
            converged = True
            break
        if len(seen) >= MAX_EVALUATIONS:
            break
        if len(seen) == 1:  # the second point of the variance's line: the other end of the noise
            noise = 0.0 if noise > 0 else 1e-3
            rms, var, vals = evaluate(sigma, noise)
            continue
        # The residual variance's line in the noise variance, through the two latest distinct points.
        (n1, v1, _), (n2, v2, _) = seen[-2], seen[-1]
        if n1 == n2:
            (n1, v1, _) = next(s for s in reversed(seen) if s[0] != n2)
        slope = (v2 - v1) / (n2 - n1)
        n_sq = n2 + (aim_var - v2) / slope if slope > 0 else n2
        noise = float(np.clip(np.sqrt(max(n_sq, 0.0)), lo_n, hi_n))
        # The true pitch RMS is proportional to the turbulence: alpha from the latest evaluation.
        alpha = max(rms * rms - n2 - floor, 1e-30) / (sigma * sigma)
        sigma = float(np.clip(np.sqrt(max(aim_rms * aim_rms - noise * noise - floor, 1e-30) / alpha), lo_s, hi_s))
        rms, var, vals = evaluate(sigma, noise)
    return AmbientFit(vals, rms, var, len(seen), converged)
