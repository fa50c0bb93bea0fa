"""State-space models by the prediction-error method (MATLAB ``ssest``), MIMO, started from n4sid.

The model is the innovations form

``x(t+1) = A x(t) + B u(t) + K e(t)``,  ``y(t) = C x(t) + D u(t) + e(t)``,

whose one-step predictor ``x^(t+1) = (A - K C) x^ + (B - K D) u + K y``, ``y^ = C x^ + D u``, run from
``x^(0) = 0``, gives the prediction errors ``e = y - y^`` (:func:`state_space_residuals`; no loop over the
samples: the predictor's transfer function, one ``lfilter`` call and ``n + 1`` products).

1. Start: :func:`~trms.identification.subspace.n4sid` of the given order (its ``A, B, C``, and ``D`` with
   ``feedthrough``, else ``D = 0``, the Record convention that ``y(t)`` depends on ``u`` before ``t`` only), with
   n4sid's Kalman gain ``K`` or ``K = 0`` (the output-error predictor), whichever predicts the data better: a
   gain far from the optimum's leaves the search a long curved valley to creep along.
2. Parametrisation: every entry of ``A, B, C, K`` (and ``D``) is free. That leaves the ``n^2`` directions of the
   similarity transforms ``x -> T x``, along which the predictor does not change; the search runs in data-driven
   local coordinates ``theta = theta0 + Q eta``, ``Q`` an orthonormal basis of the orthogonal complement of
   the tangent space of the similarity transforms at ``theta0``: ``n (m + 2 p) (+ p m)`` coordinates, all
   identifiable for a minimal model, so the problem is well-conditioned without a regularisation. The
   coordinates are re-centred at the end of each search (at most six searches).
3. Criterion: ``sum_t e(t)^T W e(t)``, ``W`` the inverse innovation covariance. With one output ``W`` is a
   scale (the minimiser is that of the sum of squares); with several it is re-estimated from the errors of the
   last search and the search repeated until ``det`` of the innovation covariance settles: that fixed point is a
   stationary point of ``det(E^T E / N)``, the Gaussian maximum-likelihood criterion, whatever the start.
4. Search (:mod:`trms.identification.ss_predictor`): ``scipy.optimize.least_squares`` (Levenberg-Marquardt,
   column-scaled) with the analytic Jacobian: every parameter's sensitivity is the predictor's response to one
   injected signal (a state, an input or a prediction error), so one filtering of ``n + m + p`` signals gives
   all of them; a point whose predictor ``A - K C`` has an eigenvalue on or outside the unit circle is refused (a large
   constant residual), so the predictor stays stable.
5. Parameter covariance: ``Cov(eta) = sigma^2 (J^T J)^-1`` from the Jacobian ``J`` of the whitened errors at the
   optimum (:func:`~trms.identification.pem.covariance`), mapped to ``Cov(theta) = Q Cov(eta) Q^T``, which is
   zero along the similarity directions (they are not identifiable).
"""

from __future__ import annotations

import warnings

import control
import numpy as np

from trms.display import html_table
from trms.errors import EstimationError, InputError, check_in_range, check_int
from trms.identification.dataset import Dataset
from trms.identification.pem import covariance
from trms.identification.ss_predictor import _covariance_of, _Layout, _loss, _minimise, _predictor_output
from trms.identification.subspace import UnstableModelWarning, _arrays, _fit_or_nan, n4sid
from trms.record import Record

__all__ = ["ssest", "PemStateSpace", "state_space_residuals"]


def _data(data: Record | object, u: object | None, sample_time: float | None) -> tuple[np.ndarray, np.ndarray, float]:
    """Outputs ``(N, p)``, inputs ``(N, m)`` and the sample time of a Record, a one-experiment Dataset or arrays."""
    if isinstance(data, Dataset):
        if data.n_experiments != 1:
            raise InputError(
                f"the dataset has {data.n_experiments} experiments; ssest takes one: select it (dataset[0])"
            )
        data = data.to_record(0)
    return _arrays(data, u, sample_time)


def state_space_residuals(
    model: control.StateSpace, data: Record | object, u: object | None = None, *, sample_time: float | None = None
) -> np.ndarray:
    """One-step prediction errors of a discrete innovations model on data (from a zero predictor state).

    Parameters
    ----------
    model : control.StateSpace
        Discrete; its ``kalman_gain`` (``K``, as :func:`~trms.identification.subspace.n4sid` and :func:`ssest`
        give it) is used, ``K = 0`` (the output error) where it has none.
    data : Record, Dataset or array_like
        A Record (deviations of all its channels), a Dataset of one experiment, or the outputs ``y``, shape
        ``(N,)`` or ``(N, p)``.
    u : array_like, optional
        Inputs with an array ``y``, shape ``(N,)`` or ``(N, m)`` (input units).
    sample_time : float, optional
        Seconds per sample (required with arrays; must equal the model's).

    Returns
    -------
    numpy.ndarray
        ``e = y - y^``, shape ``(N, p)`` (output units).

    Raises
    ------
    InputError
        Channels that do not match the model, a sample time that differs from the model's.

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> u = np.sign(np.random.default_rng(0).standard_normal(500))
    >>> y = scipy.signal.lfilter([0, 1.0], [1, -0.5], u)
    >>> e = state_space_residuals(control.ss([[0.5]], [[1.0]], [[1.0]], [[0.0]], 0.1), y, u, sample_time=0.1)
    >>> float(np.max(np.abs(e)))
    0.0
    """
    y, ua, ts = _data(data, u, sample_time)
    if not np.isclose(ts, float(model.dt)):
        raise InputError(f"sample_time = {ts} s differs from the model's {model.dt} s")
    if (ua.shape[1], y.shape[1]) != (model.ninputs, model.noutputs):
        raise InputError(
            f"the data have {ua.shape[1]} inputs and {y.shape[1]} outputs; the model has {model.ninputs} and "
            f"{model.noutputs}"
        )
    gain = getattr(model, "kalman_gain", np.zeros((model.nstates, model.noutputs)))
    return y - _predictor_output(model.A, model.B, model.C, model.D, np.asarray(gain, float), y, ua)


class PemStateSpace(control.StateSpace):
    """The discrete innovations model :func:`ssest` returns: a :class:`control.StateSpace` (``A, B, C, D``) that
    also keeps its noise model and how it was fitted, shown compactly by ``repr`` and in notebooks.

    Attributes
    ----------
    kalman_gain : numpy.ndarray
        ``K``, shape ``(states, outputs)``, of ``x(t+1) = A x + B u + K e``, ``y = C x + D u + e``.
    innovation_covariance : numpy.ndarray
        ``E^T E / N`` of the prediction errors ``e`` on the estimation data, shape ``(outputs, outputs)``.
    loss : float
        ``det`` of the innovation covariance (output units squared, the mean squared prediction error for one
        output): the criterion minimised.
    fit : numpy.ndarray
        One-step prediction fit (%) of each output on the estimation data.
    n_samples : int
        Samples of the estimation data.
    parameter_covariance : numpy.ndarray
        Covariance of ``theta = [vec A, vec B, vec C, vec K (, vec D)]`` (row-major ``vec``), zero along the
        (unidentifiable) similarity directions.
    info : dict
        ``initial_loss`` (the start's), ``start_gain`` (``"start"``: the start's own Kalman gain, ``"zero"``:
        ``K = 0``), ``passes``, ``evaluations`` (of the prediction errors), ``feedthrough``, ``horizon``.
    """

    kalman_gain: np.ndarray
    innovation_covariance: np.ndarray
    loss: float
    fit: np.ndarray
    n_samples: int
    parameter_covariance: np.ndarray
    info: dict

    @property
    def K(self) -> np.ndarray:  # noqa: N802 (the textbook name, as A, B, C, D)
        """The Kalman gain (alias of :attr:`kalman_gain`)."""
        return self.kalman_gain

    @property
    def std_errors(self) -> np.ndarray:
        """Standard errors of ``theta`` (same order as :attr:`parameter_covariance`)."""
        return np.sqrt(np.maximum(np.diag(self.parameter_covariance), 0.0))

    def to_ss(self) -> control.StateSpace:
        """The input-output model ``(A, B, C, D)`` as a plain python-control discrete StateSpace."""
        return control.ss(self.A, self.B, self.C, self.D, self.dt)

    def residuals(
        self, data: Record | object, u: object | None = None, *, sample_time: float | None = None
    ) -> np.ndarray:
        """One-step prediction errors on data (:func:`state_space_residuals`), shape ``(N, outputs)``."""
        return state_space_residuals(self, data, u, sample_time=sample_time)

    def _summary(self) -> list[tuple[str, str]]:
        return [
            ("order (states)", str(self.nstates)),
            ("inputs, outputs", f"{self.ninputs}, {self.noutputs}"),
            ("sample time (s)", f"{self.dt:g}"),
            ("estimation samples", str(self.n_samples)),
            ("loss (det of innovation covariance)", f"{self.loss:.6g}"),
            ("start's loss", f"{self.info['initial_loss']:.6g}"),
            ("prediction fit (%)", ", ".join(f"{f:.1f}" for f in self.fit)),
            ("largest pole radius |z|", f"{float(np.max(np.abs(self.poles()), initial=0.0)):.4g}"),
        ]

    def __repr__(self) -> str:
        return (
            f"PemStateSpace(order {self.nstates}, {self.ninputs} in, {self.noutputs} out, Ts={self.dt:g} s, "
            f"N={self.n_samples}, loss {self.loss:.4g}, start loss {self.info['initial_loss']:.4g})"
        )

    def _repr_html_(self) -> str:
        return html_table("PemStateSpace (ssest)", self._summary())


def _start(
    initial: control.StateSpace | None,
    y: np.ndarray,
    u: np.ndarray,
    ts: float,
    order: int | None,
    horizon: int | None,
    max_order: int,
) -> control.StateSpace:
    """The search's start: ``initial`` checked against the data, or n4sid's model."""
    if initial is None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UnstableModelWarning)
            return n4sid(y, u, order, sample_time=ts, horizon=horizon, max_order=max_order)
    if not isinstance(initial, control.StateSpace) or not initial.isdtime(strict=True):
        raise InputError(f"initial must be a discrete control.StateSpace, got {type(initial).__name__}")
    if (initial.ninputs, initial.noutputs) != (u.shape[1], y.shape[1]) or not np.isclose(float(initial.dt), ts):
        raise InputError(
            f"initial has {initial.ninputs} inputs, {initial.noutputs} outputs and dt = {initial.dt} s; the data "
            f"have {u.shape[1]}, {y.shape[1]} and {ts} s"
        )
    return initial


def _start_gain(
    start: control.StateSpace, y: np.ndarray, u: np.ndarray, d: np.ndarray, own: bool
) -> tuple[np.ndarray, np.ndarray, str]:
    """The start's Kalman gain, the innovation covariance it gives and its name (``"start"`` or ``"zero"``).

    n4sid's gain (from its noise covariances) can be far from the optimum's (white output noise, where ``K``
    tends to 0, and the predictor's poles to the plant's): the search from it then creeps along a curved
    valley. So ``K = 0`` (the output-error predictor, when ``A`` is stable) is also tried, and the gain of the
    lower loss kept. A given ``initial`` keeps its own gain.
    """
    n, p = start.nstates, y.shape[1]
    candidates = [("start", np.asarray(getattr(start, "kalman_gain", np.zeros((n, p))), float))]
    if not own and n:
        candidates.append(("zero", np.zeros((n, p))))
    best: tuple[float, np.ndarray, np.ndarray, str] | None = None
    for name, k in candidates:
        if n and np.max(np.abs(np.linalg.eigvals(start.A - k @ start.C))) >= 1.0:
            continue
        lam = _covariance_of(y - _predictor_output(start.A, start.B, start.C, d, k, y, u))
        if best is None or _loss(lam) < best[0]:
            best = (_loss(lam), k, lam, name)
    if best is None:
        raise EstimationError(
            f"ssest: the start of order {n} has an unstable predictor (an eigenvalue of A - K C at |z| >= 1, "
            "also with K = 0); try another order or horizon"
        )
    return best[1], best[2], best[3]


def ssest(
    data: Record | object,
    u: object | None = None,
    order: int | None = None,
    *,
    sample_time: float | None = None,
    feedthrough: bool = False,
    horizon: int | None = None,
    max_order: int = 10,
    max_iter: int = 100,
    tol: float = 1e-12,
    initial: control.StateSpace | None = None,
) -> PemStateSpace:
    """Discrete innovations state-space model by the prediction-error method (MATLAB's ``ssest``).

    Parameters
    ----------
    data : Record, Dataset or array_like
        A Record (deviations of all its inputs and outputs), a Dataset of one experiment, or the outputs ``y``,
        shape ``(N,)`` or ``(N, p)``.
    u : array_like, optional
        Inputs with an array ``y``, shape ``(N,)`` or ``(N, m)`` (input units, e.g. V).
    order : int, optional
        States, ``>= 0``; by default n4sid's choice (its singular values, at most ``max_order``).
    sample_time : float, optional
        Seconds per sample (required with arrays).
    feedthrough : bool
        Estimate ``D``; by default ``D = 0`` (the output at ``t`` depends on the inputs before ``t``).
    horizon, max_order : int, optional
        Passed to :func:`~trms.identification.subspace.n4sid` for the start.
    max_iter : int
        Bounds each search to ``4 max_iter`` evaluations of the prediction errors (``>= 1``; Levenberg-Marquardt
        iterations, each with its trial steps).
    tol : float
        Relative tolerance of each search on the loss, the step and the gradient, in ``(0, 1]``.
    initial : control.StateSpace, optional
        A discrete start instead of n4sid's (its ``kalman_gain`` if it has one, else ``K = 0``), of the data's
        inputs, outputs and sample time, with a stable predictor; ``order``, ``horizon`` and ``max_order`` are
        then unused.

    Returns
    -------
    PemStateSpace
        ``A, B, C, D`` (a :class:`control.StateSpace`, ``dt = sample_time``), ``kalman_gain``,
        ``innovation_covariance``, ``loss`` (``det`` of it), ``parameter_covariance`` and ``info``; never worse
        than its n4sid start (``info["initial_loss"]``).

    Raises
    ------
    InputError
        Bad data, an order below 0 or beyond what the horizon reveals, too few samples (as for n4sid).
    EstimationError
        An n4sid start whose predictor is unstable (no stable predictor to search from).

    Warns
    -----
    UnstableModelWarning
        The model has a pole outside the unit circle.

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> rng = np.random.default_rng(0)
    >>> u, e = np.sign(rng.standard_normal(1000)), 0.1 * rng.standard_normal(1000)
    >>> y = scipy.signal.lfilter([0, 1.0], [1, -1.5, 0.7], u) + scipy.signal.lfilter([1, -0.5], [1, -1.5, 0.7], e)
    >>> model = ssest(y, u, 2, sample_time=0.1)
    >>> bool(model.loss <= model.info["initial_loss"]), round(float(np.sqrt(model.loss)), 2)
    (True, 0.1)
    >>> np.round(np.sort(np.abs(model.poles())), 3)
    array([0.837, 0.837])
    """
    y, ua, ts = _data(data, u, sample_time)
    if order is not None:
        order = check_int("order", order, 0)
    max_iter = check_int("max_iter", max_iter, 1)
    tol = check_in_range("tol", tol, 0.0, 1.0, low_open=True)
    start = _start(initial, y, ua, ts, order, horizon, max_order)
    n, m, p = start.nstates, ua.shape[1], y.shape[1]
    layout = _Layout(n, m, p, bool(feedthrough))
    d0 = start.D if feedthrough else np.zeros((p, m))
    k0, lam, gain = _start_gain(start, y, ua, d0, own=initial is not None)
    theta = layout.pack(start.A, start.B, start.C, k0, d0)
    initial_loss = _loss(lam)
    theta, res, basis, lam, passes, evaluations = _minimise(
        layout, theta, y, ua, max_iter, tol, np.ones(theta.size, bool), similarity=True
    )
    a, b, c, k, d, _ = layout.unpack(theta)
    errors = y - _predictor_output(a, b, c, d, k, y, ua)
    n_eta = basis.shape[1]
    sigma2 = float(res.fun @ res.fun) / max(res.fun.size - n_eta, 1)
    cov_eta = covariance(res.jac, sigma2) if n_eta else np.zeros((0, 0))
    model = PemStateSpace(a, b, c, d, ts)
    model.kalman_gain, model.innovation_covariance, model.loss = k, lam, _loss(lam)
    model.fit = np.array([_fit_or_nan(y[:, j], y[:, j] - errors[:, j]) for j in range(p)])
    model.n_samples, model.parameter_covariance = int(y.shape[0]), basis @ cov_eta @ basis.T
    model.info = {
        "initial_loss": initial_loss,
        "start_gain": gain,
        "passes": passes,
        "evaluations": evaluations,
        "feedthrough": bool(feedthrough),
        "horizon": getattr(start, "horizon", None),
    }
    poles = np.linalg.eigvals(a)
    if poles.size and np.max(np.abs(poles)) > 1.0:
        worst = poles[np.argmax(np.abs(poles))]
        warnings.warn(
            f"ssest: the model has a pole at z = {worst:.4g} (|z| = {abs(worst):.4f}) outside the unit circle",
            UnstableModelWarning,
            stacklevel=2,
        )
    return model
