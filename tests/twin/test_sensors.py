"""The encoders: one sample's reading and a record's are the same draws and bits."""

import numpy as np
import pytest

from trms.twin import Encoder


@pytest.mark.parametrize(
    "encoder",
    [Encoder(4096, 0.0), Encoder(4096, 1e-3), Encoder(0, (1e-3, 2e-3)), Encoder(4096, (1e-4, 3e-3)), Encoder(16)],
)
def test_a_samples_reading_is_the_records_bit_for_bit(encoder):
    rng = np.random.default_rng(0)
    angles = rng.uniform(-3.0, 3.0, (5000, 2))
    count = encoder.resolution or 1.0
    angles[:50] = np.round(angles[:50] / count) * count + count / 2  # half a count: rounds half to even
    angles[50:60], angles[60:70], angles[70:80] = 0.0, -0.0, -1e-9  # a zero's sign
    one, many = np.random.default_rng(1), np.random.default_rng(1)
    rows = np.stack([encoder.measure(a, one) for a in angles])
    assert rows.tobytes() == encoder.measure(angles, many).tobytes()


def test_a_non_finite_angle_is_read_as_numpy_reads_it():
    enc = Encoder(4096, 0.0)
    assert np.isnan(enc.measure(np.array([np.nan, 0.1]), np.random.default_rng(0))[0])
