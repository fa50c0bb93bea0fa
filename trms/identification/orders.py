"""Model order selection by information criterion or validation loss, for every structure the toolkit fits.

:func:`select_order` fits each order of a grid of one polynomial structure (ARX, ARMAX, OE, BJ) and keeps the one
that minimises the criterion; :func:`select_n4sid_order` does the same for the subspace models of
:func:`~trms.identification.subspace.n4sid`, scoring each order by its Kalman predictor's one-step errors. The
criteria are MATLAB's (``fpe``, ``aic``, ``bic``): with ``V`` the loss (the innovation variance, or the determinant
of the innovation covariance for several outputs), ``N`` the predicted samples and ``d`` the free parameters,

* ``fpe = V (1 + d/N) / (1 - d/N)``,
* ``aic = N log V + 2 d``,
* ``bic = N log V + d log N`` (consistent: it finds the true order as ``N`` grows),

or ``loss`` on separate validation data. A subspace model of order ``n`` with ``m`` inputs and ``p`` outputs in
innovations form (``A, B, C, D, K``) has ``d = n (m + 2 p) + m p`` free parameters (the rest fixes the basis).
"""

from __future__ import annotations

import itertools
import warnings
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
import scipy.signal

from trms.errors import EstimationError, InputError, check_choice, check_int
from trms.identification.dataset import Dataset, siso_experiments
from trms.identification.linear import _TOL, _armax, _arx, _check_orders
from trms.identification.oe_bj import bj, oe
from trms.identification.pem import MAX_ITER
from trms.identification.polynomial import PolynomialModel
from trms.identification.subspace import SubspaceModel, UnstableModelWarning, _arrays, n4sid
from trms.record import Record

__all__ = [
    "CRITERIA",
    "STRUCTURES",
    "OrderScore",
    "OrderSelection",
    "select_order",
    "SubspaceScore",
    "SubspaceSelection",
    "select_n4sid_order",
]

#: Criteria the selections can minimise.
CRITERIA = ("loss", "fpe", "aic", "bic")
#: Polynomial structures :func:`select_order` searches.
STRUCTURES = ("armax", "arx", "oe", "bj")


@dataclass(frozen=True)
class OrderScore:
    """One candidate of a polynomial order search: orders, criteria, and why it failed if it did.

    ``na`` is 0 for OE and BJ, ``nc`` 0 for ARX and OE, ``nd`` and ``nf`` 0 for ARX and ARMAX. ``loss`` is the
    innovation variance on the estimation data (output unit squared), ``validation_loss`` the mean squared
    one-step prediction error on the validation data (NaN without them).
    """

    na: int
    nb: int
    nc: int
    nk: int
    n_parameters: int
    loss: float
    fpe: float
    aic: float
    bic: float
    validation_loss: float
    error: str = ""
    nd: int = 0
    nf: int = 0


@dataclass(frozen=True)
class OrderSelection:
    """Result of :func:`select_order`: the chosen model and the whole table."""

    best: PolynomialModel
    criterion: str
    table: tuple[OrderScore, ...]

    def score(self, row: OrderScore) -> float:
        """The value of the selection criterion for one row (the validation loss when there is one)."""
        if self.criterion == "loss":
            return row.validation_loss if np.isfinite(row.validation_loss) else row.loss
        return float(getattr(row, self.criterion))


def _grid(name: str, values: int | Iterable[int]) -> list[int]:
    """An order's candidates: non-negative ints (one, or an iterable of them; text is refused)."""
    if isinstance(values, (str, bytes)) or not isinstance(values, (int, np.integer, Iterable)):
        raise InputError(f"{name} must be an int or an iterable of ints, got {values!r}")
    grid = [values] if isinstance(values, (int, np.integer)) else list(values)
    if not grid:
        raise InputError(f"{name} must name at least one order, got an empty grid")
    return [check_int(name, v, 0) for v in grid]


def _grid_or_na(name: str, values: int | Iterable[int] | None) -> list[int | None]:
    """An order's candidates; ``None`` means "the same as na"."""
    return [None] if values is None else list(_grid(name, values))


def _fit_one(structure: str, exps: tuple, a: int, b: int, c: int, d: int, f: int, k: int) -> PolynomialModel:
    if structure in ("armax", "arx"):
        oa, ob, oc, ok = _check_orders(a, b, c, k)
        return _armax(exps, oa, ob, oc, ok, MAX_ITER, _TOL) if structure == "armax" else _arx(exps, oa, ob, ok)
    one = exps[0]
    if structure == "oe":
        return oe(one.y, one.u, nb=b, nf=f, nk=k, sample_time=one.sample_time)
    return bj(one.y, one.u, nb=b, nc=c, nd=d, nf=f, nk=k, sample_time=one.sample_time)


def select_order(
    data: Record | object,
    u: object | None = None,
    na: int | Iterable[int] = range(1, 7),
    nb: int | Iterable[int] | None = None,
    nc: int | Iterable[int] | None = None,
    nk: int | Iterable[int] = 1,
    *,
    nd: int | Iterable[int] | None = None,
    nf: int | Iterable[int] | None = None,
    structure: str = "armax",
    criterion: str = "bic",
    validation: Record | Dataset | tuple[object, object] | None = None,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
) -> OrderSelection:
    """Fit every order on a grid and keep the one that minimises a criterion.

    Parameters
    ----------
    data : Record, Dataset or array_like
        Estimation data (as for :func:`~trms.identification.linear.armax`; OE and BJ take one experiment).
    u : array_like, optional
        Input with an array ``y``.
    na : int or iterable of int
        The model order ``n`` to try: the order of ``A`` (ARX, ARMAX) or of ``F`` (OE, BJ).
    nb, nc, nd, nf : int, iterable of int or None
        Orders of ``B``, ``C``, ``D`` and ``F``; ``None`` ties them to ``na`` ("order n" means every polynomial
        of the structure has order ``n``, as in the thesis's "4th-order ARMAX"). ``nc`` is ignored for ARX and
        OE, ``nd`` and ``nf`` for ARX and ARMAX.
    nk : int or iterable of int
        Input delays (samples) to try.
    structure : {"armax", "arx", "oe", "bj"}
        Model structure.
    criterion : {"loss", "fpe", "aic", "bic"}
        ``loss`` is the mean squared one-step prediction error on ``validation`` if given,
        else on the estimation data (which always favours the largest order); ``fpe`` and
        ``aic`` (``N log V + 2p``) penalise parameters mildly, ``bic`` (``N log V + p log N``)
        consistently.
    validation : Record, Dataset or (y, u), optional
        Separate data for the ``loss`` criterion (also reported in the table); over a Dataset's
        experiments the loss is the mean over all their predictions.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    input, output : str, optional
        Channel names in a multi-channel Record.

    Returns
    -------
    OrderSelection

    Raises
    ------
    InputError
        An unknown structure or criterion, an empty grid, several experiments for OE or BJ.
    EstimationError
        If no candidate could be fitted.

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> u = np.sign(np.random.default_rng(0).standard_normal(600))
    >>> e = 0.05 * np.random.default_rng(1).standard_normal(600)
    >>> y = scipy.signal.lfilter([0, 0.5, 0.3], [1, -1.2, 0.49], u) + e
    >>> sel = select_order(y, u, na=[1, 2, 3], nb=2, structure="oe", sample_time=0.1)
    >>> sel.best.nf, len(sel.table)
    (2, 3)
    """
    check_choice("structure", structure, STRUCTURES, error=InputError)
    check_choice("criterion", criterion, CRITERIA, error=InputError)
    exps = siso_experiments(data, u, sample_time=sample_time, input=input, output=output)
    if structure in ("oe", "bj") and len(exps) != 1:
        raise InputError(f"{structure} takes one experiment; the data have {len(exps)} (select one)")
    val = None
    if validation is not None:
        val = (
            siso_experiments(validation, input=input, output=output)
            if isinstance(validation, (Record, Dataset))
            else siso_experiments(validation[0], validation[1], sample_time=exps[0].sample_time)
        )
    grids = (
        _grid("na", na),
        _grid_or_na("nb", nb),
        _grid_or_na("nc", nc),
        _grid_or_na("nd", nd),
        _grid_or_na("nf", nf),
        _grid("nk", nk),
    )
    rows: list[OrderScore] = []
    models: list[PolynomialModel | None] = []
    seen: set[tuple[int, ...]] = set()
    for n, b, c, d, f, k in itertools.product(*grids):
        b_ = n if b is None else b
        c_ = (n if c is None else c) if structure in ("armax", "bj") else 0
        d_ = (n if d is None else d) if structure == "bj" else 0
        f_ = (n if f is None else f) if structure in ("oe", "bj") else 0
        a_ = n if structure in ("armax", "arx") else 0
        if (a_, b_, c_, d_, f_, k) in seen:  # na does not enter an OE/BJ whose orders are all given
            continue
        seen.add((a_, b_, c_, d_, f_, k))
        try:
            m = _fit_one(structure, exps, a_, b_, c_, d_, f_, k)
        except (EstimationError, InputError) as exc:
            nan = float("nan")
            rows.append(OrderScore(a_, b_, c_, k, a_ + b_ + c_ + d_ + f_, nan, nan, nan, nan, nan, str(exc), d_, f_))
            models.append(None)
            continue
        v_loss = float("nan")
        if val is not None:
            e = np.concatenate([m.residuals(v.y, v.u)[m.start :] for v in val])
            v_loss = float(e @ e / e.size)
        rows.append(OrderScore(a_, b_, c_, k, m.n_parameters, m.loss, m.fpe, m.aic, m.bic, v_loss, "", d_, f_))
        models.append(m)
    table = tuple(rows)
    fitted = {i: m for i, m in enumerate(models) if m is not None}
    if not fitted:
        raise EstimationError("no candidate order could be fitted: " + "; ".join(r.error for r in rows))
    probe = OrderSelection(next(iter(fitted.values())), criterion, table)
    best = min(fitted, key=lambda i: probe.score(rows[i]))
    return OrderSelection(fitted[best], criterion, table)


@dataclass(frozen=True)
class SubspaceScore:
    """One order of a subspace order search.

    ``loss`` is the determinant of the innovation covariance of the model's Kalman predictor on the estimation
    data (output unit squared, to the power of the outputs), ``validation_loss`` the same on the validation data
    (NaN without them); ``unstable`` says the model had a pole outside the unit circle.
    """

    order: int
    n_parameters: int
    loss: float
    fpe: float
    aic: float
    bic: float
    validation_loss: float
    unstable: bool


@dataclass(frozen=True)
class SubspaceSelection:
    """Result of :func:`select_n4sid_order`: the chosen model, the common horizon and the whole table."""

    best: SubspaceModel
    criterion: str
    horizon: int
    table: tuple[SubspaceScore, ...]

    def score(self, row: SubspaceScore) -> float:
        """The value of the selection criterion for one row (the validation loss when there is one)."""
        if self.criterion == "loss":
            return row.validation_loss if np.isfinite(row.validation_loss) else row.loss
        return float(getattr(row, self.criterion))


def _predictor_loss(model: SubspaceModel, y: np.ndarray, u: np.ndarray, skip: int) -> float:
    """``det`` of the covariance of the Kalman predictor's one-step errors, from rest, after ``skip`` samples."""
    a, b, c, d = (np.asarray(x, float) for x in (model.A, model.B, model.C, model.D))
    k = np.asarray(model.kalman_gain, float)
    n, p = a.shape[0], c.shape[0]
    if n == 0:
        yhat = u @ d.T
    else:
        predictor = (a - k @ c, np.hstack([b - k @ d, k]), c, np.hstack([d, np.zeros((p, p))]), model.dt)
        _, yhat, _ = scipy.signal.dlsim(predictor, np.hstack([u, y]))
        yhat = np.asarray(yhat, float).reshape(y.shape)
    e = (y - yhat)[skip:]
    cov = np.atleast_2d(e.T @ e / e.shape[0])
    return float(np.linalg.det(cov))


def select_n4sid_order(
    data: Record | object,
    u: object | None = None,
    orders: int | Iterable[int] = range(0, 11),
    *,
    criterion: str = "bic",
    validation: Record | tuple[object, object] | None = None,
    sample_time: float | None = None,
    horizon: int | None = None,
    refine: str = "simulation",
) -> SubspaceSelection:
    """Fit an n4sid model of every order in ``orders`` at one horizon and keep the one that minimises a criterion.

    Each subspace model (n4sid's ``refine="none"``) is scored by its Kalman predictor
    (``x(t+1) = (A - K C) x + (B - K D) u + K y``) run from rest over the data, the first ``horizon`` samples left
    out while it settles; the chosen order is then refined as n4sid's ``refine`` says.

    Parameters
    ----------
    data : Record or array_like
        Estimation data as :func:`~trms.identification.subspace.n4sid` takes (outputs ``(N,)`` or ``(N, p)``).
    u : array_like, optional
        Inputs with an array ``y``, ``(N,)`` or ``(N, m)``.
    orders : int or iterable of int
        State dimensions to try (0 is a static gain).
    criterion : {"loss", "fpe", "aic", "bic"}
        As in :func:`select_order`, with ``V`` the determinant of the innovation covariance and
        ``d = n (m + 2 p) + m p`` parameters.
    validation : Record or (y, u), optional
        Separate data for the ``loss`` criterion.
    sample_time : float, optional
        Seconds per sample (required with arrays).
    horizon : int, optional
        Block rows of the Hankel matrices, the same for every order; by default n4sid's own rule applied at the
        largest order tried.
    refine : {"simulation", "none"}
        The refinement of the chosen model (:func:`~trms.identification.subspace.n4sid`; the scores are those of
        the subspace models either way).

    Returns
    -------
    SubspaceSelection

    Raises
    ------
    InputError
        An unknown criterion, an empty grid, validation data with other channels.
    EstimationError
        If no order could be fitted.

    Examples
    --------
    >>> import numpy as np, scipy.signal
    >>> u = np.sign(np.random.default_rng(0).standard_normal(1500))
    >>> e = 0.05 * np.random.default_rng(1).standard_normal(1500)
    >>> y = scipy.signal.lfilter([0, 1.0], [1, -1.5, 0.7], u) + e
    >>> sel = select_n4sid_order(y, u, orders=range(0, 6), sample_time=0.1)
    >>> sel.best.nstates
    2
    """
    check_choice("criterion", criterion, CRITERIA, error=InputError)
    refine = check_choice("refine", refine, ("simulation", "none"), error=InputError)
    y, ua, ts = _arrays(data, u, sample_time)
    grid = sorted(set(_grid("orders", orders)))
    if horizon is None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UnstableModelWarning)
            horizon = n4sid(y, ua, max(grid), sample_time=ts, max_order=max(max(grid), 1), refine="none").horizon
    val = None
    if validation is not None:
        vy, vu, _ = (
            _arrays(validation, None, ts)
            if isinstance(validation, Record)
            else _arrays(validation[0], validation[1], ts)
        )
        if vy.shape[1] != y.shape[1] or vu.shape[1] != ua.shape[1]:
            raise InputError(
                f"the validation data have {vu.shape[1]} inputs and {vy.shape[1]} outputs; "
                f"the estimation data {ua.shape[1]} and {y.shape[1]}"
            )
        val = (vy, vu)
    m_in, p = ua.shape[1], y.shape[1]
    n_pred = y.shape[0] - horizon
    rows: list[SubspaceScore] = []
    models: dict[int, SubspaceModel] = {}
    errors: list[str] = []
    for n in grid:
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", UnstableModelWarning)
                model = n4sid(y, ua, n, sample_time=ts, horizon=horizon, max_order=max(n, 1), refine="none")
        except (InputError, EstimationError, np.linalg.LinAlgError) as exc:
            errors.append(f"order {n}: {exc}")
            continue
        unstable = any(issubclass(w.category, UnstableModelWarning) for w in caught)
        d = n * (m_in + 2 * p) + m_in * p
        v = _predictor_loss(model, y, ua, horizon) if not unstable else float("inf")
        v_val = _predictor_loss(model, *val, horizon) if val is not None and not unstable else float("nan")
        if not (np.isfinite(v) and v > 0):
            fpe = aic = bic = float("inf")
        else:
            fpe = v * (1 + d / n_pred) / (1 - d / n_pred) if n_pred > d else float("inf")
            aic = n_pred * np.log(v) + 2 * d
            bic = n_pred * np.log(v) + d * np.log(n_pred)
        rows.append(SubspaceScore(n, d, v, float(fpe), float(aic), float(bic), v_val, unstable))
        models[n] = model
    if not models:
        raise EstimationError("no order could be fitted: " + "; ".join(errors))
    table = tuple(rows)
    probe = SubspaceSelection(next(iter(models.values())), criterion, horizon, table)
    best = min(rows, key=probe.score)
    chosen = models[best.order]
    if refine != "none":
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UnstableModelWarning)  # scored (and flagged) in the table already
            chosen = n4sid(y, ua, best.order, sample_time=ts, horizon=horizon, max_order=max(best.order, 1))
    return SubspaceSelection(chosen, criterion, horizon, table)
