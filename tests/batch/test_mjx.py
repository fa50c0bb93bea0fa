"""The MJX batch (float32, JAX) against the CPU batch (float64, MuJoCo): bounded differences.

Tolerances. float32 carries 7 significant digits; the closed loop integrates 1000 physics steps per
10 s at 1 ms. The encoders turn the two paths' tiny angle difference into a whole count (2 pi / 4096 =
1.53e-3 rad) wherever a true angle lies that close to a rounding boundary; from then on the two
controllers see measurements one count apart and each loop answers its own, so the runs part by a
fraction of a count. Hence:

* until the first measurement differs, the true angles agree within 5e-5 rad (a thirtieth of a count;
  float32 integration alone, measured about 1e-5 rad over 25 s). A missing or wrong physical effect
  (a gust or push 10 % off, another twin's motor lag, a thrust-curve branch) moves them by 1e-3 rad;
* over the run, the measured angles differ by at most one count, and the true angles by less than half
  a count RMS (a loop's answer to one count of measurement error);
* overshoot within 1 percentage point, 5 % settling time within 0.2 s (two samples): what half a count
  on a 0.2 rad step moves them by.
"""

import importlib.util
import multiprocessing

import numpy as np
import pytest

from trms.batch import batch_closed_loop
from trms.batch.mjx import stack_models
from trms.errors import ConfigurationError
from trms.experiments import robustness as rb
from trms.experiments.plants import make_plant
from trms.twin import Push, Twin, load_spec

# JAX starts threads that make a later os.fork in this process unsafe (other tests fork ffmpeg), so
# the MJX run happens in a spawned process and only its Records come back.
needs_mjx = pytest.mark.skipif(
    importlib.util.find_spec("jax") is None or importlib.util.find_spec("mujoco.mjx") is None,
    reason="the MJX backend is the optional extra trms[mjx] (jax / mujoco-mjx not installed)",
)

LOOP = "2-DOF LQG autopilot, pitch square wave"
COUNT = 2 * np.pi / 4096


def _batch(n):
    push = (Push.impulse(12.0, 0.02, 0.1, "pitch"),)
    twins = []
    for i in range(2):
        params, seed = rb.sample_parameters(11, i)
        twins.append(make_plant("twin", "2dof", gusts=True, parameters=params, seed=seed, pushes=push))
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
        assert d_y.max() <= COUNT * (1 + 1e-3)
        assert np.sqrt(np.mean(d_true**2)) < 0.5 * COUNT
        s_gpu, over_gpu, settle_gpu = rb.measure(LOOP, a)
        s_cpu, over_cpu, settle_cpu = rb.measure(LOOP, b)
        assert s_gpu == s_cpu
        assert abs(over_gpu - over_cpu) < 1.0
        assert abs(settle_gpu - settle_cpu) <= 0.2 + 1e-9 or (np.isnan(settle_gpu) and np.isnan(settle_cpu))
    # the twins differ, and MJX sees it
    assert np.abs(gpu.records[0].outputs - gpu.records[1].outputs).max() > 10 * COUNT


def test_mjx_refuses_actuator_delay_by_name():
    spec = load_spec()
    spec.actuators[0].nsample = 16
    spec.actuators[0].delay = 0.01
    with pytest.raises(ConfigurationError, match="actuator delay"):
        stack_models([Twin("2dof", 0.1, spec=spec).model])
