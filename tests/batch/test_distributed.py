"""Samples as Dask tasks: seeded per (seed, index), identical however the work is split."""

import numpy as np
import pytest

from trms.batch.distributed import chunk_indices, map_items, map_samples, sample_seed
from trms.errors import ConfigurationError


def _draws(indices, seed):
    return [float(np.random.default_rng(sample_seed(seed, i)).standard_normal()) for i in indices]


def test_sample_seed_is_the_spawned_child_and_independent_of_the_split():
    for i in (0, 3, 17):
        assert (
            sample_seed(5, i).generate_state(4).tolist()
            == np.random.SeedSequence(5).spawn(20)[i].generate_state(4).tolist()
        )
    assert sample_seed(5, 1).generate_state(1) != sample_seed(5, 2).generate_state(1)
    assert sample_seed(5, 1).generate_state(1) != sample_seed(6, 1).generate_state(1)


def test_results_are_identical_with_one_and_two_workers_and_any_chunking():
    one = map_samples(_draws, 11, (4,), chunk_size=11, workers=1, processes=False, progress=False)
    two = map_samples(_draws, 11, (4,), chunk_size=3, workers=2, processes=False, progress=False)
    assert one == two == _draws(range(11), 4)


def test_chunks_cover_every_index_once():
    assert chunk_indices(7, 3) == [[0, 1, 2], [3, 4, 5], [6]]
    assert chunk_indices(0, 3) == []


def test_bad_cluster_arguments_are_refused():
    with pytest.raises(ConfigurationError, match="not both"):
        map_samples(_draws, 2, (0,), workers=1, scheduler="tcp://127.0.0.1:8786")
    with pytest.raises(ConfigurationError, match="tcp://host:8786"):
        map_samples(_draws, 2, (0,), scheduler="localhost")
    with pytest.raises(ValueError, match="workers"):
        map_samples(_draws, 2, (0,), workers=0, processes=False)


def _hover(mass):
    from trms.twin import Twin, load_spec
    from trms.twin.parameters import with_parameters

    return Twin(
        "1dof", 0.2, spec=with_parameters(load_spec(), {"counterweight_mass": mass})
    ).operating_point.inputs.tolist()


def test_a_parameter_sweep_as_tasks_equals_the_serial_sweep():
    masses = [0.06, 0.07, 0.08, 0.09, 0.1]
    swept = map_items(_hover, masses, chunk_size=2, workers=2, processes=False, progress=False)
    assert swept == [_hover(m) for m in masses]
    assert len({tuple(v) for v in swept}) == len(masses)
