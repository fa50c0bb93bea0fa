"""Plot functions return a Figure, draw into the caller's axes, and save through one step."""

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from trms.control.loop import closed_loop
from trms.control.lqg import LQGController
from trms.control.plots import plot_closed_loop
from trms.errors import InputError
from trms.experiments.ch67_lqg import design, pitch_plant
from trms.present.figures import plot_coherence, plot_series, plot_spectra, save_figure
from trms.worlds import design_model


def _axes(n):
    fig = Figure()
    FigureCanvasAgg(fig)
    return fig, fig.subplots(n, 1, squeeze=False)[:, 0]


def test_plots_return_a_figure_and_draw_into_given_axes(tmp_path):
    t = np.arange(10.0)
    fig = plot_series(t, {"pitch": np.sin(t)}, "run", "rad", inputs={"u1": np.cos(t)}, limits=(-1.0, 1.0))
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    mine, axes = _axes(2)
    assert plot_series(t, {"pitch": np.sin(t)}, "run", "rad", inputs={"u1": np.cos(t)}, ax=axes) is mine
    assert len(axes[0].lines) == 1 and len(axes[1].lines) == 1
    f = np.linspace(0, 1, 50)
    mine, axes = _axes(1)
    assert plot_spectra({"a": (f, 1 + f)}, "psd", ax=axes[0]) is mine and len(axes[0].lines) == 1
    assert plot_coherence({"a": (f, f)}, "coh", ax=axes[0]) is mine
    path = save_figure(fig, tmp_path / "sub" / "run.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_wrong_number_of_axes_is_refused_in_one_line():
    _, axes = _axes(1)
    with pytest.raises(InputError, match="ax holds 1 axes; this plot draws 2"):
        plot_series(np.arange(3.0), {"y": np.zeros(3)}, "t", "rad", inputs={"u": np.zeros(3)}, ax=axes)


def test_closed_loop_plot_returns_a_figure():
    plant = pitch_plant(trim=1.0)
    rec = closed_loop(plant, LQGController(design(design_model("1dof"), 75.0)), np.full(20, 0.1), seed=0)
    fig = plot_closed_loop(rec, "step", limits=(np.array([-11.0]), np.array([9.0])))
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    mine, axes = _axes(2)
    assert plot_closed_loop(rec, ax=axes) is mine


def test_peak_labels_of_curves_sharing_a_peak_do_not_overlap():
    from trms.identification.spectral import Peak

    f = np.linspace(0.0, 1.5, 301)
    measured = 1e-3 + np.exp(-(((f - 0.34) / 0.01) ** 2))
    model = 1e-3 + 0.9 * np.exp(-(((f - 0.341) / 0.01) ** 2))
    peaks = {"measured": [Peak(0.34, 1.0)], "model": [Peak(0.341, 0.9)]}
    fig = plot_spectra({"measured": (f, measured), "model": (f, model)}, "psd", (), peaks)
    fig.canvas.draw()
    boxes = [t.get_window_extent() for t in fig.axes[0].texts]
    assert len(boxes) == 2 and not boxes[0].overlaps(boxes[1])


def test_close_peaks_on_a_wide_axis_get_labels_that_neither_overlap_nor_leave_the_axes():
    """ident/psd.png: 0.31 and 0.35 Hz on a 2 Hz axis, the higher one at the top of the axes."""
    from trms.identification.spectral import Peak

    f = np.linspace(0.0, 2.0, 401)
    psd = 1e-4 + np.exp(-(((f - 0.31) / 0.008) ** 2)) + 3.0 * np.exp(-(((f - 0.35) / 0.008) ** 2))
    peaks = {"measured": [Peak(0.31, float(np.interp(0.31, f, psd))), Peak(0.35, float(np.interp(0.35, f, psd)))]}
    fig = plot_spectra({"measured": (f, psd), "model": (f, 0.5 * psd)}, "psd", (), peaks, fmax=2.0)
    fig.canvas.draw()
    a = fig.axes[0]
    boxes = [t.get_window_extent() for t in a.texts]
    assert [t.get_text() for t in a.texts] == ["0.31", "0.35"] and not boxes[0].overlaps(boxes[1])
    frame = a.get_window_extent()
    assert all(frame.x0 <= b.x0 and b.x1 <= frame.x1 and frame.y0 <= b.y0 and b.y1 <= frame.y1 for b in boxes)
