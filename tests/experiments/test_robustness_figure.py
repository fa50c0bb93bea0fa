"""The robustness study's histograms: a Figure per loop, drawn into ``ax=`` when given, no pyplot state."""

import math

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from trms.errors import InputError
from trms.experiments.robustness import Sample
from trms.experiments.robustness_study import BINS, plot_histograms


def _samples() -> list[Sample]:
    rng = np.random.default_rng(0)
    ok = [Sample({}, "settled", float(o), float(s)) for o, s in zip(rng.uniform(0, 20, 30), rng.uniform(5, 15, 30))]
    return ok + [Sample({}, "diverged", math.nan, math.nan), Sample({}, "settled", 5.0, math.inf)]


def test_histograms_count_the_settled_samples():
    import matplotlib.pyplot as plt

    before = plt.get_fignums()
    samples = _samples()
    fig = plot_histograms("SAS", samples)
    assert isinstance(fig, Figure) and plt.get_fignums() == before
    overshoot, settling = fig.axes
    assert sum(p.get_height() for p in overshoot.patches) == 31  # every settled sample
    assert sum(p.get_height() for p in settling.patches) == 30  # the infinite settling time is left out
    assert len(overshoot.patches) == BINS
    assert fig._suptitle.get_text() == "SAS: 31/32 settled"


def test_histograms_draw_into_the_callers_axes():
    mine = Figure()
    FigureCanvasAgg(mine)
    axes = mine.subplots(1, 2)
    assert plot_histograms("SAS", _samples(), ax=axes) is mine
    with pytest.raises(InputError, match="this plot draws 2"):
        plot_histograms("SAS", _samples(), ax=axes[:1])
