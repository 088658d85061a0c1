"""Extract the typical cycle of a capture and save it as a loopable BVH clip
=========================================================================

A command-line script (the gallery shows it; it is run by the tests)::

    python examples/extract_cycle.py                      # built-in synthetic walk
    python examples/extract_cycle.py 69_01.amc --frames 200:450 --max-scale 50 -o walk_cycle.bvh

The cycle starts at its slowest pose, lasts one mean period at the capture's frame rate and
travels like the original (root re-integrated), so a game engine can loop it with root
motion.  Exit code 3 when the capture holds no clear periodic motion.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import cyclecoord as cc


def frame_range(text: str) -> tuple[int | None, int | None]:
    a, _, b = text.partition(":")
    return (int(a) if a else None, int(b) if b else None)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("input", nargs="?", help="capture (.amc, .bvh, .npz, .csv); default: the built-in walk")
    p.add_argument("-o", "--output", help="cycle file to write (default: <input stem>_cycle.bvh here)")
    p.add_argument("--frames", type=frame_range, help="0-based half-open range A:B")
    p.add_argument("--max-scale", type=float, help="Rips threshold (see cyclecoord extract --help)")
    args = p.parse_args(argv)

    if args.input:
        motion = cc.load(args.input)
        stem = Path(args.input).stem
    else:
        motion = cc.datasets.example_capture().motion
        stem = "example_walk"
    try:
        result = cc.extract(motion, frames=args.frames, max_scale=args.max_scale)
    except cc.NoPeriodicMotionError as exc:
        print(f"no cycle: {exc}", file=sys.stderr)
        return 3
    out = Path(args.output or f"{stem}_cycle.bvh")
    cc.save(result.cycle, out)
    print(
        f"{result.cycles:.2f} cycles of {result.period_frames:.1f} frames "
        f"({result.period_frames / motion.fps:.3f} s); loop closure {result.loop_closure:.2f}"
    )
    print(f"wrote {out} ({result.cycle.n_frames} frames at {result.cycle.fps:g} fps)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
