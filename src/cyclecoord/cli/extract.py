"""``cyclecoord extract``: the dominant periodic motion, its cycle, report, model and figures."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from ..errors import NoPeriodicMotionError, ParameterError
from ..io import input_files
from ._options import (
    INPUT_HELP,
    EXIT_NO_PERIODIC,
    EXIT_OK,
    add_cycle_options,
    add_feet_option,
    add_selection_options,
    add_units_option,
    export_units,
    check_output,
    cycle_options,
    delay,
    feet_option,
    named,
    positive_float,
    positive_int,
)
from ._outputs import Outputs, declare
from .report import clean, load_input, partial_report, summary_barcode, write_json


def add_parser(subparsers) -> argparse.ArgumentParser:
    e = subparsers.add_parser(
        "extract",
        help="find the dominant periodic motion and write its typical cycle",
        description=(
            "Barcode -> most persistent H1 class -> circular coordinate per frame -> periodic "
            "density -> typical cycle (each phase's pose a smooth kernel average of the frames "
            "near that phase; --weighting mean gives the paper's k-nearest centroids), resampled "
            "to the capture's frame rate and written as a loopable clip. Exit code 3 when no H1 "
            "bar stands clear (death/birth >= 1.5 and at least 2x the next bar's persistence); the "
            "report is still written."
        ),
    )
    e.add_argument("input", metavar="INPUT", help=INPUT_HELP)
    add_units_option(add_selection_options(e))
    g = e.add_argument_group("class, scale and cycle")
    g.add_argument(
        "--scale",
        type=positive_float,
        metavar="E",
        help="read the cocycle at this scale (inside the bar)",
    )
    g.add_argument(
        "--class",
        dest="class_index",
        type=int,
        default=0,
        metavar="I",
        help="use the I-th most persistent H1 class (default 0)",
    )
    g.add_argument(
        "--samples",
        type=positive_int,
        default=500,
        metavar="N",
        help="phases sampled from the density (500)",
    )
    g.add_argument(
        "--neighbors",
        type=positive_int,
        default=10,
        metavar="K",
        help="frames averaged per phase (10; should exceed the number of cycles)",
    )
    g.add_argument(
        "--weighting",
        choices=("kernel", "mean", "gaussian"),
        default="kernel",
        help="how frames near a phase are averaged: smooth kernel (default), the paper's "
        "k-nearest mean, or k-nearest Gaussian-weighted",
    )
    g.add_argument(
        "--sampling",
        choices=("quantile", "random"),
        default="quantile",
        help="density quantiles (default, smooth) or random draws as in the paper",
    )
    g.add_argument("--seed", type=int, default=0, metavar="S", help="random seed (0)")
    g.add_argument(
        "--delay",
        type=delay,
        default="auto",
        metavar="S|auto|0",
        help="delay embedding in seconds so out-and-back motions (squats, jumping jacks) form "
        "loops; auto (default): none, and 0.25 s when the poses alone show no periodic motion",
    )
    cyc = e.add_argument_group("the cycle")
    add_cycle_options(cyc)
    add_feet_option(cyc)
    e.add_argument(
        "-v",
        "--verbose",
        action="store_true",
        help="also print the barcode, the chosen class, the cocycle check, landmarks and timings",
    )
    o = e.add_argument_group("output")
    o.add_argument(
        "-o",
        "--output",
        metavar="OUT",
        help="write the cycle (.bvh, .amc, .npz, .csv, .glb, .gltf, .usda, .usdc)",
    )
    o.add_argument(
        "--report",
        metavar="R.json",
        help="write a JSON report (barcode, coordinate, figures, timings)",
    )
    o.add_argument(
        "--plot",
        metavar="DIR",
        help="write figures into DIR (created if missing): barcode, pca, density, coordinate, "
        "channels (.png)",
    )
    o.add_argument(
        "--lock-feet",
        action="store_true",
        help="pin the cycle's planted feet before writing it (a small leg IK over the loop; "
        "the report's foot_lock gives the skating before and after and how far each leg "
        "joint moved)",
    )
    o.add_argument(
        "--save-model",
        metavar="M.npz",
        help="save the fitted phase model (preparation + coordinate) to phase new frames later",
    )
    o.add_argument(
        "--apply",
        metavar="M.npz",
        help="do not fit: give every frame of INPUT its phase from a saved model (with --report)",
    )
    e.set_defaults(func=cmd_extract)
    declare(
        e,
        inputs=lambda a: input_files(a.input, a.skeleton) + input_files(a.apply),
        files=("-o", "--report", "--save-model"),
        folders={"--plot": r".*\.png"},
    )
    return e


def cmd_extract(args: argparse.Namespace) -> int:
    check_output(args.output)
    check_output(args.report, "report")
    if args.save_model:
        check_output(args.save_model, "model")
    if args.plot and Path(args.plot).exists() and not Path(args.plot).is_dir():
        raise ParameterError(f"{args.plot}: exists and is not a folder (--plot takes a folder)")
    motion = load_input(args.input, args.skeleton, args.fps)
    with Outputs() as out:  # every output moves into place at the end, or none does
        if args.apply:
            return _apply_model(args, motion, out)
        return _extract(args, motion, out)


def _extract(args: argparse.Namespace, motion, out: Outputs) -> int:
    from ..periodic.pipeline import extract
    from ..periodic.suggest import MAX_FRAMES as SUGGEST_MAX_FRAMES, what_would_help

    report_payload = None
    code = EXIT_OK
    feet = feet_option(args, motion)
    options = dict(
        frames=args.frames,
        pca=args.pca,
        normalize=args.normalize,
        rotations=args.rotations,
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
        feet=feet,
        **cycle_options(args),
    )
    try:
        res = extract(motion, **options)
    except NoPeriodicMotionError as exc:
        partial = exc.result
        print(f"cyclecoord: {named(args.input, exc)}", file=sys.stderr)
        helps = what_would_help(motion, options)
        if helps:
            print("would help here (tried): " + "; ".join(h.text() for h in helps),
                  file=sys.stderr)
        elif motion.n_frames <= SUGGEST_MAX_FRAMES:
            print("tried --rotations rotvec, --no-steady, --pca 3 and --normalize: none finds a "
                  "clean cycle here; look at the barcode (--plot) or pick frames (--frames)",
                  file=sys.stderr)
        if partial is not None:
            print(summary_barcode(partial.barcode))
            report_payload = partial_report(exc)
            report_payload["suggestions"] = [h.to_dict() for h in helps]
            if args.plot:
                _save_plots(partial, args.plot, out)
        code = EXIT_NO_PERIODIC
    else:
        for line in describe_extraction(res, args.input, verbose=args.verbose):
            print(line)
        cycle, locked = res.cycle, None
        if args.lock_feet:
            cycle, locked, why = _lock(res.cycle, feet)
            print(locked.summary() if locked is not None else f"feet: not locked: {why}")
        if args.output:
            out.save(cycle, args.output, **export_units(args, args.output))
        if args.save_model:
            res.model.save(out.file(args.save_model))
            out.wrote(args.save_model)
        if args.plot:
            _save_plots(res, args.plot, out)
        report_payload = res.to_report()
        if locked is not None:
            report_payload["foot_lock"] = locked.to_dict()
        if args.verbose:
            print("time: " + ", ".join(f"{k} {v:.3f}s" for k, v in res.timings.items()))
    if args.report and report_payload is not None:
        write_json(out.file(args.report), clean(report_payload))
        out.wrote(args.report)
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
    lines = []
    if getattr(res, "rig", None) is not None:
        changes = f" (analysed with {'; '.join(res.rig_changes)})" if res.rig_changes else ""
        lines.append(f"rig: {res.rig.summary()}{changes}")
    lines.append(
        f"{m.source or name}: {m.n_frames} frames at {fps:g} fps"
        + (f" (frames {m.start_frame}:{m.start_frame + m.n_frames})" if m.start_frame else "")
    )
    if n_used < m.n_frames:
        lines.append(
            f"steady motion in frames {_frames_text(used, m.start_frame)} ({n_used} of "
            f"{m.n_frames} frames); "
            "the rest (standing, starting, turning, stopping or another motion) has no phase"
        )
    wind = res.windings
    spread = f", spread {wind.spread:.0%}" if wind is not None and wind.pooled.size > 1 else ""
    lines.append(
        f"period: {res.period_frames:.1f} frames ({res.period_frames / fps:.3f} s), "
        f"{res.cycles:.2f} cycles over the steady frames"
        + (
            f"; complete windings {', '.join(f'{v:.0f}' for v in res.cycle_frames[:8])} "
            f"frames{spread}"
            if len(res.cycle_frames)
            else spread
        )
    )
    ratio = (
        res.jerk["cycle"] / res.jerk["original"]
        if res.jerk.get("original", 0) > 0
        else float("nan")
    )
    pq = res.pose_quality
    if pq is not None:
        # the words come from joint positions (the same whatever file the cycle is read from)
        closure, ratio = pq.seam, pq.jerk_ratio
        if pq.pops:
            seam = f"pops ({pq.pop:.1f}x the capture's largest steps)"
        elif pq.seam > 1.5:
            seam = "a visible seam"
        else:
            seam = "seamless"
        if pq.strays:
            seam += f", poses {pq.nearest_max:.1f}x the capture's spread from any captured pose"
    else:
        closure = res.loop_closure
        seam = "seamless" if closure <= 1.5 else "a visible seam"
    pops = pq is not None and (pq.pops or pq.strays)
    smooth = (
        "as smooth as the capture or smoother"
        if ratio <= 1.0 and not pops
        else f"{ratio:.2g}x the capture's jerk"
    )
    width = ""
    if res.parameters.get("bandwidth") is not None:
        chosen = " (cross-validated)" if res.typical.bandwidth_selection is not None else ""
        width = f"; kernel width {_frames(res.typical.bandwidth)}{chosen}"
    lines.append(
        f"cycle: {res.cycle.n_frames} frames ({res.cycle.n_frames / fps:.3f} s), {seam} "
        f"(last-to-first step {closure:.2f} median steps), {smooth} (jerk ratio "
        f"{ratio:.2f}){width}"
    )
    if np.isfinite(res.heading_per_cycle):
        travel = res.parameters.get("travel", "keep")
        kept = {
            "keep": "kept; --travel straight removes it",
            "straight": "removed (--travel straight)",
            "in_place": "removed, and the cycle stays in place (--travel in_place)",
        }[travel]
        lines.append(f"heading: turns {res.heading_per_cycle:+.1f} degrees per cycle ({kept})")
    feet = _feet_line(res.cycle, res.parameters.get("feet"))
    if feet:
        lines.append(feet)
    for w in res.warnings:
        lines.append(f"warning: {w}")
    if not verbose:
        return lines
    sel = res.selection
    lines.append(summary_barcode(res.barcode, sel))
    ds = "inf" if not np.isfinite(sel.death) else f"{sel.death:.4g}"
    gap = "alone" if not np.isfinite(sel.gap) else f"{sel.gap:.1f}x the next bar"
    lines.append(
        f"class #{sel.index} [{sel.birth:.4g}, {ds}) read at scale {sel.scale:.4g}: death/birth "
        f"{sel.ratio:.2f}, persistence {gap}"
    )
    chk = res.estimator.cocycle_check_
    lines.append(
        f"cocycle check: {chk.n_violations} of {chk.n_triangles} triangles violate (prime "
        f"{res.estimator.prime_})"
    )
    lines.append(
        f"frames to cycle: median distance {res.distance['median']:.3g} (median frame step "
        f"{res.distance['median_frame_step']:.3g}); kernel width {_frames(res.typical.bandwidth)}"
    )
    lines.append(
        f"largest cycle step {res.distance['largest_cycle_step']:.3g} (capture's 99th "
        f"percentile {res.distance['p99_frame_step']:.3g})"
    )
    lm = res.estimator.landmarks_
    if lm is not None:
        fb = res.selection.full_birth
        lines.append(
            f"landmarks: {len(lm)} of {len(res.estimator.points_)} frames (covering radius "
            f"{res.estimator.covering_radius_:.3g})"
            + (f"; birth on every frame {fb:.4g}" if fb is not None else "")
        )
    return lines


def _lock(cycle, feet=None):
    """The cycle with its planted feet pinned over the loop: ``(motion, result, None)``,
    or ``(cycle, None, why)`` when it has no skeleton or no feet are found (named ``feet``
    that are not joints raise)."""
    from ..errors import ParameterError
    from ..synthesis.footlock import lock_feet

    if cycle.skeleton is None:
        return cycle, None, "the cycle has no skeleton"
    if feet is not None:
        result = lock_feet(cycle, cyclic=True, feet=tuple(feet))
        return result.motion, result, None
    try:
        result = lock_feet(cycle, cyclic=True)
    except ParameterError as exc:
        return cycle, None, str(exc)
    return result.motion, result, None


def _feet_line(cycle, feet=None) -> str | None:
    """One line on the cycle's planted feet (the report's ``foot_skating``), or on why
    they are not measured; None without a skeleton."""
    from ..errors import ParameterError
    from ..quality.contacts import foot_contacts, skating_report

    if cycle is None or cycle.skeleton is None:
        return None
    feet = None if feet is None else tuple(feet)
    sk = skating_report(cycle, feet=feet)
    if sk is None:
        try:
            foot_contacts(cycle, feet=feet)
        except ParameterError as exc:
            return f"feet: not measured: {exc}"
        return None
    return (
        f"feet: planted feet slide {sk['mean_speed_leg_lengths_per_s']:.2f} leg lengths/s on "
        f"average, {sk['skating_frames']} of {cycle.n_frames} frames skate "
        "(--lock-feet, or `cyclecoord feet CYCLE --cycle --lock -o OUT`, pins them)"
    )


def _apply_model(args: argparse.Namespace, motion, out: Outputs) -> int:
    """``extract --apply MODEL``: phase of every frame from a saved model, no refit."""
    from ..periodic.phase_model import PhaseModel

    model = PhaseModel.load(args.apply)
    motion = motion.window(args.frames)
    info = model.summary(motion)
    print(
        f"{motion.source or args.input}: {motion.n_frames} frames phased with {args.apply}: "
        f"{info['cycles']:.2f} cycles, period {info['period_frames']:.1f} frames (model's own "
        f"period {model.period_frames:.1f})"
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
        write_json(out.file(args.report), clean(payload))
        out.wrote(args.report)
    return EXIT_OK


def _save_plots(result, folder: str, out: Outputs) -> None:
    """``extract --plot DIR``: the standard figures (only the barcode when nothing was found)."""
    from ..plot.figures import save_figures

    for path in save_figures(result, out.folder(folder)):
        out.wrote(Path(folder) / path.name)


def _frames(n: float) -> str:
    """``"1 frame"``, ``"2.5 frames"``: a kernel width in words."""
    return f"{n:.3g} frame" + ("" if float(f"{n:.3g}") == 1 else "s")
