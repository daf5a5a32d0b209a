"""A folding calibration rendered with `mask_beyond_fold`: the render says how many pixels get
no ray, they are black and invalid in every truth map, exactly where an independent computation
of the fold radius puts them; every other pixel sees the floor."""
import numpy as np
import pytest

from scenegen.cli import main
from scenegen.dataset import Dataset
from scenegen.geometry.conventions import pixel_centers

W, H, F, CX, CY, K1, K2 = 160, 120, 140.0, 79.5, 59.5, -0.4, 0.03
SPEC = f"""name: fold
render: {{spp: 4, max_depth: 2}}
objects:
  - name: floor
    shape: {{type: plane, size: [8, 8]}}
    material: {{type: diffuse, color: 0.5}}
lights:
  - {{type: constant, radiance: 1.0}}
cameras:
  wide: {{model: opencv, size: [{W}, {H}], fx: {F}, fy: {F}, cx: {CX}, cy: {CY}, dist: [{K1}, {K2}, 0, 0, 0], mask_beyond_fold: true}}
views:
  - camera: wide
    look_at: [{{eye: [0, 0, 1.0], target: [0, 0, 0], up: [0, 1, 0]}}]
"""


def beyond(uv):
    """From scratch: distorted radius beyond r_d at the smallest root of 1 + 3 k1 r^2 + 5 k2 r^4."""
    r2 = min(x.real for x in np.roots([5 * K2, 3 * K1, 1.0]) if abs(x.imag) < 1e-12 and x.real > 0)
    r_d_fold = np.sqrt(r2) * (1 + K1 * r2 + K2 * r2 * r2)
    return np.hypot((uv[..., 0] - CX) / F, (uv[..., 1] - CY) / F) > r_d_fold


@pytest.mark.render
def test_fold_masked_render(tmp_path, capsys):
    (tmp_path / "fold.yaml").write_text(SPEC)
    assert main(["render", str(tmp_path / "fold.yaml"), "-o", str(tmp_path / "out"), "-q"]) == 0
    centres = pixel_centers(W, H)
    want = beyond(centres)
    n = int(want.sum())
    assert n > 100
    assert f"camera 'wide': {n} of {W * H} pixels" in capsys.readouterr().err
    ds = Dataset(tmp_path / "out")
    view = ds.views[0]
    truth, img = ds.truth(view), ds.linear_image(view)
    assert np.array_equal(~truth["valid"], want)
    assert np.all(truth["object_id"][want] == 0) and np.all(truth["instance_id"][want] == 0)
    assert np.all(np.isinf(truth["depth_z"][want])) and np.all(np.isinf(truth["range"][want]))
    for key in ("points_world", "points_cam", "normals_world", "normals_cam", "uv"):
        assert np.isnan(truth[key][want]).all(), key
    # black where the whole pixel square lies beyond the fold, lit where it lies inside
    corners = [beyond(centres + np.array(o)) for o in ((-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5))]
    all_out, all_in = np.logical_and.reduce(corners), ~np.logical_or.reduce(corners)
    assert all_out.sum() > 50 and np.all(img[all_out] == 0)
    assert np.all(img[all_in] > 0.2)  # the floor: 0.5 up to Monte Carlo noise at 4 spp
    record = ds.cameras["views"][view]["camera"]
    assert record["mask_beyond_fold"] is True and record["pixels_beyond_fold"] == n
