"""docs/scene_spec.md states the dataclasses' defaults: its generated reference table is current,
and the defaults its hand-written tables show equal the dataclass fields'."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from scenegen.spec import model as m
from scenegen.spec import reference
from scenegen.spec.model.meta import field_info

DOC = Path(__file__).resolve().parents[3] / "docs" / "scene_spec.md"
TEXT = DOC.read_text()


def section(title: str) -> str:
    start = TEXT.index(f"\n## {title}\n")
    end = TEXT.find("\n## ", start + 1)
    return TEXT[start:end if end > 0 else None]


def table_rows(text: str):
    for line in text.splitlines():
        if line.startswith("| ") and not line.startswith("|---"):
            yield [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]


def same(doc: str, value) -> bool:
    """A documented default equals a value (numbers compared as numbers, backticks ignored)."""
    a, b = doc.strip("`"), reference.format_value(value).strip("`")
    try:
        return [float(x) for x in a.strip("[]").split(",")] == \
            [float(x) for x in b.strip("[]").split(",")]
    except ValueError:
        return a == b


def test_reference_table_is_current():
    start, end = TEXT.index(reference.BEGIN), TEXT.index(reference.END) + len(reference.END)
    assert TEXT[start:end] == reference.markdown(), \
        "regenerate with `python -m scenegen.spec.reference` and paste it into docs/scene_spec.md"


@pytest.mark.parametrize("title,cls,keys", [
    ("Top level", m.SceneSpec, ("description", "seed")),
    ("`render`", m.RenderSettings, ("spp", "max_depth", "seed", "variant", "bit_depth",
                                    "motion_subframes", "sampler")),
    ("Cameras", m.CameraSpec, ("model", "skew")),
    ("Crossview", m.CrossviewSpec, ("pairs", "flow", "stereo", "sift", "sift_ratio",
                                    "sift_inlier_px", "targets")),
])
def test_default_columns_match_the_dataclasses(title, cls, keys):
    shown = {row[0].strip("`"): row[2] for row in table_rows(section(title)) if len(row) >= 3}
    for key in keys:
        assert same(shown[key], field_info(cls, key).default), (key, shown[key])


SHAPES = {"plane": m.Plane, "box": m.Box, "sphere": m.Sphere, "cylinder": m.Cylinder,
          "torus": m.Torus, "blob": m.Blob}
KEY_VALUE = re.compile(r"`(\w+)(?::[^`]*)?` \((\[[^\]]*\]|-?[\d.]+)")


def test_shape_defaults_match_the_dataclasses():
    checked = 0
    for row in table_rows(section("Objects")):
        cls = SHAPES.get(row[0].strip("`"))
        if cls is None:
            continue
        for key, value in KEY_VALUE.findall(row[1]):
            assert same(value, field_info(cls, key).default), (cls.__name__, key, value)
            checked += 1
    assert checked == 11  # every shape default of the table


def test_match_set_and_placement_defaults_match_the_dataclasses():
    rows = {row[0].strip("`"): row for row in table_rows(section("Crossview"))}
    for key, value in KEY_VALUE.findall(rows["matches"][3]):
        assert same(value, field_info(m.MatchSetSpec, key).default), (key, value)
    rows = {row[0].strip("`"): row[1] for row in table_rows(section("Views"))}
    for placement, cls in (("orbit", m.Orbit), ("random", m.RandomPoses)):
        found = KEY_VALUE.findall(rows[placement])
        assert found
        for key, value in found:
            assert same(value, field_info(cls, key).default), (placement, key, value)


def test_light_defaults_match_the_dataclasses():
    rows = {row[0].strip("`"): row[1] for row in table_rows(section("Lights"))}
    assert "default 20" in rows["spot"] and field_info(m.SpotLight, "cutoff_deg").default == 20
    assert f"default {m.BEAM_WIDTH_FRACTION:g}" in rows["spot"]
    for key, value in KEY_VALUE.findall(rows["envmap"]):
        assert same(value, field_info(m.EnvmapLight, key).default), (key, value)
