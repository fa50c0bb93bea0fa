"""Closed loops of any Plant with a sampled controller: SAS (feedback alone) and CSAS (prefilter + feedback).

Thesis ch. 6.8-6.9 (figs. 6.5 and 6.8). The loop works on deviations from the plant's
operating point: the reference (rad) and the controller's input and output are
deviations; the plant speaks absolute values. :class:`trms.record.OperatingPoint` does
every conversion. The Record is built by :func:`trms.plant.drive`, as for open-loop
runs, so its conventions are those of :func:`trms.plant.simulate`: row ``k`` holds the
measurement at ``t_k`` and the absolute input commanded over ``[t_k, t_k + Ts)``.

Per sample ``k``: measure ``y_k``; the controller computes ``u_k`` from the (prefiltered)
reference ``r_k`` and ``y_k - y_trim``; the plant holds ``u_k + u_trim`` (saturating at its
limits and recording it) and returns ``y_{k+1}``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Protocol, runtime_checkable

import numpy as np
from scipy import signal

from trms.control.arguments import index_tuple, positive_count
from trms.control.shaping.filters import Prefilter
from trms.errors import ConfigurationError, InputError, as_finite_array
from trms.plant import Plant, drive
from trms.record import Record

__all__ = [
    "ControllerWrapper",
    "Controller",
    "DiagonalController",
    "Prefiltered",
    "LoopSet",
    "closed_loop",
    "deviation_limits",
    "prepare_reference",
    "loop_metadata",
    "loop_record",
    "check_loop_sample_time",
]


@runtime_checkable
class Controller(Protocol):
    """A sampled controller on deviations: ``update(reference, measurement) -> u``.

    It has a ``sample_time`` (s), ``reset()`` and ``update(reference, measurement)``, which takes the
    reference and the measurement as deviations (rad) and returns the commanded input deviation (V),
    shape ``(m,)``: :class:`~trms.control.lqg.LQGController`, :class:`~trms.control.pid.PIDController`,
    :class:`~trms.control.mpc.MPCController`, :class:`~trms.control.hinf.HinfController` and
    :class:`DiagonalController` are controllers.

    Examples
    --------
    >>> from trms.control.pid import PIDController, PIDGains
    >>> isinstance(PIDController(PIDGains(kp=1.0, ki=0.0, kd=0.0), 0.1), Controller), isinstance(object(), Controller)
    (True, False)
    """

    @property
    def sample_time(self) -> float:
        """Seconds between updates."""
        ...

    def reset(self) -> None:
        """Return to the initial state."""
        ...

    def update(self, reference: object, measurement: object) -> np.ndarray:
        """Reference (rad) and measurement (rad) deviations in; commanded input deviation (V) out."""
        ...


@runtime_checkable
class _Estimating(Protocol):
    """A controller that exposes its state estimate (``LQGController``)."""

    estimate: np.ndarray


class LoopSet:
    """Independent loops sharing one sample time: what a decentralised controller and its stacked batch
    form have in common (``loops``, ``outputs``, ``inputs``, ``n_inputs`` and the sample time).

    Examples
    --------
    >>> from trms.control.pid import PIDController, PIDGains
    >>> p = PIDController(PIDGains(kp=1.0, ki=0.0, kd=0.0), 0.1)
    >>> loops = DiagonalController([p, p], outputs=(0, 1), inputs=(0, 1), n_inputs=2)
    >>> isinstance(loops, LoopSet), loops.sample_time, loops.n_references
    (True, 0.1, 2)
    """

    loops: tuple[Any, ...]
    outputs: tuple[int, ...]
    inputs: tuple[int, ...]
    n_inputs: int
    _ts: float

    @property
    def sample_time(self) -> float:
        """Sample time (s) of every loop.

        Examples
        --------
        >>> from trms.control.pid import PIDController, PIDGains
        >>> DiagonalController([PIDController(PIDGains(1.0, 0.0, 0.0), 0.2)], (0,), (0,), 1).sample_time
        0.2
        """
        return self._ts

    @property
    def n_references(self) -> int:
        """One reference per loop.

        Examples
        --------
        >>> from trms.control.pid import PIDController, PIDGains
        >>> p = PIDController(PIDGains(1.0, 0.0, 0.0), 0.2)
        >>> DiagonalController([p, p, p], (0, 1, 2), (0, 1, 2), 3).n_references
        3
        """
        return len(self.loops)

    def reset(self) -> None:
        """Reset every loop.

        Examples
        --------
        >>> from trms.control.pid import PIDController, PIDGains
        >>> pi = PIDController(PIDGains(kp=1.0, ki=2.0, kd=0.0), 0.1)
        >>> loops = DiagonalController([pi], (0,), (0,), 1)
        >>> _ = loops.update([1.0], [0.0])
        >>> loops.reset()
        >>> pi.integral
        0.0
        """
        for c in self.loops:
            c.reset()


class DiagonalController(LoopSet):
    """Independent SISO loops side by side: loop ``i`` sees reference ``i`` and output ``outputs[i]``
    and drives input ``inputs[i]`` only (no cross-feeding; the decentralised baseline of a MIMO design).

    Parameters
    ----------
    loops : sequence of Controller
        One single-reference, single-measurement, single-input controller per loop.
    outputs, inputs : sequence of int
        The measured output and the driven input of each loop (indices into the plant's).
    n_inputs : int
        Number of plant inputs; an input no loop drives is held at 0 (deviation).

    Raises
    ------
    InputError
        Index lists of different lengths or out of range, no loop.
    ConfigurationError
        Loops with different sample times.

    Examples
    --------
    Loop 0 (``kp = 2``) closes input 0 around output 1, loop 1 (``kp = 3``) input 1 around output 0:

    >>> from trms.control.pid import PIDController, PIDGains
    >>> P = [PIDController(PIDGains(kp=k, ki=0.0, kd=0.0), 0.1) for k in (2.0, 3.0)]
    >>> DiagonalController(P, outputs=(1, 0), inputs=(0, 1), n_inputs=2).update([1.0, 1.0], [0.5, 0.0]).tolist()
    [2.0, 1.5]
    """

    def __init__(
        self, loops: Sequence[Controller], outputs: tuple[int, ...], inputs: tuple[int, ...], n_inputs: int
    ) -> None:
        n_inputs = positive_count("n_inputs", n_inputs)
        inputs = index_tuple("loop inputs", inputs, n_inputs, "input indices")
        if not isinstance(outputs, (tuple, list, np.ndarray)) or not all(
            isinstance(o, (int, np.integer)) and not isinstance(o, (bool, np.bool_)) and o >= 0 for o in outputs
        ):
            raise InputError(f"loop outputs must be non-negative integer output indices, got {outputs!r}")
        if not loops or not (len(loops) == len(outputs) == len(inputs)):
            raise InputError(f"need one output and one input per loop, got {len(loops)} loops, {outputs}, {inputs}")
        ts = {float(c.sample_time) for c in loops}
        if len(ts) != 1:
            raise ConfigurationError(f"all loops must share one sample time, got {sorted(ts)} s")
        self.loops = tuple(loops)
        self.outputs = tuple(int(o) for o in outputs)
        self.inputs = inputs
        self.n_inputs = n_inputs
        self._ts = ts.pop()

    def update(self, reference: Any, measurement: Any) -> np.ndarray:
        """References (deviation rad, one per loop) and measurements (all outputs) in; inputs (deviation V) out.

        Raises
        ------
        InputError
            A reference of the wrong length, values that are not finite.

        Examples
        --------
        An input no loop drives stays at 0:

        >>> from trms.control.pid import PIDController, PIDGains
        >>> loops = DiagonalController([PIDController(PIDGains(2.0, 0.0, 0.0), 0.1)], (0,), (1,), 2)
        >>> loops.update([0.5], [0.0, 0.0]).tolist()
        [0.0, 1.0]
        """
        r = as_finite_array("reference (deviation rad)", np.ravel(reference), (len(self.loops),))
        y = as_finite_array("measurement (deviation rad)", np.ravel(measurement))
        u = np.zeros(self.n_inputs)
        for c, ri, o, i in zip(self.loops, r, self.outputs, self.inputs):
            u[i] = np.ravel(c.update([ri], [y[o]]))[0]
        return u


class ControllerWrapper:
    """A controller around another (``self.controller``): its sample time, reference count and estimate are the
    wrapped one's, and a reset resets it. :class:`Prefiltered` and
    :class:`~trms.control.inversion.InvertedInputs` add what they do to its reference or its output.

    Examples
    --------
    >>> from trms.control.pid import PIDController, PIDGains
    >>> w = ControllerWrapper(PIDController(PIDGains(kp=1.0, ki=0.0, kd=0.0), 0.1))
    >>> w.sample_time, w.n_references
    (0.1, 1)
    """

    def __init__(self, controller: Controller) -> None:
        self.controller = controller

    @property
    def sample_time(self) -> float:
        """The wrapped controller's sample time (s)."""
        return float(self.controller.sample_time)

    @property
    def n_references(self) -> int:
        """The wrapped controller's reference count."""
        return int(getattr(self.controller, "n_references", 1))

    def __getattr__(self, name: str) -> Any:
        """The wrapped controller's ``estimate``, where it has one (so a loop records it); nothing else."""
        if name == "estimate":
            return self.__dict__["controller"].estimate
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def reset(self) -> None:
        """Reset the wrapped controller."""
        self.controller.reset()


class Prefiltered(ControllerWrapper):
    """A controller that shapes its own reference through a command prefilter, one sample at a time: the CSAS
    structure of :func:`closed_loop` with a prefilter, for loops whose reference arrives sample by sample (a
    Gymnasium policy, a rig's real-time loop). The filter starts at rest at 0, as :func:`closed_loop`'s does, and
    returns the same bits.

    Parameters
    ----------
    controller : Controller
    prefilter : CommandFilter
        Second-order sections (:class:`~trms.control.shaping.filters.CommandFilter`) at the controller's sample time.

    Examples
    --------
    The same commands as :func:`closed_loop` with the prefilter:

    >>> import control
    >>> from trms.control.pid import PIDController, PIDGains
    >>> from trms.control.shaping import butterworth_lowpass
    >>> from trms.plant import LinearPlant
    >>> plant = LinearPlant(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1))
    >>> lp, ref = butterworth_lowpass(2, 0.2, 0.1), np.full(30, 0.2)
    >>> a = closed_loop(plant, PIDController(PIDGains(kp=1.0, ki=0.5, kd=0.0), 0.1), ref, lp)
    >>> b = closed_loop(plant, Prefiltered(PIDController(PIDGains(kp=1.0, ki=0.5, kd=0.0), 0.1), lp), ref)
    >>> bool(np.array_equal(a.extras["control"], b.extras["control"]))
    True
    """

    def __init__(self, controller: Controller, prefilter: Any) -> None:
        sos = getattr(prefilter, "sos", None)
        if sos is None:
            raise InputError(
                f"prefilter must be a CommandFilter (second-order sections), got {type(prefilter).__name__}"
            )
        check_loop_sample_time("prefilter", prefilter.sample_time, controller)  # type: ignore[arg-type]
        super().__init__(controller)
        self.prefilter = prefilter
        self._sos = np.array(sos)
        self.reset()

    def reset(self) -> None:
        """Reset the controller and the filter (at rest at 0)."""
        super().reset()
        self._zi = np.zeros((self._sos.shape[0], 2, self.n_references))

    def update(self, reference: object, measurement: object) -> np.ndarray:
        """Filter the reference (deviation rad) one sample, then the controller's update."""
        r = as_finite_array("reference (deviation rad)", np.ravel(np.asarray(reference)), (self.n_references,))
        shaped, self._zi = signal.sosfilt(self._sos, r[None, :], axis=0, zi=self._zi)
        return self.controller.update(shaped[0], measurement)


def deviation_limits(plant: Plant) -> tuple[np.ndarray, np.ndarray]:
    """The plant's absolute input limits as deviations from its trim (V).

    Parameters
    ----------
    plant : Plant
        Any plant (e.g. ``+-10 V`` absolute about a trim ``u0`` gives ``-10 - u0, 10 - u0``).

    Returns
    -------
    tuple of numpy.ndarray
        Lower and upper limits (deviation V), shape ``(n_inputs,)`` each.

    Examples
    --------
    +-10 V about a 2 V trim:

    >>> import control
    >>> from trms.plant import LinearPlant
    >>> from trms.record import OperatingPoint
    >>> op = OperatingPoint(np.array([2.0]), np.array([0.0]), ("u1",), ("y1",))
    >>> plant = LinearPlant(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1), op, input_limits=(-10.0, 10.0))
    >>> [v.tolist() for v in deviation_limits(plant)]
    [[-12.0], [8.0]]
    """
    lower, upper = plant.input_limits
    op = plant.operating_point
    return op.input_deviation(lower), op.input_deviation(upper)


def check_loop_sample_time(what: str, value: float, plant: Plant) -> None:
    """Refuse a controller or prefilter (``what``) whose sample time ``value`` (s) differs from the plant's.

    Raises
    ------
    ConfigurationError
        The sample times differ (relative tolerance 1e-9).

    Examples
    --------
    >>> import control
    >>> from trms.control.pid import PIDController, PIDGains
    >>> from trms.plant import LinearPlant
    >>> check_loop_sample_time("controller", 0.1, LinearPlant(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)))
    >>> check_loop_sample_time("controller", 0.2, LinearPlant(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)))
    Traceback (most recent call last):
    ...
    trms.errors.ConfigurationError: controller sample time 0.2 s differs from the plant's 0.1 s; ...
    """
    if not np.isclose(float(value), float(plant.sample_time), rtol=1e-9, atol=0.0):
        raise ConfigurationError(
            f"{what} sample time {float(value)!r} s differs from the plant's {float(plant.sample_time)!r} s; "
            "design it at the plant's sample time"
        )


def closed_loop(
    plant: Plant,
    controller: Controller,
    reference: object,
    prefilter: Prefilter | None = None,
    seed: int | None = None,
    metadata: Mapping[str, Any] | None = None,
) -> Record:
    """Run ``plant`` under ``controller`` tracking ``reference``; SAS without a prefilter, CSAS with one.

    Parameters
    ----------
    plant : Plant
        Any plant (the linear model or the twin); reset with ``seed`` first.
    controller : Controller
        Reset first; its sample time must equal the plant's.
    reference : array_like
        Reference deviations (rad), shape ``(N,)`` for one tracked output or ``(N, p_t)``.
    prefilter : Prefilter, optional
        Command prefilter (CSAS), applied causally to the reference (at rest at 0 before
        the first sample); its sample time must equal the plant's.
    seed : int, optional
        Passed to ``plant.reset``.
    metadata : mapping, optional
        Merged into the Record's metadata.

    Returns
    -------
    Record
        ``N`` rows: absolute inputs and outputs; extras ``reference`` and
        ``prefiltered_reference`` (deviation rad, ``(N, p_t)``), ``control`` (commanded
        deviation V), ``estimate`` (the controller's state estimate, if it has one),
        ``applied_inputs`` and ``saturated`` (from the plant) and the plant's channels.

    Raises
    ------
    ConfigurationError
        Controller or prefilter sample time differs from the plant's.
    InputError
        A reference that is not finite or has the wrong shape.

    Examples
    --------
    A P-controller (``kp = 1``) on a lag of static gain 1 settles at half the reference, ``kp / (1 + kp)``:

    >>> import control
    >>> from trms.control.pid import PIDController, PIDGains
    >>> from trms.plant import LinearPlant
    >>> plant = LinearPlant(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1))
    >>> record = closed_loop(plant, PIDController(PIDGains(kp=1.0, ki=0.0, kd=0.0), 0.1), np.full(100, 0.2))
    >>> len(record), np.round(record.outputs[-1], 9).tolist(), record.metadata["loop"]
    (100, [0.1], 'SAS')
    """
    check_loop_sample_time("controller", controller.sample_time, plant)
    if prefilter is not None:
        check_loop_sample_time("prefilter", prefilter.sample_time, plant)
    ref, shaped = prepare_reference(controller, reference, prefilter)
    op = plant.operating_point
    controller.reset()
    n = ref.shape[0]
    control = np.empty((n, len(plant.input_names)))
    estimator = controller if isinstance(controller, _Estimating) else None
    estimates: list[np.ndarray] = []

    def policy(k: int, y: np.ndarray) -> np.ndarray:
        u = controller.update(shaped[k], op.output_deviation(y))
        control[k] = u
        if estimator is not None:
            estimates.append(estimator.estimate)
        return op.absolute_input(u)

    record = drive(plant, n, policy, seed, loop_metadata(controller, prefilter, metadata))
    return loop_record(record, ref, shaped, control, np.stack(estimates) if estimator is not None else None)


def prepare_reference(
    controller: Controller, reference: object, prefilter: Prefilter | None
) -> tuple[np.ndarray, np.ndarray]:
    """Check a closed loop's reference and shape it: ``(reference, prefiltered)``, ``(N, p_t)`` each (deviation rad).

    Raises
    ------
    InputError
        A reference that is not finite, has the wrong shape or no sample.

    Examples
    --------
    A step through the two-tap ZV shaper of a 2.5 Hz mode at 0.1 s (half period 2 samples):

    >>> from trms.control.pid import PIDController, PIDGains
    >>> from trms.control.shaping.sampled import discrete_shaper
    >>> p = PIDController(PIDGains(kp=1.0, ki=0.0, kd=0.0), 0.1)
    >>> ref, shaped = prepare_reference(p, [0.0, 1.0, 1.0, 1.0], discrete_shaper([(2.5, 0.0)], 0.1, kind="zv"))
    >>> ref.shape, shaped.ravel().tolist()
    ((4, 1), [0.0, 0.5, 0.5, 1.0])
    """
    ref = np.asarray(reference, dtype=float) if not isinstance(reference, np.ndarray) else reference.astype(float)
    if ref.ndim == 1:
        ref = ref[:, None]
    n_ref = getattr(controller, "n_references", ref.shape[1] if ref.ndim == 2 else 1)
    ref = as_finite_array("reference (deviation rad)", ref, (None, n_ref))
    if ref.shape[0] < 1:
        raise InputError("reference must hold at least one sample")
    shaped = ref.copy() if prefilter is None else np.asarray(prefilter.apply(ref), float).reshape(ref.shape)
    return ref, shaped


def loop_metadata(
    controller: object, prefilter: Prefilter | None, metadata: Mapping[str, Any] | None
) -> dict[str, Any]:
    """The metadata a closed loop adds to its Record (loop kind, controller, prefilter), ``metadata`` merged in.

    Examples
    --------
    >>> from trms.control.pid import PIDController, PIDGains
    >>> loop_metadata(PIDController(PIDGains(1.0, 0.0, 0.0), 0.1), None, {"run": 1})
    {'loop': 'SAS', 'controller': 'PIDController', 'prefilter': None, 'reference_unit': 'deviation rad', 'run': 1}
    """
    meta = {
        "loop": "CSAS" if prefilter is not None else "SAS",
        "controller": type(controller).__name__,
        "prefilter": None if prefilter is None else prefilter.name,
        "reference_unit": "deviation rad",
    }
    meta.update(dict(metadata or {}))
    return meta


def loop_record(
    record: Record, reference: np.ndarray, shaped: np.ndarray, control: np.ndarray, estimates: np.ndarray | None
) -> Record:
    """A plant's Record with the loop's extras put first: reference, prefiltered reference, control, estimate.

    Parameters
    ----------
    record : Record
        The plant's run (:func:`trms.plant.drive`).
    reference, shaped : numpy.ndarray
        The raw and the prefiltered reference (deviation rad), ``(N, p_t)``.
    control : numpy.ndarray
        The commanded control (deviation V), ``(N, m)``.
    estimates : numpy.ndarray or None
        The controller's state estimates, one row per sample, if it has them.

    Returns
    -------
    Record

    Examples
    --------
    >>> import control
    >>> from trms.control.pid import PIDController, PIDGains
    >>> from trms.plant import LinearPlant
    >>> plant = LinearPlant(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1))
    >>> record = closed_loop(plant, PIDController(PIDGains(kp=1.0, ki=0.0, kd=0.0), 0.1), np.full(5, 0.2))
    >>> ref, u = record.extras["reference"], record.extras["control"]
    >>> list(loop_record(record, ref, ref, u, np.zeros((5, 1))).extras)[:5]
    ['reference', 'prefiltered_reference', 'control', 'estimate', 'applied_inputs']
    """
    extras = {"reference": reference, "prefiltered_reference": shaped, "control": control}
    if estimates is not None:
        extras["estimate"] = estimates
    extras.update(record.extras)
    return Record(
        record.time, record.inputs, record.outputs, record.input_names, record.output_names, extras, record.metadata
    )
