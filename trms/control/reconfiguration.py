"""Fault-tolerant LQG: detect a fault in the innovations, estimate the actuators' effectiveness, re-design the gains.

:class:`ReconfiguringLQG` flies an integral LQG designed on a model ``(A, B, C)`` and, beside it, that model's
Kalman predictor. Each sample it

1. computes the predictor's innovation ``e = y - C x`` and feeds it to a
   :class:`~trms.control.detection.ChiSquareDetector` until it alarms;
2. after the alarm, waits ``decide_after`` samples, then estimates each input's effectiveness ``eta_j`` (the
   true ``B`` is ``B diag(eta)``) by least squares: an input-gain change ``B (eta - 1)`` makes the predictor's
   innovations ``e = sum_j (eta_j - 1) phi_j + c``, where ``phi_j`` is the response of the predictor's error
   dynamics ``x+ = (A - L C) x + b_j u_j``, ``e = C x`` to the input applied since the fault's onset, and ``c`` a
   constant for what else the model misses; the onset is estimated too, as the one that fits best within the
   stored samples (the test's window before the alarm and the samples since);
3. when an effectiveness moved by more than ``tolerance``, re-designs the LQG on ``(A, B diag(eta), C)`` (the
   controller continues from the old one's estimate and integrators,
   :meth:`~trms.control.lqg.LQGController.continue_from`) and the predictor with it; otherwise the alarm was a
   false one: the test is re-armed and the alarm counted.

With several inputs, ``eta`` is a vector, estimated jointly. An input whose estimate falls below ``drop_below`` (a
stuck or dead actuator) is dropped: its effectiveness is set to 0, so its column of ``B diag(eta)`` is zero and the
re-designed LQG gives it zero gain (the LQG of the remaining inputs; the input stays at trim). Fewer inputs may
integrate fewer outputs: ``design`` may then return an LQG that tracks a subset of the nominal one's outputs. The
loop keeps the nominal integrators, those ``design`` dropped with zero gain, and the error injection still feeds
their tracking error to the estimator, so the state feedback regulates those outputs towards their references
without integral action (:func:`embedded`).

A dead sensor is another fault: with ``frozen_after`` given, a reading that has not changed at all for that many
samples is taken as frozen (an encoder that stopped counting; choose it longer than a healthy reading ever stays
still, which the rig's ambient motion keeps short). While it is, the loop runs on its model: the controller and
the predictor are fed the predicted output in its place, and neither the test nor the estimate runs; when the
reading moves again, it is used again and the test re-armed.

This is a least-squares fault estimator with gain re-design, the classical reconfiguration for loss of actuator
effectiveness. What happened is kept: :attr:`ReconfiguringLQG.alarm_sample` and
:attr:`ReconfiguringLQG.switch_sample` (of the latest re-design), :attr:`ReconfiguringLQG.switches` (the alarm and
switch samples of every re-design), :attr:`ReconfiguringLQG.effectiveness`,
:attr:`ReconfiguringLQG.estimates` (each decision's sample and least-squares estimate, before clipping and
dropping),
:attr:`ReconfiguringLQG.false_alarms` and :attr:`ReconfiguringLQG.sensor_faults` (the samples a reading was taken
as frozen from and to).
"""

from __future__ import annotations

import dataclasses
from collections import deque
from collections.abc import Callable

import control
import numpy as np
import scipy.signal

from trms.control.arguments import real_array
from trms.control.detection import ChiSquareDetector
from trms.control.lqg import LQGController, LQGDesign
from trms.errors import DesignError, InputError, check_in_range, check_int, short_repr

__all__ = ["ReconfiguringLQG", "EFFECTIVENESS_RANGE", "embedded"]

#: The effectiveness an estimate of a kept input is clipped to (a rotor cannot gain thrust without bound, nor reverse).
EFFECTIVENESS_RANGE = (0.2, 1.5)
#: Spacing (samples) of the candidate fault onsets the estimate tries.
ONSET_STEP = 2


class ReconfiguringLQG:
    """An integral LQG that re-designs itself after a detected actuator fault (see the module docstring).

    Parameters
    ----------
    model : control.StateSpace
        The discrete design model (deviation V in, deviation rad out, ``D = 0``).
    design : callable
        ``design(model) -> LQGDesign``: the LQG of a model (the nominal one, and each re-designed one).
    detector : ChiSquareDetector
        The test on the predictor's innovations.
    input_limits : tuple of array_like, optional
        Actuator limits in deviation volts, as for :class:`~trms.control.lqg.LQGController`.
    decide_after : int
        Samples after the alarm before the effectiveness is estimated (at least 1).
    tolerance : float
        Smallest relative change of an effectiveness that re-designs the loop, in ``(0, 1]``.
    frozen_after : int, optional
        Samples without any change of a reading after which it is taken as frozen (at least 2); ``None``: never.
    drop_below : float, optional
        An input whose estimated effectiveness is below this, in ``(0, 1]``, is dropped from the design (its
        effectiveness set to 0); ``None``: never (estimates are clipped to :data:`EFFECTIVENESS_RANGE`).

    Examples
    --------
    A lag whose input gain halves at sample 100: the fault is detected, the gain estimated and the loop re-designed.

    >>> from trms.control.lqg import design_lqg
    >>> lag = control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)
    >>> loop = ReconfiguringLQG(lag, design_lqg, ChiSquareDetector([[2e-4]], window=5, false_alarm_rate=1e-3))
    >>> y, rng = 0.0, np.random.default_rng(0)
    >>> for k in range(300):
    ...     u = float(loop.update(0.2 if (k // 50) % 2 else -0.2, y)[0])
    ...     y = 0.9 * y + (0.1 if k < 100 else 0.05) * u + 0.01 * rng.standard_normal()
    >>> 100 <= loop.alarm_sample < 110, round(float(loop.effectiveness[0]), 1)
    (True, 0.5)
    """

    def __init__(
        self,
        model: control.StateSpace,
        design: Callable[[control.StateSpace], LQGDesign],
        detector: ChiSquareDetector,
        input_limits: tuple[object, object] | None = None,
        decide_after: int = 10,
        tolerance: float = 0.1,
        frozen_after: int | None = None,
        drop_below: float | None = None,
    ) -> None:
        if not isinstance(model, control.StateSpace) or not model.isdtime(strict=True):
            raise InputError(f"model must be a discrete control.StateSpace, got {type(model).__name__}")
        if not callable(design):
            raise InputError(f"design must be a function model -> LQGDesign, got {type(design).__name__}")
        if not isinstance(detector, ChiSquareDetector):
            raise InputError(f"detector must be a ChiSquareDetector, got {type(detector).__name__}")
        if detector.n_outputs != model.noutputs:
            raise InputError(f"the detector tests {detector.n_outputs} outputs; the model has {model.noutputs}")
        self.model = model
        self._design = design
        self.detector = detector
        self.decide_after = check_int("decide_after", decide_after, 1)
        self.tolerance = check_in_range("tolerance", tolerance, 0.0, 1.0, low_open=True)
        self.frozen_after = None if frozen_after is None else check_int("frozen_after", frozen_after, 2)
        self.drop_below = (
            None if drop_below is None else check_in_range("drop_below", drop_below, 0.0, 1.0, low_open=True)
        )
        self._limits = input_limits
        self._A, self._B0, self._C = (real_array(n, m) for n, m in (("A", model.A), ("B", model.B), ("C", model.C)))
        self._nominal = LQGController(self._designed(model), input_limits)
        self.reset()

    def _designed(self, model: control.StateSpace) -> LQGDesign:
        """The design function's LQG of ``model``; anything else refused in one line naming it."""
        result = self._design(model)
        if not isinstance(result, LQGDesign):
            name = getattr(self._design, "__name__", type(self._design).__name__)
            raise DesignError(
                f"design function {name} returned {short_repr(result)} ({type(result).__name__}); allowed: an "
                "LQGDesign (e.g. trms.control.lqg.design_lqg)"
            )
        return result

    @property
    def sample_time(self) -> float:
        """Controller sample time (s)."""
        return float(self.model.dt)

    @property
    def controller(self) -> LQGController:
        """The LQG flying now."""
        return self._active

    def reset(self) -> None:
        """Back to the nominal design, the predictor at rest, no alarm."""
        self._nominal.reset()
        self._active = self._nominal
        self._Lp = np.asarray(self._nominal.design.Lp, float)
        self._B = self._B0.copy()
        self.effectiveness = np.ones(self._B0.shape[1])
        self.estimates: list[tuple[int, np.ndarray]] = []
        self.switches: list[tuple[int, int]] = []
        self.detector.reset()
        self.alarm_sample: int | None = None
        self.switch_sample: int | None = None
        self.false_alarms = 0
        self._k = 0
        self._alarm: int | None = None
        self._x = np.zeros(self._A.shape[0])
        keep = self.detector.window + self.decide_after
        self._u: deque[np.ndarray] = deque(maxlen=keep)
        self._e: deque[np.ndarray] = deque(maxlen=keep)
        p = self._C.shape[0]
        self.sensor_faults: list[tuple[int, int | None]] = []
        self._last = np.full(p, np.nan)
        self._still = np.zeros(p, dtype=int)
        self._frozen = np.zeros(p, dtype=bool)

    def update(self, reference: object, measurement: object) -> np.ndarray:
        """One sample: innovation, test, decision, the active LQG (returns the commanded deviation V)."""
        y = np.atleast_1d(real_array("measurement (deviation rad)", measurement)).reshape(-1)
        if y.shape != (self._C.shape[0],):
            raise InputError(f"measurement must be {self._C.shape[0]} numbers (deviation rad), got {y.size}")
        predicted = self._C @ self._x
        if self.frozen_after is not None:
            y = self._frozen_readings(y, predicted, self.frozen_after)
        e = y - predicted
        if self._frozen.any():
            pass  # the loop runs on its model: nothing to test
        elif self._alarm is None:
            if self.detector.update(e):
                self._alarm = self._k
        elif self._k - self._alarm >= self.decide_after:
            self._decide(self._alarm)
        u = self._active.update(reference, y)
        applied = u if self._limits is None else np.clip(u, *self._active.input_limits)
        self._u.append(np.asarray(applied, float).copy())
        self._e.append(e)
        self._x = self._A @ self._x + self._B @ applied + self._Lp @ e
        self._k += 1
        return u

    def _frozen_readings(self, y: np.ndarray, predicted: np.ndarray, after: int) -> np.ndarray:
        """The measurement with each frozen reading replaced by its prediction (and the frozen flags updated)."""
        same = y == self._last
        self._still = np.where(same, self._still + 1, 0)
        self._last = y.copy()
        was = self._frozen.copy()
        self._frozen = self._still >= after - 1
        if self._frozen.any() and not was.any():
            self.sensor_faults.append((self._k, None))
            self._alarm = None
        elif was.any() and not self._frozen.any():
            self.sensor_faults[-1] = (self.sensor_faults[-1][0], self._k)
            self.detector.reset()
        return np.where(self._frozen, predicted, y)

    def _decide(self, alarm: int) -> None:
        """Estimate the effectiveness over the stored window; re-design, or count a false alarm."""
        self._alarm = None
        estimated = self.effectiveness * self._estimate()
        self.estimates.append((self._k, estimated))
        dropped = self.effectiveness == 0.0
        if self.drop_below is not None:
            dropped |= estimated < self.drop_below
        eta = np.where(dropped, 0.0, np.clip(estimated, *EFFECTIVENESS_RANGE))
        b = self._B0 * eta
        lqg = None
        if np.any(np.abs(eta - self.effectiveness) > self.tolerance * self.effectiveness):
            try:
                lqg = embedded(
                    self._designed(
                        control.ss(
                            self._A,
                            b,
                            self._C,
                            np.zeros((self._C.shape[0], b.shape[1])),
                            self.model.dt,
                            states=list(self.model.state_labels),
                            inputs=list(self.model.input_labels),
                            outputs=list(self.model.output_labels),
                        )
                    ),
                    self._nominal.design.tracked,
                )
            except DesignError:
                lqg = None
        if lqg is None:  # no change worth a new design (or none could be made): a false alarm
            self.false_alarms += 1
            self.detector.reset()
            return
        fresh = LQGController(lqg, self._limits)
        fresh.continue_from(self._active)
        self._active, self._B, self._Lp, self.effectiveness = fresh, b, np.asarray(lqg.Lp, float), eta
        self.alarm_sample, self.switch_sample = alarm, self._k
        self.switches.append((alarm, self._k))
        self.detector.reset()

    def _estimate(self) -> np.ndarray:
        """Least-squares ratio of the true to the modelled input gain of each input, from the stored window.

        The fault's onset is not known: each candidate onset (every :data:`ONSET_STEP` samples of the window)
        gives regressors ``phi_j`` that are zero before it, and the onset whose fit leaves the smallest residual
        wins (the generalised likelihood ratio estimate of a change time).
        """
        u = np.array(self._u)
        e = np.array(self._e)
        closed = self._A - self._Lp @ self._C
        n, p = e.shape
        constant = np.kron(np.ones(n), np.eye(p)).T  # one constant per output for what else the model misses
        best_rss, best_beta = np.inf, np.zeros(u.shape[1])
        for onset in range(0, max(n - self.decide_after, 1), ONSET_STEP):
            after = u.copy()
            after[:onset] = 0.0
            columns = []
            for j in range(u.shape[1]):
                sys = (closed, self._B[:, [j]], self._C, np.zeros((p, 1)), 1.0)
                _, phi, _ = scipy.signal.dlsim(sys, after[:, [j]])
                columns.append(np.asarray(phi, float).reshape(-1))
            X = np.column_stack([*columns, constant])
            coef, *_ = np.linalg.lstsq(X, e.reshape(-1), rcond=None)
            rss = float(np.sum((e.reshape(-1) - X @ coef) ** 2))
            if rss < best_rss:
                best_rss, best_beta = rss, coef[: u.shape[1]]
        return 1.0 + np.asarray(best_beta, float)


def embedded(design: LQGDesign, tracked: tuple[int, ...]) -> LQGDesign:
    """``design`` given the integrators of the outputs ``tracked`` that it lacks, each with zero gain and weight.

    A design that tracks a subset of the outputs then has the integrators (and the reference) of ``tracked``: the
    added integrators count the error but never act, and with error injection that error still reaches the
    estimator, so the state feedback regulates those outputs towards their references without integral action.

    Parameters
    ----------
    design : LQGDesign
        Tracks a subset of ``tracked``.
    tracked : tuple of int
        The outputs (indices) to have integrators for, in this order.

    Returns
    -------
    LQGDesign
        ``design`` itself when it already tracks ``tracked``.

    Raises
    ------
    DesignError
        ``design`` tracks an output not in ``tracked``.

    Examples
    --------
    >>> from trms.control.lqg import design_lqg
    >>> two = control.ss(np.diag([0.9, 0.8]), np.eye(2), np.eye(2), np.zeros((2, 2)), 0.1)
    >>> one = embedded(design_lqg(two, tracked_outputs=[0]), (0, 1))
    >>> one.tracked, one.Ki.shape, bool(np.all(one.Ki[:, 1] == 0.0))
    ((0, 1), (2, 2), True)
    """
    tracked = tuple(int(i) for i in tracked)
    if design.tracked == tracked:
        return design
    extra = sorted(set(design.tracked) - set(tracked))
    if extra:
        raise DesignError(f"the design tracks outputs {extra} that the loop does not; allowed: a subset of {tracked}")
    n = design.n_states
    rows = list(range(n)) + [n + tracked.index(i) for i in design.tracked]
    size = n + len(tracked)
    K = np.zeros((design.K.shape[0], size))
    K[:, rows] = design.K
    Q, P = np.zeros((size, size)), np.zeros((size, size))
    Q[np.ix_(rows, rows)], P[np.ix_(rows, rows)] = design.Q, design.P
    return dataclasses.replace(design, tracked=tracked, K=K, Q=Q, P=P)
