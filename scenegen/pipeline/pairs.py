"""Which views the cross-view truth relates: camera streams, consecutive pairs, stereo frames."""
from __future__ import annotations

import itertools


def streams(views) -> dict:
    """Views grouped into camera streams: same view set and rig member, in frame order."""
    out: dict = {}
    for v in views:
        out.setdefault((v.view_set, v.rig_member), []).append(v)
    return {k: sorted(vs, key=lambda v: v.frame_index) for k, vs in out.items()}


def consecutive_pairs(views) -> list[tuple[str, str]]:
    """Consecutive frames of each stream, then the members of each rig frame (first member with
    each other member), in the run's view order."""
    pairs = []
    for vs in streams(views).values():
        pairs += [(a.name, b.name) for a, b in zip(vs, vs[1:])]
    frames: dict = {}
    for v in views:
        if v.rig is not None:
            frames.setdefault((v.view_set, v.frame_index), []).append(v.name)
    for names in frames.values():
        pairs += [(names[0], other) for other in names[1:]]
    order = {v.name: k for k, v in enumerate(views)}
    return sorted(set(pairs), key=lambda p: (order[p[0]], order[p[1]]))


#: A spec's ``crossview.pairs`` mode -> the pairs it selects (explicit lists are taken as given).
PAIR_MODES = {
    "none": lambda views: [],
    "all": lambda views: [(a.name, b.name) for a, b in itertools.combinations(views, 2)],
    "consecutive": consecutive_pairs,
}


def select_pairs(mode, views) -> list[tuple[str, str]]:
    """The (i, j) view-name pairs of a ``crossview.pairs`` setting: a mode or explicit pairs."""
    if isinstance(mode, str):
        return PAIR_MODES[mode](views)
    return [tuple(p) for p in mode]


def stereo_frames(views, rigs) -> list[tuple[str, str]]:
    """(left view, right view) of every frame of a stereo rig, or of a multi rig whose members
    ``left`` and ``right`` are cameras (active IR stereo: two cameras and a projector), in order."""
    frames: dict = {}
    for v in views:
        if v.rig is not None and _stereo_like(rigs[v.rig]):
            frames.setdefault((v.view_set, v.frame_index), {})[v.rig_member] = v.name
    return [(f["left"], f["right"]) for f in frames.values() if "left" in f and "right" in f]


def _stereo_like(rig) -> bool:
    if rig.type == "stereo":
        return True
    cams = {mb.name for mb in rig.members if mb.kind == "camera"}
    return {"left", "right"} <= cams
