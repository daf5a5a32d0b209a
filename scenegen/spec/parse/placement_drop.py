"""The drop of `placement:` run at parse time: release, settle and check the dropped objects
(:mod:`scenegen.physics` on the objects' meshes). Its own module so that only a spec that drops
objects loads the engine and the mesh library (:mod:`scenegen.spec.parse.placement` imports it on use).
"""
from __future__ import annotations

import numpy as np

from scenegen.assets.meshes import object_mesh
from scenegen.errors import SpecError
from scenegen.geometry import seeds
from scenegen.located_yaml import Fields
from scenegen.physics import Body, DropError, DropSettings, bounding_radius, release_poses, settle, support_hull
from scenegen.spec.model.geometry import SceneObject
from scenegen.spec.model.placement import DropPlacement


def simulate(spec: DropPlacement, dropped: list[SceneObject], support: SceneObject, f: Fields) -> dict:
    """Release, settle and check: {name: settled world_from_object}."""
    def scaled(obj):
        return np.asarray(object_mesh(obj.geometry)[0].vertices, np.float64) * np.asarray(obj.transform.scale)

    try:
        hull = support_hull(scaled(support), support.transform.world_from_object, support.name)
    except DropError as e:
        raise f.get("onto").error(str(e)) from None
    vertices = [scaled(o) for o in dropped]
    radii = [bounding_radius(v) for v in vertices]
    top_z = float(hull.bounds[1][2])
    regions = []
    for obj, r in zip(dropped, radii):
        if spec.region_min is not None:
            regions.append((spec.region_min, spec.region_max))
            continue
        lo, hi = hull.bounds[0][:2] + r, hull.bounds[1][:2] - r
        if np.any(lo > hi):
            raise f.get("objects").error(
                f"object {obj.name!r} (bounding radius {r:.3g} m) does not fit on the support {support.name!r} "
                f"({np.ptp(hull.bounds[:, 0]):.3g} x {np.ptp(hull.bounds[:, 1]):.3g} m); give `region:`")
        regions.append((tuple(lo), tuple(hi)))
    releases = release_poses(radii, [o.transform.world_from_object.R for o in dropped], regions, top_z,
                             spec.drop_height_m, spec.orientation, seeds.rng(spec.seed))
    settings = DropSettings(friction=spec.friction, settle_s=spec.settle_s, rest_speed_m_s=spec.rest_speed_m_s)
    try:
        out = settle([Body(o.name, v, p) for o, v, p in zip(dropped, vertices, releases)], hull, settings)
    except DropError as e:
        raise f.get("objects").error(str(e)) from None
    if not out.at_rest:
        k = int(np.argmax(out.point_speed_m_s))
        low = float(out.poses[k].apply(vertices[k])[:, 2].min())
        why = f"; it fell off the support {support.name!r}" if low < top_z - 0.01 else ""
        raise SpecError.at(spec.where, f"object {dropped[k].name!r} is still moving after settle_s "
                           f"{spec.settle_s:g} s (a point at {out.point_speed_m_s[k]:.3g} m/s, rest_speed_m_s "
                           f"{spec.rest_speed_m_s:g}){why}")
    return {o.name: p for o, p in zip(dropped, out.poses)}
