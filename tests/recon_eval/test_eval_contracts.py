"""recon_eval's layer contract, checked on the source (docs/architecture.md):

* from scenegen it imports only ``scenegen.geometry``, ``scenegen.dataset``, ``scenegen.errors`` and
  ``scenegen.located_yaml`` (never Mitsuba / Dr.Jit, the spec, the renderer or the pipeline);
* ``recon_eval.metrics`` imports no reader, task, runner, report, CI or CLI module;
* no module over 400 lines, no import cycle, no private name reached across modules;
* imports at module top, except a heavy optional dependency, with a comment saying why."""
from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCENEGEN_ALLOWED = ("scenegen.geometry", "scenegen.dataset", "scenegen.errors", "scenegen.located_yaml")
FORBIDDEN_TOP = ("mitsuba", "drjit")
#: Heavy optional dependencies a function may import where it needs them (with a comment).
LOCAL_IMPORT_OK = ("cv2", "matplotlib", "pycolmap", "rich", "scipy.optimize")
MAX_LINES = 400
OTHER_LAYERS = tuple(f"recon_eval.{x}" for x in ("readers", "tasks", "runners", "report", "ci", "cli"))


def modules(root: Path = ROOT) -> dict[str, tuple[Path, ast.Module]]:
    """module name -> (file, syntax tree) of every module of ``root``/recon_eval."""
    out = {}
    for p in sorted((root / "recon_eval").rglob("*.py")):
        rel = p.relative_to(root).with_suffix("")
        name = ".".join(rel.parts[:-1] if rel.name == "__init__" else rel.parts)
        out[name] = (p, ast.parse(p.read_text(), str(p)))
    return out


MODULES = modules()


def imports(tree):
    """(module name, imported names, node, at top) of every import."""
    top = set(map(id, tree.body))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield a.name, (), node, id(node) in top
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            yield node.module, tuple(a.name for a in node.names), node, id(node) in top
        else:
            continue


def violations(rule) -> list[str]:
    return [v for name, (p, tree) in MODULES.items() for v in rule(name, p, tree)]


def test_module_sizes():
    assert violations(lambda name, p, tree: [f"{p}: {n} lines" for n in [len(p.read_text().splitlines())]
                                             if n > MAX_LINES]) == []


def _layers(name, p, tree):
    for mod, names, node, _ in imports(tree):
        where = f"{p}:{node.lineno}: {mod}"
        if mod.split(".")[0] in FORBIDDEN_TOP:
            yield where
        if mod == "scenegen":
            yield from (f"{where}.{n}" for n in names if not f"scenegen.{n}".startswith(SCENEGEN_ALLOWED))
        elif mod.split(".")[0] == "scenegen" and not mod.startswith(SCENEGEN_ALLOWED):
            yield where
        if name.startswith("recon_eval.metrics") and mod.startswith(OTHER_LAYERS):
            yield where


def test_scenegen_layers_no_mitsuba_and_pure_metrics():
    assert violations(_layers) == []


def _private(name, p, tree):
    for mod, names, node, _ in imports(tree):
        if mod.split(".")[0] in ("recon_eval", "scenegen"):
            if any(_is_private(n) for n in names) or any(_is_private(part) for part in mod.split(".")):
                yield f"{p}:{node.lineno}: from {mod} import {', '.join(names)}"
    for node in ast.walk(tree):  # obj._private where obj is not self / cls
        if (isinstance(node, ast.Attribute) and _is_private(node.attr)
                and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))):
            yield f"{p}:{node.lineno}: .{node.attr} of another object"


def _is_private(n: str) -> bool:
    return n.startswith("_") and not n.startswith("__")


def test_no_private_name_across_modules():
    assert violations(_private) == []


def _local_imports(name, p, tree):
    lines = p.read_text().splitlines()
    for mod, _, node, top in imports(tree):
        if top:
            continue
        if not mod.startswith(LOCAL_IMPORT_OK):
            yield f"{p}:{node.lineno}: local import of {mod}"
        elif "#" not in lines[node.lineno - 1]:
            yield f"{p}:{node.lineno}: say why {mod} is imported here"


def test_imports_at_module_top():
    assert violations(_local_imports) == []


def test_no_import_cycle():
    graph = {}
    for name, (_, tree) in MODULES.items():
        deps = set()
        for mod, names, _, top in imports(tree):
            if not top or not mod.startswith("recon_eval"):
                continue
            for target in [mod] + [f"{mod}.{n}" for n in names]:
                if target in MODULES and target != name:
                    deps.add(target)
        # importing a submodule runs its packages' __init__ first
        graph[name] = {d for d in deps} | {".".join(d.split(".")[:k]) for d in deps for k in range(2, d.count(".") + 1)
                                            if ".".join(d.split(".")[:k]) in MODULES and ".".join(d.split(".")[:k]) != name
                                            and not name.startswith(".".join(d.split(".")[:k]) + ".")}
    state, stack = {}, []

    def visit(n):
        state[n] = "open"
        stack.append(n)
        for d in sorted(graph[n]):
            if state.get(d) == "open":
                raise AssertionError("import cycle: " + " -> ".join(stack[stack.index(d):] + [d]))
            if d not in state:
                visit(d)
        stack.pop()
        state[n] = "done"

    for n in sorted(graph):
        if n not in state:
            visit(n)


def test_cli_registry_and_families_agree():
    import importlib

    from recon_eval.cli.registry import COMMANDS

    families = {c.family for c in COMMANDS}
    for fam in families:
        impl = importlib.import_module(f"recon_eval.cli.{fam}").COMMANDS
        assert set(impl) == {c.name for c in COMMANDS if c.family == fam}, fam
    assert {n.split(".")[-1] for n in MODULES if n.startswith("recon_eval.cli.")} == families | {
        "registry", "scored", "common"}
