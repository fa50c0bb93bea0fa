"""A faked rig of known truth, for checking a time-domain calibration end to end.

The shipped twin with some physical parameters changed (:data:`FAKED_RIG`: a heavier
counterweight, more pitch damping, a weaker and slower main motor), its encoders noisy
(:data:`ENCODER_NOISE`) and its ambient turbulence on, driven the way a rig owner drives
the rig -- binary noise and doublets of a few tenths of a volt around hover -- and logged
in degrees under the rig's own column names (:func:`to_rig_csv`). Calibrating the shipped
model on its records must give the changed values back within the reported intervals, or
say why not: the tests and ``benchmarks/bench_timedomain.py`` do exactly that.
"""

from __future__ import annotations

import csv
import os
from pathlib import Path
from typing import IO

import mujoco
import numpy as np

from trms.errors import InputError, check_choice
from trms.files import atomic_write
from trms.record import Record
from trms.signals import doublet, random_binary
from trms.twin.model import get_configuration, load_spec
from trms.twin.parameters import read_parameters, with_parameters
from trms.twin.twin import Twin

__all__ = ["ENCODER_NOISE", "FAKED_RIG", "KINDS", "excitation", "faked_rig_records", "to_rig_csv"]

#: The faked rig's parameters as multiples of the shipped model's.
FAKED_RIG = {"counterweight_mass": 1.15, "pitch_damping": 1.4, "main_motor_gain": 0.9, "main_motor_lag": 1.25}
#: The faked rig's encoder noise (rad, standard deviation, every axis).
ENCODER_NOISE = 0.002
#: The excitations :func:`excitation` draws.
KINDS = ("prbs", "doublets")
_DOUBLET_WIDTHS = (2.0, 4.0, 6.0)  # s, the halves of successive doublets (the rig's pitch period is about 3 s)


def excitation(kind: str, duration: float, sample_time: float, amplitude: float, seed: int = 0) -> np.ndarray:
    """A voltage deviation around hover (V), shape ``(round(duration / sample_time),)``.

    ``"prbs"``: a random binary signal ``+-amplitude`` at a 0.5 Hz clock (seeded). ``"doublets"``:
    doublets of ``amplitude`` with halves of 2, 4 and 6 s in turn, one second of rest before each.

    Examples
    --------
    >>> u = excitation("doublets", 20.0, 0.05, 0.25)
    >>> u.shape, float(u.max()), float(u.min())
    ((400,), 0.25, -0.25)
    """
    n = int(round(duration / sample_time))
    if kind == "prbs":
        return random_binary(duration, sample_time, 0.5, amplitude, seed=seed)
    check_choice("excitation kind", kind, KINDS, error=InputError)
    parts, total, i = [], 0, 0
    while total < n:
        width = _DOUBLET_WIDTHS[i % len(_DOUBLET_WIDTHS)]
        part = doublet(sample_time, width, amplitude, start=1.0)
        parts.append(part)
        total += len(part)
        i += 1
    return np.concatenate(parts)[:n]


def faked_rig_records(
    config: str,
    amplitude: float,
    duration: float,
    kinds: tuple[str, ...] = ("prbs", "doublets", "prbs"),
    *,
    seed: int = 0,
    sample_time: float = 0.05,
    factors: dict[str, float] | None = None,
    spec: mujoco.MjSpec | None = None,
) -> tuple[dict[str, float], list[Record]]:
    """The faked rig's true parameter values and one record a kind of excitation.

    Parameters
    ----------
    config : str
        ``"1dof"`` or ``"2dof"`` (both inputs excited, the tail one by its own binary signal).
    amplitude : float
        Excitation around hover (V).
    duration : float
        Length of each record (s).
    kinds : tuple of str
        The excitation of each record (:data:`KINDS`).
    seed : int
        Record ``i`` uses seed ``seed + i`` (its excitation, turbulence and noise).
    sample_time : float
        Control sample time (s).
    factors : dict of str to float, optional
        The changed parameters, as multiples of ``spec``'s (default :data:`FAKED_RIG`).
    spec : mujoco.MjSpec, optional
        The model to change (default: the shipped one).

    Returns
    -------
    truth : dict of str to float
        The changed parameters' values (their units).
    records : list of Record
        Absolute volts in, radians out (encoder noise, the default quantisation, turbulence on).

    Examples
    --------
    >>> truth, (rec,) = faked_rig_records("1dof", 0.25, 2.0, ("doublets",))
    >>> len(rec), rec.metadata["config"], sorted(truth) == sorted(FAKED_RIG)
    (40, '1dof', True)
    """
    spec = spec if spec is not None else load_spec()
    factors = dict(FAKED_RIG if factors is None else factors)
    start = read_parameters(spec, list(factors))
    truth = {n: start[n] * f for n, f in factors.items()}
    twin = Twin(config, sample_time, spec=with_parameters(spec, truth), noise_std=ENCODER_NOISE)
    hover = twin.operating_point.inputs
    n_in = len(get_configuration(config).inputs)
    records = []
    for i, kind in enumerate(kinds):
        u = np.tile(hover, (int(round(duration / sample_time)), 1))
        u[:, 0] += excitation(kind, duration, sample_time, amplitude, seed + i)
        if n_in > 1:
            u[:, 1] += excitation("prbs", duration, sample_time, amplitude, seed + 100 + i)
        records.append(twin.run(u, seed=seed + i))
    return truth, records


def to_rig_csv(record: Record, path: str | os.PathLike[str]) -> Path:
    """Write ``record`` as the rig logs it: ``Time [s]``, ``Main motor [V]`` (``Tail motor [V]``),
    ``Pitch [deg]`` (``Yaw [deg]``), angles in degrees, every value to full precision.

    Examples
    --------
    >>> import tempfile
    >>> _, (rec,) = faked_rig_records("1dof", 0.25, 1.0, ("prbs",))
    >>> path = to_rig_csv(rec, Path(tempfile.mkdtemp()) / "rig.csv")
    >>> path.read_text().splitlines()[0]
    'Time [s],Main motor [V],Pitch [deg]'
    """
    names = {"u1": "Main motor [V]", "u2": "Tail motor [V]", "pitch": "Pitch [deg]", "yaw": "Yaw [deg]"}

    def write(fh: IO[str]) -> None:
        w = csv.writer(fh)
        w.writerow(["Time [s]", *(names[u] for u in record.input_names), *(names[o] for o in record.output_names)])
        for t, u, y in zip(record.time, record.inputs, np.degrees(record.outputs)):
            w.writerow([repr(float(t)), *(repr(float(v)) for v in u), *(repr(float(v)) for v in y)])

    return atomic_write(path, write, binary=False)
