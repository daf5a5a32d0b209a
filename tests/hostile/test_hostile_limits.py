"""The limits of docs/scene_spec.md ("Limits") are the code's, are checked in well under a second,
and the odd inputs of issue 18 that are not files of the corpora: a NUL byte in a path given on
the command line, ``--json`` naming a folder, names at the length limit."""
from __future__ import annotations

import re
import sys
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from hostile_data import run_cli  # noqa: E402
from spec_corpus import BASE, sub  # noqa: E402

from scenegen import located_yaml  # noqa: E402
from scenegen.assets import asset_refs, checks  # noqa: E402
from scenegen.dataset import layout  # noqa: E402
from scenegen.errors import SpecError  # noqa: E402
from scenegen.located_yaml import source  # noqa: E402
from scenegen.spec import parse_spec  # noqa: E402
from scenegen.spec.model import limits  # noqa: E402

DOC = (Path(__file__).parents[2] / "docs" / "scene_spec.md").read_text()
LIMITS_TABLE = DOC[DOC.index("## Limits"):DOC.index("## Top level")]


def test_a_spec_name_fits_a_dataset_file_name():
    assert located_yaml.MAX_NAME_LEN == layout.MAX_NAME_LEN
    name = "n" * located_yaml.MAX_NAME_LEN
    spec = parse_spec(sub("  - name: ball", f"  - name: {name}")(BASE))
    assert layout.mesh_path(spec.objects[1].name) == f"scene/meshes/{name}.ply"


@pytest.mark.parametrize("value,shown", [
    (limits.MAX_IMAGE_SIDE_PX, "16,384 px"), (limits.MAX_IMAGE_PIXELS, "67,108,864"), (limits.MAX_SPP, "65,536"),
    (limits.MAX_VIEWS, "1,000,000"), (limits.MAX_BOARD_SIDE, "512"), (checks.MAX_TEXTURE_PIXELS, "2^26"),
    (limits.MAX_TRACKS, "1,000,000"), (asset_refs.MAX_GLTF_NODE_DEPTH, "1,024 levels"),
    (checks.MAX_MESH_FACES, "50,000,000"), (checks.MAX_MESH_FILE_BYTES, "4 GiB"),
    (located_yaml.MAX_NAME_LEN, "128 characters"), (source.MAX_SOURCE_BYTES, "1 MiB")])
def test_every_limit_is_documented_with_its_value(value, shown):
    assert shown in LIMITS_TABLE
    number = re.sub(r"[^0-9^]", "", shown.split()[0])
    expected = {"2^26": 1 << 26}.get(number, None)
    unit = {"GiB": 2**30, "MiB": 2**20}.get(shown.split()[-1], 1)
    assert value == (expected if expected is not None else int(number) * unit)


@pytest.mark.parametrize("edit", [
    sub("size: [64, 48]", "size: [100000, 100000]"), sub("size: [64, 48]", "size: [4000000000, 1]"),
    sub("spp: 4", "spp: 1e40"), sub("spp: 4", "spp: 1000000000"), sub("count: 3}", "count: 100000000}"),
    sub("elevations_deg: [30], count: 3", "elevations_deg: [10, 20, 30, 40, 50], count: 900000"),
    sub("color: 0.5}", "texture: {type: noise, params: {size_px: [100000000, 100000000]}}}"),
])
def test_sizes_are_refused_before_anything_is_allocated_in_well_under_a_second(edit):
    text = edit(BASE)
    parse_spec(BASE)  # warm
    t0 = time.perf_counter()
    with pytest.raises(SpecError, match="docs/scene_spec.md 'Limits'|<= 65536|<= 1000000"):
        parse_spec(text)
    assert time.perf_counter() - t0 < 0.5


def test_a_large_spec_is_refused_by_its_size_at_once(tmp_path):
    p = tmp_path / "big.yaml"
    with open(p, "wb") as f:
        f.write(BASE.encode())
        f.truncate(50 * 2**20)  # 50 MB (a sparse file: no time spent writing it)
    from scenegen.spec import load_spec
    t0 = time.perf_counter()
    with pytest.raises(SpecError, match="the spec file is 50.0 MiB; at most 1 MiB are read"):
        load_spec(p)
    assert time.perf_counter() - t0 < 0.1


def test_nul_byte_in_a_command_line_path_names_it(tmp_path):
    from scenegen.cli import main
    code, _, err = run_cli(main, ["validate", "sce\x00ne.yaml"])
    assert code == 2 and "'sce\\x00ne.yaml' contains a NUL byte" in err and "Traceback" not in err
    from recon_eval.cli import main as recon_main
    code, _, err = run_cli(recon_main, ["pnp", "a\x00b.json", tmp_path / "gt.json"])
    assert code == 2 and "'a\\x00b.json' contains a NUL byte" in err
    from scenegen.located_yaml.source import read_source
    with pytest.raises(SpecError, match="the spec file path contains a NUL byte"):
        read_source("sce\x00ne.yaml", "spec file")  # the Python API too


def test_json_report_into_a_folder_names_the_folder_not_a_temporary_file(tmp_path):
    from recon_eval.cli import main
    h = tmp_path / "h.txt"
    h.write_text("1 0 0\n0 1 0\n0 0 1\n")
    folder = tmp_path / "report"
    folder.mkdir()
    code, _, err = run_cli(main, ["homography", h, h, "--size", "80", "60", "--quiet", "--json", folder])
    assert code == 2 and f"{folder}: Is a directory" in err and "scenegen-tmp" not in err
