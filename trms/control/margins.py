"""Disk margin of a feedback loop: simultaneous gain and phase variation it tolerates.

A loop ``L`` (unity negative feedback, ``S = 1 / (1 + L)``, ``T = L / (1 + L)``) keeps a stable
closed loop when ``L`` is multiplied by any complex factor ``f`` in the disk whose real-axis
diameter is ``[(2 - alpha) / (2 + alpha), (2 + alpha) / (2 - alpha)]``, for every ``alpha`` below the
*symmetric* (skew 0, "balanced") disk margin

``alpha_max = 1 / max_w |S(jw) - T(jw)| / 2 = 1 / max_w |S(jw) - 1/2|``

(Blight, Dailey and Gangsaas; Seiler, Packard and Gahinet, "An introduction to disk margins",
2020). The disk gives the gain range ``[(2 - alpha) / (2 + alpha), (2 + alpha) / (2 - alpha)]`` with
the phase held, and the phase margin ``+-2 atan(alpha / 2)`` with the gain held; a loop with
``alpha >= 2`` tolerates any gain increase. The classic gain and phase margins vary one at a time and
are never smaller than these.

For a single-input single-output loop the loop broken at the plant input, ``K G``, and at the plant
output, ``G K``, are the same transfer function, so one number serves both. A loop of several
channels is checked one channel at a time: the caller forms the SISO loop of that channel with the
others closed.

The peak of ``|S - 1/2|`` is found on a dense frequency grid that includes every closed-loop pole's
frequency, ``0``, and Nyquist (discrete) or infinity (continuous), then refined by a bounded
search around the largest sample.
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np
from scipy.optimize import brentq, minimize_scalar

from trms.control.arguments import finite_system
from trms.errors import InputError

__all__ = ["DiskMargin", "disk_margin", "input_disk_margins", "ClassicalMargins", "classical_margins"]


@dataclass(frozen=True)
class DiskMargin:
    """The symmetric disk margin of a loop (module docstring).

    Attributes
    ----------
    alpha : float
        Disk size ``1 / max_w |S - 1/2|``; 0 when the nominal closed loop is unstable.
    gain_range : tuple of float
        ``(low, high)`` factors on the loop gain tolerated with the phase held (``low`` clipped at 0,
        ``high`` is ``inf`` when ``alpha >= 2``).
    gain_margin_db : float
        ``20 log10(high)`` (dB).
    phase_margin_deg : float
        ``2 atan(alpha / 2)`` (deg) tolerated with the gain held.
    frequency : float
        Frequency of the worst case (rad/s); ``inf`` when it is approached at infinite frequency.
    stable : bool
        The nominal closed loop is stable (every disk quantity is 0 otherwise).

    Examples
    --------
    The lag ``L = 1 / (s + 1)`` keeps ``|S - 1/2| <= 1/2``: ``alpha = 2``, any gain increase and 90 degrees:

    >>> m = disk_margin(control.tf([1.0], [1.0, 1.0]))
    >>> m.alpha, m.gain_range, m.gain_margin_db, round(m.phase_margin_deg, 9), m.stable
    (2.0, (0.0, inf), inf, 90.0, True)
    >>> disk_margin(control.tf([2.0], [1.0, 0.0], 0.2)).stable  # z = -1: the closed loop is unstable
    False
    """

    alpha: float
    gain_range: tuple[float, float]
    gain_margin_db: float
    phase_margin_deg: float
    frequency: float
    stable: bool


def _sensitivity_offset(loop: control.LTI) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """State space of ``S - 1/2`` for a SISO loop ``L = (A, B, C, D)``: ``S = 1 / (1 + L)``."""
    A, B, C, D = finite_system(loop, "loop")
    d = float(D[0, 0])
    if abs(1.0 + d) < 1e-12:
        raise InputError(f"the loop's direct term D = {d!r} makes 1 + L(inf) = 0: the feedback is not well posed")
    k = 1.0 / (1.0 + d)
    return A - k * (B @ C), k * B, -k * C, k - 0.5


def _magnitude(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: float, z: np.ndarray) -> np.ndarray:
    """``|C (z I - A)^-1 B + D|`` at each complex point ``z``."""
    if A.shape[0] == 0:
        return np.full(z.shape, abs(D))
    n = A.shape[0]
    stack = z[:, None, None] * np.eye(n) - A
    x = np.linalg.solve(stack, np.broadcast_to(B, (z.size, n, 1)))
    return np.abs((C @ x)[:, 0, 0] + D)


def disk_margin(loop: control.LTI) -> DiskMargin:
    """Symmetric disk margin of a SISO loop (module docstring).

    Parameters
    ----------
    loop : control.LTI
        Loop transfer ``L`` under unity negative feedback, continuous or discrete (``dt > 0``),
        proper, SISO: e.g. the compensator times the plant, broken at the plant input or output.

    Returns
    -------
    DiskMargin

    Raises
    ------
    InputError
        Not a python-control LTI, not SISO, NaN/inf coefficients, or ``1 + L(inf) = 0``.

    Examples
    --------
    A one-sample delay with gain 0.5: ``alpha = 2 (1 - k) / (1 + k) = 2 / 3``, the gain range is
    ``(k, 1 / k)`` and the phase margin ``2 atan(1 / 3)``:

    >>> m = disk_margin(control.tf([0.5], [1.0, 0.0], 0.2))
    >>> round(m.alpha, 9), tuple(round(g, 9) for g in m.gain_range), round(m.phase_margin_deg, 3)
    (0.666666667, (0.5, 2.0), 36.87)
    """
    if not isinstance(loop, control.LTI):
        raise InputError(f"loop must be a python-control LTI system, got {type(loop).__name__}")
    if loop.ninputs != 1 or loop.noutputs != 1:
        raise InputError(
            f"loop must be SISO (1 input, 1 output), got {loop.noutputs}x{loop.ninputs}; "
            "break a loop of several channels one channel at a time"
        )
    dt = loop.dt
    discrete = control.isdtime(loop, strict=True)
    if discrete and (dt is True or not np.isfinite(dt)):
        raise InputError(f"loop must have a finite numeric sample time dt > 0 (s) or dt = 0, got dt = {dt!r}")
    A, B, C, D = _sensitivity_offset(loop)
    poles = np.linalg.eigvals(A) if A.size else np.zeros(0, complex)
    stable = bool(np.all(np.abs(poles) < 1.0)) if discrete else bool(np.all(poles.real < 0.0))
    if not stable:
        return DiskMargin(0.0, (1.0, 1.0), 0.0, 0.0, float("nan"), False)

    if discrete:
        ts = float(dt)
        w_max = np.pi / ts  # Nyquist
        pole_w = np.abs(np.angle(poles[poles != 0])) / ts
        grid = np.concatenate([[0.0], w_max * np.logspace(-6, 0, 3000), np.linspace(0.0, w_max, 3001)])

        def at(w: np.ndarray) -> np.ndarray:
            return _magnitude(A, B, C, D, np.exp(1j * w * ts))

    else:
        speeds = np.abs(poles[poles != 0])
        w_max = 1e3 * float(speeds.max()) if speeds.size else 1e3
        w_min = 1e-3 * float(speeds.min()) if speeds.size else 1e-3
        pole_w = np.concatenate([np.abs(poles.imag), speeds])
        grid = np.concatenate([[0.0], np.logspace(np.log10(w_min), np.log10(w_max), 4000)])

        def at(w: np.ndarray) -> np.ndarray:
            return _magnitude(A, B, C, D, 1j * w)

    grid = np.unique(np.concatenate([grid, pole_w[pole_w <= w_max]]))
    mags = at(grid)
    k = int(np.argmax(mags))
    peak, w_peak = float(mags[k]), float(grid[k])
    left, right = float(grid[max(k - 1, 0)]), float(grid[min(k + 1, grid.size - 1)])
    res = minimize_scalar(lambda w: -float(at(np.array([w]))[0]), bounds=(left, right), method="bounded")
    if -res.fun > peak:
        peak, w_peak = float(-res.fun), float(res.x)
    if not discrete and abs(D) >= peak:  # approached at infinite frequency
        peak, w_peak = abs(D), float("inf")
    alpha = float("inf") if peak == 0.0 else 1.0 / peak
    low = max(0.0, (2.0 - alpha) / (2.0 + alpha)) if np.isfinite(alpha) else 0.0
    high = (2.0 + alpha) / (2.0 - alpha) if alpha < 2.0 else float("inf")
    phase = float(np.degrees(2.0 * np.arctan(alpha / 2.0)))
    return DiskMargin(alpha, (low, high), float(20.0 * np.log10(high)), phase, w_peak, True)


@dataclass(frozen=True)
class ClassicalMargins:
    """Gain, phase and delay margins of a discrete SISO loop, one variation at a time (:func:`classical_margins`).

    Attributes
    ----------
    gain_margin_db : float
        ``-20 log10 |L|`` at the phase crossover (``L`` real and negative) closest to ``|L| = 1``; ``inf`` when
        the loop's phase never reaches -180 deg.
    phase_margin_deg : float
        ``angle(L) + 180`` (deg, in ``[-180, 180)``) at the gain crossover of smallest ``|margin|``; ``inf`` when
        ``|L|`` never crosses 1.
    delay_margin_s : float
        Stable loop: the smallest extra pure delay (s) that brings a gain crossover onto -1 (:func:`classical_margins`),
        ``inf`` without a gain crossover. Unstable loop: negative, minus the smallest advance (s) that brings a gain
        crossover onto -1 (the phase margin over the crossover frequency where there is one crossover), ``-inf``
        without a gain crossover: no delay is tolerated by a loop that is unstable already.
    phase_crossovers, gain_crossovers : tuple of float
        Frequencies (rad/s) where ``L`` is real and negative, and where ``|L| = 1``.
    stable : bool
        The nominal closed loop ``L / (1 + L)`` is stable (the margins of an unstable loop are distances to
        the -1 point, not tolerances).
    """

    gain_margin_db: float
    phase_margin_deg: float
    delay_margin_s: float
    phase_crossovers: tuple[float, ...]
    gain_crossovers: tuple[float, ...]
    stable: bool = True


def _response(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: float, z: np.ndarray) -> np.ndarray:
    """``C (z I - A)^-1 B + D`` at each complex point ``z`` (in blocks: bounded memory)."""
    out = np.empty(z.shape, complex)
    n = A.shape[0]
    if n == 0:
        out[:] = D
        return out
    for k in range(0, z.size, 1024):
        zz = z[k : k + 1024]
        x = np.linalg.solve(zz[:, None, None] * np.eye(n) - A, np.broadcast_to(B.astype(complex), (zz.size, n, 1)))
        out[k : k + 1024] = (C @ x)[:, 0, 0] + D
    return out


def classical_margins(loop: control.LTI, points: int = 20000) -> ClassicalMargins:
    """Classical gain, phase and delay margins of a discrete SISO loop ``L`` under unity negative feedback.

    ``L(e^{j w Ts})`` is evaluated exactly (state space, no interpolation) on ``points`` frequencies from
    1e-3 rad/s to Nyquist; every sign change of ``angle(-L)`` with ``Re L <= 0`` (a phase crossover) and of
    ``|L| - 1`` (a gain crossover) is refined to 1e-12 rad/s by Brent's method on the exact response, so a
    high-order loop's crossings are neither missed between polynomial roots nor displaced by an interpolating
    fit. The gain and phase margins are python-control's choice among the crossings (the gain margin closest
    to 0 dB, the phase margin of smallest magnitude). The delay margin of a stable closed loop is the smallest
    over every gain crossover: at a crossover of phase ``phi`` a delay ``d`` adds the lag ``w d``, and the locus
    meets -1 when it has turned by ``(phi + 180) mod 360`` degrees. A closed loop that is unstable tolerates no
    delay: its delay margin is negative, minus the smallest advance that turns a crossover back onto -1,
    ``(-(phi + 180)) mod 360`` degrees over ``w`` (with one crossover, its phase margin over its frequency).

    Parameters
    ----------
    loop : control.LTI
        Discrete SISO loop transfer (``dt > 0``, s).
    points : int
        Frequencies of the search grid (>= 100).

    Returns
    -------
    ClassicalMargins

    Raises
    ------
    InputError
        Not a discrete SISO LTI with finite coefficients, or fewer than 100 points.

    Examples
    --------
    ``L = 0.5 / (z - 0.5)`` at 1 s reaches -180 deg at Nyquist, where ``|L| = 1/3`` (gain margin 20 log10 3),
    and never reaches ``|L| = 1``:

    >>> m = classical_margins(control.tf([0.5], [1.0, -0.5], 1.0))
    >>> round(m.gain_margin_db, 6), m.phase_margin_deg, m.delay_margin_s, m.stable
    (9.542425, inf, inf, True)
    >>> classical_margins(control.tf([1.5], [1.0, 0.0], 1.0)).stable  # closed-loop pole at -1.5
    False

    ``L = 0.8 / (z - 0.5)`` at 1 s crosses ``|L| = 1`` once, with 97.9 deg of phase margin: 1.868 s of delay. Two
    samples (2 s) of delay more make the loop unstable, its delay margin 1.868 - 2 s:

    >>> lag = control.tf([0.8], [1.0, -0.5], 1.0)
    >>> m2 = classical_margins(lag * control.tf([1.0], [1.0, 0.0, 0.0], 1.0))
    >>> round(classical_margins(lag).delay_margin_s, 3), m2.stable, round(m2.delay_margin_s, 3)
    (1.868, False, -0.132)
    """
    if not isinstance(loop, control.LTI) or loop.ninputs != 1 or loop.noutputs != 1:
        raise InputError(f"loop must be a SISO python-control LTI system, got {type(loop).__name__}")
    dt = loop.dt
    if not control.isdtime(loop, strict=True) or dt is True or not np.isfinite(dt):
        raise InputError(f"loop must be discrete with a finite numeric sample time dt > 0 (s), got dt = {dt!r}")
    if int(points) < 100:
        raise InputError(f"points = {points!r} is outside the allowed range [100, inf)")
    A, B, C, D = finite_system(loop, "loop")
    d, ts = float(D[0, 0]), float(dt)

    def at(w: np.ndarray) -> np.ndarray:
        return _response(A, B, C, d, np.exp(1j * np.asarray(w, float) * ts))

    def one(w: float) -> complex:
        return complex(at(np.array([w]))[0])

    w = np.linspace(1e-3, np.pi / ts, int(points))
    resp = at(w)

    def refine(values: np.ndarray, f: object) -> list[float]:
        cross = np.flatnonzero(np.diff(np.sign(values)) != 0)
        return [float(brentq(f, w[k], w[k + 1], xtol=1e-12)) for k in cross]

    arg = np.angle(-resp)
    # a phase wrap of angle(-L) (Re L > 0) is not a crossover: python-control's rule
    cross = np.flatnonzero(np.diff(np.sign(arg)) != 0)
    cross = cross[resp[cross].real <= 0]
    w180 = [float(brentq(lambda x: np.angle(-one(x)), w[k], w[k + 1], xtol=1e-12)) for k in cross]
    # at Nyquist a real loop's response is real: its phase crossover there is the grid's last point
    nyquist = float(w[-1])
    if resp[-1].real < 0 and abs(resp[-1].imag) <= 1e-9 * abs(resp[-1]) and all(abs(x - nyquist) > 1e-9 for x in w180):
        w180.append(nyquist)
    wc = refine(np.abs(resp) - 1.0, lambda x: abs(one(x)) - 1.0)
    gm = np.array([1.0 / abs(one(x)) for x in w180]) if w180 else np.zeros(0)
    gm_db = float("inf")
    if gm.size and not np.isinf(gm).all():
        with np.errstate(divide="ignore"):
            g = float(gm[int(np.argmin(np.abs(np.log(gm))))])
        gm_db = float(20.0 * np.log10(g)) if np.isfinite(g) and g > 0 else float("inf")
    phases = np.array([np.remainder(np.angle(one(x), deg=True), 360.0) - 180.0 for x in wc])
    pm = float(phases[int(np.argmin(np.abs(phases)))]) if phases.size else float("inf")
    closed = np.linalg.eigvals(A - B @ C / (1.0 + d)) if A.size else np.zeros(0)
    stable = bool(np.all(np.abs(closed) < 1.0))
    sign = 1.0 if stable else -1.0  # a delay turns the locus clockwise; an unstable loop needs it turned back
    turns = [np.deg2rad(np.remainder(sign * (np.angle(one(x), deg=True) + 180.0), 360.0)) / x for x in wc]
    dm = sign * float(min(turns)) if turns else sign * float("inf")
    return ClassicalMargins(gm_db, pm, dm, tuple(w180), tuple(wc), stable)


def input_disk_margins(plant: control.LTI, feedback: control.LTI) -> tuple[DiskMargin, ...]:
    """Loop-at-a-time disk margins at each plant input of a multivariable loop.

    The loop at the plant inputs is ``L = K_y G`` (``u = ... - K_y y``): broken at input ``i`` with every other
    input's loop closed, it is a SISO loop whose :func:`disk_margin` is taken.

    Parameters
    ----------
    plant : control.LTI
        ``G``, ``p`` outputs and ``m`` inputs (discrete or continuous).
    feedback : control.LTI
        ``K_y``, ``m`` outputs and ``p`` inputs, the same sample time.

    Returns
    -------
    tuple of DiskMargin
        One per plant input.

    Raises
    ------
    InputError
        Sizes that do not chain.

    Examples
    --------
    Two decoupled one-sample delays with gains 0.5 and 0.25: each input's disk margin is its SISO loop's,
    ``alpha = 2 (1 - k) / (1 + k)``:

    >>> z = control.tf([1.0], [1.0, 0.0], 0.2)
    >>> G = control.append(control.ss(0.5 * z), control.ss(0.25 * z))
    >>> [round(m.alpha, 9) for m in input_disk_margins(G, control.ss([], [], [], np.eye(2), 0.2))]
    [0.666666667, 1.2]
    """
    G, K = control.ss(plant), control.ss(feedback)
    if G.dt != K.dt and not (G.dt is None or K.dt is None):
        raise InputError(f"the plant's sample time dt = {G.dt!r} s and the feedback's dt = {K.dt!r} s differ")
    if K.ninputs != G.noutputs or K.noutputs != G.ninputs:
        raise InputError(
            f"the feedback must map the plant's {G.noutputs} outputs to its {G.ninputs} inputs, "
            f"got {K.ninputs} inputs and {K.noutputs} outputs"
        )
    loop = control.series(G, K)  # L = K G, from the plant inputs back to them
    m = G.ninputs
    out = []
    for i in range(m):
        others = np.eye(m)
        others[i, i] = 0.0
        half = control.feedback(loop, others, sign=-1)
        out.append(disk_margin(control.ss(half.A, half.B[:, [i]], half.C[[i]], half.D[[i]][:, [i]], half.dt)))
    return tuple(out)
