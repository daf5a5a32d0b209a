"""Physically plausible placement: objects released above a support and settled by a rigid-body
engine (MuJoCo) before rendering, so a spec says "drop these objects onto the table" instead of
giving their poses (docs/scene_spec.md, "Placement").

:mod:`.spawn` draws the seeded release poses (no two bounding spheres overlap), :mod:`.drop`
builds the MuJoCo model from convex hulls and steps it until every object rests. Pure functions
of arrays: the spec layer (:mod:`scenegen.spec.parse.placement`) hands them the objects' meshes
and records the settled poses. Nothing here imports the spec.
"""
from scenegen.physics.drop import (
    DENSITY_KG_M3, FLAT_SUPPORT_THICKNESS_M, GRAVITY_M_S2, TIMESTEP_S, Body, DropError, DropSettings,
    Settled, engine_version, settle, support_hull,
)
from scenegen.physics.spawn import bounding_radius, release_poses

__all__ = ["DENSITY_KG_M3", "FLAT_SUPPORT_THICKNESS_M", "GRAVITY_M_S2", "TIMESTEP_S", "Body",
           "DropError", "DropSettings", "Settled", "engine_version", "settle", "support_hull",
           "bounding_radius", "release_poses"]
