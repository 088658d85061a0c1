"""``cyclecoord batch``: extract on every capture of a folder, locally or on Dask."""

from __future__ import annotations

import argparse

from ._options import (
    EXIT_ERROR,
    EXIT_OK,
    add_cycle_options,
    byte_size,
    cycle_options,
    landmarks,
    positive_float,
    positive_int,
)


def add_parser(subparsers) -> argparse.ArgumentParser:
    ba = subparsers.add_parser(
        "batch",
        help="run extract on every capture in a folder, locally or on a Dask cluster",
        description=(
            "Run extract on every capture under DIR (recursively; .amc, .bvh, .npz, .csv by "
            "default). OUTDIR mirrors DIR's tree: NAME.report.json and NAME.cycle.bvh per capture, "
            "and summary.csv with one row per capture (status ok / no_periodic / error and the key "
            "figures). A failing capture is recorded and the batch goes on. A re-run skips "
            "captures whose report matches the input's size, modification time and the options "
            "(errors are retried); --force recomputes. OUTDIR must lie outside DIR. Exit code 1 "
            "when any capture failed or none was found."
        ),
    )
    ba.add_argument("folder", metavar="DIR", help="folder of captures")
    ba.add_argument(
        "-o", "--output", required=True, metavar="OUTDIR", help="output folder (created if missing)"
    )
    w = ba.add_argument_group("where it runs")
    w.add_argument(
        "-j",
        "--jobs",
        type=int,
        default=1,
        metavar="N",
        help="worker processes (default 1: in this process; 0: one per CPU core)",
    )
    w.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on a Dask distributed cluster, e.g. tcp://host:8786 (needs cyclecoord[dask]; "
        "the workers must see DIR and OUTDIR at the same paths)",
    )
    w.add_argument(
        "--force", action="store_true", help="recompute captures whose report is up to date"
    )
    w.add_argument(
        "--pattern",
        action="append",
        metavar="GLOB",
        help="file-name glob, case-insensitive; repeat for several (default: *.amc *.bvh *.npz "
        "*.csv)",
    )
    w.add_argument(
        "--cycles",
        choices=("bvh", "npz", "none"),
        default="bvh",
        help="format of the cycle written per capture (default bvh; none: reports only)",
    )
    w.add_argument("--no-progress", action="store_true", help="no progress bar")
    g = ba.add_argument_group("what to analyse and how (the same for every capture)")
    g.add_argument(
        "--fps",
        type=positive_float,
        metavar="F",
        help="frame rate (AMC files carry none; default 120)",
    )
    g.add_argument(
        "--pca",
        type=positive_int,
        metavar="K",
        help="project poses onto K principal components first",
    )
    g.add_argument(
        "--normalize", action="store_true", help="scale each channel by its standard deviation"
    )
    g.add_argument(
        "--temporal",
        action="store_true",
        help="time-aware metric: consecutive frames at distance 0",
    )
    g.add_argument(
        "--prime",
        type=int,
        default=47,
        metavar="P",
        help="coefficient field Z/P, a prime > 11 (default 47)",
    )
    g.add_argument(
        "--max-scale",
        type=positive_float,
        metavar="E",
        help="Rips threshold in the analysed space's units (default: half the point cloud's "
        "diameter)",
    )
    g.add_argument(
        "--landmarks",
        type=landmarks,
        default="auto",
        metavar="N|auto|none",
        help="filtration on N greedy landmarks (auto: every frame up to 1000 frames, 500 beyond)",
    )
    g.add_argument(
        "--memory-limit",
        type=byte_size,
        default=None,
        metavar="SIZE",
        help="memory budget per capture for the filtration, e.g. 2G; above it landmarks are used",
    )
    g.add_argument("--seed", type=int, default=0, metavar="S", help="random seed (0)")
    add_cycle_options(ba.add_argument_group("the cycle (the same for every capture)"))
    ba.set_defaults(func=cmd_batch)
    return ba


def cmd_batch(args: argparse.Namespace) -> int:
    from ..batch import DEFAULT_PATTERNS, run_batch

    options = dict(
        pca=args.pca,
        normalize=args.normalize,
        temporal=args.temporal,
        prime=args.prime,
        max_scale=args.max_scale,
        landmarks=args.landmarks,
        random_state=args.seed,
        **({} if args.memory_limit is None else {"memory_limit": args.memory_limit}),
        **cycle_options(args),
    )
    summary = run_batch(
        args.folder,
        args.output,
        jobs=args.jobs,
        scheduler=args.scheduler,
        pattern=args.pattern or DEFAULT_PATTERNS,
        force=args.force,
        extract_options=options,
        write_cycles=None if args.cycles == "none" else args.cycles,
        fps=args.fps,
        progress=not args.no_progress,
    )
    print(summary.describe())
    return EXIT_ERROR if summary.n_error or not summary.rows else EXIT_OK
