"""The ch. 3.4 MIMO procedure on a 2x2 linear plant whose u2 -> y1 channel is absent."""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.linalg

from trms.errors import InputError
from trms.identification.data import detrend
from trms.identification.mimo import identify_mimo
from trms.plant import LinearPlant, simulate
from trms.record import OperatingPoint, Record
from trms.signals import random_binary

TS = 0.1
TRIM_U = np.array([3.0, 1.5])
TRIM_Y = np.array([-0.2, 0.1])
# u1 -> y1 resonant (0.34 Hz-like), u1 -> y2 and u2 -> y2 slow; u2 -> y1 absent.
DEN11 = [1.0, -1.8, 0.9]
DEN2 = [1.0, -1.6, 0.68]
NUM = {("u1", "y1"): [0.02, 0.01], ("u1", "y2"): [0.01, 0.008], ("u2", "y2"): [0.03, 0.01]}
DEN = {("u1", "y1"): DEN11, ("u1", "y2"): DEN2, ("u2", "y2"): DEN2}


def plant_ss() -> control.StateSpace:
    """Block-diagonal realisation of the three SISO channels (MIMO tf -> ss needs slycot)."""
    parts = [(k, control.ss(control.tf(NUM[k], DEN[k], TS))) for k in NUM]
    a = scipy.linalg.block_diag(*[np.asarray(p.A) for _, p in parts])
    b = np.zeros((a.shape[0], 2))
    c = np.zeros((2, a.shape[0]))
    row = 0
    for (i, o), p in parts:
        n = p.nstates
        b[row : row + n, int(i[1]) - 1] = np.asarray(p.B)[:, 0]
        c[int(o[1]) - 1, row : row + n] = np.asarray(p.C)[0]
        row += n
    return control.ss(a, b, c, np.zeros((2, 2)), TS)


@pytest.fixture(scope="module")
def experiments():
    plant = LinearPlant(
        plant_ss(),
        OperatingPoint(TRIM_U, TRIM_Y, ("u1", "u2"), ("y1", "y2")),
        noise_std=0.002,
    )
    # a 2 Hz PRBS on one input, the other held at its trim (ch. 3.4.1): 120 s at 10 Hz
    excite = random_binary(120.0, TS, 2.0, 0.5, seed=1)
    u_a = np.column_stack([TRIM_U[0] + excite, np.full(excite.size, TRIM_U[1])])
    u_b = np.column_stack([np.full(excite.size, TRIM_U[0]), TRIM_U[1] + random_binary(120.0, TS, 2.0, 0.5, seed=2)])
    return simulate(plant, u_a, seed=3), simulate(plant, u_b, seed=4)


def test_channels_and_the_uncoupled_one(experiments):
    result = identify_mimo(experiments, 2, 2, 2, 1)
    assert set(result.channels) == {("u1", "y1"), ("u1", "y2"), ("u2", "y1"), ("u2", "y2")}
    assert result.uncoupled == [("u2", "y1")]
    assert result.channels[("u2", "y1")].mean_coherence < 0.2
    for key in [("u1", "y1"), ("u1", "y2"), ("u2", "y2")]:
        assert result.channels[key].mean_coherence > 0.9
    with pytest.raises(InputError, match=r"channel u2 -> y1 is uncoupled \(mean coherence 0\.\d+ < 0\.5"):
        result.model("u2", "y1")


@pytest.mark.parametrize(
    "channel, den",
    [(("u1", "y1"), DEN11), (("u1", "y2"), DEN2), (("u2", "y2"), DEN2)],
)
def test_models_of_coupled_channels_recover_the_poles_and_gain(experiments, channel, den):
    result = identify_mimo(experiments, 2, 2, 2, 1)
    model = result.model(*channel)
    assert (model.input_name, model.output_name) == channel
    # white measurement noise is the ARMAX structure with C = A, so orders (2, 2, 2) are exact:
    # poles within 0.01, DC gain within 3 % (1200 samples, noise 0.002 rad)
    np.testing.assert_allclose(np.sort_complex(model.poles()), np.sort_complex(np.roots(den)), atol=0.01)
    true_gain = np.sum(NUM[channel]) / np.sum(den)
    assert model.dc_gain() == pytest.approx(true_gain, rel=0.03)


def test_bad_experiments_are_refused(experiments):
    rec_a, rec_b = experiments
    with pytest.raises(InputError, match=r"input u1 is excited in more than one experiment"):
        identify_mimo([rec_a, rec_a])
    with pytest.raises(InputError, match=r"at least one experiment"):
        identify_mimo([])
    with pytest.raises(InputError, match=r"threshold = 1\.5 is outside"):
        identify_mimo([rec_a], threshold=1.5)
    plant = LinearPlant(plant_ss(), OperatingPoint(TRIM_U, TRIM_Y, ("u1", "u2"), ("y1", "y2")))
    both = simulate(plant, TRIM_U + np.column_stack([random_binary(20.0, TS, 2.0, 0.5, seed=1)] * 2), seed=0)
    with pytest.raises(InputError, match=r"exactly one input must be excited .* varying: u1, u2"):
        identify_mimo([both])


def test_a_record_without_an_operating_point_is_refused_and_a_detrended_one_identified(experiments):
    """The same check as the SISO path: absolute values would give wrong gains silently."""
    rec_a, _ = experiments
    bare = Record(rec_a.time, rec_a.inputs, rec_a.outputs, rec_a.input_names, rec_a.output_names)
    with pytest.raises(InputError, match="the record has no operating point"):
        identify_mimo([bare])
    result = identify_mimo([detrend(bare)], 2, 2, 2, 1)
    assert result.channels[("u1", "y1")].coupled
