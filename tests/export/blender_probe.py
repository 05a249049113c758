"""Run inside Blender (``blender -b --factory-startup --python blender_probe.py -- IN.glb
OUT.json FPS FRAMES JOINTS``): import a ``.glb`` with Blender's own glTF importer and write
what Blender made of it as JSON.

FRAMES: comma-separated animation frames (0-based); JOINTS: comma-separated joint-name
prefixes (``lid_upper_l`` turns every bone ``lid_upper_l_*``). The JSON holds the mesh objects'
names and vertex counts, for each mesh object with a UV layer its layers' names and each
vertex's UV (the first loop's, and the largest gap to its other loops' UVs), for each mesh
object with shape keys each frame's shape-key values
by name, and for each prefix and mesh object the glTF-space (y up) rest positions of the
object's vertices that move when those bones turn.
"""

import json
import sys
from pathlib import Path

import bpy
import mathutils
import numpy

# Debian bookworm's Blender 3.4 glTF importer still uses ``numpy.bool``, which Debian's numpy
# 1.24 no longer has: it fails on every mesh with normals ("module 'numpy' has no attribute
# 'bool'"). The alias meant the builtin, so give it back inside this Blender process only.
if not hasattr(numpy, "bool"):
    numpy.bool = bool  # type: ignore[attr-defined]


def _args() -> tuple[str, str, int, list[int], list[str]]:
    argv = sys.argv[sys.argv.index("--") + 1:]
    return argv[0], argv[1], int(argv[2]), [int(f) for f in argv[3].split(",")], \
        argv[4].split(",")


def _gltf_space(co: "mathutils.Vector") -> list[float]:
    """Blender's z-up world back to glTF's y-up (the importer maps glTF (x, y, z) to
    Blender (x, -z, y))."""
    return [co.x, co.z, -co.y]


def _world_positions(obj: "bpy.types.Object") -> list["mathutils.Vector"]:
    graph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(graph)
    mesh = evaluated.to_mesh()
    out = [evaluated.matrix_world @ v.co for v in mesh.vertices]
    evaluated.to_mesh_clear()
    return out


def _vertex_uvs(obj: "bpy.types.Object") -> dict:
    """The object's UV layers, each vertex's UV on the first layer (its first loop's) and the
    largest distance between the UVs of one vertex's loops."""
    mesh = obj.data
    layer = mesh.uv_layers[0].data
    first: dict[int, list[float]] = {}
    gap = 0.0
    for loop in mesh.loops:
        uv = list(layer[loop.index].uv)
        seen = first.setdefault(loop.vertex_index, uv)
        gap = max(gap, abs(seen[0] - uv[0]), abs(seen[1] - uv[1]))
    return {"layers": [u.name for u in mesh.uv_layers],
            "uv": [first.get(v, [-1.0, -1.0]) for v in range(len(mesh.vertices))], "gap": gap}


def main() -> None:
    path, out, fps, frames, prefixes = _args()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = fps, 1.0
    bpy.ops.import_scene.gltf(filepath=path)
    meshes = [o for o in scene.objects if o.type == "MESH"]
    keyed = [o for o in meshes if o.data.shape_keys is not None]
    armature = next(o for o in scene.objects if o.type == "ARMATURE")
    report: dict = {"meshes": {o.name: len(o.data.vertices) for o in meshes},
                    "bones": [b.name for b in armature.pose.bones],
                    "frame_start": scene.frame_start, "shape_keys": {}, "follow": {},
                    "uv": {o.name: _vertex_uvs(o) for o in meshes if o.data.uv_layers}}
    for obj in keyed:
        blocks = obj.data.shape_keys.key_blocks
        report["shape_keys"][obj.name] = {
            str(f): {b.name: b.value for b in blocks if b.name != blocks[0].name}
            for f in frames if scene.frame_set(f) is None}
        report["shape_keys"][obj.name]["_slider_min"] = min(b.slider_min for b in blocks)
    # the joints: rest pose (no animation, no shape keys), then turn each chain alone
    armature.animation_data_clear()
    for obj in keyed:
        obj.data.shape_keys.animation_data_clear()
        for block in obj.data.shape_keys.key_blocks:
            block.value = 0.0
    for bone in armature.pose.bones:
        bone.rotation_mode = "QUATERNION"
        bone.rotation_quaternion = (1.0, 0.0, 0.0, 0.0)
        bone.location = (0.0, 0.0, 0.0)
    still = {o.name: _world_positions(o) for o in meshes}
    turn = mathutils.Quaternion((1.0, 0.0, 0.0), 0.3)
    for prefix in prefixes:
        chain = [b for b in armature.pose.bones if b.name.rsplit("_", 1)[0] == prefix
                 or b.name == prefix]
        for bone in chain:
            bone.rotation_quaternion = turn
        report["follow"][prefix] = {
            o.name: [_gltf_space(a) for a, b in zip(still[o.name], _world_positions(o),
                                                    strict=True) if (a - b).length > 1e-5]
            for o in meshes}
        for bone in chain:
            bone.rotation_quaternion = (1.0, 0.0, 0.0, 0.0)
    Path(out).write_text(json.dumps(report))


main()
