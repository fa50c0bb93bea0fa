"""The documentation builds without a warning, the tutorial runs, and every docstring example passes."""

import doctest
import importlib
import pkgutil
import re
import subprocess
import sys
from pathlib import Path

import pytest

import trms

ROOT = Path(__file__).resolve().parents[1]
MODULES = sorted(m.name for m in pkgutil.walk_packages(trms.__path__, "trms."))


def test_the_docs_build_strictly_without_warnings(tmp_path):
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "mkdocs",
            "build",
            "--strict",
            "-q",
            "-f",
            str(ROOT / "mkdocs.yml"),
            "-d",
            str(tmp_path / "site"),
        ],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert out.returncode == 0, out.stderr
    assert "WARNING" not in out.stderr, out.stderr
    page = (tmp_path / "site" / "api" / "envs" / "index.html").read_text()
    assert "TaskRunner" in page  # the API reference is generated from the docstrings
    # Everything a page loads ships with the site (offline readers see the highlighting too): no script, style sheet
    # or image from elsewhere, and the code highlighted at build time.
    pages = list((tmp_path / "site").rglob("*.html"))
    remote = re.compile(r'<(?:script|link|img)[^>]*(?:src|href)="(?:https?:)?//')
    assert pages and not [p.name for p in pages if remote.search(p.read_text())]
    tutorial = (tmp_path / "site" / "tutorial" / "index.html").read_text()
    assert '<div class="highlight">' in tutorial and '<span class="kn">import</span>' in tutorial
    assert (tmp_path / "site" / "css" / "pygments.css").stat().st_size > 1000


def test_the_tutorials_code_runs_as_one_script():
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "tutorial.md").read_text(), re.S)
    assert len(blocks) >= 4
    scope: dict = {}
    exec(compile("\n".join(blocks), "docs/tutorial.md", "exec"), scope)  # noqa: S102
    assert scope["settled"] and type(scope["fig"]).__name__ == "Figure"


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.failed == 0


def test_doctests_exist_across_the_package():
    finder = doctest.DocTestFinder()
    n = sum(len(t.examples) for name in MODULES for t in finder.find(importlib.import_module(name)))
    assert n >= 20
