"""``cyclecoord convert``: a capture from one file format to another."""

from __future__ import annotations

import argparse

from ._options import (
    FORMATS,
    INPUT_HELP,
    EXIT_OK,
    add_memory_option,
    add_units_option,
    check_output,
    export_units,
    frame_range,
    positive_float,
    rig_line,
)
from ._outputs import Outputs, capture_inputs, declare
from .report import load_input


def add_parser(subparsers) -> argparse.ArgumentParser:
    c = subparsers.add_parser(
        "convert",
        help=f"convert between {FORMATS}",
        description=f"Convert a capture between formats, chosen by the file suffixes: {FORMATS}.",
    )
    c.add_argument("input", metavar="INPUT", help=INPUT_HELP)
    c.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="OUT",
        help="output file; its suffix chooses the format (.amc with its .asf beside it, "
        ".bvh, .npz, .csv, .glb/.gltf and .usda/.usdc/.usd in metres); never one of the inputs",
    )
    c.add_argument("--skeleton", metavar="ASF", help="ASF skeleton for an AMC input")
    c.add_argument(
        "--fps", type=positive_float, metavar="F", help="frame rate to record in the output"
    )
    c.add_argument("--frames", type=frame_range, metavar="A:B", help="only these frames")
    add_units_option(c)
    add_memory_option(c)
    c.set_defaults(func=cmd_convert)
    declare(c, inputs=capture_inputs(), files=("-o",))
    return c


def cmd_convert(args: argparse.Namespace) -> int:
    check_output(args.output)
    motion = load_input(args.input, args.skeleton, args.fps)
    motion = motion.window(args.frames)
    print(rig_line(motion, args))
    with Outputs() as out:  # an AMC and its .asf move into place together
        # the line below names it
        out.save(motion, args.output, announce=False, **export_units(args, args.output))
    print(
        f"{args.input} -> {args.output}: {motion.n_frames} frames, {motion.n_channels} channels, "
        f"{motion.fps:g} fps"
    )
    return EXIT_OK
