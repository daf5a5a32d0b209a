"""The image motion of rendered features matches the truth flow (issue 16): a plate with a smooth
dark dot moves (it slides, or it turns and rises towards the camera) in front of a uniform sky; the dots' intensity centroids, measured in the renders, move by the truth flow at
the centroid within 0.05 px.

Why the comparison is exact in principle: the plate stays fronto-parallel to a pinhole camera,
so its image moves by an affine map, and the intensity-weighted centroid of an image moves with
that affine map. The plate's white (albedo 1 under a constant sky) renders as the sky itself, so
only the dot carries weight; the dot is smooth (sigma ~3 px), so the box-filtered pixels sample
its centroid without bias."""
import cv2
import numpy as np
import pytest

from scenegen.dataset import Dataset
from scenegen.dataset.codecs import decode_flo
from scenegen.pipeline.run import render_spec

pytestmark = pytest.mark.render

TOL_CENTROID_PX = 0.05  # the bound
WINDOW_PX = 9.0  # radius of the centroid's disc: ~3.5 sigma of the dot's linear profile

HEAD = """
name: blobs
render: {spp: 512, max_depth: 2, sampler: ldsampler}
sequence: {fps: 10, frames: 2, flow_steps: [1]}
materials:
  dot: {type: diffuse, texture: {type: image, path: dot.png}}
lights: [{type: constant, radiance: 1}]
cameras: {cam: {size: [160, 120], fx: 150}}
views:
  - camera: cam
    trajectory:
      keyframes: [{time_s: 0, eye: [0, 0, 2], target: [0, 0, 0], up: [0, 1, 0]}]
objects:
"""
# One plate per scene: a second plate would shade this one's white from part of the sky once it
# rises, and that gradient (not the geometry) would pull the centroid.
PLATES = {
    "slides": """  - name: plate
    shape: {type: plane, size: [0.4, 0.4]}
    material: dot
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, translation: [-0.35, 0.1, 0.0]}
        - {time_s: 0.1, translation: [-0.27, 0.04, 0.0]}
""",
    "turns_and_rises": """  - name: plate
    shape: {type: plane, size: [0.4, 0.4]}
    material: dot
    trajectory:
      keyframes:
        - {time_s: 0.0, translation: [0.3, -0.05, 0.0], rotation_deg: [0, 0, 0]}
        - {time_s: 0.1, translation: [0.28, -0.1, 0.35], rotation_deg: [0, 0, 35]}
""",
}


def _dot_png(path):
    n = 256
    y, x = np.mgrid[0:n, 0:n] + 0.5
    # the dot off the plate's centre, so the turning plate also moves it
    r2 = (x - 150) ** 2 + (y - 110) ** 2
    img = 1.0 - 0.9 * np.exp(-r2 / (2 * 30.0 ** 2))
    cv2.imwrite(str(path), np.round(img * 65535).astype(np.uint16))


def _bilinear(field, x, y):
    x0, y0 = int(np.floor(x)), int(np.floor(y))
    fx, fy = x - x0, y - y0
    f = field[y0:y0 + 2, x0:x0 + 2]
    return (f[0, 0] * (1 - fx) * (1 - fy) + f[0, 1] * fx * (1 - fy) + f[1, 0] * (1 - fx) * fy
            + f[1, 1] * fx * fy)


def _centroid(img, mask, radius_px=WINDOW_PX, rounds=20):
    """Intensity centroid (x, y) of the dot: weights 1 - pixel (the sky is 1), in a disc about
    the current estimate, iterated from the plate's centroid. For a dot that stays round (a
    similarity image map), the disc's fixed point is the dot's centre; the disc leaves out the
    render noise of the plate's white far from the dot."""
    w_all = 1.0 - np.asarray(img, np.float64)
    yy, xx = np.mgrid[0:img.shape[0], 0:img.shape[1]]
    c = np.array([xx[mask].mean(), yy[mask].mean()])
    for _ in range(rounds):
        c0 = np.array([(w_all * mask * xx).sum(), (w_all * mask * yy).sum()]) / (w_all * mask).sum() \
            if _ == 0 else c
        disc = (xx - c0[0]) ** 2 + (yy - c0[1]) ** 2 <= radius_px ** 2
        w = w_all * disc
        c = np.array([(w * xx).sum(), (w * yy).sum()]) / w.sum()
    return c


@pytest.mark.parametrize("motion", sorted(PLATES))
def test_rendered_dot_moves_by_the_truth_flow(tmp_path, motion):
    _dot_png(tmp_path / "dot.png")
    (tmp_path / "scene.yaml").write_text(HEAD + PLATES[motion])
    render_spec(tmp_path / "scene.yaml", tmp_path / "out", progress=False)
    ds = Dataset(tmp_path / "out")
    flow = decode_flo((tmp_path / "out/sequence/flow/cam_0000/cam_0001.flo").read_bytes()).astype(np.float64)
    cents = [_centroid(ds.linear_image(v)[..., 1], ds.truth(v)["object_id"] == 1) for v in ds.views]
    moved = cents[1] - cents[0]
    truth = _bilinear(flow, *cents[0])
    error = float(np.linalg.norm(moved - truth))
    print(f"{motion}: centroid moved {moved.round(4)} px, truth flow {truth.round(4)} px, error {error:.4f} px")
    assert np.linalg.norm(truth) > 3  # it does move
    assert error < TOL_CENTROID_PX


def test_motion_blur_follows_the_trajectory_within_the_exposure(tmp_path):
    """With a 40 ms exposure the sliding dot is smeared along its path (8 motion sub-frames on
    the trajectory), and its centroid stays at the frame time's position: the linear trajectory
    is symmetric about mid-exposure."""
    _dot_png(tmp_path / "dot.png")
    plate = PLATES["slides"].replace("time_s: 0.1,", "time_s: 0.2,")  # 0.4 m/s; frames 0.1 s apart
    sharp, blurred = (HEAD.replace("fx: 150}", "fx: 150" + s + "}") for s in ("", ", shutter: {exposure_s: 0.04}"))
    moments = []
    for name, head in (("sharp", sharp), ("blurred", blurred)):
        (tmp_path / f"{name}.yaml").write_text(head.replace("frames: 2", "frames: 2, start_s: 0.05") + plate)
        render_spec(tmp_path / f"{name}.yaml", tmp_path / name, progress=False)
        ds = Dataset(tmp_path / name)
        img, mask = ds.linear_image(ds.views[0])[..., 1], ds.truth(ds.views[0])["object_id"] == 1
        c = _centroid(img, mask, radius_px=14.0)
        w = np.clip(1.0 - img.astype(np.float64), 0, None)
        yy, xx = np.mgrid[0:img.shape[0], 0:img.shape[1]]
        disc = (xx - c[0]) ** 2 + (yy - c[1]) ** 2 <= 14.0 ** 2
        d = np.stack([xx - c[0], yy - c[1]], -1)[disc]
        cov = (w[disc][:, None, None] * d[:, :, None] * d[:, None, :]).sum(0) / w[disc].sum()
        moments.append((c, cov))
    (c0, cov0), (c1, cov1) = moments
    streak = np.array([0.4 * 0.04 * 75.0, 0.3 * 0.04 * 75.0])  # image motion over the exposure, px
    print(f"blurred centroid {c1.round(4)} vs sharp {c0.round(4)}: {np.linalg.norm(c1 - c0):.4f} px; "
          f"variance along the path +{streak @ (cov1 - cov0) @ streak / (streak @ streak):.3f} px^2 "
          f"(a uniform smear of {np.linalg.norm(streak):.2f} px adds {np.linalg.norm(streak) ** 2 / 12:.3f})")
    assert np.linalg.norm(c1 - c0) < TOL_CENTROID_PX
    u = streak / np.linalg.norm(streak)
    assert abs(u @ (cov1 - cov0) @ u - np.linalg.norm(streak) ** 2 / 12) < 0.1 * np.linalg.norm(streak) ** 2 / 12
