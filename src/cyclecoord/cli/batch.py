"""``cyclecoord batch``: extract on every capture of a folder, locally or on Dask."""

from __future__ import annotations

import argparse

from ..batch import CYCLE_FORMATS
from ._options import (
    EXIT_ERROR,
    EXIT_OK,
    add_cycle_options,
    add_feet_option,
    add_selection_options,
    cycle_options,
)
from ._outputs import declare


def add_parser(subparsers) -> argparse.ArgumentParser:
    ba = subparsers.add_parser(
        "batch",
        help="run extract on every capture in a folder, locally or on a Dask cluster",
        description=(
            "Run extract on every capture under DIR (recursively; .amc, .bvh, .npz, .csv by "
            "default). OUTDIR mirrors DIR's tree: NAME.report.json and NAME.cycle.bvh (--cycles: "
            "another format) per capture, "
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
        choices=CYCLE_FORMATS + ("none",),
        default="bvh",
        help="format of the cycle written per capture, NAME.cycle.FORMAT, as extract -o writes "
        "it (default bvh; gltf adds NAME.cycle.bin; usda/usdc need usd-core; none: reports "
        "only)",
    )
    w.add_argument("--no-progress", action="store_true", help="no progress bar")
    g = add_selection_options(
        ba, "what to analyse and how (the same for every capture)", per_file=False
    )
    g.add_argument("--seed", type=int, default=0, metavar="S", help="random seed (0)")
    cyc = ba.add_argument_group("the cycle (the same for every capture)")
    add_cycle_options(cyc)
    add_feet_option(cyc)
    ba.set_defaults(func=cmd_batch)
    declare(
        ba,
        inputs=lambda a: (),
        # the captures are found by the scan: run_batch checks every capture's report and
        # cycle and the summary against every capture and its .asf (refuse_clobber)
        elsewhere={"-o": "cyclecoord.batch.run_batch"},
    )
    return ba


def cmd_batch(args: argparse.Namespace) -> int:
    from ..batch import DEFAULT_PATTERNS, run_batch

    options = dict(
        pca=args.pca,
        normalize=args.normalize,
        rotations=args.rotations,
        temporal=args.temporal,
        prime=args.prime,
        max_scale=args.max_scale,
        landmarks=args.landmarks,
        random_state=args.seed,
        **({} if args.memory_limit is None else {"memory_limit": args.memory_limit}),
        **({} if not args.feet else {"feet": args.feet}),
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
