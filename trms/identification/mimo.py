"""The MIMO procedure of ch. 3.4: one input excited at a time, a model per coupled channel.

For each experiment (a Record in which exactly one input varies and the others are held),
the excited input and every output have their means removed (this removes the
steady-state effect of the held inputs, as the thesis does), the coherence (eq. 3.1)
between the excited input and each output is averaged over a band, and:

* a channel whose mean coherence reaches ``threshold`` is *coupled* and gets an ARMAX model;
* a channel below it is reported as *uncoupled* and gets no model (the thesis's
  ``u2 -> y1``, "no strong coherence exists ... not investigated further").
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from trms.errors import InputError, check_in_range
from trms.identification.data import record_deviations
from trms.identification.linear import armax
from trms.identification.polynomial import PolynomialModel
from trms.identification.spectral import coherence, mean_coherence
from trms.record import Record

__all__ = ["ChannelResult", "MimoIdentification", "identify_mimo", "excited_input"]


@dataclass(frozen=True)
class ChannelResult:
    """One input-output channel of a MIMO identification.

    Attributes
    ----------
    input_name, output_name : str
    frequencies, coherence : numpy.ndarray
        Coherence spectrum (Hz, dimensionless).
    mean_coherence : float
        Average over the band.
    coupled : bool
        ``mean_coherence >= threshold``.
    model : PolynomialModel or None
        ARMAX model of a coupled channel (on mean-removed data), ``None`` otherwise.
    """

    input_name: str
    output_name: str
    frequencies: np.ndarray
    coherence: np.ndarray
    mean_coherence: float
    coupled: bool
    model: PolynomialModel | None


@dataclass(frozen=True)
class MimoIdentification:
    """All channels of a MIMO identification, keyed by ``(input_name, output_name)``."""

    channels: dict[tuple[str, str], ChannelResult]
    band: tuple[float, float]
    threshold: float

    def model(self, input_name: str, output_name: str) -> PolynomialModel:
        """The model of a coupled channel; InputError for an uncoupled or unknown one."""
        key = (input_name, output_name)
        if key not in self.channels:
            raise InputError(f"no channel {input_name} -> {output_name}; known: {sorted(self.channels)}")
        ch = self.channels[key]
        if ch.model is None:
            raise InputError(
                f"channel {input_name} -> {output_name} is uncoupled (mean coherence {ch.mean_coherence:.3f} "
                f"< {self.threshold} over {self.band} Hz): it has no model"
            )
        return ch.model

    @property
    def uncoupled(self) -> list[tuple[str, str]]:
        """Channels reported as uncoupled (low coherence)."""
        return [k for k, ch in self.channels.items() if not ch.coupled]


def excited_input(record: Record) -> int:
    """Index of the single input that varies in ``record`` (the others must be held constant)."""
    spread = np.ptp(record.inputs, axis=0)
    varying = np.flatnonzero(spread > 1e-12 * max(float(np.max(np.abs(record.inputs))), 1.0))
    if varying.size != 1:
        names = ", ".join(record.input_names[i] for i in varying) or "none"
        raise InputError(
            f"exactly one input must be excited per experiment (the others held constant); varying: {names}"
        )
    return int(varying[0])


def identify_mimo(
    experiments: Sequence[Record],
    na: int = 4,
    nb: int = 4,
    nc: int = 4,
    nk: int = 1,
    *,
    band: tuple[float, float] = (0.0, 1.0),
    threshold: float = 0.5,
    nperseg: int | None = None,
    estimation_samples: int | None = None,
) -> MimoIdentification:
    """Identify every channel from one-input-at-a-time experiments (ch. 3.4).

    Parameters
    ----------
    experiments : sequence of Record
        One per excited input; each Record has all inputs and outputs of the plant.
    na, nb, nc, nk : int
        ARMAX orders and delay for every coupled channel (the thesis: 4th order).
    band : (float, float)
        Frequency band (Hz) over which coherence is averaged (the thesis: 0-1 Hz).
    threshold : float
        Mean coherence at or above which a channel is coupled, in ``[0, 1]``.
    nperseg : int, optional
        Welch segment length for the coherence (see :func:`trms.identification.spectral.coherence`).
    estimation_samples : int, optional
        Fit the ARMAX models on the first ``estimation_samples`` samples of each record only (the
        thesis used 600 of its 1200); the coherence always uses the whole record. Default: all.

    Returns
    -------
    MimoIdentification
    """
    if not experiments:
        raise InputError("identify_mimo needs at least one experiment")
    thr = check_in_range("threshold", threshold, 0.0, 1.0)
    channels: dict[tuple[str, str], ChannelResult] = {}
    seen: set[str] = set()
    for rec in experiments:
        if not isinstance(rec, Record):
            raise InputError(f"experiments must be Records, got {type(rec).__name__}")
        j = excited_input(rec)
        name_in = rec.input_names[j]
        if name_in in seen:
            raise InputError(f"input {name_in} is excited in more than one experiment")
        seen.add(name_in)
        du, dy = record_deviations(rec)
        n_est = (
            len(rec)
            if estimation_samples is None
            else int(check_in_range("estimation_samples", estimation_samples, 1, len(rec), unit=" samples"))
        )
        u = du[:, j] - du[:, j].mean()
        for i, name_out in enumerate(rec.output_names):
            y = dy[:, i] - dy[:, i].mean()
            f, c = coherence(u, y, rec.sample_time, nperseg)
            mc = mean_coherence(f, c, band)
            coupled = mc >= thr
            model = (
                armax(y[:n_est], u[:n_est], na, nb, nc, nk, sample_time=rec.sample_time, input=name_in, output=name_out)
                if coupled
                else None
            )
            channels[(name_in, name_out)] = ChannelResult(name_in, name_out, f, c, mc, coupled, model)
    return MimoIdentification(channels, (float(band[0]), float(band[1])), thr)
