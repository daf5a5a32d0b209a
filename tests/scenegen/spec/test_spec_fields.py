"""The spec from metadata (scenegen.spec.parse.fields): a field declared with ``param`` and no
hand-written code is parsed (default, unit, range, choices and key from its metadata), written
back by to_yaml's writer, and listed in the docs' reference table; and every field of the
sections whose parsing is generated is accepted by its section and documented (the round trip
of every bundled scene through to_yaml: test_to_yaml.py)."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pytest
import yaml

from scenegen.errors import SpecError
from scenegen.geometry import optics
from scenegen.imaging import ExposureParams, RawOutput, SensorParams
from scenegen.imaging.vignetting import VignettingParams
from scenegen.located_yaml import Document
from scenegen.spec import model as m, reference
from scenegen.spec.model.meta import param, spec_fields
from scenegen.spec.parse import crossview, imaging, lights, materials, render, truth
from scenegen.spec.parse.fields import read_fields, record_mapping, write_fields, written_fields


@dataclass(frozen=True, kw_only=True)
class Gadget:
    """A record no parser knows: each field is one line, nothing else."""

    size_m: float = param(1.0, unit="metres", lo=0.0, lo_open=True)
    count: int = param(unit="items", lo=1, hi=10)
    mode: str = param("fast", unit="gadget mode", choices=("fast", "slow"))
    enabled: bool = param(True, unit="flag")
    offset_px: tuple[float, float] = param((0.0, 0.0), unit="u, v in pixels")
    tint: tuple[float, float, float] = param((1.0, 1.0, 1.0), unit="linear RGB", lo=0.0, hi=1.0,
                                             kind="color")
    span_deg: tuple[float, float] | None = param(None, unit="degrees", kind="range")
    weights: tuple[float, ...] = param((1.0,), unit="weights", lo=0.0)
    spin_rate: float = param(0.0, unit="turns per second", key="spin")


def parse(text: str) -> Gadget:
    node = Document(text, "g.yaml", Path(".")).root
    return Gadget(**read_fields(record_mapping(node, Gadget, "a gadget"), Gadget))


def test_a_field_with_metadata_only_is_parsed_with_its_default_unit_range_and_key():
    g = parse("count: 3\nmode: slow\ntint: 0.5\nspan_deg: [-10, 20]\nweights: [1, 2, 3]\nspin: 2")
    assert g == Gadget(count=3, mode="slow", tint=(0.5, 0.5, 0.5), span_deg=(-10.0, 20.0),
                       weights=(1.0, 2.0, 3.0), spin_rate=2.0)
    assert parse("count: 1") == Gadget(count=1)  # every other field at its dataclass default


@pytest.mark.parametrize("text,message", [
    ("count: 3\nsize_m: 0", "g.yaml:2: size_m: expected a value > 0 (metres), got 0"),
    ("count: 11", "g.yaml:1: count: expected a value >= 1 and <= 10 (items), got 11"),
    ("count: 2\nmode: quick", "g.yaml:2: mode: expected one of 'fast', 'slow' (gadget mode), "
                              "got 'quick'"),
    ("count: 2\nenabled: 1", "g.yaml:2: enabled: expected true or false, got 1"),
    ("count: 2\noffset_px: [1]", "g.yaml:2: offset_px: expected 2 numbers (u, v in pixels), got "
                                 "1 numbers [1]"),
    ("count: 2\ntint: [1, 2, 1]", "g.yaml:2: tint: expected tint in [0, 1] (linear RGB), got "
                                  "(1.0, 2.0, 1.0)"),
    ("count: 2\nspan_deg: [5, 1]", "g.yaml:2: span_deg: expected min <= max, got [5, 1]"),
    ("count: 2\nspin_rate: 1", "g.yaml:2: spin_rate: unknown key 'spin_rate'"),
    ("mode: slow", "g.yaml:1: count: missing required key 'count'"),
])
def test_its_errors_name_file_line_field_and_what_was_expected(text, message):
    with pytest.raises(SpecError) as e:
        parse(text)
    assert str(e.value).startswith(message), str(e.value)


def test_it_is_written_back_exactly():
    g = Gadget(size_m=0.1 + 0.2, count=4, mode="slow", enabled=False, offset_px=(1e-300, -2.5),
               tint=(0.25, 0.5, 1.0), span_deg=(-1.0, 1.0), weights=(3.0, 1e17), spin_rate=-7.0)
    written = write_fields(g)
    assert written["spin"] == -7.0 and "spin_rate" not in written
    assert parse(yaml.safe_dump(written)) == g
    assert "span_deg" not in write_fields(Gadget(count=1))  # None: absent


def test_it_is_listed_in_the_reference_table():
    rows = {key: (default, unit, values)
            for _, key, default, unit, values in reference.rows(((Gadget, "gadget", {}),))}
    assert rows["size_m"] == ("1", "metres", "> 0")
    assert rows["count"] == ("required", "items", ">= 1 and <= 10")
    assert rows["mode"] == ("`fast`", "gadget mode", "`fast`, `slow`")
    assert rows["spin"] == ("0", "turns per second", "")
    assert set(rows) == {fi.key for fi in spec_fields(Gadget)}


#: (record, the keys its section parser accepts) of the sections whose values are generated.
GENERATED = [
    (m.RenderSettings, render.KEYS), (m.TruthSpec, truth.KEYS),
    (m.CrossviewSpec, crossview.KEYS), (m.MatchSetSpec, crossview.MATCH_KEYS),
    (RawOutput, imaging.RAW_KEYS), (m.SurfaceMaps, materials.MAP_KEYS),
    *[(cls, materials.TYPE_KEYS[kind]) for kind, cls in materials.CLASSES.items()],
    *[(cls, None) for cls in lights.CLASSES.values()],
    (ExposureParams, None), (VignettingParams, None), (SensorParams, None),
    (optics.ThinLens, None), (optics.Shutter, None), (optics.ChromaticAberration, None),
    (optics.Motion, None), (m.PoseJitter, None), (m.Orbit, None), (m.LookAt, None),
]


@pytest.mark.parametrize("cls,keys", GENERATED, ids=lambda x: getattr(x, "__name__", ""))
def test_every_written_field_of_the_generated_sections_is_accepted_and_documented(cls, keys):
    fields = written_fields(cls)
    assert fields
    if keys is not None:
        assert {fi.key for fi in fields} <= set(keys)
    documented = {key for c, where, k in reference.RECORDS if c is cls
                  for _, key, *_ in reference.rows(((c, where, k),))}
    assert {fi.key for fi in fields} <= documented



@dataclass(frozen=True, kw_only=True)
class Ring:
    """A record with values inside a nested mapping (``circle: {radius_m, center}``)."""

    radius_m: float = param(unit="metres", lo=0.0, lo_open=True, key="circle.radius_m")
    center: tuple[float, float, float] = param((0.0, 0.0, 0.0), unit="metres",
                                               key="circle.center")
    count: int = param(3, unit="views", lo=1)


def test_nested_keys_are_read_and_written_inside_their_mapping():
    root = Document("circle: {radius_m: 2}\ncount: 5\n", "r.yaml", Path(".")).root.as_mapping()
    circle = root.get("circle").as_mapping()
    ring = Ring(**read_fields(circle, Ring, within="circle"), **read_fields(root, Ring))
    assert ring == Ring(radius_m=2.0, count=5)
    assert write_fields(ring) == {"count": 5}
    assert write_fields(ring, within="circle") == {"radius_m": 2.0, "center": [0.0, 0.0, 0.0]}
    bad = Document("circle: {radius_m: -1}\n", "r.yaml", Path(".")).root.as_mapping()
    with pytest.raises(SpecError, match=r"^r.yaml:1: circle.radius_m: expected a value > 0 "
                                        r"\(metres\), got -1"):
        read_fields(bad.get("circle").as_mapping(), Ring, within="circle")
    keys = {key for _, key, *_ in reference.rows(((Ring, "ring", {}),))}
    assert keys == {"circle.radius_m", "circle.center", "count"}
