"""``trms identify``: model.json, tests and figures; refusals in one line; angles past the stops warned."""

import json

import numpy as np
import pytest

from trms.cli import main
from trms.record import Record

from ._helpers import angle_warning, bad_input, known_failure, refusal, trms


def test_identify_writes_a_model_tests_and_plots(work):
    res = trms("identify", "prbs.npz", "--validate", "doublet.npz", "--out", "ident", cwd=work)
    assert res.returncode == 0, res.stderr
    model = json.loads((work / "ident" / "model.json").read_text())
    assert model["orders"] == [4, 4, 4, 1] and len(model["A"]) == 5
    assert set(model["residual_tests"]) == {"ee", "ue"} and np.isfinite(model["validation_fit_percent"])
    for name in ("residuals.png", "psd.png", "validation.png"):
        assert (work / "ident" / name).stat().st_size > 5000
    assert "mode " in res.stdout and "validation fit" in res.stdout


def test_the_validation_figure_names_its_units(work, figures, capsys, monkeypatch):
    monkeypatch.chdir(work)
    argv = ["identify", "prbs.npz", "--validate", "doublet.npz", "--orders", "2", "2", "2", "1", "--out", "units"]
    assert main(argv) == 0, capsys.readouterr().err
    ax = figures["validation.png"].axes[0]
    assert ax.get_ylabel() == "pitch, deviation from the operating point (rad)" and ax.get_xlabel() == "time (s)"
    np.testing.assert_array_equal(ax.get_lines()[0].get_xdata(), Record.load(work / "doublet.npz").time)


@pytest.mark.parametrize(
    "argv, match",
    [
        (["identify", "{d}/trunc.npz"], "is not a trms Record file"),
        (["identify", "{d}/empty.npz"], "is not a trms Record file: not an .npz archive"),
        (["identify", "{d}/listhdr.npz"], "its header is not a trms.Record/1 header"),
        (
            ["identify", "{d}/one.npz", "--validate", "{d}/two.npz", "--orders", "1", "1", "1", "1"],
            r"is a 2dof record with inputs \(u1, u2\) .* they must match",
        ),
    ],
)
def test_known_failures_are_one_line(files, tmp_path, capsys, argv, match):
    known_failure(files, tmp_path, capsys, argv, match)


@pytest.mark.parametrize(
    "args, message",
    [
        (("identify", "missing.npz"), "record file 'missing.npz' does not exist"),
    ],
)
def test_bad_input_exits_2_with_a_one_line_message(work, capsys, monkeypatch, args, message):
    bad_input(work, capsys, monkeypatch, args, message)


@pytest.mark.parametrize(
    "argv, match",
    [
        (["identify", "{d}/nan.npz", "--out", "{o}/id"], r"output 'pitch' is NaN in every sample"),
        (
            ["identify", "{d}/short.npz", "--out", "{o}/id"],
            r"too short for correlation tests to max_lag = 20 samples: they need at least 80 samples .* give 4\d",
        ),
    ],
)
def test_refusals_name_the_value_the_user_gave(odd, tmp_path, capsys, argv, match):
    refusal(odd, tmp_path, capsys, argv, match)


@pytest.mark.parametrize(
    "argv, warning",
    [
        (["identify", "{d}/far.npz"], r"far.npz': pitch reaches .* rad \(end stops \+-1.1 rad\), beyond the rig's"),
        (["identify", "{d}/good.npz"], None),
    ],
)
def test_angles_past_the_end_stops_are_said_in_one_warning(odd, tmp_path, capsys, argv, warning):
    angle_warning(odd, tmp_path, capsys, argv, warning)


def test_a_two_input_record_is_fitted_whole_with_a_mimo_method(files, tmp_path, capsys):
    argv = ["identify", str(files / "two.npz"), "--method", "arx-mimo", "--orders", "1", "1", "0", "1"]
    status = main([*argv, "--validate", str(files / "two.npz"), "--out", str(tmp_path / "mimo")])
    out = capsys.readouterr().out
    assert status == 0
    model = json.loads((tmp_path / "mimo" / "model.json").read_text())
    assert model["method"] == "arx-mimo" and model["inputs"] == ["u1", "u2"] and model["outputs"] == ["pitch", "yaw"]
    assert min(model["validation_fit_percent"].values()) > 90.0
    assert "arx-mimo u1, u2 -> pitch, yaw on 200 samples" in out and "validation fit pitch" in out
    names = sorted(p.name for p in (tmp_path / "mimo").iterdir())
    assert names == [
        "model.json",
        "residuals_pitch.png",
        "residuals_yaw.png",
        "validation_pitch.png",
        "validation_yaw.png",
    ]


@pytest.mark.parametrize(
    "extra, match",
    [
        ([], r"the record has 2 inputs \(u1, u2\): name the one ARMAX fits with --input, or .* --method arx-mimo"),
        (["--method", "n4sid", "--input", "u1"], r"--input and --output pick one channel for ARMAX; --method n4sid"),
        (["--states", "3"], r"--states 3 sets the order of n4sid and ssest; ARMAX takes --orders"),
    ],
)
def test_a_two_input_record_without_a_method_or_with_mixed_options_is_refused(files, tmp_path, capsys, extra, match):
    known_failure(files, tmp_path, capsys, ["identify", "{d}/two.npz", *extra], match)
