"""Blender side of bench_cycles.py: runs in the bpy environment (benchmarks/.venv-bpy), never in
the project's .venv. Reads the scene that bench_cycles.py exported (npz, no pickles), renders it
with Cycles on the CPU, prints the timings as JSON and writes the last render as a float32 EXR.

usage: python _cycles_render.py SCENE.npz OUT.exr  (settings are inside the npz)
"""
import json
import sys
import time

import bpy
import numpy as np
from mathutils import Matrix


def main(scene_path: str, out_exr: str) -> None:
    z = np.load(scene_path, allow_pickle=False)
    W, H, spp, bounces, threads = (int(x) for x in z["settings"])
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = bounces
    c.volume_bounces = 0
    c.transparent_max_bounces = 0
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0  # Cycles clamps indirect light at 10 by default
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.seed = 0
    scene.render.threads_mode = "FIXED"
    scene.render.threads = threads
    scene.render.resolution_x, scene.render.resolution_y = W, H
    scene.render.resolution_percentage = 100
    scene.render.use_persistent_data = True  # keep the BVH between renders (warm)
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0

    world = bpy.data.worlds.new("world")
    scene.world = world
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    L = float(z["env_radiance"])
    bg.inputs[0].default_value = (L, L, L, 1.0)
    bg.inputs[1].default_value = 1.0

    for name in [str(n) for n in z["objects"]]:
        verts, faces, uv = z[f"{name}.vertices"], z[f"{name}.faces"], z[f"{name}.uv"]
        mesh = bpy.data.meshes.new(name)
        mesh.from_pydata(verts.tolist(), [], faces.tolist())
        loop_vi = np.empty(len(mesh.loops), dtype=np.int32)
        mesh.loops.foreach_get("vertex_index", loop_vi)
        layer = mesh.uv_layers.new(name="UVMap")
        uv_b = np.stack([uv[:, 0], 1.0 - uv[:, 1]], axis=1)  # Blender's v = 0 is the image's bottom row
        layer.data.foreach_set("uv", uv_b[loop_vi].astype(np.float32).ravel())
        if f"{name}.normals" in z:
            mesh.polygons.foreach_set("use_smooth", np.ones(len(mesh.polygons), dtype=bool))
            mesh.normals_split_custom_set_from_vertices(z[f"{name}.normals"].tolist())
        # linear float32 RGB EXR written by bench_cycles.py (row 0 = the top row of the picture)
        img = bpy.data.images.load(str(z[f"{name}.texture_exr"]))
        img.colorspace_settings.name = "Non-Color"  # raw values, as Mitsuba's raw bitmap
        mat = bpy.data.materials.new(f"{name}_mat")
        mat.use_nodes = True
        nt = mat.node_tree
        nt.nodes.clear()
        out = nt.nodes.new("ShaderNodeOutputMaterial")
        bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Roughness"].default_value = 0.0  # Lambert, as Mitsuba's diffuse
        tnode = nt.nodes.new("ShaderNodeTexImage")
        tnode.image = img
        tnode.interpolation = "Linear"
        tnode.extension = "REPEAT"
        nt.links.new(tnode.outputs["Color"], bsdf.inputs["Color"])
        nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
        mesh.materials.append(mat)
        obj = bpy.data.objects.new(name, mesh)
        scene.collection.objects.link(obj)

    cam = bpy.data.cameras.new("cam")
    cam.type = "PERSP"
    cam.sensor_fit = "HORIZONTAL"
    cam.sensor_width = 36.0
    cam.lens = float(z["focal_px"]) * 36.0 / W
    cam.clip_start, cam.clip_end = 0.001, 1000.0
    cam_obj = bpy.data.objects.new("cam", cam)
    scene.collection.objects.link(cam_obj)
    cam_obj.matrix_world = Matrix(z["blender_matrix_world"].tolist())
    scene.camera = cam_obj

    t = time.perf_counter()
    bpy.ops.render.render()  # cold: kernels, BVH, textures
    cold = time.perf_counter() - t
    warm = []
    for _ in range(2):
        t = time.perf_counter()
        bpy.ops.render.render()
        warm.append(time.perf_counter() - t)
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.filepath = out_exr
    bpy.ops.render.render(write_still=True)
    print("CYCLES_TIMES " + json.dumps({"cold_s": cold, "warm_s": min(warm), "version": bpy.app.version_string}))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
