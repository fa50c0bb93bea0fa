"""One closed loop run once: the 1-DOF case and the autopilot on the linear model, measured and drawn."""

import numpy as np
import pytest

from trms.control.loop import deviation_limits
from trms.errors import InputError
from trms.experiments.ch8_mimo_lqg import measures
from trms.experiments.single_runs import autopilot_loop, pitch_loop, plot_autopilot
from trms.worlds import make_plant


def test_the_pitch_loop_tracks_its_square_wave_and_measures_each_step():
    rec, narrow, wide, status = pitch_loop(make_plant("linear", "1dof"), 125.0, "SAS", 0.2, 40.0, 80.0, 0)
    assert len(rec) == 400 and status == "settled" and len(narrow) == len(wide) >= 2
    assert all(np.isfinite(w.settling_time) for w in wide)
    _, dy = rec.deviations()
    assert abs(dy[-1, 0] - rec.extras["reference"][-1, 0]) < 0.02  # it ends on the command


def test_the_autopilot_measures_are_those_of_its_record_and_an_unknown_scenario_is_refused():
    plant = make_plant("linear", "2dof")
    rec, tracked, m = autopilot_loop(plant, "MIMO LQG", "pitch step", 0)
    assert tracked == 0
    np.testing.assert_equal(m, measures(rec, 0))  # nan where a step never settled, in both
    fig = plot_autopilot(rec, "title", deviation_limits(plant))
    assert [a.get_ylabel() for a in fig.axes] == ["pitch (rad)", "yaw (rad)", "control (V)"]
    with pytest.raises(InputError, match="unknown scenario 'roll'; allowed: "):
        autopilot_loop(plant, "MIMO LQG", "roll", 0)


def test_no_control_of_the_autopilot_figure_runs_under_its_legend_or_limits_line():
    """The 2-DOF run whose u2 climbed under the legend late in the run (the README's autopilot example, linear)."""
    import numpy as np

    from trms.control.loop import deviation_limits
    from trms.experiments.single_runs import autopilot_loop, plot_autopilot
    from trms.worlds import make_plant

    plant = make_plant("linear", "2dof")
    rec = autopilot_loop(plant, "MIMO LQG", "pitch step", 0)[0]
    fig = plot_autopilot(rec, "t", deviation_limits(plant))
    fig.canvas.draw()
    ctrl = fig.axes[-1]
    to_data = ctrl.transData.inverted()
    legend_bottom = to_data.transform(ctrl.get_legend().get_window_extent())[0, 1]
    text_bottom = to_data.transform(ctrl.texts[0].get_window_extent())[0, 1]
    top = float(np.max(rec.extras["control"]))
    assert top < min(legend_bottom, text_bottom) and ctrl.get_ylim()[0] <= float(np.min(rec.extras["control"]))
