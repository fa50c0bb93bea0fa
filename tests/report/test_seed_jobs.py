"""The twin at the run's other seeds: the cases its cells read, the same bits as the full runs, nothing else."""

import pytest

from trms.errors import InputError
from trms.experiments import ch67_lqg as runs67
from trms.reference import TABLE_6_1
from trms.report import Settings
from trms.report import seed_jobs as sj
from trms.worlds import design_model, make_plant


def test_the_seeds_cases_are_table_6_1s_and_those_the_findings_compare():
    cases = sj.seed_cases(Settings().weights)
    assert {(r, c) for r, c in TABLE_6_1} <= {(r, c) for r, cs in cases.items() for c in cs}
    for r in (75.0, 100.0, 125.0):
        assert {"SAS", "CSAS LPF 0.1 Hz", "CSAS LPF 0.2 Hz", "CSAS LPF 0.3 Hz", "CSAS BSF 0.34 Hz"} <= set(cases[r])
    assert set(cases[1.0]) == {c for r, c in TABLE_6_1 if r == 1.0}  # the rig ran R = 1 as SAS only


def test_a_seeds_control_runs_are_the_full_runs_bits_without_their_records():
    settings = Settings(quick=True)
    seed = settings.seeds[1]
    got = sj.run_seed_control(settings, seed)
    assert got.seed == seed and all(c.record is None for c in got.lqg.values())
    assert set(got.lqg) == {(r, c) for r, cs in sj.seed_cases(settings.weights).items() for c in cs}
    full = runs67.lqg_cases(make_plant("twin", "1dof", seed=seed), design_model("1dof"), [75.0], ["SAS"], seed=seed)
    assert repr(got.lqg[(75.0, "SAS")].summary) == repr(full[(75.0, "SAS")].summary)  # nan included
    assert set(got.push) == {75.0, 100.0, 125.0} and all(p.record is None for p in got.push.values())
    assert sorted(got.amplitudes) == [0.02, 0.05]


def test_a_seeds_identification_runs_only_what_its_cells_read():
    settings = Settings(quick=True)
    got = sj.run_seed_identification(settings, settings.seeds[1])
    assert got.ch3_1dof.fits == {} and got.ch3_2dof.fits == {} and all(n.poly is None for n in got.ch5)
    # Table 5.1 at its 20 NARX seeds in a quick run too, 10 a job: cheap, and its verdict needs many
    assert len(got.ch5) == settings.narx_per_job == 10
    assert "ZV" not in {name for name, _ in got.ch4_1dof.attenuation}


@pytest.mark.parametrize("seed", [0, 5, 2000])
def test_only_the_runs_other_seeds_are_accepted(seed):
    with pytest.raises(InputError, match=rf"seed = {seed} is not one of the run's other seeds \(1000,\)"):
        sj.run_seed_control(Settings(quick=True), seed)
