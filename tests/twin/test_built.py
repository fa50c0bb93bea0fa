"""The compiled models and trims kept per model in a process."""

import numpy as np

from trms.twin import Twin, load_spec
from trms.twin import built as built_module
from trms.twin.built import built, cache_counts
from trms.twin.model import CONFIGURATIONS
from trms.twin.parameters import read_parameters, with_parameters

ARGS = (CONFIGURATIONS["2dof"], 10.0, 0.002, (0, 1), ("pitch", "yaw"))


def test_a_hit_hands_out_copies_that_the_caller_may_change():
    a, a_lin, a_trim = built(load_spec(), *ARGS)
    a.actuator_gear[0, 0] = 99.0
    a_lin.opt.timestep = 1.0
    a_trim.qpos[:] = 7.0
    hits = cache_counts()["hits"]
    b, b_lin, b_trim = built(load_spec(), *ARGS)
    assert cache_counts()["hits"] == hits + 1
    assert b.actuator_gear[0, 0] != 99.0 and b_lin.opt.timestep == 0.002 and not np.all(b_trim.qpos == 7.0)


def test_a_changed_model_misses_even_beyond_the_files_six_digits():
    built(load_spec(), *ARGS)
    misses = cache_counts()["misses"]
    value = read_parameters(load_spec(), ["main_motor_lag"])["main_motor_lag"] + 1e-8
    lag = with_parameters(load_spec(), {"main_motor_lag": value})  # the same MJCF text, another model
    assert lag.to_xml() == load_spec().to_xml()
    model, _, _ = built(lag, *ARGS)
    assert cache_counts()["misses"] == misses + 1
    assert model.actuator_dynprm[model.actuator("main_rotor").id, 0] == value
    other_step, _, _ = built(load_spec(), ARGS[0], ARGS[1], 0.001, *ARGS[3:])
    assert other_step.opt.timestep == 0.001 and cache_counts()["misses"] == misses + 2


def test_a_twin_from_the_cache_runs_bit_for_bit_as_one_built_afresh():
    u = np.tile(Twin("2dof", 0.1).operating_point.inputs, (150, 1))
    u[20:60, 0] += 0.3
    cached = Twin("2dof", 0.1, seed=5).run(u)
    built_module._CACHE.clear()
    fresh = Twin("2dof", 0.1, seed=5).run(u)
    np.testing.assert_array_equal(cached.outputs, fresh.outputs)
    np.testing.assert_array_equal(cached.extras["qpos"], fresh.extras["qpos"])
