"""The built wheel works on its own: installed outside the source tree, it finds its model.

The wheel is built from this checkout (``pip wheel --no-deps --no-build-isolation``: no
network), installed with ``--no-deps --target`` into a temporary folder, and run from
another folder with only that folder on ``PYTHONPATH``, so the installed copy -- not the
source tree -- is imported and its packaged MJCF is the model loaded.
"""

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("wheel")
    build = subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            str(ROOT),
            "--no-deps",
            "--no-build-isolation",
            "-w",
            str(tmp / "dist"),
            "-q",
        ],
        capture_output=True,
        text=True,
        cwd=tmp,
    )
    assert build.returncode == 0, build.stderr
    wheel = next((tmp / "dist").glob("trms-*.whl"))
    site = tmp / "site"
    inst = subprocess.run(
        [sys.executable, "-m", "pip", "install", "--no-deps", "--no-compile", "--target", str(site), str(wheel), "-q"],
        capture_output=True,
        text=True,
        cwd=tmp,
    )
    assert inst.returncode == 0, inst.stderr
    user = tmp / "user"
    user.mkdir()
    env = {**os.environ, "PYTHONPATH": str(site), "PYTHONNOUSERSITE": "1"}
    return wheel, site, user, env


def _run(args, user, env):
    return subprocess.run([sys.executable, *args], cwd=user, env=env, capture_output=True, text=True)


@pytest.mark.slow
def test_the_wheel_ships_the_model_and_the_command(installed):
    wheel = installed[0]
    with zipfile.ZipFile(wheel) as zf:
        names = zf.namelist()
        entry = next(n for n in names if n.endswith("entry_points.txt"))
        assert "trms = trms.cli:main" in zf.read(entry).decode()
    assert "trms/models/trms.xml" in names and "trms/py.typed" in names


@pytest.mark.slow
def test_the_installed_copy_runs_from_another_folder_with_its_own_model(installed):
    _, site, user, env = installed
    probe = _run(
        ["-c", "import trms, trms.twin.model as m; print(trms.__file__); print(m.DEFAULT_MODEL_PATH)"], user, env
    )
    assert probe.returncode == 0, probe.stderr
    package, model = probe.stdout.split()
    assert Path(package).is_relative_to(site) and not Path(package).is_relative_to(ROOT)
    assert Path(model) == site / "trms" / "models" / "trms.xml" and Path(model).is_file()
    demo = _run(["-m", "trms.cli", "demo", "--config", "1dof", "--duration", "20", "--out", "demo"], user, env)
    assert demo.returncode == 0, demo.stderr
    assert "hover voltages" in demo.stdout and (user / "demo" / "record.npz").is_file()
    ident = _run(
        ["-m", "trms.cli", "identify", "demo/record.npz", "--orders", "2", "2", "1", "1", "--out", "ident"], user, env
    )
    assert ident.returncode == 0, ident.stderr


@pytest.mark.slow
def test_the_heavy_optional_dependencies_are_extras(installed):
    wheel = installed[0]
    with zipfile.ZipFile(wheel) as zf:
        meta = zf.read(next(n for n in zf.namelist() if n.endswith("METADATA"))).decode()
    requires = [line.split(":", 1)[1].strip() for line in meta.splitlines() if line.startswith("Requires-Dist:")]
    core = [r for r in requires if "extra ==" not in r]
    assert "mujoco==3.17.0" in core
    assert not any(r.startswith(("imageio", "plotly")) or "[sysid]" in r for r in core), core
    assert any(r.startswith("mujoco[sysid]") and 'extra == "sysid"' in r for r in requires)
    assert any(r.startswith("imageio-ffmpeg") and 'extra == "video"' in r for r in requires)
    assert not any(r.startswith(("osqp", "slycot")) for r in core), core
    assert any(r.startswith("osqp") and 'extra == "control"' in r for r in requires)


def test_the_core_runs_without_the_extras():
    """The main job's modules import and a twin runs with the extras' packages absent."""
    code = (
        "import sys\n"
        "for name in ('plotly', 'imageio_ffmpeg', 'mujoco.sysid', 'jinja2', 'tabulate', 'osqp', 'slycot'):\n"
        "    sys.modules[name] = None  # importing it now raises ImportError\n"
        "import trms, trms.twin, trms.report, trms.cli, trms.calibration, trms.control\n"
        "from trms.twin import Twin\n"
        "tw = Twin('1dof', 0.1)\n"
        "rec = tw.run([tw.operating_point.inputs] * 20)\n"
        "print(rec.outputs.shape)\n"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["(20,", "1)"]
