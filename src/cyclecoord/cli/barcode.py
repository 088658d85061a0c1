"""``cyclecoord barcode``: the H0/H1 barcode of a capture."""

from __future__ import annotations

import argparse
import json

from ._options import INPUT_HELP, EXIT_OK, add_selection_options
from ._outputs import capture_inputs, declare
from .report import clean, load_input, summary_barcode


def add_parser(subparsers) -> argparse.ArgumentParser:
    b = subparsers.add_parser(
        "barcode",
        help="print the H0/H1 barcode of a capture",
        description="Vietoris-Rips persistent cohomology barcode (H0, H1) of the prepared poses.",
    )
    b.add_argument("input", metavar="INPUT", help=INPUT_HELP)
    add_selection_options(b)
    b.add_argument(
        "--json",
        action="store_true",
        help="print JSON ({'h0': [[b, d], ...], 'h1': ...}; d null = infinite)",
    )
    b.set_defaults(func=cmd_barcode)
    declare(b, inputs=capture_inputs())  # prints; writes no file
    return b


def cmd_barcode(args: argparse.Namespace) -> int:
    from ..periodic.preprocess import Preprocessor

    motion = load_input(args.input, args.skeleton, args.fps)
    motion = motion.window(args.frames)
    prep = Preprocessor(
        difference_root=not args.no_root_diff, normalize=args.normalize, pca=args.pca,
        rotations=args.rotations,
    )
    pts = prep.fit_transform(motion).points
    from ..periodic.coordinates import CircularCoordinates

    est = CircularCoordinates(
        max_scale=args.max_scale,
        prime=args.prime,
        temporal=args.temporal,
        landmarks=args.landmarks,
        **({} if args.memory_limit is None else {"memory_limit": args.memory_limit}),
    )
    bc = est.fit_barcode(pts)
    if args.json:
        payload = {
            "threshold": bc.threshold,
            "prime": bc.prime,
            "n_points": bc.n_points,
            "landmarks": est.landmark_reason_,
            **bc.to_dict(),
        }
        print(json.dumps(clean(payload)))
    else:
        print(summary_barcode(bc))
    return EXIT_OK
