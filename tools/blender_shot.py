"""Run inside Blender (``blender -b --factory-startup --python tools/blender_shot.py -- IN.glb
OUT.png FRAME FPS``): import a facelib ``.glb`` with Blender's own glTF importer at the
clip's frame rate (Blender keys the animation at the scene's rate, 24 by default), go to an
animation frame (1-based, Blender's) and render the head (the top 28 cm) from the front with
Cycles on the CPU. Used by ``tools/render_export_shots.py`` for docs/export.md."""

import math
import sys

import bpy
import numpy
from mathutils import Vector

if not hasattr(numpy, "bool"):  # Debian's Blender 3.4 importer under numpy 1.24 (see
    numpy.bool = bool  # tests/export/blender_probe.py)

source, out, frame, fps = sys.argv[sys.argv.index("--") + 1:][:4]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps, scene.render.fps_base = int(fps), 1.0
bpy.ops.import_scene.gltf(filepath=source)
scene.frame_set(int(frame))
meshes = [o for o in scene.objects if o.type == "MESH"]
graph = bpy.context.evaluated_depsgraph_get()
points = [o.matrix_world @ v.co for o in meshes for v in o.evaluated_get(graph).data.vertices]
top = max(p[2] for p in points)
points = [p for p in points if p[2] > top - 0.28]  # the head (metres), not the bust below
low = [min(p[k] for p in points) for k in range(3)]
high = [max(p[k] for p in points) for k in range(3)]
centre = [(a + b) / 2 for a, b in zip(low, high, strict=True)]
height = high[2] - low[2]
camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(camera)
camera.data.lens = 85
# Blender is z up and the glTF importer turns glTF's +z (the face's front) into Blender's -y
camera.location = (centre[0], low[1] - 3.4 * height, centre[2])
camera.rotation_euler = (math.pi / 2, 0, 0)
scene.camera = camera
for name, where, power in (("key", (0.6, -1.0, 0.8), 350), ("fill", (-0.8, -0.8, 0.3), 120)):
    light = bpy.data.objects.new(name, bpy.data.lights.new(name, "AREA"))
    light.data.energy, light.data.size = power * height * height, height
    light.location = Vector(centre) + 2 * height * Vector(where)
    # an area light shines along its -z: turn it toward the head
    light.rotation_euler = (Vector(centre) - light.location).to_track_quat("-Z", "Y").to_euler()
    scene.collection.objects.link(light)
world = bpy.data.worlds.new("world")
world.color = (0.05, 0.05, 0.05)
scene.world = world
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 24
scene.cycles.use_denoising = False
scene.render.resolution_x = scene.render.resolution_y = 420
scene.render.filepath = out
bpy.ops.render.render(write_still=True)
