"""Shared twin fixtures (one trimmed twin per configuration, built once)."""

import pytest

from trms.twin import Twin


@pytest.fixture(scope="session")
def twin_factory():
    cache = {}

    def make(config="2dof", sample_time=0.1, **kwargs):
        key = (config, sample_time, tuple(sorted(kwargs.items())))
        if key not in cache:
            cache[key] = Twin(config, sample_time, **kwargs)
        return cache[key]

    return make
