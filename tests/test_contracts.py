"""The layers of the code base, enforced (docs/architecture.md): who may import whom, no import
cycle, no function-local import but of a heavy optional dependency with its reason, no private
name used across modules, no module over the size limit.

Read from the source with ``ast`` (nothing is imported), so a violation anywhere fails here.
"""
from __future__ import annotations

import ast
from functools import lru_cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("scenegen", "recon_eval")

#: Modules that are only Mitsuba's business: imported by scenegen.render alone.
MITSUBA = ("mitsuba", "drjit")
#: What recon_eval may take from scenegen: the numpy core, the dataset contract, the errors and
#: the located YAML layer (gate files).
RECON_EVAL_MAY_IMPORT = ("scenegen.geometry", "scenegen.dataset", "scenegen.errors", "scenegen.located_yaml")
#: Heavy or optional dependencies that may be imported inside a function (with a reason in a
#: comment on the line or the line above): import cost or availability, never to dodge a cycle.
LAZY_ALLOWED = ("cv2", "mitsuba", "drjit", "matplotlib", "dask", "distributed", "pycolmap", "trimesh", "rich",
                "scipy",
                "mujoco",  # the rigid-body engine: only a spec with `placement:` runs it (scenegen.physics)
                "open3d",  # the `runners` extra: only the alignment and TSDF fusion runners need it (recon_eval.runners.objects_align, .tsdf_fusion)
                "scenegen.render.scene", "scenegen.render.raycast", "scenegen.render.drjit_ops")
#: The command line loads each command's implementation when the command runs, so that
#: ``scenegen --help`` costs less than ``import numpy`` (docs/performance.md, "Start-up").
LAZY_ALLOWED_IN = {"scenegen.cli": ("scenegen",),
                   # the drop (MuJoCo, trimesh) loads only for a spec with `placement:`
                   "scenegen.spec.parse.placement": ("scenegen.spec.parse.placement_drop",)}
MAX_MODULE_LINES = 400  # "no module over 400 lines" (docs/architecture.md)


def _module_name(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(parts)


@lru_cache(maxsize=1)
def modules() -> dict[str, Path]:
    return {_module_name(p): p for pkg in PACKAGES for p in sorted((ROOT / pkg).rglob("*.py"))}


def _resolve(mod: str, node: ast.ImportFrom) -> str:
    if node.level == 0:
        return node.module or ""
    base = mod.split(".")
    is_pkg = modules()[mod].name == "__init__.py"
    base = base if is_pkg else base[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


@lru_cache(maxsize=None)
def imports(mod: str) -> tuple[tuple[str, tuple[str, ...], int, bool], ...]:
    """(imported module, names, line, function-local) for every import statement of ``mod``."""
    tree = ast.parse(modules()[mod].read_text(encoding="utf-8"))
    out = []

    def visit(node, local: bool):
        for child in ast.iter_child_nodes(node):
            inner = local or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            if isinstance(child, ast.Import):
                for a in child.names:
                    out.append((a.name, (), child.lineno, local))
            elif isinstance(child, ast.ImportFrom):
                target = _resolve(mod, child)
                names = tuple(a.name for a in child.names)
                out.append((target, names, child.lineno, local))
            visit(child, inner)

    visit(tree, False)
    return tuple(out)


def _internal(target: str, names=()) -> list[str]:
    """The project modules an import statement brings in (``from pkg import sub`` counts sub)."""
    mods = modules()
    found = []
    if target in mods:
        found.append(target)
    for n in names:
        if f"{target}.{n}" in mods:
            found.append(f"{target}.{n}")
    return found


def _starts(name: str, prefixes) -> bool:
    return any(name == p or name.startswith(p + ".") for p in prefixes)


def test_the_source_tree_is_read():
    assert len(modules()) > 100 and "scenegen.geometry.camera" in modules() and "recon_eval" in modules()


def test_only_render_imports_mitsuba():
    bad = [f"{m}:{line} imports {t}" for m in modules() for t, _, line, _ in imports(m)
           if _starts(t, MITSUBA) and not _starts(m, ("scenegen.render",))]
    assert not bad, "\n".join(bad)


#: What each scenegen layer may import from the project besides itself (docs/architecture.md).
SCENEGEN_LAYERS = {
    "scenegen.errors": (),
    "scenegen.bundled": (),  # the package data (example scenes and gates), standard library only
    "scenegen.located_yaml": ("scenegen.errors",),
    "scenegen.geometry": (),
    # decoding without the native libraries' own lines (OpenCV, OpenEXR): the one helper that
    # silences them, below the dataset's codecs and the asset loaders that both decode images
    "scenegen.quiet": (),
    "scenegen.dataset": ("scenegen.geometry", "scenegen.quiet"),
    "scenegen.assets": ("scenegen.geometry", "scenegen.quiet"),
    "scenegen.imaging": ("scenegen.geometry", "scenegen.dataset"),
    "scenegen.crossview": ("scenegen.geometry", "scenegen.dataset"),
    # the rigid-body drop of `placement:`: arrays in, settled poses out (MuJoCo)
    "scenegen.physics": ("scenegen.geometry",),
    # a sensor kind (scenegen.spec.sensors) names what it writes in the dataset's terms (truth keys,
    # a stream's schema and StreamWriter)
    "scenegen.spec": ("scenegen.errors", "scenegen.located_yaml", "scenegen.geometry", "scenegen.assets",
                      "scenegen.imaging", "scenegen.dataset", "scenegen.physics"),
    # the renderer implements the dataset's visibility rule (dataset.crossview.OCCLUSION_REL_TOL)
    # and casts the truth kinds the dataset stores (dataset.truth.TruthKind)
    "scenegen.render": ("scenegen.errors", "scenegen.geometry", "scenegen.assets", "scenegen.spec",
                        "scenegen.dataset.crossview", "scenegen.dataset.truth"),
    "scenegen.export": ("scenegen.geometry", "scenegen.dataset"),
    # the preview composes its sheet with the gallery's code (scenegen.export.sheet), the layer below
    "scenegen.pipeline": ("scenegen.errors", "scenegen.geometry", "scenegen.dataset", "scenegen.assets",
                          "scenegen.imaging", "scenegen.crossview", "scenegen.spec", "scenegen.render",
                          "scenegen.export"),
}


@pytest.mark.parametrize("layer", sorted(SCENEGEN_LAYERS))
def test_scenegen_layers(layer):
    """Each layer imports only what lies below it."""
    allowed = SCENEGEN_LAYERS[layer] + (layer,)
    mods = [m for m in modules() if _starts(m, (layer,))]
    assert mods, f"layer {layer} does not exist"
    bad = [f"{m}:{line} imports {t}" for m in mods for t, _, line, _ in imports(m)
           if _starts(t, PACKAGES) and t != "scenegen" and not _starts(t, allowed)]
    assert not bad, "\n".join(bad)


def test_every_scenegen_module_is_in_a_layer():
    loose = [m for m in modules() if _starts(m, ("scenegen",)) and m not in ("scenegen", "scenegen.cli", "scenegen.api")
             and not _starts(m, tuple(SCENEGEN_LAYERS))]
    assert not loose, loose


def test_metrics_are_pure():
    """recon_eval's metrics import no reader, runner, report, task, gate or command."""
    bad = [f"{m}:{line} imports {t}" for m in modules() if _starts(m, ("recon_eval.metrics",))
           for t, _, line, _ in imports(m)
           if _starts(t, ("recon_eval",)) and not _starts(t, ("recon_eval.metrics", "recon_eval.arrays",
                                                                "recon_eval.errors"))]
    assert any(_starts(m, ("recon_eval.metrics",)) for m in modules()) and not bad, "\n".join(bad)


def test_recon_eval_takes_only_the_contract_from_scenegen():
    bad = [f"{m}:{line} imports {t}" for m in modules() if _starts(m, ("recon_eval",))
           for t, _, line, _ in imports(m) if _starts(t, ("scenegen",)) and not _starts(t, RECON_EVAL_MAY_IMPORT)]
    assert not bad, "\n".join(bad)


def test_nothing_imports_the_pipeline_back():
    bad = [f"{m}:{line} imports {t}" for m in modules()
           if not _starts(m, ("scenegen.pipeline", "scenegen.cli", "scenegen.api"))
           for t, _, line, _ in imports(m) if _starts(t, ("scenegen.pipeline",))]
    assert not bad, "\n".join(bad)


def test_no_import_cycle():
    graph = {m: sorted({d for t, names, _, _ in imports(m) for d in _internal(t, names) if d != m})
             for m in modules()}
    # a package's __init__ re-exporting its submodules is not a cycle of theirs: an edge from a
    # package into its own submodule is dropped
    graph = {m: [d for d in ds if not d.startswith(m + ".")] for m, ds in graph.items()}
    index, low, stack, on, cycles, counter = {}, {}, [], set(), [], [0]

    def strongconnect(v):  # Tarjan
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                strongconnect(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in graph:
        if v not in index:
            strongconnect(v)
    assert not cycles, cycles


def test_function_local_imports_are_heavy_optional_dependencies_with_a_reason():
    bad = []
    for m, path in modules().items():
        lines = path.read_text(encoding="utf-8").splitlines()
        for t, names, line, local in imports(m):
            if not local or t == "__future__":
                continue
            if not _starts(t, LAZY_ALLOWED + LAZY_ALLOWED_IN.get(m, ())):
                bad.append(f"{m}:{line} imports {t} inside a function")
                continue
            here, above = lines[line - 1], lines[line - 2] if line >= 2 else ""
            if "#" not in here and not above.strip().startswith("#"):
                bad.append(f"{m}:{line} imports {t} inside a function without a comment saying why")
    assert not bad, "\n".join(bad)


def test_no_private_name_is_used_across_modules():
    bad = []
    for m in modules():
        for t, names, line, _ in imports(m):
            if not _starts(t, PACKAGES):
                continue
            priv = [n for n in names if n.startswith("_") and not n.startswith("__")]
            priv += [t] if any(p.startswith("_") and not p.startswith("__") for p in t.split(".")) else []
            if priv:
                bad.append(f"{m}:{line} takes {priv} from {t}")
        # module._name attribute access on an imported project module
        tree = ast.parse(modules()[m].read_text(encoding="utf-8"))
        aliases = {}
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                for a in node.names:
                    if _starts(a.name, PACKAGES):
                        aliases[a.asname or a.name.split(".")[0]] = a.name
            elif isinstance(node, ast.ImportFrom):
                base = _resolve(m, node)
                for a in node.names:
                    if f"{base}.{a.name}" in modules():
                        aliases[a.asname or a.name] = f"{base}.{a.name}"
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in aliases
                    and node.attr.startswith("_") and not node.attr.startswith("__")):
                bad.append(f"{m}:{node.lineno} uses {aliases[node.value.id]}.{node.attr}")
    assert not bad, "\n".join(bad)


def test_modules_stay_small():
    big = [f"{m}: {n} lines" for m, p in modules().items()
           if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_MODULE_LINES]
    assert not big, "\n".join(big)
