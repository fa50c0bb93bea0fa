"""Input/output data of several experiments, as MATLAB's multi-experiment ``iddata``.

A :class:`Dataset` holds one or more experiments that share a sample time and channel names
(inputs in V, outputs in rad, or the units of the arrays given). Each experiment is a separate
stretch of data: the estimators that take a Dataset (:func:`~trms.identification.linear.arx`,
:func:`~trms.identification.linear.armax`, :func:`~trms.identification.orders.select_order`,
the recursive and non-parametric estimators) form their regressors and correlations inside each
experiment only, so no product ever mixes samples of two experiments, and sum the criterion over
the experiments. Joining the experiments end to end instead (one long record) would invent a
transition at each junction that the plant never made.

Estimators that take one experiment (``oe``, ``bj``, ``narx_rbf``) accept a Dataset holding one.
Sample ``k`` of an experiment that starts at ``t0`` is at ``t0 + k Ts`` (the Record convention:
the input is held over ``[t_k, t_k + Ts)``, the output measured at ``t_k``).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from trms.display import html_table
from trms.errors import InputError, as_finite_array, check_in_range, check_int
from trms.identification.data import (
    SisoData,
    channel_index,
    detrend_array,
    experiments_siso,
    record_deviations,
    siso_data,
)
from trms.record import Record

__all__ = ["Dataset", "merge", "siso_experiments"]

#: Tolerance (in samples) when deciding whether a sample time lies in a time window.
_EDGE_TOL = 1e-9


def _experiment_arrays(name: str, value: object) -> list[np.ndarray]:
    """One experiment (an array) or several (a list or tuple of numpy arrays), each as a 2-D float array."""
    items = list(value) if isinstance(value, (list, tuple)) and value and isinstance(value[0], np.ndarray) else None
    if items is None:
        items = [value]
    elif not all(isinstance(v, np.ndarray) for v in items):
        raise InputError(f"{name}: a list of experiments must hold only numpy arrays (one per experiment)")
    out = []
    for i, v in enumerate(items):
        label = name if len(items) == 1 else f"{name} of experiment {i + 1}"
        arr = as_finite_array(label, v)
        if arr.ndim == 1:
            arr = arr[:, None]
        if arr.ndim != 2 or arr.shape[0] < 1:
            raise InputError(f"{label} must have shape (N,) or (N, channels) with N >= 1, got shape {arr.shape}")
        arr.flags.writeable = False
        out.append(arr)
    return out


def _names(kind: str, given: Sequence[str] | str | None, count: int, default: str) -> tuple[str, ...]:
    if given is None:
        return (default,) if count == 1 else tuple(f"{default}{j + 1}" for j in range(count))
    names = (given,) if isinstance(given, str) else tuple(given)
    if len(names) != count or not all(isinstance(n, str) and n for n in names):
        raise InputError(f"{kind} names must be {count} non-empty strings (one per channel), got {given!r}")
    if len(set(names)) != len(names):
        raise InputError(f"{kind} names must be distinct, got {names!r}")
    return names


class Dataset:
    """Input/output data of one or more experiments with a common sample time and channel names.

    Parameters
    ----------
    y : array_like or list of numpy.ndarray
        Outputs: one experiment (shape ``(N,)`` or ``(N, n_outputs)``) or a list/tuple of numpy
        arrays, one per experiment (lengths may differ).
    u : array_like or list of numpy.ndarray
        Inputs, matching ``y`` (shape ``(N,)`` or ``(N, n_inputs)`` per experiment).
    sample_time : float
        Seconds between samples, > 0, common to every experiment.
    input_names, output_names : sequence of str, optional
        Channel names; default ``"u"``/``"y"`` for one channel, ``"u1", "u2", ...`` for several.
    experiment_names : sequence of str, optional
        Distinct names; default ``"exp1", "exp2", ...`` by position (renumbered after :func:`merge`).
    start_times : sequence of float, optional
        Time of each experiment's first sample (s); default 0.

    Raises
    ------
    InputError
        NaN/inf, an experiment whose input and output lengths differ, channel counts that differ
        between experiments, names that do not match the channels, a bad sample time.

    Examples
    --------
    Two experiments of different lengths, one input and one output:

    >>> rng = np.random.default_rng(0)
    >>> data = Dataset([rng.standard_normal(200), rng.standard_normal(150)],
    ...                [rng.standard_normal(200), rng.standard_normal(150)], 0.2)
    >>> data
    Dataset(2 experiments (exp1: 200, exp2: 150 samples), Ts=0.2 s, inputs=(u), outputs=(y))
    >>> data["exp2"].n_samples, data.time_slice(10.0, 35.0).n_samples
    ((150,), (125, 100))
    """

    __slots__ = ("_y", "_u", "_sample_time", "_input_names", "_output_names", "_given_names", "_start_times")

    def __init__(
        self,
        y: object,
        u: object,
        sample_time: float,
        *,
        input_names: Sequence[str] | str | None = None,
        output_names: Sequence[str] | str | None = None,
        experiment_names: Sequence[str | None] | None = None,
        start_times: Sequence[float] | None = None,
    ) -> None:
        ys, us = _experiment_arrays("y", y), _experiment_arrays("u", u)
        if len(ys) != len(us):
            raise InputError(f"y holds {len(ys)} experiments and u {len(us)}; give one input array per output array")
        for i, (ya, ua) in enumerate(zip(ys, us)):
            if ya.shape[0] != ua.shape[0]:
                raise InputError(
                    f"experiment {i + 1}: y and u must have the same length, got {ya.shape[0]} and {ua.shape[0]} "
                    "samples"
                )
        for kind, arrays in (("output", ys), ("input", us)):
            widths = {a.shape[1] for a in arrays}
            if len(widths) > 1:
                raise InputError(f"every experiment must have the same number of {kind}s, got {sorted(widths)}")
        self._y: tuple[np.ndarray, ...] = tuple(ys)
        self._u: tuple[np.ndarray, ...] = tuple(us)
        self._sample_time = check_in_range("sample_time", sample_time, 0.0, np.inf, unit=" s", low_open=True)
        self._input_names = _names("input", input_names, us[0].shape[1], "u")
        self._output_names = _names("output", output_names, ys[0].shape[1], "y")
        k = len(ys)
        given: tuple[str | None, ...] = (None,) * k if experiment_names is None else tuple(experiment_names)
        if len(given) != k or not all(n is None or (isinstance(n, str) and n) for n in given):
            raise InputError(f"experiment_names must be {k} non-empty strings (one per experiment), got {given!r}")
        self._given_names = given
        names = self.experiment_names
        if len(set(names)) != k:
            raise InputError(f"experiment names must be distinct, got {names!r}")
        t0 = np.zeros(k) if start_times is None else as_finite_array("start_times", start_times, (k,))
        self._start_times: tuple[float, ...] = tuple(float(t) for t in t0)

    # ------------------------------------------------------------ construction
    @classmethod
    def from_records(cls, *records: Record, names: Sequence[str] | None = None) -> Dataset:
        """One experiment per Record, as deviations from each record's operating point.

        Parameters
        ----------
        *records : Record
            At least one; the same channel names and sample time, each with an operating point
            (see :func:`~trms.identification.data.record_deviations`).
        names : sequence of str, optional
            Experiment names (default ``exp1, exp2, ...``).

        Returns
        -------
        Dataset
            Start times from the records' first time stamps.

        Raises
        ------
        InputError
            No record, a record without an operating point, channel names or sample times that differ.

        Examples
        --------
        >>> from trms.identification.data import detrend
        >>> rec = detrend(Record(np.arange(4) * 0.1, np.arange(4.0), np.ones(4), ("u1",), ("pitch",)))
        >>> Dataset.from_records(rec, rec, names=["a", "b"])
        Dataset(2 experiments (a: 4, b: 4 samples), Ts=0.1 s, inputs=(u1), outputs=(pitch))
        """
        if not records:
            raise InputError("Dataset.from_records needs at least one Record")
        for i, rec in enumerate(records):
            if not isinstance(rec, Record):
                raise InputError(f"argument {i + 1} of Dataset.from_records is a {type(rec).__name__}, not a Record")
        first = records[0]
        ts = first.sample_time
        for i, rec in enumerate(records[1:], start=2):
            if (rec.input_names, rec.output_names) != (first.input_names, first.output_names):
                raise InputError(
                    f"record {i} has channels {rec.input_names} -> {rec.output_names}, record 1 has "
                    f"{first.input_names} -> {first.output_names}; a dataset needs the same channels"
                )
            if not np.isclose(rec.sample_time, ts, rtol=1e-9, atol=0.0):
                raise InputError(f"record {i} has sample time {rec.sample_time} s, record 1 {ts} s; they must agree")
        pairs = [record_deviations(rec) for rec in records]
        return cls(
            [dy for _, dy in pairs],
            [du for du, _ in pairs],
            ts,
            input_names=first.input_names,
            output_names=first.output_names,
            experiment_names=names,
            start_times=[float(rec.time[0]) if len(rec) else 0.0 for rec in records],
        )

    def _replace(
        self,
        ys: Sequence[np.ndarray],
        us: Sequence[np.ndarray],
        given: Sequence[str | None],
        starts: Sequence[float],
    ) -> Dataset:
        return Dataset(
            list(ys),
            list(us),
            self._sample_time,
            input_names=self._input_names,
            output_names=self._output_names,
            experiment_names=list(given),
            start_times=list(starts),
        )

    # ------------------------------------------------------------ views
    @property
    def sample_time(self) -> float:
        """Seconds between samples."""
        return self._sample_time

    @property
    def input_names(self) -> tuple[str, ...]:
        """Input channel names."""
        return self._input_names

    @property
    def output_names(self) -> tuple[str, ...]:
        """Output channel names."""
        return self._output_names

    @property
    def experiment_names(self) -> tuple[str, ...]:
        """Experiment names (``exp<position>`` where none was given)."""
        return tuple(n if n is not None else f"exp{i + 1}" for i, n in enumerate(self._given_names))

    @property
    def start_times(self) -> tuple[float, ...]:
        """Time of each experiment's first sample (s)."""
        return self._start_times

    @property
    def n_experiments(self) -> int:
        """Number of experiments."""
        return len(self._y)

    @property
    def n_samples(self) -> tuple[int, ...]:
        """Samples in each experiment."""
        return tuple(int(y.shape[0]) for y in self._y)

    @property
    def outputs(self) -> tuple[np.ndarray, ...]:
        """Outputs of each experiment, shapes ``(N_i, n_outputs)`` (read-only)."""
        return self._y

    @property
    def inputs(self) -> tuple[np.ndarray, ...]:
        """Inputs of each experiment (V), shapes ``(N_i, n_inputs)`` (read-only)."""
        return self._u

    def time(self, experiment: int | str = 0) -> np.ndarray:
        """Sample times (s) of one experiment (by position or name)."""
        i = self._index(experiment)
        return self._start_times[i] + np.arange(self.n_samples[i]) * self._sample_time

    def _index(self, key: object) -> int:
        names = self.experiment_names
        if isinstance(key, str):
            if key not in names:
                raise InputError(f"unknown experiment {key!r}; this dataset has {', '.join(names)}")
            return names.index(key)
        if isinstance(key, bool) or not isinstance(key, (int, np.integer)):
            raise InputError(f"an experiment is selected by position (int) or name (str), got {key!r}")
        k = self.n_experiments
        if not -k <= int(key) < k:
            raise InputError(f"experiment index {int(key)} is outside the allowed range [{-k}, {k - 1}]")
        return int(key) % k

    def __getitem__(self, key: int | str | slice | Iterable[int | str]) -> Dataset:
        """The experiments selected by position, name, slice or a list of them, as a Dataset."""
        if isinstance(key, slice):
            idx = list(range(self.n_experiments))[key]
        elif isinstance(key, (list, tuple, np.ndarray)):
            idx = [self._index(k) for k in key]
        else:
            idx = [self._index(key)]
        if not idx:
            raise InputError(f"the selection {key!r} holds no experiment")
        names = self.experiment_names
        return self._replace(
            [self._y[i] for i in idx],
            [self._u[i] for i in idx],
            [names[i] for i in idx],
            [self._start_times[i] for i in idx],
        )

    def sample_slice(self, start: int = 0, stop: int | None = None) -> Dataset:
        """Samples ``start .. stop - 1`` (indices from 0) of every experiment; start times move along.

        Experiments left empty are dropped; a selection empty in every experiment is refused.

        Raises
        ------
        InputError
            ``start`` not an int >= 0, ``stop`` not an int > ``start`` (or None), or nothing selected.
        """
        first = check_int("start", start, 0)
        last = None if stop is None else check_int("stop", stop, first + 1)
        spans = [(i, first, n if last is None else min(n, last)) for i, n in enumerate(self.n_samples)]
        return self._keep([s for s in spans if s[2] > s[1]], f"samples {first}:{'' if last is None else last}")

    def time_slice(self, start: float = -np.inf, stop: float = np.inf) -> Dataset:
        """The samples with ``start <= t < stop`` (s) in every experiment; empty experiments are dropped.

        Raises
        ------
        InputError
            ``start >= stop``, NaN, or no sample of any experiment in the window.
        """
        lo = check_in_range("start", start, -np.inf, np.inf, unit=" s") if np.isfinite(start) else -np.inf
        hi = check_in_range("stop", stop, -np.inf, np.inf, unit=" s") if np.isfinite(stop) else np.inf
        if np.isnan(start) or np.isnan(stop) or not lo < hi:
            raise InputError(f"a time window needs start < stop, got start = {start!r} s and stop = {stop!r} s")
        ts = self._sample_time
        spans = []
        for i, (t0, n) in enumerate(zip(self._start_times, self.n_samples)):
            first = max(0, int(np.ceil((lo - t0) / ts - _EDGE_TOL))) if np.isfinite(lo) else 0
            last = min(n, int(np.ceil((hi - t0) / ts - _EDGE_TOL))) if np.isfinite(hi) else n
            if last > first:
                spans.append((i, first, last))
        return self._keep(spans, f"the time window [{lo}, {hi}) s")

    def _keep(self, spans: list[tuple[int, int, int]], what: str) -> Dataset:
        if not spans:
            ends = ", ".join(
                f"{n}: {t0:g}-{t0 + (k - 1) * self._sample_time:g} s"
                for n, t0, k in zip(self.experiment_names, self._start_times, self.n_samples)
            )
            raise InputError(f"{what} holds no sample of the dataset ({ends})")
        names = self.experiment_names
        return self._replace(
            [self._y[i][a:b] for i, a, b in spans],
            [self._u[i][a:b] for i, a, b in spans],
            [names[i] for i, _, _ in spans],
            [self._start_times[i] + a * self._sample_time for i, a, _ in spans],
        )

    def detrend(self, kind: str = "constant") -> Dataset:
        """Remove each experiment's own mean (``constant``) or least-squares line (``linear``).

        Raises
        ------
        InputError
            Unknown ``kind``, or an experiment of fewer than 2 samples.
        """
        if kind not in ("constant", "linear"):
            raise InputError(f"unknown detrend kind {kind!r}; allowed: 'constant', 'linear'")
        for name, n in zip(self.experiment_names, self.n_samples):
            if n < 2:
                raise InputError(f"experiment {name!r} has {n} sample; detrending needs at least 2")
        return self._replace(
            [detrend_array(y, kind)[0] for y in self._y],
            [detrend_array(u, kind)[0] for u in self._u],
            self._given_names,
            self._start_times,
        )

    def merge(self, *others: Dataset) -> Dataset:
        """This dataset's experiments followed by those of ``others`` (see :func:`merge`)."""
        return merge(self, *others)

    def siso(self, input: str | None = None, output: str | None = None) -> tuple[SisoData, ...]:
        """One input/output pair of every experiment (channels by name; needed when there are several).

        Examples
        --------
        >>> data = Dataset([np.zeros((5, 2)), np.ones((3, 2))], [np.arange(5.0), np.arange(3.0)], 0.1,
        ...                output_names=["pitch", "yaw"])
        >>> [d.y.size for d in data.siso(output="yaw")]
        [5, 3]
        """
        i = channel_index(self._input_names, input, "input")
        o = channel_index(self._output_names, output, "output")
        return tuple(
            SisoData(y[:, o].copy(), u[:, i].copy(), self._sample_time, self._input_names[i], self._output_names[o])
            for y, u in zip(self._y, self._u)
        )

    def to_record(self, experiment: int | str = 0) -> Record:
        """One experiment as a Record whose operating point is zero (the data are its deviations)."""
        i = self._index(experiment)
        meta = {
            "sample_time": self._sample_time,
            "experiment": self.experiment_names[i],
            "operating_point": {
                "inputs": [0.0] * len(self._input_names),
                "outputs": [0.0] * len(self._output_names),
                "input_names": list(self._input_names),
                "output_names": list(self._output_names),
            },
        }
        return Record(
            self.time(i), self._u[i].copy(), self._y[i].copy(), self._input_names, self._output_names, metadata=meta
        )

    # ------------------------------------------------------------ display
    def __repr__(self) -> str:
        k = self.n_experiments
        exps = ", ".join(f"{n}: {m}" for n, m in zip(self.experiment_names, self.n_samples))
        return (
            f"Dataset({k} experiment{'s' if k > 1 else ''} ({exps} samples), Ts={self._sample_time:g} s, "
            f"inputs=({', '.join(self._input_names)}), outputs=({', '.join(self._output_names)}))"
        )

    def _repr_html_(self) -> str:
        rows = [
            ("sample time (s)", f"{self._sample_time:g}"),
            ("inputs", ", ".join(self._input_names)),
            ("outputs", ", ".join(self._output_names)),
        ]
        rows += [
            (f"experiment {n}", f"{m} samples from {t:g} s")
            for n, m, t in zip(self.experiment_names, self.n_samples, self._start_times)
        ]
        return html_table("Dataset", rows)


def merge(*datasets: Dataset) -> Dataset:
    """The experiments of several datasets in one (MATLAB's ``merge`` of ``iddata``).

    Parameters
    ----------
    *datasets : Dataset
        At least one; the same sample time and channel names.

    Returns
    -------
    Dataset
        The experiments in order; unnamed ones are renumbered ``exp<position>``.

    Raises
    ------
    InputError
        No dataset, different sample times or channel names, duplicate experiment names.

    Examples
    --------
    >>> a = Dataset(np.zeros(10), np.arange(10.0), 0.1)
    >>> merge(a, a, a).experiment_names
    ('exp1', 'exp2', 'exp3')
    """
    if not datasets:
        raise InputError("merge needs at least one Dataset")
    for i, d in enumerate(datasets):
        if not isinstance(d, Dataset):
            raise InputError(f"argument {i + 1} of merge is a {type(d).__name__}, not a Dataset")
    first = datasets[0]
    for i, d in enumerate(datasets[1:], start=2):
        if not np.isclose(d.sample_time, first.sample_time, rtol=1e-9, atol=0.0):
            raise InputError(f"dataset {i} has sample time {d.sample_time} s, dataset 1 {first.sample_time} s")
        if (d.input_names, d.output_names) != (first.input_names, first.output_names):
            raise InputError(
                f"dataset {i} has channels {d.input_names} -> {d.output_names}, dataset 1 has "
                f"{first.input_names} -> {first.output_names}; merged experiments need the same channels"
            )
    return Dataset(
        [y for d in datasets for y in d.outputs],
        [u for d in datasets for u in d.inputs],
        first.sample_time,
        input_names=first.input_names,
        output_names=first.output_names,
        experiment_names=[n for d in datasets for n in d._given_names],
        start_times=[t for d in datasets for t in d.start_times],
    )


def siso_experiments(
    data: Dataset | Record | object,
    u: object | None = None,
    *,
    sample_time: float | None = None,
    input: str | None = None,
    output: str | None = None,
) -> tuple[SisoData, ...]:
    """The input/output pair of every experiment: a Dataset's experiments, or the one of a Record or arrays.

    Parameters
    ----------
    data : Dataset, Record or array_like
        As :func:`~trms.identification.data.siso_data` takes, or a :class:`Dataset`.
    u : array_like, optional
        The input with an output array (refused with a Dataset or Record).
    sample_time : float, optional
        Required with arrays; checked against a Dataset's or Record's own.
    input, output : str, optional
        Channel names where there are several.

    Returns
    -------
    tuple of SisoData
        One per experiment, in order.

    Examples
    --------
    >>> len(siso_experiments(np.zeros(8), np.ones(8), sample_time=0.1))
    1
    """
    if not isinstance(data, Dataset):
        return (siso_data(data, u, sample_time=sample_time, input=input, output=output),)
    return experiments_siso(data, u, sample_time, input, output)
