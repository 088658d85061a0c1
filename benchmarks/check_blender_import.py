"""Do Blender's own glTF and USD importers read our files as we wrote them?

Run with the project's Python; give it a Python that has Blender's ``bpy`` module (the PyPI
wheel ``bpy``, e.g. in a separate venv: ``python -m venv /tmp/bpyenv &&
/tmp/bpyenv/bin/pip install bpy``)::

    PYTHONPATH=src python benchmarks/check_blender_import.py --bpy-python /tmp/bpyenv/bin/python \
        ../shared/data/cmu/69/69_01.amc

It converts the capture to ``--format`` (glb, gltf, usdc or usda), has Blender import it
(``bpy.ops.import_scene.gltf`` or ``bpy.ops.wm.usd_import``, the scene at the motion's frame
rate), reads every pose bone's head in world space on every
frame, and compares them with cyclecoord's forward kinematics after the axis change (glTF y
up -> Blender z up: Blender (x, y, z) = glTF (x, -z, y)) and the unit change (metres back to
skeleton units; Blender's USD importer also converts to metres with ``metersPerUnit``).  Prints the frame and joint counts and the largest error.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

_BLENDER_SIDE = r"""
import sys, json
import numpy as np
import bpy

glb, out, fps = sys.argv[1], sys.argv[2], float(sys.argv[3])
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = int(round(fps))
if glb.endswith((".glb", ".gltf")):
    bpy.ops.import_scene.gltf(filepath=glb)
else:
    bpy.ops.wm.usd_import(filepath=glb)
arm = next(o for o in scene.objects if o.type == "ARMATURE")
action = arm.animation_data.action
start, end = (int(round(v)) for v in action.frame_range)
names = [pb.name for pb in arm.pose.bones]
pos = []
for f in range(start, end + 1):
    scene.frame_set(f)
    pos.append([list(arm.matrix_world @ pb.head) for pb in arm.pose.bones])
np.savez(out, pos=np.array(pos), names=np.array(names), start=start, end=end,
         version=bpy.app.version_string)
"""


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("capture")
    ap.add_argument("--bpy-python", required=True, help="a Python interpreter with bpy")
    ap.add_argument("--format", default="glb", choices=("glb", "gltf", "usdc", "usda"))
    args = ap.parse_args()

    import numpy as np

    import cyclecoord as cc
    from cyclecoord.rig import metres_per_unit

    motion = cc.load(args.capture)
    with tempfile.TemporaryDirectory() as tmp:
        glb = Path(tmp) / f"motion.{args.format}"
        cc.save(motion, glb)
        side = Path(tmp) / "blender_side.py"
        side.write_text(_BLENDER_SIDE)
        out = Path(tmp) / "blender.npz"
        t0 = time.perf_counter()
        r = subprocess.run([args.bpy_python, str(side), str(glb), str(out), str(motion.fps)],
                           capture_output=True, text=True, check=False)
        if r.returncode != 0:
            print(r.stdout[-2000:], r.stderr[-2000:], file=sys.stderr)
            return 1
        wall = time.perf_counter() - t0
        data = np.load(out)
        names = [str(n) for n in data["names"]]
        pos = data["pos"]
        version = str(data["version"])
    fk = motion.positions()
    scale = metres_per_unit(motion)  # what the export scaled by
    fk_names = [n[:-4] + "/end" if n.endswith("_end") else n for n in names]
    cols = [fk.names.index(n) for n in fk_names]
    blender_as_gltf = np.stack([pos[..., 0], pos[..., 2], -pos[..., 1]], axis=-1) / scale
    err = np.linalg.norm(blender_as_gltf - fk.positions[:, cols], axis=-1)
    report = {
        "blender": version,
        "format": args.format,
        "frames": [int(pos.shape[0]), motion.n_frames],
        "joints": [len(names), len(fk.names)],
        "max_error_units": float(err.max()),
        "worst_frame": int(err.max(axis=1).argmax()),
        "blender_wall_s": round(wall, 1),
    }
    print(json.dumps(report, indent=1))
    return 0 if report["frames"][0] == report["frames"][1] and err.max() < 1e-3 else 1


if __name__ == "__main__":
    sys.exit(main())
