"""``cyclecoord animate``: run a JSON script of latent-synthesis commands into a motion file."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ._options import add_feet_option, add_memory_option
from ._outputs import Outputs, crossing_refusal, declare

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "animate",
        help="synthesise a motion from a script of latent-space commands",
        description=(
            "Run SCRIPT.json (models by name, MOVE/IDLE/TRANSITION/PLAY commands, fps, seed; see "
            "the README) and write the motion (.bvh, .amc, .npz or .csv). Nothing is written if "
            "the script fails."
        ),
    )
    p.add_argument(
        "script", metavar="SCRIPT.json",
        help="the script: models by name, start, commands (see examples/latent_script.json)",
    )
    p.add_argument(
        "-o", "--output", required=True, metavar="OUT.bvh",
        help="the synthesised motion; its suffix chooses the format (.bvh, .amc, .npz, .csv, "
        ".glb/.gltf, .usda/.usdc/.usd)",
    )
    p.add_argument(
        "--report", metavar="R.json", help="write a JSON report (commands, bridges, timing, checks)"
    )
    p.add_argument("--no-check", action="store_true", help="skip the plausibility checks")
    p.add_argument(
        "--allow-contacts",
        action="store_true",
        help="write the motion even when its limbs pass through each other (bone contacts the "
        "training takes never make, left after frames along a gait were pulled toward the "
        "captured pose); by default such a motion is refused and only the report is written",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar over the commands")
    add_feet_option(p)
    add_memory_option(p)
    p.set_defaults(func=run)
    declare(p, inputs=_script_files, files=("-o", "--report"), derived=_skeleton_output)


def _script_files(args: argparse.Namespace) -> list[Path]:
    from ..synthesis.latent.script import script_files

    return script_files(args.script)


def _skeleton_output(args: argparse.Namespace) -> list[tuple[str, Path]]:
    """``-o OUT.amc`` also writes ``OUT.asf``."""
    out = Path(args.output)
    return [("-o", out.with_suffix(".asf"))] if out.suffix.lower() == ".amc" else []


def run(args: argparse.Namespace) -> int:
    from ..errors import ParameterError
    from ..io import atomic_write
    from ..synthesis.latent.script import run_script

    out = Path(args.output)
    script = Path(args.script)
    for target in [out] + ([Path(args.report)] if args.report else []):
        if not (target.parent if str(target.parent) else Path(".")).is_dir():
            raise ParameterError(f"{target}: folder {target.parent} does not exist")
    motion, report = run_script(
        script, check=not args.no_check, progress=not args.no_progress, feet=args.feet or None
    )
    crossing = (report.get("plausibility") or {}).get("new_contact_frames") or []
    if crossing and not args.allow_contacts:
        return _refuse_crossing(args, report, crossing)
    # every output moves into place at the end, so a failure or Ctrl-C leaves none
    with Outputs() as staged:
        skeleton = [asf for _option, asf in _skeleton_output(args)]
        staged.save(motion, out, announce=False, **({"asf_path": skeleton[0]} if skeleton else {}))
        if args.report:
            with atomic_write(staged.file(args.report)) as fh:
                json.dump(report, fh, indent=2, default=float)
    for line in report.get("motion_quality_lines", []):
        print(line)
    t = report["timing"]
    fps = t["frames_per_second"]
    cpu = t.get("frames_per_cpu_second")
    speed = f", synthesis {fps:,.0f} frames/s" if fps else ""
    if cpu:
        speed += f" ({cpu:,.0f} per CPU second)"
    print(
        f"{out}: {report['frames']} frames ({report['duration_s']:.1f} s at {report['fps']:g} "
        "fps), "
        f"{len(report['transitions'])} transitions{speed}"
    )
    for ev in report["transitions"]:
        if ev.get("in_step"):
            a, b = ev["transition"]
            print(
                f"commands[{ev['command']}] TRANSITION {a} -> {b} in step at gait phase "
                f"{ev['phase']:.2f} (pose distance {ev['bridge_distance']:.3g}, blend "
                f"{ev['blend_frames']} frames)"
            )
        elif ev["route"][1:] != ev["transition"][1:] or not ev["under_threshold"]:
            a, b = ev["transition"]
            kind = (
                "over a bridge"
                if ev["under_threshold"]
                else f"at the closest poses, {ev['bridge_distance'] / ev['threshold']:.2f}x the "
                "bridge threshold"
            )
            print(
                f"commands[{ev['command']}] TRANSITION {' -> '.join(ev['route'])}: {a} -> {b} "
                f"{kind} (pose distance {ev['bridge_distance']:.3g}, blend {ev['blend_frames']} "
                "frames)"
            )
    for note in report.get("notes", []):
        print(note)
    if "plausibility" in report:
        pl = report["plausibility"]
        print("plausibility: " + ("clean" if pl["clean"] else "; ".join(pl["notes"])))
    return 0


def _crossing_hint(report: dict, frames: list) -> str:
    """What may avoid limbs passing through each other in ``frames``: where they fall in
    a TRANSITION's blend (three frames each side), a blend of another length, which
    crosses the two gaits at another moment of the stride (the Bandai benchmark script's
    run -> walk blend of 0.4 s brought the feet too close on every seed, 0.5 s on none of
    seeds 0-4); else another seed."""
    fps = float(report.get("fps") or 30.0)
    for ev in report.get("transitions") or []:
        a, n = ev.get("start_frame"), ev.get("blend_frames")
        if a is None or n is None or not any(a - 3 <= f < a + n + 3 for f in frames):
            continue
        return (f"commands[{ev['command']}] TRANSITION {' -> '.join(ev['transition'])} "
                f"blends there: a blend of another length (\"blend\": {(n + 3) / fps:.2f} "
                "instead of {:.2f}) or another seed may avoid it".format(n / fps))
    return "another seed may avoid it"


def _refuse_crossing(args: argparse.Namespace, report: dict, frames: list) -> int:
    """Write the report, not a motion whose limbs pass through each other."""
    from ..errors import ImplausibleMotionError
    from ..io import atomic_write

    why = crossing_refusal("synthesised motion", frames, _crossing_hint(report, frames))
    report = {**report, "refused": why}
    if args.report:
        with Outputs() as staged, atomic_write(staged.file(args.report)) as fh:
            json.dump(report, fh, indent=2, default=float)
    for line in report.get("motion_quality_lines", []):
        print(line)
    print("plausibility: " + "; ".join(report["plausibility"]["notes"]))
    raise ImplausibleMotionError(why)
