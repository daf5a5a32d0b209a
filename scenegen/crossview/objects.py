"""Object truth of a view in numpy (docs/dataset_format.md, "Object truth"; stored by
:mod:`scenegen.dataset.objects`): BOP's silhouette statistics of an object from its full mask
(cast alone) and its visible mask (the ids truth), a model's diameter, and a keypoint's state from
its projection and the distances along its ray to the first surface of the scene and of its own
object (or articulated tree) alone.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import ConvexHull, QhullError
from scipy.spatial.distance import pdist

from scenegen.dataset.crossview import OCCLUSION_REL_TOL
from scenegen.geometry.conventions import in_image


#: BOP's calc_gt_info.py renders each object alone into an image 3x as wide and high, the
#: image in its middle (``ren_cx_offset = im_width``), so that ``px_count_all`` and ``bbox_obj``
#: include the silhouette's part beyond the image border: the same grid here.
def extended_pixels(width: int, height: int) -> np.ndarray:
    """(3H * 3W, 2) OpenCV pixel centres of the extended grid, row-major: u in [-W, 2W), v in
    [-H, 2H) (the image is the block [H:2H, W:2W])."""
    u, v = np.meshgrid(np.arange(-width, 2 * width, dtype=np.float64),
                       np.arange(-height, 2 * height, dtype=np.float64))
    return np.stack([u, v], axis=-1).reshape(-1, 2)


def in_image_block(mask_ext: np.ndarray, width: int, height: int) -> np.ndarray:
    """The image's (H, W) block of an extended (3H, 3W) mask."""
    return mask_ext[height:2 * height, width:2 * width]


def mask_box(mask: np.ndarray, offset_uv=(0, 0)) -> tuple[int, int, int, int] | None:
    """``[u_min, v_min, u_max, v_max]``: the inclusive range of the OpenCV pixel centres of an
    (H, W) bool mask's pixels, shifted by ``offset_uv`` (the extended grid's: (-W, -H)); None if empty."""
    v, u = np.nonzero(mask)
    if u.size == 0:
        return None
    du, dv = offset_uv
    return (int(u.min() + du), int(v.min() + dv), int(u.max() + du), int(v.max() + dv))


def silhouette_stats(mask_all: np.ndarray, mask_visib: np.ndarray) -> tuple[int, int, float]:
    """(px_count_all, px_count_visib, visib_fract) of an object's silhouette alone (the extended
    grid) and its visible mask; ``visib_fract`` = visible / all as BOP's ``calc_gt_info.py`` (0
    when the silhouette covers no pixel)."""
    n_all, n_vis = int(np.count_nonzero(mask_all)), int(np.count_nonzero(mask_visib))
    return n_all, n_vis, (n_vis / n_all if n_all > 0 else 0.0)


def diameter(vertices: np.ndarray) -> float:
    """The largest distance between two of the (V, 3) vertices (BOP's model diameter), metres;
    reached at vertices of the convex hull, so only those are compared."""
    v = np.asarray(vertices, np.float64).reshape(-1, 3)
    if len(v) < 2:
        return 0.0
    try:
        v = v[ConvexHull(v).vertices]
    except QhullError:  # flat or degenerate: compare them all
        pass
    return float(pdist(v).max())


def keypoint_states(uv: np.ndarray, projects: np.ndarray, width: int, height: int, dist_m: np.ndarray,
                    t_scene_m: np.ndarray, t_self_m: np.ndarray) -> list[str]:
    """The state of each of N keypoints (:data:`scenegen.dataset.objects.KEYPOINT_STATES`):
    ``uv`` (N, 2) their projections, ``projects`` (N,) whether they project at all, ``dist_m``
    (N,) their distance from the camera centre, ``t_scene_m`` / ``t_self_m`` (N,) the distance
    along the ray towards each to the first surface of the scene / of its own object (tree) alone
    (+inf: none). Hidden when a surface lies nearer than ``dist (1 - OCCLUSION_REL_TOL)`` (the
    visibility rule of the cross-view truth); by itself when its own surface does."""
    near = dist_m * (1.0 - OCCLUSION_REL_TOL)
    inside = np.asarray(projects, bool) & in_image(uv, width, height)
    out = []
    for k in range(len(dist_m)):
        if not inside[k]:
            out.append("out_of_image")
        elif t_self_m[k] < near[k]:
            out.append("self_occluded")
        elif t_scene_m[k] < near[k]:
            out.append("occluded")
        else:
            out.append("visible")
    return out
