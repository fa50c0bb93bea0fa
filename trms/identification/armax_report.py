"""An ARMAX fit of one channel of a Record with everything a reader checks it by: residual tests, measured and
model spectra with their peaks, an optional free-run validation on a second Record, and the whole as JSON data
(:meth:`ArmaxIdentification.to_dict`, the ``model.json`` of ``trms identify``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from trms.errors import InputError
from trms.identification.data import SisoData, siso_data
from trms.identification.linear import armax
from trms.identification.polynomial import PolynomialModel
from trms.identification.spectral import Peak, find_modes, psd
from trms.identification.validation import Comparison, CorrelationTest, compare, residual_tests
from trms.modes import oscillatory
from trms.record import Record

__all__ = ["PEAK_BAND", "ArmaxIdentification", "identify_armax", "check_same_configuration"]

#: Band (Hz) searched for the measured spectrum's peaks, and the widest band its figure shows: the rig's slow
#: yaw mode (about 0.1 Hz) up to well above its pitch mode (about 0.33 Hz); capped at Nyquist.
PEAK_BAND = (0.03, 2.0)


@dataclass(frozen=True)
class ArmaxIdentification:
    """An ARMAX model of one channel of a Record, its residual tests and spectra, and an optional validation.

    Attributes
    ----------
    data : SisoData
        The channel fitted (deviations from the record's operating point, rad and V).
    model : PolynomialModel
        The ARMAX model.
    tests : list of CorrelationTest
        Residual autocorrelation and input-residual cross-correlation (``ee``, ``ue``).
    frequency : ndarray
        Frequencies (Hz) of the spectra.
    measured_psd, model_psd : ndarray
        Welch PSD of the measured output and of the model's free-run output.
    peaks : list of Peak
        Up to 3 peaks of the measured PSD in :attr:`band`.
    orders : (na, nb, nc, nk)
        The orders asked for.
    validation : Comparison or None
        Free-run fit on a second Record (:meth:`validated`).
    """

    data: SisoData
    model: PolynomialModel
    tests: list[CorrelationTest]
    frequency: np.ndarray
    measured_psd: np.ndarray
    model_psd: np.ndarray
    peaks: list[Peak]
    orders: tuple[int, int, int, int]
    validation: Comparison | None = None

    @property
    def band(self) -> tuple[float, float]:
        """The band (Hz) the peaks were searched in: :data:`PEAK_BAND` up to the spectrum's last frequency."""
        return PEAK_BAND[0], min(PEAK_BAND[1], float(self.frequency[-1]))

    def validated(self, record: Record) -> ArmaxIdentification:
        """This identification with a free-run validation of the model on ``record`` (the same channel)."""
        d = siso_data(record, input=self.data.input_name, output=self.data.output_name)
        return replace(self, validation=compare(self.model, d.y, d.u))

    def to_dict(self) -> dict[str, Any]:
        """The identification as JSON-ready data: channel, sample time (s), orders, the A, B, C polynomials,
            noise variance, DC gain, modes (Hz, damping), PSD peaks (Hz), residual tests and the validation fit (%).

            Examples
            --------
            >>> from trms.record import OperatingPoint
        >>> HOVER = {"operating_point": OperatingPoint.zero(["u1"], ["pitch"]).to_dict()}
        >>> u = np.random.default_rng(0).choice([-1.0, 1.0], 300)
            >>> y = np.r_[0.0, np.convolve(u, 0.5 * 0.8 ** np.arange(30))[:299]]
            >>> rec = Record(np.arange(300) * 0.2, u, y, ("u1",), ("pitch",), metadata=HOVER)
            >>> d = identify_armax(rec, (1, 1, 1, 1)).to_dict()
            >>> d["orders"], round(d["dc_gain"], 2), sorted(d["residual_tests"])
            ([1, 1, 1, 1], 2.5, ['ee', 'ue'])
        """
        m, d = self.model, self.data
        out: dict[str, Any] = {
            "input": d.input_name,
            "output": d.output_name,
            "sample_time": d.sample_time,
            "orders": list(self.orders),
            "A": m.A.tolist(),
            "B": m.B.tolist(),
            "C": m.C.tolist(),
            "noise_variance": m.noise_variance,
            "dc_gain": m.dc_gain(),
            "modes": [
                {"frequency_hz": x.frequency_hz, "damping": x.damping} for x in oscillatory(m.modes(), m.sample_time)
            ],
            "psd_peaks_hz": [pk.frequency for pk in self.peaks],
            "residual_tests": {t.name: {"passed": t.passed, "outside": t.n_outside} for t in self.tests},
        }
        if self.validation is not None:
            out["validation_fit_percent"] = self.validation.fit
        return out


def identify_armax(
    record: Record, orders: Sequence[int], input: str | None = None, output: str | None = None
) -> ArmaxIdentification:
    """Fit ARMAX(na, nb, nc, nk) by the prediction-error method to one channel of ``record`` and test it.

    Parameters
    ----------
    record : Record
        With an operating point; the fit is on deviations from it.
    orders : (na, nb, nc, nk)
        Orders of A, B, C and the input delay (samples).
    input, output : str, optional
        The channel (needed when the record has several).

    Returns
    -------
    ArmaxIdentification

    Examples
    --------
    >>> from trms.record import OperatingPoint
    >>> HOVER = {"operating_point": OperatingPoint.zero(["u1"], ["pitch"]).to_dict()}
    >>> u = np.random.default_rng(0).choice([-1.0, 1.0], 300)
    >>> y = np.r_[0.0, np.convolve(u, 0.5 * 0.8 ** np.arange(30))[:299]]  # y_k depends on u_0 .. u_{k-1}
    >>> ident = identify_armax(Record(np.arange(300) * 0.2, u, y, ("u1",), ("pitch",), metadata=HOVER), (1, 1, 1, 1))
    >>> [round(float(a), 3) for a in ident.model.A], ident.band
    ([1.0, -0.8], (0.03, 2.0))
    """
    d = siso_data(record, input=input, output=output)
    na, nb, nc, nk = orders
    if isinstance(nk, (int, np.integer)) and not isinstance(nk, bool) and nk < 1:
        raise InputError(
            f"input delay nk = {nk} lets y_k depend on u_k, which a Record rules out (y_k is measured at t_k, before "
            "u_k is applied over [t_k, t_k + Ts)); allowed: nk >= 1"
        )
    model = armax(d.y, d.u, na, nb, nc, nk, sample_time=d.sample_time, input=d.input_name, output=d.output_name)
    tests = residual_tests(model, d.y, d.u, nonlinear=False)
    f, p = psd(d.y, d.sample_time)
    _, pm = psd(model.simulate(d.u, d.y), d.sample_time)
    peaks = find_modes(f, p, (PEAK_BAND[0], min(PEAK_BAND[1], f[-1])), n=3)
    return ArmaxIdentification(d, model, tests, f, p, pm, peaks, (na, nb, nc, nk))


def check_same_configuration(record: Record, other: Record, name: str, other_name: str) -> None:
    """Refuse ``other`` (one line) when it is a record of another configuration than ``record``: other
    channels, or another ``config`` in the metadata. ``name`` and ``other_name`` name them in the message.

    Examples
    --------
    >>> a = Record(np.arange(3.0), np.zeros(3), np.zeros(3), ("u1",), ("pitch",), metadata={"config": "1dof"})
    >>> check_same_configuration(a, a, "a.npz", "b.npz") is None
    True
    """
    a, b = record.metadata.get("config"), other.metadata.get("config")
    if (record.input_names, record.output_names) != (other.input_names, other.output_names) or (a and b and a != b):
        raise InputError(
            f"{other_name!r} is a {b or 'unknown'} record with inputs ({', '.join(other.input_names)}) and outputs "
            f"({', '.join(other.output_names)}); {name!r} is a {a or 'unknown'} record with inputs "
            f"({', '.join(record.input_names)}) and outputs ({', '.join(record.output_names)}): they must match"
        )
