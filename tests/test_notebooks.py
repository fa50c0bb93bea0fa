"""The notebooks run: every code cell of ``notebooks/*.ipynb`` in order, as one script, and their results hold.

The runner does what a stock Jupyter kernel does with a cell, without a kernel: the cell's last
expression is its result, shown as IPython's display formatter would (``text/plain``, ``text/html``
from ``_repr_html_``, and ``image/png`` for a matplotlib Figure once ``%matplotlib inline`` has
registered the PNG formatter, rendered as IPython's ``print_figure`` does). ``%matplotlib inline`` is
the one magic it knows; any other is refused.
"""

import ast
import io
import json
from pathlib import Path

import control
import numpy as np
import pytest
from matplotlib.figure import Figure

ROOT = Path(__file__).resolve().parents[1]
QUICKSTART = ROOT / "notebooks" / "quickstart.ipynb"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _cells(path: Path) -> list[dict]:
    notebook = json.loads(path.read_text())
    assert notebook["nbformat"] == 4
    return notebook["cells"]


def _python(source: str, where: str) -> tuple[str, bool]:
    """The cell's Python (its ``%matplotlib inline`` line blanked) and whether it had that line."""
    lines, inline = [], False
    for line in source.splitlines():
        if line.startswith("%"):
            assert line.split() == ["%matplotlib", "inline"], f"{where}: unknown magic {line!r}"
            inline, line = True, ""
        lines.append(line)
    return "\n".join(lines), inline


def _display(value: object, inline: bool) -> dict:
    """The MIME bundle a stock kernel sends for a cell's result ``value``."""
    bundle: dict = {"text/plain": repr(value)}
    html = getattr(value, "_repr_html_", None)
    if callable(html) and (text := html()) is not None:
        bundle["text/html"] = text
    if inline and isinstance(value, Figure) and value.axes:
        buffer = io.BytesIO()
        value.savefig(buffer, format="png", bbox_inches="tight")
        bundle["image/png"] = buffer.getvalue()
    return bundle


def run_notebook(path: Path) -> tuple[dict, list[dict]]:
    """Run the code cells of ``path`` in one namespace; return it and the cells' results as MIME bundles."""
    scope: dict = {}
    outputs: list[dict] = []
    inline = False
    for i, cell in enumerate(c for c in _cells(path) if c["cell_type"] == "code"):
        where = f"{path.name}, code cell {i}"
        source, magic = _python("".join(cell["source"]), where)
        inline |= magic
        tree = ast.parse(source, where)
        shown = tree.body and isinstance(tree.body[-1], ast.Expr) and not source.rstrip().endswith(";")
        last = tree.body.pop() if shown else None
        exec(compile(tree, where, "exec"), scope)  # noqa: S102
        if last is not None:
            value = eval(compile(ast.Expression(last.value), where, "eval"), scope)  # noqa: S307
            if value is not None:
                outputs.append(_display(value, inline))
    return scope, outputs


def test_the_notebooks_are_stored_without_outputs():
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        for cell in _cells(path):
            if cell["cell_type"] == "code":
                assert cell["outputs"] == [] and cell["execution_count"] is None, path.name


@pytest.mark.parametrize("magic, images", [("", 0), ("%matplotlib inline\n", 1)])
def test_the_runner_shows_a_figure_as_png_only_after_matplotlib_inline(tmp_path, magic, images):
    # A stock kernel shows a Figure that ends a cell as text alone until %matplotlib inline registers
    # the PNG formatter; the runner must do the same, or counting images proves nothing.
    source = magic + "from matplotlib.figure import Figure\nfig = Figure()\nfig.subplots()\nfig"
    notebook = {"nbformat": 4, "nbformat_minor": 5, "metadata": {}, "cells": []}
    notebook["cells"] = [{"cell_type": "code", "metadata": {}, "outputs": [], "source": source}]
    path = tmp_path / "figure.ipynb"
    path.write_text(json.dumps(notebook))
    _, outputs = run_notebook(path)
    assert len(outputs) == 1 and outputs[0]["text/plain"].startswith("<Figure size")
    assert sum("image/png" in o for o in outputs) == images


@pytest.fixture(scope="module")
def executed(tmp_path_factory, monkeypatch_module):
    monkeypatch_module.chdir(tmp_path_factory.mktemp("quickstart"))
    monkeypatch_module.setenv("MPLBACKEND", "Agg")
    return run_notebook(QUICKSTART)


@pytest.fixture(scope="module")
def quickstart(executed):
    return executed[0]


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
    legend = [t.get_text() for t in quickstart["bode"].axes[0].get_legend().get_texts()]
    assert "eq. (3.11), the thesis's model" in legend and "truth" not in legend  # the thesis's model, not the truth
    assert isinstance(quickstart["loop_figure"], Figure)
    for name in ("model", "record"):
        text = repr(quickstart[name])
        assert "array(" not in text and len(text) < 400, text
        assert quickstart[name]._repr_html_().startswith("<table>")


def test_quickstart_figures_show_in_a_stock_kernel(executed):
    images = [o["image/png"] for o in executed[1] if "image/png" in o]
    assert len(images) >= 2  # the Bode plot and the closed loop
    assert all(image.startswith(PNG_SIGNATURE) and len(image) > 10_000 for image in images)
