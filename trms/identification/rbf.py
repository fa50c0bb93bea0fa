"""NARX models with Gaussian radial basis function networks, centres by OLS (thesis ch. 5).

The model (eq. 5.1-5.6) predicts the output from the regressor vector (eq. 5.4)

``x(t) = [y(t-1) .. y(t-ny), u(t-nk) .. u(t-nk-nu+1)]``

as ``yhat(t) = w0 + sum_i w_i exp(-||x(t) - c_i||^2 / sigma^2)`` (eq. 5.3, 5.5), all in
normalised units: ``y`` and ``u`` are rescaled to zero mean and unit standard deviation
with the training set's statistics (eq. 5.10-5.12, ``N - 1`` in the variance), and so is
the target.

Training is the orthogonal least squares algorithm of Chen, Cowan and Grant (1991):
every training regressor vector is a candidate centre (or, beyond ``max_candidates``
training vectors, that many of them evenly spaced in time, so the time grows linearly in
``N``); at each pass the candidate whose
column, orthogonalised against the columns already chosen, explains the largest fraction
of the target's energy (its error-reduction ratio, ERR) is added, until the unexplained
fraction ``1 - sum ERR`` falls below ``tolerance`` or ``max_centres`` are chosen. The bias
``w0`` is put in first. The output weights are then the least-squares solution on the
chosen columns.

The ``N x candidates`` matrix of Gaussian responses is never held whole beyond a fixed
size (``OLS_CACHE`` elements, 16 MB): its first columns are kept and orthogonalised in place,
the others are recomputed at every pass a block at a time and projected out of the span of
the chosen columns, and the median distance (the default width) is found exactly by
counting sweeps over the distances. Memory is then ``O(N x max_centres)`` plus that
constant; the result is the same as with the whole matrix (to rounding in the ERR).

Width and range
---------------
The default width is the median distance between training vectors and candidate centres.
A width for which the Gaussian units are indicator functions of their own training vector
(nearly every other response below ``1e-3``) or all but constant (every response above
``0.999``) gives a useless model: :class:`DegenerateWidthWarning` says so. A fitted model
records the range of its training signals; predicting or simulating outside it (the
Gaussian network falls back to its bias there) by more than a quarter of a training
standard deviation raises an :class:`ExtrapolationWarning` naming how far and how often,
and :meth:`NarxRbf.extrapolation` measures any excursion.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np
import scipy.spatial.distance

from trms.display import html_table
from trms.errors import EstimationError, InputError, check_in_range, check_int
from trms.identification.data import lag_matrix, measured_signals, model_signals, siso_data
from trms.identification.ols import OLS_BLOCK, OLS_CACHE, ols_blocks
from trms.identification.order_statistics import order_statistics
from trms.record import Record

__all__ = [
    "NarxRbf",
    "narx_rbf",
    "DegenerateWidthWarning",
    "ExtrapolationWarning",
    "Extrapolation",
    "MAX_CANDIDATES",
]

#: Default cap on candidate centres (training vectors beyond it are subsampled evenly in time).
MAX_CANDIDATES = 1000
#: Excursion beyond the training range (training standard deviations) that raises an ExtrapolationWarning.
_WARN_BEYOND = 0.25
#: Gaussian responses below this count as "off" and above ``1 - _FIRING`` as saturated.
_FIRING = 1e-3


class DegenerateWidthWarning(UserWarning):
    """The Gaussian width makes the units indicator functions or constants."""


class ExtrapolationWarning(UserWarning):
    """A model is run on signals outside the range it was trained on."""


@dataclass(frozen=True)
class Extrapolation:
    """How far signals leave a model's training range.

    Attributes
    ----------
    fraction : float
        Fraction of samples with the input or output outside the training range.
    worst : float
        Largest excursion beyond the range, in training standard deviations.
    """

    fraction: float
    worst: float


def _gaussian(x: np.ndarray, centres: np.ndarray, width: float) -> np.ndarray:
    """``exp(-||x - c||^2 / width^2)`` for every row of ``x`` and every centre (eq. 5.5)."""
    return np.exp(-scipy.spatial.distance.cdist(x, centres, "sqeuclidean") / width**2)


@dataclass(frozen=True, eq=False)
class NarxRbf:
    """A Gaussian RBF NARX model (eq. 5.3-5.5) on normalised signals.

    Attributes
    ----------
    ny, nu, nk : int
        Output lags, input lags, input delay (samples).
    centres : numpy.ndarray
        Centres in the normalised regressor space, shape ``(m, ny + nu)``.
    width : float
        Gaussian width ``sigma`` (normalised units).
    weights : numpy.ndarray
        Output weights, shape ``(m,)``.
    bias : float
        ``w0`` (normalised units).
    y_mean, y_std, u_mean, u_std : float
        Normalisation of the training data (eq. 5.10-5.12).
    sample_time : float
        Seconds per sample.
    err : numpy.ndarray
        ERR of each chosen term, bias first.
    training_sse : float
        Sum of squared one-step errors on the training data, normalised units.
    n_samples : int
        Training targets used.
    y_range, u_range : tuple of float
        ``(min, max)`` of the training output and input (original units).
    """

    ny: int
    nu: int
    nk: int
    centres: np.ndarray
    width: float
    weights: np.ndarray
    bias: float
    y_mean: float
    y_std: float
    u_mean: float
    u_std: float
    sample_time: float
    err: np.ndarray = field(default_factory=lambda: np.zeros(0))
    training_sse: float = float("nan")
    n_samples: int = 0
    y_range: tuple[float, float] = (-np.inf, np.inf)
    u_range: tuple[float, float] = (-np.inf, np.inf)

    @property
    def start(self) -> int:
        """First sample with a prediction: ``max(ny, nk + nu - 1)``."""
        return max(self.ny, self.nk + self.nu - 1)

    @property
    def n_centres(self) -> int:
        """Number of Gaussian units (the bias not counted)."""
        return int(self.centres.shape[0])

    @property
    def training_mse(self) -> float:
        """Mean squared one-step error on the training data (normalised units; ``nan`` if unknown)."""
        return self.training_sse / self.n_samples if self.n_samples else float("nan")

    def __repr__(self) -> str:
        return (
            f"NarxRbf(ny={self.ny} nu={self.nu} nk={self.nk}, {self.n_centres} centres, width {self.width:.3g}, "
            f"Ts={self.sample_time:g} s, N={self.n_samples}, training MSE {self.training_mse:.3g} (normalised))"
        )

    def _repr_html_(self) -> str:
        rows = [
            ("lags ny, nu; delay nk", f"{self.ny}, {self.nu}; {self.nk}"),
            ("Gaussian centres", str(self.n_centres)),
            ("width sigma (normalised)", f"{self.width:.4g}"),
            ("sample time (s)", f"{self.sample_time:g}"),
            ("training samples", str(self.n_samples)),
            ("training MSE (normalised)", f"{self.training_mse:.4g}"),
            ("output mean, std", f"{self.y_mean:.4g}, {self.y_std:.4g}"),
            ("input mean, std", f"{self.u_mean:.4g}, {self.u_std:.4g}"),
            ("output range", f"{self.y_range[0]:.4g} to {self.y_range[1]:.4g}"),
            ("input range", f"{self.u_range[0]:.4g} to {self.u_range[1]:.4g}"),
        ]
        return html_table("NarxRbf", rows)

    def _network(self, x: np.ndarray) -> np.ndarray:
        """Normalised output for normalised regressor rows ``x``."""
        return self.bias + _gaussian(x, self.centres, self.width) @ self.weights

    def _signals(self, y: object | None, u: object) -> tuple[np.ndarray | None, np.ndarray]:
        return model_signals(y, u, self.start)

    def extrapolation(self, y: object | None, u: object) -> Extrapolation:
        """How far ``u`` (and ``y``, if given) leave the training range.

        Parameters
        ----------
        y : array_like or None
            Output (original units), shape ``(N,)``.
        u : array_like
            Input (original units), shape ``(N,)``.

        Returns
        -------
        Extrapolation

        Examples
        --------
        >>> import numpy as np
        >>> rng = np.random.default_rng(0)
        >>> u = rng.uniform(-1, 1, 300)
        >>> y = np.convolve(u, [0, 0.5, 0.3])[:300]
        >>> model = narx_rbf(y, u, 2, 2, 1, sample_time=0.1)
        >>> model.extrapolation(None, 2 * u).fraction > 0.3
        True
        """
        ya, ua = self._signals(y, u)
        outside = np.zeros(ua.size, bool)
        worst = 0.0
        for x, (lo, hi), std in ((ua, self.u_range, self.u_std), (ya, self.y_range, self.y_std)):
            if x is None:
                continue
            beyond = np.maximum(lo - x, x - hi)
            outside |= beyond > 0
            worst = max(worst, float(np.max(beyond, initial=0.0)) / std)
        return Extrapolation(float(np.mean(outside)), worst)

    def _warn_outside(self, y: np.ndarray | None, u: np.ndarray, what: str) -> None:
        ex = self.extrapolation(y, u)
        if ex.worst > _WARN_BEYOND:
            warnings.warn(
                f"{what}: {100 * ex.fraction:.1f} % of the samples lie outside the training range "
                f"(y in [{self.y_range[0]:.4g}, {self.y_range[1]:.4g}], u in [{self.u_range[0]:.4g}, "
                f"{self.u_range[1]:.4g}]), up to {ex.worst:.2f} training standard deviations beyond it: "
                "the Gaussian network extrapolates there",
                ExtrapolationWarning,
                stacklevel=3,
            )

    def _u_lags(self, un: np.ndarray) -> np.ndarray:
        return lag_matrix(un, range(self.nk, self.nk + self.nu), self.start)

    def predict(self, y: object, u: object, horizon: int = 1) -> np.ndarray:
        """``horizon``-step-ahead prediction; ``horizon = 1`` is the one-step-ahead (OSA) output.

        For ``k > 1`` the network is iterated ``k`` times from the measurements available at
        ``t - k`` (vectorised over ``t``); a horizon as long as the record is the free run.

        Parameters
        ----------
        y, u : array_like
            Measured output and input (original units), shape ``(N,)``.
        horizon : int
            Samples ahead, >= 1.

        Returns
        -------
        numpy.ndarray
            Shape ``(N,)``, original units; equal to ``y`` for the first :attr:`start` samples.
        """
        k = check_int("horizon", horizon, 1, unit=" samples")
        ya, ua = measured_signals(y, u, self.start)
        self._warn_outside(ya, ua, "NARX-RBF prediction")
        yn = (ya - self.y_mean) / self.y_std
        ul = self._u_lags((ua - self.u_mean) / self.u_std)
        s = self.start
        steps = [yn]
        for j in range(1, min(k, ya.size) + 1):
            cols = [lag_matrix(steps[max(j - i, 0)], [i], s)[:, 0] for i in range(1, self.ny + 1)]
            nxt = yn.copy()
            nxt[s:] = self._network(np.column_stack(cols + [ul]))
            steps.append(nxt)
        return steps[-1] * self.y_std + self.y_mean

    def residuals(self, y: object, u: object) -> np.ndarray:
        """One-step prediction errors ``y - yhat`` (original units); 0 for the first :attr:`start` samples."""
        ya, _ = measured_signals(y, u, self.start)
        return ya - self.predict(ya, u, 1)

    def simulate(self, u: object, y: object | None = None) -> np.ndarray:
        """Model predicted output (MPO, eq. 5.14): the network fed back its own outputs.

        Parameters
        ----------
        u : array_like
            Input (original units), shape ``(N,)``.
        y : array_like, optional
            Measured output; its first :attr:`start` samples are the initial conditions.
            Without it the model starts from ``y = 0``.

        Returns
        -------
        numpy.ndarray
            Shape ``(N,)``, original units.
        """
        ya, ua = self._signals(y, u)
        n, s = ua.size, self.start
        out = np.zeros(n) if ya is None else ya.copy()
        yn = (out - self.y_mean) / self.y_std
        ul = self._u_lags((ua - self.u_mean) / self.u_std)
        c, w2, wts = self.centres, self.width**2, self.weights
        for t in range(s, n):
            x = np.concatenate([yn[t - self.ny : t][::-1], ul[t - s]])
            yn[t] = self.bias + np.exp(-np.sum((c - x) ** 2, axis=1) / w2) @ wts
        out = yn * self.y_std + self.y_mean
        self._warn_outside(out, ua, "NARX-RBF free run")
        return out


class _RbfColumns:
    """The OLS candidate matrix ``[1, exp(-||x - x[c]||^2 / sigma^2) for c in cand]`` (bias first, eq. 5.5), made on
    demand from ``distances(j0, j1)`` (blocks of the squared distances to candidates ``j0 .. j1 - 1``); counts the
    responses above ``_FIRING`` and ``1 - _FIRING`` of each Gaussian column the first time it is made."""

    def __init__(self, distances: Callable[[int, int], Iterator[np.ndarray]], n: int, sigma: float) -> None:
        self.distances, self.n, self.sigma = distances, n, sigma
        self.firing = self.saturated = self._counted = 0

    def __call__(self, j0: int, j1: int) -> np.ndarray:
        g = np.hstack(
            [np.exp(-d / self.sigma**2) for d in self.distances(max(j0, 1) - 1, j1 - 1)] or [np.ones((self.n, 0))]
        )
        if j1 > self._counted:
            new = g[:, max(self._counted, j0, 1) - max(j0, 1) :]
            self.firing += int(np.count_nonzero(new > _FIRING))
            self.saturated += int(np.count_nonzero(new > 1.0 - _FIRING))
            self._counted = j1
        return np.hstack([np.ones((self.n, 1)), g]) if j0 == 0 else g


def _normalise(name: str, x: np.ndarray) -> tuple[float, float]:
    mean, std = float(np.mean(x)), float(np.std(x, ddof=1))
    if std == 0:
        raise InputError(f"{name} is constant: it cannot be normalised (eq. 5.10) and carries no information")
    return mean, std


def narx_rbf(
    data: Record | object,
    u: object | None = None,
    ny: int = 8,
    nu: int = 8,
    nk: int = 1,
    *,
    width: float | None = None,
    max_centres: int = 30,
    tolerance: float = 1e-3,
    max_candidates: int | None = MAX_CANDIDATES,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
) -> NarxRbf:
    """Train a Gaussian RBF NARX model by forward OLS selection of centres (ch. 5.3-5.5).

    Parameters
    ----------
    data : Record or array_like
        A Record (deviations are used) or the output ``y``.
    u : array_like, optional
        Input with an array ``y``.
    ny, nu, nk : int
        Output lags >= 1, input lags >= 1, input delay >= 0 (samples). The thesis's
        "8th-order NARX" is ``ny = nu = 8``.
    width : float, optional
        Gaussian width ``sigma`` in normalised units; default the median distance between the
        training vectors and the candidate centres. A degenerate width (units that fire only
        on their own sample, or everywhere) gives a :class:`DegenerateWidthWarning`.
    max_centres : int
        Most Gaussian units (the bias not counted).
    tolerance : float
        Stop when the unexplained fraction of the normalised target's energy ``1 - sum ERR``
        is below it.
    max_candidates : int or None
        Most candidate centres (>= ``max_centres``): with more training vectors, that many
        evenly spaced in time are the candidates, so the time grows linearly in ``N`` (about
        ``N x max_candidates`` Gaussian responses per pass); ``None`` takes every training
        vector (the textbook algorithm, time in ``N^2``). Memory is ``O(N x max_centres)``
        either way.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.

    Returns
    -------
    NarxRbf

    Raises
    ------
    InputError
        Bad data, lags too long for the data, a constant signal.
    EstimationError
        Nothing could be selected.

    Examples
    --------
    A Hammerstein system (a square-law input into a first-order lag):

    >>> import numpy as np, scipy.signal
    >>> rng = np.random.default_rng(0)
    >>> u = rng.uniform(-1, 1, 400)
    >>> y = scipy.signal.lfilter([0, 0.3], [1, -0.8], u + 0.5 * u**2)
    >>> model = narx_rbf(y, u, 2, 2, 1, sample_time=0.1, max_centres=20)
    >>> model.n_centres <= 20, bool(np.std(model.residuals(y, u)[2:]) < 0.05 * np.std(y))
    (True, True)
    """
    d = siso_data(data, u, sample_time=sample_time, input=input, output=output)
    ny, nu, nk = check_int("ny", ny, 1), check_int("nu", nu, 1), check_int("nk", nk, 0)
    max_centres = check_int("max_centres", max_centres, 1)
    tol = check_in_range("tolerance", tolerance, 0.0, 1.0)
    start = max(ny, nk + nu - 1)
    n_targets = len(d) - start
    if n_targets < 2 * (ny + nu) + 2:
        raise InputError(
            f"ny={ny}, nu={nu}, nk={nk} leave {n_targets} training targets from {len(d)} samples; "
            f"at least {2 * (ny + nu) + 2} are needed"
        )
    y_mean, y_std = _normalise("output y", d.y)
    u_mean, u_std = _normalise("input u", d.u)
    yn, un = (d.y - y_mean) / y_std, (d.u - u_mean) / u_std
    x = np.hstack([lag_matrix(yn, range(1, ny + 1), start), lag_matrix(un, range(nk, nk + nu), start)])
    target = yn[start:]
    n_x = x.shape[0]
    if max_candidates is None or max_candidates >= n_x:
        cand = np.arange(n_x)
    else:
        cand = np.unique(
            np.round(np.linspace(0, n_x - 1, check_int("max_candidates", max_candidates, max_centres))).astype(int)
        )
    per = max(1, OLS_BLOCK // n_x)
    # small enough to keep: the squared distances are computed once, else block by block at every use
    kept = scipy.spatial.distance.cdist(x, x[cand], "sqeuclidean") if n_x * cand.size <= OLS_CACHE else None

    def distances(j0: int = 0, j1: int = cand.size) -> Iterator[np.ndarray]:
        for k in range(j0, j1, per if kept is None else max(1, j1 - j0)):
            k1 = min(k + per, j1) if kept is None else j1
            yield scipy.spatial.distance.cdist(x, x[cand[k:k1]], "sqeuclidean") if kept is None else kept[:, k:k1]

    if width is None:
        # median over the pairs but each candidate with itself: those are the cand.size zeros, the smallest values
        pairs = n_x * cand.size - cand.size
        ranks = sorted({cand.size + (pairs - 1) // 2, cand.size + pairs // 2})
        keep = OLS_BLOCK if kept is None else kept.size  # a kept matrix is sorted in one sweep
        guide = np.zeros(0)
        if n_x * cand.size > keep:
            side = min(cand.size, math.isqrt(keep))  # about `keep` distances, evenly spread over the matrix
            rows, cols = (
                np.unique(np.round(np.linspace(0, k - 1, m)).astype(int))
                for k, m in ((n_x, keep // side), (cand.size, side))
            )
            guide = scipy.spatial.distance.cdist(x[rows], x[cand[cols]], "sqeuclidean").ravel()
        sigma = float(np.sqrt(np.mean(order_statistics(distances, n_x * cand.size, ranks, guide, keep))))
    else:
        sigma = check_in_range("width", width, 0.0, np.inf, low_open=True)
    columns = _RbfColumns(distances, n_x, sigma)
    sel = ols_blocks(columns, cand.size + 1, target, int(max_centres) + 1, tol, forced=0)
    # the responses of every candidate to its own vector are exp(0) = 1: not counted
    pairs = n_x * cand.size - cand.size
    _check_width((columns.firing - cand.size) / pairs, (columns.saturated - cand.size) / pairs, sigma)
    chosen = cand[sel.selected[1:] - 1]
    if chosen.size == 0:
        raise EstimationError("OLS selected no centre: the target is not explained by any candidate")
    design = np.hstack([np.ones((n_x, 1)), _gaussian(x, x[chosen], sigma)])
    theta, *_ = np.linalg.lstsq(design, target, rcond=None)
    resid = target - design @ theta
    return NarxRbf(
        ny=int(ny),
        nu=int(nu),
        nk=int(nk),
        centres=x[chosen],
        width=sigma,
        weights=theta[1:],
        bias=float(theta[0]),
        y_mean=y_mean,
        y_std=y_std,
        u_mean=u_mean,
        u_std=u_std,
        sample_time=d.sample_time,
        err=sel.err,
        training_sse=float(resid @ resid),
        n_samples=int(target.size),
        y_range=(float(d.y.min()), float(d.y.max())),
        u_range=(float(d.u.min()), float(d.u.max())),
    )


def _check_width(firing: float, saturated: float, sigma: float) -> None:
    """Warn when the Gaussian units respond to (almost) no other training vector, or to all alike.

    ``firing`` and ``saturated`` are the fractions of the unit-sample pairs (a unit with its own sample not
    counted) whose response is above ``_FIRING`` and above ``1 - _FIRING``.
    """
    if firing < 0.01:
        warnings.warn(
            f"width = {sigma:.3g} (normalised units) is degenerate: only {100 * firing:.2g} % of the unit-sample "
            f"pairs respond above {_FIRING:g}, so each unit is an indicator of its own sample and the model "
            "cannot generalise; leave width=None (chosen from the data) or widen it",
            DegenerateWidthWarning,
            stacklevel=3,
        )
    elif saturated > 0.99:
        warnings.warn(
            f"width = {sigma:.3g} (normalised units) is degenerate: {100 * saturated:.3g} % of the unit-sample "
            f"pairs respond above {1 - _FIRING:g}, so the units are nearly constant and collinear; leave "
            "width=None (chosen from the data) or narrow it",
            DegenerateWidthWarning,
            stacklevel=3,
        )
