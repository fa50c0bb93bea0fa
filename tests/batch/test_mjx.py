"""The MJX batch (float32, JAX) against the CPU batch (float64, MuJoCo): bounded differences; the
transport delay's schedule against MuJoCo's own delay lines, physics step by physics step.

Tolerances. float32 carries 7 significant digits; the closed loop integrates 1000 physics steps per
10 s at 1 ms. The encoders turn the two paths' tiny angle difference into a whole count (2 pi / 4096 =
1.53e-3 rad) wherever a true angle lies that close to a rounding boundary; from then on the two
controllers see measurements one count apart and each loop answers its own, so the runs part by a
fraction of a count. Hence:

* until the first measurement differs, the true angles agree within 5e-5 rad (a thirtieth of a count;
  float32 integration alone, measured about 1e-5 rad over 25 s). A missing or wrong physical effect
  (a gust or push 10 % off, another twin's motor lag, a thrust-curve branch) moves them by 1e-3 rad;
* until then the rotor thrusts (the motor lags' activations, about 1 N) agree within 1e-4 N (float32:
  about 1e-5 N measured). The rotors' transport delay must switch to a new control at the physics
  step where MuJoCo's does: one step early or late moves a thrust by the control's change times
  (1 ms / motor lag), 2e-3 N and 1e-4 to 4e-4 rad of pitch in this run (measured);
* over the run, the measured angles differ by at most one count, and the true angles by less than half
  a count RMS (a loop's answer to one count of measurement error);
* overshoot within 1 percentage point, 5 % settling time within 0.2 s (two samples): what half a count
  on a 0.2 rad step moves them by.
"""

import importlib.util
import multiprocessing

import mujoco
import numpy as np
import pytest

from trms.batch import batch_closed_loop
from trms.batch.mjx import MJX_TIMESTEP, delay_schedule, mjx_spec, without_delay
from trms.errors import ConfigurationError
from trms.experiments import robustness as rb
from trms.twin import Push, Twin, load_spec
from trms.worlds import make_plant

# JAX starts threads that make a later os.fork in this process unsafe (other tests fork ffmpeg), so
# the MJX run happens in a spawned process and only its Records come back.
needs_mjx = pytest.mark.skipif(
    importlib.util.find_spec("jax") is None or importlib.util.find_spec("mujoco.mjx") is None,
    reason="the MJX backend is the optional extra trms[mjx] (jax / mujoco-mjx not installed)",
)

LOOP = "2-DOF LQG autopilot, pitch step"
COUNT = 2 * np.pi / 4096


def _batch(n):
    push = (Push.impulse(12.0, 0.02, 0.1, "pitch"),)
    twins = []
    for i in range(2):
        params, seed = rb.sample_parameters(11, i)
        twins.append(make_plant("twin", "2dof", gusts=True, parameters=params, seed=seed, pushes=push, spec=mjx_spec()))
    setups = [rb.loop_setup(LOOP, t) for t in twins]
    return twins, [s[0] for s in setups], setups[0][1][:n]


def _mjx_run(n):
    from trms.batch.mjx import mjx_closed_loop

    return mjx_closed_loop(*_batch(n))


@needs_mjx
def test_mjx_closed_loop_stays_within_float32_bounds_of_the_cpu_batch():
    n = 250  # 25 s at 0.1 s: the first step of the square wave, a push at 12 s, gusts and noise throughout
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        gpu = pool.apply(_mjx_run, (n,))
    cpu = batch_closed_loop(*_batch(n), threads=1)
    assert all(e is None for e in gpu.errors + cpu.errors)
    for a, b in zip(gpu.records, cpu.records):
        assert a.outputs.shape == b.outputs.shape and a.metadata["physics"] == "mjx float32"
        d_true = np.abs(a.extras["true_angles"] - b.extras["true_angles"])
        d_y = np.abs(a.outputs - b.outputs)
        flips = np.flatnonzero(d_y.max(axis=1) > 0.5 * COUNT)
        before = flips[0] if flips.size else len(d_y)
        assert d_true[:before].max() < 5e-5
        assert np.abs(a.extras["rotor_thrust"] - b.extras["rotor_thrust"])[:before].max() < 1e-4
        assert d_y.max() <= COUNT * (1 + 1e-3)
        assert np.sqrt(np.mean(d_true**2)) < 0.5 * COUNT
        s_gpu, over_gpu, settle_gpu = rb.measure(LOOP, a)
        s_cpu, over_cpu, settle_cpu = rb.measure(LOOP, b)
        assert s_gpu == s_cpu
        assert abs(over_gpu - over_cpu) < 1.0
        assert abs(settle_gpu - settle_cpu) <= 0.2 + 1e-9 or (np.isnan(settle_gpu) and np.isnan(settle_cpu))
    # the twins differ, and MJX sees it
    assert np.abs(gpu.records[0].outputs - gpu.records[1].outputs).max() > 10 * COUNT


def _delayed_reads(twin, n):
    """Run ``twin`` from the trim with control k (every actuator) held over interval k and its delay lines at
    -1; return, per physics step and actuator, the control MuJoCo's delay makes the actuator read."""
    m, d = twin.model, twin.data
    twin.reset()
    nsub = int(round(twin.sample_time / m.opt.timestep))
    for a in np.flatnonzero(m.actuator_history[:, 0]):
        mujoco.mj_initCtrlHistory(m, d, a, None, np.full((int(m.actuator_history[a, 0]), 1), -1.0))
    out, res = np.empty((n, nsub, m.nu)), np.zeros((1, 1))
    for k in range(n):
        d.ctrl[:] = k
        for j in range(nsub):
            out[k, j] = [mujoco.mj_readCtrl(m, d, a, d.time, res, -1).ravel()[0] for a in range(m.nu)]
            mujoco.mj_step(m, d)
    return out


@pytest.mark.parametrize("delay, sample_time", [(None, 0.1), (0.2537, 0.05), (0.0, 0.1)])
def test_delay_schedule_switches_at_the_physics_step_where_the_cpu_twin_does(delay, sample_time):
    # The shipped delay is a whole number of physics steps: MuJoCo's float64 time stamps then put the
    # switch at one step or the next from interval to interval, and the schedule must follow them.
    spec = load_spec()
    if delay is not None:
        spec.numeric("input_delay").data = [delay]
    twin = Twin("2dof", sample_time, spec=spec)
    n = 40
    reads = _delayed_reads(twin, n)
    lag, switch = delay_schedule(twin.model, n, reads.shape[1], 0.0)
    k = np.arange(n)[:, None, None]
    j = np.arange(reads.shape[1])[None, :, None]
    predicted = np.maximum(k - lag[:, None, :] - (j < switch[:, None, :]), -1)
    np.testing.assert_array_equal(predicted, reads)
    commands = [twin.model.actuator(a).id for a in ("main_rotor", "tail_rotor", "main_spin", "tail_spin")]
    assert (lag.max() > 0) == (twin.model.actuator_delay[commands] > 0).all() == (delay != 0.0)
    assert not lag[:, twin._wash].any()  # the air acts at once: the turbulence actuators are not delayed


def test_mjx_refuses_interpolated_delay_by_name():
    spec = mjx_spec()
    spec.actuators[0].interp = 1
    with pytest.raises(ConfigurationError, match="zero-order-hold actuator delay only"):
        without_delay(Twin("2dof", 0.1, spec=spec).model)


def test_mjx_refuses_the_discrete_integrator_and_its_spec_is_the_same_model_at_a_step_mjx_steps():
    with pytest.raises(ConfigurationError, match="integrator is discrete, which MJX does not step"):
        without_delay(Twin("2dof", 0.1).model)
    shipped, mjx = Twin("2dof", 0.1).model, Twin("2dof", 0.1, spec=mjx_spec()).model
    assert mjx.opt.timestep == MJX_TIMESTEP and mjx.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    assert np.array_equal(mjx.body_mass, shipped.body_mass) and np.array_equal(mjx.jnt_stiffness, shipped.jnt_stiffness)
    # the transport delay is the same time, its history sized for the finer step
    assert np.array_equal(mjx.actuator_delay, shipped.actuator_delay)
    assert mjx.actuator_history[:, 0].max() > shipped.actuator_history[:, 0].max()


@needs_mjx
def test_mjx_refuses_a_controller_without_a_stacked_matrix_form():
    from trms.batch.mjx import mjx_closed_loop
    from trms.control.pid import PIDController
    from trms.control.pid_tuning import tune_pid
    from trms.worlds import design_model

    twin = make_plant("twin", "1dof", 0.2, spec=mjx_spec())
    pid = PIDController(tune_pid(design_model("1dof")), 0.2, (-10.0, 10.0))
    with pytest.raises(ConfigurationError, match="runs LQG controllers"):
        mjx_closed_loop([twin], [pid], np.zeros(10))
