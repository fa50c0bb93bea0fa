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


def _raw_record(path, **arrays):
    """An .npz in Record's layout written without Record's checks (what a hand-made file may hold)."""
    import json

    rec = _record(6)
    fields = {"time": rec.time, "inputs": rec.inputs, "outputs": rec.outputs}
    fields.update({f"extra_{i}": v for i, v in enumerate(rec.extras.values())})
    meta = dict(rec.metadata)
    meta.update(arrays.pop("metadata", {}))
    fields.update(arrays)
    header = {"input_names": ["u1", "u2"], "output_names": ["pitch"], "extras": list(rec.extras)}
    header.update(metadata=meta, format="trms.Record/1")
    np.savez(path, header=np.array(json.dumps(header)), **fields)
    return path


@pytest.mark.parametrize(
    "arrays, match",
    [
        (dict(inputs=np.ones((6, 2), bool)), r"array 'inputs' holds booleans \(bool\); allowed: real numbers"),
        (dict(inputs=np.ones((6, 2)) + 0.5j), r"array 'inputs' holds complex numbers"),
        (dict(outputs=np.full((6, 1), "1.5")), r"array 'outputs' holds text"),
        (dict(time=np.arange(6) * 0.1 > 0), r"array 'time' holds booleans"),
        (dict(inputs=np.zeros((7, 2))), r"array 'inputs' must have shape \(6, 2\) \(as its time\), declared shape"),
        (dict(metadata={"sample_time": -0.1}), r"sample_time = -0.1 s; allowed: a finite number of seconds > 0"),
        (dict(metadata={"sample_time": float("nan")}), r"sample_time = nan s; allowed"),
        (dict(time=np.arange(6)[::-1] * 0.1), r"time 0.4 s at row 1 does not increase \(previous 0.5 s\)"),
        (dict(time=np.array([0, 0.1, 0.1, 0.2, 0.3, 0.4])), r"time 0.1 s at row 2 does not increase"),
        (dict(time=np.array([0, 0.1, 0.2, 0.3, 0.4, np.inf])), r"time is inf at row 5; allowed: finite times"),
        (dict(time=np.arange(6) * 0.2), r"time steps 0.2 s at row 1 .* sample_time is 0.1 s"),
    ],
)
def test_record_load_refuses_arrays_of_the_wrong_type_shape_or_clock(tmp_path, arrays, match):
    path = _raw_record(tmp_path / "r.npz", **arrays)
    with pytest.raises(InputError, match=match) as exc:
        Record.load(path)
    assert "\n" not in str(exc.value) and str(exc.value).startswith(f"{str(path)!r} is not a trms Record file")


def _with_member(src, dst, name, shape, payload=b""):
    """A copy of the archive ``src`` whose member ``name`` declares ``shape`` (float64) and holds ``payload``."""
    import io
    import zipfile

    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            if item.filename != f"{name}.npy":
                zout.writestr(item.filename, zin.read(item.filename))
        head = np.lib.format.header_data_from_array_1_0(np.zeros(1))
        head["shape"] = shape
        buf = io.BytesIO()
        np.lib.format.write_array_header_1_0(buf, head)
        with zout.open(f"{name}.npy", "w", force_zip64=True) as fh:
            fh.write(buf.getvalue())
            for _ in range(len(payload) and 50):
                fh.write(payload)
    return dst


def test_record_load_checks_the_declared_shapes_and_sizes_before_decompressing(tmp_path, monkeypatch):
    import time

    good = _raw_record(tmp_path / "good.npz")
    claims = _with_member(good, tmp_path / "claims.npz", "inputs", (250_000_000, 2))  # a header claiming 4 GB
    bomb = _with_member(good, tmp_path / "bomb.npz", "inputs", (50 * 2**20 // 8 // 2, 2), bytes(2**20))  # 50 MB
    real_read = np.lib.format.read_array

    def small_only(fp, *args, **kwargs):  # any large array decompressed fails the test
        array = real_read(fp, *args, **kwargs)
        assert array.size < 1000, array.shape
        return array

    monkeypatch.setattr(np.lib.format, "read_array", small_only)
    t0 = time.perf_counter()
    with pytest.raises(InputError, match=r"'inputs' declares shape \(250000000, 2\) of float64 .* but holds 0 bytes"):
        Record.load(claims)
    with pytest.raises(InputError, match=r"'inputs' must have shape \(6, 2\) \(as its time\), declared shape"):
        Record.load(bomb)
    assert time.perf_counter() - t0 < 1.0


def test_record_load_refuses_more_than_the_stated_bytes(tmp_path, monkeypatch):
    import trms.record

    monkeypatch.setattr(trms.record, "MAX_RECORD_BYTES", 100)
    with pytest.raises(InputError, match=r"arrays declare more than 100 bytes \(MAX_RECORD_BYTES\)"):
        Record.load(_raw_record(tmp_path / "r.npz"))


@pytest.mark.parametrize(
    "kind, match",
    [
        ("folder", r"record file '.*x\.npz' is a folder, not a regular file; allowed: a file"),
        ("fifo", r"record file '.*x\.npz' is a FIFO \(named pipe\), not a regular file"),
        ("loop", r"record file '.*x\.npz' cannot be opened: a loop of symbolic links"),
        ("device", r"record file '/dev/zero' is a character device, not a regular file"),
        ("unreadable", r"record file '.*x\.npz' cannot be read: permission denied"),
    ],
)
def test_record_load_names_a_path_that_is_no_readable_file(tmp_path, monkeypatch, kind, match):
    import builtins
    import os

    path = tmp_path / "x.npz"
    if kind == "folder":
        path.mkdir()
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "loop":
        path.symlink_to(path)
    elif kind == "device":
        path = "/dev/zero"
    else:
        _record().save(path)
        real_open = builtins.open

        def denied(file, *args, **kwargs):  # what a user without read permission meets (root reads anything)
            if str(file) == str(path):
                raise PermissionError(13, "Permission denied", str(file))
            return real_open(file, *args, **kwargs)

        monkeypatch.setattr(builtins, "open", denied)
    with pytest.raises(InputError, match=match):
        Record.load(path)
