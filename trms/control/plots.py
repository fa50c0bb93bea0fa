"""Figures of closed-loop runs: response and control with the actuator limit drawn (like figs. 6.6-6.14).

:func:`plot_closed_loop` returns the :class:`matplotlib.figure.Figure` (drawn into ``ax=`` when
given, else on matplotlib's Agg canvas, no pyplot state touched);
:func:`trms.present.figures.save_figure` writes it as PNG.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from trms.control.arguments import real_array
from trms.errors import InputError
from trms.record import Record

__all__ = ["plot_closed_loop", "draw_limits"]


def draw_limits(ax: Any, signal: np.ndarray, lower: float, upper: float, color: str = "k") -> None:
    """Draw actuator limits on ``ax`` without flattening the signal.

    The axes follow ``signal``; a limit inside that range is drawn dashed, limits outside it are named
    in the panel's corner (a 0.15 V control stays readable beside +-10 V limits, and +-60 V of commanded
    control shows where it crosses them).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The panel.
    signal : numpy.ndarray
        The plotted control (V); non-finite values are ignored.
    lower, upper : float
        Actuator limits (V; ``+-inf`` for none).
    color : str
        Colour of the dashed lines.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> ax = Figure().subplots()
    >>> draw_limits(ax, np.array([0.0, 0.15]), -10.0, 10.0)
    >>> len(ax.lines), ax.texts[0].get_text(), [round(float(v), 3) for v in ax.get_ylim()]
    (0, 'actuator limits -10 / +10 V (outside the view)', [-0.015, 0.165])
    >>> ax = Figure().subplots()
    >>> draw_limits(ax, np.array([-60.0, 60.0]), -10.0, 10.0)
    >>> [float(line.get_ydata()[0]) for line in ax.lines], len(ax.texts)
    ([-10.0, 10.0], 0)
    """
    u = np.asarray(signal, float)
    u = u[np.isfinite(u)]
    top, bottom = (float(u.max()), float(u.min())) if u.size else (0.0, 0.0)
    pad = 0.1 * max(top - bottom, 1e-6)
    view = (
        min(bottom - pad, lower) if bottom <= lower else bottom - pad,
        max(top + pad, upper) if top >= upper else top + pad,
    )
    shown = [v for v in (lower, upper) if np.isfinite(v) and view[0] <= v <= view[1]]
    for v in shown:
        ax.axhline(v, color=color, ls="--", lw=0.8)
    ax.set_ylim(*view)
    if len(shown) < 2:
        ax.text(
            0.01,
            0.95,
            f"actuator limits {lower:+.3g} / {upper:+.3g} V" + ("" if shown else " (outside the view)"),
            transform=ax.transAxes,
            fontsize=7,
            va="top",
        )


def plot_closed_loop(
    record: Record,
    title: str = "",
    limits: tuple[np.ndarray, np.ndarray] | None = None,
    output: int = 0,
    ax: Any = None,
) -> Figure:
    """Two panels: output and reference (top), commanded control and limits (bottom).

    Parameters
    ----------
    record : Record
        A run of :func:`trms.control.loop.closed_loop` (needs the ``reference`` and ``control`` extras).
    title : str
        Figure title.
    limits : tuple of numpy.ndarray, optional
        Actuator limits in deviation volts, drawn dashed.
    output : int
        Index of the tracked output to draw.
    ax : sequence of two matplotlib.axes.Axes, optional
        Axes to draw into (default: a new figure).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    InputError
        A record without the loop's extras, a bad output index, limits or axes.

    Examples
    --------
    >>> import control
    >>> from trms.control.loop import closed_loop
    >>> from trms.control.pid import PIDController, PIDGains
    >>> from trms.plant import LinearPlant
    >>> plant = LinearPlant(control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1))
    >>> record = closed_loop(plant, PIDController(PIDGains(kp=1.0, ki=0.0, kd=0.0), 0.1), np.full(50, 0.2))
    >>> fig = plot_closed_loop(record, "P control", limits=(np.array([-1.0]), np.array([1.0])))
    >>> [ax.get_ylabel() for ax in fig.axes], [line.get_label() for line in fig.axes[0].lines]
    (['pitch (rad)', 'control (V)'], ['command', 'y1 (deviation)'])
    """
    if "reference" not in record.extras or "control" not in record.extras:
        raise InputError("record has no 'reference'/'control' extras; run it with trms.control.loop.closed_loop")
    n_ref = record.extras["reference"].shape[1]
    if isinstance(output, (bool, np.bool_)) or not isinstance(output, (int, np.integer)) or not 0 <= output < n_ref:
        raise InputError(f"output must be an integer index of a tracked output in [0, {n_ref - 1}], got {output!r}")
    if limits is not None:
        if isinstance(limits, (str, bytes)) or not isinstance(limits, (tuple, list)) or len(limits) != 2:
            raise InputError(f"limits must be a pair (lower, upper) of deviation volts, got {limits!r}")
        low = float(np.max(real_array("limits lower", limits[0], infinite=True)))
        high = float(np.min(real_array("limits upper", limits[1], infinite=True)))
    _, dy = record.deviations()
    t = record.time
    if ax is None:
        fig = Figure(figsize=(8.0, 5.5), dpi=100)
        FigureCanvasAgg(fig)
        ax1, ax2 = fig.subplots(2, 1, sharex=True)
    else:
        axes = list(np.asarray(ax, dtype=object).reshape(-1))
        if len(axes) != 2:
            raise InputError(f"ax holds {len(axes)} axes; the closed-loop plot draws 2")
        ax1, ax2 = axes
        fig = ax1.figure
    ax1.plot(t, record.extras["reference"][:, output], "k:", lw=1.0, label="command")
    if "prefiltered_reference" in record.extras and record.metadata.get("prefilter"):
        ax1.plot(t, record.extras["prefiltered_reference"][:, output], "g--", lw=1.0, label="prefiltered command")
    ax1.plot(t, dy[:, output], "b", lw=1.2, label=f"{record.output_names[output]} (deviation)")
    ax1.set_ylabel("pitch (rad)")
    ax1.legend(loc="upper right", fontsize=8)
    ax1.grid(True, alpha=0.3)
    u = record.extras["control"]
    for j in range(u.shape[1]):
        ax2.plot(t, u[:, j], lw=1.0, label=f"{record.input_names[j]} commanded (deviation)")
    if limits is not None:
        draw_limits(ax2, u, low, high, color="r")
    ax2.set_ylabel("control (V)")
    ax2.set_xlabel("time (s)")
    ax2.legend(loc="upper right", fontsize=8)
    ax2.grid(True, alpha=0.3)
    if title:
        fig.suptitle(title)
    return fig
