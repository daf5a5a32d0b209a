"""Validate builds what render builds from files and parameters: every object's mesh (mesh files
loaded and checked: readable, finite, indices in range, within the size limits; procedural shapes
and calibration boards made) and every texture (image files decoded, procedural ones made), so
``scenegen validate`` fails exactly where ``render`` would, and every asset error names the spec's
file:line (:func:`located`), in both commands."""
from __future__ import annotations

from contextlib import contextmanager

from scenegen.assets import meshes
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
    render); SpecError naming the object's spec line for the first that fails."""
    for obj in spec.objects:
        with located(obj, f"object {obj.name!r}"):
            meshes.object_mesh(obj.geometry)
        texture = getattr(obj.material, "texture", None)
        if texture is not None:
            with located(texture if getattr(texture, "where", None) else obj, f"object {obj.name!r} texture"):
                meshes.texture_image(texture)
