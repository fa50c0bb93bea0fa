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
    """A maker of a rig with no transport delay and no full-speed cap: a 1000 V input blows the beam up within one
    interval."""

    def make():
        spec = with_parameters(load_spec(), {"input_delay": 0.0})
        curve = spec.numeric("main_thrust_curve")
        curve.data = np.r_[np.asarray(curve.data)[:5], 1e9, np.asarray(curve.data)[6]]
        return spec

    return make
