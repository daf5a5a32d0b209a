"""KITTI 2015 optical-flow layout from a sequence's motion truth (sequence/motion/*): every pair
(a, b) of frames with step 1 of each camera stream, forward, becomes

* ``training/image_2/{k:06d}_10.png`` (frame a) and ``{k:06d}_11.png`` (frame b), 8-bit RGB;
* ``training/flow_occ/{k:06d}_10.png``: the flow a -> b at every pixel whose surface point
  projects into b (visible, occluded or out of frame: KITTI's "all" pixels);
* ``training/flow_noc/{k:06d}_10.png``: only where b sees the point (state ``visible``);

16-bit RGB, ``u = (R - 2^15) / 64``, ``v = (G - 2^15) / 64``, valid where ``B = 1``
(:mod:`scenegen.dataset.codecs.kitti_flow`; 1/64 px steps, |flow| < 512 px). ``pairs.json`` maps
each index to our views.
"""
from __future__ import annotations

import json

import numpy as np

from scenegen.dataset.codecs import encode_kitti_flow_png, encode_png
from scenegen.dataset.crossview import VISIBLE
from scenegen.export.common import write
from scenegen.export.errors import ExportError
from scenegen.geometry.color import to_uint8


def export(ds, dest, progress=None) -> dict:
    index = ds.sequence.index
    pairs = [(a, b) for a, b, step in (index.pairs if index is not None else ()) if step == 1]
    if not pairs:
        raise ExportError(f"{ds.root} has no sequence flow with step 1 (a sequence with flow_steps [1, ...])")
    out = []
    for k, (a, b) in enumerate(pairs):
        tag = f"{k:06d}"
        write(dest, f"training/image_2/{tag}_10.png", encode_png(to_uint8(ds.image(a))))
        write(dest, f"training/image_2/{tag}_11.png", encode_png(to_uint8(ds.image(b))))
        m = ds.sequence.motion(a, b)
        flow = m.flow
        write(dest, f"training/flow_occ/{tag}_10.png", encode_kitti_flow_png(flow))
        write(dest, f"training/flow_noc/{tag}_10.png",
              encode_kitti_flow_png(np.where((m.state == VISIBLE)[..., None], flow, np.nan)))
        out.append({"index": tag, "a": a, "b": b})
        if progress is not None:
            progress(k + 1, len(pairs))
    write(dest, "pairs.json", (json.dumps({"pairs": out}, indent=1) + "\n").encode())
    return {"files": 4 * len(out) + 1, "pairs": len(out)}
