"""The ToF camera (scenegen.spec.sensors.tof) rendered through the pipeline, against closed forms:

* a convex object in the dark (a sphere, nothing else: no path has a second vertex on a surface)
  with noise off and every ray through its pixel centre decodes to the truth range to float32
  precision, wraps at exactly c / (2 f) (a frequency whose ambiguity range cuts the sphere), is
  unwrapped by two frequencies, and has zero multipath and mixing error;
* with rays over the pixel footprint, the flying pixels are the silhouette's;
* in a concave corner of two Lambertian walls the multipath error of a two-bounce path is
  positive (the indirect path A -> B -> camera is longer than A -> camera by the triangle
  inequality, and its phase delay stays below pi) and has the size of the phasor sum computed
  here by quadrature over the other wall: e = c / (4 pi f) arg(1 + P_ind / P_dir), with
  P_dir = (rho / pi) cos(theta_A) / r_A^2 e^{i 2 pi f 2 r_A / c} and
  P_ind = int_wall (rho / pi) L_B cos(theta_A') cos(theta_B') / |A - B|^2 e^{i 2 pi f L / c} dB,
  L_B = (rho / pi) cos(theta_B) / |B - c|^2, L = r_A + |A - B| + |B - c| (unit source intensity).
"""
from __future__ import annotations

import dataclasses
import json
import math

import cv2
import numpy as np
import OpenEXR
import pytest
from scipy import ndimage

from recon_eval.cli import main as recon_main
from scenegen.dataset import Dataset, verify
from scenegen.export import export
from scenegen.geometry.conventions import pixel_centers
from scenegen.geometry.tof import SPEED_OF_LIGHT_M_S, ambiguity_range_m
from scenegen.pipeline.run import render_spec
from scenegen.render import load_scene
from scenegen.spec import load_spec, resolve_views
from scenegen.spec.sensors.tof import tof_frame

pytestmark = pytest.mark.render

SPHERE = """\
name: tof_sphere
sequence: {fps: 10, frames: 2}
objects:
  - {name: ball, shape: {type: sphere, radius: 0.5}, material: {type: diffuse, color: 0.8}}
cameras:
  ir: {size: [32, 24], fx: 30}
tof_cameras:
  wrap: {camera: ir, frequency_mhz: 55, noise: false, pixel_centre_rays: true, spp: 1}
  dual: {camera: ir, frequency_mhz: 100, frequency2_mhz: 80, noise: false, pixel_centre_rays: true, spp: 1}
  edges: {camera: ir, frequency_mhz: 20, noise: false, spp: 16, max_bounces: 1}
rigs:
  kinect:
    type: multi
    members:
      - {camera: ir, name: rgb}
      - {kind: tof, sensor: wrap, name: wrap}
      - {kind: tof, sensor: dual, name: dual}
      - {kind: tof, sensor: edges, name: edges, time_offset_s: 0.001}
views:
  - rig: kinect
    name: seq
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, eye: [0, -3, 0], target: [0, 0, 0]}
        - {time_s: 0.1, eye: [0.2, -3.1, 0], target: [0, 0, 0]}
"""
EDGE = """\
name: tof_edge
sequence: {fps: 10, frames: 2}
objects:
  - {name: box, shape: {type: box, size: [0.6, 0.6, 0.6]}, material: {type: diffuse, color: 0.8}}
  - {name: wall, shape: {type: plane, size: [5, 5]}, material: {type: diffuse, color: 0.5},
     transform: {translation: [0, 1, 0], rotation_deg: [90, 0, 0]}}
cameras:
  ir: {size: [32, 24], fx: 30}
tof_cameras:
  tof0: {camera: ir, frequency_mhz: 20, noise: false, spp: 16, max_bounces: 1}
rigs:
  kinect: {type: multi, members: [{kind: tof, sensor: tof0, name: depth}]}
views:
  - rig: kinect
    name: seq
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, eye: [0, -3, 0], target: [0, 0, 0]}
        - {time_s: 0.1, eye: [0.3, -3, 0.2], target: [0, 0, 0]}
"""
CORNER_F_MHZ = 20.0
RHO = 0.8
CORNER = f"""\
name: tof_corner
render: {{spp: 256, max_depth: 3}}
sequence: {{fps: 10, frames: 2}}
objects:
  - {{name: wall_a, shape: {{type: plane, size: [2, 2]}}, material: {{type: diffuse, color: {RHO}}},
     transform: {{translation: [1, 0, 0], rotation_deg: [-90, 0, 0]}}}}
  - {{name: wall_b, shape: {{type: plane, size: [2, 2]}}, material: {{type: diffuse, color: {RHO}}},
     transform: {{translation: [0, 1, 0], rotation_deg: [0, 90, 0]}}}}
lights:  # at the ToF camera's centre: the RGB camera renders what the ToF camera's DC is
  - {{type: point, position: [1.2, 1.2, 0], intensity: 1}}
cameras:
  ir: {{size: [32, 24], fx: 30}}
tof_cameras:
  tof0: {{camera: ir, frequency_mhz: {CORNER_F_MHZ}, noise: false, pixel_centre_rays: true, spp: 256,
          max_bounces: 2}}
rigs:
  kinect: {{type: multi, members: [{{camera: ir, name: rgb}}, {{kind: tof, sensor: tof0, name: depth}}]}}
views:
  - rig: kinect
    name: seq
    trajectory:
      interpolation: linear
      keyframes:
        - {{time_s: 0.0, eye: [1.2, 1.2, 0], target: [0, 0, 0]}}
        - {{time_s: 0.1, eye: [1.2, 1.2, 0], target: [0, 0, 0]}}
"""


def _render(tmp_path_factory, name, text):
    d = tmp_path_factory.mktemp(name)
    (d / "scene.yaml").write_text(text)
    render_spec(d / "scene.yaml", d / "out", progress=False)
    return d / "scene.yaml", d / "out"


@pytest.fixture(scope="module")
def sphere(tmp_path_factory):
    return _render(tmp_path_factory, "sphere", SPHERE)


@pytest.fixture(scope="module")
def edge(tmp_path_factory):
    return _render(tmp_path_factory, "edge", EDGE)


@pytest.fixture(scope="module")
def corner(tmp_path_factory):
    return _render(tmp_path_factory, "corner", CORNER)


def test_convex_object_decodes_to_the_truth_range_and_wraps_at_c_over_2f(sphere):
    spec, out = sphere
    assert verify(out).ok
    s = Dataset(out).streams["seq_wrap"]
    assert (s.kind, s.sensor, s.samples) == ("tof", "wrap", 2)
    R = ambiguity_range_m(55e6)
    t = s.field("range_true_m").astype(np.float64)
    r = s.field("range_m").astype(np.float64)
    n = s.field("wrap_count")[..., 0]
    valid = s.field("valid")
    assert valid.sum() > 120 and np.all(np.isfinite(t[valid]))
    assert np.array_equal(n[valid], np.floor(t[valid] / R))
    assert {0, 1} <= set(n[valid].tolist())  # the sphere straddles the ambiguity range
    assert np.all(r[valid] < R)
    # float32 storage of both (6e-8 relative each) and the float32 path length of the renderer
    np.testing.assert_allclose(r[valid], t[valid] - n[valid] * R, rtol=0, atol=3e-7 * 3.0)
    for key in ("multipath_error_m", "mixing_error_m"):
        assert np.nanmax(np.abs(s.field(key)[valid])) < 1e-6
    assert not s.field("flying").any()
    rays_z = s.field("depth_true_m")[valid] / s.field("range_true_m")[valid]
    np.testing.assert_allclose(s.field("depth_m")[valid], r[valid] * rays_z, rtol=1e-6)


def test_two_frequencies_unwrap_to_the_truth_range(sphere):
    s = Dataset(sphere[1]).streams["seq_dual"]
    t, r, valid = s.field("range_true_m"), s.field("range_m"), s.field("valid")
    assert valid.sum() > 120
    assert np.all(s.field("wrap_count")[valid][:, 0] >= 1)  # 100 MHz wraps at 1.5 m, the sphere is at 2.5 m
    np.testing.assert_allclose(r[valid], t[valid], rtol=0, atol=1e-6)


def test_flying_pixels_are_the_silhouette_s_mixed_returns(sphere):
    s = Dataset(sphere[1]).streams["seq_edges"]
    assert np.array_equal(s.time_s, Dataset(sphere[1]).streams["seq_wrap"].time_s + 0.001)
    for k in range(s.samples):
        on = np.isfinite(s.field("range_true_m")[k])
        flying = s.field("flying")[k]
        edge = ndimage.binary_dilation(on, np.ones((3, 3))) & ~ndimage.binary_erosion(on, np.ones((3, 3)))
        assert flying.any() and not (flying & ~edge).any()
        # rays over a pixel of a smooth surface read its centre's range to second order
        inner = ndimage.binary_erosion(on, np.ones((3, 3)))
        assert np.nanmax(np.abs(s.field("mixing_error_m")[k][inner])) < 0.02
        # against the void, a return where the centre sees nothing is a flying pixel
        lit_void = ~on & (s.field("amplitude_e")[k][..., 0] > 0)
        assert lit_void.any() and not (lit_void & ~flying).any()


def _expected_multipath(A, n_A, n_B, B_corners, c, f_hz, cells=100):
    """The two-bounce multipath error (module docstring) of the points A (N, 3) on one wall,
    by the midpoint rule over the other wall (an axis-aligned 2 m x 2 m square)."""
    o, du, dv = B_corners
    g = (np.arange(cells) + 0.5) / cells
    B = (o + g[:, None, None] * du + g[None, :, None] * dv).reshape(-1, 3)
    dA = np.linalg.norm(du) * np.linalg.norm(dv) / cells ** 2
    Bc = c - B
    d_Bc = np.linalg.norm(Bc, axis=1)
    L_B = RHO / math.pi * np.clip(Bc @ n_B, 0, None) / d_Bc ** 3
    out = []
    for a in A:
        AB = B - a
        d_AB = np.linalg.norm(AB, axis=1)
        cos_a, cos_b = np.clip(AB @ n_A, 0, None) / d_AB, np.clip(-(AB @ n_B), 0, None) / d_AB
        r_A = np.linalg.norm(c - a)
        p_ind = np.sum(RHO / math.pi * L_B * cos_a * cos_b / d_AB ** 2 * dA
                       * np.exp(2j * math.pi * f_hz * (r_A + d_AB + d_Bc) / SPEED_OF_LIGHT_M_S))
        p_dir = RHO / math.pi * ((c - a) @ n_A / r_A) / r_A ** 2 * np.exp(2j * math.pi * f_hz * 2 * r_A
                                                                           / SPEED_OF_LIGHT_M_S)
        out.append(SPEED_OF_LIGHT_M_S / (4 * math.pi * f_hz) * np.angle(1 + p_ind / p_dir))
    return np.array(out)


def test_corner_multipath_error_has_the_sign_and_size_of_the_two_bounce_path(corner):
    spec_path, out = corner
    s = Dataset(out).streams["seq_depth"]
    cam = load_spec(spec_path).cameras["ir"].to_camera()
    rays_cam = cam.unproject_unit(pixel_centers(cam.width, cam.height).reshape(-1, 2))
    f = CORNER_F_MHZ * 1e6
    walls = {"a": (np.array([0.0, 1.0, 0.0]), (np.array([0.0, 0.0, -1.0]), np.array([2.0, 0.0, 0.0]),
                                                  np.array([0.0, 0.0, 2.0]))),
             "b": (np.array([1.0, 0.0, 0.0]), (np.array([0.0, 0.0, -1.0]), np.array([0.0, 2.0, 0.0]),
                                                  np.array([0.0, 0.0, 2.0])))}
    ratios, expected = [], {}
    assert np.array_equal(s.field("world_from_sensor")[0], s.field("world_from_sensor")[1])  # the light is there
    for k in range(s.samples):  # two frames of one pose: two Monte Carlo estimates of one quadrature
        T = s.field("world_from_sensor")[k]
        c = T[:3, 3]
        r = s.field("range_true_m")[k].astype(np.float64).ravel()
        A = c + r[:, None] * (rays_cam @ T[:3, :3].T)
        mp = s.field("multipath_error_m")[k].astype(np.float64).ravel()
        on_a = np.isfinite(r) & (np.abs(A[:, 1]) < 1e-4)
        on_b = np.isfinite(r) & (np.abs(A[:, 0]) < 1e-4)
        assert on_a.sum() > 200 and on_b.sum() > 200
        assert np.all(mp[on_a | on_b] > 0)  # the sign: the indirect light only ever arrives later
        for w, on, (n_A, _), (n_B, quad) in (("a", on_a, walls["a"], walls["b"]), ("b", on_b, walls["b"], walls["a"])):
            if w not in expected:
                expected[w] = _expected_multipath(A[on], n_A, n_B, quad, c, f)
            exp = expected[w]
            assert exp.min() > 0.01
            ratios.append(mp[on] / exp)
    ratio = np.concatenate(ratios)
    # Monte Carlo noise of 256 bounce samples a pixel (measured over 1,536 pixels: mean ratio 1.001,
    # median |ratio - 1| 0.064; the mean of 1,536 pixels is known to about 0.3 %)
    assert abs(ratio.mean() - 1) < 0.02
    assert np.median(np.abs(ratio - 1)) < 0.1


def test_recon_eval_scores_the_tof_stream(sphere, tmp_path):
    """``recon-eval depth-sensor`` on the noise-free dual-frequency stream: complete, exact;
    a planted 2 cm offset in a user's range maps comes back as the bias; a missing stream is exit 2."""
    out = sphere[1]
    assert recon_main(["depth-sensor", str(out), "--stream", "seq_dual", "--json", str(tmp_path / "a.json"),
                       "--quiet"]) == 0
    doc = json.loads((tmp_path / "a.json").read_text())
    sensor = doc["results"]["sensor"]
    assert sensor["completeness"] > 0.9 and sensor["rmse_m"] < 1e-6 and doc["metrics"]["abs_rel"] < 1e-6
    s = Dataset(out).streams["seq_dual"]
    np.save(tmp_path / "est.npy", s.field("range_true_m").astype(np.float64) + 0.02)
    assert recon_main(["depth-sensor", str(out), "--stream", "seq_dual", "--est", str(tmp_path / "est.npy"),
                       "--json", str(tmp_path / "b.json"), "--quiet"]) == 0
    sensor = json.loads((tmp_path / "b.json").read_text())["results"]["sensor"]
    assert sensor["completeness"] == 1.0 and abs(sensor["bias_m"] - 0.02) < 1e-9
    assert recon_main(["depth-sensor", str(out), "--stream", "nope", "--quiet"]) == 2


def test_the_tof_export_writes_png16_exr_and_calibration_readable_by_their_tools(sphere, tmp_path):
    out = sphere[1]
    summary = export(out, "tof", tmp_path / "tof")
    s = Dataset(out).streams["seq_dual"]
    root = tmp_path / "tof" / "seq_dual"
    raw = s.field("raw_dn")
    for k in range(s.samples):
        for i in range(2):
            for j, psi in enumerate((0, 90, 180, 270)):
                png = cv2.imread(str(root / "raw" / f"{k:06d}_f{i}_{psi:03d}.png"), cv2.IMREAD_UNCHANGED)
                assert png.dtype == np.uint16 and np.array_equal(png, raw[k, :, :, i, j])
        with OpenEXR.File(str(root / "exr" / f"{k:06d}.exr"), separate_channels=True) as f:
            ch = {n: c.pixels for n, c in f.channels().items()}
        assert np.array_equal(ch["raw_f1_270"], raw[k, :, :, 1, 3].astype(np.float32))
        assert np.array_equal(ch["range_true"], s.field("range_true_m")[k], equal_nan=True)
        assert np.array_equal(ch["flying"], s.field("flying")[k].astype(np.float32))
    calib = json.loads((root / "calibration.json").read_text())
    assert calib["frequencies_hz"] == [100e6, 80e6] and calib["camera"]["fx"] == 30.0
    assert calib["ambiguity_ranges_m"][0] == ambiguity_range_m(100e6)
    assert [f["time_s"] for f in calib["frames"]] == s.time_s.tolist()
    # per stream: 2 frames x (4 PNGs a frequency + an EXR) + calibration; one, two and one frequencies
    assert summary["files"] == (2 * 5 + 1) + (2 * 9 + 1) + (2 * 5 + 1)


def test_same_seed_same_bits(sphere):
    """Footprint rays, bounce samples and noise are seeded: a frame twice is the same bytes, another
    seed is not."""
    spec = load_spec(sphere[0])
    scene = load_scene(spec, variant="llvm_ad_rgb")
    tof = dataclasses.replace(spec.sensors["tof"]["edges"], noise=True, max_bounces=2)
    pose = resolve_views(spec)[0].cam_from_world
    a, b, c = (tof_frame(scene, tof, pose, 0.0, seed) for seed in (5, 5, 6))
    assert all(np.array_equal(a[k], b[k], equal_nan=True) for k in a)
    assert not np.array_equal(a["raw_dn"], c["raw_dn"])


def test_the_tof_dc_equals_mitsuba_s_path_tracer_with_a_point_light_at_the_centre(corner):
    """The radiometry of the ToF tracer against Mitsuba's own path tracer (an independent
    implementation): the DC of every path up to 2 vertices (max_bounces 2) equals the RGB render
    (max_depth 3, its channel mean) of the same scene lit by a unit point light at the camera
    centre, pixel by pixel within the Monte Carlo noise of both (256 samples each)."""
    d = Dataset(corner[1])
    s = d.streams["seq_depth"]
    k = math.pi * 2e6 * 1e-3  # electrons per rendered unit: signal_e_per_s_at_1m x integration_s x pi
    ratios = []
    for i, view in enumerate(d.views):
        dc = s.field("raw_mean_e")[i, :, :, 0, :].astype(np.float64).mean(axis=-1) / k
        rgb = d.linear_image(view).astype(np.float64).mean(axis=-1)
        on = np.isfinite(s.field("range_true_m")[i])
        inner = ndimage.binary_erosion(on, np.ones((3, 3)))  # the box filter mixes the image's edge pixels
        ratios.append(dc[inner] / rgb[inner])
    ratio = np.concatenate(ratios)
    # measured over 1,320 pixels: mean ratio 1.001, median |ratio - 1| 0.013; without the
    # indirect light the ratio would fall by its share (10-20 % here)
    assert abs(ratio.mean() - 1) < 0.01
    assert np.median(np.abs(ratio - 1)) < 0.03


def test_flying_pixels_at_a_depth_edge_read_between_the_two_surfaces(edge):
    """A box 2.7 m away in front of a wall 4 m away, direct light only, rays over each pixel's
    square: the pixels whose footprint straddles the box's outline mix the two returns, and as the
    two phasors are 1.1 rad apart at 20 MHz (< pi) their sum's phase, so the decoded range, lies
    strictly between the two surfaces' ranges; these are the flying pixels, all on the outline.
    Elsewhere the reading is the mean range of the pixel's 16 uniform rays: the centre's range
    within the sampling noise of the range's slope g (m/px) over the footprint, g / sqrt(12 x 16),
    checked to 5 of those plus 2 mm for the second-order terms."""
    s = Dataset(edge[1]).streams["seq_depth"]
    for k in range(s.samples):
        t = s.field("range_true_m")[k].astype(np.float64)
        r = s.field("range_m")[k].astype(np.float64)
        box = t < 3.2  # the box's faces are at 2.7-3.2 m, the wall at 4 m and beyond
        outline = ndimage.binary_dilation(box, np.ones((3, 3))) & ~ndimage.binary_erosion(box, np.ones((3, 3)))
        flying = s.field("flying")[k]
        assert flying.sum() >= 10 and not (flying & ~outline).any()
        near = ndimage.minimum_filter(t, 3)  # the nearest and farthest surface a footprint can meet
        far = ndimage.maximum_filter(t, 3)
        assert np.all((r[flying] > near[flying] + 0.05) & (r[flying] < far[flying] - 0.05))
        gy, gx = np.gradient(np.where(np.isfinite(t), t, np.nan))
        tol = 5 * np.hypot(gx, gy) / math.sqrt(12 * 16) + 2e-3
        mixing = np.abs(s.field("mixing_error_m")[k])
        assert np.all(mixing[~outline] < tol[~outline])
