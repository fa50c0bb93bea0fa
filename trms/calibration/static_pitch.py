"""The twin's large signals, stated: its static pitch over the main rotor's voltage, beside Feedback's published
model's.

A design made on eq. (3.11) meets one gain; the twin, as the rig, has a thrust curve, so its static gain changes
along the voltage. :func:`static_pitch_curves` solves the 1-DOF twin's static equilibrium in still air (every
MuJoCo acceleration zero: :func:`~trms.twin.trim.solve_trim` with the pitch held, which gives the voltage that
holds each pitch) and reads the pitch at main-rotor offsets around the hover trim, with the local static gain
(rad/V) along it. Past the fold -- the largest pitch a voltage holds, where gravity's restoring torque stops
growing -- or past an end stop, the beam sits on the stop (gain 0).

Beside it Feedback's published model (:func:`trms.twin.published.static_pitch`) around its own hover voltage,
scaled to the twin's small-signal gain at trim by ``c = twin's gain / published gain`` two ways:

* input: the published model driven by ``c`` times the offset -- the published rotor behind an amplifier of gain
  ``c``, which is what the twin's lumped motor gain says it is;
* output: ``c`` times the published pitch -- the published model's own shape per volt, stretched to the twin's
  gain.

Both meet the twin's gain at trim by construction; they part, from the twin and from each other, in the large
signal. The published model has no end stops: its pitch is shown on the twin's (the rig's). About half a second.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
import scipy.optimize
from matplotlib.figure import Figure

from trms.errors import DesignError
from trms.present.figures import new_axes
from trms.present.tables import ComparisonTable
from trms.twin.model import CONFIGURATIONS, build_model, thrust_curves
from trms.twin.published import PUBLISHED, hover, static_gain, static_pitch
from trms.twin.trim import rest_pose, solve_trim

__all__ = ["OFFSETS", "TABLE_STEP", "PitchCurve", "StaticPitch", "static_pitch_curves", "plot_static_pitch"]

#: Main-rotor offsets from each model's hover voltage (V): -1 to +1 V in 50 mV steps.
OFFSETS = np.round(np.linspace(-1.0, 1.0, 41), 10)
#: The table's offsets: every multiple of this (V).
TABLE_STEP = 0.1
#: Pitch step (rad) of the central difference that reads the twin's local gain.
_GAIN_STEP = 1e-4


@dataclass(frozen=True, eq=False)
class PitchCurve:
    """One model's static pitch over the offsets.

    Attributes
    ----------
    label : str
        The model, as the table names it.
    trim : float
        Its hover voltage (V), where the offsets start.
    pitch : numpy.ndarray
        Pitch at rest (rad from the flat beam); the stop's angle where ``on_stop``.
    gain : numpy.ndarray
        Local static gain, d pitch / d volt (rad/V); 0 on a stop.
    on_stop : numpy.ndarray of bool
        Where no pitch short of a stop holds the voltage: the beam sits on the stop.
    reach : float
        The largest offset (V) that holds a steady pitch short of the upper stop.

    Examples
    --------
    >>> c = PitchCurve("m", 1.0, np.array([0.1, 1.1]), np.array([1.0, 0.0]), np.array([False, True]), 0.2)
    >>> PitchCurve.from_dict(c.to_dict()).to_dict() == c.to_dict()
    True
    """

    label: str
    trim: float
    pitch: np.ndarray
    gain: np.ndarray
    on_stop: np.ndarray
    reach: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable form."""
        return {
            "label": self.label,
            "trim_V": self.trim,
            "pitch_rad": self.pitch.tolist(),
            "gain_rad_per_V": self.gain.tolist(),
            "on_stop": self.on_stop.tolist(),
            "reach_V": self.reach,
        }

    @classmethod
    def from_dict(cls, data: dict) -> PitchCurve:
        """From :meth:`to_dict`'s form."""
        return cls(
            str(data["label"]),
            float(data["trim_V"]),
            np.asarray(data["pitch_rad"], float),
            np.asarray(data["gain_rad_per_V"], float),
            np.asarray(data["on_stop"], bool),
            float(data["reach_V"]),
        )


@dataclass(frozen=True, eq=False)
class StaticPitch:
    """The twin's static pitch curve beside the published model's, scaled both ways (module docstring).

    Attributes
    ----------
    offsets : numpy.ndarray
        Main-rotor offsets from each model's hover voltage (V).
    twin, input_scaled, output_scaled : PitchCurve
        The twin; the published model at ``scale`` times the offset; ``scale`` times the published pitch.
    scale : float
        The twin's small-signal gain at trim over the published model's (dimensionless).
    stops : tuple of float
        The pitch end stops (rad from flat).
    thrust_slope : numpy.ndarray
        The twin's main thrust slope dF/dV at each offset (N/V).
    rest_pitch : float
        The twin's 1-DOF rest pose with the rotors off (rad from flat).
    log_slope : float
        The twin's thrust law's logarithmic slope at trim, ``V dF/dV / F`` (1 for a thrust linear in the voltage,
        2 for a quadratic one).
    """

    offsets: np.ndarray
    twin: PitchCurve
    input_scaled: PitchCurve
    output_scaled: PitchCurve
    scale: float
    stops: tuple[float, float]
    thrust_slope: np.ndarray
    rest_pitch: float
    log_slope: float

    @property
    def curves(self) -> tuple[PitchCurve, PitchCurve, PitchCurve]:
        """The twin, then the published model scaled at its input and at its output."""
        return self.twin, self.input_scaled, self.output_scaled

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable form."""
        return {
            "offsets_V": self.offsets.tolist(),
            "twin": self.twin.to_dict(),
            "input_scaled": self.input_scaled.to_dict(),
            "output_scaled": self.output_scaled.to_dict(),
            "scale": self.scale,
            "stops_rad": list(self.stops),
            "thrust_slope_N_per_V": self.thrust_slope.tolist(),
            "rest_pitch_rad": self.rest_pitch,
            "log_slope": self.log_slope,
        }

    @classmethod
    def from_dict(cls, data: dict) -> StaticPitch:
        """From :meth:`to_dict`'s form."""
        lo, hi = (float(v) for v in data["stops_rad"])
        return cls(
            np.asarray(data["offsets_V"], float),
            PitchCurve.from_dict(data["twin"]),
            PitchCurve.from_dict(data["input_scaled"]),
            PitchCurve.from_dict(data["output_scaled"]),
            float(data["scale"]),
            (lo, hi),
            np.asarray(data["thrust_slope_N_per_V"], float),
            float(data["rest_pitch_rad"]),
            float(data["log_slope"]),
        )

    def table(self, step: float = TABLE_STEP) -> ComparisonTable:
        """The curves at every multiple of ``step`` (V) among the offsets, with what they rest on in the notes.

        Parameters
        ----------
        step : float
            Offset spacing of the rows (V).

        Returns
        -------
        ComparisonTable
            Pitch (rad from flat) and local gain (rad/V) of each model; the twin's pitch over the offset too.
        """
        rows = np.flatnonzero(np.isclose(np.round(self.offsets / step) * step, self.offsets, atol=1e-9))
        c = self.scale
        table = ComparisonTable(
            "The twin's static pitch over the main rotor's voltage (1-DOF, still air), beside Feedback's published "
            "model scaled to the twin's small-signal gain",
            [
                "offset from trim (V)",
                "twin: pitch (rad)",
                "twin: pitch / offset (rad/V)",
                "twin: local gain (rad/V)",
                f"published, input x {c:.3g}: pitch (rad)",
                "its local gain (rad/V)",
                f"published, pitch x {c:.3g}: pitch (rad)",
                "its local gain (rad/V)",
            ],
        )
        for i in rows:
            cells: list[object] = [f"{self.offsets[i]:+.2f}"]
            for k, curve in enumerate(self.curves):
                stop = bool(curve.on_stop[i])
                cells.append(f"on the stop ({curve.pitch[i]:+.2g})" if stop else f"{curve.pitch[i]:+.3f}")
                if k == 0:
                    off = self.offsets[i]
                    cells.append("-" if stop or off == 0 else f"{curve.pitch[i] / off:.3g}")
                cells.append("-" if stop else f"{curve.gain[i]:.3g}")
            table.rows.append(cells)
        trim = int(np.argmin(np.abs(self.offsets)))
        tw, ins, outs = self.curves
        per_volt = _relative_change_per_volt(self.offsets, self.thrust_slope, trim)
        table.notes = [
            f"Trims: the twin hovers at {tw.trim:.3f} V, the published model at {ins.trim:.3f} V; each curve's offsets "
            "are taken from its own trim. Pitch from the flat beam at rest (static equilibrium); local gain: its "
            "slope d pitch / d volt; pitch / offset: the gain a step from trim reads.",
            f"Scaled to the same small-signal gain at trim: the twin's is {tw.gain[trim]:.3f} rad/V, the published "
            f"model's {tw.gain[trim] / c:.3f} rad/V, c = {c:.3f}. Input: the published model driven by c x the offset "
            "(its rotor behind an amplifier of gain c, as the twin's lumped motor gain has it); output: c x the "
            "published pitch (its own shape per volt).",
            f"Reach, the largest offset that holds a steady pitch short of the +{self.stops[1]:g} rad stop (past it "
            f"the beam swings onto the stop): twin {tw.reach:+.3f} V, published input-scaled {ins.reach:+.3f} V, "
            f"output-scaled {outs.reach:+.3f} V. The published model has no stops; its pitch is shown on the twin's "
            f"({self.stops[0]:g} to +{self.stops[1]:g} rad).",
            f"The twin's main thrust slope dF/dV: {self.thrust_slope[0]:.3g} N/V at {self.offsets[0]:+g} V, "
            f"{self.thrust_slope[trim]:.3g} at trim, {self.thrust_slope[-1]:.3g} at {self.offsets[-1]:+g} V "
            f"({100 * per_volt:.0f} % of its trim value per volt at trim); its rotor voltage crosses 0 at "
            f"{-tw.trim:+.3f} V, where the thrust curve turns to its reverse branch (the twin's is "
            "asymmetric, the published one symmetric).",
            *self.hover_note(),
        ]
        return table

    def hover_note(self) -> list[str]:
        """Why the twin hovers where it does, from the run's figures: at rest the thrust's torque balances a
        pendulum, so its trim is about ``n tan(-rest) / g`` (``n`` the thrust law's log slope at trim, ``rest`` its
        rest pose, ``g`` its gain at trim), whatever its motor gain."""
        trim = int(np.argmin(np.abs(self.offsets)))
        g, lean = float(self.twin.gain[trim]), float(np.tan(-self.rest_pitch))
        return [
            f"Why the twin hovers at {self.twin.trim:.3f} V: at rest its thrust's torque balances a pendulum, so the "
            f"hover voltage is about n tan(-rest) / g = {self.log_slope * lean / g:.3f} V, with n = V dF/dV / F = "
            f"{self.log_slope:.3f} its thrust law's log slope at trim, rest = {self.rest_pitch:.3f} rad its rest "
            f"pose and g = {g:.3f} rad/V its gain at trim, whatever its motor gain. A propeller's thrust "
            f"(a tau|tau| + b tau) has n < 2: with this gain and rest pose no motor gain puts the hover above "
            f"{2 * lean / g:.2f} V, and the published model's {self.input_scaled.trim:.3f} V would need "
            f"n = {self.input_scaled.trim * g / lean:.2f}."
        ]


def _relative_change_per_volt(offsets: np.ndarray, values: np.ndarray, at: int) -> float:
    """The central slope of ``values`` at index ``at`` over its value there (1/V)."""
    lo, hi = max(at - 1, 0), min(at + 1, offsets.size - 1)
    return float((values[hi] - values[lo]) / (offsets[hi] - offsets[lo]) / values[at])


def _twin_curve(
    spec: mujoco.MjSpec, offsets: np.ndarray
) -> tuple[PitchCurve, tuple[float, float], np.ndarray, float, float]:
    """The twin's curve (:func:`static_pitch_curves`), its pitch stops (rad), thrust slope (N/V) at the offsets, rest
    pose (rad) and its thrust law's log slope at trim."""
    model = build_model(spec, CONFIGURATIONS["1dof"], delay=False, scene=False)
    curves = thrust_curves(spec)
    lo, hi = (float(v) for v in model.jnt_range[model.joint("pitch").id])

    def volts(theta: float) -> float:
        """The main-rotor voltage that holds the beam still at ``theta`` (rad from flat)."""
        held = solve_trim(model, curves, (0,), ("pitch",), axis_angles={"pitch": theta})
        return float(held.voltages[0])

    trim = volts(0.0)
    # The fold: the largest voltage a pitch short of the upper stop holds (else the stop itself).
    top = scipy.optimize.minimize_scalar(
        lambda t: -volts(t), bounds=(0.0, hi), method="bounded", options={"xatol": 1e-9}
    )
    theta_top, v_top = float(top.x), volts(float(top.x))
    if volts(hi) >= v_top:
        theta_top, v_top = hi, volts(hi)
    v_bottom = volts(lo)
    pitch, gain, on_stop = np.empty(offsets.size), np.zeros(offsets.size), np.zeros(offsets.size, bool)
    guess, slope_guess, previous = 0.0, 0.0, trim
    for i, dv in enumerate(offsets):
        v = trim + float(dv)
        if v >= v_top or v <= v_bottom:
            pitch[i], on_stop[i] = (hi if v >= v_top else lo), True
            continue
        theta = _pitch_at(volts, v, guess + slope_guess * (v - previous), lo, theta_top)
        a, b = max(lo, theta - _GAIN_STEP), min(theta_top, theta + _GAIN_STEP)
        pitch[i], gain[i] = theta, (b - a) / (volts(b) - volts(a))
        guess, slope_guess, previous = theta, gain[i], v
    slope = np.asarray(curves[0].slope(trim + offsets), float)
    log_slope = float(curves[0].slope(trim)) * trim / float(curves[0].thrust(trim))
    rest = float(rest_pose(model)[model.jnt_qposadr[model.joint("pitch").id]])
    return PitchCurve("twin", trim, pitch, gain, on_stop, v_top - trim), (lo, hi), slope, rest, log_slope


def _pitch_at(volts: Any, v: float, start: float, lo: float, top: float) -> float:
    """The pitch in ``[lo, top]`` (rad) where ``volts`` (increasing there) is ``v``: secant steps from ``start``
    (a few solves from a neighbour's extrapolation), else bisection-safe Brent on the whole branch."""
    start = min(max(start, lo), top)
    try:
        found = scipy.optimize.root_scalar(
            lambda t: volts(t) - v,
            x0=start,
            x1=start + 1e-3 * (1 if start < top else -1),
            method="secant",
            xtol=1e-12,
            maxiter=12,
        )
        if found.converged and lo <= found.root <= top:
            return float(found.root)
    except DesignError:  # a secant step left the branch for a pitch no voltage within the limits holds
        pass
    return float(scipy.optimize.brentq(lambda t: volts(t) - v, lo, top, xtol=1e-12))


def _published_curve(
    offsets: np.ndarray, scale: float, stops: tuple[float, float], at_input: bool, p: dict[str, float]
) -> PitchCurve:
    """The published model's curve scaled at its input or its output (module docstring), on the twin's stops."""
    lo, hi = stops
    x = scale * offsets if at_input else offsets
    raw, slope = static_pitch(x, p), scale * static_gain(x, p)
    pitch = raw if at_input else scale * raw
    past = ~np.isfinite(pitch)  # past the fold: the beam swings onto the stop on the offset's side
    on_stop = past | (np.nan_to_num(pitch) > hi) | (np.nan_to_num(pitch) < lo)
    pitch = np.where(past, np.where(x > 0, hi, lo), np.clip(np.nan_to_num(pitch), lo, hi))
    v0, flat = hover(p)
    # The reach: the offset whose torque holds the highest pitch short of the stop (or the fold, pi/2 from rest).
    top = min((hi if at_input else hi / scale) + flat, np.pi / 2)
    torque = p["Mg"] * np.sin(top)
    tau = (-p["b1"] + np.sqrt(p["b1"] ** 2 + 4.0 * p["a1"] * torque)) / (2.0 * p["a1"])
    reach = (tau * p["T10"] / p["k1"] - v0) / (scale if at_input else 1.0)
    label = "published, input-scaled" if at_input else "published, output-scaled"
    return PitchCurve(label, v0, pitch, np.where(on_stop, 0.0, slope), on_stop, float(reach))


def static_pitch_curves(
    spec: mujoco.MjSpec, offsets: Sequence[float] | np.ndarray = OFFSETS, p: dict[str, float] = PUBLISHED
) -> StaticPitch:
    """The 1-DOF twin's static pitch over main-rotor offsets around its trim, beside the published model's.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The twin's model (not modified).
    offsets : sequence of float
        Offsets from each model's hover voltage (V), increasing; 0 among them (the trim, where the scale is read).
    p : dict
        The published model's parameters (:data:`~trms.twin.published.PUBLISHED`).

    Returns
    -------
    StaticPitch
        Pitch (rad from flat) and local gain (rad/V) of the twin and of the published model scaled to its
        small-signal gain at its input and at its output (module docstring).

    Raises
    ------
    ValueError
        ``offsets`` not increasing or without 0.

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> curves = static_pitch_curves(load_spec(), [-0.1, 0.0, 0.1, 1.0])
    >>> bool(curves.twin.gain[2] > curves.twin.gain[1] > curves.twin.gain[0] > 0), curves.twin.on_stop.tolist()
    (True, [False, False, False, True])
    >>> [round(float(c.gain[1] / curves.twin.gain[1]), 9) for c in (curves.input_scaled, curves.output_scaled)]
    [1.0, 1.0]
    """
    x = np.asarray(offsets, float)
    if x.ndim != 1 or np.any(np.diff(x) <= 0) or not np.any(x == 0.0):
        raise ValueError(f"offsets must increase and hold 0 V, got {x.tolist()}")
    twin, stops, slope, rest, log_slope = _twin_curve(spec, x)
    at_trim = int(np.flatnonzero(x == 0.0)[0])
    scale = float(twin.gain[at_trim] / static_gain(0.0, p))
    return StaticPitch(
        x,
        twin,
        _published_curve(x, scale, stops, True, p),
        _published_curve(x, scale, stops, False, p),
        scale,
        stops,
        slope,
        rest,
        log_slope,
    )


def plot_static_pitch(curves: StaticPitch, ax: Any = None) -> Figure:
    """The static pitch and its local gain over the offset: the twin and the scaled published model.

    Parameters
    ----------
    curves : StaticPitch
        What :func:`static_pitch_curves` measured.
    ax : sequence of two matplotlib Axes, optional
        Pitch and gain panels; by default a new figure on matplotlib's Agg canvas.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> fig = plot_static_pitch(static_pitch_curves(load_spec(), [-0.5, 0.0, 0.5]))
    >>> [a.get_ylabel() for a in fig.axes]
    ['pitch from flat (rad)', 'local static gain (rad/V)']
    """
    fig, axes = new_axes(1, 2, (10.0, 3.4), ax=ax)
    pitch_ax, gain_ax = np.ravel(axes)[:2]
    styles = (("k", "-"), ("b", "--"), ("tab:orange", ":"))
    for curve, (color, ls) in reversed(list(zip(curves.curves, styles))):  # the twin drawn last, on top
        free = ~curve.on_stop
        pitch_ax.plot(curves.offsets[free], curve.pitch[free], color=color, ls=ls, label=curve.label)
        pitch_ax.plot(
            curves.offsets[curve.on_stop], curve.pitch[curve.on_stop], "x", color=color, ms=4 + 2 * (ls == "-")
        )
        gain_ax.semilogy(curves.offsets[free], curve.gain[free], color=color, ls=ls, label=curve.label)
    for stop in curves.stops:
        pitch_ax.axhline(stop, color="r", lw=0.8, alpha=0.5)
    pitch_ax.set_title(f"static pitch (x: on a stop; published scaled by c = {curves.scale:.3g})", fontsize=9)
    gain_ax.set_title("local static gain", fontsize=9)
    pitch_ax.set_ylabel("pitch from flat (rad)")
    gain_ax.set_ylabel("local static gain (rad/V)")
    for panel in (pitch_ax, gain_ax):
        panel.set_xlabel("main rotor offset from trim (V)")
        panel.grid(True, which="both", alpha=0.3)
    handles, labels = pitch_ax.get_legend_handles_labels()
    pitch_ax.legend(handles[::-1], labels[::-1], fontsize=8)  # the twin first
    return fig
