"""``cyclecoord view``: an interactive 3-D page (one self-contained HTML file) of a motion."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..io import input_files
from ._options import add_feet_option, add_memory_option
from ._outputs import Outputs, declare


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "view",
        help="write an interactive 3-D viewer page (self-contained HTML)",
        description=(
            "Write one self-contained HTML page (plotly.js inlined: it opens with no network) "
            "showing INPUT's skeleton animated, with play/pause, a frame slider, planted feet "
            "and the floor. With --cycle INPUT is a loop (such as the cycle extract writes): a "
            "phase dial shows each frame's phase and the seam. --side-by-side adds a second "
            "motion beside it (a cycle repeats to the length of the other). Foot skating of "
            "each motion is printed."
        ),
        epilog=(
            "examples:\n"
            "  cyclecoord view 69_01.amc --frames 200:450 -o walk.html\n"
            "  cyclecoord view cycle.bvh --cycle --side-by-side 69_01.amc -o cycle.html"
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "input", metavar="INPUT", help="motion file (.amc, .bvh, .npz, .csv, .glb, .gltf, .usd*)"
    )
    p.add_argument("-o", "--output", metavar="OUT", required=True, help="the page to write (.html)")
    p.add_argument("--side-by-side", metavar="OTHER", help="a second motion shown beside INPUT")
    p.add_argument(
        "--frames", metavar="A:B", help="0-based half-open frame range of INPUT, e.g. 200:450"
    )
    p.add_argument("--other-frames", metavar="A:B", help="frame range of OTHER")
    p.add_argument(
        "--cycle",
        action="store_true",
        help="INPUT is a loop: show its phase and seam, and print its loop closure, jerk and "
        "largest step",
    )
    p.add_argument("--other-cycle", action="store_true", help="OTHER is a loop")
    p.add_argument(
        "--skeleton", metavar="ASF", help="skeleton for an .amc INPUT (default: beside it)"
    )
    p.add_argument("--fps", type=float, metavar="HZ", help="frame rate of INPUT (AMC default 120)")
    p.add_argument(
        "--max-fps",
        type=float,
        default=30.0,
        metavar="HZ",
        help="animate at most this many frames per second (default 30; more are skipped)",
    )
    p.add_argument("--no-contacts", action="store_true", help="do not mark planted feet")
    add_feet_option(p)
    add_memory_option(p)
    p.set_defaults(func=run)
    declare(
        p,
        inputs=lambda a: input_files(a.input, a.skeleton) + input_files(a.side_by_side),
        files=("-o",),
    )


def frame_window(text: str | None):
    from ..errors import ParameterError

    if text is None:
        return None
    try:
        a, b = text.split(":")
        return (int(a) if a else None, int(b) if b else None)
    except ValueError:
        raise ParameterError(
            f"frame range must look like A:B (0-based, half-open), got {text!r}"
        ) from None


def run(args: argparse.Namespace) -> int:
    from ..errors import ParameterError
    from ..plot.viewer import ViewerInput, skeleton_figure, write_viewer
    from ..quality.contacts import foot_skating
    from ._options import feet_option
    from .report import load_input

    out = Path(args.output)
    if out.suffix.lower() not in (".html", ".htm"):
        raise ParameterError(f"{out}: the viewer writes an .html page, give it a .html name")
    folder = out.parent if str(out.parent) else Path(".")
    if not folder.is_dir():
        raise ParameterError(f"{out}: folder {folder} does not exist")
    items = []
    m = load_input(args.input, args.skeleton, args.fps).window(frame_window(args.frames))
    items.append(ViewerInput(m, Path(args.input).name, args.cycle, feet_option(args, m)))
    if args.side_by_side:
        o = load_input(args.side_by_side).window(frame_window(args.other_frames))
        items.append(
            ViewerInput(o, Path(args.side_by_side).name, args.other_cycle, feet_option(args, o))
        )
    for it in items:
        if it.cycle and it.motion.n_frames >= 5:
            from ..synthesis.sources import cycle_summary
            from .blend import figures_line

            print(f"{it.label}: {figures_line(cycle_summary(it.motion))}")
        try:
            print(f"{it.label}: {foot_skating(it.motion, feet=it.feet).summary()}")
        except ParameterError as exc:
            print(f"{it.label}: foot skating not measured ({exc})")
    fig = skeleton_figure(items, contacts=not args.no_contacts, max_fps=args.max_fps)
    with Outputs() as staged:
        size = write_viewer(fig, staged.file(out)).stat().st_size / 1e6
    print(f"wrote {out} ({size:.1f} MB, {len(fig.frames)} animation frames, self-contained)")
    return 0
