"""Controllers of a batch stacked into one: one ``update`` over all loops, matrix arithmetic on stacked states.

The integral LQG (:class:`trms.control.lqg.LQGController`) and the decentralised loops
(:class:`trms.control.loop.DiagonalController`) are linear apart from their clipping and
anti-windup, so B copies of them advance together as products of stacked matrices
``(B, a, b)`` with stacked vectors ``(B, b)``. Every product is ``numpy.matmul`` of one
matrix with one column per loop, the same kernel the single controller uses, and every
operation is the single controller's in the same order, so a stacked update returns the
same bits as B separate updates.

Any other controller of the :class:`~trms.control.loop.Controller` protocol (PID, H-infinity, MPC, ...)
is stacked as :class:`StackedLoops`: B independent controllers, each updated once per control
interval with its own loop's reference and measurement, so its output is the single controller's
by construction.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from trms.control.loop import Controller, DiagonalController, LoopSet
from trms.control.lqg import LQGController
from trms.errors import ConfigurationError, InputError

__all__ = ["StackedLQG", "StackedDiagonal", "StackedLoops", "stack_controllers"]


def _mv(matrix: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """``matrix[b] @ vectors[b]`` for every ``b`` (one matrix-vector product per loop)."""
    return np.matmul(matrix, vectors[..., None])[..., 0]


class StackedLQG:
    """B integral LQG compensators (:class:`~trms.control.lqg.LQGController`) advanced together.

    Parameters
    ----------
    controllers : sequence of LQGController
        Same sizes, tracked outputs and reference injection; designs and limits may differ.

    Examples
    --------
    >>> from trms.worlds import design_model
    >>> from trms.control.lqg import LQGController, design_lqg
    >>> c = LQGController(design_lqg(design_model("1dof"), R=75.0))
    >>> s = StackedLQG([c, c])
    >>> s.update(np.zeros((2, 1)), np.zeros((2, 1))).shape
    (2, 1)
    """

    def __init__(self, controllers: Sequence[LQGController]) -> None:
        if not controllers or not all(isinstance(c, LQGController) for c in controllers):
            raise InputError("StackedLQG needs a non-empty sequence of LQGController")
        d0 = controllers[0].design
        for c in controllers:
            d = c.design
            if (
                d.tracked != d0.tracked
                or d.reference_injection != d0.reference_injection
                or d.K.shape != d0.K.shape
                or d.Lc.shape != d0.Lc.shape
            ):
                raise ConfigurationError(
                    "stacked LQG controllers must share sizes, tracked outputs and reference injection"
                )
        mats = [
            (
                np.asarray(c.design.model.A, float),
                np.asarray(c.design.model.B, float),
                np.asarray(c.design.model.C, float),
                c.design.Lc,
                c.design.Kx,
                c.design.Ki,
            )
            for c in controllers
        ]
        self._A, self._B, self._C, self._Lc, self._Kx, self._Ki = (np.stack(m) for m in zip(*mats))
        self._tracked = np.asarray(d0.tracked, dtype=np.intp)
        self._inject = 1.0 if d0.reference_injection == "error" else 0.0
        self._lower = np.stack([c.input_limits[0] for c in controllers])
        self._upper = np.stack([c.input_limits[1] for c in controllers])
        self._ts = float(d0.sample_time)
        if any(not np.isclose(c.sample_time, self._ts, rtol=1e-9, atol=0.0) for c in controllers):
            raise ConfigurationError("stacked controllers must share one sample time")
        self.reset()

    @property
    def size(self) -> int:
        """Number of loops B."""
        return int(self._A.shape[0])

    @property
    def sample_time(self) -> float:
        """Sample time (s) of every loop."""
        return self._ts

    @property
    def n_references(self) -> int:
        """References per loop (tracked outputs)."""
        return int(self._tracked.size)

    @property
    def estimate(self) -> np.ndarray:
        """Current estimates ``x_hat(k)``, shape ``(B, n)``."""
        return self._x_hat.copy()

    def reset(self) -> None:
        """Zero every estimate and integrator."""
        b, n = self._A.shape[:2]
        self._x_bar = np.zeros((b, n))
        self._x_hat = np.zeros((b, n))
        self._xi = np.zeros((b, self._tracked.size))

    def update(self, reference: np.ndarray, measurement: np.ndarray) -> np.ndarray:
        """One sample of every loop: references ``(B, p_t)`` and measurements ``(B, p)`` (deviation rad)
        in, commanded inputs ``(B, m)`` (deviation V, not clipped) out."""
        r = np.asarray(reference, float)
        y = np.asarray(measurement, float)
        y_est = y.copy()
        y_est[:, self._tracked] -= self._inject * r
        x_hat = self._x_bar + _mv(self._Lc, y_est - _mv(self._C, self._x_bar))
        u = -(_mv(self._Kx, x_hat)) - _mv(self._Ki, self._xi)
        held = np.minimum(np.maximum(u, self._lower), self._upper)
        over, under = u > self._upper, u < self._lower
        error = r - y[:, self._tracked]
        du = -(_mv(self._Ki, error))
        hold = np.any(over & (du > 0), axis=1) | np.any(under & (du < 0), axis=1)
        error[hold] = 0.0
        self._xi = self._xi + error
        self._x_hat = x_hat
        self._x_bar = _mv(self._A, x_hat) + _mv(self._B, held)
        return u


class StackedDiagonal(LoopSet):
    """B decentralised controllers (:class:`~trms.control.loop.DiagonalController`) advanced together."""

    def __init__(self, controllers: Sequence[DiagonalController]) -> None:
        c0 = controllers[0]
        if any((c.outputs, c.inputs, c.n_inputs) != (c0.outputs, c0.inputs, c0.n_inputs) for c in controllers):
            raise ConfigurationError("stacked decentralised controllers must share their loop structure")
        self.loops = tuple(stack_controllers([c.loops[j] for c in controllers]) for j in range(len(c0.loops)))
        self.outputs, self.inputs, self.n_inputs = c0.outputs, c0.inputs, c0.n_inputs
        self._ts = c0.sample_time
        self._size = len(controllers)

    def update(self, reference: np.ndarray, measurement: np.ndarray) -> np.ndarray:
        """References ``(B, loops)`` and measurements ``(B, p)`` in, inputs ``(B, n_inputs)`` out."""
        r = np.asarray(reference, float)
        y = np.asarray(measurement, float)
        u = np.zeros((self._size, self.n_inputs))
        for j, (c, o, i) in enumerate(zip(self.loops, self.outputs, self.inputs)):
            u[:, i] = c.update(r[:, [j]], y[:, [o]])[:, 0]
        return u


class StackedLoops:
    """B independent controllers of any kind, each updated once per control interval on its own loop.

    Parameters
    ----------
    controllers : sequence of Controller
        One distinct object per loop (each keeps its own state), one sample time and one number of
        references.

    Raises
    ------
    ConfigurationError
        Something that is not a Controller, one object for several loops, or differing sample times
        or numbers of references.

    Examples
    --------
    Two proportional loops, each with its own gain, on their own references and measurements:

    >>> from trms.control.pid import PIDController, PIDGains
    >>> s = StackedLoops([PIDController(PIDGains(kp=k, ki=0.0, kd=0.0), 0.2) for k in (1.0, 2.0)])
    >>> s.update(np.array([[0.1], [0.1]]), np.zeros((2, 1))).tolist()
    [[0.1], [0.2]]
    """

    def __init__(self, controllers: Sequence[Controller]) -> None:
        if not controllers or not all(isinstance(c, Controller) for c in controllers):
            raise ConfigurationError(
                "StackedLoops needs a non-empty sequence of controllers (reset, update, sample_time)"
            )
        if len({id(c) for c in controllers}) != len(controllers):
            raise ConfigurationError("every loop of a batch needs its own controller object (each keeps its own state)")
        self._controllers = list(controllers)
        self._ts = float(controllers[0].sample_time)
        if any(not np.isclose(c.sample_time, self._ts, rtol=1e-9, atol=0.0) for c in controllers):
            raise ConfigurationError("stacked controllers must share one sample time")
        refs = {int(getattr(c, "n_references", 1)) for c in controllers}
        if len(refs) != 1:
            raise ConfigurationError(f"stacked controllers must track as many references, got {sorted(refs)}")
        self._n_references = refs.pop()
        self._estimating = all(hasattr(c, "estimate") for c in controllers)  # as closed_loop decides

    @property
    def size(self) -> int:
        """Number of loops B."""
        return len(self._controllers)

    @property
    def sample_time(self) -> float:
        """Sample time (s) of every loop."""
        return self._ts

    @property
    def n_references(self) -> int:
        """References per loop."""
        return self._n_references

    @property
    def estimate(self) -> np.ndarray | None:
        """Every loop's state estimate stacked, ``(B, n)``, when every controller has one (MPC); else None."""
        if not self._estimating:
            return None
        return np.stack([np.asarray(c.estimate) for c in self._controllers])  # type: ignore[attr-defined]

    def reset(self) -> None:
        """Reset every controller."""
        for c in self._controllers:
            c.reset()

    def update(self, reference: np.ndarray, measurement: np.ndarray) -> np.ndarray:
        """References ``(B, p_t)`` and measurements ``(B, p)`` (deviation rad) in, each loop's ``update`` of its
        own row; commanded inputs ``(B, m)`` (deviation V) out."""
        r = np.asarray(reference, float)
        y = np.asarray(measurement, float)
        return np.stack([np.asarray(c.update(r[b], y[b]), float) for b, c in enumerate(self._controllers)])


def stack_controllers(controllers: Sequence[Controller]) -> StackedLQG | StackedDiagonal | StackedLoops:
    """Stack B controllers into one batched controller.

    Parameters
    ----------
    controllers : sequence of Controller
        All :class:`~trms.control.lqg.LQGController` (vectorised: :class:`StackedLQG`), all
        :class:`~trms.control.loop.DiagonalController` (:class:`StackedDiagonal`, each loop stacked
        in turn), or any other controllers (:class:`StackedLoops`, one object per loop).

    Returns
    -------
    StackedLQG or StackedDiagonal or StackedLoops

    Raises
    ------
    ConfigurationError
        Something that is not a controller, or controllers that cannot share a batch (see :class:`StackedLoops`).

    Examples
    --------
    >>> from trms.worlds import design_model
    >>> from trms.control.lqg import LQGController, design_lqg
    >>> c = LQGController(design_lqg(design_model("1dof"), R=75.0))
    >>> stack_controllers([c] * 3).size
    3
    >>> from trms.control.pid import PIDController, PIDGains
    >>> type(stack_controllers([PIDController(PIDGains(1.0, 0.0, 0.0), 0.2) for _ in range(2)])).__name__
    'StackedLoops'
    """
    if not controllers:
        raise InputError("stack_controllers needs at least one controller")
    lqgs = [c for c in controllers if type(c) is LQGController]
    if len(lqgs) == len(controllers):
        return StackedLQG(lqgs)
    diagonals = [c for c in controllers if type(c) is DiagonalController]
    if len(diagonals) == len(controllers):
        return StackedDiagonal(diagonals)
    return StackedLoops(controllers)
