"""Fixtures of the scenegen tests: one small rendered dataset with cross-view truth, shared by
the cross-view, stereo and export tests (rendered once per session; ~5 s on 2 cores)."""
from __future__ import annotations

import time
from pathlib import Path

import pytest

from scenegen.pipeline.run import render_spec
from scenegen.render import load_scene
from scenegen.spec import load_spec

# A verged stereo rig (two cameras with different intrinsics and distortion) over speckle-textured
# planes, a sphere (occluder) and a checkerboard, plus a free camera of another size.
SPEC = """
name: crossview_test
seed: 3
render: {spp: 16, max_depth: 3}
materials:
  speckle:
    type: diffuse
    texture: {type: speckle, params: {density: 0.5, dot_radius_px: 2.0}}
objects:
  - name: wall
    shape: {type: plane, size: [4, 3]}
    transform: {translation: [0, 1.5, 1.0], rotation_deg: [90, 0, 0]}
    material: speckle
  - name: floor
    shape: {type: plane, size: [4, 4]}
    material: speckle
  - name: ball
    shape: {type: sphere, radius: 0.25}
    transform: {translation: [-0.1, 0.5, 0.45]}
    material: speckle
  - name: board
    target: {type: checkerboard, inner_cols: 5, inner_rows: 4, square_m: 0.12}
    transform: {translation: [0.75, 1.2, 0.75], rotation_deg: [90, 0, 0]}
lights:
  - {type: point, position: [0, -1.5, 2.5], intensity: 10}
  - {type: constant, radiance: 0.3}
cameras:
  left: {model: opencv, size: [200, 150], fx: 170, fy: 171, cx: 99.2, cy: 74.8, dist: [-0.05, 0.01, 0.0005, -0.0003, 0]}
  right: {model: opencv, size: [200, 150], fx: 172, fy: 170, cx: 100.5, cy: 74.0, dist: [-0.048, 0.009, 0.0002, -0.0001]}
  side: {model: opencv, size: [176, 132], fx: 150, fy: 152, cx: 88.7, cy: 65.1, dist: [0.03, -0.01, 0, 0]}
rigs:
  st: {type: stereo, left: left, right: right, baseline_m: 0.12, vergence_deg: 2.0}
views:
  - rig: st
    path: {line: {from: [-0.2, -1.5, 1.2], to: [0.2, -1.45, 1.25]}, count: 2, target: [0, 0.8, 0.6]}
  - camera: side
    look_at: [{eye: [0.9, -1.2, 1.5], target: [0, 0.8, 0.6]}]
crossview:
  pairs: [[st_left_0000, st_right_0000], [st_left_0000, st_left_0001], [st_left_0000, side_0002]]
  matches: {count: 400, sigma_px: 0.5, outlier_fraction: 0.25, near_miss_fraction: 0.5, near_miss_px: [4, 12], seed: 11}
  sift: true
"""



@pytest.fixture(scope="session")
def crossview_render(tmp_path_factory):
    """(spec path, dataset folder, seconds the render took) of CROSSVIEW_SPEC."""
    root = tmp_path_factory.mktemp("crossview")
    spec = root / "crossview_test.yaml"
    spec.write_text(SPEC)
    out = root / "out"
    t0 = time.perf_counter()
    render_spec(spec, out, progress=False)
    return spec, out, time.perf_counter() - t0


@pytest.fixture(scope="session")
def crossview_scene(crossview_render):
    """(spec, LoadedScene) of the same scene in llvm_ad_rgb, for independent ray casts."""
    spec = load_spec(crossview_render[0])
    return spec, load_scene(spec, variant="llvm_ad_rgb", spp=1)


# Object truth (issue 29): two instances of one crate model (one hides part of the other), a can
# with a continuous symmetry and a stone, annotated with keypoints on face centres (not on edges,
# where a ray's float32 rounding decides the hit), on a table; two 64x48 views, 1 spp.
OBJECTS_SPEC = """
name: objects_test
seed: 5
render: {spp: 1, max_depth: 2}
truth: {objects: true}
lights: [{type: constant, radiance: 1}]
cameras:
  cam: {model: pinhole, size: [64, 48], fx: 90, cx: 30.5, cy: 24.2}
views:
  - camera: cam
    look_at: [{eye: [0.2, -0.75, 0.45], target: [0.0, -0.02, 0.05]}, {eye: [-0.55, -0.4, 0.4], target: [0.0, 0.0, 0.05]}]
objects:
  - name: table
    shape: {type: plane, size: [1.2, 1.2]}
  - name: crate_1
    shape: {type: box, size: [0.12, 0.08, 0.1]}
    transform: {translation: [0.0, 0.06, 0.05], rotation_deg: [0, 0, 20]}
    annotation: &crate
      model: crate
      symmetries: {discrete: [{rotation_deg: [0, 0, 180]}]}
      keypoints: {top: [0.0, 0.0, 0.05], front: [0.0, -0.04, 0.0], right: [0.06, 0.0, 0.01], back: [0.0, 0.04, 0.02]}
  - name: crate_2
    shape: {type: box, size: [0.12, 0.08, 0.1]}
    transform: {translation: [0.05, -0.08, 0.05], rotation_deg: [0, 0, -35]}
    annotation: *crate
  - name: can
    shape: {type: cylinder, radius: 0.03, height: 0.12}
    transform: {translation: [-0.12, -0.05, 0.06]}
    annotation:
      model: can
      symmetries: {continuous: [{axis: [0, 0, 1], offset: [0, 0, 0.01]}]}
      keypoints: {lid: [0.0, 0.0, 0.06], side: {vertex: 3}}
  - name: stone
    shape: {type: blob, radius: 0.03, subdivisions: 2}
    transform: {translation: [0.13, 0.02, 0.03]}
    annotation: {model: stone}
"""


@pytest.fixture(scope="session")
def objects_dataset(tmp_path_factory):
    """The path of :data:`OBJECTS_SPEC` rendered (with ``truth: {objects: true}``)."""
    d = tmp_path_factory.mktemp("objects")
    spec = d / "objects.yaml"
    spec.write_text(OBJECTS_SPEC)
    render_spec(spec, d / "out", progress=False)
    return d / "out"


@pytest.fixture(scope="session")
def figure_dataset(tmp_path_factory):
    """scenes/articulated_figure.yaml at 64x48 px, 1 spp (three frames; eleven parts on joints,
    13 keypoints visible, self-occluded and occluded by a post): the path of the dataset."""
    text = (Path(__file__).parents[2] / "scenes" / "articulated_figure.yaml").read_text()
    text = text.replace("size: [160, 120], fx: 190", "size: [64, 48], fx: 76").replace("spp: 16", "spp: 1")
    d = tmp_path_factory.mktemp("figure")
    spec = d / "figure.yaml"
    spec.write_text(text)
    render_spec(spec, d / "out", progress=False)
    return d / "out"
