"""Glass, water, principled, normal and bump maps and alpha masks: the image against closed-form
values, the truth (first surface hit) against analytic geometry, and truth vs image where an
alpha mask makes holes."""
import cv2
import numpy as np
import pytest

from scenegen.cli import main
from scenegen.dataset import Dataset
from scenegen.spec import load_spec, resolve_views

# Analytic depth: Mitsuba intersects in float32 (relative ~1e-7).
TOL_ANALYTIC_REL = 1e-5
# Closed-form radiance ratios of noise-free direct lighting (point light, delta lobes): 8-bit
# maps are decoded exactly in the expectation, so what is left is float32 shading.
TOL_RATIO = 2e-3
# The mean over a 64x64 image at 16 spp of a pane that reflects (to black) with probability
# R ~ 0.077 and transmits otherwise: Monte Carlo standard error ~0.03 % (measured error below).
TOL_PANE = 3e-3

CAM = """cameras:
  cam: {model: pinhole, size: [64, 64], fx: 64, fy: 64, cx: 31.5, cy: 31.5}
views:
  - camera: cam
    look_at: [{eye: [0, 0, 1.5], target: [0, 0, 0], up: [0, 1, 0]}]
"""


def render(tmp_path, tag, body):
    spec = tmp_path / f"{tag}.yaml"
    spec.write_text(f"name: {tag}\n" + body + CAM)
    assert main(["render", str(spec), "-o", str(tmp_path / tag), "-q"]) == 0
    ds = Dataset(tmp_path / tag)
    return spec, ds.linear_image(ds.views[0]), ds.truth(ds.views[0])


ALPHA_SCENE = """render: {spp: 16, max_depth: 4}
objects:
  - name: front
    shape: {type: plane, size: [1, 1]}
    transform: {translation: [0, 0, 0.5]}
    material: {type: diffuse, color: [0.8, 0.1, 0.1], alpha: alpha.png}
  - name: back
    shape: {type: plane, size: [3, 3]}
    material: {type: diffuse, color: [0.1, 0.1, 0.8]}
lights:
  - {type: constant, radiance: 1.0}
"""


@pytest.mark.render
def test_alpha_mask_holes_truth_agrees_with_the_image(tmp_path):
    a = np.zeros((4, 4), np.uint8)
    a[::2, ::2] = a[1::2, 1::2] = 255  # a 4x4 checker of holes; 16 px per texel in the image
    cv2.imwrite(str(tmp_path / "alpha.png"), a)
    spec_path, img, truth = render(tmp_path, "alpha", ALPHA_SCENE)
    oid, depth = truth["object_id"], truth["depth_z"]
    # the image: red where the front plane is, blue through its holes
    shows_front = img[..., 0] > img[..., 2]
    assert np.array_equal(shows_front, oid == 1)
    # texel (i, j) of the mask covers pixels 16i..16i+15 (rows) x 16j..16j+15: the truth's pattern
    want = np.kron(a > 0, np.ones((16, 16), bool))
    assert np.array_equal(oid == 1, want)
    # depth through a hole is the back plane's (z = 0, 1.5 m from the eye), exactly
    np.testing.assert_allclose(depth[~want], 1.5, rtol=TOL_ANALYTIC_REL)
    np.testing.assert_allclose(depth[want], 1.0, rtol=TOL_ANALYTIC_REL)

    from scenegen.render import load_scene
    from scenegen.render.truth import truth_pass

    spec = load_spec(spec_path)
    built = load_scene(spec, variant="llvm_ad_rgb", spp=1)
    view = resolve_views(spec)[0]
    cam = built.cameras["cam"]
    # Mitsuba's own ray_intersect does not see the holes: the truth would be wrong without them
    plain = truth_pass(built.scene, cam, view.cam_from_world, built.id_tables)
    assert np.all(plain["object_id"] == 1)
    # cross-view visibility: a back-plane point behind a hole is visible, behind paint it is not
    eye = view.cam_from_world.inverse().t
    # the rays to these back-plane points cross the front plane (1.0 of their 1.5 m) at the
    # centres of texels (row 0, col 3), a hole, and (row 1, col 1), paint
    crossings = np.array([[0.375, 0.375], [-0.125, 0.125]])
    assert a[0, 3] == 0 and a[1, 1] == 255
    pts = np.concatenate([crossings * 1.5, np.zeros((2, 1))], axis=1)
    assert built.visible_from(eye, pts).tolist() == [True, False]


def fresnel_dielectric(cos_i, eta):
    """Unpolarised Fresnel reflectance of a smooth interface (from first principles)."""
    sin_t2 = (1 - cos_i**2) / eta**2
    cos_t = np.sqrt(1 - sin_t2)
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (rs**2 + rp**2)


@pytest.mark.render
def test_thin_dielectric_pane_transmits_its_closed_form(tmp_path):
    """An emitter of radiance 1 seen through a thin pane (IOR 1.5, tint T) at normal incidence:
    radiance T (1 - R) with R = 2 r / (1 + r), r the Fresnel reflectance (both faces, all
    inter-reflections)."""
    body = """render: {spp: 16, max_depth: 8}
objects:
  - name: pane
    shape: {type: plane, size: [2, 2]}
    transform: {translation: [0, 0, 0.6]}
    material: {type: thin_dielectric, ior: 1.5, transmittance: [0.9, 0.8, 0.7]}
lights:
  - {type: area, size: [4, 4], position: [0, 0, -0.2], look_at: [0, 0, 1], radiance: 1.0}
"""
    _, img, truth = render(tmp_path, "pane", body)
    # per pixel: the incidence angle of its ray on the pane (normal +z)
    rays = truth["points_cam"].astype(np.float64)
    cos_i = np.abs(rays[..., 2]) / np.linalg.norm(rays, axis=-1)
    r = fresnel_dielectric(cos_i, 1.5 / 1.000277)
    want = np.array([0.9, 0.8, 0.7]) * np.mean(1 - 2 * r / (1 + r))
    got = img.reshape(-1, 3).mean(axis=0)
    print(f"thin pane: {got} vs closed form {want} (rel. error {np.max(np.abs(got / want - 1)):.1e})")
    np.testing.assert_allclose(got, want, rtol=TOL_PANE)
    # the truth is the pane (first surface), 0.9 m from the eye
    np.testing.assert_allclose(truth["depth_z"][32, 32], 0.9, rtol=TOL_ANALYTIC_REL)
    assert truth["object_id"][32, 32] == 1


@pytest.mark.render
@pytest.mark.parametrize("roughness", [0.0, 0.2])
def test_glass_sphere_truth_is_its_front_surface(tmp_path, roughness):
    body = f"""render: {{spp: 16, max_depth: 8}}
objects:
  - name: glass
    shape: {{type: sphere, radius: 0.3}}
    material: {{type: dielectric, ior: 1.5, roughness: {roughness}}}
  - name: back
    shape: {{type: plane, size: [4, 4]}}
    transform: {{translation: [0, 0, -0.5]}}
    material: {{type: diffuse, texture: {{type: checkerboard}}}}
lights:
  - {{type: constant, radiance: 1.0}}
"""
    spec_path, img, truth = render(tmp_path, f"glass{int(roughness * 10)}", body)
    assert np.isfinite(img).all()
    view = resolve_views(load_spec(spec_path))[0]
    cam = load_spec(spec_path).cameras["cam"].to_camera()
    from scenegen.geometry.conventions import pixel_centers

    d = cam.unproject_unit(pixel_centers(64, 64).reshape(-1, 2))
    world_from_cam = view.cam_from_world.inverse()
    o, dw = world_from_cam.t, world_from_cam.rotate(d)
    b = dw @ o
    disc = b**2 - (o @ o - 0.3**2)
    hit = disc > 0
    t = -b - np.sqrt(np.where(hit, disc, 0))  # the nearer root: the glass's front surface
    got = truth["range"].reshape(-1)
    np.testing.assert_allclose(got[hit], t[hit], rtol=TOL_ANALYTIC_REL)
    assert np.all(truth["object_id"].reshape(-1)[hit] == 1)


def terminator_shadowing(n_perturbed, to_light):
    """The bump-terminator shadowing Mitsuba's normalmap and bumpmap apply (Estevez, Kulla et
    al., "A Microfacet-Based Shadowing Function to Solve the Bump Terminator Problem", Ray
    Tracing Gems 2019): G = 2 / (1 + sqrt(1 + alpha^2 tan^2(theta_i))), alpha^2 = tan^2(d) / 8,
    d the angle between the perturbed and the surface normal (+z here)."""
    cos_d = min(abs(n_perturbed[2]), 1.0)
    alpha2 = np.clip(0.125 * (1 - cos_d**2) / cos_d**2, 0.0, 1.0)
    cos_i = np.maximum(np.abs(to_light[..., 2]), 1e-6)
    return 2.0 / (1.0 + np.sqrt(1.0 + alpha2 * (1 - cos_i**2) / cos_i**2))


def write_png16(path, rgb01):
    img = np.round(np.asarray(rgb01) * 65535).astype(np.uint16)
    cv2.imwrite(str(path), img[..., ::-1] if img.ndim == 3 else img)
    return img.astype(np.float64) / 65535


@pytest.mark.render
@pytest.mark.parametrize("kind", ["normal_map", "bump_map"])
def test_normal_and_bump_maps_tilt_the_shading(tmp_path, kind):
    """A 2 m x 2 m plane (texture upright: u along world +x, the image's top towards +y) lit by a
    point light off to one side: the radiance ratio to the unmapped plane is (n' . l) / (n . l)
    per pixel (direct light of a point source is noise-free), times Mitsuba's bump-terminator
    shadowing (:func:`terminator_shadowing`). A normal map's tangent space: +x
    along u, +y = n x (+x), UP the image (world +y here), +z along n. A bump map of heights
    h(u) = u with scale s displaces s h metres along n: over the plane's 2 m per UV unit that is a
    slope s / 2, so n' ~ (-s / 2, 0, 1). The light's offset makes the sign of each tilt count."""
    if kind == "normal_map":
        n = np.array([np.sin(np.radians(25.0)), np.sin(np.radians(30.0)), 0.0])
        n[2] = np.sqrt(1 - n[0] ** 2 - n[1] ** 2)
        stored = write_png16(tmp_path / "map.png", np.tile((n + 1) / 2, (4, 4, 1)))
        n_map = 2 * stored[0, 0] - 1
        extra = "normal_map: map.png"
    else:
        W, scale = 64, 0.8
        ramp = np.tile((np.arange(W) + 0.5) / W, (8, 1))  # h(u) = u: slope 1 in UV units
        write_png16(tmp_path / "map.png", ramp)
        n_map = np.array([-scale / 2, 0.0, 1.0])
        extra = f"bump_map: map.png, bump_scale: {scale}"
    n_map = n_map / np.linalg.norm(n_map)
    light = np.array([-6.0, 8.0, 20.0])
    lights = f"lights:\n  - {{type: point, position: {light.tolist()}, intensity: 1600}}\n"
    base = "render: {spp: 4, max_depth: 2}\nobjects:\n  - name: p\n    shape: {type: plane, size: [2, 2]}\n"
    _, flat, _ = render(tmp_path, "flat", base + "    material: {type: diffuse, color: 0.5}\n" + lights)
    _, tilted, truth = render(tmp_path, kind, base + f"    material: {{type: diffuse, color: 0.5, {extra}}}\n" + lights)
    ratio = tilted[24:40, 24:40, 0] / flat[24:40, 24:40, 0]
    p = truth["points_world"][24:40, 24:40].astype(np.float64)
    to_light = (light - p) / np.linalg.norm(light - p, axis=-1, keepdims=True)
    want = (to_light @ n_map) / to_light[..., 2] * terminator_shadowing(n_map, to_light)
    mirrored = (to_light @ (n_map * [-1, -1, 1])) / to_light[..., 2]
    assert np.min(np.abs(want - mirrored)) > 0.1  # the test tells the tilt's sign
    print(f"{kind}: radiance ratio {ratio.mean():.5f} vs closed form {want.mean():.5f}, "
          f"max rel. error {np.max(np.abs(ratio / want - 1)):.2e}")
    np.testing.assert_allclose(ratio, want, rtol=TOL_RATIO)
    # the truth normal is the surface's, not the map's (docs/scene_spec.md)
    np.testing.assert_allclose(truth["normals_world"][32, 32], [0, 0, 1], atol=1e-6)
