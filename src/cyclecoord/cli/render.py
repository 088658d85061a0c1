"""``cyclecoord render``: a capture animated as a stick figure (.gif or .mp4)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import ParameterError
from ..io import input_files
from ._options import INPUT_HELP, EXIT_OK, frame_range, positive_float, positive_int
from ._outputs import Outputs, declare
from .report import load_input


def add_parser(subparsers) -> argparse.ArgumentParser:
    r = subparsers.add_parser(
        "render",
        help="animate a capture as a stick figure (.gif, or .mp4 with ffmpeg)",
        description=(
            "Draw the skeleton of every STEP-th frame (forward kinematics, y up, with the floor) "
            "and write a GIF, or an MP4 when ffmpeg is installed. Plays in real time. With "
            "--side-by-side a second capture (e.g. an extracted cycle) is drawn next to it; the "
            "shorter one loops."
        ),
    )
    r.add_argument("input", metavar="INPUT", help=INPUT_HELP)
    r.add_argument(
        "-o", "--output", required=True, metavar="OUT", help="animation file, .gif or .mp4"
    )
    r.add_argument(
        "--skeleton",
        metavar="ASF",
        help="ASF skeleton for an AMC input (default: found beside the AMC)",
    )
    r.add_argument(
        "--frames",
        type=frame_range,
        metavar="A:B",
        help="only these frames of INPUT (0-based, half-open)",
    )
    r.add_argument(
        "--fps",
        type=positive_float,
        metavar="F",
        help="frame rate of the capture (AMC files carry none; default 120)",
    )
    r.add_argument(
        "--side-by-side",
        metavar="OTHER",
        help="a second capture to draw beside INPUT (e.g. the cycle from extract -o)",
    )
    r.add_argument(
        "--step",
        type=positive_int,
        metavar="K",
        help="draw every K-th frame (default: about 30 frames per second)",
    )
    r.add_argument(
        "--view",
        choices=("side", "front", "3d"),
        default="side",
        help="side: across the direction of travel (default); front: along it; 3d: perspective",
    )
    r.add_argument(
        "--follow",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="keep the figure centred and move the floor (default: only when it travels far)",
    )
    r.add_argument("--no-progress", action="store_true", help="no progress bar over the frames")
    r.set_defaults(func=cmd_render)
    declare(
        r,
        inputs=lambda a: input_files(a.input, a.skeleton) + input_files(a.side_by_side),
        files=("-o",),
    )
    return r


def cmd_render(args: argparse.Namespace) -> int:
    from ..plot.figures import render

    out = Path(args.output)
    if out.suffix.lower() not in (".gif", ".mp4"):
        raise ParameterError(
            f"{args.output}: render writes .gif or .mp4 animations, "
            f"got {out.suffix or '(no suffix)'!r}"
        )
    folder = out.parent if str(out.parent) else Path(".")
    if not folder.is_dir():
        raise ParameterError(f"{args.output}: folder {folder} does not exist")
    motion = load_input(args.input, args.skeleton, args.fps)
    motion = motion.window(args.frames)
    other = load_input(args.side_by_side, None, None) if args.side_by_side else None
    with Outputs() as staged:
        render(motion, staged.file(out), other=other, view=args.view, step=args.step,
               follow=args.follow, progress=not args.no_progress)
    what = f"{motion.n_frames} frames" + (
        f" beside {other.n_frames} frames of {args.side_by_side}" if other else ""
    )
    print(f"wrote {out} ({what}, {args.view} view)")
    return EXIT_OK
