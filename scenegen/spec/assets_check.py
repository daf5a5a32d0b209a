"""Validate builds what render builds from files and parameters: every object's mesh (mesh files
loaded and checked: readable, finite, indices in range, within the size limits; procedural shapes
and calibration boards made), a mesh file's own materials (its MTL's or glTF's texture images
decoded), every texture (image files decoded, procedural ones made) and every environment map
(size by its header, then decoded: :mod:`scenegen.assets.envmap`), so ``scenegen validate``
fails exactly where ``render`` would, and every asset error names the spec's file:line
(:func:`located`), in both commands."""
from __future__ import annotations

from contextlib import contextmanager

from scenegen.assets import meshes
from scenegen.assets.envmap import check_envmap
from scenegen.assets.libraries import mesh_within
from scenegen.assets.mesh_materials import mesh_parts
from scenegen.assets.texture_files import load_data_image
from scenegen.errors import SpecError


@contextmanager
def located(record, what: str):
    """Turn an asset builder's ValueError into a SpecError at ``record.where`` (file:line: field)."""
    try:
        yield
    except (ValueError, TypeError) as e:  # TypeError: procedural parameters of the wrong kind
        raise SpecError.at(getattr(record, "where", None), f"{what}: {e}") from None


def check_assets(spec) -> None:
    """Build every object's mesh and texture once (the asset cache keeps procedural ones for the
    render), read each mesh file's own materials and each environment map; SpecError naming the
    spec line of the object or light for the first that fails."""
    for obj in spec.objects:
        with located(obj, f"object {obj.name!r}"):
            meshes.object_mesh(obj.geometry)
            if obj.geometry.kind == "mesh" and obj.geometry.own_materials:  # render's condition
                mesh_parts(obj.geometry.path, mesh_within(obj.geometry))  # the MTL's / glTF's images, as render reads them
        texture = getattr(obj.material, "texture", None)
        if texture is not None:
            with located(texture if getattr(texture, "where", None) else obj, f"object {obj.name!r} texture"):
                meshes.texture_image(texture)
        pbr = getattr(obj.material, "pbr_set", None)
        if pbr is not None:  # a texture set's data maps, decoded as render decodes them
            with located(pbr, f"object {obj.name!r} pbr_set"):
                for mp in (pbr.roughness, pbr.metallic, pbr.normal, pbr.disp):
                    if mp is not None:
                        load_data_image(mp.path)
    for light in spec.lights:
        if light.type == "envmap":
            with located(light, f"light {light.name!r}"):
                check_envmap(light.path)
