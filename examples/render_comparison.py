"""Render a capture next to its extracted typical cycle as a stick-figure GIF
==========================================================================

A command-line script (the gallery shows it; it is run by the tests)::

    python examples/render_comparison.py                  # built-in synthetic walk
    python examples/render_comparison.py 69_01.amc --frames 200:450 --max-scale 50 -o walk.gif

Left: the original frames; right: the typical cycle, looped (its root carried on by one
period's travel per loop) for as long as the original lasts.  Also writes the analysis
figures (barcode, PCA, density, coordinate, channels) with ``--figures DIR``.
"""

from __future__ import annotations

import argparse
import sys

import cyclecoord as cc
from cyclecoord import plot


def frame_range(text: str) -> tuple[int | None, int | None]:
    a, _, b = text.partition(":")
    return (int(a) if a else None, int(b) if b else None)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("input", nargs="?", help="capture with a skeleton (.amc or .bvh); default: the built-in walk")
    p.add_argument("-o", "--output", default="original_vs_cycle.gif", help="animation (.gif, or .mp4 with ffmpeg)")
    p.add_argument("--frames", type=frame_range, help="0-based half-open range A:B")
    p.add_argument("--max-scale", type=float, help="Rips threshold (see cyclecoord extract --help)")
    p.add_argument("--view", default="side", choices=("side", "front", "3d"))
    p.add_argument("--step", type=int, help="draw every STEP-th frame (default: about 30 frames per second)")
    p.add_argument("--figures", metavar="DIR", help="also write the analysis figures into DIR")
    args = p.parse_args(argv)

    motion = cc.load(args.input) if args.input else cc.datasets.example_capture().motion
    try:
        result = cc.extract(motion, frames=args.frames, max_scale=args.max_scale)
        path = plot.render(result.motion, args.output, other=result.cycle, view=args.view, step=args.step,
                           titles=("original", f"cycle ({result.cycle.n_frames} frames, looped)"))
    except cc.NoPeriodicMotionError as exc:
        print(f"no cycle: {exc}", file=sys.stderr)
        return 3
    except cc.CycleCoordError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    print(f"wrote {path}")
    if args.figures:
        for f in plot.save_figures(result, args.figures):
            print(f"wrote {f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
