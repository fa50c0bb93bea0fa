"""The package's layout: imports run down the layers and never in a circle, modules stay small, one home per name.

The imports are read from the source (every ``import`` statement, also those inside functions and under
``TYPE_CHECKING``), so a lazy import that runs up a layer counts as much as one at the top of a module.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import re
from collections import defaultdict
from pathlib import Path

import pytest

import trms

PACKAGE = Path(trms.__file__).resolve().parent

#: The layers, lowest first: a module imports from its own layer or below, never above.
LAYERS: tuple[tuple[str, ...], ...] = (
    ("trms.errors", "trms.files", "trms.display", "trms.modes", "trms.reference", "trms.processes"),
    (
        "trms",
        "trms.record",
        "trms.plant",
        "trms.signals",
        "trms.rig",
    ),
    ("trms.identification", "trms.control", "trms.twin", "trms.present"),
    ("trms.envs", "trms.batch", "trms.rig.faked"),
    ("trms.measurement",),
    ("trms.calibration", "trms.worlds"),
    ("trms.experiments",),
    ("trms.report",),
    ("trms.cli",),
)
LONGEST_MODULE = 600
#: The package itself, in a layer of its own without the modules below it.
ROOT = "trms"
#: Names every module of a package defines as its part of a protocol (the command line's subcommands).
PROTOCOLS = {"trms.cli": ("add_arguments", "run")}


def _modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        elif parts[-1] == "__main__":
            continue
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def _layer(module: str) -> int:
    """The layer of ``module``: that of the longest entry of :data:`LAYERS` it is or lies inside (the package's root,
    ``trms``, holds only itself: a new module must be given a layer)."""
    best, found = -1, None
    for i, names in enumerate(LAYERS):
        for name in names:
            inside = module.startswith(name + ".") and name != ROOT
            if (module == name or inside) and len(name) > best:
                best, found = len(name), i
    if found is None:
        raise AssertionError(f"{module} is in no layer: add it to LAYERS in {Path(__file__).name}")
    return found


def _imports(module: str, path: Path) -> set[str]:
    """The package's modules that ``module`` imports (``from P import m`` counts as importing ``P.m`` alone)."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([node.module] if node.module else []))
            subs = [f"{base}.{alias.name}" for alias in node.names if f"{base}.{alias.name}" in MODULES]
            targets = subs if len(subs) == len(node.names) else [base, *subs]
        else:
            continue
        found.update(t for t in targets if t in MODULES and t != module)
    return found


EDGES = {m: _imports(m, p) for m, p in MODULES.items()}


def test_every_module_has_a_layer_and_imports_nothing_above_it():
    upward = [
        f"{m} (layer {_layer(m)}) imports {t} (layer {_layer(t)})"
        for m, targets in EDGES.items()
        for t in sorted(targets)
        if _layer(t) > _layer(m)
    ]
    assert upward == []


def _cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan's algorithm)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return out


def test_the_imports_have_no_circles():
    assert _cycles(EDGES) == []


def test_the_circle_finder_finds_a_circle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def test_the_layer_check_sees_an_upward_import_inside_a_function(tmp_path):
    path = tmp_path / "mod.py"
    path.write_text("def f():\n    from trms.report import reproduce\n")
    assert _imports("trms.twin.mod", path) == {"trms.report"}


@pytest.mark.parametrize("module", sorted(MODULES))
def test_no_module_is_over_600_lines(module):
    n = len(MODULES[module].read_text().splitlines())
    assert n <= LONGEST_MODULE, f"{module} has {n} lines"


def _readme_layers(text: str) -> list[str]:
    """The README's layer list: one text per "- Layer N:" item, in order."""
    items = re.split(r"^- Layer \d+: ", text, flags=re.M)[1:]
    return [item.split("\n\n")[0] for item in items]


def test_the_readme_names_every_layer_in_its_order():
    listed = _readme_layers((PACKAGE.parent / "README.md").read_text())
    assert len(listed) == len(LAYERS)
    for i, (names, text) in enumerate(zip(LAYERS, listed)):
        named = set(re.findall(r"`(trms(?:\.\w+)*)`", text))
        assert set(names) <= named, f"layer {i}: the README does not name {sorted(set(names) - named)}"


def test_the_readme_check_sees_a_missing_layer():
    text = "- Layer 0: `trms.errors`\n- Layer 1: `trms.record`\n\nmore"
    assert _readme_layers(text) == ["`trms.errors`\n", "`trms.record`"]


def test_a_module_outside_every_layer_is_caught():
    with pytest.raises(AssertionError, match="in no layer"):
        _layer("trms.newcomer")
    assert _layer("trms") == _layer("trms.record") and _layer("trms.twin.twin") == _layer("trms.twin")


def _private_imports(module: str, path: Path) -> list[str]:
    """``from trms.x import _name`` in ``module``: an underscore name taken from another module."""
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("trms"):
            private = [a.name for a in node.names if a.name.startswith("_") and not a.name.startswith("__")]
            if any(part.startswith("_") and not part.startswith("__") for part in node.module.split(".")):
                private = [a.name for a in node.names]  # a private module: every name taken from it
            out += [f"{module} takes {node.module}.{name}" for name in private]
    return out


def test_no_module_takes_an_underscore_name_from_another():
    assert [line for m, p in MODULES.items() for line in _private_imports(m, p)] == []


def test_the_private_import_check_sees_one(tmp_path):
    path = tmp_path / "mod.py"
    path.write_text("def f():\n    from trms.twin.interval import _hidden, shown\n    from trms.twin._inner import x\n")
    got = _private_imports("trms.twin.mod", path)
    assert got == ["trms.twin.mod takes trms.twin.interval._hidden", "trms.twin.mod takes trms.twin._inner.x"]


def _definitions(paths: dict[str, Path]) -> dict[str, list[str]]:
    """Public module-level functions and classes by name -> the modules defining them (overloads once; a package's
    protocol names left out)."""
    homes: dict[str, list[str]] = defaultdict(list)
    for module, path in paths.items():
        protocol = next((names for pkg, names in PROTOCOLS.items() if module.startswith(pkg + ".")), ())
        seen = set()
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                name = node.name
                if name.startswith("_") or name in protocol or name in seen:
                    continue
                seen.add(name)
                homes[name].append(module)
    return homes


def test_every_public_name_is_defined_once():
    assert {n: m for n, m in _definitions(MODULES).items() if len(m) > 1} == {}


def test_the_definition_check_sees_a_name_defined_twice(tmp_path):
    (tmp_path / "a.py").write_text("def fit_percent():\n    pass\n")
    (tmp_path / "b.py").write_text("class Other:\n    pass\n\n\ndef fit_percent():\n    pass\n")
    homes = _definitions({"trms.a": tmp_path / "a.py", "trms.b": tmp_path / "b.py"})
    assert homes["fit_percent"] == ["trms.a", "trms.b"] and homes["Other"] == ["trms.b"]


def test_every_public_name_has_one_home():
    """A class or function is public (in ``__all__``) in one module, or also in packages above that module."""
    homes: dict[int, set[str]] = defaultdict(set)
    names: dict[int, str] = {}
    for info in pkgutil.walk_packages(trms.__path__, "trms."):
        if info.name.endswith("__main__"):
            continue
        module = importlib.import_module(info.name)
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name)
            if inspect.isclass(obj) or inspect.isfunction(obj):
                homes[id(obj)].add(info.name)
                names[id(obj)] = name
    shared = []
    for key, where in homes.items():
        deepest = max(where, key=len)
        if any(not deepest.startswith(w + ".") and w != deepest for w in where):
            shared.append(f"{names[key]}: {', '.join(sorted(where))}")
    assert shared == []
