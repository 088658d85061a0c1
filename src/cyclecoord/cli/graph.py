"""``cyclecoord graph``: motion-graph synthesis (Gauch & Peters) and its cross-validation.

``cyclecoord graph TRAIN... --start FILE[:FRAME] --frames N -o OUT.bvh`` follows the
vector field of a Delaunay (or k-NN, or union) motion graph from a start pose;
``cyclecoord graph crossval TAKE...`` prints the paper's Table II for the takes.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import ParameterError
from ..io import input_files
from ._options import EXIT_OK, add_memory_option, check_output, positive_float, positive_int
from ._outputs import Outputs, crossing_refusal, declare
from .report import clean, load_input, write_json

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "graph",
        help="generate motion along a motion graph's vector field ('graph crossval': the table)",
        description=(
            "Motion graph and vector-field synthesis (Gauch & Peters): PCA of the joint angles "
            "of the training takes, a Delaunay / k-NN / union graph over their frames and the "
            "interpolated field of their velocities. 'cyclecoord graph TRAIN...' generates a "
            "motion from a start pose; 'cyclecoord graph crossval TAKE...' leaves each take out "
            "in turn and prints a Table II-style table."
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=(
            "examples:\n"
            "  cyclecoord graph 35_16.amc 35_07.amc 35_08.amc 35_13.amc \\\n"
            "      --start 35_16.amc:0 --frames 450 \\\n"
            "      -o walk.bvh --report walk.json --plot figures\n"
            "  cyclecoord graph crossval 35_16.amc 35_07.amc 35_08.amc 35_13.amc \\\n"
            "      --report table.json\n"
            "  cyclecoord graph crossval 35_*.amc --method delaunay --dims 3"
        ),
    )
    p.add_argument(
        "inputs",
        nargs="+",
        metavar="TRAIN",
        help="training takes of one rig (other actors are put on the first take's skeleton, "
        "a line says so); 'crossval' first for the table",
    )
    p.add_argument(
        "--method",
        default=None,
        help="delaunay, knn or union, the Delaunay ones optionally with +ring (the simplices "
        "adjacent to the containing one) and +agree (neighbours weighted by agreement with the "
        "path's heading), e.g. delaunay+ring+agree; any of them with +phase: the phase-aware "
        "field that follows the gait's circular coordinate and never stalls (generation "
        "default delaunay+phase; 'delaunay' is the paper's field); crossval takes a comma list "
        "(default delaunay,delaunay+ring+agree,knn,union,delaunay+phase)",
    )
    p.add_argument(
        "--dims",
        type=_dims,
        default=None,
        help="latent PCA dimensions, or 'auto': the fewest explaining 85 %% of the joint-angle "
        "variance (generation default auto, so strides keep their amplitude; crossval default "
        "2, as the paper)",
    )
    p.add_argument(
        "-k",
        "--k",
        type=positive_int,
        default=16,
        help="neighbours of the k-NN graph and field (default 16)",
    )
    p.add_argument(
        "--integrator",
        choices=("euler", "rk4"),
        default="euler",
        help="field step: the paper's Euler step or fourth-order Runge-Kutta (default euler)",
    )
    p.add_argument(
        "--step-scale",
        type=positive_float,
        default=None,
        help="step length in training vectors (half a frame's change): 1 is the paper's step "
        "(about half speed; crossval default), 2 the captured speed (generation default)",
    )
    p.add_argument(
        "--start",
        default=None,
        metavar="FILE[:FRAME]",
        help="start pose: a take and 0-based frame (default the first training take, frame 0)",
    )
    p.add_argument(
        "--target",
        default=None,
        metavar="FILE[:FRAME]",
        help="instead of following the field, the shortest graph path to this pose",
    )
    p.add_argument(
        "--frames", type=positive_int, default=450, help="frames to generate (default 450)"
    )
    p.add_argument("-o", "--output", default=None, help="generated motion (.bvh, .amc, ...)")
    p.add_argument("--report", default=None, help="JSON report")
    p.add_argument("--plot", default=None, metavar="DIR", help="write figures (PNG) into DIR")
    p.add_argument(
        "--strict",
        action="store_true",
        help="write nothing when the motion fails the plausibility checks",
    )
    p.add_argument(
        "--fps",
        type=positive_float,
        action="append",
        metavar="F",
        help="frame rate of the inputs (AMC files carry none; default 120): once for every "
        "input or once per input in order. Takes at a whole multiple of the slowest take's "
        "rate are taken every k-th frame (a line says so); other mixed rates are refused",
    )
    p.add_argument("--no-topo", action="store_true", help="crossval: skip the bottleneck distances")
    p.add_argument(
        "--no-progress", action="store_true",
        help="no progress bars (loading the takes, crossval's folds)",
    )
    p.add_argument(
        "--horizon",
        type=int,
        default=3,
        help="crossval: also follow the field for this many times each left-out take, with "
        "freeze and slip columns (default 3; 0 skips it)",
    )
    _feet_options(p)
    add_memory_option(p)
    p.set_defaults(func=run)
    declare(p, inputs=_files_read, files=("-o", "--report"), folders={"--plot": r".*\.png"})
    return p


def _feet_options(p: argparse.ArgumentParser) -> None:
    """Generation's options for the feet and the limbs."""
    p.add_argument(
        "--no-carry",
        action="store_true",
        help="generation: keep the training frames' mean root step (the feet glide) instead of "
        "moving the root as the feet on the ground carry it, and do not pin the feet",
    )
    p.add_argument(
        "--no-lock",
        action="store_true",
        help="generation: do not pin the planted feet by leg IK (on by default where it adds "
        "no pop)",
    )
    p.add_argument(
        "--allow-contacts",
        action="store_true",
        help="write the motion even when its limbs pass through each other (bone contacts the "
        "training takes never make); by default such a motion is refused and only the report "
        "is written",
    )


def _dims(text: str):
    """``--dims``: a whole number >= 1 or ``auto``."""
    return "auto" if text == "auto" else positive_int(text)


def _files_read(args: argparse.Namespace) -> list[Path]:
    """Every file graph reads: the takes (an AMC's ``.asf`` with it), --start and --target."""
    names = list(args.inputs) + [_take_spec(t)[0] for t in (args.start, args.target) if t]
    return [f for name in names for f in input_files(name)]


def _take_spec(text: str) -> tuple[str, int]:
    """``FILE`` or ``FILE:FRAME`` (a trailing ``:N`` is a frame when N is a whole number)."""
    if ":" in text:
        head, tail = text.rsplit(":", 1)
        if tail.lstrip("-").isdigit() and head:
            return head, int(tail)
    return text, 0


def _find(path: str, inputs: list[str], motions: list, fps: float | None = None):
    """The motion ``--start``/``--target`` names: a training take when it names one, else
    the file loaded.

    Paths are matched as files: the same file named two ways (``35_16.amc``,
    ``./data/35_16.amc``, an absolute path or a link) is the same take; a name that is
    not a file here but is the name (or the trailing path) of one training take is that
    take, and of two is an error naming both.  ``fps``: the rate of a file loaded (an
    AMC carries none).
    """
    given = Path(path)
    if given.is_file():
        for name, m in zip(inputs, motions):
            if Path(name).is_file() and _same_file(Path(name), given):
                return m
        return load_input(path, None, fps)
    parts = given.parts
    matches = [
        (name, m)
        for name, m in zip(inputs, motions)
        if parts and Path(name).parts[-len(parts):] == parts
    ]
    if len(matches) > 1:
        raise ParameterError(
            f"{path}: names more than one training take ({', '.join(n for n, _ in matches)}); "
            "give the path of the one you mean"
        )
    if matches:
        return matches[0][1]
    return load_input(path, None, fps)


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.samefile(b)
    except OSError:
        return a.resolve() == b.resolve()


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    crossval = args.inputs[0] == "crossval" and not Path("crossval").exists()
    inputs = args.inputs[1:] if crossval else list(args.inputs)
    check_output(args.report, "report")
    if not crossval:
        check_output(args.output)
    if args.plot and Path(args.plot).exists() and not Path(args.plot).is_dir():
        raise ParameterError(f"{args.plot}: exists and is not a folder")
    from .blend import _per_input

    rates = _per_input(args.fps, len(inputs), "--fps")
    motions = [
        load_input(p, None, f)
        for p, f in tqdm(list(zip(inputs, rates)), desc="loading", unit="take",
                         disable=len(inputs) < 4 or args.no_progress)
    ]
    with Outputs() as out:  # every output moves into place at the end, or none does
        if crossval:
            return _crossval(args, motions, out)
        return _generate(args, inputs, motions, out)


def _crossval(args: argparse.Namespace, motions: list, out: Outputs) -> int:
    from ..synthesis.graph import DEFAULT_METHODS, cross_validate

    methods = [m.strip() for m in (args.method or ",".join(DEFAULT_METHODS)).split(",")]
    methods = [m for m in methods if m]
    cv = cross_validate(
        motions,
        methods=methods,
        dims=2 if args.dims is None else args.dims,
        k=args.k,
        integrator=args.integrator,
        step_scale=args.step_scale or 1.0,
        topo=not args.no_topo,
        progress=not args.no_progress,
        horizon=args.horizon,
    )
    for note in cv.notes:
        print(note)
    print(cv.table())
    outside = sum(f["outside_hull_steps"] for f in cv.folds)
    print(
        "errors A/F: latent (/ longest side of the training box), deg (RMS over joint angles), "
        "pos (RMS joint distance, skeleton units); topo: bottleneck of H1 barcodes; "
        f"{outside} steps outside the hull"
    )
    if cv.long:
        print()
        print(cv.long_table())
        print(
            f"longer horizon: the field followed for {args.horizon}x each left-out take; "
            "freeze: longest stretch (s) under 10 % of the training takes' median pose speed "
            "(folds fz: folds with one over 0.2 s); slip: support-foot speed (m/s; x the "
            "training takes'), root carried by the feet, no foot locking"
        )
    if args.report:
        write_json(out.file(args.report), clean(cv.to_report()))
        out.wrote(args.report)
    if args.plot:
        from ..plot.graph import save_crossval_figures

        for p in save_crossval_figures(cv, motions, out.folder(args.plot)):
            out.wrote(Path(args.plot) / p.name)
    return EXIT_OK


def _drew_on(synth, gen, inputs: list[str]) -> tuple[str, dict[str, float]]:
    """The console line saying how much the path drew on each take (none for one take),
    naming the takes it left alone that are another gait, and the report's shares by take.
    Two actors' walks lie apart in the pose space and the path stays with the one it
    starts in: "over 829 frames of 2 takes" alone read as if it mixed them."""
    shares = synth.take_shares(gen.path)
    by_take = {name: round(float(x), 4) for name, x in zip(synth.names_, shares)}
    if len(shares) < 2:
        return "", by_take
    line = "the path drew on " + ", ".join(
        f"{name} {100 * x:.0f} %" for name, x in zip(synth.names_, shares) if x >= 0.005)
    gaits = getattr(synth, "gaits_", None) or [list(range(len(shares)))]
    used = {g for g, members in enumerate(gaits) if shares[members].sum() >= 0.005}
    apart = [i for g, members in enumerate(gaits) if g not in used for i in members]
    if apart:
        names = ", ".join(synth.names_[i] for i in apart)
        first = Path(inputs[apart[0]]).name
        line += (f"; not on {names}: {'its' if len(apart) == 1 else 'their'} poses lie apart "
                 f"from the path's gait (another gait or actor); --target {first}:FRAME "
                 "crosses to it in step")
    return line, by_take


def _generate(args: argparse.Namespace, inputs: list[str], motions: list, out: Outputs) -> int:
    from ..quality.plausibility import check_plausibility
    from ..synthesis.graph import MotionGraphSynth
    from .blend import finish

    method = args.method or "delaunay+phase"
    if "," in method:
        raise ParameterError(
            f"--method {method}: generation uses one method (a list is for 'graph crossval')"
        )
    synth = MotionGraphSynth(
        method=method,
        dims=args.dims or "auto",
        k=args.k,
        integrator=args.integrator,
        step_scale=args.step_scale or 2.0,
        carry=not args.no_carry,
        lock=not (args.no_lock or args.no_carry),
    ).fit(motions)
    path, frame = _take_spec(args.start) if args.start else (inputs[0], 0)
    one_rate = args.fps[0] if args.fps and len(args.fps) == 1 else None
    start = _find(path, inputs, motions, one_rate)
    if args.target:
        tpath, tframe = _take_spec(args.target)
        gen = synth.to_target(
            start, frame, _find(tpath, inputs, motions, one_rate), tframe,
            speed=(args.step_scale or 2.0) / 2,
        )
    else:
        gen = synth.generate(args.frames, start, frame)
    from .blend import _lead

    quality = _lead(gen.motion, motions, reference=synth.reference(gen), hold=gen.hold)
    conn = synth.graph_.connectivity()
    field = ("phase-aware" if synth.phase_field_ is not None else synth.field_.name)
    print(
        f"{synth.graph_.method} graph ({field} field) over {conn['nodes']} frames of "
        f"{len(motions)} takes: "
        f"{conn['edges']} edges, "
        f"{conn['weak_components']} weak / {conn['strong_components']} strong components; "
        f"start/end graph H {'connected' if conn['H']['connected'] else 'NOT connected'}"
    )
    if conn["cannot_reach"]:
        print(
            "  takes that cannot reach each other: "
            + ", ".join(f"{synth.names_[i]} -> {synth.names_[j]}" for i, j in conn["cannot_reach"])
        )
    ev = synth.space_.explained_variance_ratio_
    print(
        f"latent space: {synth.dims_} PCA dims explain {100 * ev.sum():.1f} % "
        "of the joint-angle variance"
    )
    print(
        f"generated {gen.motion.n_frames} frames from {gen.start['take']}:{gen.start['frame']} "
        f"({gen.path.kind}; {gen.path.outside_hull_steps} steps outside the hull)"
    )
    for note in synth.proportion_notes_ + synth.phase_notes_ + gen.notes:
        print(note)
    drew, shares = _drew_on(synth, gen, inputs)
    if drew:
        print(drew)
    payload = {
        "method": method,
        "dims": synth.dims_,
        "k": args.k,
        "integrator": args.integrator,
        "step_scale": synth.step_scale,
        "takes": synth.names_,
        "start": gen.start,
        "frames": gen.motion.n_frames,
        "outside_hull_steps": gen.path.outside_hull_steps,
        "explained_variance_ratio": ev.tolist(),
        "graph": {
            key: conn[key] for key in ("nodes", "edges", "weak_components", "strong_components")
        },
        "connectivity": conn,
        "take_shares": shares,
        "notes": synth.proportion_notes_ + gen.notes + ([drew] if drew else []),
        "root": "turns, heights and tilts: weighted mean over the training frames weighing on "
        "each generated point (the field's neighbourhood), integrated from the start frame's "
        "root; ground travel "
        + (
            "as the lowest foot points carry the body (quality.generated's support foot), "
            "raised where a foot would go under the training takes' floor"
            if synth.carry and synth.floor_ is not None
            else "the weighted mean of the training frames' root steps"
        ),
    }
    if args.plot:
        from ..plot.graph import save_graph_figures

        for p in save_graph_figures(synth, gen, out.folder(args.plot)):
            out.wrote(Path(args.plot) / p.name)
    report = check_plausibility(gen.motion, motions)
    crossing = [int(f) for f in getattr(report, "new_contact_frames", None) or []]
    if crossing and not args.allow_contacts:
        return _refuse_crossing(args, gen.motion, payload, report, crossing, out, quality)
    return finish(args, gen.motion, payload, report, "generated motion", out=out, quality=quality)


def _refuse_crossing(args, motion, payload, report, frames, out, quality) -> int:
    """Write the report, not a motion whose limbs pass through each other."""
    from ..errors import ImplausibleMotionError
    from .blend import finish

    why = crossing_refusal(
        "generated motion", frames, "another --start or --method may avoid it"
    )
    payload = {**payload, "refused": why}
    try:
        finish(argparse.Namespace(**{**vars(args), "strict": True}), motion, payload, report,
               "generated motion", out=out, quality=quality)
    except ImplausibleMotionError:
        raise ImplausibleMotionError(why) from None
    raise ImplausibleMotionError(why)  # pragma: no cover (finish refuses an unclean report)
