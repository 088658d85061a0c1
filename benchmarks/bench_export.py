"""Time the exporters, the foot-contact measures, foot locking and the viewer on CMU 69_01.

Run from a checkout::

    PYTHONPATH=src python benchmarks/bench_export.py [--capture PATH] [--repeat R]

Prints, per step, the median wall time and the process CPU time of ``R`` runs (the machine
may be shared: CPU time is the steadier figure).  Nothing is asserted.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

DEFAULT = (
    Path(__file__).resolve().parents[1].parent / "shared" / "data" / "cmu" / "69" / "69_01.amc"
)


def _time(fn, repeat: int) -> tuple[float, float]:
    walls, cpus = [], []
    for _ in range(repeat):
        w, c = time.perf_counter(), time.process_time()
        fn()
        walls.append(time.perf_counter() - w)
        cpus.append(time.process_time() - c)
    return statistics.median(walls), statistics.median(cpus)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--capture", type=Path, default=DEFAULT)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()

    import cyclecoord as cc
    from cyclecoord.plot.viewer import skeleton_figure, write_viewer
    from cyclecoord.quality.contacts import foot_contacts, foot_skating
    from cyclecoord.synthesis.footlock import lock_feet

    motion = cc.load(args.capture)
    window = motion[200:450]
    print(f"{args.capture.name}: {motion.n_frames} frames, {len(motion.skeleton.joints)} joints")
    with tempfile.TemporaryDirectory() as tmp:
        steps = {}
        for suffix in (".glb", ".gltf", ".usda", ".usdc"):
            out = Path(tmp) / f"m{suffix}"
            steps[f"save {suffix}"] = lambda out=out: cc.save(motion, out)
            steps[f"load {suffix}"] = lambda out=out: cc.load(out)
        steps["foot_contacts (469 frames)"] = lambda: foot_contacts(motion)
        steps["foot_skating (469 frames)"] = lambda: foot_skating(motion)
        steps["lock_feet (frames 200:450)"] = lambda: lock_feet(window)
        page = Path(tmp) / "v.html"
        steps["viewer page (469 frames, 30 fps)"] = lambda: write_viewer(
            skeleton_figure(motion), page
        )
        for name, fn in steps.items():
            if name.startswith("load"):
                cc.save(motion, Path(tmp) / ("m" + name.split()[-1]))
            wall, cpu = _time(fn, args.repeat)
            print(f"  {name:<36} wall {wall:7.3f} s   cpu {cpu:7.3f} s")


if __name__ == "__main__":
    main()
