"""The LK long-track baseline on sequences whose motion is known exactly."""
import cv2
import numpy as np

from recon_eval.metrics.tapvid import tapvid_metrics
from recon_eval.runners.tracking import FB_MAX_PX, lk_tracks


def _texture(h=160, w=200, seed=3):
    rng = np.random.default_rng(seed)
    return cv2.GaussianBlur(rng.uniform(0, 255, (h * 2, w * 2)).astype(np.float32), (0, 0), 2.0)


def _shifted(tex, dx, dy, h=120, w=160):
    m = np.float32([[1, 0, dx - 20], [0, 1, dy - 20]])  # frame pixel x shows texture pixel x - dx + 20
    return cv2.warpAffine(tex, m, (w, h), flags=cv2.INTER_CUBIC, borderMode=cv2.BORDER_REFLECT)


def test_tracks_follow_a_known_translation_and_leave_the_frame():
    tex = _texture()
    shifts = [(6.1 * t, -0.7 * t) for t in range(8)]
    frames = [np.clip(_shifted(tex, dx, dy), 0, 255).astype(np.uint8) for dx, dy in shifts]
    ys, xs = np.mgrid[30:90:15, 20:150:26]
    q = np.stack([np.zeros(xs.size), ys.ravel(), xs.ravel()], 1).astype(float)
    q[-3:, 0] = 4  # three queries from the middle of the sequence (tracked backwards too)
    tracks, occ = lk_tracks(frames, q)
    t = np.arange(8)
    qt = q[:, 0].astype(int)
    truth = np.stack([q[:, 2:3] + 6.1 * (t - qt[:, None]), q[:, 1:2] - 0.7 * (t - qt[:, None])], -1)
    gt_occ = (truth[..., 0] < 0) | (truth[..., 0] > 159) | (truth[..., 1] < 0) | (truth[..., 1] > 119)
    err = np.linalg.norm(tracks - truth, axis=-1)
    assert gt_occ.sum() >= 5  # the case has points that leave the image
    assert np.median(err[~occ]) < 0.1 and err[~occ].max() < FB_MAX_PX  # the chain drops points beyond its FB bound
    assert np.mean(occ[~gt_occ]) < 0.05  # points in view are kept
    assert occ[gt_occ].all()  # points that left the image are lost, not kept at the border
    r = tapvid_metrics(q, truth, gt_occ, tracks, occ, image_size=(160, 120), query_mode="strided")
    assert r.average_pts_within > 0.8 and r.occlusion_accuracy > 0.9


def test_a_point_covered_by_a_new_surface_is_lost():
    tex = _texture()
    frames = [np.clip(_shifted(tex, 0, 0), 0, 255).astype(np.uint8) for _ in range(4)]
    frames[2] = frames[2].copy()
    frames[2][30:90, 50:110] = 128  # a flat occluder over the query point at frame 2
    tracks, occ = lk_tracks(frames, [[0, 60, 80]])
    assert not occ[0, :2].any() and occ[0, 2]
    assert np.allclose(tracks[0, 0], [80, 60])
