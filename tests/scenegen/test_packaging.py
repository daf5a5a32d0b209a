"""pip install users get the example scenes, gate files, their own-estimator example and the
baselines: the wheel (pip wheel --no-deps, built from a copy of the tracked tree) holds scenes/,
gates/, examples/ and baselines/ as package data under scenegen/examples/, and `scenegen
examples` finds them through importlib.resources."""
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

from scenegen.bundled import copy_examples, example_files
from scenegen.cli import main

ROOT = Path(__file__).resolve().parents[2]
FOLDERS = ("scenes", "gates", "examples", "baselines")


def _files(folder: str) -> list[Path]:
    return [p for p in (ROOT / folder).rglob("*") if p.is_file() and "__pycache__" not in p.parts]


def _tracked_copy(dest: Path) -> None:
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    for rel in filter(None, files.decode().split("\0")):
        src, dst = ROOT / rel, dest / rel
        dst.parent.mkdir(parents=True, exist_ok=True)
        if src.is_symlink():
            dst.symlink_to(src.readlink())
        elif src.is_file():
            shutil.copy2(src, dst)


def test_the_wheel_holds_the_scenes_and_gates(tmp_path):
    src = tmp_path / "src"
    _tracked_copy(src)
    r = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
                        "-w", str(tmp_path / "dist"), str(src)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-3000:]
    (wheel,) = (tmp_path / "dist").glob("scenegen-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    for folder in FOLDERS:
        want = {f"scenegen/examples/{folder}/{p.relative_to(ROOT / folder).as_posix()}" for p in _files(folder)}
        assert want and want <= names, sorted(want - names)
    assert "scenegen/examples/scenes/demo.yaml" in names and "scenegen/examples/gates/geometry.yaml" in names
    assert {"scenegen/examples/examples/my_fmatrix.py", "scenegen/examples/examples/methods.yaml",
            "scenegen/examples/baselines/calib_checkerboard.json"} <= names
    assert "scenegen/bundled.py" in names and "recon_eval/cli/__init__.py" in names
    # installed, the examples are found where the package is (not in this checkout)
    site = tmp_path / "site"
    r = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(site), str(wheel)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-3000:]
    code = ("import sys; sys.path.insert(0, sys.argv[1]); import scenegen.bundled as b; "
            "f = b.example_files(); assert all(p.startswith(sys.argv[1]) for _, p in f), f; print(len(f))")
    r = subprocess.run([sys.executable, "-c", code, str(site)], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-3000:]
    assert int(r.stdout) == sum(len(_files(f)) for f in FOLDERS)


def test_examples_are_found_and_copied(tmp_path, capsys):
    found = example_files()
    assert ("scenes", str(Path(str(found[0][1])))) == found[0] and {k for k, _ in found} == set(FOLDERS)
    assert {Path(p).name for _, p in found} >= {"demo.yaml", "geometry.yaml", "orbit_objects.yaml"}
    assert main(["examples"]) == 0 and "demo.yaml" in capsys.readouterr().out
    n = copy_examples(tmp_path / "ex")
    assert n == sum(len(_files(f)) for f in FOLDERS)
    for rel in ("scenes/demo.yaml", "examples/my_fmatrix.py", "examples/methods.yaml", "examples/gates_my_fmatrix.yaml",
                "baselines/calib_checkerboard.json"):  # what docs/ci.md's worked example and workflow name
        assert (tmp_path / "ex" / rel).read_bytes() == (ROOT / rel).read_bytes(), rel
    assert main(["examples", "--copy", str(tmp_path / "ex")]) == 2  # refuses to overwrite
