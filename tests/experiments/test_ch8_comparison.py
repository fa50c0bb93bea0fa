"""The ch. 8 controller study: its tables in order, the responses overlaid in a figure, refusals in one line."""

import pytest
from PIL import Image

from trms.errors import InputError
from trms.experiments.ch8_comparison import (
    ControllerStudy,
    controller_study,
    plot_responses,
    study_figures,
    study_tables,
)
from trms.experiments.ch8_controllers import compare_controllers
from trms.experiments.ch8_designs import CONTROLLERS


@pytest.fixture(scope="module")
def twin_comparison():
    return compare_controllers(seeds=(0,), cases=["twin, moving air"], push=False)


def test_the_figure_overlays_every_controller_on_the_reference(twin_comparison, tmp_path):
    fig = plot_responses(twin_comparison)
    pitch, command = fig.axes[:2]
    assert [line.get_label() for line in pitch.get_lines()] == [
        "reference",
        "reference through the prefilter",
        *CONTROLLERS,
    ]
    assert [line.get_label() for line in command.get_lines()][: len(CONTROLLERS)] == list(CONTROLLERS)
    record = twin_comparison.records[("LQG", "twin, moving air")]
    assert (pitch.get_lines()[2].get_ydata() == record.deviations()[1][:, 0]).all()
    styles = {line.get_label(): (line.get_color(), line.get_linestyle()) for line in pitch.get_lines()}
    assert len({styles[n] for n in CONTROLLERS}) == len(CONTROLLERS)  # every controller told apart
    assert all(
        (line.get_color(), line.get_linestyle()) == styles[line.get_label()]
        for line in command.get_lines()[: len(CONTROLLERS)]
    )
    (ref,) = study_figures(ControllerStudy(twin_comparison, None, None), tmp_path)
    assert Image.open(ref.path).size[0] > 400 and "moving air" in ref.caption
    with pytest.raises(InputError, match="case 'linear model' was not flown; flown: 'twin, moving air'"):
        plot_responses(twin_comparison, "linear model")


def test_the_tables_follow_the_parts_that_ran(twin_comparison):
    tables = study_tables(ControllerStudy(twin_comparison, None, None))
    assert list(tables) == ["comparison", "designs"]
    rows = tables["comparison"].rows
    assert [r[0] for r in rows] == list(CONTROLLERS) and {r[1] for r in rows} == {"twin, moving air"}
    assert {(r[11], r[12]) for r in rows} == {("not flown", "not flown")}  # no push was flown


def test_bad_counts_are_one_line():
    with pytest.raises(InputError, match="samples = -1 is outside the allowed range"):
        controller_study(seeds=(0,), samples=-1, mimo_seeds=())
    with pytest.raises(InputError, match="MIMO seed must be a non-negative integer, got -3"):
        controller_study(seeds=(0,), samples=0, mimo_seeds=(-3,))
    with pytest.raises(InputError, match="not a string"):
        controller_study(seeds="0", samples=0, mimo_seeds=())
