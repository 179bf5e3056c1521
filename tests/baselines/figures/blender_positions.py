"""Run by Blender (not by pytest): import a ``.glb`` and print, as one JSON line, each object
whose name starts with a prefix: whether it is keyframed, and its world position at times.

    blender -b --python blender_positions.py -- FILE.glb PREFIX FPS T1,T2,...
"""

import json
import sys

import bpy
import numpy

if not hasattr(numpy, "bool"):  # Blender 3.4's glTF importer still names np.bool (NumPy < 1.24)
    numpy.bool = numpy.bool_

path, prefix, fps, times = sys.argv[sys.argv.index("--") + 1 :]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = int(fps)  # before the import: the importer turns seconds into frames at it
bpy.ops.import_scene.gltf(filepath=path)
found = [o for o in bpy.data.objects if o.name.startswith(prefix)]
out = {o.name: {"keyframed": bool(o.animation_data and o.animation_data.action
                                  and o.animation_data.action.fcurves), "at": {}}
       for o in found}  # fmt: skip
for t in times.split(","):
    scene.frame_set(round(float(t) * int(fps)))
    for o in found:
        out[o.name]["at"][t] = list(o.matrix_world.translation)
print("POSITIONS " + json.dumps(out))
