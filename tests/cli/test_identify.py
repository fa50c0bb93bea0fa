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
