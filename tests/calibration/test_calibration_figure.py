"""The calibration's target figure is a plot function like the others: it returns a Figure and draws into ``ax=``."""

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from trms.calibration import Targets
from trms.calibration.checks import Check
from trms.calibration.report import plot_targets
from trms.calibration.verify import Verification
from trms.errors import InputError
from trms.identification import PolynomialModel
from trms.present.figures import save_figure
from trms.reference import eq_3_11


def _verification(targets: Targets) -> Verification:
    """Flat spectra on every target channel, and eq. (3.11) as the identified model; the first peak met."""
    f = np.linspace(0.0, 2.5, 129)
    spectra = {(t.config, t.channel): (f, np.ones_like(f), np.ones_like(f)) for t in targets.peaks}
    first = targets.peaks[0]
    check = Check(first.name, first.frequency_hz, first.frequency_hz, f"+-{first.tolerance_hz:g} Hz", True)
    ref = eq_3_11()
    model = PolynomialModel(np.ravel(ref.den[0][0]), np.r_[0.0, np.ravel(ref.num[0][0])], [1.0], float(ref.dt))
    return Verification([check], spectra=spectra, model=model)


def test_plot_targets_returns_a_figure_without_touching_pyplot(tmp_path):
    import matplotlib.pyplot as plt

    targets = Targets.thesis()
    before = plt.get_fignums()
    fig = plot_targets(_verification(targets), targets)
    assert isinstance(fig, Figure) and plt.get_fignums() == before
    channels = len({(t.config, t.channel) for t in targets.peaks})
    drawn = [a for a in fig.axes if a.axison]
    assert len(drawn) == channels + 2  # a PSD per channel, then magnitude and phase
    # The met target is shaded green, the others red; eq. (3.11) is drawn twice (target and model).
    colours = {tuple(np.round(p.get_facecolor()[:3], 2)) for p in drawn[0].patches}
    assert (0.0, 0.5, 0.0) in colours
    assert len(drawn[channels].get_lines()) == 2
    assert save_figure(fig, tmp_path / "calibration.png", dpi=110).stat().st_size > 10_000


def test_plot_targets_draws_into_the_callers_axes():
    targets = Targets.thesis()
    panels = len({(t.config, t.channel) for t in targets.peaks}) + 2
    mine = Figure()
    FigureCanvasAgg(mine)
    axes = mine.subplots(1, panels)
    assert plot_targets(_verification(targets), targets, ax=axes) is mine
    assert all(a.has_data() for a in axes)
    with pytest.raises(InputError, match=f"this plot draws {panels}"):
        plot_targets(_verification(targets), targets, ax=axes[:-1])
