"""COCO keypoint files (cocodataset.org/#format-data, #format-results): an annotation file
(``images``, ``annotations`` with ``keypoints`` x, y, v triples, ``categories``) and a result
file (a list of ``image_id``, ``category_id``, ``keypoints``, ``score``), read into
:mod:`recon_eval.metrics.objects_coco`'s objects. Errors name the file and the field
(``annotations[3].keypoints``)."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.objects_coco import COCO_PERSON_SIGMAS, KeypointDetection, KeypointTruth
from recon_eval.readers.text import json_document, read_text


def _doc(path, what: str):
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected {what})")
    return p, json_document(read_text(p, what), p, what)


def _get(d, key: str, where: str):
    if not isinstance(d, dict) or key not in d:
        raise InputError(f"{where}: missing field {key!r}")
    return d[key]


def _int(d, key: str, where: str) -> int:
    v = _get(d, key, where)
    if not isinstance(v, int) or isinstance(v, bool):
        raise InputError(f"{where}.{key}: expected an integer, got {v!r}"[:200])
    return v


def _numbers(d, key: str, where: str, n: int | None = None) -> np.ndarray:
    v = _get(d, key, where)
    if not isinstance(v, list) or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v):
        raise InputError(f"{where}.{key}: expected a list of numbers")
    a = np.asarray(v, dtype=np.float64)
    if (n is not None and a.size != n) or not np.all(np.isfinite(a)):
        raise InputError(f"{where}.{key}: expected {n if n is not None else 'a list of'} finite numbers, got {a.size}")
    return a


def _scalar(d, key: str, where: str) -> float:
    v = _get(d, key, where)
    if not isinstance(v, (int, float)) or isinstance(v, bool) or not np.isfinite(v):
        raise InputError(f"{where}.{key}: expected a finite number, got {v!r}"[:200])
    return float(v)


def _keypoints(d, where: str, k: int | None) -> np.ndarray:
    a = _numbers(d, "keypoints", where)
    if a.size % 3 or (k is not None and a.size != 3 * k):
        raise InputError(f"{where}.keypoints: expected x, y, v triples"
                         + (f" for {k} keypoints ({3 * k} numbers)" if k is not None else "") + f", got {a.size}")
    return a.reshape(-1, 3)


@dataclass(frozen=True)
class CocoKeypointTruthFile:
    truths: tuple  # KeypointTruth
    image_ids: tuple
    sigmas: dict  # category_id -> (K_c,) per-keypoint OKS sigmas
    sigmas_source: dict  # category_id -> where its sigmas came from


def _category_sigmas(c: dict, k: int, given, where: str) -> tuple[np.ndarray, str]:
    """A category's sigmas: its own ``sigmas`` list (not in COCO's format; a tool may write it),
    else ``given`` (K numbers, or one for every keypoint), else COCO's 17 person sigmas when it
    has 17 keypoints."""
    if "sigmas" in c:
        s, src = _numbers(c, "sigmas", where, k), "the category's sigmas"
    elif given is not None and len(given) in (1, k):
        s, src = np.broadcast_to(np.asarray(given, dtype=np.float64), (k,)).copy(), "--kpt-sigmas"
    elif k == 17:
        s, src = COCO_PERSON_SIGMAS, "COCO's 17 person keypoint sigmas"
    else:
        raise InputError(f"{where}: {k} keypoints and no OKS sigmas for them: give --kpt-sigmas (one value for "
                         "every keypoint, or one per keypoint; COCO's defaults are for its 17 person keypoints)")
    if not np.all(s > 0):
        raise InputError(f"{where}: OKS sigmas must be positive ({src})")
    return s, src


def read_coco_keypoint_truth(path, sigmas=None) -> CocoKeypointTruthFile:
    """The annotations with keypoints of a COCO annotation file; each category's keypoint count
    is its ``keypoints`` names' count (else its first annotation's)."""
    p, doc = _doc(path, "a COCO annotation file")
    images = _get(doc, "images", str(p))
    anns = _get(doc, "annotations", str(p))
    cats = _get(doc, "categories", str(p))
    if not isinstance(images, list) or not isinstance(anns, list) or not isinstance(cats, list):
        raise InputError(f"{p}: images, annotations and categories must be lists")
    image_ids = tuple(_int(im, "id", f"{p}: images[{i}]") for i, im in enumerate(images))
    n_kp = {}
    for j, c in enumerate(cats):
        cid = _int(c, "id", f"{p}: categories[{j}]")
        if isinstance(c.get("keypoints"), list) and c["keypoints"]:
            n_kp[cid] = len(c["keypoints"])
    truths = []
    for i, a in enumerate(anns):
        where = f"{p}: annotations[{i}]"
        if not isinstance(a, dict) or "keypoints" not in a:
            continue  # an instance without keypoints: not a keypoint truth
        cid = _int(a, "category_id", where)
        kp = _keypoints(a, where, n_kp.get(cid))
        n_kp.setdefault(cid, len(kp))
        if not np.all(np.isin(kp[:, 2], (0, 1, 2))):
            raise InputError(f"{where}.keypoints: visibility flags must be 0, 1 or 2")
        if _int(a, "image_id", where) not in image_ids:
            raise InputError(f"{where}.image_id: {a['image_id']} is not in images")
        bbox = _numbers(a, "bbox", where, 4)
        nk = _int(a, "num_keypoints", where) if "num_keypoints" in a else None
        truths.append(KeypointTruth(_int(a, "id", where), a["image_id"], cid, kp, tuple(float(x) for x in bbox),
                                    _scalar(a, "area", where), bool(a.get("iscrowd", 0)), nk))
    if not truths:
        raise InputError(f"{p}: no annotation has keypoints (expected a COCO keypoint annotation file)")
    used = sorted({t.category_id for t in truths})
    by_id = {c.get("id"): (j, c) for j, c in enumerate(cats) if isinstance(c, dict)}
    sig, src = {}, {}
    for cid in used:
        j, c = by_id.get(cid, (None, {}))
        where = f"{p}: categories[{j}]" if j is not None else f"{p}: category {cid}"
        sig[cid], src[cid] = _category_sigmas(c, n_kp[cid], sigmas, where)
    return CocoKeypointTruthFile(tuple(truths), image_ids, sig, src)


def read_coco_keypoint_results(path, image_ids, n_keypoints: dict) -> tuple:
    """A COCO keypoint result file: KeypointDetection per entry. As ``COCO.loadRes``, every
    ``image_id`` must be an image of the annotation file; ``n_keypoints``: category_id -> K
    (a category not in it is refused)."""
    p, doc = _doc(path, "a COCO keypoint result file")
    if not isinstance(doc, list):
        raise InputError(f"{p}: expected a JSON list of results")
    known, out = set(image_ids), []
    for i, r in enumerate(doc):
        where = f"{p}: [{i}]"
        image_id = _int(r, "image_id", where)
        if image_id not in known:
            raise InputError(f"{where}.image_id: {image_id} is not an image of the annotation file")
        cid = _int(r, "category_id", where)
        if cid not in n_keypoints:
            raise InputError(f"{where}.category_id: {cid} is not a keypoint category of the annotation file")
        out.append(KeypointDetection(image_id, cid, _keypoints(r, where, n_keypoints[cid]), _scalar(r, "score", where)))
    return tuple(out)
