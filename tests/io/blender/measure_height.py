"""Run inside Blender: import a glTF with Blender's own importer and print the armature's
height (the vertical extent of its bone heads, metres) over up to 21 frames, as JSON.

    blender -b --factory-startup --python measure_height.py -- FILE.glb OUT.json
"""

import json
import sys

import bpy

path, out = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.wm.read_factory_settings(use_empty=True)
# 'SMOOTH' shading: Blender 3.4's 'NORMALS' guess uses np.bool, gone from numpy >= 1.24
bpy.ops.import_scene.gltf(filepath=path, import_shading="SMOOTH")
arm = [o for o in bpy.context.scene.objects if o.type == "ARMATURE"][0]
scene = bpy.context.scene
step = max(1, (scene.frame_end - scene.frame_start) // 20)
heights = []
for f in range(int(scene.frame_start), int(scene.frame_end) + 1, step):
    scene.frame_set(f)
    # a static root at the origin (a Bandai-style rig's joint_Root) is not part of the body
    zs = [(arm.matrix_world @ b.head).z for b in arm.pose.bones
          if not (b.parent is None and (arm.matrix_world @ b.head).length < 1e-6)]
    heights.append(max(zs) - min(zs))
heights.sort()
with open(out, "w") as fh:
    json.dump({"median_height_m": heights[len(heights) // 2], "bones": len(arm.pose.bones)}, fh)
