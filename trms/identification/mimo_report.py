"""A model of every input and output of a Record at once, with what a reader checks it by: each output's free-run fit
on the record, the residual tests of each output's one-step prediction errors, the model's modes, an optional
free-run validation on a second Record, and the whole as JSON data (``model.json`` of ``trms identify --method``).

On the 2-DOF rig the main rotor drives yaw as well as pitch (its reaction torque, the gyroscopic coupling): a
single-input model of yaw sees the main rotor's part as noise. The estimators here take both inputs together:
:func:`~trms.identification.mimo_pem.arx_mimo`, :func:`~trms.identification.mimo_pem.armax_mimo`,
:func:`~trms.identification.subspace.n4sid` and :func:`~trms.identification.ssest.ssest`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import control
import numpy as np
import scipy.signal

from trms.errors import InputError, check_choice
from trms.identification.mimo_pem import MimoPolynomialModel, armax_mimo, arx_mimo
from trms.identification.polynomial import modes_of_poles
from trms.identification.ssest import ssest, state_space_residuals
from trms.identification.subspace import n4sid
from trms.identification.validation import CorrelationTest, fit_percent, independence_test, whiteness_test
from trms.modes import oscillatory
from trms.record import Record

__all__ = ["MIMO_METHODS", "MimoFit", "identify_all_channels"]

#: The estimators of :func:`identify_all_channels`.
MIMO_METHODS = ("arx-mimo", "armax-mimo", "n4sid", "ssest")
#: Lags of the residual tests (samples), as for the single-input ARMAX.
MAX_LAG = 20


@dataclass(frozen=True)
class MimoFit:
    """A model of all of a Record's inputs and outputs (deviations from its operating point).

    Attributes
    ----------
    method : str
        One of :data:`MIMO_METHODS`.
    model : MimoPolynomialModel or control.StateSpace
        The estimator's model.
    input_names, output_names : tuple of str
    sample_time : float
        Seconds per sample.
    estimation_fit : numpy.ndarray
        Free-run fit (%) of each output on the fitted record, simulated from rest (the record starts at rest).
    tests : list of (str, CorrelationTest)
        Per output: the whiteness of its one-step prediction errors (``ee``) and their independence of each input
        (``ue``, named ``ue:u1`` ...).
    validation_fit : numpy.ndarray or None
        Free-run fit (%) of each output on a second record (:meth:`validated`).
    validation : (numpy.ndarray, numpy.ndarray) or None
        That record's time (s), measured and simulated outputs ``(N, p)`` (deviations).
    """

    method: str
    model: MimoPolynomialModel | control.StateSpace
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    sample_time: float
    estimation_fit: np.ndarray
    tests: list[tuple[str, CorrelationTest]]
    validation_fit: np.ndarray | None = None
    validation: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    @property
    def state_space(self) -> control.StateSpace:
        """The model as a discrete state space (a polynomial model's non-minimal one)."""
        return self.model.to_ss() if isinstance(self.model, MimoPolynomialModel) else self.model

    def simulate(self, u: np.ndarray) -> np.ndarray:
        """Free-run outputs ``(N, p)`` from rest for input deviations ``u`` ``(N, m)`` (V)."""
        ss = self.state_space
        return np.asarray(scipy.signal.dlsim((ss.A, ss.B, ss.C, ss.D, self.sample_time), u)[1]).reshape(len(u), -1)

    def validated(self, record: Record) -> MimoFit:
        """This fit with each output's free-run fit on ``record`` (the same channels, the same sample time)."""
        du, dy = _deviations(record, self.input_names, self.output_names)
        if not np.isclose(record.sample_time, self.sample_time):
            raise InputError(
                f"the validation record is sampled every {record.sample_time:g} s, the model every "
                f"{self.sample_time:g} s"
            )
        sim = self.simulate(du)
        fits = np.array([fit_percent(dy[:, j], sim[:, j]) for j in range(dy.shape[1])])
        return replace(self, validation_fit=fits, validation=(record.time, dy, sim))

    def to_dict(self) -> dict[str, Any]:
        """The fit as JSON-ready data: method, channels, sample time (s), the model's matrices or polynomials, its
        modes (Hz, damping), each output's estimation (and validation) fit (%), the residual tests."""
        ss = self.state_space
        modes = oscillatory(modes_of_poles(ss.poles(), self.sample_time), self.sample_time)
        out: dict[str, Any] = {
            "method": self.method,
            "inputs": list(self.input_names),
            "outputs": list(self.output_names),
            "sample_time": self.sample_time,
            "states": int(ss.nstates),
            "modes": [{"frequency_hz": m.frequency_hz, "damping": m.damping} for m in modes],
            "estimation_fit_percent": dict(zip(self.output_names, map(float, self.estimation_fit))),
            "residual_tests": {name: t.passed for name, t in self.tests},
        }
        if isinstance(self.model, MimoPolynomialModel):
            out.update(A=self.model.A.tolist(), B=self.model.B.tolist(), C=self.model.C.tolist())
            out["noise_covariance"] = self.model.noise_covariance.tolist()
        else:
            out.update({k: np.asarray(getattr(ss, k)).tolist() for k in "ABCD"})
            gain = getattr(self.model, "kalman_gain", None)
            if gain is not None:
                out["kalman_gain"] = np.asarray(gain).tolist()
                out["innovation_covariance"] = np.asarray(self.model.innovation_covariance).tolist()
        if self.validation_fit is not None:
            out["validation_fit_percent"] = dict(zip(self.output_names, map(float, self.validation_fit)))
        return out


def _deviations(record: Record, inputs: Sequence[str], outputs: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """A record's input and output deviations (V, rad) in the given channel order; a missing channel refused."""
    if "operating_point" not in record.metadata:
        raise InputError(
            "the record has no operating point: give it one (trms import --hover, or trms.identification.detrend)"
        )
    du, dy = record.deviations()
    for kind, want, have in (("input", inputs, record.input_names), ("output", outputs, record.output_names)):
        missing = [n for n in want if n not in have]
        if missing:
            raise InputError(f"the record lacks {kind} {missing[0]!r} (it has {', '.join(have)})")
    return (
        du[:, [record.input_names.index(n) for n in inputs]],
        dy[:, [record.output_names.index(n) for n in outputs]],
    )


def _errors(model: MimoPolynomialModel | control.StateSpace, y: np.ndarray, u: np.ndarray, ts: float) -> np.ndarray:
    """One-step prediction errors ``(N, p)``: ``C_j(q)^-1 (A_j(q) y - B_j(q) u)`` per output, or the innovations
    form's predictor (its Kalman gain)."""
    if not isinstance(model, MimoPolynomialModel):
        return state_space_residuals(model, y, u, sample_time=ts)
    e = np.zeros_like(y)
    for j in range(y.shape[1]):
        v = sum(scipy.signal.lfilter(model.A[j, i], [1.0], y[:, i]) for i in range(y.shape[1]))
        v = v - sum(scipy.signal.lfilter(model.B[j, i], [1.0], u[:, i]) for i in range(u.shape[1]))
        e[:, j] = scipy.signal.lfilter([1.0], np.trim_zeros(model.C[j], "b"), v)  # C_j is monic
    return e


def identify_all_channels(
    record: Record,
    method: str,
    orders: Sequence[int] = (2, 2, 1, 1),
    states: int | None = None,
) -> MimoFit:
    """Fit one model of every input and output of ``record`` at once (deviations from its operating point).

    Parameters
    ----------
    record : Record
        With an operating point; its inputs in the order ``u1, u2`` and outputs ``pitch, yaw`` (or as named).
    method : {"arx-mimo", "armax-mimo", "n4sid", "ssest"}
        The estimator.
    orders : (na, nb, nc, nk)
        Polynomial orders for every entry (``arx-mimo``, ``armax-mimo``; ``nc`` only for the latter), ``nk >= 1``.
    states : int, optional
        States of ``n4sid`` and ``ssest`` (default: n4sid's choice from its singular values).

    Returns
    -------
    MimoFit

    Raises
    ------
    InputError
        An unknown method, no operating point, ``nk < 1``, orders or states given to a method without them,
        or the estimator's own refusals.

    Examples
    --------
    Two inputs driving two outputs, the first input both of them (as the main rotor drives yaw on the rig):

    >>> from trms.record import OperatingPoint
    >>> rng = np.random.default_rng(0)
    >>> u = np.repeat(rng.choice([-1.0, 1.0], (150, 2)), 4, axis=0)
    >>> y = np.zeros((600, 2))
    >>> for k in range(1, 600):
    ...     y[k] = [0.8 * y[k - 1, 0] + 0.5 * u[k - 1, 0], 0.6 * y[k - 1, 1] + 0.3 * u[k - 1, 0] + 0.4 * u[k - 1, 1]]
    >>> op = OperatingPoint.zero(["u1", "u2"], ["pitch", "yaw"]).to_dict()
    >>> rec = Record(np.arange(600) * 0.1, u, y, ("u1", "u2"), ("pitch", "yaw"), {}, {"operating_point": op})
    >>> fit = identify_all_channels(rec, "arx-mimo", (1, 1, 0, 1))
    >>> [round(float(f), 3) for f in fit.estimation_fit]
    [100.0, 100.0]
    """
    check_choice("method", method, MIMO_METHODS, error=InputError)
    du, dy = _deviations(record, record.input_names, record.output_names)
    ts = record.sample_time
    na, nb, nc, nk = (int(v) for v in orders)
    if nk < 1:
        raise InputError(
            f"input delay nk = {nk} lets y_k depend on u_k, which a Record rules out (y_k is measured at t_k, before "
            "u_k is applied over [t_k, t_k + Ts)); allowed: nk >= 1"
        )
    if method in ("arx-mimo", "armax-mimo"):
        if states is not None:
            raise InputError(f"states = {states} sets n4sid's and ssest's order; {method} takes --orders")
        model: MimoPolynomialModel | control.StateSpace = (
            arx_mimo(dy, du, na, nb, nk, sample_time=ts)
            if method == "arx-mimo"
            else armax_mimo(dy, du, na, nb, nc, nk, sample_time=ts)
        )
    elif method == "n4sid":
        model = n4sid(dy, du, states, sample_time=ts)
    else:
        model = ssest(dy, du, states, sample_time=ts)
    fit = MimoFit(method, model, record.input_names, record.output_names, ts, np.zeros(dy.shape[1]), [])
    sim = fit.simulate(du)
    e = _errors(model, dy, du, ts)
    start = max(na, nk + nb - 1, 1) if isinstance(model, MimoPolynomialModel) else 1
    tests = []
    for j, out in enumerate(record.output_names):
        tests.append((f"{out}: ee", whiteness_test(e[start:, j], MAX_LAG)))
        for i, name in enumerate(record.input_names):
            tests.append((f"{out}: ue:{name}", independence_test(du[start:, i], e[start:, j], MAX_LAG)))
    fits = np.array([fit_percent(dy[:, j], sim[:, j]) for j in range(dy.shape[1])])
    return replace(fit, estimation_fit=fits, tests=tests)
