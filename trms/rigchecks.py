"""The plausibility checks of a rig's export, column by column: units, the sample time and its uniform grid,
motor voltages, and angles against the rig's end stops and speed.

:mod:`trms.rigdata` runs them on every export it reads (text or MATLAB); each refusal is one line naming the
row and column, each note (a snapped grid, a saturated drive, degrees that look like radians) one line too.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from trms import reference
from trms.errors import InputError
from trms.record import Record
from trms.reference import EQ_3_11_MODE, SAMPLE_TIME_RANGE, VOLTAGE_LIMIT

__all__ = [
    "ANGLE_UNITS",
    "TIME_UNITS",
    "JITTER_TOLERANCE",
    "END_STOP_MARGIN",
    "STOP_CONTACT",
    "MAX_RATE",
    "MAX_INPUT_V",
    "ExportLayout",
    "angle_stop",
    "beyond_end_stops",
    "check_sample_time",
    "uniform_grid",
    "check_voltages",
    "check_angles",
]

#: Angle units a rig's export may use, and their factor to radians.
ANGLE_UNITS = {"rad": 1.0, "deg": np.pi / 180.0}
#: Time units a rig's export may use, and their factor to seconds.
TIME_UNITS = {"s": 1.0, "ms": 1e-3}
#: Largest distance of a timestamp from the record's uniform grid that is snapped to it, as a fraction
#: of the sample time (logger jitter); beyond it the record is refused unless it is resampled.
JITTER_TOLERANCE = 0.05
#: How far an angle may read beyond its end stop, as a fraction of the stop: an encoder's zero a little
#: off the model's, the beam pressing into the rubber of the stop.
END_STOP_MARGIN = 0.2
#: An angle within this fraction of its joint's range (the span between its two stops) from an end stop is at the
#: stop: samples every control interval miss the peak of a bounce between them.
STOP_CONTACT = 0.01
#: Fastest each axis can move (rad/s), about twice the fastest the twin moves under +-10 V square waves on
#: both rotors (periods 0.5-12 s, 1-DOF, 2-DOF and yaw rigs, a 0.01 s sample time: pitch 12.7 rad/s, yaw
#: 19.6 rad/s, bouncing off the stops). An angle that changes faster between two samples is not that axis
#: in the stated unit.
MAX_RATE = {"pitch": 26.0, "yaw": 40.0}
#: Largest motor voltage (V) an export may hold: ten times the drives' +-10 V. Beyond it the column is not a
#: voltage in V (a raw count, another unit); between the two the drives saturated (a note says so).
MAX_INPUT_V = 10.0 * VOLTAGE_LIMIT
#: Relative spread of the timestamps below which they are on the grid already (printed rounding).
_UNIFORM_TOL = 1e-3


@dataclass(frozen=True)
class ExportLayout:
    """The column options of an export (the same for text and .mat files).

    Attributes
    ----------
    time : str
        The time column.
    inputs, outputs : tuple of str
        The voltage and angle columns.
    units, time_unit : str
        Angle unit (a key of :data:`ANGLE_UNITS`) and time unit (a key of :data:`TIME_UNITS`).
    resample : bool
        Interpolate a record off a uniform grid onto one (refused otherwise).
    in_names, out_names : tuple of str
        The channels' names in the Record.

    Examples
    --------
    >>> ExportLayout("t", ("V",), ("pitch",), "deg", "s", False, ("u1",), ("pitch",)).wanted
    ('t', 'V', 'pitch')
    """

    time: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    units: str
    time_unit: str
    resample: bool
    in_names: tuple[str, ...]
    out_names: tuple[str, ...]

    @property
    def wanted(self) -> tuple[str, ...]:
        """The columns read, in order: time, inputs, outputs."""
        return (self.time, *self.inputs, *self.outputs)


def _grid(t: np.ndarray, ts: float) -> tuple[float, np.ndarray]:
    """The origin of the uniform grid of step ``ts`` (s) nearest to ``t`` and each timestamp's distance from it."""
    k = np.arange(t.size)
    origin = float(np.mean(t - k * ts))
    return origin, t - (origin + k * ts)


def check_sample_time(ts: float, layout: ExportLayout, where: str) -> str | None:
    """Refuse a sample time outside the rig's kernel; a note for one too slow to see the pitch mode."""
    lo, hi, _ = SAMPLE_TIME_RANGE
    other = "ms" if layout.time_unit == "s" else "s"
    alt = ts / TIME_UNITS["ms"] if other == "s" else ts * TIME_UNITS["ms"]
    hint = (
        f": is the time column in {'milliseconds' if other == 'ms' else 'seconds'}? say time_unit={other!r} "
        f"(--time-unit {other})"
        if lo <= alt <= hi
        else ""
    )
    if not lo <= ts <= hi:
        raise InputError(
            f"column {layout.time!r}{where}: sample time {ts:.6g} s (median interval, time in {layout.time_unit}) is "
            f"outside the rig's range [{lo:g} s, {hi:g} s]{hint}"
        )
    nyquist = 1.0 / (2.0 * EQ_3_11_MODE[0])
    if ts > nyquist:
        return (
            f"column {layout.time!r}{where}: sample time {ts:.6g} s cannot resolve the rig's {EQ_3_11_MODE[0]:g} Hz "
            f"pitch mode (needs < {nyquist:.3g} s){hint or '; check the time column'}"
        )
    return None


def uniform_grid(
    data: np.ndarray, layout: ExportLayout, row: Callable[[int], str], where: str
) -> tuple[np.ndarray, float, float, list[str]]:
    """The data on a uniform time grid: ``(data, sample time s, origin s, notes)``; the time column in s."""
    t = data[:, 0]
    dt = np.diff(t)
    ts_med = float(np.median(dt))
    k = np.arange(t.size)
    slope = float(np.polyfit(k, t, 1)[0])
    res = SAMPLE_TIME_RANGE[2]
    on_kernel = round(slope / res) * res
    candidates = [c for c in (on_kernel, slope) if c > 0]
    for ts in candidates:
        origin, dev = _grid(t, ts)
        worst = float(np.max(np.abs(dev)))
        if worst <= JITTER_TOLERANCE * ts:
            break
    notes = []
    if worst > JITTER_TOLERANCE * ts:
        off = np.abs(dt - ts_med) > JITTER_TOLERANCE * ts_med
        i = int(np.argmax(off)) if off.any() else max(int(np.argmax(np.abs(dev))) - 1, 0)
        if not layout.resample:
            raise InputError(
                f"{row(i + 1)}, column {layout.time!r}: sample interval {dt[i]:.6g} s differs from the record's "
                f"{ts_med:.6g} s (timestamps up to {100 * worst / ts:.3g} % of a sample off a uniform grid, beyond the "
                f"{100 * JITTER_TOLERANCE:g} % jitter tolerance); resample=True (--resample) interpolates the record "
                "linearly onto a uniform grid"
            )
        ts = ts_med
        if abs(round(ts / res) * res - ts) <= _UNIFORM_TOL * ts:
            ts = round(ts / res) * res
        n = int(np.floor((t[-1] - t[0]) / ts + 1e-9)) + 1
        origin = float(t[0])
        grid = origin + np.arange(n) * ts
        out = np.column_stack([grid] + [np.interp(grid, t, data[:, j]) for j in range(1, data.shape[1])])
        notes.append(
            f"column {layout.time!r}{where}: timestamps up to {100 * worst / ts:.3g} % of a sample off a uniform grid "
            f"(beyond the {100 * JITTER_TOLERANCE:g} % jitter tolerance; intervals {dt.min():.6g} .. "
            f"{dt.max():.6g} s); "
            f"resampled by linear interpolation onto {ts:.6g} s: {t.size} rows -> {n} samples"
        )
        return out, ts, origin, notes
    if worst > _UNIFORM_TOL * ts:
        notes.append(
            f"column {layout.time!r}{where}: timestamps up to {100 * worst / ts:.3g} % of the {ts:.6g} s sample time "
            f"off a uniform grid (jitter tolerance {100 * JITTER_TOLERANCE:g} %); snapped to the grid"
        )
    out = data.copy()
    out[:, 0] = origin + k * ts
    return out, ts, origin, notes


def _axis(name: str, column: str) -> str | None:
    for text in (name, column):
        low = text.lower()
        hits = [a for a in ("pitch", "yaw") if a in low]
        if len(hits) == 1:
            return hits[0]
    return None


def angle_stop(name: str, column: str) -> tuple[str | None, float, str]:
    """The axis of an angle channel (or None), its end stop (rad; the widest when the axis is unknown), in words."""
    stops = dict(reference.END_STOPS)
    axis = _axis(name, column)
    stop = stops[axis] if axis else max(stops.values())
    return axis, stop, f"{axis}'s end stops +-{stop:g} rad" if axis else f"the rig's widest end stops +-{stop:g} rad"


def check_voltages(u: np.ndarray, layout: ExportLayout, row: Callable[[int], str], where: str) -> list[str]:
    """Refuse a voltage beyond :data:`MAX_INPUT_V`; a note for one beyond the drives' saturation."""
    notes = []
    for j, col in enumerate(layout.inputs):
        i = int(np.argmax(np.abs(u[:, j])))
        if abs(u[i, j]) > MAX_INPUT_V:
            raise InputError(
                f"{row(i)}, column {col!r}: {u[i, j]:.6g} V is beyond the plausible +-{MAX_INPUT_V:g} V of a motor "
                f"voltage (the drives saturate at +-{VOLTAGE_LIMIT:g} V): is the column in volts?"
            )
        if abs(u[i, j]) > VOLTAGE_LIMIT:
            notes.append(
                f"column {col!r}{where}: voltage reaches {u[i, j]:.4g} V, beyond the drives' +-{VOLTAGE_LIMIT:g} V: "
                "the rig applied at most that"
            )
    return notes


def check_angles(
    y_raw: np.ndarray,
    ts: float,
    layout: ExportLayout,
    row: Callable[[int], str],
    where: str,
    time: np.ndarray | None = None,
) -> list[str]:
    """Refuse angles beyond the end stops or faster than the rig; a note for radians that look labelled degrees, and
    one for an axis that reaches its end stop (within :data:`STOP_CONTACT` of its range), with the time of the first
    contact on the export's own clock (``time``, s; the sample's row without it)."""
    notes = []
    units = layout.units
    other = "deg" if units == "rad" else "rad"
    for j, (col, name) in enumerate(zip(layout.outputs, layout.out_names)):
        axis, stop, ends = angle_stop(name, col)
        max_rate = MAX_RATE[axis] if axis else max(MAX_RATE.values())
        what = axis or "an angle"
        limit = stop * (1.0 + END_STOP_MARGIN)
        raw = y_raw[:, j]
        y = raw * ANGLE_UNITS[units]
        i = int(np.argmax(np.abs(y)))
        if abs(y[i]) > limit:
            alt = float(np.max(np.abs(raw))) * ANGLE_UNITS[other]
            hint = (
                f"; as {other} it reaches {alt:.3g} rad: say units={other!r} (--units {other})"
                if alt <= limit
                else f"; in {other} too ({alt:.3g} rad): check the column"
            )
            raise InputError(
                f"{row(i)}, column {col!r}: {what} {raw[i]:.6g} {units}"
                + ("" if units == "rad" else f" ({y[i]:.3g} rad)")
                + f" is beyond {ends} "
                f"(with a {100 * END_STOP_MARGIN:g} % margin){hint}"
            )
        rate = np.abs(np.diff(y)) / ts
        if rate.size and rate.max() > max_rate:
            i = int(np.argmax(rate > max_rate))
            alt = float(rate.max()) / ANGLE_UNITS[units] * ANGLE_UNITS[other]
            hint = (
                f"; as {other} it would be {alt:.3g} rad/s: say units={other!r} (--units {other})"
                if alt <= max_rate
                else ""
            )
            raise InputError(
                f"{row(i + 1)}, column {col!r}: {what} moves {rate[i] * ts:.3g} rad in one sample ({ts:.6g} s), "
                f"{rate[i]:.3g} rad/s; the rig's {axis or 'fastest axis'} moves at most about {max_rate:g} rad/s{hint}"
            )
        at_stop = np.flatnonzero(np.abs(y) >= stop - STOP_CONTACT * 2.0 * stop)
        if axis is not None and at_stop.size:
            k = int(at_stop[0])
            when = f"at t = {time[k]:.6g} s" if time is not None else f"at {row(k)}"
            peak = int(np.argmax(np.abs(y)))
            deg = "" if units == "deg" else f" ({np.degrees(y[peak]):.4g} deg)"
            notes.append(
                f"column {col!r}{where}: {axis} reaches {raw[peak]:.6g} {units}{deg}, at its end stop +-{stop:g} rad "
                f"(+-{np.degrees(stop):.2f} deg), first {when}, {at_stop.size} sample(s) at the stop: the beam rests "
                "on it there, which identification and calibration cannot fit; record with a lower amplitude"
            )
        as_rad_possible = np.max(np.abs(raw)) <= stop and np.max(np.abs(np.diff(raw))) / ts <= max_rate
        if units == "deg" and np.ptp(raw) > 0 and as_rad_possible:
            notes.append(
                f"column {col!r}{where}: {what} reads {raw.min():.4g} .. {raw.max():.4g} deg, a motion of only "
                f"{np.ptp(raw):.3g} deg; the numbers fit {ends} and speed as radians: if the column is in radians, say "
                "units='rad' (--units rad)"
            )
    return notes


def beyond_end_stops(record: Record, margin: float = END_STOP_MARGIN) -> str | None:
    """Which of a record's angle outputs pass the rig's end stops (:data:`trms.reference.END_STOPS`), in one
    phrase, or ``None``.

    Parameters
    ----------
    record : Record
        Its outputs named for their axis (``pitch``, ``yaw``; others are not checked), in rad.
    margin : float
        Fraction of each stop an angle may read beyond it (:data:`END_STOP_MARGIN` for measured
        data, 0 for a model).

    Returns
    -------
    str or None
        E.g. ``"pitch reaches -13.2 rad (end stops +-1.1 rad)"``; ``None`` when every angle is within.

    Examples
    --------
    >>> r = Record(np.arange(3) * 0.1, np.zeros(3), [0.0, 0.5, 4.0], ("u1",), ("pitch",))
    >>> beyond_end_stops(r)
    'pitch reaches 4 rad (end stops +-1.1 rad)'
    """
    stops, parts = dict(reference.END_STOPS), []
    for j, name in enumerate(record.output_names):
        y = record.outputs[:, j]
        if name not in stops or not np.isfinite(y).any():
            continue
        i = int(np.nanargmax(np.abs(y)))
        if abs(y[i]) > stops[name] * (1.0 + margin):
            parts.append(f"{name} reaches {y[i]:.3g} rad (end stops +-{stops[name]:g} rad)")
    return ", ".join(parts) or None
