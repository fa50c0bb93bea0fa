"""Doing nothing scores poorly and the shipped LQG well on every task (the task table's claim)."""

from trms.experiments.task_baselines import POLICIES, format_table, task_table
from trms.twin.tasks import TASKS


def test_zero_volts_and_holding_the_trim_score_below_half_of_the_lqg_and_random_below_both():
    rows = task_table(episodes=2)
    assert [r.task for r in rows] == list(TASKS)
    for r in rows:
        ret = r.returns
        assert ret["hold trim"] < 0.5 * ret["LQG"], r
        assert ret["zero volts"] < 0.5 * ret["LQG"], r
        assert ret["random"] < 0.5 * ret["LQG"], r
        assert ret["LQG"] > 0.25 * r.steps, r  # the LQG spends a good share of the episode on target
    text = format_table(rows)
    assert all(f"trms/{t}-v0" in text for t in TASKS) and all(p in text for p in POLICIES)
