"""The report's jobs: every part once, longest first, typed records, workers stopped on failure."""

from pathlib import Path

import numpy as np
import pytest

from trms.errors import InputError
from trms.report import Control, Identification, Render, RobustnessPart, SeedControl, SeedIdentification, Settings
from trms.report import jobs as jb


def test_every_part_runs_once_longest_first(tmp_path):
    # the controller comparison and its amplitude sweep (the full run only), the longest, and the twin's control part
    # first; then the twin's identification parts (its own seed's, then the others': the parent draws chapters 3-5, the
    # most figures, while the rest runs), the linear identification, the twin's control parts at the other seeds, the
    # linear control part, the render (when a folder is given) and the robustness batch's parts (three in the full run,
    # one in the quick)
    def names(settings, render=None):
        return [j.name for j in jb._jobs(settings, render)]

    seeds = Settings().seeds[1:]
    full = [
        "controllers",
        "controller sweep",
        "twin control",
        "twin identification",
        *(f"twin identification, seed {s}" for s in seeds),
        "linear identification",
        *(f"twin control, seed {s}" for s in seeds),
        "linear control",
        "robustness 0",
        "robustness 1",
        "robustness 2",
    ]
    assert names(Settings()) == full and len(seeds) == 4
    quick = [
        "controllers",
        "twin control",
        "twin identification",
        "twin identification, seed 1000",
        "linear identification",
        "twin control, seed 1000",
        "linear control",
    ]
    assert names(Settings(quick=True)) == [*quick, "robustness 0"]
    gif = tmp_path / "csas.gif"
    assert names(Settings(quick=True), gif) == [*quick, "twin render", "robustness 0"]
    runs = {j.name: (j.run, j.args) for j in jb._jobs(Settings(seed=4), gif)}
    assert runs["robustness 2"] == (jb.run_robustness, (Settings(seed=4), 2))
    assert runs["linear identification"] == (jb.run_identification, ("linear", Settings(seed=4)))
    assert runs["twin control"] == (jb.run_control, ("twin", Settings(seed=4)))
    assert runs["controllers"] == (jb.run_controllers, (Settings(seed=4),))
    assert runs["controller sweep"] == (jb.run_sweep, (Settings(seed=4),))
    assert runs["twin render"] == (jb.run_render, (Settings(seed=4), gif))
    assert runs["twin control, seed 1004"] == (jb.run_seed_control, (Settings(seed=4), 1004))
    assert runs["twin identification, seed 4004"] == (jb.run_seed_identification, (Settings(seed=4), 4004))


def test_the_render_replays_the_run_the_control_part_flies():
    # a job of its own, the render flies the rendered case alone; the control part flies it among the others: the
    # same bits, because each case starts from the plant's reset at the run's seed
    settings = Settings(quick=True, seed=3)
    alone = jb._pitch_loops("twin", settings, [jb.RENDERED[0]], [jb.RENDERED[1]])[jb.RENDERED].record
    among = jb._pitch_loops("twin", settings, [1.0, jb.RENDERED[0]], ["SAS", jb.RENDERED[1]])[jb.RENDERED].record
    assert alone is not None and among is not None
    assert np.array_equal(alone.outputs, among.outputs) and np.array_equal(alone.inputs, among.inputs)
    assert np.array_equal(alone.extras["qpos"], among.extras["qpos"])  # what the render draws


def test_the_render_path_is_checked_before_any_job_starts(monkeypatch):
    monkeypatch.setattr(jb, "_jobs", lambda settings, render: pytest.fail("a job list was made"))
    with pytest.raises(InputError, match="must end in .gif"):
        jb.run_jobs(Settings(quick=True), 2, print, render=Path("csas.mp4"))


def test_a_record_of_the_wrong_kind_is_refused():
    part = RobustnessPart({}, None, 0.0)
    assert jb._take({"robustness 0": part}, "robustness 0", RobustnessPart) is part
    with pytest.raises(TypeError, match="job .twin control. returned RobustnessPart, expected Control"):
        jb._take({"twin control": part}, "twin control", Control)
    with pytest.raises(TypeError, match="expected Identification"):
        jb._take({"linear identification": part}, "linear identification", Identification)


def _made(kind):
    """A record of ``kind`` that carries only its worker time (the callbacks' test needs no experiment)."""
    out = object.__new__(kind)
    object.__setattr__(out, "seconds", 0.5)
    return out


def test_the_callbacks_see_work_that_needs_no_job_first_then_every_record_as_it_ends(monkeypatch):
    from trms.experiments.ch8.comparison import ControllerStudy

    kinds = {"identification": Identification, "control": Control, "controllers": ControllerStudy}
    at_seed = {"identification": SeedIdentification, "control": SeedControl}

    def fake(name):
        if name.startswith("robustness"):
            return lambda: RobustnessPart({}, {}, 0.5)
        if name == "twin render":
            return lambda: Render(Path("csas.gif"), 0.5)
        if ", seed " in name:
            return lambda: _made(at_seed[name.split(",")[0].split()[-1]])
        return lambda: _made(kinds[name.split()[-1]])

    gif = Path("csas.gif")
    fakes = [jb._Job(j.name, fake(j.name), ()) for j in jb._jobs(Settings(quick=True), gif)]
    monkeypatch.setattr(jb, "_jobs", lambda settings, render: fakes)
    seen, lines = [], []
    results = jb.run_jobs(
        Settings(quick=True),
        1,
        lines.append,
        on_result=lambda name, record: seen.append((name, record.seconds)),
        meanwhile=lambda: seen.append(("meanwhile", None)),
        render=gif,
    )
    assert seen == [("meanwhile", None)] + [(j.name, 0.5) for j in fakes]
    assert lines == [f"{j.name} done in 0.5 s" for j in fakes]
    assert results.worlds["twin"].control.seconds == 0.5 and results.render == Render(gif, 0.5)
    assert [type(r) for r in (*results.seed_identification, *results.seed_control)] == [SeedIdentification, SeedControl]
