"""Two-view geometry on planted poses: E, F, epipoles, plane homographies, the zero baseline."""
import json

import numpy as np

from scenegen.dataset.codecs import encode_json
from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3, look_at
from scenegen.geometry.twoview import TwoView, fundamental, plane_homography


def test_twoview_known_values():
    """A planted pose: pure x translation gives F with horizontal epipolar lines and epipoles at
    infinity; E = [t]x R by hand."""
    K = np.array([[100.0, 0, 50], [0, 100, 40], [0, 0, 1]])
    rel = Rigid3(np.eye(3), [-0.2, 0, 0])
    F = fundamental(K, K, rel)
    x = np.array([[10.0, 30.0, 1.0]])
    line = F @ x[0]  # epipolar line in j: a v + b u + c = 0 with b = 0 -> v = 30
    assert abs(line[0]) < 1e-15 and abs(-line[2] / line[1] - 30.0) < 1e-12
    tv = TwoView.of(Camera("pinhole", 100, 80, 100, 100, 50, 40), Rigid3.identity(),
                    Camera("pinhole", 100, 80, 100, 100, 50, 40), rel)
    assert np.allclose(tv.F, F) and tv.to_dict()["epipole_i_px"] is None  # at infinity
    assert np.allclose(tv.E, [[0, 0, 0], [0, 0, 0.2], [0, -0.2, 0]])
    # a plane z = 2 in i: its homography maps the centre (depth 2) to u - f B / Z = 50 - 10
    H = plane_homography(K, K, rel, [0, 0, 1.0], 2.0)
    x = H @ [50.0, 40.0, 1.0]
    assert np.allclose(x[:2] / x[2], [40.0, 40.0])


def test_twoview_zero_baseline():
    """A roll about the optical axis (one centre) and the very same pose: no E, F or epipoles
    (null in JSON, not NaN or noise); the plane homography is the infinite one, K R K^-1."""
    cam = Camera("pinhole", 100, 80, 100, 100, 49.5, 39.5)
    eye = [0.3, -1.2, 1.0]
    ref = look_at(eye, [0.3, 0, 1.0]).inverse()
    rolled = look_at(eye, [0.3, 0, 1.0], up=[np.sin(0.5), 0, np.cos(0.5)]).inverse()
    for other in (rolled, ref):
        tv = TwoView.of(cam, ref, cam, other)
        assert tv.E is None and tv.F is None and tv.epipole_i is None and tv.epipole_j is None
        d = json.loads(encode_json(tv.to_dict()))  # JSON has no NaN: this would raise
        assert d["E"] is d["F"] is d["epipole_i_px"] is None and d["baseline_m"] < 1e-12
        H = plane_homography(cam.K, cam.K, tv.j_from_i, [0, 0, 1.0], 1.2)
        H_inf = cam.K @ tv.j_from_i.R @ np.linalg.inv(cam.K)
        assert np.allclose(H, H_inf / H_inf[2, 2], atol=1e-9)
    # the roll turns the image about the principal point, counter-clockwise on screen: a point
    # 10 px right of it moves up by 0.5 rad
    x = plane_homography(cam.K, cam.K, TwoView.of(cam, ref, cam, rolled).j_from_i, [0, 0, 1.0], 1.2) @ [59.5, 39.5, 1]
    assert np.allclose(x[:2] / x[2], [49.5 + 10 * np.cos(0.5), 39.5 - 10 * np.sin(0.5)], atol=1e-9)


# --- occlusion against an analytic occluder ------------------------------------------------
