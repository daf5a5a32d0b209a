"""The resolved spec as plain JSON-able data (for cameras.json / the manifest) and its hash.

Poses are written as ``{"R": 3x3 rows, "t": [x, y, z]}`` (metres) with frame names in the keys
(``cam_from_world``, ``world_from_object``). Files appear as the path written in the spec
(relative to the spec file) plus the sha256 of their content, never as absolute paths, so the
hash does not depend on where the project is checked out.
"""
from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import os
from pathlib import Path
from types import MappingProxyType

from scenegen.geometry.pose import Rigid3
from scenegen.spec import model as m
from scenegen.spec.model.meta import spec_meta
from scenegen.spec.sensors import SENSOR_KINDS
from scenegen.spec.views import resolve_views

#: Version of the layout returned by spec_to_dict.
SPEC_DICT_FORMAT = "scenegen.spec/1"
#: Significant digits of floats in the hashed canonical JSON: derived poses may differ in the last
#: ulp between numpy/libm builds; 12 digits (1e-12 relative) keep the hash stable across them.
HASH_FLOAT_DIGITS = 12


def file_sha256(path: Path) -> str:
    st = os.stat(path)
    return _file_sha256(str(path), st.st_mtime_ns, st.st_size)


@functools.lru_cache(maxsize=256)
def _file_sha256(path: str, mtime_ns: int, size: int) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _at_omitted_default(x, f: dataclasses.Field, v) -> bool:
    """A field whose metadata says ``omit_default`` and whose value is its default."""
    meta = spec_meta(type(x), f)
    return meta is not None and meta.omit_default and f.default is not dataclasses.MISSING \
        and v == f.default


def _plain(x):
    """Dataclasses, mappings, tuples, Rigid3 and paths -> JSON-able values (fields marked
    ``omit_default`` left out at their default, so older specs keep their form and hash)."""
    if isinstance(x, Rigid3):
        return x.to_dict()
    if dataclasses.is_dataclass(x):
        out = {}
        for f in dataclasses.fields(x):
            if f.name in ("where", "path_as_written"):
                continue
            v = getattr(x, f.name)
            if _at_omitted_default(x, f, v):
                continue
            if f.name == "path":
                v = None if v is None else {"path": getattr(x, "path_as_written"),
                                           "sha256": file_sha256(v)}
            out[f.name] = _plain(v)
        return out
    if isinstance(x, (dict, MappingProxyType)):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, Path):
        return str(x)
    if hasattr(x, "tolist"):
        return x.tolist()
    return x


def rig_to_dict(rig: m.Rig) -> dict:
    """A rig as plain data, each member's sensor and pose under its kind's keys (a camera's
    ``camera`` and ``rig_from_cam``, as datasets have always held them)."""
    d = _plain(rig)
    d["members"] = []
    for mb in rig.members:
        member = _plain(mb)
        sensor_key, pose_key = SENSOR_KINDS[mb.kind].member_keys
        member[sensor_key], member[pose_key] = member.pop("sensor"), member.pop("rig_from_sensor")
        d["members"].append(member)
    return d


def spec_to_dict(spec: m.SceneSpec) -> dict:
    """The resolved spec: every default filled in, references replaced by what they name, every
    view's pose computed. JSON-able; stable key order."""
    cameras = {}
    for name, cam in spec.cameras.items():
        d = _plain(cam)
        d["K"] = cam.K.tolist()
        cameras[name] = d
    objects = []
    for obj in spec.objects:
        d = _plain(obj)
        d["transform"] = {"world_from_object": obj.transform.world_from_object.to_dict(),
                          "scale": list(obj.transform.scale),
                          "matrix": obj.transform.matrix.tolist()}
        objects.append(d)
    views = [{"name": v.name, "camera": v.camera, "rig": v.rig, "rig_member": v.rig_member,
              "frame_index": v.frame_index, "view_set": v.view_set,
              "cam_from_world": v.cam_from_world.to_dict(),
              **({"time_s": v.time_s} if v.time_s is not None else {})} for v in resolve_views(spec)]
    return {
        "format": SPEC_DICT_FORMAT,
        "name": spec.name,
        "description": spec.description,
        "seed": spec.seed,
        "render": _plain(spec.render),
        "materials": _plain(spec.materials),
        "objects": objects,
        "lights": _plain(spec.lights),
        "cameras": cameras,
        "rigs": {str(name): rig_to_dict(r) for name, r in spec.rigs.items()},
        "view_sets": _view_sets(spec.view_sets),
        "views": views,
        # only when declared, so that specs without variation keep their hashes
        # only when declared: sensors of the kinds other than cameras
        **({"sensors": _plain(spec.sensors)} if spec.sensors else {}),
        **({"variation": _plain(spec.variation)} if spec.variation is not None else {}),
        # likewise the cross-view outputs: their settings are part of the run's identity
        **({"crossview": _plain(spec.crossview)} if getattr(spec, "crossview", None) is not None else {}),
        **({"variant": _plain(dict(spec.variant))} if spec.variant is not None else {}),
        **({"sequence": _plain(spec.sequence)} if getattr(spec, "sequence", None) is not None else {}),
        **({"truth": _plain(spec.truth)} if getattr(spec, "truth", None) is not None else {}),
        **({"placement": _plain(spec.placement)} if getattr(spec, "placement", None) is not None else {}),
    }


def _view_sets(view_sets) -> list:
    """The view sets; ``lights`` only where given, so specs without it keep their hashes."""
    out = []
    for vs in view_sets:
        d = _plain(vs)
        if d.get("lights") is None:
            d.pop("lights", None)
        out.append(d)
    return out


def _rounded(x):
    if isinstance(x, float):
        r = float(f"{x:.{HASH_FLOAT_DIGITS}g}")
        return 0.0 if r == 0 else r  # -0.0 and 0.0 hash alike
    if isinstance(x, dict):
        return {k: _rounded(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_rounded(v) for v in x]
    return x


def canonical_json(d: dict) -> str:
    """Sorted keys, no spaces, floats to HASH_FLOAT_DIGITS significant digits, no NaN."""
    return json.dumps(_rounded(d), sort_keys=True, separators=(",", ":"), allow_nan=False,
                      ensure_ascii=True)


def spec_sha256(spec: m.SceneSpec) -> str:
    """sha256 (hex) of the canonical JSON of :func:`spec_to_dict` (includes the referenced
    files' content hashes)."""
    return hashlib.sha256(canonical_json(spec_to_dict(spec)).encode()).hexdigest()
