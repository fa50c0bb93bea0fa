"""The Record and the operating point: lossless round trips, refusals, reprs, the trim plus a signal."""

import numpy as np
import pytest

from trms.errors import ConfigurationError, InputError
from trms.record import OperatingPoint, Record


def _record(n=20):
    rng = np.random.default_rng(3)
    return Record(
        np.arange(n) * 0.1,
        rng.normal(size=(n, 2)),
        rng.normal(size=(n, 1)),
        ("u1", "u2"),
        ("pitch",),
        {"qpos": rng.normal(size=(n, 4)), "flag": rng.normal(size=n) > 0},
        {"sample_time": 0.1, "seed": 3, "note": "x"},
    )


def test_record_save_load_is_lossless_and_atomic(tmp_path):
    rec = _record()
    path = rec.save(tmp_path / "r.npz")
    back = Record.load(path)
    assert back.equals(rec)
    assert back.extras["flag"].dtype == bool
    assert [p.name for p in tmp_path.iterdir()] == ["r.npz"]  # no temporary left behind


def test_record_csv_has_every_column(tmp_path):
    rec = _record(5)
    path = rec.to_csv(tmp_path / "r.csv")
    lines = path.read_text().splitlines()
    header = lines[0].split(",")
    assert header[:4] == ["time", "u1", "u2", "pitch"]
    assert "qpos[3]" in header and "flag" in header
    assert len(lines) == 6
    assert float(lines[1].split(",")[3]) == rec.outputs[0, 0]  # repr() keeps every bit


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(inputs=np.zeros((3, 1))), "inputs must have shape"),
        (dict(extras={"x": np.zeros(2)}), "must have 4 rows"),
        (dict(metadata={"bad": object()}), r"metadata\['bad'\] = .* allowed in Record metadata"),
        (dict(metadata={"pair": (1, 2)}), r"metadata\['pair'\] = \(1, 2\) is a tuple"),
        (dict(metadata={"nested": {1: "a"}}), r"metadata\['nested'\] has the key 1 \(int\)"),
    ],
)
def test_record_refuses_inconsistent_fields(kwargs, match):
    base = dict(
        time=np.arange(4.0),
        inputs=np.zeros((4, 2)),
        outputs=np.zeros((4, 1)),
        input_names=("u1", "u2"),
        output_names=("y",),
    )
    base.update(kwargs)
    with pytest.raises(InputError, match=match):
        Record(**base)


def test_record_load_refuses_missing_and_foreign_files(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        Record.load(tmp_path / "none.npz")
    np.savez(tmp_path / "other.npz", a=np.zeros(3))
    with pytest.raises(InputError, match="not a trms Record"):
        Record.load(tmp_path / "other.npz")


def test_trim_plus_a_signal_on_one_input():
    from trms.errors import InputError

    op = OperatingPoint(np.array([1.0, -2.0]), np.zeros(2), ("u1", "u2"), ("pitch", "yaw"))
    u = op.with_signal(np.array([0.5, 0.0, -0.5]), "u1")
    np.testing.assert_array_equal(u, [[1.5, -2.0], [1.0, -2.0], [0.5, -2.0]])
    np.testing.assert_array_equal(op.with_signal(np.ones(2), 1), [[1.0, -1.0], [1.0, -1.0]])
    with pytest.raises(InputError, match="unknown input channel 'u3'"):
        op.with_signal(np.ones(2), "u3")
    with pytest.raises(InputError, match="input channel = 2 is outside 0..1"):
        op.with_signal(np.ones(2), 2)


def test_record_reprs_are_compact_and_the_dataframe_has_every_channel():
    n = 5000
    rec = Record(
        np.arange(n) * 0.1,
        np.zeros((n, 2)),
        np.ones((n, 2)),
        ("u1", "u2"),
        ("pitch", "yaw"),
        {"true_angles": np.zeros((n, 2)), "saturated": np.zeros((n, 2), bool)},
        {"sample_time": 0.1, "seed": 3},
    )
    text = repr(rec)
    assert len(text) < 200 and "5000 samples" in text and "pitch" in text
    html = rec._repr_html_()
    assert "<table>" in html and "seed" in html and len(html) < 2000
    df = rec.to_dataframe()
    assert df.shape == (n, 8) and list(df.columns[:4]) == ["u1", "u2", "pitch", "yaw"]
    assert "true_angles[1]" in df.columns and df.index.name == "time (s)"


def test_to_dataframe_without_pandas_says_so_in_one_line(monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "pandas", None)
    rec = Record(np.arange(3.0), np.zeros(3), np.zeros(3), ("u1",), ("pitch",))
    with pytest.raises(ConfigurationError, match="needs pandas"):
        rec.to_dataframe()


@pytest.mark.parametrize("channel", ["inputs", "outputs"])
def test_record_load_refuses_a_channel_that_is_nan_in_every_sample(tmp_path, channel):
    rec = _record()
    getattr(rec, channel)[:, 0] = np.nan
    rec.save(tmp_path / "r.npz")
    name = rec.input_names[0] if channel == "inputs" else rec.output_names[0]
    with pytest.raises(InputError, match=rf"{channel[:-1]} '{name}' is NaN in every sample") as exc:
        Record.load(tmp_path / "r.npz")
    assert "\n" not in str(exc.value)
    getattr(rec, channel)[1:, 0] = 0.5  # one NaN sample is data with a gap, not a channel without data
    rec.save(tmp_path / "r.npz")
    assert np.isnan(getattr(Record.load(tmp_path / "r.npz"), channel)[0, 0])


@pytest.mark.parametrize(
    "name, match",
    [
        ("r.txt", r"Record file '.*r\.txt' must end in \.npz"),
        ("r", r"Record file '.*r' must end in \.npz"),
        ("folder", r"Record file '.*folder' is an existing folder; allowed: a file name ending in \.npz"),
    ],
)
def test_record_save_refuses_a_name_it_would_have_to_change(tmp_path, name, match):
    (tmp_path / "folder").mkdir()
    with pytest.raises(InputError, match=match):
        _record().save(tmp_path / name)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder"]


def test_row_buffer_grows_a_runs_channels_as_stacking_them_would():
    from trms.record import RowBuffer

    rng = np.random.default_rng(0)
    rows = [{"q": rng.normal(size=3), "flag": rng.normal(size=2) > 0, "t": float(k)} for k in range(7)]
    buffer = RowBuffer(7)
    assert buffer.arrays() == {}
    for k, row in enumerate(rows):
        buffer.put(k, row)
    got = buffer.arrays()
    for key in rows[0]:
        stacked = np.stack([np.array(r[key]) for r in rows])
        assert got[key].dtype == stacked.dtype and got[key].tobytes() == stacked.tobytes()
