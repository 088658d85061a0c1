"""``cyclecoord detect``: several periodic motions in one capture, segmented and labelled."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import NoPeriodicMotionError, ParameterError
from ..io import input_files
from .._words import plural
from ._options import (
    INPUT_HELP,
    EXIT_NO_PERIODIC,
    EXIT_OK,
    add_feet_option,
    add_selection_options,
    bandwidth,
    check_output,
    feet_option,
    named,
    positive_int,
    rig_line,
)
from ._outputs import Outputs, declare
from .report import clean, load_input, summary_barcode, write_json


def add_parser(subparsers) -> argparse.ArgumentParser:
    d = subparsers.add_parser(
        "detect",
        help="find several periodic motions in one capture and segment it",
        description=(
            "Reads several long H1 bars as several periodic motions (paper sec. 4.6): every "
            "candidate class (death/birth >= 1.5 and at least 10% of the longest bar's "
            "persistence, at most 30) gets a circular coordinate at its own scale; a class counts "
            "where its coordinate advances steadily for at least 1.5 cycles; classes exciting the "
            "same frames are one motion. The windowed stage (--method windows or auto, the "
            "default) also reads the barcodes of sliding 2, 4 and 6 s windows, groups windows with "
            "alike typical cycles into motions and labels each frame with the motion whose cycle "
            "is nearest. Prints segments and writes per-frame labels (-1: nothing periodic) in the "
            "report. Exit code 3 when nothing is found."
        ),
    )
    d.add_argument("input", metavar="INPUT", help=INPUT_HELP)
    add_selection_options(d)
    d.add_argument(
        "--classes",
        type=positive_int,
        metavar="N",
        help="use exactly the N most persistent H1 classes",
    )
    d.add_argument(
        "--delay",
        type=float,
        default=0.25,
        metavar="S",
        help="delay embedding in seconds so out-and-back motions form loops (0.25; 0 = off, as "
        "the paper)",
    )
    d.add_argument(
        "--method",
        choices=("auto", "global", "windows"),
        default="auto",
        help="global: long bars of the one barcode (the paper); windows: sliding-window barcodes; "
        "auto (default): both, windowed motions that excite a global motion's frames join it",
    )
    d.add_argument("--no-progress", action="store_true", help="no progress bar over the windows")
    d.add_argument(
        "--report",
        metavar="R.json",
        help="JSON: segments, labels per frame, classes, windows, barcode (and the --extract "
        "cycles with their foot skating)",
    )
    d.add_argument(
        "--extract", metavar="OUTDIR", help="write a typical cycle (BVH) for each detected motion"
    )
    dc = d.add_argument_group("the cycles written by --extract (as extract's)")
    dc.add_argument(
        "--timing",
        choices=("capture", "coordinate"),
        default="capture",
        help="capture (default): at the capture's pace, repetitions aligned; coordinate: the "
        "paper's",
    )
    dc.add_argument(
        "--travel",
        choices=("keep", "straight", "in_place"),
        default="keep",
        help="keep the heading change and travel of a cycle, walk straight, or stay in place",
    )
    dc.add_argument(
        "--bandwidth",
        type=bandwidth,
        default=None,
        metavar="auto|F",
        help="kernel width in frames of time (default 1), or 'auto' (cross-validated)",
    )
    dc.add_argument(
        "--cycle-start",
        choices=("slowest", "first"),
        default="slowest",
        help="begin each cycle at its slowest pose (default) or at phase 0",
    )
    add_feet_option(dc)
    d.add_argument(
        "--extract-format",
        default="bvh",
        choices=("bvh", "glb", "gltf", "usda", "usdc", "npz", "csv"),
        help="file format of the --extract cycles (default bvh)",
    )
    d.add_argument(
        "--plot",
        metavar="DIR",
        help="write the barcode (barcode.png), the coordinates with segments shaded "
        "(coordinates.png) and the windows coloured by motion (windows.png)",
    )
    d.set_defaults(func=cmd_detect)
    declare(
        d,
        inputs=lambda a: input_files(a.input, a.skeleton),
        files=("--report",),
        # the cycles, in any --extract-format (a .gltf's .bin beside it)
        folders={"--extract": r"motion\d+_cycle\.[A-Za-z]+", "--plot": r".*\.png"},
    )
    return d


def cmd_detect(args: argparse.Namespace) -> int:
    """``cyclecoord detect``: several periodic motions, their segments and per-frame labels."""
    check_output(args.report, "report")
    if args.extract and Path(args.extract).exists() and not Path(args.extract).is_dir():
        raise ParameterError(
            f"{args.extract}: exists and is not a folder (--extract takes a folder)"
        )
    if args.plot and Path(args.plot).exists() and not Path(args.plot).is_dir():
        raise ParameterError(f"{args.plot}: exists and is not a folder (--plot takes a folder)")
    motion = load_input(args.input, args.skeleton, args.fps)
    if args.extract:  # a wrong --feet name fails before the detection runs
        feet_option(args, motion)
    if motion.skeleton is not None:
        print(f"rig: {rig_line(motion, args)}")
    with Outputs() as out:  # every output moves into place at the end, or none does
        return _detect(args, motion, out)


def _detect(args: argparse.Namespace, motion, out: Outputs) -> int:
    from ..periodic.detection import detect, motion_cycles

    code = EXIT_OK
    feet = feet_option(args, motion) if args.extract else None
    try:
        res = detect(
            motion,
            frames=args.frames,
            pca=args.pca,
            normalize=args.normalize,
            rotations=args.rotations,
            temporal=args.temporal,
            difference_root=not args.no_root_diff,
            prime=args.prime,
            max_scale=args.max_scale,
            landmarks=args.landmarks,
            memory_limit=args.memory_limit,
            n_classes=args.classes,
            delay=args.delay if args.delay > 0 else None,
            method=args.method,
            progress=not args.no_progress,
        )
    except NoPeriodicMotionError as exc:
        print(f"cyclecoord: {named(args.input, exc)}", file=sys.stderr)
        res, code = exc.result, EXIT_NO_PERIODIC
    m = res.motion
    print(
        f"{m.source or args.input}: frames {m.start_frame}:{m.start_frame + m.n_frames} "
        f"({m.n_frames} frames, {m.fps:g} fps)"
    )
    print(summary_barcode(res.barcode))
    kept = [c for c in res.classes if c.motion >= 0]
    print(
        f"method {res.method}: {len(res.classes)} candidate H1 classes, {len(kept)} excited", end=""
    )
    if res.windows:
        print(
            f"; {len(res.windows)} windows, {sum(w.looping for w in res.windows)} looping", end=""
        )
    print(f": {plural(res.n_motions, 'motion')}")
    for sg in res.segments:
        print(
            f"  motion {sg.motion}: frames {m.start_frame + sg.start}-{m.start_frame + sg.stop} "
            f"({sg.cycles:.2f} cycles, period {sg.period_frames:.1f} frames, classes "
            f"{list(sg.classes)})"
        )
    for w in res.warnings:
        print(f"warning: {w}")
    extracted = []
    if args.extract and code == EXIT_OK:
        from ..periodic.pipeline import MAX_POP
        from ..quality.contacts import skating_line, skating_report

        folder = Path(args.extract)
        cycles = motion_cycles(
            res,
            bandwidth=args.bandwidth,
            cycle_start=args.cycle_start,
            timing=args.timing,
            travel=args.travel,
            feet=feet,
        )
        have = {mc.motion for mc in cycles}
        for mid in range(res.n_motions):
            segs = [sg for sg in res.segments if sg.motion == mid]
            if segs and mid not in have:
                seg = max(segs, key=lambda sg: sg.stop - sg.start)
                print(
                    f"motion {mid}: no cycle written: its longest segment holds {seg.cycles:.2f} "
                    "cycles, under the 1.5 a typical cycle needs (extract refuses such a take too)"
                )
        for mc in cycles:
            path = folder / f"motion{mc.motion}_cycle.{args.extract_format}"
            out.save(mc.cycle, path, announce=False)  # the line below names it
            how = (
                f"phase from H1 {mc.phase_from}'s coordinate on {mc.n_frames_used} excited frames"
                if mc.phase_from != "time"
                else f"phase from time over {mc.n_frames_used} frames"
            )
            print(
                f"motion {mc.motion}: cycle of {mc.cycle.n_frames} frames from frames "
                f"{m.start_frame + mc.start}:{m.start_frame + mc.stop} ({how}), loop closure "
                f"{mc.loop_closure:.2f} -> {path}"
            )
            if mc.largest_step > MAX_POP:
                print(
                    f"  warning: the cycle jumps {mc.largest_step:.1f}x the capture's "
                    "99th-percentile step in one frame (its repetitions disagree there); look "
                    "at it, and try --bandwidth 2"
                )
            skating = skating_report(mc.cycle, feet=feet)
            print("  " + skating_line(skating))
            extracted.append(
                {
                    "motion": int(mc.motion),
                    "path": str(path),
                    "frames": int(mc.cycle.n_frames),
                    "source_frames": [m.start_frame + mc.start, m.start_frame + mc.stop],
                    "loop_closure": float(mc.loop_closure),
                    "largest_step": float(mc.largest_step),
                    "foot_skating": skating,
                }
            )
    if args.plot:
        _save_plots(res, args.plot, out)
    if args.report:
        payload = res.to_report()
        if args.extract:
            # the cycles written by --extract, with their foot skating (as extract's report)
            payload["extracted"] = extracted
        write_json(out.file(args.report), clean(payload))
        out.wrote(args.report)
    print("time: " + ", ".join(f"{k} {v:.3f}s" for k, v in res.timings.items()))
    return code


def _save_plots(res, folder: str, out: Outputs) -> None:
    """``detect --plot DIR``: barcode, coordinates with segments shaded, windows by motion."""
    from ..plot.figures import plot_barcode, plot_coordinate, plot_windows

    m = res.motion
    staged = out.folder(folder)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figs = {"barcode.png": plot_barcode(res.barcode)}
    if res.classes:
        coords = {f"class {c.index}": c.coordinate for c in res.classes if c.motion >= 0} or {
            f"class {c.index}": c.coordinate for c in res.classes[:4]
        }
        figs["coordinates.png"] = plot_coordinate(
            coords,
            start_frame=m.start_frame,
            segments=[
                (m.start_frame + s.start, m.start_frame + s.stop, f"motion {s.motion}")
                for s in res.segments
            ],
        )
    if res.windows:
        figs["windows.png"] = plot_windows(res)
    from ..io import atomic_write

    for name, fig in figs.items():
        with atomic_write(staged / name, "wb") as fh:
            fig.savefig(fh, format="png", dpi=100)
        plt.close(fig)
        out.wrote(Path(folder) / name)
