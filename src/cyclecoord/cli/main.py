"""The ``cyclecoord`` command line: subcommands over the library, JSON reports, exit codes.

Exit codes: 0 success, 1 bad input or failure (one-line message, no traceback),
2 usage error, 3 no periodic motion found (the report is still written), 130 interrupted
by Ctrl-C (atomic writes leave no partial file).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Sequence

import numpy as np

from ..errors import CycleCoordError, NoPeriodicMotionError, ParameterError
from ..io._paths import input_files, refuse_clobber

__all__ = ["main", "build_parser"]

EXIT_OK, EXIT_ERROR, EXIT_USAGE, EXIT_NO_PERIODIC = 0, 1, 2, 3

EXAMPLES = ("walk", "jog", "jumping_jack", "arm_circles", "squat", "chain", "take")


# ----------------------------------------------------------------- helpers
def _frame_range(text: str) -> tuple[int | None, int | None]:
    """Parse ``A:B`` (0-based, half-open; either side may be empty)."""
    if ":" not in text:
        raise argparse.ArgumentTypeError(f"expected A:B (0-based, half-open), got {text!r}")
    a, b = text.split(":", 1)
    try:
        start = int(a) if a.strip() else None
        stop = int(b) if b.strip() else None
    except ValueError:
        raise argparse.ArgumentTypeError(f"frame range must be integers A:B, got {text!r}") from None
    if start is not None and start < 0 or stop is not None and stop < 0:
        raise argparse.ArgumentTypeError(f"frame numbers must be >= 0, got {text!r}")
    if start is not None and stop is not None and start >= stop:
        raise argparse.ArgumentTypeError(
            f"frame range {text!r} is reversed or empty: A:B means frames A to B-1, so A must be "
            f"below B (e.g. {min(start, stop)}:{max(start, stop) + (start == stop)})"
        )
    return start, stop


def _positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"expected a number >= 1, got {v}")
    return v


def _bandwidth(text: str) -> str | float:
    if text == "auto":
        return text
    try:
        return _positive_float(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"expected 'auto' or a positive number of frames, got {text!r}") from None


def _positive_float(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not np.isfinite(v) or v <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return v


def load_input(path: str, skeleton: str | None = None, fps: float | None = None):
    """Load a capture, or a built-in example when ``path`` is ``example[:kind]``."""
    from .. import datasets
    from ..io import load

    if (path == "example" or path.startswith("example:")) and not Path(path).exists():
        kind = path.split(":", 1)[1] if ":" in path else "walk"
        if kind not in EXAMPLES:
            raise ParameterError(f"unknown built-in example {kind!r}; choose from {', '.join(EXAMPLES)}")
        if kind == "walk":
            cap = datasets.example_capture()
        elif kind == "chain":
            cap = datasets.make_motion_chain(random_state=0)
        elif kind == "take":
            cap = datasets.make_whole_take(random_state=0)
        else:
            cap = datasets.make_periodic_capture(kind=kind, n_frames=480, random_state=0)
        m = cap.motion
        if fps is not None:
            from dataclasses import replace

            m = replace(m, fps=fps)
        return m
    return load(path, skeleton=skeleton, fps=fps)


def _check_output(path: str | None, what: str = "output") -> None:
    """Fail fast, before any computation, on an output we could not write."""
    if not path:
        return
    from ..io import SUPPORTED_FORMATS

    out = Path(path)
    if what == "output" and out.suffix.lower() not in SUPPORTED_FORMATS:
        raise ParameterError(
            f"{path}: unknown output format {out.suffix or '(no suffix)'!r}; use one of {', '.join(SUPPORTED_FORMATS)}"
        )
    if what == "report" and out.suffix.lower() != ".json":
        raise ParameterError(f"{path}: the report is JSON; give it a .json name")
    if what == "model" and out.suffix.lower() != ".npz":
        raise ParameterError(f"{path}: a model is saved as .npz; give it a .npz name")
    folder = out.parent if str(out.parent) else Path(".")
    if not folder.is_dir():
        raise ParameterError(f"{path}: folder {folder} does not exist")


def _named(path: object, exc: BaseException) -> str:
    """The error's message, led by the input's name when it does not name it already."""
    text = str(exc)
    if isinstance(path, str) and path and path not in text and Path(path).name not in text:
        return f"{path}: {text}"
    return text


def _write_json(path: str, payload: dict) -> None:
    from ..io._atomic import atomic_write

    with atomic_write(path, "w") as fh:
        json.dump(payload, fh, indent=1, allow_nan=False, default=_json_default)
        fh.write("\n")


def _json_default(o):
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, (np.floating,)):
        v = float(o)
        return v if np.isfinite(v) else None
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def _clean(obj):
    """Replace non-finite floats by None so the JSON is strict."""
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, (float, np.floating)):
        return float(obj) if np.isfinite(obj) else None
    return obj


def _delay(text: str) -> str | float | None:
    if text == "auto":
        return "auto"
    v = _nonnegative_float(text)
    return v or None


def _nonnegative_float(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds or 'auto', got {text!r}") from None
    if not np.isfinite(v) or v < 0:
        raise argparse.ArgumentTypeError(f"expected a number of seconds >= 0 or 'auto', got {text!r}")
    return v


def _landmarks(text: str) -> int | str | None:
    t = text.strip().lower()
    if t in ("auto",):
        return "auto"
    if t in ("none", "all", "full"):
        return None
    try:
        v = int(t)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, 'auto' or 'none', got {text!r}") from None
    if v < 10:
        raise argparse.ArgumentTypeError(f"need at least 10 landmarks, got {v}")
    return v


def _bytes(text: str) -> float:
    """Parse sizes such as 2G, 500M, 1.5GB or a plain number of bytes."""
    t = text.strip().upper().rstrip("B")
    mult = {"K": 1024, "M": 1024**2, "G": 1024**3, "T": 1024**4}
    try:
        if t and t[-1] in mult:
            v = float(t[:-1]) * mult[t[-1]]
        else:
            v = float(t)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a size such as 2G or 500M, got {text!r}") from None
    if not np.isfinite(v) or v <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive size, got {text!r}")
    return v


def _add_selection_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("what to analyse and how")
    g.add_argument("--skeleton", metavar="ASF", help="ASF skeleton for an AMC input (default: found beside the AMC)")
    g.add_argument("--frames", type=_frame_range, metavar="A:B", help="0-based half-open frame range, e.g. 200:450")
    g.add_argument("--fps", type=_positive_float, metavar="F", help="frame rate (AMC files carry none; default 120)")
    g.add_argument("--pca", type=_positive_int, metavar="K", help="project poses onto K principal components first")
    g.add_argument("--normalize", action="store_true", help="scale each channel by its standard deviation")
    g.add_argument("--temporal", action="store_true", help="time-aware metric: consecutive frames at distance 0")
    g.add_argument("--no-root-diff", action="store_true", help="keep root translation/orientation as they are")
    g.add_argument("--prime", type=int, default=47, metavar="P", help="coefficient field Z/P, a prime > 11 (default 47)")
    g.add_argument(
        "--max-scale", type=_positive_float, metavar="E",
        help="Rips threshold in the analysed space's units (default: half the point cloud's diameter)",
    )
    g.add_argument(
        "--landmarks", type=_landmarks, default="auto", metavar="N|auto|none",
        help="build the filtration on N greedy landmarks and extend the coordinate to every frame "
        "(auto: every frame up to 1000 frames, 500 landmarks beyond; none: every frame)",
    )
    g.add_argument(
        "--memory-limit", type=_bytes, default=None, metavar="SIZE",
        help="memory for the run's large arrays, e.g. 500M: per-frame arrays and the filtration, whose "
        "landmarks are reduced to fit (default: 2G for the filtration alone; never more than the machine has)",
    )


def _add_cycle_options(g: argparse._ArgumentGroup) -> None:
    """Options of the typical cycle, the same on extract, detect --extract and batch."""
    g.add_argument("--no-steady", dest="steady", action="store_false",
                   help="build the cycle from every frame (default: only the steady stretches of the take, "
                   "leaving out standing, starting, turning and stopping)")
    g.add_argument("--timing", choices=("capture", "coordinate"), default="capture",
                   help="capture (default): the cycle moves at the capture's pace (phase re-timed between "
                   "the coordinate's crossings and aligned by time warping); coordinate: the paper's "
                   "density-sampled coordinate (--samples, --neighbors, --weighting, --sampling)")
    g.add_argument("--travel", choices=("keep", "straight", "in_place"), default="keep",
                   help="the cycle's root: travel and turn as captured on average (keep, default), walk "
                   "along a line (straight: the heading change per cycle removed) or stay in place")
    g.add_argument("--min-turns", type=_positive_float, default=1.5, metavar="N",
                   help="fewer turns of the coordinate over the steady frames is no periodic motion, exit 3 (1.5)")
    g.add_argument("--bandwidth", type=_bandwidth, default=None, metavar="auto|F",
                   help="width of the average that builds the cycle, in frames of time: a number fixes it "
                   "(default 1 with --timing capture), 'auto' picks it by leave-one-out cross-validation")
    g.add_argument("--cycle-start", choices=("slowest", "first"), default="slowest",
                   help="begin the cycle at its slowest pose (default, hides the loop seam) or at phase 0")


def _cycle_options(args: argparse.Namespace) -> dict:
    """The typical-cycle keyword arguments of :func:`extract` from parsed options."""
    return dict(steady=args.steady, timing=args.timing, travel=args.travel, min_turns=args.min_turns,
                bandwidth=args.bandwidth, cycle_start=args.cycle_start)


def _summary_barcode(bc, sel=None) -> str:
    pers = bc.persistence(1)
    lines = [f"barcode up to {bc.threshold:.4g} (Z/{bc.prime}): {len(bc.h0)} H0 bars, {len(bc.h1)} H1 bars"]
    for k, (b, d) in enumerate(bc.h1[:5]):
        mark = "  <- selected" if sel is not None and k == sel.index else ""
        ds = "inf" if not np.isfinite(d) else f"{d:.4g}"
        lines.append(f"  H1 #{k}: [{b:.4g}, {ds})  persistence {pers[k]:.4g}{mark}")
    if len(bc.h1) > 5:
        lines.append(f"  ... {len(bc.h1) - 5} shorter H1 bars (longest {pers[5]:.4g})")
    return "\n".join(lines)


# ---------------------------------------------------------------- commands
def cmd_extract(args: argparse.Namespace) -> int:
    from ..io import save
    from ..periodic.pipeline import extract

    _check_output(args.output)
    _check_output(args.report, "report")
    if args.save_model:
        _check_output(args.save_model, "model")
    if args.plot and Path(args.plot).exists() and not Path(args.plot).is_dir():
        raise ParameterError(f"{args.plot}: exists and is not a folder (--plot takes a folder)")
    refuse_clobber(
        input_files(args.input, args.skeleton) + input_files(args.apply),
        [("-o", args.output), ("--report", args.report), ("--save-model", args.save_model)],
        [("--plot", args.plot, r".*\.png")],
    )
    motion = load_input(args.input, args.skeleton, args.fps)
    if args.apply:
        return _apply_model(args, motion)
    report_payload = None
    code = EXIT_OK
    try:
        res = extract(
            motion,
            frames=args.frames,
            pca=args.pca,
            normalize=args.normalize,
            temporal=args.temporal,
            delay=args.delay,
            difference_root=not args.no_root_diff,
            prime=args.prime,
            max_scale=args.max_scale,
            scale=args.scale,
            class_index=args.class_index,
            n_samples=args.samples,
            n_neighbors=args.neighbors,
            weighting=args.weighting,
            sampling=args.sampling,
            landmarks=args.landmarks,
            memory_limit=args.memory_limit,
            random_state=args.seed,
            **_cycle_options(args),
        )
    except NoPeriodicMotionError as exc:
        partial = exc.result
        print(f"cyclecoord: {_named(args.input, exc)}", file=sys.stderr)
        if partial is not None:
            print(_summary_barcode(partial.barcode))
            report_payload = {
                "source": partial.motion.source,
                "frames": [partial.motion.start_frame, partial.motion.start_frame + partial.motion.n_frames],
                "n_frames": partial.motion.n_frames,
                "dims": int(partial.prepared.points.shape[1]),
                "threshold": partial.barcode.threshold,
                "prime": partial.barcode.prime,
                "barcode": partial.barcode.to_dict(),
                "selected": None,
                "error": str(exc),
                "timings": partial.timings,
                "warnings": partial.warnings,
            }
            if args.plot:
                _save_plots(partial, args.plot)
        code = EXIT_NO_PERIODIC
    else:
        for line in describe_extraction(res, args.input, verbose=args.verbose):
            print(line)
        if args.output:
            save(res.cycle, args.output)
            print(f"wrote {args.output}")
        if args.save_model:
            res.model.save(args.save_model)
            print(f"wrote {args.save_model}")
        if args.plot:
            _save_plots(res, args.plot)
        report_payload = res.to_report()
        if args.verbose:
            print("time: " + ", ".join(f"{k} {v:.3f}s" for k, v in res.timings.items()))
    if args.report and report_payload is not None:
        _write_json(args.report, _clean(report_payload))
        print(f"wrote {args.report}")
    return code


def _frames_text(runs: list, offset: int) -> str:
    return ", ".join(f"{a + offset}-{b + offset}" for a, b in runs)


def describe_extraction(res, name: str, verbose: bool = False) -> list[str]:
    """What an animator needs first (period, cycles, where the loop was taken, quality in
    words); the barcode, cocycle and landmark details with ``verbose``."""
    m = res.motion
    fps = m.fps
    used = res.used_frames
    n_used = sum(b - a for a, b in used)
    lines = [f"{m.source or name}: {m.n_frames} frames at {fps:g} fps"
             + (f" (frames {m.start_frame}:{m.start_frame + m.n_frames})" if m.start_frame else "")]
    if n_used < m.n_frames:
        lines.append(
            f"steady motion in frames {_frames_text(used, m.start_frame)} ({n_used} of {m.n_frames} frames); "
            "the rest (standing, starting, turning or stopping) has no phase"
        )
    wind = res.windings
    spread = f", spread {wind.spread:.0%}" if wind is not None and wind.pooled.size > 1 else ""
    lines.append(
        f"period: {res.period_frames:.1f} frames ({res.period_frames / fps:.3f} s), "
        f"{res.cycles:.2f} cycles over the steady frames"
        + (f"; complete windings {', '.join(f'{v:.0f}' for v in res.cycle_frames[:8])} frames{spread}"
           if len(res.cycle_frames) else spread)
    )
    ratio = res.jerk["cycle"] / res.jerk["original"] if res.jerk.get("original", 0) > 0 else float("nan")
    seam = "seamless" if res.loop_closure <= 1.5 else "a visible seam"
    smooth = "as smooth as the capture or smoother" if ratio <= 1.0 else f"{ratio:.1f}x the capture's jerk"
    width = ""
    if res.parameters.get("bandwidth") is not None:
        chosen = " (cross-validated)" if res.typical.bandwidth_selection is not None else ""
        width = f"; kernel width {res.typical.bandwidth:.3g} frames{chosen}"
    lines.append(
        f"cycle: {res.cycle.n_frames} frames ({res.cycle.n_frames / fps:.3f} s), {seam} "
        f"(last-to-first step {res.loop_closure:.2f} median steps), {smooth} (jerk ratio {ratio:.2f}){width}"
    )
    if np.isfinite(res.heading_per_cycle):
        travel = res.parameters.get("travel", "keep")
        kept = {"keep": "kept; --travel straight removes it", "straight": "removed (--travel straight)",
                "in_place": "removed, and the cycle stays in place (--travel in_place)"}[travel]
        lines.append(f"heading: turns {res.heading_per_cycle:+.1f} degrees per cycle ({kept})")
    for w in res.warnings:
        lines.append(f"warning: {w}")
    if not verbose:
        return lines
    sel = res.selection
    lines.append(_summary_barcode(res.barcode, sel))
    ds = "inf" if not np.isfinite(sel.death) else f"{sel.death:.4g}"
    gap = "alone" if not np.isfinite(sel.gap) else f"{sel.gap:.1f}x the next bar"
    lines.append(f"class #{sel.index} [{sel.birth:.4g}, {ds}) read at scale {sel.scale:.4g}: "
                 f"death/birth {sel.ratio:.2f}, persistence {gap}")
    chk = res.estimator.cocycle_check_
    lines.append(f"cocycle check: {chk.n_violations} of {chk.n_triangles} triangles violate "
                 f"(prime {res.estimator.prime_})")
    lines.append(f"frames to cycle: median distance {res.distance['median']:.3g} "
                 f"(median frame step {res.distance['median_frame_step']:.3g}); "
                 f"kernel width {res.typical.bandwidth:.3g} frames")
    lm = res.estimator.landmarks_
    if lm is not None:
        fb = res.selection.full_birth
        lines.append(f"landmarks: {len(lm)} of {len(res.estimator.points_)} frames "
                     f"(covering radius {res.estimator.covering_radius_:.3g})"
                     + (f"; birth on every frame {fb:.4g}" if fb is not None else ""))
    return lines


def _apply_model(args: argparse.Namespace, motion) -> int:
    """``extract --apply MODEL``: phase of every frame from a saved model, no refit."""
    from ..periodic.phase_model import PhaseModel

    model = PhaseModel.load(args.apply)
    motion = motion.window(args.frames)
    info = model.summary(motion)
    print(
        f"{motion.source or args.input}: {motion.n_frames} frames phased with {args.apply}: "
        f"{info['cycles']:.2f} cycles, period {info['period_frames']:.1f} frames "
        f"(model's own period {model.period_frames:.1f})"
    )
    if args.report:
        payload = {
            "source": motion.source,
            "model": str(args.apply),
            "frames": [motion.start_frame, motion.start_frame + motion.n_frames],
            "n_frames": motion.n_frames,
            "coordinate": [float(v) for v in info["coordinate"]],
            "cycles": info["cycles"],
            "period_frames": info["period_frames"],
            "model_period_frames": model.period_frames,
        }
        _write_json(args.report, _clean(payload))
        print(f"wrote {args.report}")
    return EXIT_OK


def _save_plots(result, folder: str) -> None:
    """``extract --plot DIR``: the standard figures (only the barcode when nothing was found)."""
    from ..plot.figures import save_figures

    for path in save_figures(result, folder):
        print(f"wrote {path}")


def cmd_detect(args: argparse.Namespace) -> int:
    """``cyclecoord detect``: several periodic motions, their segments and per-frame labels."""
    from ..periodic.detection import detect, motion_cycles
    from ..io import save

    _check_output(args.report, "report")
    if args.extract and Path(args.extract).exists() and not Path(args.extract).is_dir():
        raise ParameterError(f"{args.extract}: exists and is not a folder (--extract takes a folder)")
    if args.plot and Path(args.plot).exists() and not Path(args.plot).is_dir():
        raise ParameterError(f"{args.plot}: exists and is not a folder (--plot takes a folder)")
    refuse_clobber(
        input_files(args.input, args.skeleton), [("--report", args.report)],
        [("--extract", args.extract, r"motion\d+_cycle\.bvh"), ("--plot", args.plot, r".*\.png")],
    )
    motion = load_input(args.input, args.skeleton, args.fps)
    code = EXIT_OK
    try:
        res = detect(
            motion, frames=args.frames, pca=args.pca, normalize=args.normalize, temporal=args.temporal,
            difference_root=not args.no_root_diff, prime=args.prime, max_scale=args.max_scale,
            landmarks=args.landmarks, memory_limit=args.memory_limit, n_classes=args.classes,
            delay=args.delay if args.delay > 0 else None, method=args.method, progress=not args.no_progress,
        )
    except NoPeriodicMotionError as exc:
        print(f"cyclecoord: {_named(args.input, exc)}", file=sys.stderr)
        res, code = exc.result, EXIT_NO_PERIODIC
    m = res.motion
    print(
        f"{m.source or args.input}: frames {m.start_frame}:{m.start_frame + m.n_frames} "
        f"({m.n_frames} frames, {m.fps:g} fps)"
    )
    print(_summary_barcode(res.barcode))
    kept = [c for c in res.classes if c.motion >= 0]
    print(f"method {res.method}: {len(res.classes)} candidate H1 classes, {len(kept)} excited", end="")
    if res.windows:
        print(f"; {len(res.windows)} windows, {sum(w.looping for w in res.windows)} looping", end="")
    print(f": {res.n_motions} motion(s)")
    for sg in res.segments:
        print(
            f"  motion {sg.motion}: frames {m.start_frame + sg.start}-{m.start_frame + sg.stop} "
            f"({sg.cycles:.1f} cycles, period {sg.period_frames:.1f} frames, classes {list(sg.classes)})"
        )
    for w in res.warnings:
        print(f"warning: {w}")
    if args.extract and code == EXIT_OK:
        folder = Path(args.extract)
        folder.mkdir(parents=True, exist_ok=True)
        for mc in motion_cycles(res, bandwidth=args.bandwidth, cycle_start=args.cycle_start,
                                timing=args.timing, travel=args.travel):
            out = folder / f"motion{mc.motion}_cycle.{args.extract_format}"
            save(mc.cycle, out)
            how = (f"phase from H1 {mc.phase_from}'s coordinate on {mc.n_frames_used} excited frames"
                   if mc.phase_from != "time" else f"phase from time over {mc.n_frames_used} frames")
            print(
                f"motion {mc.motion}: cycle of {mc.cycle.n_frames} frames from frames "
                f"{m.start_frame + mc.start}:{m.start_frame + mc.stop} ({how}), loop closure "
                f"{mc.loop_closure:.2f} -> {out}"
            )
    if args.plot:
        from ..plot.figures import plot_barcode, plot_coordinate, plot_windows

        folder = Path(args.plot)
        folder.mkdir(parents=True, exist_ok=True)
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        figs = {"barcode.png": plot_barcode(res.barcode)}
        if res.classes:
            coords = {f"class {c.index}": c.coordinate for c in res.classes if c.motion >= 0} or {
                f"class {c.index}": c.coordinate for c in res.classes[:4]
            }
            figs["coordinates.png"] = plot_coordinate(
                coords, start_frame=m.start_frame,
                segments=[(m.start_frame + s.start, m.start_frame + s.stop, f"motion {s.motion}") for s in res.segments],
            )
        if res.windows:
            figs["windows.png"] = plot_windows(res)
        from ..io._atomic import atomic_write

        for name, fig in figs.items():
            with atomic_write(folder / name, "wb") as fh:
                fig.savefig(fh, format="png", dpi=100)
            plt.close(fig)
            print(f"wrote {folder / name}")
    if args.report:
        _write_json(args.report, _clean(res.to_report()))
        print(f"wrote {args.report}")
    print("time: " + ", ".join(f"{k} {v:.3f}s" for k, v in res.timings.items()))
    return code


def cmd_render(args: argparse.Namespace) -> int:
    from ..plot.figures import render

    out = Path(args.output)
    if out.suffix.lower() not in (".gif", ".mp4"):
        raise ParameterError(f"{args.output}: render writes .gif or .mp4 animations, got {out.suffix or '(no suffix)'!r}")
    folder = out.parent if str(out.parent) else Path(".")
    if not folder.is_dir():
        raise ParameterError(f"{args.output}: folder {folder} does not exist")
    refuse_clobber(
        input_files(args.input, args.skeleton) + input_files(args.side_by_side),
        [("-o", args.output)],
    )
    motion = load_input(args.input, args.skeleton, args.fps)
    motion = motion.window(args.frames)
    other = load_input(args.side_by_side, None, None) if args.side_by_side else None
    path = render(motion, out, other=other, view=args.view, step=args.step, follow=args.follow)
    what = f"{motion.n_frames} frames" + (f" beside {other.n_frames} frames of {args.side_by_side}" if other else "")
    print(f"wrote {path} ({what}, {args.view} view)")
    return EXIT_OK


def cmd_barcode(args: argparse.Namespace) -> int:
    from ..periodic.preprocess import Preprocessor

    motion = load_input(args.input, args.skeleton, args.fps)
    motion = motion.window(args.frames)
    prep = Preprocessor(difference_root=not args.no_root_diff, normalize=args.normalize, pca=args.pca)
    pts = prep.fit_transform(motion).points
    from ..periodic.coordinates import CircularCoordinates

    est = CircularCoordinates(
        max_scale=args.max_scale, prime=args.prime, temporal=args.temporal, landmarks=args.landmarks,
        **({} if args.memory_limit is None else {"memory_limit": args.memory_limit}),
    )
    bc = est.fit_barcode(pts)
    if args.json:
        payload = {"threshold": bc.threshold, "prime": bc.prime, "n_points": bc.n_points,
                   "landmarks": est.landmark_reason_, **bc.to_dict()}
        print(json.dumps(_clean(payload)))
    else:
        print(_summary_barcode(bc))
    return EXIT_OK


def cmd_convert(args: argparse.Namespace) -> int:
    from ..io import save

    _check_output(args.output)
    refuse_clobber(input_files(args.input, args.skeleton), [("-o", args.output)])
    motion = load_input(args.input, args.skeleton, args.fps)
    motion = motion.window(args.frames)
    save(motion, args.output)
    print(f"{args.input} -> {args.output}: {motion.n_frames} frames, {motion.n_channels} channels, {motion.fps:g} fps")
    return EXIT_OK


def _auto_or_positive(text: str) -> float | None:
    """A positive number, or ``auto`` for the default (per-input options of blend/transition)."""
    if text.strip().lower() == "auto":
        return None
    return _positive_float(text)


def _weights(text: str) -> list[float]:
    """Parse ``0.3,0.7`` into numbers (their range is checked by the blend)."""
    try:
        return [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers such as 0.3,0.7, got {text!r}") from None


def _per_input(values: list | None, n: int, option: str) -> list:
    """An option given once (for every input) or once per input, in input order."""
    if not values:
        return [None] * n
    if len(values) == 1:
        return list(values) * n
    if len(values) != n:
        raise ParameterError(f"{option} given {len(values)} times for {n} inputs; give it once or once per input")
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
    for path, window, fps, max_scale, scale in zip(args.inputs, windows, fpss, scales, cocycle_scales):
        motion = load_input(path, None, fps)
        options = {"random_state": args.seed}
        if max_scale is not None:
            options["max_scale"] = max_scale
        if scale is not None:
            options["scale"] = scale
        try:
            src = as_cycle(motion, mode=mode, frames=window, **options)
        except NoPeriodicMotionError as exc:
            raise NoPeriodicMotionError(f"{path}: {exc}", result=exc.result) from None
        c = src.cycle
        print(f"{path}: cycle of {c.n_frames} frames ({c.n_frames / c.fps:.3f} s at {c.fps:g} fps); {src.reason}")
        out.append(src)
    return out


def _check_outputs(args: argparse.Namespace) -> None:
    """Fail fast on outputs we could not write or that would overwrite an input."""
    _check_output(args.output)
    _check_output(args.report, "report")
    refuse_clobber(
        [f for src in args.inputs for f in input_files(src)],
        [("-o", args.output), ("--report", args.report)],
    )


def _finish(args: argparse.Namespace, motion, payload: dict, report, what: str, problem: str | None = None) -> int:
    """Print the plausibility verdict, honour --strict, write the motion and the report."""
    from ..io import save
    from ..errors import ImplausibleMotionError

    print(report.summary())
    payload["plausibility"] = report.to_dict()
    refused = args.strict and (not report.clean or problem is not None)
    payload["written"] = None if refused or not args.output else args.output
    if args.report:
        _write_json(args.report, _clean(payload))
        print(f"wrote {args.report}")
    if refused:
        why = problem if report.clean and problem else "fails the plausibility checks"
        raise ImplausibleMotionError(
            f"the {what} {why} and --strict is set; nothing written"
            + (f" (see {args.report})" if args.report else "")
        )
    if args.output:
        save(motion, args.output)
        print(f"wrote {args.output}")
    return EXIT_OK


def cmd_blend(args: argparse.Namespace) -> int:
    from ..synthesis.blend import blend
    from ..synthesis.sources import cycle_summary
    from ..quality.plausibility import check_plausibility

    _check_outputs(args)
    try:
        sources = _load_cycles(args)
    except NoPeriodicMotionError as exc:
        print(f"cyclecoord: {exc}", file=sys.stderr)
        return EXIT_NO_PERIODIC
    n = len(sources)
    weights = args.weights if args.weights is not None else [1.0 / n] * n
    cycles = [s.cycle for s in sources]
    out = blend(sources, weights, allow_reverse=args.allow_reverse, align_heading=not args.no_heading, up=args.up)
    info = out.metadata["blend"]
    for i, al in enumerate(info["alignments"][1:], start=1):
        rev = ", reversed" if al["reversed"] else ""
        print(
            f"aligned {args.inputs[i]} to {args.inputs[0]}: shift {al['shift_frames']:.2f} frames{rev}, "
            f"rms pose difference {al['cost']:.3g} (unaligned {al['cost_unaligned']:.3g})"
        )
    summaries = [cycle_summary(c) for c in cycles]
    s = cycle_summary(out)
    print(
        f"blend {', '.join(f'{w:g}' for w in info['weights'])}: {out.n_frames} frames ({s['seconds']:.3f} s; inputs "
        + ", ".join(f"{v['frames']}" for v in summaries)
        + f"), loop closure {s['loop_closure']:.2f}, jerk {s['jerk']:.4g} (inputs "
        + ", ".join(f"{v['jerk']:.4g}" for v in summaries) + ")"
    )
    for note in info["notes"]:
        print(f"note: {note}")
    report = check_plausibility(out, cycles, margin_deg=args.margin)
    payload = {
        "inputs": [dict(src.to_dict(), path=p, summary=sm) for src, p, sm in zip(sources, args.inputs, summaries)],
        "weights": info["weights"],
        "output": dict(s, path=args.output),
        "root_displacement": out.metadata["root_displacement"],
        "blend": info,
    }
    return _finish(args, out, payload, report, "blend")


def cmd_transition(args: argparse.Namespace) -> int:
    from ..synthesis.blend import transition
    from ..quality.plausibility import check_plausibility

    _check_outputs(args)
    try:
        sources = _load_cycles(args)
    except NoPeriodicMotionError as exc:
        print(f"cyclecoord: {exc}", file=sys.stderr)
        return EXIT_NO_PERIODIC
    a, b = (s.cycle for s in sources)
    clip = transition(
        sources[0], sources[1], frames=args.frames, cycles=args.cycles,
        lead_in=args.lead_in, lead_out=args.lead_out,
        allow_reverse=args.allow_reverse, align_heading=not args.no_heading, up=args.up,
    )
    info = clip.metadata["transition"]
    al = info["alignment"]
    cont = info["continuity"]
    print(
        f"aligned {args.inputs[1]} to {args.inputs[0]}: shift {al['shift_frames']:.2f} frames"
        + (", reversed" if al["reversed"] else "")
    )
    print(
        f"transition: {clip.n_frames} frames ({info['lead_in_frames']} of A, ramp {info['ramp_frames']} frames = "
        f"{info['ramp_cycles']:.2f} cycles, {info['lead_out_frames']} of B); largest step {cont['max_ratio']:.2f}x "
        f"the typical step at its phase (limit {cont['limit']:g})"
    )
    for note in info["notes"]:
        print(f"note: {note}")
    report = check_plausibility(clip, [a, b], margin_deg=args.margin)
    meta = {k: v for k, v in info.items() if k not in ("weight", "phase")}
    payload = {
        "inputs": [dict(src.to_dict(), path=p) for src, p in zip(sources, args.inputs)],
        "output": {"path": args.output, "frames": clip.n_frames, "fps": clip.fps},
        "transition": meta,
        "weight": info["weight"],
        "phase": info["phase"],
    }
    problem = None
    if cont["max_ratio"] > cont["limit"]:
        problem = f"has a step {cont['max_ratio']:.2f}x the typical step (limit {cont['limit']:g})"
    return _finish(args, clip, payload, report, "transition", problem)


def cmd_batch(args: argparse.Namespace) -> int:
    from ..batch import DEFAULT_PATTERNS, run_batch

    options = dict(
        pca=args.pca, normalize=args.normalize, temporal=args.temporal, prime=args.prime,
        max_scale=args.max_scale, landmarks=args.landmarks, random_state=args.seed,
        **({} if args.memory_limit is None else {"memory_limit": args.memory_limit}),
        **_cycle_options(args),
    )
    summary = run_batch(
        args.folder, args.output, jobs=args.jobs, scheduler=args.scheduler,
        pattern=args.pattern or DEFAULT_PATTERNS, force=args.force, extract_options=options,
        write_cycles=None if args.cycles == "none" else args.cycles, fps=args.fps,
        progress=not args.no_progress,
    )
    print(summary.describe())
    return EXIT_ERROR if summary.n_error or not summary.rows else EXIT_OK


# ------------------------------------------------------------------ parser
#: Subcommands that live in a module of their own under ``cyclecoord.cli``: each module has
#: ``add_parser(subparsers)``, which adds its parser and sets ``func`` to the function that
#: runs it (taking the parsed arguments, returning the exit code).  Modules must import
#: their heavy dependencies inside that function so ``cyclecoord --help`` stays fast.
COMMAND_MODULES: tuple[str, ...] = ("view", "feet", "graph", "latent", "animate")


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="cyclecoord",
        description=(
            "Find, parameterise and reuse periodic motion in motion capture with persistent "
            "cohomology. INPUT is an .amc (skeleton found beside it), .bvh, .npz or .csv file, "
            "or 'example' for the built-in synthetic walk (example:jog, example:chain, "
            "example:take, ...)."
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=(
            "examples:\n"
            "  cyclecoord extract example -o walk_cycle.bvh --report report.json\n"
            "  cyclecoord extract 69_01.amc --frames 200:450 --max-scale 50 -o cycle.bvh\n"
            "  cyclecoord barcode 69_01.amc --frames 200:450 --json\n"
            "  cyclecoord convert 69_01.amc -o 69_01.bvh\n"
            "  cyclecoord extract 69_01.amc --frames 200:450 --max-scale 50 -o cycle.bvh --plot figures\n"
            "  cyclecoord render 69_01.amc --frames 200:450 -o walk.gif --side-by-side cycle.bvh\n"
            "  cyclecoord blend 69_01.amc 143_01.amc --window 200:450 --window 0:96 --max-scale 50 \\\n"
            "      --scale auto --scale 40 --weights 0.5,0.5 -o walk_jog.bvh --report blend.json\n"
            "  cyclecoord transition walk_cycle.bvh jog_cycle.bvh --cycles 2 -o walk_to_jog.bvh\n"
            "  cyclecoord batch captures/ -o results/ --jobs 4\n"
            "exit codes: 0 ok, 1 error (one line naming the file and what was wrong), 2 usage, "
            "3 no periodic motion found, 130 interrupted (Ctrl-C; no partial files are left)"
        ),
    )
    from .. import __version__

    p.add_argument("--version", action="version", version=f"cyclecoord {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")

    e = sub.add_parser(
        "extract",
        help="find the dominant periodic motion and write its typical cycle",
        description=(
            "Barcode -> most persistent H1 class -> circular coordinate per frame -> periodic "
            "density -> typical cycle (each phase's pose a smooth kernel average of the frames near "
            "that phase; --weighting mean gives the paper's k-nearest centroids), resampled to the capture's "
            "frame rate and written as a loopable clip. Exit code 3 when no H1 bar stands clear "
            "(death/birth >= 1.5 and at least 2x the next bar's persistence); the report is still written."
        ),
    )
    e.add_argument("input", metavar="INPUT")
    _add_selection_options(e)
    g = e.add_argument_group("class, scale and cycle")
    g.add_argument("--scale", type=_positive_float, metavar="E", help="read the cocycle at this scale (inside the bar)")
    g.add_argument("--class", dest="class_index", type=int, default=0, metavar="I",
                   help="use the I-th most persistent H1 class (default 0)")
    g.add_argument("--samples", type=_positive_int, default=500, metavar="N", help="phases sampled from the density (500)")
    g.add_argument("--neighbors", type=_positive_int, default=10, metavar="K", help="frames averaged per phase (10; should exceed the number of cycles)")
    g.add_argument("--weighting", choices=("kernel", "mean", "gaussian"), default="kernel",
                   help="how frames near a phase are averaged: smooth kernel (default), the paper's "
                   "k-nearest mean, or k-nearest Gaussian-weighted")
    g.add_argument("--sampling", choices=("quantile", "random"), default="quantile",
                   help="density quantiles (default, smooth) or random draws as in the paper")
    g.add_argument("--seed", type=int, default=0, metavar="S", help="random seed (0)")
    g.add_argument("--delay", type=_delay, default="auto", metavar="S|auto|0",
                   help="delay embedding in seconds so out-and-back motions (squats, jumping jacks) form "
                   "loops; auto (default): none, and 0.25 s when the poses alone show no periodic motion")
    _add_cycle_options(e.add_argument_group("the cycle"))
    e.add_argument("-v", "--verbose", action="store_true",
                   help="also print the barcode, the chosen class, the cocycle check, landmarks and timings")
    o = e.add_argument_group("output")
    o.add_argument("-o", "--output", metavar="OUT", help="write the cycle (.bvh, .amc, .npz, .csv, .glb, .gltf, .usda, .usdc)")
    o.add_argument("--report", metavar="R.json", help="write a JSON report (barcode, coordinate, figures, timings)")
    o.add_argument("--plot", metavar="DIR",
                   help="write figures into DIR (created if missing): barcode, pca, density, coordinate, channels (.png)")
    o.add_argument("--save-model", metavar="M.npz",
                   help="save the fitted phase model (preparation + coordinate) to phase new frames later")
    o.add_argument("--apply", metavar="M.npz",
                   help="do not fit: give every frame of INPUT its phase from a saved model (with --report)")
    e.set_defaults(func=cmd_extract)

    b = sub.add_parser("barcode", help="print the H0/H1 barcode of a capture",
                       description="Vietoris-Rips persistent cohomology barcode (H0, H1) of the prepared poses.")
    b.add_argument("input", metavar="INPUT")
    _add_selection_options(b)
    b.add_argument("--json", action="store_true", help="print JSON ({'h0': [[b, d], ...], 'h1': ...}; d null = infinite)")
    b.set_defaults(func=cmd_barcode)

    c = sub.add_parser("convert", help="convert between ASF/AMC, BVH, NPZ and CSV",
                       description="Convert a capture between formats, chosen by the file suffixes.")
    c.add_argument("input", metavar="INPUT")
    c.add_argument("-o", "--output", required=True, metavar="OUT",
                   help="output file; its suffix chooses the format (.amc with its .asf beside it, "
                   ".bvh, .npz, .csv); never one of the inputs")
    c.add_argument("--skeleton", metavar="ASF", help="ASF skeleton for an AMC input")
    c.add_argument("--fps", type=_positive_float, metavar="F", help="frame rate to record in the output")
    c.add_argument("--frames", type=_frame_range, metavar="A:B", help="only these frames")
    c.set_defaults(func=cmd_convert)

    d = sub.add_parser(
        "detect", help="find several periodic motions in one capture and segment it",
        description=(
            "Reads several long H1 bars as several periodic motions (paper sec. 4.6): every candidate "
            "class (death/birth >= 1.5 and at least 10% of the longest bar's persistence, at most 30) gets "
            "a circular coordinate at its own scale; a class counts where its coordinate advances steadily "
            "for at least 1.5 cycles; classes exciting the same frames are one motion. The windowed stage "
            "(--method windows or auto, the default) also reads the barcodes of sliding 2, 4 and 6 s windows, "
            "groups windows with alike typical cycles into motions and labels each frame with the motion "
            "whose cycle is nearest. Prints segments and writes per-frame labels (-1: nothing periodic) in "
            "the report. Exit code 3 when nothing is found."
        ),
    )
    d.add_argument("input", metavar="INPUT")
    _add_selection_options(d)
    d.add_argument("--classes", type=_positive_int, metavar="N", help="use exactly the N most persistent H1 classes")
    d.add_argument("--delay", type=float, default=0.25, metavar="S",
                   help="delay embedding in seconds so out-and-back motions form loops (0.25; 0 = off, as the paper)")
    d.add_argument("--method", choices=("auto", "global", "windows"), default="auto",
                   help="global: long bars of the one barcode (the paper); windows: sliding-window barcodes; "
                   "auto (default): both, windowed motions that excite a global motion's frames join it")
    d.add_argument("--no-progress", action="store_true", help="no progress bar over the windows")
    d.add_argument("--report", metavar="R.json", help="JSON: segments, labels per frame, classes, windows, barcode")
    d.add_argument("--extract", metavar="OUTDIR", help="write a typical cycle (BVH) for each detected motion")
    dc = d.add_argument_group("the cycles written by --extract (as extract's)")
    dc.add_argument("--timing", choices=("capture", "coordinate"), default="capture",
                    help="capture (default): at the capture's pace, repetitions aligned; coordinate: the paper's")
    dc.add_argument("--travel", choices=("keep", "straight", "in_place"), default="keep",
                    help="keep the heading change and travel of a cycle, walk straight, or stay in place")
    dc.add_argument("--bandwidth", type=_bandwidth, default=None, metavar="auto|F",
                    help="kernel width in frames of time (default 1), or 'auto' (cross-validated)")
    dc.add_argument("--cycle-start", choices=("slowest", "first"), default="slowest",
                    help="begin each cycle at its slowest pose (default) or at phase 0")
    d.add_argument("--extract-format", default="bvh", choices=("bvh", "glb", "gltf", "usda", "usdc", "npz", "csv"),
                   help="file format of the --extract cycles (default bvh)")
    d.add_argument("--plot", metavar="DIR", help="write the barcode (barcode.png), the coordinates with segments shaded (coordinates.png) and the windows coloured by motion (windows.png)")
    d.set_defaults(func=cmd_detect)

    r = sub.add_parser(
        "render", help="animate a capture as a stick figure (.gif, or .mp4 with ffmpeg)",
        description=(
            "Draw the skeleton of every STEP-th frame (forward kinematics, y up, with the floor) and "
            "write a GIF, or an MP4 when ffmpeg is installed. Plays in real time. With --side-by-side "
            "a second capture (e.g. an extracted cycle) is drawn next to it; the shorter one loops."
        ),
    )
    r.add_argument("input", metavar="INPUT")
    r.add_argument("-o", "--output", required=True, metavar="OUT", help="animation file, .gif or .mp4")
    r.add_argument("--skeleton", metavar="ASF", help="ASF skeleton for an AMC input (default: found beside the AMC)")
    r.add_argument("--frames", type=_frame_range, metavar="A:B", help="only these frames of INPUT (0-based, half-open)")
    r.add_argument("--fps", type=_positive_float, metavar="F", help="frame rate of the capture (AMC files carry none; default 120)")
    r.add_argument("--side-by-side", metavar="OTHER", help="a second capture to draw beside INPUT (e.g. the cycle from extract -o)")
    r.add_argument("--step", type=_positive_int, metavar="K", help="draw every K-th frame (default: about 30 frames per second)")
    r.add_argument("--view", choices=("side", "front", "3d"), default="side",
                   help="side: across the direction of travel (default); front: along it; 3d: perspective")
    r.add_argument("--follow", action=argparse.BooleanOptionalAction, default=None,
                   help="keep the figure centred and move the floor (default: only when it travels far)")
    r.set_defaults(func=cmd_render)

    def cycle_inputs(q: argparse.ArgumentParser) -> None:
        g = q.add_argument_group(
            "inputs",
            "An input is taken as one cycle when it was written by extract or blend (NPZ metadata), or when "
            "it loops (last-to-first step <= 1.5x its median step), does not repeat within its length "
            "(at most ~1.5 periods by autocorrelation) and moves (some pose >= 3 median steps from the mean "
            "pose); anything else is a capture and its typical cycle is "
            "extracted first (facing heading 0, to keep the root's Euler angles away from gimbal lock). "
            "Options given once apply to every input; given once per input, they apply in input order "
            "('auto' or ':' keeps an input's default).",
        )
        how = g.add_mutually_exclusive_group()
        how.add_argument("--as-cycle", action="store_true", help="take every input as a cycle as it is")
        how.add_argument("--extract", action="store_true", help="extract the typical cycle of every input")
        g.add_argument("--window", type=_frame_range, action="append", metavar="A:B",
                       help="0-based half-open frame window of an input (like extract's --frames)")
        g.add_argument("--fps", type=_auto_or_positive, action="append", metavar="F",
                       help="frame rate of an input (AMC files carry none; default 120)")
        g.add_argument("--max-scale", type=_auto_or_positive, action="append", metavar="E",
                       help="Rips threshold for extracting an input ('auto': extract's default)")
        g.add_argument("--scale", type=_auto_or_positive, action="append", metavar="E",
                       help="scale to read an input's cocycle at ('auto': extract's default)")
        g.add_argument("--seed", type=int, default=0, metavar="S", help="random seed for extraction (0)")
        m = q.add_argument_group("matching and checks")
        m.add_argument("--allow-reverse", action="store_true",
                       help="let a cycle play backwards when that matches the first better")
        m.add_argument("--no-heading", action="store_true",
                       help="do not turn the cycles to the first one's heading before blending")
        m.add_argument("--up", choices=("x", "y", "z"), default="y", help="vertical axis (default y)")
        m.add_argument("--margin", type=float, default=5.0, metavar="DEG",
                       help="joint-range tolerance beyond the inputs' range, degrees (5)")
        m.add_argument("--strict", action="store_true",
                       help="refuse to write an output that fails the plausibility checks (exit 1)")
        o = q.add_argument_group("output")
        o.add_argument("-o", "--output", metavar="OUT", help="write the result (.bvh, .amc, .npz, .csv, .glb, .gltf, .usda, .usdc)")
        o.add_argument("--report", metavar="R.json",
                       help="write a JSON report (inputs, alignment, figures, plausibility)")

    bl = sub.add_parser(
        "blend",
        help="blend two or more cycles by weights into a new loopable cycle",
        description=(
            "Convex combination y(θ) = Σ w_i x_i(θ) of periodic cycles (paper §4.5). The first input is the "
            "reference: the others are scaled to its skeleton, turned to its heading and aligned to its phase "
            "(circular search over shifts); the blend lasts Σ w_i T_i and travels the weighted mean stride. "
            "Limbs passing through each other and joint angles outside the inputs' range are reported."
        ),
    )
    bl.add_argument("inputs", nargs="+", metavar="INPUT", help="two or more cycles or captures")
    bl.add_argument("--weights", type=_weights, metavar="W1,W2,...",
                    help="one non-negative weight per input, summing to 1 (default: equal)")
    cycle_inputs(bl)
    bl.set_defaults(func=cmd_blend)

    tr = sub.add_parser(
        "transition",
        help="a clip that turns one cycle into another without a hitch",
        description=(
            "Cycles of A, then a ramp over which the weight of B rises smoothly from 0 to 1 while the phase "
            "keeps advancing and the cadence slides from A's to B's (the paper's homotopy), then cycles of B. "
            "The continuity check compares every step with the typical step of A and B at the same phase."
        ),
    )
    tr.add_argument("inputs", nargs=2, metavar="INPUT", help="cycle (or capture) A, then B")
    length = tr.add_mutually_exclusive_group(required=True)
    length.add_argument("--frames", type=_positive_int, metavar="N", help="length of the ramp in frames")
    length.add_argument("--cycles", type=_positive_float, metavar="C", help="length of the ramp in cycles")
    tr.add_argument("--lead-in", type=int, default=1, metavar="K", help="whole cycles of A before the ramp (1)")
    tr.add_argument("--lead-out", type=int, default=1, metavar="K", help="whole cycles of B after the ramp (1)")
    cycle_inputs(tr)
    tr.set_defaults(func=cmd_transition)

    ba = sub.add_parser(
        "batch",
        help="run extract on every capture in a folder, locally or on a Dask cluster",
        description=(
            "Run extract on every capture under DIR (recursively; .amc, .bvh, .npz, .csv by default). "
            "OUTDIR mirrors DIR's tree: NAME.report.json and NAME.cycle.bvh per capture, and summary.csv "
            "with one row per capture (status ok / no_periodic / error and the key figures). A failing "
            "capture is recorded and the batch goes on. A re-run skips captures whose report matches the "
            "input's size, modification time and the options (errors are retried); --force recomputes. "
            "OUTDIR must lie outside DIR. Exit code 1 when any capture failed or none was found."
        ),
    )
    ba.add_argument("folder", metavar="DIR", help="folder of captures")
    ba.add_argument("-o", "--output", required=True, metavar="OUTDIR", help="output folder (created if missing)")
    w = ba.add_argument_group("where it runs")
    w.add_argument("-j", "--jobs", type=int, default=1, metavar="N",
                   help="worker processes (default 1: in this process; 0: one per CPU core)")
    w.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on a Dask distributed cluster, e.g. tcp://host:8786 (needs cyclecoord[dask]; "
                   "the workers must see DIR and OUTDIR at the same paths)")
    w.add_argument("--force", action="store_true", help="recompute captures whose report is up to date")
    w.add_argument("--pattern", action="append", metavar="GLOB",
                   help="file-name glob, case-insensitive; repeat for several (default: *.amc *.bvh *.npz *.csv)")
    w.add_argument("--cycles", choices=("bvh", "npz", "none"), default="bvh",
                   help="format of the cycle written per capture (default bvh; none: reports only)")
    w.add_argument("--no-progress", action="store_true", help="no progress bar")
    g = ba.add_argument_group("what to analyse and how (the same for every capture)")
    g.add_argument("--fps", type=_positive_float, metavar="F", help="frame rate (AMC files carry none; default 120)")
    g.add_argument("--pca", type=_positive_int, metavar="K", help="project poses onto K principal components first")
    g.add_argument("--normalize", action="store_true", help="scale each channel by its standard deviation")
    g.add_argument("--temporal", action="store_true", help="time-aware metric: consecutive frames at distance 0")
    g.add_argument("--prime", type=int, default=47, metavar="P", help="coefficient field Z/P, a prime > 11 (default 47)")
    g.add_argument("--max-scale", type=_positive_float, metavar="E",
                   help="Rips threshold in the analysed space's units (default: half the point cloud's diameter)")
    g.add_argument("--landmarks", type=_landmarks, default="auto", metavar="N|auto|none",
                   help="filtration on N greedy landmarks (auto: every frame up to 1000 frames, 500 beyond)")
    g.add_argument("--memory-limit", type=_bytes, default=None, metavar="SIZE",
                   help="memory budget per capture for the filtration, e.g. 2G; above it landmarks are used")
    g.add_argument("--seed", type=int, default=0, metavar="S", help="random seed (0)")
    _add_cycle_options(ba.add_argument_group("the cycle (the same for every capture)"))
    ba.set_defaults(func=cmd_batch)
    for name in COMMAND_MODULES:
        import importlib

        importlib.import_module(f".{name}", __package__).add_parser(sub)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "command", None):
        parser.print_help()
        return EXIT_USAGE
    try:
        return int(args.func(args))
    except CycleCoordError as exc:
        print(f"cyclecoord: error: {_named(getattr(args, 'input', None), exc)}", file=sys.stderr)
        return EXIT_ERROR
    except FileNotFoundError as exc:
        print(f"cyclecoord: error: {exc}", file=sys.stderr)
        return EXIT_ERROR
    except PermissionError as exc:
        print(f"cyclecoord: error: {exc}", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        print("cyclecoord: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into `head` and the like
        import os

        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_OK


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
