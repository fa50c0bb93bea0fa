"""Shared twin fixtures (one trimmed twin per configuration, built once)."""

import numpy as np
import pytest

from trms.twin import Twin, load_spec
from trms.twin.parameters import with_parameters


@pytest.fixture(scope="session")
def twin_factory():
    cache = {}

    def make(config="2dof", sample_time=0.1, **kwargs):
        key = (config, sample_time, tuple(sorted(kwargs.items())))
        if key not in cache:
            cache[key] = Twin(config, sample_time, **kwargs)
        return cache[key]

    return make


@pytest.fixture(scope="session")
def runaway_spec():
    """A maker of a rig with no transport delay, no full-speed cap and a hundred times the rotor's speed per volt: the
    drives' full 10 V blows the beam up within one interval (hover needs 6 mV more than the hover trim's)."""

    def make():
        spec = with_parameters(load_spec(), {"input_delay": 0.0})
        curve = spec.numeric("main_thrust_curve")
        data = np.asarray(curve.data, float).copy()
        data[0] *= 100.0
        curve.data = np.r_[data[:5], 1e9, data[6] / 100.0]
        return spec

    return make
