"""COCO keypoint OKS and AP/AR (docs/metrics.md, "Keypoints"), transliterated from pycocotools'
``cocoeval.py`` (``computeOks``, ``evaluateImg``, ``accumulate``, ``summarize`` with
``iouType='keypoints'``) and ``coco.py`` (``loadRes``: a result's area and box from its keypoints'
extent) and checked against pycocotools itself (tests/recon_eval/agreement).

Conventions kept from pycocotools: detections per (image, category) ranked by score (stable),
at most ``max_dets`` = 20; a truth is ignored when crowd, when it has no labelled keypoint
(``num_keypoints == 0``) or outside the area range; a truth without labelled keypoints is scored
by the distance outside its box enlarged by its size on each side; OKS divides by
``area + eps``; precision interpolated at 101 recall points; AP = mean over the 10 OKS
thresholds 0.50:0.05:0.95, the 101 recall points and the categories of the defined (> -1)
precisions. Pixels in COCO's convention (keypoint x, y as stored); areas in px^2.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: cocoeval.Params.setKpParams: the 17 COCO person keypoints' sigmas.
COCO_PERSON_SIGMAS = np.array([.26, .25, .25, .35, .35, .79, .79, .72, .72, .62, .62, 1.07, 1.07, .87, .87, .89,
                               .89]) / 10.0
OKS_THRESHOLDS = np.linspace(.5, 0.95, int(np.round((0.95 - .5) / .05)) + 1, endpoint=True)
RECALL_POINTS = np.linspace(.0, 1.00, int(np.round((1.00 - .0) / .01)) + 1, endpoint=True)
AREA_RANGES = {"all": (0 ** 2, 1e5 ** 2), "medium": (32 ** 2, 96 ** 2), "large": (96 ** 2, 1e5 ** 2)}
MAX_DETS = 20


@dataclass(frozen=True)
class KeypointTruth:
    id: int  # annotation id (COCO: > 0; a match stores it, and id 0 reads as unmatched there too)
    image_id: int
    category_id: int
    keypoints: np.ndarray  # (K, 3) x, y, v (v = 0 unlabelled, 1 labelled occluded, 2 visible)
    bbox: tuple  # (x, y, w, h) px
    area: float  # px^2
    iscrowd: bool = False
    num_keypoints: int | None = None  # the annotation's field (pycocotools reads it); default: count of v > 0


@dataclass(frozen=True)
class KeypointDetection:
    image_id: int
    category_id: int
    keypoints: np.ndarray  # (K, 3); the third column is not used
    score: float

    @property
    def area(self) -> float:
        """coco.loadRes: the area of the keypoints' extent."""
        x, y = self.keypoints[:, 0], self.keypoints[:, 1]
        return float((np.max(x) - np.min(x)) * (np.max(y) - np.min(y)))


def oks(detections, truths, sigmas=COCO_PERSON_SIGMAS) -> np.ndarray:
    """cocoeval.computeOks: (D, G) object keypoint similarity of ``detections`` (already ranked
    and cut) against ``truths`` of one image and category."""
    sigmas = np.asarray(sigmas, dtype=np.float64)
    variances = (sigmas * 2) ** 2
    out = np.zeros((len(detections), len(truths)))
    for j, gt in enumerate(truths):
        g = np.asarray(gt.keypoints, dtype=np.float64)
        xg, yg, vg = g[:, 0], g[:, 1], g[:, 2]
        k1 = np.count_nonzero(vg > 0)
        bx, by, bw, bh = gt.bbox
        x0, x1, y0, y1 = bx - bw, bx + bw * 2, by - bh, by + bh * 2
        for i, dt in enumerate(detections):
            d = np.asarray(dt.keypoints, dtype=np.float64)
            xd, yd = d[:, 0], d[:, 1]
            if k1 > 0:
                dx, dy = xd - xg, yd - yg
            else:
                z = np.zeros(len(sigmas))
                dx = np.max((z, x0 - xd), axis=0) + np.max((z, xd - x1), axis=0)
                dy = np.max((z, y0 - yd), axis=0) + np.max((z, yd - y1), axis=0)
            e = (dx ** 2 + dy ** 2) / variances / (gt.area + np.spacing(1)) / 2
            if k1 > 0:
                e = e[vg > 0]
            out[i, j] = np.sum(np.exp(-e)) / e.shape[0]
    return out


def _ranked(dts: list, max_dets: int) -> list:
    order = np.argsort([-d.score for d in dts], kind="mergesort")
    return [dts[i] for i in order[:max_dets]]


def _ignored(gt: KeypointTruth) -> bool:
    n = gt.num_keypoints if gt.num_keypoints is not None else int(np.count_nonzero(gt.keypoints[:, 2] > 0))
    return bool(gt.iscrowd or n == 0)  # COCOeval._prepare: an 'ignore' field is overwritten by iscrowd


@dataclass(frozen=True)
class _ImageEval:
    dt_matches: np.ndarray  # (T, D) matched truth id, 0 = none
    dt_scores: np.ndarray  # (D,)
    gt_ignore: np.ndarray  # (G,)
    dt_ignore: np.ndarray  # (T, D)


def _evaluate_image(gts, dts, ious, area_rng, max_dets) -> _ImageEval | None:
    """cocoeval.evaluateImg (``dts`` ranked, ``ious`` (D, G) in the given order)."""
    if not gts and not dts:
        return None
    g_ig = [1 if (_ignored(g) or g.area < area_rng[0] or g.area > area_rng[1]) else 0 for g in gts]
    gind = np.argsort(g_ig, kind="mergesort")
    gts = [gts[i] for i in gind]
    dts = dts[:max_dets]
    ious = ious[:, gind] if len(ious) > 0 else ious
    T, G, D = len(OKS_THRESHOLDS), len(gts), len(dts)
    gtm, dtm, dt_ig = np.zeros((T, G)), np.zeros((T, D)), np.zeros((T, D))
    gt_ig = np.array([g_ig[i] for i in gind])
    crowd = [int(g.iscrowd) for g in gts]
    if len(ious):
        for tind, t in enumerate(OKS_THRESHOLDS):
            for dind in range(D):
                iou, m = min([t, 1 - 1e-10]), -1
                for gi in range(G):
                    if gtm[tind, gi] > 0 and not crowd[gi]:
                        continue
                    if m > -1 and gt_ig[m] == 0 and gt_ig[gi] == 1:
                        break
                    if ious[dind, gi] < iou:
                        continue
                    iou, m = ious[dind, gi], gi
                if m == -1:
                    continue
                dt_ig[tind, dind] = gt_ig[m]
                dtm[tind, dind] = gts[m].id
                gtm[tind, m] = dind + 1  # a detection's id: only its non-zero-ness is read
    outside = np.array([d.area < area_rng[0] or d.area > area_rng[1] for d in dts]).reshape((1, D))
    dt_ig = np.logical_or(dt_ig, np.logical_and(dtm == 0, np.repeat(outside, T, 0)))
    return _ImageEval(dtm, np.array([d.score for d in dts], dtype=np.float64), gt_ig, dt_ig)


@dataclass(frozen=True)
class CocoKeypointResult:
    """COCOeval.summarize for keypoints (each -1 where undefined, as pycocotools)."""

    ap: float  # OKS 0.50:0.95, all areas, 20 detections
    ap50: float
    ap75: float
    ap_medium: float
    ap_large: float
    ar: float
    ar50: float
    ar75: float
    ar_medium: float
    ar_large: float
    n_truths: int  # not ignored, all areas
    n_detections: int

    def stats(self) -> tuple:
        """COCOeval.stats order."""
        return (self.ap, self.ap50, self.ap75, self.ap_medium, self.ap_large, self.ar, self.ar50, self.ar75,
                self.ar_medium, self.ar_large)


def keypoint_ap(truths, detections, *, sigmas=COCO_PERSON_SIGMAS, image_ids=None) -> CocoKeypointResult:
    """COCO keypoint AP/AR of ``detections`` against ``truths`` over ``image_ids`` (default: the
    truths' images; COCO's are the annotation file's ``images``). ``sigmas``: (K,) for every
    category, or a dict category_id -> (K_c,) where categories have their own keypoints
    (pycocotools holds one vector: the same numbers when all categories share it)."""
    imgs = sorted(set(image_ids) if image_ids is not None else {g.image_id for g in truths})
    cats = sorted({g.category_id for g in truths})
    gts: dict = {}
    for g in truths:
        gts.setdefault((g.image_id, g.category_id), []).append(g)
    dts: dict = {}
    for d in detections:
        dts.setdefault((d.image_id, d.category_id), []).append(d)
    ranked = {k: _ranked(v, MAX_DETS) for k, v in dts.items()}
    per_cat = sigmas if isinstance(sigmas, dict) else {c: sigmas for c in cats}
    ious = {(i, c): (oks(ranked.get((i, c), []), gts.get((i, c), []), per_cat[c])
                     if ranked.get((i, c)) and gts.get((i, c)) else np.zeros((0, 0))) for i in imgs for c in cats}
    T, R = len(OKS_THRESHOLDS), len(RECALL_POINTS)
    precision = -np.ones((T, R, len(cats), len(AREA_RANGES)))
    recall = -np.ones((T, len(cats), len(AREA_RANGES)))
    for k, c in enumerate(cats):
        for a, rng in enumerate(AREA_RANGES.values()):
            E = [e for e in (_evaluate_image(gts.get((i, c), []), ranked.get((i, c), []), ious[(i, c)], rng, MAX_DETS)
                             for i in imgs) if e is not None]
            if not E:
                continue
            scores = np.concatenate([e.dt_scores[:MAX_DETS] for e in E])
            inds = np.argsort(-scores, kind="mergesort")
            dtm = np.concatenate([e.dt_matches[:, :MAX_DETS] for e in E], axis=1)[:, inds]
            dt_ig = np.concatenate([e.dt_ignore[:, :MAX_DETS] for e in E], axis=1)[:, inds]
            npig = np.count_nonzero(np.concatenate([e.gt_ignore for e in E]) == 0)
            if npig == 0:
                continue
            tp_sum = np.cumsum(np.logical_and(dtm, np.logical_not(dt_ig)), axis=1).astype(float)
            fp_sum = np.cumsum(np.logical_and(np.logical_not(dtm), np.logical_not(dt_ig)), axis=1).astype(float)
            for t, (tp, fp) in enumerate(zip(tp_sum, fp_sum)):
                nd = len(tp)
                rc = tp / npig
                pr = (tp / (fp + tp + np.spacing(1))).tolist()
                recall[t, k, a] = rc[-1] if nd else 0
                for i in range(nd - 1, 0, -1):
                    if pr[i] > pr[i - 1]:
                        pr[i - 1] = pr[i]
                q = np.zeros(R)
                for ri, pi in enumerate(np.searchsorted(rc, RECALL_POINTS, side="left")):
                    if pi >= nd:
                        break  # pycocotools' try/except IndexError: the rest stay 0
                    q[ri] = pr[pi]
                precision[t, :, k, a] = q

    def mean(s):
        return float(np.mean(s[s > -1])) if np.any(s > -1) else -1.0

    def ap(area: int, t=None):
        s = precision[:, :, :, area] if t is None else precision[np.where(OKS_THRESHOLDS == t)[0], :, :, area]
        return mean(s)

    def ar(area: int, t=None):
        s = recall[:, :, area] if t is None else recall[np.where(OKS_THRESHOLDS == t)[0], :, area]
        return mean(s)

    n_truths = sum(1 for g in truths if g.image_id in set(imgs) and not _ignored(g))
    return CocoKeypointResult(ap(0), ap(0, .5), ap(0, .75), ap(1), ap(2), ar(0), ar(0, .5), ar(0, .75), ar(1), ar(2),
                              n_truths, len(list(detections)))
