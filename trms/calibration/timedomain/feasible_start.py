"""A start that can be fitted from: end stops the model hits where the rig did not, and a coarse search around them.

A Gauss-Newton fit needs a residual that changes smoothly with the parameters. A start whose
twin, driven by the recorded voltages, runs into a mechanical end stop (a joint range) that
the rig never reached gives the opposite: while the beam rests on the stop, the prediction
no longer depends on the parameters, and the few contact samples make a finite-difference
Jacobian meaningless; the optimiser then stops on its first step with the start unchanged.
So before fitting, the start is rolled out on the records (:func:`stop_hit`); if it hits a
stop that a record stays away from, a coarse global stage draws a few seeded Latin-hypercube
candidates (:func:`latin_hypercube`) -- first within a factor :data:`SPREAD` of the start,
then over the whole bounds -- and the fit continues from the candidate of least sum of
squares that hits no stop its records do not (:func:`best_feasible`). When none does, the
calibration is refused, naming the axis, the record and the time of the start's first hit.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.stats import qmc

from trms.rig.checks import STOP_CONTACT

__all__ = ["SPREAD", "STOP_MARGIN", "StopHit", "best_feasible", "latin_hypercube", "stop_hit", "stop_reached"]

#: An angle within this fraction of its joint's range from an end stop counts as at the stop (the import's
#: :data:`~trms.rig.checks.STOP_CONTACT`): samples every control interval miss the peak of a bounce between them.
STOP_MARGIN = STOP_CONTACT
#: The first round of the coarse stage draws each parameter within this factor of its start.
SPREAD = 2.0


@dataclass(frozen=True)
class StopHit:
    """The first sample at which a prediction runs into an end stop that its record stays away from.

    Attributes
    ----------
    axis : str
        The output (joint) name, e.g. ``"pitch"``.
    record : str
        The record's label.
    time : float
        Time of the sample from the record's start (s).
    angle : float
        The predicted angle there (rad; ``nan`` when the prediction is not finite).
    stop : float
        The end stop reached (rad).
    recorded : tuple of float
        The record's own smallest and largest angle on that axis (rad).

    Examples
    --------
    >>> print(StopHit("yaw", "rig1.csv", 2.5, -3.0, -3.0, (-1.2, 0.8)))
    it hits the yaw end stop (-3 rad) on record rig1.csv at 2.50 s, where the record stays within -1.2..+0.8 rad
    """

    axis: str
    record: str
    time: float
    angle: float
    stop: float
    recorded: tuple[float, float]

    def __str__(self) -> str:
        if not np.isfinite(self.angle):
            return f"the {self.axis} prediction on record {self.record} is not finite at {self.time:.2f} s"
        return (
            f"it hits the {self.axis} end stop ({self.stop:+.3g} rad) on record {self.record} at {self.time:.2f} s, "
            f"where the record stays within {self.recorded[0]:+.3g}..{self.recorded[1]:+.3g} rad"
        )


def stop_hit(
    predicted: np.ndarray,
    measured: np.ndarray,
    times: np.ndarray,
    stops: Sequence[tuple[float, float] | None],
    axes: Sequence[str],
    record: str,
    margin: float = STOP_MARGIN,
) -> StopHit | None:
    """The first sample where ``predicted`` reaches an end stop that ``measured`` never reaches, or ``None``.

    A prediction that is not finite counts as a hit (a diverged candidate is no start either).

    Parameters
    ----------
    predicted, measured : numpy.ndarray
        Angles (rad), shape ``(N, n_axes)``, at the same samples.
    times : numpy.ndarray
        Sample times (s), shape ``(N,)``.
    stops : sequence of (float, float) or None
        Each axis's joint range (rad); ``None`` for an axis without stops.
    axes : sequence of str
        Axis names, for the message.
    record : str
        The record's label, for the message.
    margin : float
        Fraction of the range counted as at the stop (default :data:`STOP_MARGIN`).

    Returns
    -------
    StopHit or None

    Examples
    --------
    >>> t = np.arange(4) * 0.5
    >>> pred = np.array([[0.0], [0.6], [1.1], [0.9]])
    >>> meas = np.array([[0.0], [0.3], [0.6], [0.4]])
    >>> print(stop_hit(pred, meas, t, [(-1.1, 1.1)], ["pitch"], "rig1"))
    it hits the pitch end stop (+1.1 rad) on record rig1 at 1.00 s, where the record stays within +0..+0.6 rad
    >>> stop_hit(meas, meas, t, [(-1.1, 1.1)], ["pitch"], "rig1") is None
    True
    """
    pred = np.asarray(predicted, float)
    meas = np.asarray(measured, float)
    first: StopHit | None = None
    for j, (axis, limits) in enumerate(zip(axes, stops)):
        seen = meas[:, j][np.isfinite(meas[:, j])]
        recorded = (float(seen.min()), float(seen.max())) if seen.size else (np.nan, np.nan)
        bad = ~np.isfinite(pred[:, j])
        stop = np.full(len(pred), np.nan)
        if limits is not None:
            lo, hi = limits
            band = margin * (hi - lo)
            for limit, reached in ((lo, pred[:, j] <= lo + band), (hi, pred[:, j] >= hi - band)):
                # a stop the record itself reaches is the rig's: the model must reproduce it, not avoid it
                if not (seen.size and np.any(seen <= lo + band if limit == lo else seen >= hi - band)):
                    stop[reached & ~bad] = limit
        hits = np.flatnonzero(bad | np.isfinite(stop))
        if hits.size and (first is None or times[hits[0]] < first.time):
            k = int(hits[0])
            first = StopHit(axis, record, float(times[k]), float(pred[k, j]), float(stop[k]), recorded)
    return first


def stop_reached(
    measured: np.ndarray,
    times: np.ndarray,
    stops: Sequence[tuple[float, float] | None],
    axes: Sequence[str],
    record: str,
    margin: float = STOP_MARGIN,
) -> str | None:
    """Where a record itself first runs into an end stop, as one sentence, or ``None`` when it stays off them.

    A record that reaches a stop is no error (the model reproduces the stop), but its impacts
    make a fit's residual jump with the parameters: the bounce's timing moves with them, so a
    Gauss-Newton step fitted to a finite-difference Jacobian may lower nothing.

    Parameters
    ----------
    measured : numpy.ndarray
        Angles (rad), shape ``(N, n_axes)``.
    times : numpy.ndarray
        Sample times (s), shape ``(N,)``.
    stops : sequence of (float, float) or None
        Each axis's joint range (rad); ``None`` for an axis without stops.
    axes : sequence of str
        Axis names, for the message.
    record : str
        The record's label, for the message.
    margin : float
        Fraction of the range counted as at the stop (default :data:`STOP_MARGIN`).

    Returns
    -------
    str or None

    Examples
    --------
    >>> y = np.array([[0.0], [2.5], [2.99], [1.0]])
    >>> stop_reached(y, np.arange(4) * 0.5, [(-3.0, 3.0)], ["yaw"], "rig1")
    'record rig1 reaches the yaw end stop (+3 rad) at 1.00 s (1 sample at a stop)'
    >>> stop_reached(y, np.arange(4) * 0.5, [(-3.5, 3.5)], ["yaw"], "rig1") is None
    True
    """
    y = np.asarray(measured, float)
    first: tuple[float, str, float] | None = None
    contacts = 0
    for j, (axis, limits) in enumerate(zip(axes, stops)):
        if limits is None:
            continue
        lo, hi = limits
        band = margin * (hi - lo)
        at = np.flatnonzero((y[:, j] <= lo + band) | (y[:, j] >= hi - band))
        contacts += at.size
        if at.size and (first is None or times[at[0]] < first[0]):
            k = int(at[0])
            first = (float(times[k]), axis, lo if y[k, j] <= lo + band else hi)
    if first is None:
        return None
    return (
        f"record {record} reaches the {first[1]} end stop ({first[2]:+.3g} rad) at {first[0]:.2f} s "
        f"({contacts} sample{'s' if contacts != 1 else ''} at a stop)"
    )


def latin_hypercube(
    start: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    n: int,
    seed: int = 0,
    spread: float | None = SPREAD,
) -> np.ndarray:
    """``n`` seeded Latin-hypercube candidates around ``start`` within the bounds.

    Each parameter is drawn log-uniformly between ``start / spread`` and ``start * spread``
    cut to its bounds (over the whole bounds when ``spread`` is ``None``); a parameter whose
    bounds or start are not positive is drawn uniformly over the same stretch of its bounds
    (``start +- (spread - 1) |start|``, or the whole bounds).

    Parameters
    ----------
    start, lower, upper : numpy.ndarray
        Shape ``(p,)``, in the parameters' units.
    n : int
        Candidates, >= 1.
    seed : int
        The same seed gives the same candidates.
    spread : float or None
        Factor around the start (> 1), or ``None`` for the whole bounds.

    Returns
    -------
    numpy.ndarray
        Shape ``(n, p)``, every row within ``[lower, upper]``.

    Examples
    --------
    >>> c = latin_hypercube(np.array([1.0, 0.0]), np.array([0.1, -1.0]), np.array([10.0, 1.0]), 5, seed=3)
    >>> c.shape, bool(np.all((c[:, 0] >= 0.5) & (c[:, 0] <= 2.0))), bool(np.all(np.abs(c[:, 1]) <= 1.0))
    ((5, 2), True, True)
    """
    x0, lo, hi = (np.asarray(a, float) for a in (start, lower, upper))
    positive = (lo > 0) & (x0 > 0)
    if spread is None:
        a, b = lo.copy(), hi.copy()
    else:
        width = (spread - 1.0) * np.abs(x0)
        a = np.where(positive, x0 / spread, x0 - width)
        b = np.where(positive, x0 * spread, x0 + width)
        a, b = np.maximum(a, lo), np.minimum(b, hi)
    a, b = np.where(b > a, a, lo), np.where(b > a, b, hi)  # a start at zero: its whole bounds
    u = qmc.LatinHypercube(d=x0.size, seed=np.random.default_rng(seed)).random(int(n))
    la, lb = np.log(np.where(positive, a, 1.0)), np.log(np.where(positive, b, 1.0))
    return np.where(positive, np.exp(la + u * (lb - la)), a + u * (b - a))


def best_feasible(sse: np.ndarray, hits: Sequence[StopHit | None]) -> int | None:
    """Index of the least sum of squares among the candidates without a stop hit, or ``None``.

    Examples
    --------
    >>> hit = StopHit("pitch", "r", 1.0, 1.1, 1.1, (-0.5, 0.6))
    >>> best_feasible(np.array([1.0, 3.0, 2.0]), [hit, None, None])
    2
    """
    ok = [i for i, h in enumerate(hits) if h is None and np.isfinite(sse[i])]
    return min(ok, key=lambda i: float(sse[i])) if ok else None
