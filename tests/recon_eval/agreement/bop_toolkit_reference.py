"""A faithful copy of the reference BOP evaluation code, for the agreement tests of
recon_eval.metrics.objects_bop (bop_toolkit is not on PyPI, so it cannot be a dev dependency).

Source: https://github.com/thodan/bop_toolkit, commit cea62d651c7e395b2e1962b9749e4e89693c6ac4
(2026-06-19). The functions below are copied verbatim from bop_toolkit_lib/transform.py,
misc.py, visibility.py, pose_error.py, pose_matching.py and score.py; the module prefixes they
use (``misc.``, ``visibility.``, ``transform.``) resolve to the namespaces at the end of this
file. ``evaluate_bop19`` at the end is the loop of scripts/eval_calc_errors.py,
scripts/eval_calc_scores.py and scripts/eval_bop19_pose.py (localization mode, n_top = -1,
visib_gt_min = -1, max_sym_disc_step = 0.01, the VSD/MSSD/MSPD thresholds of eval_bop19_pose.py)
with the files replaced by in-memory dicts; the renderer passed to ``vsd`` is any object with
``render_object(obj_id, R, t, fx, fy, cx, cy) -> {"depth": ...}`` (the tests pass our ray-cast
renderer: what is compared is the VSD arithmetic, not OpenGL rasterisation).

Licence of the copied code (bop_toolkit LICENSE):

MIT License

Copyright (c) 2019 Tomas Hodan

Permission is hereby granted, free of charge, to any person obtaining a copy
of this software and associated documentation files (the "Software"), to deal
in the Software without restriction, including without limitation the rights
to use, copy, modify, merge, publish, distribute, sublicense, and/or sell
copies of the Software, and to permit persons to whom the Software is
furnished to do so, subject to the following conditions:

The above copyright notice and this permission notice shall be included in all
copies or substantial portions of the Software.

THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER
LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM,
OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE
SOFTWARE.
"""
# ruff: noqa
import math
import types
from collections import defaultdict

import numpy
import numpy as np
from scipy import spatial

# ---- bop_toolkit_lib/transform.py --------------------------------------------

def rotation_matrix(angle, direction, point=None):
    """Return matrix to rotate about axis defined by point and direction.

    >>> R = rotation_matrix(math.pi/2, [0, 0, 1], [1, 0, 0])
    >>> numpy.allclose(numpy.dot(R, [0, 0, 0, 1]), [1, -1, 0, 1])
    True
    >>> angle = (random.random() - 0.5) * (2*math.pi)
    >>> direc = numpy.random.random(3) - 0.5
    >>> point = numpy.random.random(3) - 0.5
    >>> R0 = rotation_matrix(angle, direc, point)
    >>> R1 = rotation_matrix(angle-2*math.pi, direc, point)
    >>> is_same_transform(R0, R1)
    True
    >>> R0 = rotation_matrix(angle, direc, point)
    >>> R1 = rotation_matrix(-angle, -direc, point)
    >>> is_same_transform(R0, R1)
    True
    >>> I = numpy.identity(4, numpy.float64)
    >>> numpy.allclose(I, rotation_matrix(math.pi*2, direc))
    True
    >>> numpy.allclose(2, numpy.trace(rotation_matrix(math.pi/2,
    ...                                               direc, point)))
    True

    """
    sina = math.sin(angle)
    cosa = math.cos(angle)
    direction = unit_vector(direction[:3])
    # rotation matrix around unit vector
    R = numpy.diag([cosa, cosa, cosa])
    R += numpy.outer(direction, direction) * (1.0 - cosa)
    direction *= sina
    R += numpy.array(
        [
            [0.0, -direction[2], direction[1]],
            [direction[2], 0.0, -direction[0]],
            [-direction[1], direction[0], 0.0],
        ]
    )
    M = numpy.identity(4)
    M[:3, :3] = R
    if point is not None:
        # rotation not around origin
        point = numpy.array(point[:3], dtype=numpy.float64, copy=False)
        M[:3, 3] = point - numpy.dot(R, point)
    return M


def unit_vector(data, axis=None, out=None):
    """Return ndarray normalized by length, i.e. Euclidean norm, along axis.

    >>> v0 = numpy.random.random(3)
    >>> v1 = unit_vector(v0)
    >>> numpy.allclose(v1, v0 / numpy.linalg.norm(v0))
    True
    >>> v0 = numpy.random.rand(5, 4, 3)
    >>> v1 = unit_vector(v0, axis=-1)
    >>> v2 = v0 / numpy.expand_dims(numpy.sqrt(numpy.sum(v0*v0, axis=2)), 2)
    >>> numpy.allclose(v1, v2)
    True
    >>> v1 = unit_vector(v0, axis=1)
    >>> v2 = v0 / numpy.expand_dims(numpy.sqrt(numpy.sum(v0*v0, axis=1)), 1)
    >>> numpy.allclose(v1, v2)
    True
    >>> v1 = numpy.empty((5, 4, 3))
    >>> unit_vector(v0, axis=1, out=v1)
    >>> numpy.allclose(v1, v2)
    True
    >>> list(unit_vector([]))
    []
    >>> list(unit_vector([1]))
    [1.0]

    """
    if out is None:
        data = numpy.array(data, dtype=numpy.float64, copy=True)
        if data.ndim == 1:
            data /= math.sqrt(numpy.dot(data, data))
            return data
    else:
        if out is not data:
            out[:] = numpy.array(data, copy=False)
        data = out
    length = numpy.atleast_1d(numpy.sum(data * data, axis))
    numpy.sqrt(length, length)
    if axis is not None:
        length = numpy.expand_dims(length, axis)
    data /= length
    if out is None:
        return data


# ---- bop_toolkit_lib/misc.py -------------------------------------------------

def get_symmetry_transformations(model_info, max_sym_disc_step):
    """Returns a set of symmetry transformations for an object model.

    :param model_info: See files models_info.json provided with the datasets.
    :param max_sym_disc_step: The maximum fraction of the object diameter which
      the vertex that is the furthest from the axis of continuous rotational
      symmetry travels between consecutive discretized rotations.
    :return: The set of symmetry transformations.
    """
    # Discrete symmetries.
    trans_disc = [{"R": np.eye(3), "t": np.array([[0, 0, 0]]).T}]  # Identity.
    if "symmetries_discrete" in model_info:
        for sym in model_info["symmetries_discrete"]:
            sym_4x4 = np.reshape(sym, (4, 4))
            R = sym_4x4[:3, :3]
            t = sym_4x4[:3, 3].reshape((3, 1))
            trans_disc.append({"R": R, "t": t})

    # Discretized continuous symmetries.
    trans_cont = []
    if "symmetries_continuous" in model_info:
        for sym in model_info["symmetries_continuous"]:
            axis = np.array(sym["axis"])
            offset = np.array(sym["offset"]).reshape((3, 1))

            # (PI * diam.) / (max_sym_disc_step * diam.) = discrete_steps_count
            discrete_steps_count = int(np.ceil(np.pi / max_sym_disc_step))

            # Discrete step in radians.
            discrete_step = 2.0 * np.pi / discrete_steps_count

            for i in range(0, discrete_steps_count):
                R = transform.rotation_matrix(i * discrete_step, axis)[:3, :3]
                t = -R.dot(offset) + offset
                trans_cont.append({"R": R, "t": t})

    # Combine the discrete and the discretized continuous symmetries.
    trans = []
    for tran_disc in trans_disc:
        if len(trans_cont):
            for tran_cont in trans_cont:
                R = tran_cont["R"].dot(tran_disc["R"])
                t = tran_cont["R"].dot(tran_disc["t"]) + tran_cont["t"]
                trans.append({"R": R, "t": t})
        else:
            trans.append(tran_disc)

    return trans


def project_pts(pts, K, R, t):
    """Projects 3D points.

    :param pts: nx3 ndarray with the 3D points.
    :param K: 3x3 ndarray with an intrinsic camera matrix.
    :param R: 3x3 ndarray with a rotation matrix.
    :param t: 3x1 ndarray with a translation vector.
    :return: nx2 ndarray with 2D image coordinates of the projections.
    """
    assert pts.shape[1] == 3
    P = K.dot(np.hstack((R, t)))
    pts_h = np.hstack((pts, np.ones((pts.shape[0], 1))))
    pts_im = P.dot(pts_h.T)
    pts_im /= pts_im[2, :]
    return pts_im[:2, :].T


class Precomputer(object):
    """Caches pre_Xs, pre_Ys for a 30% speedup of depth_im_to_dist_im()"""

    xs, ys = None, None
    pre_Xs, pre_Ys = None, None
    depth_im_shape = None
    K = None

    @staticmethod
    def precompute_lazy(depth_im, K):
        """Lazy precomputation for depth_im_to_dist_im() if depth_im.shape or K changes

        :param depth_im: hxw ndarray with the input depth image, where depth_im[y, x]
          is the Z coordinate of the 3D point [X, Y, Z] that projects to pixel [x, y],
          or 0 if there is no such 3D point (this is a typical output of the
          Kinect-like sensors).
        :param K: 3x3 ndarray with an intrinsic camera matrix.
        :return: hxw ndarray (Xs/depth_im, Ys/depth_im)
        """
        if depth_im.shape != Precomputer.depth_im_shape:
            Precomputer.xs, Precomputer.ys = np.meshgrid(
                np.arange(depth_im.shape[1]), np.arange(depth_im.shape[0])
            )

        if depth_im.shape != Precomputer.depth_im_shape or not np.all(
            K == Precomputer.K
        ):
            Precomputer.K = K
            Precomputer.pre_Xs = (Precomputer.xs - K[0, 2]) / np.float64(K[0, 0])
            Precomputer.pre_Ys = (Precomputer.ys - K[1, 2]) / np.float64(K[1, 1])

        Precomputer.depth_im_shape = depth_im.shape
        return Precomputer.pre_Xs, Precomputer.pre_Ys


def depth_im_to_dist_im_fast(depth_im, K):
    """Converts a depth image to a distance image.

    :param depth_im: hxw ndarray with the input depth image, where depth_im[y, x]
      is the Z coordinate of the 3D point [X, Y, Z] that projects to pixel [x, y],
      or 0 if there is no such 3D point (this is a typical output of the
      Kinect-like sensors).
    :param K: 3x3 ndarray with an intrinsic camera matrix.
    :return: hxw ndarray with the distance image, where dist_im[y, x] is the
      distance from the camera center to the 3D point [X, Y, Z] that projects to
      pixel [x, y], or 0 if there is no such 3D point.
    """
    # Only recomputed if depth_im.shape or K changes.
    pre_Xs, pre_Ys = Precomputer.precompute_lazy(depth_im, K)

    dist_im = np.sqrt(
        np.multiply(pre_Xs, depth_im) ** 2
        + np.multiply(pre_Ys, depth_im) ** 2
        + depth_im.astype(np.float64) ** 2
    )

    return dist_im


def transform_pts_Rt(pts, R, t):
    """Applies a rigid transformation to 3D points.

    :param pts: nx3 ndarray with 3D points.
    :param R: 3x3 ndarray with a rotation matrix.
    :param t: 3x1 ndarray with a translation vector.
    :return: nx3 ndarray with transformed 3D points.
    """
    assert pts.shape[1] == 3
    pts_t = R.dot(pts.T) + t.reshape((3, 1))
    return pts_t.T


def overlapping_sphere_projections(radius, p1, p2):
    """Checks if projections of two spheres overlap (approximated).

    :param radius: Radius of the two spheres.
    :param p1: [X1, Y1, Z1] center of the first sphere.
    :param p2: [X2, Y2, Z2] center of the second sphere.
    :return: True if the projections of the two spheres overlap.
    """
    if p1[2] == 0 or p2[2] == 0:
        return False

    # 2D projections of centers of the spheres.
    proj1 = (p1 / p1[2])[:2]
    proj2 = (p2 / p2[2])[:2]

    # Distance between the center projections.
    proj_dist = np.linalg.norm(proj1 - proj2)

    # The max. distance of the center projections at which the sphere projections,
    # i.e. sphere silhouettes, still overlap (approximated).
    proj_dist_thresh = radius * (1.0 / p1[2] + 1.0 / p2[2])

    return proj_dist < proj_dist_thresh


# ---- bop_toolkit_lib/visibility.py -------------------------------------------

def _estimate_visib_mask(d_test, d_model, delta, visib_mode="bop19"):
    """Estimates a mask of the visible object surface.

    :param d_test: Distance image of a scene in which the visibility is estimated.
    :param d_model: Rendered distance image of the object model.
    :param delta: Tolerance used in the visibility test.
    :param visib_mode: Visibility mode:
    1) 'bop18' - Object is considered NOT VISIBLE at pixels with missing depth.
    2) 'bop19' - Object is considered VISIBLE at pixels with missing depth. This
         allows to use the VSD pose error function also on shiny objects, which
         are typically not captured well by the depth sensors. A possible problem
         with this mode is that some invisible parts can be considered visible.
         However, the shadows of missing depth measurements, where this problem is
         expected to appear and which are often present at depth discontinuities,
         are typically relatively narrow and therefore this problem is less
         significant.
    :return: Visibility mask.
    """
    assert d_test.shape == d_model.shape

    if visib_mode == "bop18":
        mask_valid = np.logical_and(d_test > 0, d_model > 0)
        d_diff = d_model.astype(np.float32) - d_test.astype(np.float32)
        visib_mask = np.logical_and(d_diff <= delta, mask_valid)

    elif visib_mode == "bop19":
        d_diff = d_model.astype(np.float32) - d_test.astype(np.float32)
        visib_mask = np.logical_and(
            np.logical_or(d_diff <= delta, d_test == 0), d_model > 0
        )

    else:
        raise ValueError("Unknown visibility mode.")

    return visib_mask


def estimate_visib_mask_gt(d_test, d_gt, delta, visib_mode="bop19"):
    """Estimates a mask of the visible object surface in the ground-truth pose.

    :param d_test: Distance image of a scene in which the visibility is estimated.
    :param d_gt: Rendered distance image of the object model in the GT pose.
    :param delta: Tolerance used in the visibility test.
    :param visib_mode: See _estimate_visib_mask.
    :return: Visibility mask.
    """
    visib_gt = _estimate_visib_mask(d_test, d_gt, delta, visib_mode)
    return visib_gt


def estimate_visib_mask_est(d_test, d_est, visib_gt, delta, visib_mode="bop19"):
    """Estimates a mask of the visible object surface in the estimated pose.

    For an explanation of why the visibility mask is calculated differently for
    the estimated and the ground-truth pose, see equation (14) and related text in
    Hodan et al., On Evaluation of 6D Object Pose Estimation, ECCVW'16.

    :param d_test: Distance image of a scene in which the visibility is estimated.
    :param d_est: Rendered distance image of the object model in the est. pose.
    :param visib_gt: Visibility mask of the object model in the GT pose (from
      function estimate_visib_mask_gt).
    :param delta: Tolerance used in the visibility test.
    :param visib_mode: See _estimate_visib_mask.
    :return: Visibility mask.
    """
    visib_est = _estimate_visib_mask(d_test, d_est, delta, visib_mode)
    visib_est = np.logical_or(visib_est, np.logical_and(visib_gt, d_est > 0))
    return visib_est


# ---- bop_toolkit_lib/pose_error.py -------------------------------------------

def vsd(
    R_est,
    t_est,
    R_gt,
    t_gt,
    depth_test,
    K,
    delta,
    taus,
    normalized_by_diameter,
    diameter,
    renderer,
    obj_id,
    cost_type="step",
):
    """Visible Surface Discrepancy -- by Hodan, Michel et al. (ECCV 2018).

    :param R_est: 3x3 ndarray with the estimated rotation matrix.
    :param t_est: 3x1 ndarray with the estimated translation vector.
    :param R_gt: 3x3 ndarray with the ground-truth rotation matrix.
    :param t_gt: 3x1 ndarray with the ground-truth translation vector.
    :param depth_test: hxw ndarray with the test depth image.
    :param K: 3x3 ndarray with an intrinsic camera matrix.
    :param delta: Tolerance used for estimation of the visibility masks.
    :param taus: A list of misalignment tolerance values.
    :param normalized_by_diameter: Whether to normalize the pixel-wise distances
        by the object diameter.
    :param diameter: Object diameter.
    :param renderer: Instance of the Renderer class (see renderer.py).
    :param obj_id: Object identifier.
    :param cost_type: Type of the pixel-wise matching cost:
        'tlinear' - Used in the original definition of VSD in:
            Hodan et al., On Evaluation of 6D Object Pose Estimation, ECCVW'16
        'step' - Used for SIXD Challenge 2017 onwards.
    :return: List of calculated errors (one for each misalignment tolerance).
    """
    # Render depth images of the model in the estimated and the ground-truth pose.
    fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    depth_est = renderer.render_object(obj_id, R_est, t_est, fx, fy, cx, cy)["depth"]
    depth_gt = renderer.render_object(obj_id, R_gt, t_gt, fx, fy, cx, cy)["depth"]

    # Convert depth images to distance images.
    dist_test = misc.depth_im_to_dist_im_fast(depth_test, K)
    dist_gt = misc.depth_im_to_dist_im_fast(depth_gt, K)
    dist_est = misc.depth_im_to_dist_im_fast(depth_est, K)

    # Visibility mask of the model in the ground-truth pose.
    visib_gt = visibility.estimate_visib_mask_gt(
        dist_test, dist_gt, delta, visib_mode="bop19"
    )

    # Visibility mask of the model in the estimated pose.
    visib_est = visibility.estimate_visib_mask_est(
        dist_test, dist_est, visib_gt, delta, visib_mode="bop19"
    )

    # Intersection and union of the visibility masks.
    visib_inter = np.logical_and(visib_gt, visib_est)
    visib_union = np.logical_or(visib_gt, visib_est)

    visib_union_count = visib_union.sum()
    visib_comp_count = visib_union_count - visib_inter.sum()

    # Pixel-wise distances.
    dists = np.abs(dist_gt[visib_inter] - dist_est[visib_inter])

    # Normalization of pixel-wise distances by object diameter.
    if normalized_by_diameter:
        dists /= diameter

    # Calculate VSD for each provided value of the misalignment tolerance.
    if visib_union_count == 0:
        errors = [1.0] * len(taus)
    else:
        errors = []
        for tau in taus:
            # Pixel-wise matching cost.
            if cost_type == "step":
                costs = dists >= tau
            elif cost_type == "tlinear":  # Truncated linear function.
                costs = dists / tau
                costs[costs > 1.0] = 1.0
            else:
                raise ValueError("Unknown pixel matching cost.")

            e = (np.sum(costs) + visib_comp_count) / float(visib_union_count)
            errors.append(e)

    return errors


def mssd(R_est, t_est, R_gt, t_gt, pts, syms):
    """Maximum Symmetry-Aware Surface Distance (MSSD).

    See: http://bop.felk.cvut.cz/challenges/bop-challenge-2019/

    :param R_est: 3x3 ndarray with the estimated rotation matrix.
    :param t_est: 3x1 ndarray with the estimated translation vector.
    :param R_gt: 3x3 ndarray with the ground-truth rotation matrix.
    :param t_gt: 3x1 ndarray with the ground-truth translation vector.
    :param pts: nx3 ndarray with 3D model points.
    :param syms: Set of symmetry transformations, each given by a dictionary with:
      - 'R': 3x3 ndarray with the rotation matrix.
      - 't': 3x1 ndarray with the translation vector.
    :return: The calculated error.
    """
    pts_est = misc.transform_pts_Rt(pts, R_est, t_est)
    es = []
    for sym in syms:
        R_gt_sym = R_gt.dot(sym["R"])
        t_gt_sym = R_gt.dot(sym["t"]) + t_gt
        pts_gt_sym = misc.transform_pts_Rt(pts, R_gt_sym, t_gt_sym)
        es.append(np.linalg.norm(pts_est - pts_gt_sym, axis=1).max())
    return min(es)


def mspd(R_est, t_est, R_gt, t_gt, K, pts, syms):
    """Maximum Symmetry-Aware Projection Distance (MSPD).

    See: http://bop.felk.cvut.cz/challenges/bop-challenge-2019/

    :param R_est: 3x3 ndarray with the estimated rotation matrix.
    :param t_est: 3x1 ndarray with the estimated translation vector.
    :param R_gt: 3x3 ndarray with the ground-truth rotation matrix.
    :param t_gt: 3x1 ndarray with the ground-truth translation vector.
    :param K: 3x3 ndarray with the intrinsic camera matrix.
    :param pts: nx3 ndarray with 3D model points.
    :param syms: Set of symmetry transformations, each given by a dictionary with:
      - 'R': 3x3 ndarray with the rotation matrix.
      - 't': 3x1 ndarray with the translation vector.
    :return: The calculated error.
    """
    proj_est = misc.project_pts(pts, K, R_est, t_est)
    es = []
    for sym in syms:
        R_gt_sym = R_gt.dot(sym["R"])
        t_gt_sym = R_gt.dot(sym["t"]) + t_gt
        proj_gt_sym = misc.project_pts(pts, K, R_gt_sym, t_gt_sym)
        es.append(np.linalg.norm(proj_est - proj_gt_sym, axis=1).max())
    return min(es)


def add(R_est, t_est, R_gt, t_gt, pts):
    """Average Distance of Model Points for objects with no indistinguishable
    views - by Hinterstoisser et al. (ACCV'12).

    :param R_est: 3x3 ndarray with the estimated rotation matrix.
    :param t_est: 3x1 ndarray with the estimated translation vector.
    :param R_gt: 3x3 ndarray with the ground-truth rotation matrix.
    :param t_gt: 3x1 ndarray with the ground-truth translation vector.
    :param pts: nx3 ndarray with 3D model points.
    :return: The calculated error.
    """
    pts_est = misc.transform_pts_Rt(pts, R_est, t_est)
    pts_gt = misc.transform_pts_Rt(pts, R_gt, t_gt)
    e = np.linalg.norm(pts_est - pts_gt, axis=1).mean()
    return e


def adi(R_est, t_est, R_gt, t_gt, pts):
    """Average Distance of Model Points for objects with indistinguishable views
    - by Hinterstoisser et al. (ACCV'12).

    :param R_est: 3x3 ndarray with the estimated rotation matrix.
    :param t_est: 3x1 ndarray with the estimated translation vector.
    :param R_gt: 3x3 ndarray with the ground-truth rotation matrix.
    :param t_gt: 3x1 ndarray with the ground-truth translation vector.
    :param pts: nx3 ndarray with 3D model points.
    :return: The calculated error.
    """
    pts_est = misc.transform_pts_Rt(pts, R_est, t_est)
    pts_gt = misc.transform_pts_Rt(pts, R_gt, t_gt)

    # Calculate distances to the nearest neighbors from vertices in the
    # ground-truth pose to vertices in the estimated pose.
    nn_index = spatial.cKDTree(pts_est)
    nn_dists, _ = nn_index.query(pts_gt, k=1)

    e = nn_dists.mean()
    return e


def re(R_est, R_gt):
    """Rotational Error.

    :param R_est: 3x3 ndarray with the estimated rotation matrix.
    :param R_gt: 3x3 ndarray with the ground-truth rotation matrix.
    :return: The calculated error.
    """
    assert R_est.shape == R_gt.shape == (3, 3)
    error_cos = float(0.5 * (np.trace(R_est.dot(np.linalg.inv(R_gt))) - 1.0))

    # Avoid invalid values due to numerical errors.
    error_cos = min(1.0, max(-1.0, error_cos))

    error = math.acos(error_cos)
    error = 180.0 * error / np.pi  # Convert [rad] to [deg].
    return error


def te(t_est, t_gt):
    """Translational Error.

    :param t_est: 3x1 ndarray with the estimated translation vector.
    :param t_gt: 3x1 ndarray with the ground-truth translation vector.
    :return: The calculated error.
    """
    assert t_est.size == t_gt.size == 3
    error = np.linalg.norm(t_gt - t_est)
    return error


# ---- bop_toolkit_lib/pose_matching.py ----------------------------------------

def match_poses(errs, error_ths, max_ests_count=0, gt_valid_mask=None):
    """Matches the estimated poses to the ground-truth poses.

    The estimated poses are greedily matched to the ground truth poses in the
    order of decreasing score of the estimates. An estimated pose is matched to a
    ground-truth pose if the error w.r.t. the ground-truth pose is below the
    specified threshold. Each estimated pose is matched to up to one ground-truth
    pose and each ground-truth pose is matched to up to one estimated pose.

    :param errs: List of dictionaries, where each dictionary holds the following
      info about one pose estimate:
      - 'est_id': ID of the pose estimate.
      - 'score': Confidence score of the pose estimate.
      - 'errors': Dictionary mapping ground-truth ID's to errors of the pose
          estimate w.r.t. the ground-truth poses.
    :param error_ths: Thresholds of correctness. The pose error can be given
      by more than one element (e.g. translational + rotational error), in which
      case there is one threshold for each element.
    :param max_ests_count: Top k pose estimates to consider (0 = all).
    :param gt_valid_mask: Mask of ground-truth poses which can be considered.
    :return: List of dictionaries, where each dictionary holds info for one pose
      estimate (the estimates are ordered as in errs) about the matching
      ground-truth pose:
      - 'est_id': ID of the pose estimate.
      - 'gt_id': ID of the matched ground-truth pose (-1 means there is no
          matching ground-truth pose).
      - 'score': Confidence score of the pose estimate.
      - 'error': Error of the pose estimate w.r.t. the matched ground-truth pose.
      - 'error_norm': Error normalized by the threshold value.
    """
    # Sort the estimated poses by decreasing confidence score.
    errs_sorted = sorted(errs, key=lambda e: e["score"], reverse=True)

    # Keep only the required number of poses with the highest confidence score.
    # 0 = all pose estimates are considered.
    if max_ests_count > 0:
        errs_sorted = errs_sorted[:max_ests_count]

    # Number of values defining the error (e.g. 1 for "ADD", 2 for "5deg 5cm").
    error_num_elems = len(list(error_ths))

    # Greedily match the estimated poses to the ground truth poses in the order of
    # decreasing score of the estimates.
    matches = []
    gt_matched = []
    for e in errs_sorted:
        best_gt_id = -1
        best_error = list(error_ths)
        for gt_id, error in e["errors"].items():
            gt_visib_fract = e["gt_visib_fracts"][gt_id]
            # If the mask of valid GT poses is not provided, consider all valid.
            is_valid = not gt_valid_mask or gt_valid_mask[gt_id]

            # Only valid GT poses that have not been matched yet are considered.
            if is_valid and gt_id not in gt_matched:
                # The current pose estimate is considered the best so far if all error
                # elements are the lowest so far.
                if np.all([error[i] < best_error[i] for i in range(error_num_elems)]):
                    best_gt_id = gt_id
                    best_error = error
                    gt_visib_fract_of_best_gt_id = gt_visib_fract

        if best_gt_id >= 0:
            # Mark the GT pose as matched.
            gt_matched.append(best_gt_id)

            # Error normalized by the threshold.
            best_errors_normed = [
                best_error[i] / float(error_ths[i]) for i in range(error_num_elems)
            ]

            # Save info about the match.
            matches.append(
                {
                    "est_id": e["est_id"],
                    "gt_id": best_gt_id,
                    "score": e["score"],
                    "error": best_error,
                    "error_norm": best_errors_normed,
                    "gt_visib_fract": gt_visib_fract_of_best_gt_id,
                }
            )

    return matches


def match_poses_scene(
    scene_id, scene_gt, scene_gt_info, scene_gt_valid, scene_errs, correct_th, n_top
):
    """Matches the estimated poses to the ground-truth poses in one scene.

    :param scene_id: Scene ID.
    :param scene_gt: Dictionary mapping image ID's to lists of dictionaries with:
      - 'obj_id': Object ID of the ground-truth pose.
    :param scene_gt_valid: Dictionary mapping image ID's to lists of boolean
      values indicating which ground-truth poses should be considered.
    :param scene_errs: List of dictionaries with:
      - 'im_id': Image ID.
      - 'obj_id': Object ID.
      - 'est_id': ID of the pose estimate.
      - 'score': Confidence score of the pose estimate.
      - 'errors': Dictionary mapping ground-truth ID's to errors of the pose
          estimate w.r.t. the ground-truth poses.
    :param error_obj_threshs: Dictionary mapping object ID's to values of the
      threshold of correctness.
    :param n_top: Top N pose estimates (with the highest score) to be evaluated
      for each object class in each image.
    :return:
    """
    # Organize the errors by image ID and object ID (for faster query).
    scene_errs_org = {}
    for e in scene_errs:
        scene_errs_org.setdefault(e["im_id"], {}).setdefault(e["obj_id"], []).append(e)

    # Matching of poses in individual images.
    scene_matches = []
    for im_id, im_gts in scene_gt.items():
        im_matches = []

        for gt_id, gt in enumerate(im_gts):
            
            im_matches.append(
                {
                    "scene_id": scene_id,
                    "im_id": im_id,
                    "obj_id": gt["obj_id"],
                    "gt_id": gt_id,
                    "est_id": -1,
                    "score": -1,
                    "error": -1,
                    "error_norm": -1,
                    "valid": scene_gt_valid[im_id][gt_id],
                    "gt_visib_fract": scene_gt_info[im_id][gt_id]["visib_fract"], 
                }
            )

        # Treat estimates of each object separately.
        im_obj_ids = set([gt["obj_id"] for gt in im_gts])
        for obj_id in im_obj_ids:
            if (
                im_id in scene_errs_org.keys()
                and obj_id in scene_errs_org[im_id].keys()
            ):
                # Greedily match the estimated poses to the ground truth poses.
                errs_im_obj = scene_errs_org[im_id][obj_id]
                ms = match_poses(errs_im_obj, correct_th, n_top, scene_gt_valid[im_id])

                # Update info about the matched GT poses.
                for m in ms:
                    g = im_matches[m["gt_id"]]
                    g["est_id"] = m["est_id"]
                    g["score"] = m["score"]
                    g["error"] = m["error"]
                    g["error_norm"] = m["error_norm"]

        scene_matches += im_matches

    return scene_matches


# ---- bop_toolkit_lib/score.py ------------------------------------------------

def calc_recall(tp_count, targets_count):
    """Calculates recall.

    :param tp_count: Number of true positives.
    :param targets_count: Number of targets.
    :return: The recall rate.
    """
    if targets_count == 0:
        return 0.0
    else:
        return tp_count / float(targets_count)


def calc_localization_scores(scene_ids, obj_ids, matches, n_top, do_print=True):
    """Calculates performance scores for the 6D object localization task.

    References:
    Hodan et al., BOP: Benchmark for 6D Object Pose Estimation, ECCV'18.
    Hodan et al., On Evaluation of 6D Object Pose Estimation, ECCVW'16.

    :param scene_ids: ID's of considered scenes.
    :param obj_ids: ID's of considered objects.
    :param matches: Info about matching pose estimates to ground-truth poses
      (see pose_matching.py for details).
    :param n_top: Number of top pose estimates to consider per test target.
    :param do_print: Whether to print the scores to the standard output.
    :return: Dictionary with the evaluation scores.
    """
    # Count the number of visible object instances in each image.
    insts = {i: {j: defaultdict(lambda: 0) for j in scene_ids} for i in obj_ids}
    for m in matches:
        if m["valid"]:
            insts[m["obj_id"]][m["scene_id"]][m["im_id"]] += 1

    # Count the number of targets = object instances to be found.
    # For SiSo, there is either zero or one target in each image - there is just
    # one even if there are more instances of the object of interest.
    tars = 0  # Total number of targets.
    obj_tars = {i: 0 for i in obj_ids}  # Targets per object.
    scene_tars = {i: 0 for i in scene_ids}  # Targets per scene.
    for obj_id, obj_insts in insts.items():
        for scene_id, scene_insts in obj_insts.items():
            # Count the number of targets for the current object in the current scene.
            if n_top > 0:
                count = sum(np.minimum(n_top, list(scene_insts.values())))
            else:
                count = sum(list(scene_insts.values()))

            tars += count
            obj_tars[obj_id] += count
            scene_tars[scene_id] += count

    # Count the number of true positives.
    tps = 0  # Total number of true positives.
    obj_tps = {i: 0 for i in obj_ids}  # True positives per object.
    scene_tps = {i: 0 for i in scene_ids}  # True positives per scene.
    for m in matches:
        if m["valid"] and m["est_id"] != -1:
            tps += 1
            obj_tps[m["obj_id"]] += 1
            scene_tps[m["scene_id"]] += 1

    # Total recall.
    recall = calc_recall(tps, tars)

    # Recall per object.
    obj_recalls = {}
    for i in obj_ids:
        obj_recalls[i] = calc_recall(obj_tps[i], obj_tars[i])
    mean_obj_recall = float(np.mean(list(obj_recalls.values())).squeeze())

    # Recall per scene.
    scene_recalls = {}
    for i in scene_ids:
        scene_recalls[i] = float(calc_recall(scene_tps[i], scene_tars[i]))
    mean_scene_recall = float(np.mean(list(scene_recalls.values())).squeeze())

    # Final scores.
    scores = {
        "recall": float(recall),
        "obj_recalls": obj_recalls,
        "mean_obj_recall": float(mean_obj_recall),
        "scene_recalls": scene_recalls,
        "mean_scene_recall": float(mean_scene_recall),
        "gt_count": len(matches),
        "targets_count": int(tars),
        "tp_count": int(tps),
    }

    if do_print:
        obj_recalls_str = ", ".join(
            ["{}: {:.3f}".format(i, s) for i, s in scores["obj_recalls"].items()]
        )

        scene_recalls_str = ", ".join(
            ["{}: {:.3f}".format(i, s) for i, s in scores["scene_recalls"].items()]
        )

        misc.log("")
        misc.log("GT count:           {:d}".format(scores["gt_count"]))
        misc.log("Target count:       {:d}".format(scores["targets_count"]))
        misc.log("TP count:           {:d}".format(scores["tp_count"]))
        misc.log("Recall:             {:.4f}".format(scores["recall"]))
        misc.log("Mean object recall: {:.4f}".format(scores["mean_obj_recall"]))
        misc.log("Mean scene recall:  {:.4f}".format(scores["mean_scene_recall"]))
        misc.log("Object recalls:\n{}".format(obj_recalls_str))
        misc.log("Scene recalls:\n{}".format(scene_recalls_str))
        misc.log("")

    return scores


transform = types.SimpleNamespace(rotation_matrix=rotation_matrix, unit_vector=unit_vector)
misc = types.SimpleNamespace(
    get_symmetry_transformations=get_symmetry_transformations, project_pts=project_pts,
    depth_im_to_dist_im_fast=depth_im_to_dist_im_fast, transform_pts_Rt=transform_pts_Rt,
    overlapping_sphere_projections=overlapping_sphere_projections, log=print)
visibility = types.SimpleNamespace(estimate_visib_mask_gt=estimate_visib_mask_gt,
                                   estimate_visib_mask_est=estimate_visib_mask_est)


# ---- scripts/eval_bop19_pose.py, eval_calc_errors.py, eval_calc_scores.py (the loops) ----------
BOP19_ERRORS = [
    {"type": "vsd", "vsd_taus": list(np.arange(0.05, 0.51, 0.05)),
     "correct_th": [[th] for th in np.arange(0.05, 0.51, 0.05)]},
    {"type": "mssd", "correct_th": [[th] for th in np.arange(0.05, 0.51, 0.05)]},
    {"type": "mspd", "correct_th": [[th] for th in np.arange(5, 51, 5)]},
]


def calc_errors(error_type, ests, targets, scene_gt, scene_gt_info, scene_camera, depth_ims, models_pts,
                models_info, renderer, vsd_delta=15, vsd_taus=None, max_sym_disc_step=0.01):
    """eval_calc_errors.py for one scene (n_top = -1, skip_missing = 1, num_workers = 1)."""
    ests_org = {}
    for est in ests:
        ests_org.setdefault(est["scene_id"], {}).setdefault(est["im_id"], {}).setdefault(est["obj_id"], []).append(est)
    models_sym = {obj_id: get_symmetry_transformations(models_info[obj_id], max_sym_disc_step)
                  for obj_id in models_info}
    targets_org = {}
    for target in targets:
        targets_org.setdefault(target["scene_id"], {}).setdefault(target["im_id"], {})[target["obj_id"]] = target
    scene_errs = []
    for scene_id, scene_targets in targets_org.items():
        for im_id, im_targets in scene_targets.items():
            K = scene_camera[im_id]["cam_K"]
            depth_im = None
            if error_type == "vsd":
                depth_im = depth_ims[im_id] * scene_camera[im_id]["depth_scale"]
            for obj_id, target in im_targets.items():
                n_top_curr = target["inst_count"]
                try:
                    obj_ests = ests_org[scene_id][im_id][obj_id]
                except KeyError:
                    obj_ests = []
                obj_ests_sorted = sorted(enumerate(obj_ests), key=lambda x: x[1]["score"], reverse=True)
                obj_ests_sorted = obj_ests_sorted[slice(0, n_top_curr)]
                for est_id, est in obj_ests_sorted:
                    R_e = est["R"]
                    t_e = est["t"]
                    errs = {}
                    gt_visib_fracts = {}
                    for gt_id, gt in enumerate(scene_gt[im_id]):
                        if gt["obj_id"] != obj_id:
                            continue
                        R_g = gt["cam_R_m2c"]
                        t_g = gt["cam_t_m2c"]
                        gt_visib_fract = scene_gt_info[im_id][gt_id]["visib_fract"]
                        if error_type == "vsd":
                            radius = 0.5 * models_info[obj_id]["diameter"]
                            if not overlapping_sphere_projections(radius, t_e.squeeze(), t_g.squeeze()):
                                e = [1.0] * len(vsd_taus)
                            else:
                                e = vsd(R_e, t_e, R_g, t_g, depth_im, K, vsd_delta, vsd_taus, True,
                                        models_info[obj_id]["diameter"], renderer, obj_id, "step")
                        elif error_type == "mssd":
                            if not np.linalg.norm(t_e - t_g) < models_info[obj_id]["diameter"]:
                                e = [float("inf")]
                            else:
                                e = [mssd(R_e, t_e, R_g, t_g, models_pts[obj_id], models_sym[obj_id])]
                        elif error_type == "mspd":
                            e = [mspd(R_e, t_e, R_g, t_g, K, models_pts[obj_id], models_sym[obj_id])]
                        errs[gt_id] = e
                        gt_visib_fracts[gt_id] = gt_visib_fract
                    scene_errs.append({"im_id": im_id, "obj_id": obj_id, "est_id": est_id, "score": est["score"],
                                       "errors": errs, "gt_visib_fracts": gt_visib_fracts, "scene_id": scene_id})
    if error_type != "vsd":
        return {None: scene_errs}
    # eval_calc_errors.py writes one error file per tau ("errors" = the tau-th element)
    out = {}
    for i, tau in enumerate(vsd_taus):
        out[tau] = [dict(e, errors={g: [v[i]] for g, v in e["errors"].items()}) for e in scene_errs]
    return out


def calc_scores(err_type, scene_errs, correct_th, targets, scene_gt, scene_gt_info, models_info, im_width,
                scene_ids, obj_ids):
    """eval_calc_scores.py (localization, visib_gt_min = -1, n_top = -1) for one scene."""
    import copy
    scene_errs = copy.deepcopy(scene_errs)
    targets_org = {}
    for target in targets:
        targets_org.setdefault(target["scene_id"], {}).setdefault(target["im_id"], {})[target["obj_id"]] = target
    matches = []
    for scene_id, scene_targets in targets_org.items():
        scene_gt_curr, scene_gt_curr_info, scene_gt_valid = {}, {}, {}
        for im_id, im_targets in scene_targets.items():
            im_gt = scene_gt[im_id]
            im_gt_info = scene_gt_info[im_id]
            scene_gt_curr[im_id] = scene_gt[im_id]
            scene_gt_curr_info[im_id] = scene_gt_info[im_id]
            scene_gt_valid[im_id] = [True] * len(im_gt)
            gt_ids_sorted = sorted(range(len(im_gt)), key=lambda gt_id: im_gt_info[gt_id]["visib_fract"], reverse=True)
            to_add = {obj_id: trg["inst_count"] for obj_id, trg in im_targets.items()}
            for gt_id in gt_ids_sorted:
                obj_id = im_gt[gt_id]["obj_id"]
                if obj_id in to_add.keys() and to_add[obj_id] > 0:
                    scene_gt_valid[im_id][gt_id] = True
                    to_add[obj_id] -= 1
                else:
                    scene_gt_valid[im_id][gt_id] = False
        if err_type == "mssd":  # normalized_by_diameter
            for err in scene_errs:
                diameter = float(models_info[err["obj_id"]]["diameter"])
                for gt_id in err["errors"].keys():
                    err["errors"][gt_id] = [e / diameter for e in err["errors"][gt_id]]
        if err_type == "mspd":  # normalized_by_im_width
            for err in scene_errs:
                factor = 640.0 / im_width
                for gt_id in err["errors"].keys():
                    err["errors"][gt_id] = [factor * e for e in err["errors"][gt_id]]
        matches += match_poses_scene(scene_id, scene_gt_curr, scene_gt_curr_info, scene_gt_valid, scene_errs,
                                     correct_th, -1)
    return calc_localization_scores(scene_ids, obj_ids, matches, -1, do_print=False)


def evaluate_bop19(ests, targets, scene_gt, scene_gt_info, scene_camera, depth_ims, models_pts, models_info,
                   renderer, im_width, vsd_delta=15):
    """eval_bop19_pose.py: {"bop19_average_recall_<type>": ..., "bop19_average_recall": ...}."""
    scene_ids = sorted({t["scene_id"] for t in targets})
    obj_ids = sorted(models_info)
    average_recalls = {}
    for error in BOP19_ERRORS:
        errs = calc_errors(error["type"], ests, targets, scene_gt, scene_gt_info, scene_camera, depth_ims,
                           models_pts, models_info, renderer, vsd_delta, error.get("vsd_taus"))
        recalls = []
        for _, scene_errs in errs.items():
            for correct_th in error["correct_th"]:
                scores = calc_scores(error["type"], scene_errs, correct_th, targets, scene_gt, scene_gt_info,
                                     models_info, im_width, scene_ids, obj_ids)
                recalls.append(scores["recall"])
        average_recalls[error["type"]] = np.mean(recalls)
    final = {"bop19_average_recall_{}".format(t): v for t, v in average_recalls.items()}
    final["bop19_average_recall"] = np.mean([average_recalls["vsd"], average_recalls["mssd"], average_recalls["mspd"]])
    return final
