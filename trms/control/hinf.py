"""H-infinity mixed-sensitivity design (python-control ``mixsyn``, which needs slycot) and its sampled controller.

The design minimises ``gamma = || [W1 S; W2 K S; W3 T] ||_inf`` over stabilising controllers ``K``
(``S = 1 / (1 + G K)``, ``T = 1 - S``), for a continuous plant ``G``. A discrete design model (such as
eq. (3.11), a zero-order-hold model) is first turned into the continuous model whose zero-order-hold
discretisation it is (the exact matrix logarithm, :func:`trms.control.realization.continuous_jacobians`);
the continuous controller is then discretised at the rig's sample time by the bilinear (Tustin) map
``s = 2 (z - 1) / (Ts (z + 1))``, which maps the imaginary axis onto the unit circle and so keeps stability
and the controller's peak gain; at the sensitivity crossover ``wb = 0.5`` rad/s its frequency warping is
0.08 % (``Ts = 0.2 s``) or 0.02 % (0.1 s), so no prewarping is used. Before that, the controller's modes
faster than :data:`FAST_MODE` times the Nyquist frequency are residualised in its modal form
(:func:`trms.control.realization.residualise`, DC gain kept): with a constant ``W2`` and a strictly
proper plant the pitch design has a real pole near ``-1e8`` rad/s, which Tustin would map next to
``z = -1`` (a controller mode ringing at Nyquist) and whose realisation loses every digit beyond the
sixth.

Weights for the pitch axis (:func:`pitch_weights`)
    ``W1 = (s / M + wb) / (s + wb A)``: performance. ``|S| < 1 / |W1|`` forces ``|S(0)| <= A`` (near-integral
    action: a steady offset of at most ``A`` = 0.1 % of the reference), a sensitivity crossover near
    ``wb`` (rad/s) and a sensitivity peak of at most ``M``: with ``gamma <= 1``, ``|S| <= gamma M`` at every
    frequency (``|W1| >= 1 / M``), so the symmetric disk margin ``alpha = 1 / max |S - 1/2|`` is at least
    ``1 / (gamma M + 1/2)`` (0.4 for ``M = 2``, ``gamma = 1``). ``A`` stays above 0 because
    ``mixsyn`` needs weights without poles on the imaginary axis.
    ``W2 = effort``: a constant weight on the control (V/rad), which also makes the problem regular
    (``D12`` of full rank) and limits the controller's high-frequency gain so that the rotor's lag, the
    beam's bending and the encoder noise (none of them in the design model) are not excited.
    No ``W3``: ``W2`` bounds ``|K S|``, and so the controller's gain where ``S`` is near 1, by ``gamma / effort``
    (14 V/rad for the default weights), so the loop rolls off with the plant where the model stops being
    accurate.

Disturbances at the plant input (``Wd``, :func:`~trms.control.generalised_plant.disturbance_plant`)
    Weighting ``S``, ``K S`` and ``T`` alone lets the optimum cancel a lightly damped plant pole with controller
    zeros (Skogestad and Postlethwaite, *Multivariable feedback control*, 2005, ch. 9.3): on eq. (3.11) every such
    design keeps a closed-loop pole at the 0.34 Hz mode with the plant's own damping (0.041), invisible to a
    reference step and ringing after any input disturbance. An exogenous disturbance ``d`` entering at the plant
    input through ``Wd`` adds the blocks ``W1 S G Wd`` and ``W2 K S G Wd`` (the "four-block" problem), which
    contain the plant's poles unless the loop moves them: the optimum must *damp* the mode
    (:mod:`trms.control.damping`). The generalised plant is built explicitly and solved by python-control's
    ``hinfsyn`` (slycot's ``sb10ad``); without ``Wd`` the design is ``mixsyn``'s, bit for bit.

Several outputs (:func:`diagonal_weights`)
    A square plant with ``p`` inputs and outputs takes ``p x p`` weights; :func:`diagonal_weights` puts one
    channel's ``(W1, W2)`` of the form above on each output and input, so each output's ``|S|`` gets its own
    crossover, offset and peak and each input its own control weight, and the synthesis (on the whole
    ``p x p`` plant, its coupling included) trades the channels against one another only through ``gamma``.
    ``S = (I + G K)^-1`` and ``K`` maps the ``p`` errors to the ``p`` inputs.
"""

from __future__ import annotations

import contextlib
import ctypes
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import control
import numpy as np

from trms.control._checks import finite_system, is_discrete_dt, real_vector
from trms.control.generalised_plant import disturbance_plant
from trms.control.limits import limit_pair
from trms.control.margins import DiskMargin, disk_margin
from trms.control.realization import continuous_jacobians, residualise
from trms.errors import ConfigurationError, DesignError, InputError, check_in_range

__all__ = [
    "HinfDesign",
    "HinfController",
    "design_mixsyn",
    "pitch_weights",
    "diagonal_weights",
    "continuous_model",
    "FAST_MODE",
]

#: Controller modes faster than this multiple of the Nyquist frequency are residualised before discretising.
FAST_MODE = 100.0


def _require_slycot() -> None:
    try:
        import slycot  # type: ignore[import-untyped]  # noqa: F401
    except ImportError as exc:
        raise ConfigurationError("H-infinity synthesis needs slycot: pip install 'trms[control]'") from exc


@contextlib.contextmanager
def _one_blas_thread() -> Iterator[None]:
    """Run slycot's bundled OpenBLAS on one thread: the synthesis's matrices are tiny (tens of rows), so its thread
    pool only contends with other processes for the cores (a 30 ms synthesis takes seconds on a busy machine)."""
    import slycot

    lib = None
    for path in sorted(Path(slycot.__file__).parent.parent.glob("slycot.libs/libscipy_openblas*.so")):
        try:
            lib = ctypes.CDLL(str(path))
            before = int(lib.scipy_openblas_get_num_threads())
            lib.scipy_openblas_set_num_threads(1)
        except (OSError, AttributeError):
            lib = None
        break
    try:
        yield
    finally:
        if lib is not None:
            lib.scipy_openblas_set_num_threads(before)


def pitch_weights(
    bandwidth: float = 0.5, peak: float = 2.0, low_gain: float = 1e-3, effort: float = 0.05
) -> tuple[control.TransferFunction, control.TransferFunction]:
    """The pitch axis's weights ``(W1, W2)`` (module docstring).

    Parameters
    ----------
    bandwidth : float
        ``wb``, the sensitivity crossover (rad/s).
    peak : float
        ``M``, the allowed peak of ``|S|``.
    low_gain : float
        ``A``, the allowed ``|S(0)|``.
    effort : float
        Constant control weight (V/rad).

    Examples
    --------
    >>> W1, W2 = pitch_weights()
    >>> round(float(abs(W1(0))), 3), round(float(abs(W1(1e6j))), 3)
    (1000.0, 0.5)
    """
    wb = check_in_range("bandwidth", bandwidth, 0.0, 1e3, unit=" rad/s", low_open=True)
    M = check_in_range("peak", peak, 1.0, 10.0)
    A = check_in_range("low_gain", low_gain, 0.0, 1.0, low_open=True)
    w2 = check_in_range("effort", effort, 0.0, 1e6, low_open=True)
    return control.tf([1.0 / M, wb], [1.0, wb * A]), control.tf([w2], [1.0])


def diagonal_weights(*channels: tuple[object, object]) -> tuple[control.StateSpace, control.StateSpace]:
    """Diagonal ``(W1, W2)`` of a square plant from one SISO pair per channel (module docstring).

    Parameters
    ----------
    *channels : tuple of control.LTI
        ``(W1_i, W2_i)`` for output and input ``i`` (e.g. :func:`pitch_weights` with that channel's values).

    Returns
    -------
    tuple of control.StateSpace
        ``W1 = diag(W1_i)`` and ``W2 = diag(W2_i)``, ``p x p`` each.

    Raises
    ------
    InputError
        No channel, or a weight that is not a continuous SISO python-control LTI.

    Examples
    --------
    >>> W1, W2 = diagonal_weights(pitch_weights(bandwidth=0.3), pitch_weights(bandwidth=0.2, effort=0.1))
    >>> W1.noutputs, round(float(abs(W1(0)[1, 1])), 3), round(float(abs(W2(0)[1, 1])), 3), float(abs(W2(0)[0, 1]))
    (2, 1000.0, 0.1, 0.0)
    """
    if not channels:
        raise InputError("diagonal_weights needs at least one (W1, W2) channel pair")
    blocks: list[list[control.StateSpace]] = [[], []]
    for i, pair in enumerate(channels):
        if not isinstance(pair, tuple) or len(pair) != 2:
            raise InputError(f"channel {i} must be a pair (W1, W2) of SISO weights, got {pair!r:.60}")
        for j, w in enumerate(pair):
            if not isinstance(w, control.LTI) or control.isdtime(w, strict=True) or w.ninputs != 1 or w.noutputs != 1:
                raise InputError(f"channel {i}'s W{j + 1} must be a continuous SISO python-control LTI, got {w!r:.60}")
            blocks[j].append(control.ss(w))
    W1, W2 = (control.append(*b) for b in blocks)
    return W1, W2


def continuous_model(model: control.StateSpace | control.TransferFunction) -> control.StateSpace:
    """The continuous model whose zero-order-hold discretisation is ``model`` (exact), or ``model`` if continuous
    (a transfer function is realised first).

    Examples
    --------
    >>> d = control.c2d(control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]]), 0.1)
    >>> round(float(continuous_model(d).A[0, 0]), 12)
    -1.0
    """
    if not isinstance(model, (control.StateSpace, control.TransferFunction)):
        raise InputError(f"model must be a python-control StateSpace or TransferFunction, got {type(model).__name__}")
    A, B, C, D = finite_system(model, "model")  # a transfer function's coefficients checked, then realised
    if not control.isdtime(model, strict=True):
        return control.ss(model)  # python-control's own realisation, as control.mixsyn makes it
    if not is_discrete_dt(model.dt):
        raise InputError(f"model must have a finite sample time dt > 0 (s) or be continuous, got dt = {model.dt!r}")
    poles = np.linalg.eigvals(A) if A.size else np.zeros(0)
    bad = poles[(np.abs(poles) < 1e-12) | ((poles.real <= 0) & (np.abs(poles.imag) < 1e-12))]
    if bad.size:
        raise InputError(
            f"model has a pole at z = {complex(bad[0]).real:.3g}: a discrete pole at 0 or on the negative real axis "
            "has no continuous zero-order-hold equivalent; give the continuous model"
        )
    Ac, Bc = continuous_jacobians(A, B, float(model.dt))
    return control.ss(Ac, Bc, C, D)


@dataclass(frozen=True)
class HinfDesign:
    """A mixed-sensitivity design.

    Attributes
    ----------
    plant : control.StateSpace
        The continuous plant designed on.
    weights : tuple
        ``(W1, W2, W3)`` (``None`` for an absent weight).
    gamma : float
        Achieved ``|| [W1 S; W2 K S; W3 T] ||_inf``.
    controller : control.StateSpace
        Continuous controller ``K(s)`` (error in, V out).
    closed_loop : control.StateSpace
        ``mixsyn``'s closed loop from the exogenous input to the weighted outputs.
    discrete_controller : control.StateSpace or None
        ``K`` without its modes beyond :data:`FAST_MODE` times Nyquist, discretised by Tustin at
        ``sample_time`` (None when no sample time).
    sample_time : float or None
        Seconds.
    disturbance_weight : control.LTI or None
        ``Wd`` of the input-disturbance channel (None: the plain ``mixsyn`` problem).

    Examples
    --------
    The pitch weights (:func:`pitch_weights`: ``M = 2``) on a unit lag sampled at 0.1 s: ``gamma <= 1``, so the
    disk margin of the sampled loop is at least ``1 / (gamma M + 1/2)`` (module docstring):

    >>> s = control.tf("s")
    >>> model = control.c2d(control.ss(1 / (s + 1)), 0.1)
    >>> d = design_mixsyn(model, *pitch_weights())
    >>> round(d.gamma, 3), d.sample_time, bool(d.margin(model).alpha >= 1.0 / (2.0 * d.gamma + 0.5))
    (0.502, 0.1, True)
    """

    plant: control.StateSpace
    weights: tuple[object, object, object]
    gamma: float
    controller: control.StateSpace
    closed_loop: control.StateSpace
    discrete_controller: control.StateSpace | None
    sample_time: float | None
    disturbance_weight: object = None

    def loop(self, model: control.StateSpace) -> control.StateSpace:
        """The discrete loop ``L = K(z) G(z)`` with a discrete model at the design's sample time.

        Raises
        ------
        ConfigurationError
            The design has no sample time.

        Examples
        --------
        >>> s = control.tf("s")
        >>> model = control.c2d(control.ss(1 / (s + 1)), 0.1)
        >>> d = design_mixsyn(model, *pitch_weights())
        >>> L = d.loop(model)
        >>> L.dt, L.ninputs, L.noutputs
        (0.1, 1, 1)
        """
        if self.discrete_controller is None:
            raise ConfigurationError("the design has no sample time; design it with sample_time set")
        return control.series(model, self.discrete_controller)

    def margin(self, model: control.StateSpace) -> DiskMargin:
        """Disk margin (:func:`trms.control.margins.disk_margin`) of the discrete loop with ``model`` (a SISO design;
        a loop of several channels is refused in one line).

        Examples
        --------
        >>> s = control.tf("s")
        >>> model = control.c2d(control.ss(1 / (s + 1)), 0.1)
        >>> d = design_mixsyn(model, *pitch_weights())
        >>> m = d.margin(model)
        >>> m.stable, bool(m.alpha > 1.0), bool(m.phase_margin_deg > 50.0)
        (True, True, True)
        """
        return disk_margin(self.loop(model))

    def stable_with(self, model: control.StateSpace) -> bool:
        """Whether the discrete closed loop with ``model`` (unity negative feedback on every channel) is stable.

        Examples
        --------
        The design holds on its model; 100 times its gain (beyond the disk margin's gain range, up to 20) or the
        opposite sign destabilises the loop:

        >>> s = control.tf("s")
        >>> model = control.c2d(control.ss(1 / (s + 1)), 0.1)
        >>> d = design_mixsyn(model, *pitch_weights())
        >>> d.stable_with(model), d.stable_with(100.0 * model), d.stable_with(-1.0 * model)
        (True, False, False)
        """
        loop = self.loop(model)
        poles = control.feedback(loop, np.eye(loop.ninputs)).poles()
        return bool(np.all(np.abs(poles) < 1.0))


def design_mixsyn(
    model: control.StateSpace | control.TransferFunction,
    W1: object,
    W2: object = None,
    W3: object = None,
    sample_time: float | None = None,
    Wd: object = None,
) -> HinfDesign:
    """Mixed-sensitivity H-infinity design (module docstring), optionally with an input-disturbance channel.

    Parameters
    ----------
    model : control.StateSpace or control.TransferFunction
        Square plant (SISO or ``p`` inputs and ``p`` outputs), continuous or a discrete zero-order-hold model
        (converted exactly).
    W1, W2, W3 : control.LTI or None
        Continuous, stable weights on ``S``, ``K S`` and ``T``, ``p x p`` each (e.g. :func:`pitch_weights`, or
        :func:`diagonal_weights` for several channels); ``W1`` is required.
    sample_time : float, optional
        Sample time (s) of the Tustin-discretised controller; default the model's ``dt`` (none for
        a continuous model).
    Wd : control.LTI, optional
        Input-disturbance weight (module docstring, "Disturbances at the plant input"), ``p x p`` (V per unit of
        the exogenous disturbance); without it the design is python-control's ``mixsyn``.

    Returns
    -------
    HinfDesign

    Raises
    ------
    ConfigurationError
        slycot is missing.
    InputError
        A plant that is not square, a weight of the wrong size, with a pole on or right of the imaginary axis, or
        discrete.
    DesignError
        The synthesis fails (e.g. weights that leave the problem singular).

    Examples
    --------
    >>> s = control.tf("s")
    >>> d = design_mixsyn(1 / (s + 1), control.tf([0.5, 1], [1, 1e-3]), control.tf([0.1], [1]))
    >>> d.gamma < 1.0
    True

    A 2 x 2 plant with a diagonal weight per channel, its controller sampled at 0.1 s:

    >>> G = control.ss(control.tf([[[1], [0.2]], [[0.1], [1]]], [[[1, 1], [1, 2]], [[1, 1], [1, 3]]]))
    >>> d2 = design_mixsyn(G, *diagonal_weights(pitch_weights(), pitch_weights()), sample_time=0.1)
    >>> d2.discrete_controller.ninputs, d2.discrete_controller.noutputs, d2.stable_with(control.c2d(G, 0.1))
    (2, 2, True)
    """
    _require_slycot()
    if isinstance(model, control.LTI) and model.ninputs != model.noutputs:  # before any conversion of the model
        raise InputError(
            f"model must be square (as many inputs as outputs), got {model.noutputs} outputs x {model.ninputs} inputs"
        )
    plant = continuous_model(model)
    ts: float | None
    if sample_time is None:
        ts = float(model.dt) if control.isdtime(model, strict=True) else None
    else:
        ts = check_in_range("sample_time", sample_time, 0.0, 1e3, unit=" s", low_open=True)
    for name, w in (("W1", W1), ("W2", W2), ("W3", W3), ("Wd", Wd)):
        _check_weight(name, w, plant.noutputs)
    if Wd is not None and W2 is None:
        raise InputError("Wd needs a control weight W2 (the disturbance channel's problem is singular without one)")
    try:
        with warnings.catch_warnings(), _one_blas_thread():
            warnings.filterwarnings("ignore", category=FutureWarning, module="control")  # its internal connect()
            if Wd is None:
                K, CL, info = control.mixsyn(plant, W1, W2, W3)
                gamma = float(info[0])
            else:
                P = disturbance_plant(plant, W1, W2, W3, Wd)
                K, CL, gamma, _ = control.hinfsyn(P, plant.noutputs, plant.ninputs)
    except Exception as exc:  # slycot raises several types for a failed synthesis
        raise DesignError(f"the mixed-sensitivity synthesis failed: {' '.join(str(exc).split())[:200]}") from exc
    Kd = None if ts is None else control.c2d(_without_fast_modes(K, ts), ts, method="bilinear")
    return HinfDesign(plant, (W1, W2, W3), float(gamma), K, CL, Kd, ts, Wd)


def _check_weight(name: str, w: object, size: int) -> None:
    """Refuse a weight that is not a continuous, stable ``size x size`` LTI (``None`` allowed but for ``W1``)."""
    if w is None and name != "W1":
        return
    if not isinstance(w, control.LTI) or control.isdtime(w, strict=True):
        raise InputError(f"{name} must be a continuous python-control LTI weight or None, got {w!r:.60}")
    if w.ninputs != size or w.noutputs != size:
        raise InputError(
            f"{name} must be {size}x{size} (one row and column per plant output), got {w.noutputs}x{w.ninputs}"
        )
    poles = np.asarray(control.poles(w), complex)
    if poles.size and not np.all(np.isfinite(poles)):
        raise InputError(f"{name} has poles that are not finite; allowed: a finite, stable weight")
    if poles.size and np.max(poles.real) >= 0.0:
        worst = complex(poles[np.argmax(poles.real)])
        at = f"{worst.real:.4g}" if worst.imag == 0.0 else f"{worst.real:.4g} {worst.imag:+.4g}j"
        raise InputError(
            f"{name} has a pole at s = {at} rad/s; allowed: poles with real part < 0 (a weight must be stable, "
            "e.g. 1 / (s + 1e-3) for near-integral action)"
        )


def _without_fast_modes(K: control.StateSpace, ts: float) -> control.StateSpace:
    """``K`` in modal form with its modes faster than ``FAST_MODE`` times Nyquist residualised (DC gain kept)."""
    modal, _ = control.modal_form(K)
    speed = np.abs(np.linalg.eigvals(np.asarray(modal.A, float)))
    keep = [i for i in range(speed.size) if speed[i] <= FAST_MODE * np.pi / ts]
    if len(keep) == speed.size or not keep:
        return modal
    # modal form is block diagonal: a fast real pole is its own 1x1 block, a fast complex pair a 2x2 block
    return residualise(modal, keep)


class HinfController:
    """A discrete LTI controller on the tracking errors, ``u = K(z) (r - y)``, as a sampled controller.

    The commanded inputs are clipped to ``input_limits`` (deviation V) before they are returned; the
    controller's state runs on unclipped (no anti-windup), so keep references within what the
    actuators can reach. A design on ``p`` outputs takes ``p`` references and measurements and returns
    ``p`` inputs.

    Parameters
    ----------
    design : HinfDesign
        A design with a sample time.
    input_limits : tuple of float or array_like, optional
        ``(lower, upper)`` deviation volts, each a scalar or one per input (``lower <= 0 <= upper``);
        unlimited by default.

    Examples
    --------
    >>> s = control.tf("s")
    >>> d = design_mixsyn(1 / (s + 1), control.tf([0.5, 1], [1, 1e-3]), control.tf([0.1], [1]), sample_time=0.1)
    >>> c = HinfController(d, (-1.0, 1.0))
    >>> abs(float(c.update(10.0, 0.0)[0])) <= 1.0
    True
    """

    def __init__(self, design: HinfDesign, input_limits: tuple[object, object] | None = None) -> None:
        if not isinstance(design, HinfDesign) or design.discrete_controller is None:
            raise InputError("design must be an HinfDesign with a sample time (design_mixsyn(..., sample_time=Ts))")
        self.design = design
        K = design.discrete_controller
        self._A, self._B, self._C, self._D = finite_system(K, "controller")
        lo, hi = limit_pair("input_limits", input_limits, K.noutputs)
        if np.any(lo > 0.0) or np.any(hi < 0.0) or np.any(lo >= hi):
            raise InputError(
                f"input_limits (deviation V) must satisfy lower <= 0 <= upper, got {lo.tolist()}, {hi.tolist()}"
            )
        self.input_limits: tuple[float, float] | tuple[np.ndarray, np.ndarray] = (
            (float(lo[0]), float(hi[0])) if K.noutputs == 1 else (lo, hi)
        )
        self._lo, self._hi = lo, hi
        self.reset()

    @property
    def sample_time(self) -> float:
        """Controller sample time (s).

        Examples
        --------
        >>> s = control.tf("s")
        >>> HinfController(design_mixsyn(1 / (s + 1), *pitch_weights(), sample_time=0.2)).sample_time
        0.2
        """
        return float(self.design.sample_time)  # type: ignore[arg-type]

    @property
    def n_references(self) -> int:
        """One reference per plant output.

        Examples
        --------
        >>> s = control.tf("s")
        >>> HinfController(design_mixsyn(1 / (s + 1), *pitch_weights(), sample_time=0.2)).n_references
        1
        """
        return int(self._B.shape[1])

    def reset(self) -> None:
        """Zero the controller's state.

        Examples
        --------
        >>> s = control.tf("s")
        >>> c = HinfController(design_mixsyn(1 / (s + 1), *pitch_weights(), sample_time=0.1))
        >>> first = c.update(0.1, 0.0)
        >>> _ = c.update(0.1, 0.0)
        >>> c.reset()
        >>> bool(c.update(0.1, 0.0)[0] == first[0])
        True
        """
        self._x = np.zeros(self._A.shape[0])

    def update(self, reference: object, measurement: object) -> np.ndarray:
        """One sample: ``u = K (r - y)`` (deviation rad in, ``(p,)`` each), clipped; returns ``(p,)`` deviation V.

        Raises
        ------
        InputError
            A reference or measurement that is not ``p`` real, finite numbers.

        Examples
        --------
        On the sampled unit lag the loop follows a 0.1 rad step to within ``|S(0)| <= A`` = 0.1 %:

        >>> s = control.tf("s")
        >>> model = control.c2d(control.ss(1 / (s + 1)), 0.1)
        >>> d = design_mixsyn(model, *pitch_weights())
        >>> c = HinfController(d)
        >>> x, y = np.zeros(1), 0.0
        >>> for _ in range(400):
        ...     x = model.A @ x + model.B @ c.update(0.1, y)
        ...     y = float((model.C @ x)[0])
        >>> bool(abs(y - 0.1) <= 1e-3 * 0.1)
        True
        """
        p = self._B.shape[1]
        r = real_vector("reference (deviation rad)", reference, p)
        y = real_vector("measurement (deviation rad)", measurement, p)
        e = r - y
        u = self._C @ self._x + self._D @ e
        self._x = self._A @ self._x + self._B @ e
        return np.minimum(np.maximum(u, self._lo), self._hi)
