"""Lint, format and types with the configuration in pyproject.toml.

``ruff check``, ``ruff format --check`` and ``mypy trms`` must each report nothing.

The tools are the ``lint`` extra's pins (installed by scripts/bootstrap.sh), run from the virtual
environment that runs the tests.
"""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def _run(*args: str) -> subprocess.CompletedProcess:
    tool = BIN / args[0]
    assert tool.exists(), f"{tool} is missing: install the lint extra (bash scripts/test.sh does)"
    return subprocess.run([str(tool), *args[1:]], cwd=ROOT, capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize(
    "command",
    [("ruff", "check", "--no-cache", "."), ("ruff", "format", "--check", "--no-cache", "."), ("mypy", "trms")],
    ids=["ruff check", "ruff format", "mypy"],
)
def test_the_code_is_clean(command):
    out = _run(*command)
    assert out.returncode == 0, f"{' '.join(command)} failed:\n{out.stdout}\n{out.stderr}"
