"""Figures of the experiments: spectra with modes marked, coherence, correlation tests, responses.

Every plot function returns its :class:`matplotlib.figure.Figure` (shown inline by notebooks) and
draws into the caller's axes when given ``ax=``; :func:`save_figure` writes one as PNG (what the
report does). Without ``ax`` the figure is drawn on matplotlib's Agg canvas: no pyplot state is
touched.

Examples
--------
>>> import numpy as np
>>> fig = plot_series(np.arange(3.0), {"pitch": np.zeros(3)}, "a run", "angle (rad)")
>>> type(fig).__name__
'Figure'
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from trms.control.plots import draw_limits
from trms.errors import InputError
from trms.files import atomic_write
from trms.identification.spectral import Peak
from trms.identification.validation import CorrelationTest

__all__ = ["plot_spectra", "plot_coherence", "plot_correlation_tests", "plot_series", "save_figure", "new_axes"]

_SIZE = (8.0, 4.5)


def save_figure(fig: Figure, path: str | os.PathLike[str], dpi: float = 100.0) -> Path:
    """Write ``fig`` as PNG at ``path`` (atomically, parent folders created); return the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    return atomic_write(path, lambda fh: fig.savefig(fh, format="png", dpi=dpi))


def new_axes(
    rows: int = 1, cols: int = 1, size: tuple[float, float] = _SIZE, ax: Any = None
) -> tuple[Figure, np.ndarray]:
    """The figure and ``(rows, cols)`` array of axes to draw into: the caller's ``ax`` (one Axes or a
    sequence of ``rows * cols``), else a new Agg figure of ``size`` inches.

    Raises
    ------
    InputError
        ``ax`` holds a different number of axes than the plot draws.
    """
    if ax is None:
        fig = Figure(figsize=size, dpi=100)
        FigureCanvasAgg(fig)
        return fig, fig.subplots(rows, cols, squeeze=False)
    axes = np.asarray(ax, dtype=object).reshape(-1)
    if axes.size != rows * cols:
        raise InputError(f"ax holds {axes.size} axes; this plot draws {rows * cols} ({rows} x {cols})")
    return axes[0].figure, axes.reshape(rows, cols)


#: Offsets (points) tried in turn for a peak's label, right of its dot: above it, stepping up, then below it. The
#: first that overlaps no label already drawn and stays inside the axes is taken.
LABEL_OFFSETS = ((3, 4), (3, 16), (3, 28), (3, 40), (3, -12), (3, -24), (-24, 4), (-24, 16))


def plot_spectra(
    spectra: Mapping[str, tuple[np.ndarray, np.ndarray]],
    title: str,
    thesis_modes: Sequence[float] = (),
    peaks: Mapping[str, Sequence[Peak]] | None = None,
    fmax: float = 1.5,
    ylabel: str = "PSD (rad$^2$/Hz)",
    ax: Any = None,
) -> Figure:
    """Power spectra on a log scale, the thesis's modes as dashed lines and found peaks as dots.

    Each peak's frequency is written beside its dot where it overlaps no other label and stays inside the axes
    (:data:`LABEL_OFFSETS`, measured on the drawn figure): close peaks (0.31 and 0.35 Hz on a 2 Hz axis) and the
    same peak on two curves stay readable.

    Parameters
    ----------
    spectra : mapping of label to (frequencies Hz, PSD)
    title : str
    thesis_modes : sequence of float
        Frequencies (Hz) drawn as grey dashed lines.
    peaks : mapping of label to list of Peak, optional
        Peaks marked on the curve of the same label.
    fmax : float
        Upper frequency shown (Hz).
    ax : matplotlib.axes.Axes, optional
        Axes to draw into (default: a new figure).
    """
    fig, axes = new_axes(ax=ax)
    a = axes[0, 0]
    marks: list[tuple[Peak, Any]] = []
    for label, (f, p) in spectra.items():
        keep = f <= fmax
        (line,) = a.semilogy(f[keep], np.maximum(p[keep], 1e-300), lw=1.2, label=label)
        for pk in (peaks or {}).get(label, ()):
            if not 0 <= pk.frequency <= fmax or not pk.height > 0:
                continue
            a.plot(pk.frequency, pk.height, "o", color=line.get_color(), ms=5)
            marks.append((pk, line.get_color()))
    for i, m in enumerate(thesis_modes):
        a.axvline(m, color="0.5", ls="--", lw=0.8, label="thesis modes" if i == 0 else None)
    a.set_xlabel("frequency (Hz)")
    a.set_ylabel(ylabel)
    a.set_xlim(0, fmax)
    a.grid(True, which="both", alpha=0.3)
    a.legend(fontsize=8)
    a.set_title(title, fontsize=10)
    _label_peaks(a, marks)
    return fig


def _label_peaks(a: Any, marks: Sequence[tuple[Peak, Any]]) -> None:
    """Write each peak's frequency beside its dot, at the first of :data:`LABEL_OFFSETS` that overlaps no label
    drawn before and lies inside the axes (the last offset tried when none does)."""
    renderer = a.figure.canvas.get_renderer()
    inside = a.get_window_extent(renderer)
    taken: list[Any] = []
    for pk, color in sorted(marks, key=lambda m: (m[0].frequency, -m[0].height)):
        for dx, dy in LABEL_OFFSETS:
            text = a.annotate(
                f"{pk.frequency:.2f}",
                (pk.frequency, pk.height),
                textcoords="offset points",
                xytext=(dx, dy),
                fontsize=7,
                color=color,
            )
            box = text.get_window_extent(renderer)
            fits = inside.x0 <= box.x0 and box.x1 <= inside.x1 and inside.y0 <= box.y0 and box.y1 <= inside.y1
            if fits and not any(box.overlaps(other) for other in taken):
                break
            if (dx, dy) != LABEL_OFFSETS[-1]:
                text.remove()
        taken.append(box)


def plot_coherence(
    curves: Mapping[str, tuple[np.ndarray, np.ndarray]],
    title: str,
    marks: Sequence[float] = (),
    fmax: float = 2.5,
    ax: Any = None,
) -> Figure:
    """Coherence spectra (eq. 3.1) on ``[0, 1]``; ``marks`` (Hz) as grey dashed lines; into ``ax`` when given."""
    fig, axes = new_axes(ax=ax)
    a = axes[0, 0]
    for label, (f, c) in curves.items():
        keep = f <= fmax
        a.plot(f[keep], c[keep], lw=1.2, label=label)
    for m in marks:
        a.axvline(m, color="0.5", ls="--", lw=0.8)
    a.set_ylim(0, 1.05)
    a.set_xlim(0, fmax)
    a.set_xlabel("frequency (Hz)")
    a.set_ylabel("coherence")
    a.grid(True, alpha=0.3)
    a.legend(fontsize=8)
    a.set_title(title, fontsize=10)
    return fig


def plot_correlation_tests(tests: Sequence[CorrelationTest], title: str, ax: Any = None) -> Figure:
    """One panel per correlation test with its +-band dashed (figs. 3.11, 5.5); ``ax``: one Axes per test."""
    n = len(tests)
    fig, ax = new_axes(n, 1, (7.0, 1.7 * n + 0.6), ax)
    for a, t in zip(ax[:, 0], tests):
        a.vlines(t.lags, 0, t.values, lw=1.2)
        a.plot(t.lags, t.values, ".", ms=3)
        a.axhline(t.bound, color="r", ls="--", lw=0.8)
        a.axhline(-t.bound, color="r", ls="--", lw=0.8)
        a.axhline(0, color="k", lw=0.5)
        verdict = "pass" if t.passed else "fail"
        a.set_ylabel(f"phi_{t.name}", fontsize=8)
        a.set_title(f"phi_{t.name}: {verdict} ({t.n_outside} lags outside)", fontsize=8)
    ax[-1, 0].set_xlabel("lag (samples)")
    fig.suptitle(title, fontsize=10)
    return fig


def plot_series(
    time: np.ndarray,
    series: Mapping[str, np.ndarray],
    title: str,
    ylabel: str,
    inputs: Mapping[str, np.ndarray] | None = None,
    input_label: str = "input (V, deviation)",
    limits: tuple[float, float] | None = None,
    ax: Any = None,
) -> Figure:
    """Time series on one panel (outputs), and the inputs on a second panel when given.

    ``limits`` (V, deviation) are the actuator limits: drawn dashed on the input panel when they fall
    inside the signal's range, else named in the panel, whose axes always follow the signal (a
    0.15 V control is not drawn flat on a +-10 V scale). ``ax``: one Axes, or two with ``inputs``.
    """
    rows = 2 if inputs else 1
    fig, ax = new_axes(rows, 1, (8.0, 3.0 * rows + 0.5), ax)
    a = ax[0, 0]
    for i, (label, y) in enumerate(series.items()):
        a.plot(time, y, lw=1.2 if i == 0 else 1.0, ls="-" if i == 0 else "--", label=label)
    a.set_ylabel(ylabel)
    a.grid(True, alpha=0.3)
    a.legend(fontsize=8)
    a.set_title(title, fontsize=10)
    if inputs:
        b = ax[1, 0]
        for label, u in inputs.items():
            b.plot(time, u, lw=1.0, label=label)
        if limits is not None:
            draw_limits(b, np.concatenate([np.ravel(u) for u in inputs.values()]), float(limits[0]), float(limits[1]))
        b.set_ylabel(input_label)
        b.grid(True, alpha=0.3)
        b.legend(fontsize=8)
    ax[-1, 0].set_xlabel("time (s)")
    return fig
