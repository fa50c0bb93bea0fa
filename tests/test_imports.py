"""The one import root keeps python-control importable as ``control`` from the repository root."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_control_is_python_control_from_repository_root():
    out = subprocess.run(
        [sys.executable, "-c", "import control; control.dlqr; print(control.__file__)"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    assert "site-packages" in out.stdout
    assert not Path(out.stdout.strip()).resolve().is_relative_to(ROOT / "trms")


def test_package_imports_without_mujoco_for_toolkits():
    code = "import sys, trms, trms.plant, trms.reference; assert 'mujoco' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True)
