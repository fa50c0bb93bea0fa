"""Input-output data for the estimators: from a Record or from arrays, checked once.

Identification works on deviations from the operating point (``Record.deviations()``).
Sample ``k`` of the input is held over ``[k Ts, (k + 1) Ts)`` and output sample ``k`` is
measured at ``k Ts`` (the Record's timing convention), so a physical input delay is at
least one sample (``nk >= 1``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from trms.errors import InputError, as_finite_array, check_in_range
from trms.record import Record

__all__ = [
    "SisoData",
    "Experiments",
    "siso_data",
    "record_deviations",
    "detrend",
    "lag_matrix",
    "check_excitation",
    "model_signals",
    "measured_signals",
]


@runtime_checkable
class Experiments(Protocol):
    """Several experiments of one system, each from rest (:class:`~trms.identification.dataset.Dataset` is one).

    The estimators that take one experiment accept such a collection when it holds exactly one.

    Examples
    --------
    >>> from trms.identification import Dataset
    >>> isinstance(Dataset([np.zeros(5)], [np.ones(5)], sample_time=0.1), Experiments)
    True
    >>> isinstance(np.zeros(5), Experiments)
    False
    """

    @property
    def n_experiments(self) -> int: ...

    @property
    def experiment_names(self) -> tuple[str, ...]: ...

    @property
    def sample_time(self) -> float: ...

    def siso(self, input: str | None = None, output: str | None = None) -> tuple[SisoData, ...]: ...

    def detrend(self, kind: str = "constant") -> Any: ...


def experiments_siso(
    data: Experiments, u: object | None, sample_time: float | None, input: str | None, output: str | None
) -> tuple[SisoData, ...]:
    """The input/output pair of every experiment of ``data``, the arguments checked against it."""
    if u is not None:
        raise InputError("pass either a Dataset or the arrays y and u, not both")
    if sample_time is not None and not np.isclose(float(sample_time), data.sample_time):
        raise InputError(f"sample_time = {sample_time!r} s differs from the dataset's {data.sample_time} s")
    return data.siso(input, output)


@dataclass(frozen=True)
class SisoData:
    """One input and one output channel, as deviations, with their sample time.

    Attributes
    ----------
    y : numpy.ndarray
        Output (rad, or the record's unit), shape ``(N,)``.
    u : numpy.ndarray
        Input (V), shape ``(N,)``.
    sample_time : float
        Seconds between samples.
    input_name, output_name : str
        Channel names (``"u"``/``"y"`` for arrays).
    """

    y: np.ndarray
    u: np.ndarray
    sample_time: float
    input_name: str = "u"
    output_name: str = "y"

    def __len__(self) -> int:
        return int(self.y.size)


def channel_index(names: tuple[str, ...], name: str | None, kind: str) -> int:
    if name is None:
        if len(names) != 1:
            raise InputError(f"the record has {len(names)} {kind}s ({', '.join(names)}); name the {kind} to use")
        return 0
    if name not in names:
        raise InputError(f"unknown {kind} {name!r}; this record has {', '.join(names)}")
    return names.index(name)


def record_deviations(record: Record) -> tuple[np.ndarray, np.ndarray]:
    """A Record's inputs and outputs as deviations from its operating point, refused without one.

    Parameters
    ----------
    record : Record
        Metadata ``operating_point`` set (the twin's records, :func:`~trms.rig.exports.record_from_csv`
        with ``hover_segment`` or ``operating_point``, or :func:`detrend`).

    Returns
    -------
    du, dy : numpy.ndarray
        Inputs (V) and outputs (rad) minus the operating point, shapes ``(N, m)`` and ``(N, p)``.

    Raises
    ------
    InputError
        The record has no operating point.

    Examples
    --------
    >>> from trms.plant import Record
    >>> bare = Record(np.arange(3) * 0.1, np.ones((3, 1)), np.zeros((3, 1)), ("u1",), ("pitch",))
    >>> record_deviations(detrend(bare))[0].ravel()
    array([0., 0., 0.])
    """
    if "operating_point" not in record.metadata:
        raise InputError(
            "the record has no operating point, so its deviations are unknown (identifying absolute values "
            "gives a wrong DC gain and spurious slow modes): give it one (trms.rig.exports.record_from_csv(..., "
            "hover_segment=(t0, t1)) or operating_point=...), or detrend it (trms.identification.detrend)"
        )
    return record.deviations()


def siso_data(
    data: Record | object,
    u: object | None = None,
    *,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
) -> SisoData:
    """Extract one input/output pair from a Record (as deviations) or from two arrays.

    Parameters
    ----------
    data : Record or array_like
        A :class:`trms.record.Record`, or the output samples ``y`` (shape ``(N,)``).
    u : array_like, optional
        The input samples (shape ``(N,)``); required with an array ``y``, refused with a Record.
    sample_time : float, optional
        Seconds between samples; required with arrays, taken from the Record otherwise.
    input, output : str, optional
        Channel names in a Record with several inputs or outputs.

    Returns
    -------
    SisoData

    Raises
    ------
    InputError
        NaN/inf, mismatched lengths, missing ``u`` or ``sample_time``, unknown channels, a
        :class:`~trms.identification.dataset.Dataset` of several experiments (select one).

    Examples
    --------
    >>> d = siso_data(np.array([0.0, 1.0, 0.5]), np.array([1.0, 0.0, 0.0]), sample_time=0.2)
    >>> len(d), d.sample_time, d.input_name
    (3, 0.2, 'u')
    """
    if isinstance(data, Experiments):
        if data.n_experiments != 1:
            raise InputError(
                f"the dataset has {data.n_experiments} experiments ({', '.join(data.experiment_names)}); this "
                "estimator takes one: select it (dataset[0] or dataset['name']), or use arx/armax, which take several"
            )
        return experiments_siso(data, u, sample_time, input, output)[0]
    if isinstance(data, Record):
        if u is not None:
            raise InputError("pass either a Record or the arrays y and u, not both")
        du, dy = record_deviations(data)
        i, o = channel_index(data.input_names, input, "input"), channel_index(data.output_names, output, "output")
        ts = data.sample_time
        if sample_time is not None and not np.isclose(float(sample_time), ts):
            raise InputError(f"sample_time = {sample_time!r} s differs from the record's {ts} s")
        y_arr = as_finite_array(f"output {data.output_names[o]}", dy[:, o])
        u_arr = as_finite_array(f"input {data.input_names[i]}", du[:, i])
        return SisoData(y_arr, u_arr, ts, data.input_names[i], data.output_names[o])
    if u is None:
        raise InputError("with an output array y, the input array u is required")
    if sample_time is None:
        raise InputError("sample_time (s) is required when y and u are arrays")
    y_arr = as_finite_array("y", data)
    u_arr = as_finite_array("u", u)
    if y_arr.ndim != 1 or u_arr.ndim != 1:
        raise InputError(f"y and u must be 1-D (one channel each), got shapes {y_arr.shape} and {u_arr.shape}")
    if y_arr.size != u_arr.size:
        raise InputError(f"y and u must have the same length, got {y_arr.size} and {u_arr.size} samples")
    ts = check_in_range("sample_time", sample_time, 0.0, np.inf, unit=" s", low_open=True)
    return SisoData(y_arr, u_arr, ts, input or "u", output or "y")


def detrend_array(x: np.ndarray, kind: str) -> tuple[np.ndarray, np.ndarray]:
    """Detrended ``x`` (along axis 0) and the removed trend's value at the first sample."""
    n = x.shape[0]
    if kind == "constant":
        trend = np.broadcast_to(x.mean(axis=0), x.shape)
    else:
        t = np.arange(n, dtype=float)
        design = np.column_stack([np.ones(n), t - t.mean()])
        coef, *_ = np.linalg.lstsq(design, x.reshape(n, -1), rcond=None)
        trend = (design @ coef).reshape(x.shape)
    return x - trend, np.array(trend[0], float)


def detrend(data: Record | object, kind: str = "constant") -> Any:
    """Remove the mean (``constant``) or the least-squares line (``linear``) from data.

    Parameters
    ----------
    data : Record, Dataset or array_like
        A Record (inputs and outputs are detrended; the result is a Record whose
        operating point is zero, with the removed means recorded in the metadata as
        ``detrended``), a :class:`~trms.identification.dataset.Dataset` (each experiment
        detrended on its own), or an array (detrended along axis 0).
    kind : {"constant", "linear"}

    Returns
    -------
    Record, Dataset or numpy.ndarray
        The same kind as ``data``.

    Raises
    ------
    InputError
        Unknown ``kind``, NaN/inf, fewer than 2 samples.

    Examples
    --------
    >>> detrend(np.array([1.0, 2.0, 3.0]))
    array([-1.,  0.,  1.])
    >>> detrend(np.array([1.0, 2.0, 3.0]), "linear")
    array([0., 0., 0.])
    """
    if kind not in ("constant", "linear"):
        raise InputError(f"unknown detrend kind {kind!r}; allowed: 'constant', 'linear'")
    if isinstance(data, Experiments):
        return data.detrend(kind)
    if isinstance(data, Record):
        if len(data) < 2:
            raise InputError(f"a record of {len(data)} samples cannot be detrended; at least 2 are needed")
        u, u0 = detrend_array(as_finite_array("record inputs", data.inputs), kind)
        y, y0 = detrend_array(as_finite_array("record outputs", data.outputs), kind)
        meta = dict(data.metadata)
        meta["operating_point"] = {
            "inputs": [0.0] * u.shape[1],
            "outputs": [0.0] * y.shape[1],
            "input_names": list(data.input_names),
            "output_names": list(data.output_names),
        }
        meta["operating_point_source"] = f"detrend ({kind})"
        meta["detrended"] = {"kind": kind, "inputs_at_start": u0.tolist(), "outputs_at_start": y0.tolist()}
        return Record(
            data.time.copy(),
            u,
            y,
            data.input_names,
            data.output_names,
            {k: v.copy() for k, v in data.extras.items()},
            meta,
        )
    x = as_finite_array("data", data)
    if x.ndim == 0 or x.shape[0] < 2:
        raise InputError(f"data must have at least 2 samples along axis 0, got shape {x.shape}")
    return detrend_array(x, kind)[0]


def lag_matrix(x: np.ndarray, lags: Sequence[int] | np.ndarray, start: int) -> np.ndarray:
    """Columns ``x(t - lag)`` for ``t = start .. N - 1``, zero where ``t - lag < 0``.

    Parameters
    ----------
    x : numpy.ndarray
        Signal, shape ``(N,)``.
    lags : sequence of int
        Non-negative lags (samples), one column each.
    start : int
        First row's time index.

    Returns
    -------
    numpy.ndarray
        Shape ``(N - start, len(lags))``.
    """
    n = x.size
    out = np.zeros((n - start, len(lags)))
    for j, lag in enumerate(lags):
        first = max(start - int(lag), 0)
        rows = n - int(lag) - first
        if rows > 0:
            out[out.shape[0] - rows :, j] = x[first : first + rows]
    return out


def check_excitation(u: np.ndarray | Sequence[np.ndarray], order: int, what: str = "input u") -> None:
    """Refuse an input that is not persistently exciting of ``order`` (e.g. a constant).

    The ``order`` columns ``u(t), ..., u(t - order + 1)`` must be linearly independent
    (smallest singular value above ``1e-8`` times the largest); a single sinusoid only
    excites order 2. A constant input is refused whatever the order (``nb = 1`` included):
    it excites no dynamics and is indistinguishable from an offset. With several experiments
    (a sequence of arrays) the lagged columns of all of them are stacked, never mixing two.

    Raises
    ------
    InputError
        Naming the order required and the order the input reaches.

    Examples
    --------
    >>> check_excitation(np.array([1.0, -1.0, 1.0, 1.0, -1.0]), 2)
    >>> check_excitation(np.sin(np.arange(50.0)), 3)
    Traceback (most recent call last):
    ...
    trms.errors.InputError: input u is not persistently exciting of order 3 (it reaches order 2; ...
    """
    if order < 1:
        return
    parts = [np.asarray(u, float)] if isinstance(u, np.ndarray) else [np.asarray(x, float) for x in u]
    m = np.vstack([lag_matrix(x, range(order), order - 1) for x in parts if x.size >= order] or [np.zeros((0, order))])
    u = np.concatenate(parts)
    s = np.linalg.svd(m, compute_uv=False) if m.size else np.zeros(1)
    if s[0] == 0.0:
        raise InputError(f"{what} is identically zero: it excites nothing (order {order} needed)")
    rank = int(np.sum(s > 1e-8 * s[0]))
    if rank < order:
        raise InputError(
            f"{what} is not persistently exciting of order {order} (it reaches order {rank}; "
            "a constant input reaches 1): the model's input coefficients are not identifiable"
        )
    if np.ptp(u) <= 1e-12 * np.max(np.abs(u)):
        raise InputError(
            f"{what} is constant ({u[0]:.6g} throughout): as a deviation it cannot be told apart from an "
            f"output offset, and it excites no dynamics (order {order} needed)"
        )


def model_signals(y: object | None, u: object, start: int) -> tuple[np.ndarray | None, np.ndarray]:
    """Check the data a fitted model is run on: finite 1-D ``u``, and ``y`` (if given) of the
    same length with more than ``start`` samples (the model's initial conditions)."""
    if y is None:
        return None, _model_input(u)
    return measured_signals(y, u, start)


def measured_signals(y: object, u: object, start: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`model_signals` where the measured output ``y`` is required (predictions, residuals)."""
    ua = _model_input(u)
    if y is None:
        raise InputError("y (the measured output, shape (N,)) is required, got None")
    ya = as_finite_array("y", y)
    if ya.shape != ua.shape:
        raise InputError(f"y and u must have the same length, got {ya.size} and {ua.size} samples")
    if ya.size <= start:
        raise InputError(f"the data have {ya.size} samples; this model needs more than start = {start}")
    return ya, ua


def _model_input(u: object) -> np.ndarray:
    ua = as_finite_array("u", u)
    if ua.ndim != 1:
        raise InputError(f"u must be 1-D, got shape {ua.shape}")
    return ua
