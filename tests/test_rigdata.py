"""A rig's CSV export in: units, checks, the operating point, and one clear line per bad file."""

import csv

import numpy as np
import pytest

from trms.errors import ConfigurationError, InputError
from trms.identification import armax, detrend, siso_data
from trms.record import Record
from trms.rigchecks import beyond_end_stops
from trms.rigdata import record_from_csv


def _write(path, header, rows):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)
    return path


def test_a_rig_export_reads_in_radians_with_the_hover_operating_point(rig_csv):
    path, t, u, pitch_deg = rig_csv
    rec = record_from_csv(
        path,
        time="Time [s]",
        inputs="Vmain",
        outputs="Pitch_deg",
        units="deg",
        hover_segment=(0.0, 9.95),
        input_names=["u1"],
        output_names=["pitch"],
        config="1dof",
    )
    assert rec.input_names == ("u1",) and rec.output_names == ("pitch",) and len(rec) == t.size
    np.testing.assert_allclose(rec.outputs[:, 0], np.radians(pitch_deg), rtol=0, atol=1e-7)
    assert rec.sample_time == pytest.approx(0.05) and rec.metadata["config"] == "1dof"
    op = rec.operating_point
    np.testing.assert_allclose(op.inputs, [2.0], rtol=1e-6)
    np.testing.assert_allclose(op.outputs, [np.radians(1.5)], rtol=1e-6)
    assert rec.metadata["operating_point_source"] == "mean of hover segment [0, 9.95) s"
    given = record_from_csv(
        path, time="Time [s]", inputs="Vmain", outputs="Pitch_deg", units="deg", operating_point=([2.0], [1.5])
    )
    np.testing.assert_allclose(given.operating_point.outputs, [np.radians(1.5)])
    assert given.metadata["operating_point_source"] == "given"


def test_identification_refuses_a_record_without_operating_point_and_accepts_it_detrended(rig_csv):
    path = rig_csv[0]
    rec = record_from_csv(path, time="Time [s]", inputs="Vmain", outputs="Pitch_deg", units="deg")
    assert "operating_point" not in rec.metadata
    with pytest.raises(InputError, match="the record has no operating point"):
        siso_data(rec)
    d = siso_data(detrend(rec))
    assert abs(d.y.mean()) < 1e-12 and abs(d.u.mean()) < 1e-12
    model = armax(detrend(rec), na=2, nb=2, nc=1, nk=1)
    assert model.input_name == "Vmain" and model.output_name == "Pitch_deg"


@pytest.mark.parametrize("kind", ["constant", "linear"])
def test_detrend_removes_offsets_and_ramps_so_a_gain_is_not_spoilt(kind):
    """A first-order system with gain 7.5: 2 V of input offset (and a ramp) removed, the gain comes back."""
    rng = np.random.default_rng(0)
    u = rng.standard_normal(3000)
    y = np.zeros_like(u)
    for k in range(1, u.size):
        y[k] = 0.9 * y[k - 1] + 0.75 * u[k - 1]
    ramp = np.linspace(0, 1, u.size) if kind == "linear" else 0.0
    du, dy = detrend(u + 2.0 + ramp, kind), detrend(y + 0.4 + ramp, kind)
    coef, *_ = np.linalg.lstsq(np.column_stack([dy[:-1], du[:-1]]), dy[1:], rcond=None)
    assert coef[1] / (1 - coef[0]) == pytest.approx(7.5, rel=1e-2)
    np.testing.assert_allclose(detrend(np.array([1.0, 2.0, 3.0]), "linear"), 0.0, atol=1e-12)
    with pytest.raises(InputError, match="unknown detrend kind 'quadratic'"):
        detrend(u, "quadratic")


@pytest.mark.parametrize(
    "rows, kwargs, message",
    [
        ([["0", "1", "2"], ["0.1", "1", "2"], ["0.2", "1", "2"]], {"outputs": "yaw"}, "column 'yaw' is missing"),
        ([["0", "1", "2"], ["0.1", "x", "2"], ["0.2", "1", "2"]], {}, "row 3, column 'V': 'x' is not a number"),
        (
            [["0", "1", "2"], ["0.1", "1", "nan"], ["0.2", "1", "2"]],
            {},
            "row 3, column 'p': 'nan' is not a finite number",
        ),
        (
            [["0", "1", "2"], ["0.2", "1", "2"], ["0.1", "1", "2"]],
            {},
            "row 4, column 't': time 0.1 s does not increase",
        ),
        (
            [["0", "1", "2"], ["0.1", "1", "2"], ["0.2", "1", "2"], ["0.35", "1", "2"]],
            {},
            "row 5, column 't': sample interval 0.15 s differs",
        ),
        (
            [["0", "1", "2"], ["0.1", "1", "2"], ["0.2", "1", "2"]],
            {"units": None},
            "units of the angle columns not given",
        ),
        ([["0", "1", "2"], ["0.1", "1", "2"], ["0.2", "1", "2"]], {"units": "grad"}, "unknown angle units 'grad'"),
    ],
)
def test_bad_csv_gives_one_line_naming_the_column_or_row_and_writes_nothing(tmp_path, rows, kwargs, message):
    path = _write(tmp_path / "bad.csv", ["t", "V", "p"], rows)
    before = sorted(p.name for p in tmp_path.iterdir())
    args = {"time": "t", "inputs": "V", "outputs": "p", "units": "deg", **kwargs}
    with pytest.raises(InputError, match=message) as exc:
        record_from_csv(path, **args)
    assert "\n" not in str(exc.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == before


# ------------------------------------------------------------------------------- exports as they come
import errno  # noqa: E402
import warnings  # noqa: E402

import scipy.io  # noqa: E402

from trms.rigchecks import END_STOP_MARGIN, JITTER_TOLERANCE, MAX_RATE  # noqa: E402
from trms.rigdata import (  # noqa: E402
    RigDataWarning,
    end_stops,
    hover_operating_point,
    load_record,
    read_inputs,
    record_from_export,
    record_from_mat,
)

N, TS = 400, 0.05


def _signals():
    """A hover segment (t < 10 s) then a square wave on the main rotor and a sine on pitch (deg), yaw (deg)."""
    t = np.arange(N) * TS
    u1 = 2.0 + np.where(t < 10, 0.0, 0.3 * np.sign(np.sin(t) + 1e-9))
    u2 = -1.0 + np.where(t < 10, 0.0, 0.2 * np.cos(t))
    pitch = 1.5 + np.where(t < 10, 0.0, 5.0 * np.sin(t - 10))
    yaw = np.where(t < 10, 0.0, 20.0 * np.sin(0.3 * (t - 10)))
    return t, u1, u2, pitch, yaw


def _text(rows, header, delimiter=",", head=(), fmt="{:.6g}"):
    lines = [*head, delimiter.join(header)]
    lines += [delimiter.join(fmt.format(v) for v in row) for row in zip(*rows)]
    return "\n".join(lines) + "\n"


def _read(path, **kw):
    """record_from_export with the warnings it gave (as strings)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rec = record_from_export(path, **kw)
    said = [str(w.message) for w in caught if issubclass(w.category, RigDataWarning)]
    assert said == rec.metadata.get("import_warnings", [])  # what was said is kept with the Record
    assert all("\n" not in s for s in said)
    return rec, said


def test_a_semicolon_export_with_a_title_line_and_decimal_commas_reads_exactly(tmp_path):
    t, u1, _, pitch, _ = _signals()
    body = _text([t, u1, pitch], ["Zeit [s]", "U1 [V]", "Pitch [deg]"], ";", head=["TRMS 33-220 run 3;;", "  "])
    (tmp_path / "point.csv").write_text(body)
    (tmp_path / "comma.csv").write_text(body.replace(".", ","))  # a German spreadsheet's decimal commas
    for name in ("point.csv", "comma.csv"):
        rec, said = _read(
            tmp_path / name, time="Zeit [s]", inputs="U1 [V]", outputs="Pitch [deg]", units="deg", hover_segment=(0, 10)
        )
        np.testing.assert_array_equal(rec.time, np.arange(N) * 0.05)
        np.testing.assert_array_equal(rec.inputs[:, 0], [float(f"{v:.6g}") for v in u1])
        np.testing.assert_allclose(
            rec.outputs[:, 0], np.radians([float(f"{v:.6g}") for v in pitch]), rtol=0, atol=1e-15
        )
        assert rec.sample_time == 0.05 and rec.metadata["import"]["delimiter"] == "semicolon"
        np.testing.assert_array_equal(rec.operating_point.inputs, [2.0])
        assert said == [f"{str(tmp_path / name)!r}: skipped line 1 'TRMS 33-220 run 3;;' (its header is line 3)"]


@pytest.mark.parametrize("delimiter, name", [("\t", "tab"), (" ", "whitespace")])
def test_tab_and_whitespace_exports_with_comment_lines(tmp_path, delimiter, name):
    t, u1, _, pitch, _ = _signals()
    head = ["# exported by the rig's logger", "# channels: time, main rotor, pitch"]
    path = tmp_path / "rig.txt"
    path.write_text(_text([t, u1, pitch], ["t", "V1", "pitch"], delimiter, head=head))
    rec, said = _read(path, time="t", inputs="V1", outputs="pitch", units="deg")
    assert rec.metadata["import"]["delimiter"] == name and len(rec) == N
    np.testing.assert_allclose(rec.outputs[:, 0], np.radians(pitch), rtol=0, atol=1e-7)
    assert said == [f"{str(path)!r}: skipped 2 comment lines (#) from line 1 (its header is line 3)"]


def test_millisecond_timestamps_with_jitter_are_snapped_and_seconds_are_refused(tmp_path):
    """50 ms logging with +-0.25 ms jitter (0.5 % of a sample): snapped to the 0.05 s grid, said in one line."""
    t, u1, _, pitch, _ = _signals()
    jitter = np.random.default_rng(7).uniform(-0.25, 0.25, N)
    path = tmp_path / "ms.csv"
    path.write_text(_text([1000 * t + jitter, u1, pitch], ["t_ms", "V1", "pitch"], fmt="{:.4f}"))
    cols = {"time": "t_ms", "inputs": "V1", "outputs": "pitch", "units": "deg"}
    rec, said = _read(path, **cols, time_unit="ms", hover_segment=(0, 10))
    np.testing.assert_array_equal(rec.time, np.arange(N) * 0.05)
    assert rec.sample_time == 0.05 and rec.metadata["units"]["time"] == "ms"
    np.testing.assert_allclose(rec.outputs[:, 0], np.radians(np.round(pitch, 4)), rtol=0, atol=1e-12)
    worst = np.max(np.abs(np.round(1000 * t + jitter, 4) / 1000 - rec.metadata["start_time"] - rec.time)) / 0.05
    assert 0.004 < worst < JITTER_TOLERANCE
    assert said == [
        f"column 't_ms' of {str(path)!r}: timestamps up to {100 * worst:.3g} % of the 0.05 s sample time off a "
        "uniform grid (jitter tolerance 5 %); snapped to the grid"
    ]
    np.testing.assert_array_equal(rec.operating_point.inputs, [2.0])
    with pytest.raises(InputError) as exc:  # read as seconds: a 50 s sample time
        record_from_csv(path, **cols)
    median = np.median(np.diff(np.round(1000 * t + jitter, 4)))
    assert 49.9 < median < 50.1
    assert str(exc.value) == (
        f"column 't_ms' of {str(path)!r}: sample time {median:.6g} s (median interval, time in s) is outside the rig's "
        "range [0.001 s, 32.767 s]: is the time column in milliseconds? say time_unit='ms' (--time-unit ms)"
    )


def test_six_hundred_samples_at_100_s_are_refused_and_10_s_is_warned_about(tmp_path):
    t, u1, _, pitch, _ = _signals()
    path = tmp_path / "slow.csv"
    path.write_text(_text([np.arange(N) * 100.0, u1, pitch], ["t", "V1", "pitch"]))
    with pytest.raises(InputError, match=r"sample time 100 s .* say time_unit='ms' \(--time-unit ms\)$"):
        record_from_csv(path, time="t", inputs="V1", outputs="pitch", units="deg")
    rec = record_from_csv(path, time="t", inputs="V1", outputs="pitch", units="deg", time_unit="ms")
    assert rec.sample_time == 0.1
    path.write_text(_text([np.arange(N) * 10.0, u1, pitch], ["t", "V1", "pitch"]))  # 10 ms logging read as s
    rec, said = _read(path, time="t", inputs="V1", outputs="pitch", units="deg")
    assert said == [
        f"column 't' of {str(path)!r}: sample time 10 s cannot resolve the rig's 0.342 Hz pitch mode (needs < 1.46 s): "
        "is the time column in milliseconds? say time_unit='ms' (--time-unit ms)"
    ]


def test_gaps_beyond_the_jitter_tolerance_are_refused_or_resampled_linearly(tmp_path):
    t, u1, u2, pitch, _ = _signals()
    ramp = 1.0 + 0.01 * t  # linear in time: interpolation gives it back exactly
    keep = np.ones(N, bool)
    keep[[50, 51, 200]] = False  # three samples the logger lost
    path = tmp_path / "gaps.csv"
    path.write_text(_text([t[keep], ramp[keep], pitch[keep]], ["t", "V1", "pitch"], fmt="{:.17g}"))
    cols = {"time": "t", "inputs": "V1", "outputs": "pitch", "units": "deg"}
    with pytest.raises(InputError) as exc:
        record_from_csv(path, **cols)
    assert str(exc.value).startswith(
        "row 52, column 't': sample interval 0.15 s differs from the record's 0.05 s (timestamps up to "
    )
    assert str(exc.value).endswith(
        "beyond the 5 % jitter tolerance); resample=True (--resample) interpolates the record linearly onto a "
        "uniform grid"
    )
    rec, said = _read(path, **cols, resample=True)
    assert len(rec) == N and rec.sample_time == 0.05
    np.testing.assert_allclose(rec.inputs[:, 0], ramp, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(rec.outputs[keep, 0], np.radians(pitch[keep]))  # the samples kept are unchanged
    assert len(said) == 1 and said[0].startswith(f"column 't' of {str(path)!r}: timestamps up to ")
    assert said[0].endswith(
        "(beyond the 5 % jitter tolerance; intervals 0.05 .. 0.15 s); resampled by linear interpolation onto 0.05 s: "
        "397 rows -> 400 samples"
    )


def test_a_latin1_degree_sign_in_the_header_is_decoded(tmp_path):
    t, u1, _, pitch, _ = _signals()
    path = tmp_path / "latin1.csv"
    path.write_bytes(_text([t, u1, pitch], ["t [s]", "U1 [V]", "pitch [°]"]).encode("latin-1"))
    assert b"[\xb0]" in path.read_bytes()
    rec, said = _read(path, time="t [s]", inputs="U1 [V]", outputs="pitch [°]", units="deg")
    assert rec.output_names == ("pitch [°]",) and rec.metadata["import"]["encoding"] == "latin-1" and not said
    np.testing.assert_allclose(rec.outputs[:, 0], np.radians(pitch), rtol=0, atol=1e-7)
    path.write_bytes(b"\xff\xfe" + _text([t, u1, pitch], ["t", "U1", "pitch [°]"]).encode("utf-16-le"))
    rec, _ = _read(path, time="t", inputs="U1", outputs="pitch [°]", units="deg")  # a spreadsheet's "Unicode text"
    assert rec.metadata["import"]["encoding"] == "utf-16" and len(rec) == N


def _rig_file(tmp_path, name, angle, units_col="pitch"):
    t, u1, _, _, _ = _signals()
    path = tmp_path / name
    path.write_text(_text([t, u1, angle], ["t", "V1", units_col]))
    return path


def test_degrees_labelled_radians_are_refused_with_the_unit_that_fits(tmp_path):
    pitch = _signals()[3]  # -3.5 .. 6.5 deg
    path = _rig_file(tmp_path, "deg.csv", pitch)
    with pytest.raises(InputError) as exc:
        record_from_csv(path, time="t", inputs="V1", outputs="pitch", units="rad")
    i = int(np.argmax(np.abs(pitch)))
    assert str(exc.value) == (
        f"row {i + 2}, column 'pitch': pitch {pitch[i]:.6g} rad is beyond pitch's end stops +-1.1 rad (with a 20 % "
        f"margin); as deg it reaches {np.radians(pitch[i]):.3g} rad: say units='deg' (--units deg)"
    )
    assert end_stops() == {"pitch": 1.1, "yaw": 3.0} and END_STOP_MARGIN == 0.2  # the shipped model's joint ranges


def test_a_small_motion_in_degrees_labelled_radians_is_refused_by_its_speed(tmp_path):
    """Within +-1 deg the numbers fit the stops as radians, but 0.8 "rad" in one 0.05 s sample is 16 rad/s... and
    at 0.01 s it is 80 rad/s, beyond the rig's 25 rad/s on pitch."""
    t = np.arange(300) * 0.01
    pitch = 0.8 * np.sign(np.sin(2 * np.pi * 0.5 * t) + 1e-9)  # a +-0.8 deg square wave
    path = tmp_path / "fast.csv"
    path.write_text(_text([t, np.full(t.size, 2.0), pitch], ["t", "V1", "pitch"]))
    jump = int(np.flatnonzero(np.diff(pitch))[0]) + 1  # the first sample after a flip of the square wave
    with pytest.raises(InputError) as exc:
        record_from_csv(path, time="t", inputs="V1", outputs="pitch", units="rad")
    assert str(exc.value) == (
        f"row {jump + 2}, column 'pitch': pitch moves 1.6 rad in one sample (0.01 s), 160 rad/s; the rig's pitch "
        f"moves at most about {MAX_RATE['pitch']:g} rad/s; as deg it would be 2.79 rad/s: say units='deg' (--units deg)"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", RigDataWarning)  # as radians it could not be: no doubt about degrees either
        rec = record_from_csv(path, time="t", inputs="V1", outputs="pitch", units="deg")
    assert np.max(np.abs(rec.outputs)) == pytest.approx(np.radians(0.8))


def test_radians_labelled_degrees_are_warned_about(tmp_path):
    pitch_rad = np.radians(_signals()[3])
    path = _rig_file(tmp_path, "rad.csv", pitch_rad)
    rec, said = _read(path, time="t", inputs="V1", outputs="pitch", units="deg")
    lo, hi = (float(f"{v:.6g}") for v in (pitch_rad.min(), pitch_rad.max()))
    assert said == [
        f"column 'pitch' of {str(path)!r}: pitch reads {lo:.4g} .. {hi:.4g} deg, a motion of only {hi - lo:.3g} deg; "
        "the numbers fit pitch's end stops +-1.1 rad and speed as radians: if the column is in radians, say "
        "units='rad' (--units rad)"
    ]
    rec, said = _read(path, time="t", inputs="V1", outputs="pitch", units="rad")
    assert not said and rec.outputs[:, 0] == pytest.approx(pitch_rad, abs=1e-6)


def test_angles_a_hundred_times_beyond_the_end_stops_are_refused_in_either_unit(tmp_path):
    yaw = 300.0 * np.sin(np.arange(N) * TS)  # yaw's stops are +-3 rad: 300 is 100 x
    path = _rig_file(tmp_path, "yaw.csv", yaw, "yaw_angle")
    i = int(np.argmax(np.abs(yaw)))
    with pytest.raises(InputError) as exc:
        record_from_csv(path, time="t", inputs="V1", outputs="yaw_angle", units="rad")
    assert str(exc.value) == (
        f"row {i + 2}, column 'yaw_angle': yaw {yaw[i]:.6g} rad is beyond yaw's end stops +-3 rad (with a 20 % "
        f"margin); in deg too ({np.radians(abs(yaw[i])):.3g} rad): check the column"
    )


def test_the_same_column_for_both_inputs_of_a_2dof_record_is_refused(tmp_path):
    t, u1, u2, pitch, yaw = _signals()
    path = tmp_path / "two.csv"
    path.write_text(_text([t, u1, u2, pitch, yaw], ["t", "V1", "V2", "pitch", "yaw"]))
    with pytest.raises(InputError) as exc:
        record_from_csv(
            path, time="t", inputs=["V1", "V1"], outputs=["pitch", "yaw"], units="deg", input_names=["u1", "u2"]
        )
    assert str(exc.value) == "column 'V1' is given for both u1 and u2; each channel needs its own column"
    rec = record_from_csv(path, time="t", inputs=["V1", "V2"], outputs=["pitch", "yaw"], units="deg")
    np.testing.assert_array_equal(rec.inputs, [[float(f"{v:.6g}") for v in row] for row in zip(u1, u2)])


@pytest.mark.parametrize(
    "content, message",
    [
        (bytes(np.random.default_rng(3).integers(0, 256, 4096, dtype=np.uint8)), r"is not a text export: byte 0x"),
        (b"PK\x03\x04" + bytes(60), r"is a zip archive \(a saved Record .npz\?\), not a CSV export"),
        (b"t,V1," + b"p" * 131_073 + b"\n0,1,2\n0.1,1,2\n0.2,1,2\n", "has a field longer than 131072 characters"),
        (b"0,1,2\n0.1,1,2\n0.2,1,2\n", "has no header row: line 1 is numbers already"),
    ],
    ids=["binary garbage", "npz as csv", "huge header field", "no header"],
)
def test_files_that_are_not_exports_give_one_line(tmp_path, content, message):
    path = tmp_path / "rig.csv"
    path.write_bytes(content)
    with pytest.raises(InputError, match=message) as exc:
        record_from_csv(path, time="t", inputs="V1", outputs="p", units="deg")
    assert "\n" not in str(exc.value) and len(str(exc.value)) < 300
    assert [p.name for p in tmp_path.iterdir()] == ["rig.csv"]


def test_the_hover_segment_is_half_open(tmp_path):
    """The excitation starts at t = 10 s: --hover 0:10 must not take that first excited sample."""
    t, u1, _, pitch, _ = _signals()
    path = _rig_file(tmp_path, "hover.csv", pitch)
    rec = record_from_csv(path, time="t", inputs="V1", outputs="pitch", units="deg", hover_segment=(0, 10))
    assert u1[t == 10.0] != 2.0  # the first excited sample, at T1
    np.testing.assert_array_equal(rec.operating_point.inputs, [2.0])
    np.testing.assert_allclose(rec.operating_point.outputs, [np.radians(1.5)], rtol=1e-12)
    assert rec.metadata["operating_point_source"] == "mean of hover segment [0, 10) s"
    r = Record(np.arange(4) * 0.1, [1.0, 1.0, 5.0, 5.0], np.zeros(4), ("u1",), ("pitch",))
    assert hover_operating_point(r, 0.0, 0.2).inputs == [1.0]
    assert hover_operating_point(r, 0.0, 0.2 + 1e-12).inputs == [1.0]  # rounding of T1 does not pull it in
    with pytest.raises(InputError, match=r"hover segment \[0.1, 0.2\) s holds 1 samples"):
        hover_operating_point(r, 0.1, 0.2)


# ---------------------------------------------------------------------------------------------- .mat
@pytest.fixture
def mat_file(tmp_path):
    t, u1, u2, pitch, yaw = _signals()
    path = tmp_path / "run.mat"
    scipy.io.savemat(
        path,
        {
            "data": {"time": t, "u1": u1, "u2": u2, "pitch": pitch, "yaw": yaw},
            "log": np.column_stack([1000 * t, u1, u2, pitch, yaw]),  # a Simulink-style matrix, time in ms
            "ScopeData": {"time": t, "signals": [{"values": pitch}, {"values": np.column_stack([pitch, yaw])}]},
            "zc": pitch + 0.5j,
            "label": "run 3",
        },
    )
    return path, (t, u1, u2, pitch, yaw)


@pytest.mark.parametrize(
    "cols",
    [
        {"time": "data.time", "inputs": ["data.u1", "data.u2"], "outputs": ["data.pitch", "data.yaw"]},
        {"time": "data.time", "inputs": ["u1", "u2"], "outputs": ["pitch", "yaw"]},  # fields of the one struct
        {"time": "log(:,1)", "inputs": ["log(:,2)", "log(:,3)"], "outputs": ["log(:,4)", "log(:,5)"], "ms": True},
        {
            "time": "ScopeData.time",
            "inputs": ["data.u1", "data.u2"],
            "outputs": ["ScopeData.signals(1).values", "ScopeData.signals(2).values(:,2)"],
        },
    ],
    ids=["struct fields", "fields named alone", "matrix columns", "struct array"],
)
def test_a_mat_export_reads_exactly(mat_file, cols):
    path, (t, u1, u2, pitch, yaw) = mat_file
    ms = cols.pop("ms", False)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RigDataWarning)
        rec = record_from_mat(
            path,
            **cols,
            units="deg",
            time_unit="ms" if ms else "s",
            hover_segment=(0, 10),
            input_names=["u1", "u2"],
            output_names=["pitch", "yaw"],
            config="2dof",
        )
    np.testing.assert_array_equal(rec.time, np.arange(N) * 0.05)
    np.testing.assert_array_equal(rec.inputs, np.column_stack([u1, u2]))
    np.testing.assert_array_equal(rec.outputs, np.radians(np.column_stack([pitch, yaw])))
    np.testing.assert_array_equal(rec.operating_point.inputs, [2.0, -1.0])
    assert rec.metadata["import"] == {"format": "mat"} and rec.metadata["config"] == "2dof"


@pytest.mark.parametrize(
    "outputs, message",
    [
        ("zc", r"variable 'zc' of '.*run.mat' must be real numbers .*: complex values are not allowed"),
        ("label", r"variable 'label' of '.*run.mat' must be real numbers .*: text values are not allowed"),
        ("log", r"variable 'log' of '.*run.mat' is 400x5, not one series; name one column, e.g. 'log\(:,1\)'"),
        ("log(:,9)", r"'log\(:,9\)' is not a column of 'log', a 400x5 matrix"),
        ("data", r"variable 'data' of '.*run.mat' is a struct \(fields time, u1, u2, pitch, yaw\)"),
        ("nope", r"variable 'nope' is missing from '.*run.mat'; it has data \(struct: time, u1, u2, pitch, yaw\), "),
        ("time", r"'time' is a field of several structs in '.*run.mat' \(data, ScopeData\)"),
    ],
)
def test_bad_mat_variables_give_one_line(mat_file, outputs, message):
    path, _ = mat_file
    with pytest.raises(InputError, match=message) as exc:
        record_from_mat(path, time="data.time", inputs="data.u1", outputs=outputs, units="deg")
    assert "\n" not in str(exc.value)


def test_a_matlab_v73_file_is_refused_with_one_line(tmp_path):
    """MATLAB's -v7.3 files are HDF5: a 128-byte MAT header, then the HDF5 signature at byte 512."""
    head = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon May  6 10:00:00 2024 HDF5 schema 1.00 ."
    raw = head.ljust(116, b" ") + bytes(8) + b"\x00\x02IM"
    path = tmp_path / "run73.mat"
    path.write_bytes(raw.ljust(512, b"\x00") + b"\x89HDF\r\n\x1a\n" + bytes(512))
    with pytest.raises(InputError) as exc:
        record_from_export(path, time="t", inputs="u1", outputs="pitch", units="deg")
    assert str(exc.value) == (
        f"{str(path)!r} is a MATLAB v7.3 (HDF5) MAT-file, which trms cannot read; save it as v7 in MATLAB "
        "(save('run73.mat', ..., '-v7')) and import that"
    )
    renamed = tmp_path / "run.csv"
    path.rename(renamed)
    with pytest.raises(InputError, match="is a MATLAB v7.3"):  # found by its header, whatever its name
        record_from_export(renamed, time="t", inputs="u1", outputs="pitch", units="deg")


def test_a_missing_export_is_one_line_not_an_os_error(tmp_path):
    with pytest.raises(InputError, match="CSV file .* does not exist"):
        record_from_export(tmp_path / "none.csv", time="t", inputs="u1", outputs="pitch", units="deg")
    assert errno.ENOENT  # the OS error never escapes


@pytest.mark.parametrize("kind", ["folder", "fifo", "device"])
def test_an_export_that_is_no_regular_file_is_named_as_what_it_is(tmp_path, kind):
    import os

    path = tmp_path / "rig.csv"
    if kind == "folder":
        path.mkdir()
    elif kind == "fifo":
        os.mkfifo(path)  # a reader would wait for a writer for ever
    else:
        path = "/dev/zero"  # a reader would never reach the end
    what = {"folder": "a folder", "fifo": r"a FIFO \(named pipe\)", "device": "a character device"}[kind]
    with pytest.raises(InputError, match=rf"CSV file '.*' is {what}, not a regular file"):
        record_from_export(path, time="t", inputs="u1", outputs="pitch", units="deg")
    with pytest.raises(InputError, match=rf"input file '.*' is {what}, not a regular file"):
        read_inputs(path, 1)


def test_the_speed_bound_is_twice_the_twins_fastest_at_full_voltage():
    """+-10 V square waves on both rotors of the 2-DOF twin (12 s period, 0.01 s samples): the beam slams
    from stop to stop; MAX_RATE is about twice that, so a real rig never trips it and degrees labelled
    radians (57 x) do."""
    from trms.twin import Twin

    twin = Twin("2dof", 0.01, seed=0)
    square = np.where(np.sin(2 * np.pi * np.arange(3600) * 0.01 / 12) >= 0, 10.0, -10.0)
    rec = twin.run(np.column_stack([square, square]))
    fastest = np.max(np.abs(np.diff(rec.outputs, axis=0)), axis=0) / 0.01
    for axis, rate in zip(rec.output_names, fastest):
        assert MAX_RATE[axis] / 4 < rate < MAX_RATE[axis] / 2 + 0.5, (axis, rate)
    assert np.max(np.abs(rec.outputs[:, 0])) > 1.0  # it did reach the pitch stops


# ------------------------------------------------ implausible import arguments: one line each, nothing kept
def _small_rig(tmp_path, header=("t", "V", "W", "pitch"), volts=3.0):
    """30 s at 0.1 s: two voltage columns and a small pitch motion in rad."""
    t = np.arange(300) * 0.1
    rows = [[f"{a:.6g}", f"{volts:.6g}", "1.0", f"{0.1 * np.sin(a):.6g}"] for a in t]
    return _write(tmp_path / "rig.csv", list(header), rows)


@pytest.mark.parametrize(
    "header, volts, kwargs, error, message",
    [
        (
            ("t", "V", "V", "pitch"),
            3.0,
            {"inputs": "V"},
            InputError,
            r"column 'V' is ambiguous: the header of .* has it twice \(columns 2 and 3\); rename one",
        ),
        (None, 1e6, {}, InputError, r"row 2, column 'V': 1e\+06 V is beyond the plausible \+-100 V"),
        (None, 3.0, {"operating_point": ([3.0], [50.0])}, InputError, r"operating_point output 'pitch' = 50 rad is"),
        (None, 3.0, {"operating_point": ([300.0], [0.0])}, InputError, r"operating_point input 'V' = 300 V"),
        (None, 3.0, {"config": "3dof"}, ConfigurationError, r"unknown configuration '3dof'; allowed: '1dof'"),
        (None, 3.0, {"hover_segment": (25, 100)}, InputError, r"hover segment \[25, 100\) s is not inside the record"),
        (None, 3.0, {"hover_segment": (-5, 10)}, InputError, r"hover segment \[-5, 10\) s is not inside"),
        (None, 3.0, {"hover_segment": "0:10"}, InputError, r"hover_segment .* got '0:10': text values"),
        (None, 3.0, {"inputs": 3}, InputError, r"inputs must name at least one column, got 3"),
    ],
)
def test_implausible_import_arguments_are_refused_in_one_line(tmp_path, header, volts, kwargs, error, message):
    path = _small_rig(tmp_path, header or ("t", "V", "W", "pitch"), volts)
    args = {"time": "t", "inputs": "V", "outputs": "pitch", "units": "rad", **kwargs}
    with pytest.raises(error, match=message) as exc:
        record_from_csv(path, **args)
    assert "\n" not in str(exc.value)


def test_a_path_that_is_not_a_path_is_refused_in_one_line():
    with pytest.raises(InputError, match=r"path must be a file path \(str or os.PathLike\), got None"):
        record_from_csv(None, time="t", inputs="V", outputs="pitch", units="rad")


def test_a_hover_segment_inside_the_record_and_voltages_beyond_the_drives_are_accepted(tmp_path):
    path = _small_rig(tmp_path, volts=12.0)
    with pytest.warns(RigDataWarning, match=r"column 'V' .* voltage reaches 12 V, beyond the drives' \+-10 V"):
        rec = record_from_csv(path, time="t", inputs="V", outputs="pitch", units="rad", hover_segment=(20, 30))
    assert rec.operating_point.inputs.tolist() == [12.0]  # the whole last 10 s, up to the record's end


@pytest.mark.parametrize(
    "outputs, margin, expected",
    [
        ([0.0, 1.0, -1.2], 0.2, None),  # within 1.1 rad * 1.2
        ([0.0, 1.0, -1.2], 0.0, "pitch reaches -1.2 rad (end stops +-1.1 rad)"),
        ([0.0, 1.0, np.nan], 0.0, None),
        ([0.0, 50.0, 1.0], 0.2, "pitch reaches 50 rad (end stops +-1.1 rad)"),
    ],
)
def test_beyond_end_stops_names_the_axis_and_its_farthest_angle(outputs, margin, expected):
    rec = Record(np.arange(3) * 0.1, np.zeros(3), outputs, ("u1",), ("pitch",))
    assert beyond_end_stops(rec, margin) == expected


# ------------------------------------------------------------------------------------------ input files
@pytest.mark.parametrize(
    "name, content",
    [
        ("volts.csv", "u1,u2\n2.0,-1.0\n2.5,-1.5\n"),
        ("volts.txt", "2.0 -1.0\n2.5 -1.5\n"),
        ("volts.npy", None),
        ("volts.npz", None),
    ],
)
def test_read_inputs_gives_the_same_volts_from_every_format(tmp_path, name, content):
    volts = np.array([[2.0, -1.0], [2.5, -1.5]])
    path = tmp_path / name
    if name.endswith(".npy"):
        np.save(path, volts)
    elif name.endswith(".npz"):
        Record(np.arange(2) * 0.1, volts, np.zeros((2, 2)), ("u1", "u2"), ("pitch", "yaw")).save(path)
    else:
        path.write_text(content)
    np.testing.assert_array_equal(read_inputs(path, 2), volts)


def test_read_inputs_takes_one_flat_column_and_refuses_what_is_not_volts(tmp_path):
    np.save(tmp_path / "flat.npy", np.array([1.0, 2.0, 3.0]))
    assert read_inputs(tmp_path / "flat.npy", 1).shape == (3, 1)
    (tmp_path / "kv.csv").write_text("u1\n0.5\n2000\n")
    with pytest.raises(InputError, match=r"2000 V is beyond the plausible \+-100 V"):
        read_inputs(tmp_path / "kv.csv", 1)
    (tmp_path / "word.csv").write_text("u1\n0.5\nhigh\n")
    with pytest.raises(InputError, match="holds a non-numeric value"):
        read_inputs(tmp_path / "word.csv", 1)
    with pytest.raises(InputError, match="must have shape"):
        read_inputs(tmp_path / "flat.npy", 2)


def test_load_record_warns_once_for_angles_past_the_stops(tmp_path):
    Record(np.arange(3) * 0.1, np.zeros(3), [0.0, 0.5, 1.0], ("u1",), ("pitch",)).save(tmp_path / "ok.npz")
    Record(np.arange(3) * 0.1, np.zeros(3), [0.0, 0.5, 57.0], ("u1",), ("pitch",)).save(tmp_path / "deg.npz")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert len(load_record(tmp_path / "ok.npz")) == 3
        assert len(load_record(tmp_path / "deg.npz")) == 3
    assert [str(w.message) for w in caught] == [
        f"record {str(tmp_path / 'deg.npz')!r}: pitch reaches 57 rad (end stops +-1.1 rad), beyond the rig's end "
        "stops: no rig moves there (angles not in rad?)"
    ]


def test_a_log_clock_that_starts_late_is_the_one_every_message_speaks(tmp_path):
    """A logger's clock starting at 12.5 s: the hover segment is given, refused and reported on it."""
    t, u1, u2, pitch, yaw = _signals()
    path = tmp_path / "late.csv"
    path.write_text(_text([t + 12.5, u1, u2, pitch, yaw], ["t", "V1", "V2", "pitch", "yaw"]))
    cols = dict(time="t", inputs=["V1", "V2"], outputs=["pitch", "yaw"], units="deg")
    with pytest.raises(InputError) as exc:
        record_from_export(path, hover_segment=(0, 10), **cols)
    assert str(exc.value) == (
        "hover segment [0, 10) s is not inside the record (time 12.5 .. 32.5 s); allowed: a segment within it"
    )
    rec, _ = _read(path, hover_segment=(12.5, 22.5), **cols)
    assert rec.metadata["start_time"] == 12.5 and rec.time[0] == 0.0
    assert rec.metadata["operating_point_source"] == "mean of hover segment [12.5, 22.5) s"
    np.testing.assert_allclose(rec.operating_point.inputs, [2.0, -1.0])


def test_an_axis_at_its_end_stop_is_said_on_import_with_the_first_contact_on_the_log_clock(tmp_path):
    """Yaw at 172.09 deg, past its 171.89 deg (3 rad) stop but within the reading margin: accepted, and said."""
    t, u1, u2, pitch, _ = _signals()
    yaw = np.where(t < 15, 0.0, np.clip(300.0 * np.sin(0.5 * (t - 15)), -172.09, 172.09))
    path = tmp_path / "stop.csv"
    path.write_text(_text([t + 12.5, u1, u2, pitch, yaw], ["t", "V1", "V2", "pitch", "yaw"], fmt="{:.8g}"))
    rec, said = _read(
        path, time="t", inputs=["V1", "V2"], outputs=["pitch", "yaw"], units="deg", hover_segment=(12.5, 22)
    )
    first = 12.5 + t[np.flatnonzero(np.abs(yaw) >= np.degrees(3.0 * 0.98))[0]]
    (line,) = [s for s in said if "end stop" in s]
    assert line.startswith(
        f"column 'yaw' of {str(path)!r}: yaw reaches 172.09 deg, at its end stop +-3 rad (+-171.89 deg), "
        f"first at t = {first:.6g} s, "
    )
    assert "record with a lower amplitude" in line
    quiet = tmp_path / "quiet.csv"
    quiet.write_text(_text([t, u1, u2, pitch, 0.9 * yaw], ["t", "V1", "V2", "pitch", "yaw"]))
    _, said = _read(quiet, time="t", inputs=["V1", "V2"], outputs=["pitch", "yaw"], units="deg", hover_segment=(0, 10))
    assert not [s for s in said if "end stop" in s]
