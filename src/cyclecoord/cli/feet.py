"""``cyclecoord feet``: foot contacts and foot skating of a motion, and foot locking."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ._options import add_feet_option, add_memory_option, add_units_option, export_units, rig_line
from ._outputs import Outputs, capture_inputs, declare


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "feet",
        help="foot contacts and foot skating; --lock pins planted feet (small leg IK)",
        description=(
            "Find when each foot point (ankle and toe of each leg; four legs on a quadruped) is "
            "planted, from forward "
            "kinematics with thresholds scaled to the leg length and a floor estimated from "
            "the motion, and measure foot skating: the horizontal speed of planted feet and "
            "the frames on which a planted foot moves faster than --skate-speed. With --lock "
            "and -o, planted feet are pinned by re-solving each leg's thigh, shin and foot "
            "rotations (the rest of the body is untouched) and the result is written in the "
            "format of OUT's suffix."
        ),
        epilog=(
            "examples:\n"
            "  cyclecoord feet 69_01.amc --frames 200:450\n"
            "  cyclecoord feet walk.bvh --feet Foot_L:Toes_L,Foot_R:Toes_R\n"
            "  cyclecoord feet cycle.bvh --cycle --lock -o cycle_locked.glb --report feet.json"
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("input", metavar="INPUT", help="motion file with a skeleton")
    p.add_argument("--frames", metavar="A:B", help="0-based half-open frame range")
    p.add_argument("--skeleton", metavar="ASF", help="skeleton for an .amc INPUT")
    p.add_argument("--fps", type=float, metavar="HZ", help="frame rate of INPUT")
    add_units_option(p)
    add_memory_option(p)
    p.add_argument(
        "--height",
        type=float,
        default=0.05,
        metavar="H",
        help="contact height band, leg lengths (0.05)",
    )
    p.add_argument(
        "--speed",
        type=float,
        default=0.5,
        metavar="V",
        help="planted feet move slower than V leg lengths/s (0.5)",
    )
    p.add_argument(
        "--skate-speed",
        type=float,
        default=0.1,
        metavar="V",
        help="a planted foot faster than V leg lengths/s skates (0.1)",
    )
    add_feet_option(p)
    p.add_argument("--lock", action="store_true", help="pin planted feet (needs -o)")
    p.add_argument(
        "--cycle",
        action="store_true",
        help="INPUT is a loop: contacts and locks wrap around the seam",
    )
    p.add_argument("-o", "--output", metavar="OUT", help="write the (locked) motion")
    p.add_argument("--report", metavar="JSON", help="write contacts and skating figures")
    p.set_defaults(func=run)
    declare(p, inputs=capture_inputs(), files=("-o", "--report"))


def run(args: argparse.Namespace) -> int:
    from ..errors import ParameterError
    from ..quality.contacts import contact_runs, contact_skeleton, foot_contacts, foot_skating
    from ..quality.legs import find_legs, legs_of_feet
    from ._options import check_output, feet_option
    from .report import load_input, write_json
    from .view import frame_window

    if args.lock and not args.output:
        raise ParameterError("--lock writes the locked motion: give -o OUT")
    check_output(args.output)
    check_output(args.report, "report")
    motion = load_input(args.input, args.skeleton, args.fps).window(frame_window(args.frames))
    print(rig_line(motion, args))
    from ..rig import describe_rig

    up = describe_rig(motion).up_axis.lower() if motion.skeleton is not None else "y"
    skeleton = contact_skeleton(motion)
    given = feet_option(args, motion)
    legs = (
        find_legs(skeleton, motion, up=up)
        if given is None
        else legs_of_feet(skeleton, given, motion, up=up)
    )
    options = {"height": args.height, "speed": args.speed, "up": up, "feet": legs.feet}
    contacts = foot_contacts(motion, **options)
    skating = foot_skating(motion, contacts, skate_speed=args.skate_speed)
    print(
        f"{Path(args.input).name}: {motion.n_frames} frames, leg length "
        f"{contacts.leg_length:.3g} units, floor at {contacts.floor:.3g}"
    )
    print(legs.describe() if given is None else legs.describe().replace("by given", "given"))
    width = max(12, *(len(f) for f in contacts.feet))
    for i, f in enumerate(contacts.feet):
        runs = contact_runs(contacts.planted[:, i])
        shown = ", ".join(f"{a}:{b}" for a, b in runs[:6]) + (" ..." if len(runs) > 6 else "")
        print(f"  {f:>{width}}: planted {100 * contacts.planted[:, i].mean():5.1f}% ({shown})")
    print(skating.summary())
    payload = {
        "input": args.input,
        "frames": motion.n_frames,
        "feet": list(contacts.feet),
        "legs": {leg.label: list(leg.points) for leg in legs.legs},
        "feet_found_by": legs.method,
        "floor": contacts.floor,
        "leg_length": contacts.leg_length,
        "contacts": {f: contact_runs(contacts.planted[:, i]) for i, f in enumerate(contacts.feet)},
        "skating": skating.to_dict(),
    }
    result = motion
    if args.lock:
        from ..synthesis.footlock import lock_feet

        locked = lock_feet(motion, contacts, cyclic=args.cycle)
        after = foot_skating(locked.motion, contacts, skate_speed=args.skate_speed)
        again = foot_skating(locked.motion, skate_speed=args.skate_speed, **options)
        print(f"locked: {after.summary()}")
        print(f"  contacts found again on the locked motion: {again.skating_frames} frames skating")
        moved = {k: v for k, v in locked.joint_change.items() if v > 0}
        print(
            "  mean joint change (deg): "
            + ", ".join(f"{k} {v:.2f}" for k, v in moved.items())
            + f"; all {len(locked.joint_change)} joints {locked.mean_joint_change:.3f}"
        )
        payload["locked"] = {
            "skating": after.to_dict(),
            "skating_redetected": again.to_dict(),
            "joint_change_deg": locked.joint_change,
            "max_lock_error": locked.max_error,
        }
        result = locked.motion
    with Outputs() as out:  # both move into place at the end, or neither does
        if args.output:
            out.save(result, args.output, **export_units(args, args.output))
        if args.report:
            write_json(out.file(args.report), json.loads(json.dumps(payload, default=float)))
            out.wrote(args.report)
    return 0
