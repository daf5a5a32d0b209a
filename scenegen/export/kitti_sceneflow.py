"""KITTI 2015 scene flow layout from a stereo rig's sequence truth on the rectified grid
(``sequence/stereo_motion/*`` and the rectified stereo frames ``crossview/stereo/*``).

Every pair (a, b) of a stereo rig's frames with step 1, forward, becomes pair ``k`` (in the
sequence index's order), everything on the rectified LEFT grid of frame a (the KITTI 2015
devkit's "reference frame", its readme.txt, "Dataset description"):

* ``training/image_2/{k:06d}_10.png``, ``_11.png``: rectified left at a and b (8-bit RGB);
  ``training/image_3/...``: rectified right at a and b;
* ``training/disp_occ_0/{k:06d}_10.png``: disparity at a on every pixel with a surface;
  ``disp_noc_0``: only where a's rectified right view sees the point (both as ``kitti-stereo``);
* ``training/disp_occ_1/{k:06d}_10.png``: disparity at b OF THE POINT SEEN AT EACH PIXEL OF a,
  ``f_b B_b / Z_b`` with ``Z_b`` its depth in b's rectified left camera after it moved with its
  object, on every pixel whose moved point has a positive depth there; ``disp_noc_1``: only where
  b's rectified left AND right views see the moved point;
* ``training/flow_occ/{k:06d}_10.png``: flow of the rectified left view a -> b on every pixel
  whose moved point projects into b's rectified left view (occluded and out of frame included);
  ``flow_noc``: only where b's rectified left view sees it;
* ``training/obj_map/{k:06d}_10.png``: KITTI's foreground map of frame a's rectified left view,
  uint8: the instance id where the pixel sees an object that moves over the sequence (its pose
  or presence changes between frames: KITTI's moving cars), 0 on everything static;
  ``training/calib_cam_to_cam/{k:06d}.txt`` of frame a as ``kitti-stereo`` writes it;
  ``pairs.json`` maps each index to our views.

Disparity PNGs: uint16 ``round(d * 256)``, 0 invalid (also d >= 256); flow PNGs: 16-bit RGB
``u = (R - 2^15) / 64``, valid where B = 1, clipped to the encodable [-512, 512) px
(:mod:`scenegen.dataset.codecs.kitti`, :mod:`~scenegen.dataset.codecs.kitti_flow`). A point
whose object no longer exists at b has flow and disparity where it would be (occ) and is
occluded (not noc).
"""
from __future__ import annotations

import json

import numpy as np

from scenegen.dataset.codecs import encode_kitti_disparity, encode_kitti_flow_png, encode_png
from scenegen.dataset.crossview import VISIBLE
from scenegen.dataset.files import copy_file
from scenegen.dataset.layout import stereo_dir, stereo_path
from scenegen.export.common import crossview_index, write
from scenegen.export.errors import ExportError
from scenegen.export.kitti_stereo import calib_cam_to_cam, obj_map
from scenegen.geometry.color import to_uint8

#: KITTI's flow PNG holds (value * 64 + 2^15) in 16 bits: |flow| beyond this is clipped.
FLOW_LIMIT_PX = 512.0


def export(ds, dest, progress=None) -> dict:
    index = ds.sequence.index
    pairs = [(a, b) for a, b, step in (index.stereo_pairs if index is not None else ()) if step == 1]
    if not pairs:
        raise ExportError(f"{ds.root} has no stereo scene flow with step 1 (a sequence with flow_steps [1, ...]"
                          " and a stereo rig with crossview.stereo: true)")
    crossview_index(ds)
    out, n_obj, clipped = [], 0, 0
    moving = np.array(sorted(ds.sequence.moving_object_ids()), np.uint32)
    for k, (a, b) in enumerate(pairs):
        tag = f"{k:06d}"
        fa, fb = ds.crossview.stereo(a), ds.crossview.stereo(b)
        for side, folder in (("left", "image_2"), ("right", "image_3")):
            write(dest, f"training/{folder}/{tag}_10.png", encode_png(to_uint8(fa.image(side))))
            write(dest, f"training/{folder}/{tag}_11.png", encode_png(to_uint8(fb.image(side))))
        for kind in ("occ", "noc"):
            (dest / f"training/disp_{kind}_0").mkdir(parents=True, exist_ok=True)
            copy_file(ds.path(stereo_path(a, f"disparity_{kind}", "left")),
                      dest / f"training/disp_{kind}_0/{tag}_10.png")
        m = ds.sequence.stereo_motion(a, b)
        flow = m.flow
        write(dest, f"training/disp_occ_1/{tag}_10.png", encode_kitti_disparity(m.disparity, np.isfinite(m.disparity)))
        write(dest, f"training/disp_noc_1/{tag}_10.png", encode_kitti_disparity(m.disparity, m.visible_both))
        write(dest, f"training/flow_occ/{tag}_10.png", encode_kitti_flow_png(flow))
        write(dest, f"training/flow_noc/{tag}_10.png",
              encode_kitti_flow_png(np.where((m.state == VISIBLE)[..., None], flow, np.nan)))
        with np.errstate(invalid="ignore"):
            clipped += int(np.count_nonzero(np.any(np.abs(flow) >= FLOW_LIMIT_PX, axis=2)))
        om = obj_map(ds, fa)
        if om is not None:  # foreground: what moves (KITTI's dynamic objects), the rest background
            om = np.where(np.isin(fa.object_ids("left"), moving), om, 0).astype(np.uint8)
            write(dest, f"training/obj_map/{tag}_10.png", encode_png(om))
            n_obj += 1
        write(dest, f"training/calib_cam_to_cam/{tag}.txt", calib_cam_to_cam(fa.calib).encode())
        out.append({"index": tag, "a": {"left_view": a, "right_view": fa.right_view, "stereo_dir": stereo_dir(a)},
                    "b": {"left_view": b, "right_view": fb.right_view, "stereo_dir": stereo_dir(b)}})
        if progress is not None:
            progress(k + 1, len(pairs))
    write(dest, "pairs.json", (json.dumps({"pairs": out}, indent=1) + "\n").encode())
    return {"files": 11 * len(out) + n_obj + 1, "pairs": len(out), "obj_map": n_obj, "flow_clipped_px": clipped}
