"""``objects[i].annotation`` and ``truth: {objects: true}``: parsed values, the write-back of
``to_yaml`` (round trip), the bundled object scenes, and one-line errors naming file:line and
field for bad annotations."""
from pathlib import Path

import numpy as np
import pytest

from scenegen.errors import SpecError
from scenegen.spec import load_spec, parse_spec
from scenegen.spec.serialize import spec_sha256
from scenegen.spec.to_yaml import to_yaml

ROOT = Path(__file__).parents[3]
HEAD = """
cameras: {c: {size: [32, 24], fx: 30}}
views: [{camera: c, look_at: [{eye: [0, -1, 1], target: [0, 0, 0]}]}]
"""
SPEC = HEAD + """
truth: {objects: true}
objects:
  - name: crate
    shape: {type: box, size: [0.1, 0.08, 0.06]}
    annotation:
      symmetries:
        discrete: [{rotation_deg: [0, 0, 180]}]
        continuous: [{axis: [0, 0, 2], offset: [0, 0, 0.01]}]
      keypoints: {top: [0, 0, 0.03], corner: {vertex: 2}}
      skeleton: [[top, corner]]
  - name: plain
    shape: {type: sphere, radius: 0.05}
"""


def test_parsed_values_and_defaults():
    spec = parse_spec(SPEC)
    a = spec.objects[0].annotation
    assert a.model == "crate"  # the object's name by default
    np.testing.assert_allclose(a.symmetries_discrete[0].R, np.diag([-1.0, -1.0, 1.0]), atol=1e-15)
    assert a.symmetries_continuous[0].axis == (0.0, 0.0, 1.0)  # normalised
    assert a.symmetries_continuous[0].offset_m == (0.0, 0.0, 0.01)
    assert [(k.name, k.position_object_m, k.vertex) for k in a.keypoints] == [
        ("top", (0.0, 0.0, 0.03), None), ("corner", None, 2)]
    assert a.skeleton == (("top", "corner"),)
    assert spec.objects[1].annotation is None and spec.truth.objects


def test_to_yaml_round_trip_keeps_the_annotation():
    spec = parse_spec(SPEC)
    again = parse_spec(to_yaml(spec))
    assert spec_sha256(again) == spec_sha256(spec)
    a, b = spec.objects[0].annotation, again.objects[0].annotation
    assert (b.model, b.keypoints, b.skeleton, b.symmetries_continuous) == (a.model, a.keypoints, a.skeleton,
                                                                          a.symmetries_continuous)
    np.testing.assert_array_equal(b.symmetries_discrete[0].matrix, a.symmetries_discrete[0].matrix)


def test_specs_without_annotations_keep_their_hash():
    """No `annotation:` and no `truth.objects`: nothing new in the resolved spec (the bundled
    scenes' datasets keep their bytes)."""
    spec = parse_spec(HEAD + "objects: [{name: b, shape: box}]\n")
    plain = parse_spec(HEAD + "objects: [{name: b, shape: box}]\ntruth: {albedo: false}\n")
    from scenegen.spec.serialize import spec_to_dict
    assert "annotation" not in spec_to_dict(spec)["objects"][0]
    assert "objects" not in spec_to_dict(plain)["truth"]


@pytest.mark.parametrize("path", ["scenes/objects_tabletop.yaml", "scenes/objects_bin.yaml",
                                  "scenes/objects_symmetric.yaml", "scenes/articulated_figure.yaml"])
def test_bundled_object_scenes(path):
    spec = load_spec(ROOT / path)
    annotated = [o for o in spec.objects if o.annotation is not None]
    assert spec.truth.objects and len(annotated) >= 4
    models = [o.annotation.model for o in annotated]
    if path != "scenes/articulated_figure.yaml":  # several instances of one model
        assert len(set(models)) < len(models)
    for o in annotated:  # every discrete symmetry is a rotation about the object origin
        for S in o.annotation.symmetries_discrete:
            np.testing.assert_allclose(S.R @ S.R.T, np.eye(3), atol=1e-12)


BAD = [
    ("annotation: {symmetries: {discrete: [{matrix: [[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]}]}}",
     "orthonormal"),
    ("annotation: {symmetries: {continuous: [{axis: [0, 0, 0]}]}}", "non-zero axis"),
    ("annotation: {symmetries: {continuous: [{offset: [0, 0, 0]}]}}", "axis"),
    ("annotation: {keypoints: {a: [0, 0]}}", "3"),
    ("annotation: {keypoints: {a: {vertex: -1}}}", ">= 0"),
    ("annotation: {keypoints: {a: [0, 0, 0]}, skeleton: [[a, b]]}", "skeleton names keypoint 'b'"),
    ("annotation: {skeleton: [[a]]}", "pair"),
    ("annotation: {model: 'a b'}", "model name"),
    ("annotation: {keypoints: {a: [0, 0, 0]}, colour: red}", "colour"),
]


@pytest.mark.parametrize("line, message", BAD)
def test_bad_annotations_are_one_line_errors_naming_the_line(line, message):
    text = HEAD + "objects:\n  - name: b\n    shape: box\n    " + line + "\n"
    with pytest.raises(SpecError) as e:
        parse_spec(text, file="s.yaml")
    msg = str(e.value)
    assert "\n" not in msg and message in msg and msg.startswith("s.yaml:") and "annotation" in msg, msg


def test_object_truth_without_annotated_objects_is_refused():
    with pytest.raises(SpecError, match="no object has one"):
        parse_spec(HEAD + "truth: {objects: true}\nobjects: [{name: b, shape: box}]\n", file="s.yaml")


def test_instances_of_one_model_must_be_alike():
    text = HEAD + """objects:
  - {name: a, shape: {type: box, size: [0.1, 0.1, 0.1]}, annotation: {model: m, keypoints: {k: [0, 0, 0.05]}}}
  - {name: b, shape: {type: box, size: [0.1, 0.1, 0.1]}, annotation: {model: m, keypoints: {k: [0, 0, 0.05]}}}
"""
    assert parse_spec(text).objects[1].annotation.model == "m"
    for other in ("size: [0.1, 0.1, 0.2]", "keypoints: {k: [0, 0, 0.04]}"):
        lines = text.splitlines()
        if other.startswith("size"):
            lines[-1] = lines[-1].replace("size: [0.1, 0.1, 0.1]", other)
        else:
            lines[-1] = lines[-1].replace("keypoints: {k: [0, 0, 0.05]}", other)
        with pytest.raises(SpecError, match="instances of one model must be alike") as e:
            parse_spec("\n".join(lines) + "\n", file="s.yaml")
        assert str(e.value).startswith("s.yaml:6: objects[1].annotation"), str(e.value)  # the second instance
