"""A view's bounding boxes (``truth: {boxes: true}``): the objects' meshes in their object frames
and their poses at the view's time, handed to :mod:`scenegen.crossview.boxes` with the view's
stored object-id truth (docs/dataset_format.md, "Bounding boxes")."""
from __future__ import annotations

from scenegen.crossview.boxes import object_boxes, visible_boxes
from scenegen.dataset.boxes import ViewBoxes, boxes_document
from scenegen.dataset.codecs import encode_json
from scenegen.dataset.layout import boxes_path
from scenegen.dataset.truth import TruthKind
from scenegen.spec.timeline import object_states


def view_boxes(spec, built, view, truth) -> ViewBoxes:
    """The boxes of every spec object in ``view`` (``truth``: the view's truth as stored). The
    object frame is the one of ``transform`` (its scale acts in it; docs/scene_spec.md); the
    world meshes were placed at ``transform``, so ``transform.world_from_object`` takes them back.
    A sequence's frame has every object where the timeline has it at the view's ``time_s``."""
    time_s = getattr(view, "time_s", None)
    states = object_states(spec.objects, time_s) if time_s is not None else None
    camera = built.cameras[view.camera]
    visible = visible_boxes(truth[TruthKind.OBJECT_ID])
    objects = []
    for obj in spec.objects:
        world_from_object_0 = obj.transform.world_from_object
        vertices_object = world_from_object_0.inverse().apply(built.meshes_world[obj.name].vertices)
        state = states[obj.name] if states is not None else None
        objects.append(object_boxes(
            obj.name, obj.object_id, obj.instance_id, present=True if state is None else state.present,
            vertices_object=vertices_object,
            world_from_object=world_from_object_0 if state is None else state.world_from_object,
            camera=camera, cam_from_world=view.cam_from_world, visible=visible))
    return ViewBoxes(view.name, (camera.width, camera.height), view.cam_from_world, tuple(objects))


def view_boxes_file(spec, built, view, truth) -> tuple[str, bytes]:
    """(path, bytes) of ``truth/<view>_boxes.json``."""
    return boxes_path(view.name), encode_json(boxes_document(view_boxes(spec, built, view, truth)))
