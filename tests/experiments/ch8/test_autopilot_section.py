"""Chapter 8's autopilot in the report: the scan table, the section, its figures."""

import pytest

from trms.experiments.ch8 import autopilot as c8
from trms.experiments.ch8 import autopilot_margins as cm
from trms.experiments.ch8 import autopilot_section as c8s
from trms.worlds import design_model, make_plant


@pytest.fixture(scope="module")
def linear_runs():
    """The autopilot on the linear model: both controllers, both scenarios."""
    return c8.autopilot_runs(make_plant("linear", "2dof"), design_model("2dof"))


@pytest.fixture(scope="module")
def scan():
    return cm.shipped_margin_scan(0.1)


def test_section_is_complete(linear_runs, tmp_path):
    twin = c8.autopilot_runs(make_plant("twin", "2dof", gusts=True), design_model("2dof"))
    sec = c8s.section_8_autopilot({"linear": linear_runs, "twin": twin}, tmp_path)
    assert sec.tables[0].missing() == []
    assert all(f.path.is_file() for f in sec.figures)


def test_scan_table_marks_the_design(scan, tmp_path):
    t = c8s.table_scan(scan, {})
    marks = [row[-1] for row in t.rows]
    assert marks.count("the design") == 1 and t.rows[marks.index("the design")][0] == "1"
    assert all(row[6] == "not run" and row[-2] == "not run" for row in t.rows)


def test_section_shows_the_design_with_its_runs_and_the_targets_before_the_autopilot(linear_runs, scan, tmp_path):
    runs = {1.0: {scen: linear_runs[("MIMO LQG", scen)] for scen in c8.SCENARIOS}}
    sec = c8s.section_8_autopilot({"linear": linear_runs, "twin": linear_runs}, tmp_path, None, scan, runs)
    t = sec.tables[0]
    assert t.title.startswith("Ch. 8: the MIMO LQG autopilot's design") and sec.tables[1].title.startswith(
        "Ch. 8 future"
    )
    design = next(row for row in t.rows if row[-1] == "the design")
    assert all(cell != "not run" for cell in design[6:8]) and design[-2] in ("met",) or design[-2].startswith("missed")
    assert all(row[6] == "not run" for row in t.rows if row[-1] != "the design")
    assert "per-channel weights" in " ".join(sec.paragraphs) and "pitch step: TR <= 6" in " ".join(sec.paragraphs)


def test_figures_drawn_as_their_job_ends_are_the_ones_the_section_draws(linear_runs, tmp_path):
    both = {"linear": linear_runs, "twin": linear_runs}
    drawn = c8s.autopilot_figures(linear_runs, tmp_path)
    assert len(drawn) == len(c8.SCENARIOS) and all(f.path.is_file() for f in drawn)
    given = c8s.section_8_autopilot(both, tmp_path / "unused", figures=drawn)
    assert given.figures[: len(drawn)] == drawn and not (tmp_path / "unused").exists()
    assert [(f.path, f.caption) for f in c8s.section_8_autopilot(both, tmp_path).figures] == [
        (f.path, f.caption) for f in drawn
    ]
