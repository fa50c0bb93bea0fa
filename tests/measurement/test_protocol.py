"""The thesis's protocols run on twins: repeats side by side equal the runs one at a time."""

import numpy as np

from trms.measurement.protocol import Protocol, protocol_records, repeated_records
from trms.twin.model import load_spec


def test_repeated_records_equal_the_runs_one_at_a_time():
    """Verification runs every seed's repeats side by side: each run is the same bits as when run alone."""
    protocol = Protocol("2dof", "u2", 2.0, 10.0, 0.05)
    together = repeated_records(load_spec(), protocol, seeds=(7, 1007, 8))
    for record, seed in zip(together, (7, 1007, 8)):
        alone = protocol_records([load_spec()], protocol, seed=seed)[0]
        assert record.metadata["seed"] == seed
        assert np.array_equal(record.outputs, alone.outputs) and np.array_equal(record.inputs, alone.inputs)
    assert not np.array_equal(together[0].outputs, together[2].outputs)
