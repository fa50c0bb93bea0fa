"""Fault detection from a Kalman filter's innovations: a windowed chi-square test with a stated false-alarm rate.

While the plant is the model the filter was designed on, the innovations ``e_k = y_k - C x_k|k-1`` are zero-mean and
white with covariance ``S``, so the normalised innovation squared ``q_k = e_k^T S^-1 e_k`` is chi-square with ``p``
degrees of freedom (``p`` outputs), and its sum over a window of ``w`` samples chi-square with ``p w``. The test
raises an alarm at sample ``k`` when that sum exceeds the ``1 - alpha`` quantile: each sample of a fault-free run
then alarms with probability ``alpha`` (the false-alarm rate it is designed for). A fault (a lost actuator, a stuck
rotor, a dead sensor) biases or colours the innovations and the sum grows until it alarms: the detection delay.

:func:`innovations` recomputes a filter's innovations from a record of its inputs and outputs, so the test runs on
any logged run; :class:`ChiSquareDetector` also runs online, one sample at a time, inside a controller.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.signal
import scipy.stats

from trms.control.arguments import real_array
from trms.errors import InputError, as_finite_array, check_in_range, check_int

__all__ = ["ChiSquareDetector", "Detection", "innovations"]


@dataclass(frozen=True)
class Detection:
    """The test run over a whole sequence of innovations.

    Attributes
    ----------
    statistic : numpy.ndarray
        The windowed sum of normalised innovations squared at each sample, ``(N,)`` (dimensionless; NaN until
        the first window is full).
    threshold : float
        The alarm threshold (dimensionless).
    alarms : numpy.ndarray
        ``statistic > threshold`` at each sample, ``(N,)`` bool.
    """

    statistic: np.ndarray
    threshold: float
    alarms: np.ndarray

    @property
    def first_alarm(self) -> int | None:
        """Index of the first alarm, or ``None``."""
        hits = np.flatnonzero(self.alarms)
        return int(hits[0]) if hits.size else None

    def false_alarm_rate(self, before: int | None = None) -> float:
        """Fraction of the samples (with a full window, before sample ``before``) that alarm."""
        stop = self.alarms.size if before is None else check_int("before", before, 0, " samples")
        valid = np.isfinite(self.statistic[:stop])
        return float(self.alarms[:stop][valid].mean()) if valid.any() else float("nan")


class ChiSquareDetector:
    """Windowed chi-square test on a filter's innovations, designed for a false-alarm rate per sample.

    Parameters
    ----------
    covariance : array_like
        The innovation covariance ``S`` the filter predicts, ``(p, p)`` (output units squared), positive definite.
    window : int
        Samples summed (at least 1). Longer windows detect small faults, later.
    false_alarm_rate : float
        Probability that a fault-free sample alarms, in ``(0, 0.5]``.

    Attributes
    ----------
    threshold : float
        The ``1 - false_alarm_rate`` quantile of chi-square with ``p * window`` degrees of freedom.
    covariance : numpy.ndarray
        ``S`` (read-only).

    Examples
    --------
    White innovations of the designed covariance alarm at about the designed rate:

    >>> rng = np.random.default_rng(0)
    >>> det = ChiSquareDetector(np.eye(2) * 0.01, window=10, false_alarm_rate=0.01)
    >>> round(det.threshold, 2)
    37.57
    >>> quiet = det.run(0.1 * rng.standard_normal((20000, 2)))
    >>> round(quiet.false_alarm_rate(), 3)
    0.01
    >>> biased = det.run(0.1 * rng.standard_normal((200, 2)) + [0.1, 0.0])
    >>> biased.first_alarm is not None
    True
    """

    def __init__(self, covariance: object, window: int = 10, false_alarm_rate: float = 1e-3) -> None:
        s = np.atleast_2d(real_array("covariance", covariance))
        if s.ndim != 2 or s.shape[0] != s.shape[1] or s.shape[0] == 0:
            raise InputError(f"covariance must be a square (p, p) matrix, got shape {s.shape}")
        if not np.allclose(s, s.T, rtol=1e-9, atol=0.0):
            raise InputError("covariance must be symmetric")
        try:
            self._chol = np.linalg.cholesky(s)
            self.covariance = s.copy()
            self.covariance.flags.writeable = False
        except np.linalg.LinAlgError as exc:
            raise InputError("covariance must be positive definite") from exc
        self.window = check_int("window", window, 1)
        self.false_alarm_rate = check_in_range("false_alarm_rate", false_alarm_rate, 0.0, 0.5, low_open=True)
        self.n_outputs = int(s.shape[0])
        self.threshold = float(scipy.stats.chi2.isf(self.false_alarm_rate, self.n_outputs * self.window))
        self._recent: deque[float] = deque(maxlen=self.window)

    @classmethod
    def calibrated(cls, runs: Sequence[object], window: int = 10, false_alarm_rate: float = 1e-3) -> ChiSquareDetector:
        """A detector whose covariance and threshold come from fault-free runs' innovations.

        A filter designed on a model that differs from the plant (or tuned with covariances that are not the
        noise's) gives innovations that are neither of its predicted covariance nor white, so the chi-square
        quantile would alarm far more often than designed. Here ``S`` is the innovations' sample covariance over
        ``runs``, and the threshold the larger of the chi-square quantile and the empirical ``1 - false_alarm_rate``
        quantile of the windowed statistic over the runs.

        Parameters
        ----------
        runs : sequence of array_like
            Innovations of fault-free runs, each ``(N_i, p)`` or ``(N_i,)``.
        window, false_alarm_rate
            As for the constructor.

        Returns
        -------
        ChiSquareDetector

        Examples
        --------
        Innovations coloured by a model error (an AR(1) with coefficient 0.8):

        >>> import scipy.signal
        >>> rng = np.random.default_rng(1)
        >>> runs = [scipy.signal.lfilter([1.0], [1.0, -0.8], rng.standard_normal(2000)) for _ in range(20)]
        >>> det = ChiSquareDetector.calibrated(runs, window=10, false_alarm_rate=0.01)
        >>> plain = ChiSquareDetector(det.covariance, window=10, false_alarm_rate=0.01)
        >>> det.threshold > plain.threshold
        True
        >>> unseen = [scipy.signal.lfilter([1.0], [1.0, -0.8], rng.standard_normal(2000)) for _ in range(20)]
        >>> round(float(np.mean([det.run(e).false_alarm_rate() for e in unseen])), 3)  # as designed
        0.01
        >>> round(float(np.mean([plain.run(e).false_alarm_rate() for e in unseen])), 2)  # seven times too many
        0.07
        """
        if isinstance(runs, np.ndarray) or not isinstance(runs, (list, tuple)):
            raise InputError(
                f"runs must be a list of runs (each an (N, p) or (N,) array of innovations), got {type(runs).__name__}"
            )
        arrays = [real_array(f"runs[{i}]", r) for i, r in enumerate(runs)]
        if not arrays:
            raise InputError("runs must hold at least one fault-free run of innovations")
        arrays = [a.reshape(-1, 1) if a.ndim == 1 else a for a in arrays]
        widths = {a.shape[1] if a.ndim == 2 else -1 for a in arrays}
        if len(widths) != 1 or -1 in widths:
            shapes = ", ".join(str(a.shape) for a in arrays[:4])
            raise InputError(f"every run must be (N, p) with the same p outputs, got shapes {shapes}")
        pooled = np.concatenate(arrays)
        if pooled.shape[0] <= pooled.shape[1]:
            raise InputError(f"the runs hold {pooled.shape[0]} samples; a covariance needs more than {pooled.shape[1]}")
        window = check_int("window", window, 1)
        longest = max(a.shape[0] for a in arrays)
        if longest < window:
            raise InputError(
                f"the longest run holds {longest} samples, fewer than the window of {window}: no windowed statistic "
                f"to calibrate the threshold on; allowed: runs of at least {window} samples (many more, for the "
                "threshold's quantile)"
            )
        centred = pooled - pooled.mean(axis=0)
        det = cls(centred.T @ centred / pooled.shape[0], window, false_alarm_rate)
        stats = np.concatenate([det.run(a).statistic for a in arrays])
        stats = stats[np.isfinite(stats)]
        if stats.size:
            det.threshold = max(det.threshold, float(np.quantile(stats, 1.0 - det.false_alarm_rate)))
        return det

    def normalised_squares(self, e: np.ndarray) -> np.ndarray:
        """``e_k^T S^-1 e_k`` of each row of ``e`` ``(N, p)`` (dimensionless)."""
        return self._normalised_squares(e)

    def _normalised_squares(self, e: np.ndarray) -> np.ndarray:
        white = scipy.linalg.solve_triangular(self._chol, e.T, lower=True)
        return np.sum(white**2, axis=0)

    def run(self, innovations: object) -> Detection:
        """Test a whole sequence: innovations ``(N, p)`` (or ``(N,)`` for one output), in output units.

        Returns
        -------
        Detection
        """
        e = real_array("innovations", innovations)
        e = e.reshape(-1, 1) if e.ndim == 1 else e
        if e.ndim != 2 or e.shape[1] != self.n_outputs:
            raise InputError(f"innovations must have shape (N, {self.n_outputs}), got {e.shape}")
        q = self._normalised_squares(e)
        c = np.concatenate([[0.0], np.cumsum(q)])
        stat = np.full(q.size, np.nan)
        w = self.window
        if q.size >= w:
            stat[w - 1 :] = c[w:] - c[:-w]
        return Detection(stat, self.threshold, np.nan_to_num(stat, nan=-np.inf) > self.threshold)

    def reset(self) -> None:
        """Forget the samples of the online test."""
        self._recent.clear()

    def update(self, innovation: object) -> bool:
        """Add one innovation ``(p,)`` to the online test; ``True`` when the full window alarms."""
        e = real_array("innovation", innovation).reshape(1, -1)
        if e.shape[1] != self.n_outputs:
            raise InputError(f"innovation must have {self.n_outputs} entries, got {e.shape[1]}")
        self._recent.append(float(self._normalised_squares(e)[0]))
        return len(self._recent) == self.window and sum(self._recent) > self.threshold


def innovations(
    A: object, B: object, C: object, L: object, inputs: object, outputs: object, x0: object | None = None
) -> np.ndarray:
    """A Kalman predictor's innovations over a record: ``e_k = y_k - C x_k``, ``x_k+1 = A x_k + B u_k + L e_k``.

    Parameters
    ----------
    A, B, C : array_like
        The filter's model, ``(n, n)``, ``(n, m)``, ``(p, n)`` (deviation units).
    L : array_like
        The predictor gain ``(n, p)`` (a current-estimate filter's gain ``M`` gives ``L = A M``).
    inputs : array_like
        Inputs ``u_k`` applied, ``(N, m)`` or ``(N,)`` (deviations, e.g. V).
    outputs : array_like
        Measurements ``y_k``, ``(N, p)`` or ``(N,)`` (deviations, e.g. rad).
    x0 : array_like, optional
        The predicted state at sample 0 (zero by default).

    Returns
    -------
    numpy.ndarray
        ``(N, p)``.

    Examples
    --------
    A filter of the true system predicts a noise-free output exactly:

    >>> u = np.sin(np.arange(50) / 5.0)
    >>> x = np.zeros(51)
    >>> for k in range(50):
    ...     x[k + 1] = 0.9 * x[k] + 0.5 * u[k]
    >>> e = innovations([[0.9]], [[0.5]], [[1.0]], [[0.4]], u, x[:50])
    >>> bool(np.max(np.abs(e)) < 1e-12)
    True
    """
    a, b, c, gain = (np.atleast_2d(real_array(n, v)) for n, v in (("A", A), ("B", B), ("C", C), ("L", L)))
    u = real_array("inputs", inputs)
    y = real_array("outputs", outputs)
    u = u.reshape(-1, 1) if u.ndim == 1 else u
    y = y.reshape(-1, 1) if y.ndim == 1 else y
    n = a.shape[0]
    shapes = {"A": (a.shape, (n, n)), "B": (b.shape, (n, u.shape[1])), "C": (c.shape, (y.shape[1], n))}
    shapes["L"] = (gain.shape, (n, y.shape[1]))
    for name, (got, want) in shapes.items():
        if got != want:
            raise InputError(f"{name} must have shape {want} for these data, got {got}")
    if u.ndim != 2 or y.ndim != 2 or u.shape[0] == 0:
        raise InputError(f"inputs and outputs must be (N, m) and (N, p) with N > 0, got {u.shape} and {y.shape}")
    if u.shape[0] != y.shape[0]:
        raise InputError(f"inputs and outputs must have the same length, got {u.shape[0]} and {y.shape[0]}")
    start = np.zeros(n) if x0 is None else as_finite_array("x0", x0, (n,))
    p = y.shape[1]
    # The predictor as one LTI system from (u, y) to e = y - C x: x+ = (A - L C) x + [B, L] [u; y].
    closed = a - gain @ c
    radius = float(np.max(np.abs(np.linalg.eigvals(closed)))) if n else 0.0
    sys = (closed, np.hstack([b, gain]), -c, np.hstack([np.zeros((p, b.shape[1])), np.eye(p)]), 1.0)
    with np.errstate(over="ignore", invalid="ignore"):  # a growing predictor is refused below, by name
        _, out, _ = scipy.signal.dlsim(sys, np.hstack([u, y]), x0=start)
    e: np.ndarray = np.asarray(out, float).reshape(y.shape)
    bad = np.flatnonzero(~np.isfinite(e).all(axis=1))
    if bad.size:
        raise InputError(
            f"the predictor's innovations overflow from sample {int(bad[0])} of {y.shape[0]}: A - L C has a pole of "
            f"|z| = {radius:.4g}, outside the unit circle (an unstable predictor); allowed: a gain L that makes "
            "A - L C stable (a Kalman predictor's)"
        )
    return e
