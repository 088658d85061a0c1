"""``cyclecoord blend`` and ``cyclecoord transition``: new cycles from captured ones."""

from __future__ import annotations

import argparse
import sys

from ..errors import NoPeriodicMotionError, ParameterError
from ..io import input_files
from ._options import (
    EXIT_NO_PERIODIC,
    EXIT_OK,
    add_feet_option,
    check_output,
    feet_option,
    frame_range,
    positive_float,
    positive_int,
)
from ._outputs import Outputs, declare
from .report import clean, load_input, write_json


def add_parser(subparsers) -> None:
    bl = subparsers.add_parser(
        "blend",
        help="blend two or more cycles by weights into a new loopable cycle",
        description=(
            "Convex combination y(θ) = Σ w_i x_i(θ) of periodic cycles (paper §4.5). The first "
            "input is the reference: the others are scaled to its skeleton, turned to its heading "
            "and aligned to its phase (circular search over shifts); the blend lasts Σ w_i T_i and "
            "travels the weighted mean stride. Limbs passing through each other and joint angles "
            "outside the inputs' range are reported."
        ),
    )
    bl.add_argument("inputs", nargs="+", metavar="INPUT", help="two or more cycles or captures")
    bl.add_argument(
        "--weights",
        type=_weights,
        metavar="W1,W2,...",
        help="one non-negative weight per input, summing to 1 (default: equal)",
    )
    add_input_options(bl)
    bl.set_defaults(func=cmd_blend)
    declare(bl, inputs=_inputs, files=("-o", "--report"))

    tr = subparsers.add_parser(
        "transition",
        help="a clip that turns one cycle into another without a hitch",
        description=(
            "Cycles of A, then a ramp over which the weight of B rises smoothly from 0 to 1 while "
            "the phase keeps advancing and the cadence slides from A's to B's (the paper's "
            "homotopy), then cycles of B. The continuity check compares every step with the "
            "typical step of A and B at the same phase."
        ),
    )
    tr.add_argument("inputs", nargs=2, metavar="INPUT", help="cycle (or capture) A, then B")
    length = tr.add_mutually_exclusive_group(required=True)
    length.add_argument(
        "--frames", type=positive_int, metavar="N", help="length of the ramp in frames"
    )
    length.add_argument(
        "--cycles", type=positive_float, metavar="C", help="length of the ramp in cycles"
    )
    tr.add_argument(
        "--lead-in", type=int, default=1, metavar="K", help="whole cycles of A before the ramp (1)"
    )
    tr.add_argument(
        "--lead-out", type=int, default=1, metavar="K", help="whole cycles of B after the ramp (1)"
    )
    add_input_options(tr)
    tr.set_defaults(func=cmd_transition)
    declare(tr, inputs=_inputs, files=("-o", "--report"))


def _inputs(args: argparse.Namespace) -> list:
    """Every file blend and transition read: each input and an AMC's ``.asf``."""
    return [f for src in args.inputs for f in input_files(src)]


def add_input_options(q: argparse.ArgumentParser) -> None:
    """The input, matching and output options that blend and transition share."""
    g = q.add_argument_group(
        "inputs",
        "An input is taken as one cycle when it was written by extract or blend (NPZ metadata), "
        "or when it loops (last-to-first step <= 1.5x its median step), does not repeat within "
        "its length (at most ~1.5 periods by autocorrelation) and moves (some pose >= 3 median "
        "steps from the mean pose); anything else is a capture and its typical cycle is extracted "
        "first (facing heading 0, to keep the root's Euler angles away from gimbal lock). Options "
        "given once apply to every input; given once per input, they apply in input order ('auto' "
        "or ':' keeps an input's default).",
    )
    how = g.add_mutually_exclusive_group()
    how.add_argument("--as-cycle", action="store_true", help="take every input as a cycle as it is")
    how.add_argument(
        "--extract", action="store_true", help="extract the typical cycle of every input"
    )
    g.add_argument(
        "--window",
        type=frame_range,
        action="append",
        metavar="A:B",
        help="0-based half-open frame window of an input (like extract's --frames)",
    )
    g.add_argument(
        "--fps",
        type=_auto_or_positive,
        action="append",
        metavar="F",
        help="frame rate of an input (AMC files carry none; default 120)",
    )
    g.add_argument(
        "--max-scale",
        type=_auto_or_positive,
        action="append",
        metavar="E",
        help="Rips threshold for extracting an input ('auto': extract's default)",
    )
    g.add_argument(
        "--scale",
        type=_auto_or_positive,
        action="append",
        metavar="E",
        help="scale to read an input's cocycle at ('auto': extract's default)",
    )
    g.add_argument(
        "--seed", type=int, default=0, metavar="S", help="random seed for extraction (0)"
    )
    add_feet_option(g)
    m = q.add_argument_group("matching and checks")
    m.add_argument(
        "--allow-reverse",
        action="store_true",
        help="let a cycle play backwards when that matches the first better",
    )
    m.add_argument(
        "--no-heading",
        action="store_true",
        help="do not turn the cycles to the first one's heading before blending",
    )
    m.add_argument("--up", choices=("x", "y", "z"), default="y", help="vertical axis (default y)")
    m.add_argument(
        "--margin",
        type=float,
        default=5.0,
        metavar="DEG",
        help="joint-range tolerance beyond the inputs' range, degrees (5)",
    )
    m.add_argument(
        "--strict",
        action="store_true",
        help="refuse to write an output that fails the plausibility checks (exit 1)",
    )
    o = q.add_argument_group("output")
    o.add_argument(
        "-o",
        "--output",
        metavar="OUT",
        help="write the result (.bvh, .amc, .npz, .csv, .glb, .gltf, .usda, .usdc)",
    )
    o.add_argument(
        "--report",
        metavar="R.json",
        help="write a JSON report (inputs, alignment, figures, plausibility)",
    )


def _auto_or_positive(text: str) -> float | None:
    """A positive number, or ``auto`` for the default (per-input options of blend/transition)."""
    if text.strip().lower() == "auto":
        return None
    return positive_float(text)


def _weights(text: str) -> list[float]:
    """Parse ``0.3,0.7`` into numbers (their range is checked by the blend)."""
    try:
        return [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated numbers such as 0.3,0.7, got {text!r}"
        ) from None


def _per_input(values: list | None, n: int, option: str) -> list:
    """An option given once (for every input) or once per input, in input order."""
    if not values:
        return [None] * n
    if len(values) == 1:
        return list(values) * n
    if len(values) != n:
        raise ParameterError(
            f"{option} given {len(values)} times for {n} inputs; give it once or once per input"
        )
    return list(values)


def _load_cycles(args: argparse.Namespace) -> list:
    """Every input as a cycle (captures are extracted first), with why."""
    from ..synthesis.sources import as_cycle

    n = len(args.inputs)
    windows = _per_input(args.window, n, "--window")
    fpss = _per_input(args.fps, n, "--fps")
    scales = _per_input(args.max_scale, n, "--max-scale")
    cocycle_scales = _per_input(args.scale, n, "--scale")
    mode = "cycle" if args.as_cycle else "extract" if args.extract else "auto"
    out = []
    for path, window, fps, max_scale, scale in zip(
        args.inputs, windows, fpss, scales, cocycle_scales
    ):
        motion = load_input(path, None, fps)
        options = {"random_state": args.seed}
        feet = feet_option(args, motion)
        if feet is not None:
            options["feet"] = feet
        if max_scale is not None:
            options["max_scale"] = max_scale
        if scale is not None:
            options["scale"] = scale
        try:
            src = as_cycle(motion, mode=mode, frames=window, **options)
        except NoPeriodicMotionError as exc:
            raise NoPeriodicMotionError(f"{path}: {exc}", result=exc.result) from None
        c = src.cycle
        print(
            f"{path}: cycle of {c.n_frames} frames ({c.n_frames / c.fps:.3f} s at {c.fps:g} fps); "
            f"{src.reason}"
        )
        out.append(src)
    return out


def _check_outputs(args: argparse.Namespace) -> None:
    """Fail fast on outputs we could not write (main has refused those naming an input)."""
    check_output(args.output)
    check_output(args.report, "report")


def finish(
    args: argparse.Namespace,
    motion,
    payload: dict,
    report,
    what: str,
    problem: str | None = None,
    out: Outputs | None = None,
    quality: dict | None = None,
) -> int:
    """Print the plausibility verdict, honour --strict, write the motion and the report.

    ``quality`` (the measure of generated motion, :func:`~cyclecoord.quality.generated.
    lead_lines`; printed by the command first) leads the report as ``motion_quality``.

    The outputs go through ``out`` (the command's staged outputs; a new one when None) and
    move into place together; with --strict and a failed check the report (and what was
    staged before it) is moved into place and the motion is not written.
    """
    from ..errors import ImplausibleMotionError

    if out is None:
        with Outputs() as own:
            return finish(args, motion, payload, report, what, problem, own, quality)
    if quality is not None:
        payload = {"motion_quality": quality, **payload}
    print(report.summary())
    payload["plausibility"] = report.to_dict()
    refused = args.strict and (not report.clean or problem is not None)
    payload["written"] = None if refused or not args.output else args.output
    if args.report:
        write_json(out.file(args.report), clean(payload))
        out.wrote(args.report)
    if refused:
        out.commit()  # the report says why the motion is not written
        why = problem if report.clean and problem else "fails the plausibility checks"
        raise ImplausibleMotionError(
            f"the {what} {why} and --strict is set; nothing written"
            + (f" (see {args.report})" if args.report else "")
        )
    if args.output:
        out.save(motion, args.output)
    return EXIT_OK


def cmd_blend(args: argparse.Namespace) -> int:
    from ..quality.plausibility import check_plausibility
    from ..synthesis.blend import blend
    from .._words import si
    from ..synthesis.sources import cycle_summary

    _check_outputs(args)
    try:
        sources = _load_cycles(args)
    except NoPeriodicMotionError as exc:
        print(f"cyclecoord: {exc}", file=sys.stderr)
        return EXIT_NO_PERIODIC
    n = len(sources)
    weights = args.weights if args.weights is not None else [1.0 / n] * n
    cycles = [s.cycle for s in sources]
    out = blend(
        sources,
        weights,
        allow_reverse=args.allow_reverse,
        align_heading=not args.no_heading,
        up=args.up,
    )
    quality = _lead(out, cycles, args.feet, shares=out.metadata["blend"]["weights"])
    info = out.metadata["blend"]
    for i, al in enumerate(info["alignments"][1:], start=1):
        rev = ", reversed" if al["reversed"] else ""
        print(
            f"aligned {args.inputs[i]} to {args.inputs[0]}: shift {al['shift_frames']:.2f} "
            f"frames{rev}, rms pose difference {al['cost']:.3g} (unaligned "
            f"{al['cost_unaligned']:.3g})"
        )
    summaries = [cycle_summary(c) for c in cycles]
    s = cycle_summary(out)
    print(
        f"blend {', '.join(f'{w:g}' for w in info['weights'])}: {out.n_frames} frames "
        f"({s['seconds']:.3f} s; inputs "
        + ", ".join(f"{v['frames']}" for v in summaries)
        + f"), loop closure {s['loop_closure']:.2f}, largest step "
        + si(s["largest_step"], "m" if s["unit"] == "m" else "units")
        + f", {_jerk_words(s, summaries)}"
    )
    for note in info["notes"]:
        print(f"note: {note}")
    skating, inputs_skating = _skating(out, cycles, "blend", args.feet)
    report = check_plausibility(out, cycles, margin_deg=args.margin)
    payload = {
        "inputs": [
            dict(src.to_dict(), path=p, summary=sm, foot_skating=sk)
            for src, p, sm, sk in zip(sources, args.inputs, summaries, inputs_skating)
        ],
        "weights": info["weights"],
        "output": dict(s, path=args.output),
        "root_displacement": out.metadata.get(
            "root_displacement", out.metadata.get("travel_displacement")),
        "foot_skating": skating,
        "blend": info,
    }
    return finish(args, out, payload, report, "blend", quality=quality)


def _jerk_words(out: dict, inputs: list[dict]) -> str:
    """The blend's jerk against its inputs': a ratio, then the figures with an SI prefix
    (:func:`~cyclecoord.synthesis.sources.cycle_summary`: metres / s³ on joint positions,
    channel units / s³ without a skeleton)."""
    import math

    from .._words import si

    mean = sum(v["jerk"] for v in inputs) / max(len(inputs), 1)
    if not (math.isfinite(mean) and mean > 0 and math.isfinite(out["jerk"])):
        return "jerk not measured (fewer than 7 frames)"
    unit = "m/s³" if out.get("unit") == "m" else "units/s³"
    ratio = f"{out['jerk'] / mean:.2f}x the inputs' mean"
    figures = ", ".join(si(v["jerk"], unit) for v in inputs)
    return f"jerk {ratio} ({si(out['jerk'], unit)}; inputs {figures})"


def figures_line(s: dict) -> str:
    """A cycle's loop closure, jerk and largest step in words (a
    :func:`~cyclecoord.synthesis.sources.cycle_summary` dict): the line ``transition``
    and ``view`` print for each cycle, ``extract`` and ``blend`` print the same figures."""
    from .._words import si

    unit = "m" if s.get("unit") == "m" else "units"
    return (
        f"loop closure {s['loop_closure']:.2f}, jerk {si(s['jerk'], unit + '/s³')}, "
        f"largest step {si(s['largest_step'], unit)} ({s['largest_step'] / s['median_step']:.2f} "
        f"median steps; on {s['space']})"
        if s.get("median_step") else f"loop closure {s['loop_closure']:.2f}"
    )


def _lead(
    motion, sources: list, feet: str | None = None, reference=None, shares=None, hold=None
) -> dict | None:
    """Print the measure of generated motion against ``sources`` (or their figures
    ``reference``, or each source's mixed by ``shares``; ``hold``: frames of an asked
    stand; the console's first lines) and return its report dict (None when it cannot be
    measured)."""
    from ..quality.generated import lead_lines

    quality, lines = lead_lines(motion, sources, feet=feet or None, reference=reference,
                                shares=shares, hold=hold)
    for line in lines:
        print(line)
    return quality


def _skating(motion, inputs: list, what: str, feet: str | None = None) -> tuple[dict | None, list]:
    """Foot skating of the result and of each input cycle (``skating_report`` dicts, None
    where not measurable), and one console line for them; ``feet`` is ``--feet``'s text
    (None: found on each)."""
    from ..quality.contacts import skating_report, skating_line

    result = skating_report(motion, feet=feet)
    per_input = [skating_report(c, feet=feet) for c in inputs]
    line = skating_line(result, what)
    if any(r is not None for r in per_input):
        # the inputs' shares beside their counts: a 430-frame transition's 162 frames
        # read as worse than its inputs' 30 and 9 where they are 38 % against 23 and 21 %
        line += (
            " (inputs: "
            + ", ".join("-" if r is None else
                        f"{r['skating_frames']} ({100 * r['skating_fraction']:.0f}%)"
                        for r in per_input)
            + " frames; speed-gated contacts, beside the support-foot slip above)"
        )
    print(line)
    return result, per_input


def cmd_transition(args: argparse.Namespace) -> int:
    from ..quality.plausibility import check_plausibility
    from ..synthesis.blend import transition
    from ..synthesis.sources import cycle_summary

    _check_outputs(args)
    try:
        sources = _load_cycles(args)
    except NoPeriodicMotionError as exc:
        print(f"cyclecoord: {exc}", file=sys.stderr)
        return EXIT_NO_PERIODIC
    a, b = (s.cycle for s in sources)
    clip = transition(
        sources[0],
        sources[1],
        frames=args.frames,
        cycles=args.cycles,
        lead_in=args.lead_in,
        lead_out=args.lead_out,
        allow_reverse=args.allow_reverse,
        align_heading=not args.no_heading,
        up=args.up,
    )
    w = clip.metadata["transition"]["weight"]
    quality = _lead(clip, [a, b], args.feet, shares=[sum(1 - v for v in w), sum(w)])
    info = clip.metadata["transition"]
    al = info["alignment"]
    cont = info["continuity"]
    print(
        f"aligned {args.inputs[1]} to {args.inputs[0]}: shift {al['shift_frames']:.2f} frames"
        + (", reversed" if al["reversed"] else "")
    )
    summaries = [cycle_summary(c) for c in (a, b)]
    for name, sm in zip(args.inputs, summaries):
        print(f"{name}: {figures_line(sm)}")
    print(
        f"transition: {clip.n_frames} frames ({info['lead_in_frames']} of A, ramp "
        f"{info['ramp_frames']} frames = {info['ramp_cycles']:.2f} cycles, "
        f"{info['lead_out_frames']} of B); largest step {cont['max_ratio']:.2f}x the typical step "
        f"at its phase (limit {cont['limit']:g})"
    )
    for note in info["notes"]:
        print(f"note: {note}")
    skating, inputs_skating = _skating(clip, [a, b], "transition", args.feet)
    report = check_plausibility(clip, [a, b], margin_deg=args.margin)
    meta = {k: v for k, v in info.items() if k not in ("weight", "phase")}
    payload = {
        "inputs": [
            dict(src.to_dict(), path=p, summary=sm, foot_skating=sk)
            for src, p, sm, sk in zip(sources, args.inputs, summaries, inputs_skating)
        ],
        "output": {"path": args.output, "frames": clip.n_frames, "fps": clip.fps},
        "foot_skating": skating,
        "transition": meta,
        "weight": info["weight"],
        "phase": info["phase"],
    }
    problem = None
    if cont["max_ratio"] > cont["limit"]:
        problem = f"has a step {cont['max_ratio']:.2f}x the typical step (limit {cont['limit']:g})"
    return finish(args, clip, payload, report, "transition", problem, quality=quality)
