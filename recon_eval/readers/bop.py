"""BOP's file formats (bop_toolkit docs/bop_datasets_format.md, docs/bop_challenge_2019.md):
a result CSV ``scene_id,im_id,obj_id,score,R,t,time`` and a dataset split
(``<split>/<scene_id:06d>/scene_gt.json``, ``scene_gt_info.json``, ``scene_camera.json``,
``depth/<im_id:06d>.png``; ``models_eval/`` or ``models/`` with ``models_info.json`` and
``obj_<obj_id:06d>.ply``; ``test_targets_bop19.json``), read into recon_eval's objects
(:mod:`recon_eval.metrics.objects_bop_recall`). Ids read from files only ever reach a path as
formatted integers."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.objects_bop_eval import BopModel, BopView
from recon_eval.metrics.objects_bop_recall import GtPose, PoseEstimate, Target
from recon_eval.readers.ply import read_geometry
from recon_eval.readers.text import json_document, read_text
from scenegen.geometry.rotation import is_rotation

HEADER = "scene_id,im_id,obj_id,score,R,t,time"
#: A result's R is written with a few decimals (BOP's sample results: 6): orthonormal to this.
RESULT_ROTATION_ATOL = 1e-4
#: BOP19 targets: object instances with at least this visible fraction (bop_toolkit
#: scripts/calc_gt_info.py + the targets the challenge publishes).
TARGET_VISIB_MIN = 0.1


def _numbers(text: str, n: int, where: str, field: str) -> np.ndarray:
    tok = text.split()
    if len(tok) != n:
        raise InputError(f"{where}: field {field!r}: expected {n} space-separated numbers, got {len(tok)}")
    try:
        a = np.array([float(v) for v in tok], dtype=np.float64)
    except ValueError:
        raise InputError(f"{where}: field {field!r}: not numbers: {text.strip()!r}") from None
    if not np.all(np.isfinite(a)):
        raise InputError(f"{where}: field {field!r}: non-finite value")
    return a


def _int(text: str, where: str, field: str) -> int:
    try:
        v = int(text.strip())
    except ValueError:
        raise InputError(f"{where}: field {field!r}: expected an integer, got {text.strip()!r}") from None
    if v < 0:
        raise InputError(f"{where}: field {field!r}: expected a non-negative integer, got {v}")
    return v


def read_bop_results(path) -> list[PoseEstimate]:
    """A BOP19 result CSV (header optional, as ``inout.load_bop_results``); ``t`` in mm."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a BOP result CSV: {HEADER})")
    out = []
    for k, line in enumerate(read_text(p, "a BOP result CSV").splitlines(), start=1):
        if not line.strip() or (k == 1 and HEADER in line):
            continue
        where = f"{p}:{k}"
        f = line.split(",")
        if len(f) != 7:
            raise InputError(f"{where}: expected 7 comma-separated fields ({HEADER}), got {len(f)}")
        R = _numbers(f[4], 9, where, "R").reshape(3, 3)
        if not is_rotation(R, atol=RESULT_ROTATION_ATOL):
            raise InputError(f"{where}: field 'R': not a rotation matrix (R R^T = I, det 1, within "
                             f"{RESULT_ROTATION_ATOL})")
        score = _numbers(f[3], 1, where, "score")[0]
        time_s = _numbers(f[6], 1, where, "time")[0]
        out.append(PoseEstimate(_int(f[0], where, "scene_id"), _int(f[1], where, "im_id"), _int(f[2], where, "obj_id"),
                                float(score), R, _numbers(f[5], 3, where, "t"), float(time_s)))
    return out


def _json(path: Path, what: str):
    if not path.is_file():
        raise InputError(f"{path}: no such file (expected {what})")
    return json_document(read_text(path, what), path, what)


def _field(d, key: str, where: str, n: int | None = None):
    if not isinstance(d, dict) or key not in d:
        raise InputError(f"{where}: missing field {key!r}")
    v = d[key]
    if n is None:
        return v
    try:
        a = np.asarray(v, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(f"{where}.{key}: expected {n} numbers") from None
    if a.size != n or not np.all(np.isfinite(a)):
        raise InputError(f"{where}.{key}: expected {n} finite numbers, got {a.size}")
    return a


def _im_key(key: str, path: Path) -> int:
    if not key.isdigit():
        raise InputError(f"{path}: key {key!r}: expected an image id (a non-negative integer)")
    return int(key)


@dataclass(frozen=True)
class BopDataset:
    root: Path  # the dataset folder (models, targets)
    split: Path  # the folder of the scene folders
    gts: dict  # (scene_id, im_id) -> [GtPose] in scene_gt order
    views: dict  # (scene_id, im_id) -> BopView
    models: dict  # obj_id -> BopModel
    targets: tuple  # Target
    targets_source: str  # the targets file, or how they were derived


def _depth(path: Path, scale: float, where: str) -> np.ndarray | None:
    import cv2  # heavy; only reading depth images needs it

    if not path.is_file():
        return None
    d = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if d is None or d.ndim != 2:
        raise InputError(f"{path}: expected a single-channel 16-bit depth PNG ({where})")
    return d.astype(np.float64) * scale


def _scene(sdir: Path, scene_id: int, image_size):
    gt_doc = _json(sdir / "scene_gt.json", "BOP scene_gt.json")
    info_doc = _json(sdir / "scene_gt_info.json", "BOP scene_gt_info.json")
    cam_doc = _json(sdir / "scene_camera.json", "BOP scene_camera.json")
    gts, views = {}, {}
    for key, anns in (gt_doc.items() if isinstance(gt_doc, dict) else ()):
        im_id = _im_key(key, sdir / "scene_gt.json")
        infos = info_doc.get(key) if isinstance(info_doc, dict) else None
        if not isinstance(anns, list) or not isinstance(infos, list) or len(infos) != len(anns):
            raise InputError(f"{sdir / 'scene_gt_info.json'}: [{key!r}]: expected one entry per scene_gt.json entry")
        poses = []
        for j, a in enumerate(anns):
            where = f"{sdir / 'scene_gt.json'}: [{key!r}][{j}]"
            R = _field(a, "cam_R_m2c", where, 9).reshape(3, 3)
            obj_id = _field(a, "obj_id", where)
            if not isinstance(obj_id, int) or obj_id < 0:
                raise InputError(f"{where}.obj_id: expected a non-negative integer")
            vf = _field(infos[j], "visib_fract", f"{sdir / 'scene_gt_info.json'}: [{key!r}][{j}]", 1)[0]
            poses.append(GtPose(obj_id, R, _field(a, "cam_t_m2c", where, 3), float(vf)))
        cam = cam_doc.get(key) if isinstance(cam_doc, dict) else None
        where = f"{sdir / 'scene_camera.json'}: [{key!r}]"
        if cam is None:
            raise InputError(f"{where}: missing (every scene_gt.json image needs its camera)")
        K = _field(cam, "cam_K", where, 9).reshape(3, 3)
        scale = float(_field(cam, "depth_scale", where, 1)[0]) if "depth_scale" in cam else 1.0
        depth = _depth(sdir / "depth" / f"{im_id:06d}.png", scale, where)
        if depth is not None:
            h, w = depth.shape
        elif image_size is not None:
            w, h = image_size
        else:
            raise InputError(f"{sdir}: image {im_id}: no depth/{im_id:06d}.png and no camera.json width/height "
                             "in the dataset folder: the image size is unknown (MSPD needs it)")
        gts[(scene_id, im_id)] = poses
        views[(scene_id, im_id)] = BopView(K, depth, int(w), int(h))
    return gts, views


def _models(root: Path, obj_ids) -> dict:
    mdir = next((root / d for d in ("models_eval", "models") if (root / d / "models_info.json").is_file()), None)
    if mdir is None:
        raise InputError(f"{root}: no models_eval/models_info.json or models/models_info.json")
    info = _json(mdir / "models_info.json", "BOP models_info.json")
    out = {}
    for oid in sorted(obj_ids):
        entry = info.get(str(oid)) if isinstance(info, dict) else None
        where = f"{mdir / 'models_info.json'}: [{str(oid)!r}]"
        if entry is None:
            raise InputError(f"{where}: missing (object {oid} is in the truth)")
        diameter = float(_field(entry, "diameter", where, 1)[0])
        g = read_geometry(mdir / f"obj_{oid:06d}.ply")
        if g.faces is None:
            raise InputError(f"{g.path}: expected a triangle mesh (VSD renders it)")
        out[oid] = BopModel(g.vertices, g.faces, diameter, entry)
    return out


def derived_targets(gts: dict, visib_min: float = TARGET_VISIB_MIN) -> tuple:
    """BOP19's targets where the dataset has no ``test_targets_bop19.json``: per image and
    object, the instances with ``visib_fract >= visib_min``."""
    out = []
    for (scene_id, im_id), poses in sorted(gts.items()):
        counts: dict = {}
        for g in poses:
            if g.visib_fract >= visib_min:
                counts[g.obj_id] = counts.get(g.obj_id, 0) + 1
        out += [Target(scene_id, im_id, oid, n) for oid, n in sorted(counts.items())]
    return tuple(out)


def read_bop_dataset(path, *, with_targets: bool = True) -> BopDataset:
    """A BOP dataset folder or one of its split folders (``test/``), or a single scene folder.
    ``with_targets=False``: no targets (a reference split such as ``train/``)."""
    p = Path(path)
    if not p.is_dir():
        raise InputError(f"{p}: not a folder (expected a BOP dataset, split or scene folder)")
    if (p / "scene_gt.json").is_file():
        scene_dirs, split = [p], p.parent
    else:
        split = next((p / s for s in ("test", "val", "train_pbr") if (p / s).is_dir()), p)
        scene_dirs = sorted(d for d in split.iterdir() if d.is_dir() and (d / "scene_gt.json").is_file())
    if not scene_dirs:
        raise InputError(f"{p}: no scene folder with a scene_gt.json (expected a BOP dataset)")
    root = next((d for d in (split, split.parent, split.parent.parent)
                 if (d / "models_eval").is_dir() or (d / "models").is_dir()), split.parent)
    cam_doc = _json(root / "camera.json", "BOP camera.json") if (root / "camera.json").is_file() else None
    size = (int(cam_doc["width"]), int(cam_doc["height"])) if isinstance(cam_doc, dict) and \
        isinstance(cam_doc.get("width"), int) and isinstance(cam_doc.get("height"), int) else None
    gts, views = {}, {}
    for sdir in scene_dirs:
        if not sdir.name.isdigit():
            raise InputError(f"{sdir}: expected a scene folder named by its id (000001)")
        g, v = _scene(sdir, int(sdir.name), size)
        gts.update(g)
        views.update(v)
    models = _models(root, {g.obj_id for poses in gts.values() for g in poses})
    tfile = root / "test_targets_bop19.json"
    if not with_targets:
        return BopDataset(root, split, gts, views, models, (), "none")
    if tfile.is_file():
        doc = _json(tfile, "BOP test_targets_bop19.json")
        targets = []
        for i, t in enumerate(doc if isinstance(doc, list) else [None]):
            where = f"{tfile}: [{i}]"
            vals = [_field(t, k, where) for k in ("scene_id", "im_id", "obj_id", "inst_count")]
            if not all(isinstance(v, int) and v >= 0 for v in vals):
                raise InputError(f"{where}: scene_id, im_id, obj_id, inst_count: expected non-negative integers")
            if (vals[0], vals[1]) not in gts:
                raise InputError(f"{where}: image {vals[1]} of scene {vals[0]} is not in the truth")
            targets.append(Target(*vals))
        return BopDataset(root, split, gts, views, models, tuple(targets), str(tfile))
    return BopDataset(root, split, gts, views, models, derived_targets(gts),
                      f"derived: instances with visib_fract >= {TARGET_VISIB_MIN}")
