"""The notebooks run: every code cell of ``notebooks/*.ipynb`` in order, as one script, and their results hold."""

import json
from pathlib import Path

import control
import numpy as np
import pytest
from matplotlib.figure import Figure

ROOT = Path(__file__).resolve().parents[1]
QUICKSTART = ROOT / "notebooks" / "quickstart.ipynb"


def _cells(path: Path) -> list[dict]:
    notebook = json.loads(path.read_text())
    assert notebook["nbformat"] == 4
    return notebook["cells"]


def test_the_notebooks_are_stored_without_outputs():
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        for cell in _cells(path):
            if cell["cell_type"] == "code":
                assert cell["outputs"] == [] and cell["execution_count"] is None, path.name


@pytest.fixture(scope="module")
def quickstart(tmp_path_factory, monkeypatch_module):
    monkeypatch_module.chdir(tmp_path_factory.mktemp("quickstart"))
    monkeypatch_module.setenv("MPLBACKEND", "Agg")
    code = [cell for cell in _cells(QUICKSTART) if cell["cell_type"] == "code"]
    scope: dict = {}
    for i, cell in enumerate(code):
        exec(compile("".join(cell["source"]), f"quickstart.ipynb, code cell {i}", "exec"), scope)  # noqa: S102
    return scope


@pytest.fixture(scope="module")
def monkeypatch_module():
    with pytest.MonkeyPatch.context() as mp:
        yield mp


def test_quickstart_identifies_the_twins_pitch_mode(quickstart):
    twin, model = quickstart["twin"], quickstart["model"]
    assert len(quickstart["record"]) == 900
    assert model.orders == (4, 4, 4, 1)
    # The ARMAX of the PRBS record finds the pitch mode and the DC gain of the twin's own linearisation,
    # which the fit never saw (a small signal, 0.05 V, and 180 s: the rig's ambient excitation and the
    # thrust curve's and the pendulum's curvature bias a shorter or larger experiment by up to 13 %).
    truth = min((m for m in twin.modes() if m.dominant == "pitch"), key=lambda m: m.frequency_hz)
    assert quickstart["pitch_mode"] == truth
    assert abs(quickstart["armax_mode"].frequency_hz - truth.frequency_hz) < 0.02
    assert abs(model.dc_gain() / control.dcgain(twin.linearise().continuous) - 1) < 0.10


def test_quickstart_loop_settles_on_the_step(quickstart):
    run, metrics = quickstart["run"], quickstart["metrics"]
    assert np.isfinite(metrics.settling_time) and metrics.target == pytest.approx(0.2)
    assert abs(run.deviations()[1][-1, 0] - 0.2) < 0.02 * 0.2
    assert not run.extras["saturated"].any()


def test_quickstart_figures_and_reprs(quickstart):
    assert isinstance(quickstart["bode"], Figure) and len(quickstart["bode"].axes) == 2
    assert isinstance(quickstart["loop_figure"], Figure)
    for name in ("model", "record"):
        text = repr(quickstart[name])
        assert "array(" not in text and len(text) < 400, text
        assert quickstart[name]._repr_html_().startswith("<table>")
