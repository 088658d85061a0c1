"""``cyclecoord latent fit``: train a latent (GPLVM) model on takes or labelled segments."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ._options import add_memory_option, positive_float
from ._outputs import Outputs, declare

__all__ = ["add_parser", "parse_take", "run"]

#: latent fit trains at about this rate by default (--step).
TRAINING_FPS = 30.0


def parse_take(text: str) -> tuple[str, int | None, int | None, str | None]:
    """``PATH[:A:B][=NAME]`` -> (path, start, stop, name); A, B 0-based half-open frames."""
    from ..errors import ParameterError

    name = None
    if "=" in text:
        text, name = text.rsplit("=", 1)
    parts = text.split(":")
    if len(parts) == 1:
        return parts[0], None, None, name
    if len(parts) != 3:
        raise ParameterError(
            f"take {text!r}: expected PATH or PATH:A:B (0-based, half-open frames)"
        )
    try:
        a = int(parts[1]) if parts[1] else None
        b = int(parts[2]) if parts[2] else None
    except ValueError:
        raise ParameterError(f"take {text!r}: frames A:B must be whole numbers") from None
    return parts[0], a, b, name


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "latent",
        help="train latent-space (GPLVM) motion models",
        description="Latent-space models (Bailey et al.): influence scaling, PCA, GPLVM.",
    )
    sub = p.add_subparsers(dest="latent_command", metavar="ACTION")
    f = sub.add_parser(
        "fit",
        help="train one model on takes or labelled segments",
        description=(
            "Train one GPLVM model on one or several training segments, each TAKE[:A:B][=NAME] "
            "(an .amc/.bvh/.npz capture, optionally frames A..B-1, optionally named), e.g. "
            "13_29.amc:0:456=JumpJack. All segments need the same channels."
        ),
    )
    f.add_argument(
        "takes", nargs="+", metavar="TAKE[:A:B][=NAME]",
        help="training segments: a capture, optionally frames A..B-1 of it, optionally named "
        "(e.g. 13_29.amc:0:456=JumpJack; the name is what scripts call the segment)",
    )
    f.add_argument(
        "-o", "--output", required=True, metavar="MODEL.npz",
        help="the model file to write (.npz: the model with its training frames and skeleton, "
        "read by 'cyclecoord animate' scripts)",
    )
    f.add_argument("--dims", type=int, default=3, help="latent dimensions (default 3)")
    f.add_argument(
        "--variance",
        type=float,
        default=0.85,
        help="variance the PCA keeps, in (0, 1] (default 0.85)",
    )
    f.add_argument(
        "--step",
        type=int,
        default=None,
        help="keep every STEP-th frame (default: the step that brings each take nearest "
        "30 fps: 4 for CMU's 120 fps, 1 for a 30 fps BVH)",
    )
    f.add_argument(
        "--fps",
        type=positive_float,
        action="append",
        metavar="F",
        help="frame rate of the takes (AMC files carry none; default 120): once for every "
        "take or once per take in order (subject 143's 143_01 jog is 60 fps)",
    )
    f.add_argument("--max-iter", type=int, default=200, help="optimiser iterations (default 200)")
    f.add_argument("--report", metavar="R.json", help="also write the model's summary as JSON")
    f.add_argument("--no-progress", action="store_true",
                   help="no progress bar over the GPLVM's optimisation")
    add_memory_option(f)
    f.set_defaults(func=run)
    declare(f, inputs=_take_files, files=("-o", "--report"))
    p.set_defaults(func=lambda args: _usage(p))
    declare(p, inputs=lambda args: ())


def _take_files(args: argparse.Namespace) -> list[Path]:
    """Every file ``latent fit`` reads: each take and, for an AMC, its ``.asf``."""
    from ..errors import ParameterError
    from ..io import input_files

    files: list[Path] = []
    for text in args.takes:
        try:
            path = parse_take(text)[0]
        except ParameterError:
            continue  # run() reports it
        files += input_files(path)
    return files


def _usage(parser) -> int:
    parser.print_help()
    return 2


def run(args: argparse.Namespace) -> int:
    import time

    from .. import load
    from ..errors import ParameterError
    from ..io import atomic_write
    from .._words import plural
    from ..synthesis.latent.model import LatentModel, root_position_problem

    if args.dims < 1:
        raise ParameterError(f"--dims must be >= 1, got {args.dims}")
    if not 0 < args.variance <= 1:
        raise ParameterError(f"--variance must be in (0, 1], got {args.variance}")
    if (args.step is not None and args.step < 1) or args.max_iter < 1:
        raise ParameterError("--step and --max-iter must be >= 1")
    out = Path(args.output)
    for target in [out] + ([Path(args.report)] if args.report else []):
        folder = target.parent if str(target.parent) else Path(".")
        if not folder.is_dir():
            raise ParameterError(f"{target}: folder {folder} does not exist")
    from ..rig import analysis_motion, describe_rig, normalize_rig

    from .blend import _per_input

    segments, names = [], []
    rig_lines: list[str] = []
    rates = _per_input(getattr(args, "fps", None), len(args.takes), "--fps")
    for i, (text, rate) in enumerate(zip(args.takes, rates)):
        path, a, b, name = parse_take(text)
        motion = load(path, fps=rate).window((a, b))
        if i == 0 and motion.skeleton is not None:
            info = describe_rig(motion)
            changes = normalize_rig(motion, info, drop_reference=False)[1].changes()
            rig_lines.append(
                f"rig: {info.summary()}"
                + (f" (modelled with {'; '.join(changes)}; what the model makes uses that rig)"
                   if changes else "")
            )
        problem = (
            root_position_problem(analysis_motion(motion)) if motion.skeleton is not None else None
        )
        if problem:
            raise ParameterError(f"{path}: {problem}")
        step = args.step or max(1, int(round(motion.fps / TRAINING_FPS)))
        seg = motion[::step]
        if seg.n_frames < 3:
            raise ParameterError(
                f"take {text!r} has only {seg.n_frames} frames after --step {step}"
            )
        segments.append(seg)
        label = name or Path(path).stem + (
            f"[{a or 0}:{b if b is not None else motion.n_frames + (a or 0)}]"
            if a is not None or b is not None
            else ""
        )
        names.append(label)
    if len(set(names)) != len(names):
        raise ParameterError(f"segment names repeat: {names}; name them with =NAME")
    t0 = time.process_time()
    w0 = time.perf_counter()
    model = LatentModel(
        n_components=args.dims, variance=args.variance, gplvm={"max_iter": args.max_iter}
    ).fit(segments, names, progress=not args.no_progress)
    summary = model.describe() | {
        "fit_cpu_s": time.process_time() - t0,
        "fit_wall_s": time.perf_counter() - w0,
        "iterations": model.gp_.n_iter_,
    }
    with Outputs() as staged:  # the model and the report move into place together
        model.save(staged.file(out))
        if args.report:
            with atomic_write(staged.file(args.report)) as fh:
                json.dump(summary, fh, indent=2)
    charted = summary["joints_about_their_mean_rotation"]
    if charted:
        rig_lines.append(
            "modelled about their mean rotation (Euler channels that wrap or come near "
            f"gimbal lock in the takes): {', '.join(charted)}"
        )
    for line in rig_lines:
        print(line)
    for g in summary["gait"] or []:  # which frames the gait (MOVE ahead, in step) uses
        print(
            f"gait: {g['segment']}: "
            + (f"{g['cycle_s']:.2f} s cycle, phase over {g['phase_from_s']:.1f}-"
               f"{g['phase_to_s']:.1f} s of {g['seconds']:.1f} s"
               if g["cycle_s"] is not None else "none (no steady periodic motion found)")
        )
    print(
        f"{out}: {summary['frames']} frames in {plural(len(names), 'segment')}, "
        f"{plural(summary['pca_components'], 'PCA component')} "
        f"({summary['explained_variance']:.0%}), {args.dims}-D latent, fitted in "
        f"{summary['fit_wall_s']:.1f} s ({summary['fit_cpu_s']:.1f} s CPU)"
    )
    return 0
