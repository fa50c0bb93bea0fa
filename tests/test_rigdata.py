"""A rig's CSV export in: units, checks, the operating point, and one clear line per bad file."""

import csv

import numpy as np
import pytest

from trms.errors import InputError
from trms.identification import armax, detrend, siso_data
from trms.plant import Record
from trms.rigdata import record_from_csv


def _write(path, header, rows):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)
    return path


@pytest.fixture
def rig_csv(tmp_path):
    """A rig's layout: time in s, main voltage, pitch in degrees, a column the twin does not know."""
    t = np.arange(400) * 0.05
    u = 2.0 + np.where(t < 10, 0.0, 0.3 * np.sign(np.sin(t)))
    pitch_deg = 1.5 + np.where(t < 10, 0.0, 5.0 * np.sin(t - 10))
    rows = [[f"{a:.6g}", f"{b:.6g}", f"{c:.6g}", "7"] for a, b, c in zip(t, u, pitch_deg)]
    return _write(tmp_path / "rig.csv", ["Time [s]", "Vmain", "Pitch_deg", "Tacho"], rows), t, u, pitch_deg


def test_a_rig_export_reads_in_radians_with_the_hover_operating_point(rig_csv):
    path, t, u, pitch_deg = rig_csv
    rec = Record.from_csv(
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
    assert rec.metadata["operating_point_source"] == "mean of hover segment 0..9.95 s"
    given = record_from_csv(
        path, time="Time [s]", inputs="Vmain", outputs="Pitch_deg", units="deg", operating_point=([2.0], [1.5])
    )
    np.testing.assert_allclose(given.operating_point.outputs, [np.radians(1.5)])
    assert given.metadata["operating_point_source"] == "given"


def test_identification_refuses_a_record_without_operating_point_and_accepts_it_detrended(rig_csv):
    path = rig_csv[0]
    rec = record_from_csv(path, time="Time [s]", inputs="Vmain", outputs="Pitch_deg", units="rad")
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


def test_trms_import_says_where_the_operating_point_came_from_and_writes_nothing_on_bad_input(
    rig_csv, capsys, monkeypatch
):
    from trms.cli import main

    path = rig_csv[0]
    monkeypatch.chdir(path.parent)
    args = [
        "import",
        path.name,
        "--time",
        "Time [s]",
        "--inputs",
        "Vmain",
        "--outputs",
        "Pitch_deg",
        "--config",
        "1dof",
        "--out",
        "rig.npz",
    ]
    assert main([*args, "--units", "deg", "--hover", "0:9.95"]) == 0
    out = capsys.readouterr().out
    assert "operating point (mean of hover segment 0..9.95 s): inputs [2.0] V" in out
    rec = Record.load(path.parent / "rig.npz")
    assert rec.input_names == ("u1",) and rec.output_names == ("pitch",) and rec.metadata["config"] == "1dof"
    (path.parent / "rig.npz").unlink()
    assert main(args) == 2  # no --units
    assert "units of the angle columns not given" in capsys.readouterr().err
    assert main([*args[:7], "Pitch", *args[8:], "--units", "deg"]) == 2
    assert capsys.readouterr().err.strip() == (
        f"trms import: error: column 'Pitch' is missing from {path.name!r}; it has Time [s], Vmain, Pitch_deg, Tacho"
    )
    assert not (path.parent / "rig.npz").exists()
