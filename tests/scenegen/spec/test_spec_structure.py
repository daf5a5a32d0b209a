"""The spec package's shape: small modules, imports at module top, no import cycle, no private
name used across modules, and nothing from the renderer, the pipeline or the dataset layer."""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
SPEC = ROOT / "scenegen" / "spec"
FILES = sorted(SPEC.rglob("*.py"))
MAX_LINES = 400
#: What scenegen.spec may import from the project (besides itself).
ALLOWED = ("scenegen.errors", "scenegen.located_yaml", "scenegen.geometry", "scenegen.assets",
           "scenegen.imaging")
FORBIDDEN = ("mitsuba", "drjit", "scenegen.render", "scenegen.pipeline", "scenegen.dataset")


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in FILES}


def imports(path: Path):
    """(node, imported module or 'module.name') of every import in the file."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield node, a.name
        elif isinstance(node, ast.ImportFrom) and node.level == 0:
            for a in node.names:
                full = f"{node.module}.{a.name}"
                yield node, full if full in MODULES else node.module


@pytest.mark.parametrize("path", FILES, ids=lambda p: module_name(p))
def test_module_is_small(path):
    assert len(path.read_text().splitlines()) <= MAX_LINES


@pytest.mark.parametrize("path", FILES, ids=lambda p: module_name(p))
def test_imports_are_at_module_top(path):
    tree = ast.parse(path.read_text())
    top = {id(n) for n in tree.body}
    local = [n.lineno for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom))
             and id(n) not in top]
    assert not local, f"function-local imports at lines {local}"


@pytest.mark.parametrize("path", FILES, ids=lambda p: module_name(p))
def test_imports_only_allowed_project_packages(path):
    for node, name in imports(path):
        assert not name.startswith(FORBIDDEN), f"line {node.lineno}: {name}"
        if name.startswith("scenegen.") and not name.startswith("scenegen.spec"):
            assert name.startswith(ALLOWED), f"line {node.lineno}: {name}"


@pytest.mark.parametrize("path", FILES, ids=lambda p: module_name(p))
def test_no_private_name_crosses_a_module(path):
    tree = ast.parse(path.read_text())
    bad = [f"line {n.lineno}: {n.module}.{a.name}" for n in ast.walk(tree)
           if isinstance(n, ast.ImportFrom) and (n.module or "").startswith("scenegen")
           for a in n.names if a.name.startswith("_") and a.name != "__future__"]
    aliases = {a.asname or a.name for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom))
               for a in n.names}
    bad += [f"line {n.lineno}: {n.value.id}.{n.attr}" for n in ast.walk(tree)
            if isinstance(n, ast.Attribute) and isinstance(n.value, ast.Name)
            and n.value.id in aliases and n.attr.startswith("_") and not n.attr.startswith("__")]
    assert not bad, bad


def test_no_import_cycle_inside_the_spec():
    graph = {name: {dep for _, dep in imports(path) if dep in MODULES and dep != name}
             for name, path in MODULES.items()}
    # a package's __init__ runs before its submodules: a submodule importing its own package's
    # face would be a cycle, so no edge is dropped here
    state: dict[str, int] = {}

    def visit(n, trail):
        if state.get(n) == 1:
            raise AssertionError("import cycle: " + " -> ".join(trail + [n]))
        if state.get(n) == 2:
            return
        state[n] = 1
        for d in sorted(graph[n]):
            visit(d, trail + [n])
        state[n] = 2

    for n in sorted(graph):
        visit(n, [])
