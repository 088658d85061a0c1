"""The ``cyclecoord`` command line: subcommands over the library, JSON reports, exit codes.

Exit codes: 0 success, 1 bad input or failure (one-line message, no traceback),
2 usage error, 3 no periodic motion found (the report is still written), 130 interrupted
by Ctrl-C (atomic writes leave no partial file).
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from ..errors import CycleCoordError
from ..io._limits import memory_limit
from ._options import FORMATS, EXIT_ERROR, EXIT_NO_PERIODIC, EXIT_OK, EXIT_USAGE, named
from ._outputs import check_paths

__all__ = [
    "COMMAND_MODULES",
    "EXIT_ERROR",
    "EXIT_NO_PERIODIC",
    "EXIT_OK",
    "EXIT_USAGE",
    "build_parser",
    "main",
]


#: Subcommands that live in a module of their own under ``cyclecoord.cli``: each module has
#: ``add_parser(subparsers)``, which adds its parser, sets ``func`` to the function that
#: runs it (taking the parsed arguments, returning the exit code) and declares what it
#: reads and writes (:func:`cyclecoord.cli._outputs.declare`; :func:`main` refuses an output
#: that names an input before running it).  Modules must import their heavy dependencies
#: inside that function so ``cyclecoord --help`` stays fast.
COMMAND_MODULES: tuple[str, ...] = (
    "extract",
    "barcode",
    "convert",
    "detect",
    "render",
    "blend",  # blend and transition
    "batch",
    "view",
    "feet",
    "graph",
    "latent",
    "animate",
)


def build_parser() -> argparse.ArgumentParser:
    """The ``cyclecoord`` parser: top-level options and every module of ``COMMAND_MODULES``."""
    p = argparse.ArgumentParser(
        prog="cyclecoord",
        description=(
            "Find, parameterise and reuse periodic motion in motion capture with persistent "
            "cohomology. INPUT is an .amc (skeleton found beside it), .bvh, .npz, .csv, glTF "
            "(.glb/.gltf) or USD (.usda/.usdc/.usd) file, or 'example' for the built-in synthetic "
            "walk (example:jog, example:chain, example:take, ...). Motions are written as "
            f"{FORMATS}, chosen by the output's suffix."
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=(
            "examples:\n"
            "  cyclecoord extract example -o walk_cycle.bvh --report report.json\n"
            "  cyclecoord extract 69_01.amc --frames 200:450 --max-scale 50 -o cycle.bvh\n"
            "  cyclecoord barcode 69_01.amc --frames 200:450 --json\n"
            "  cyclecoord convert 69_01.amc -o 69_01.bvh\n"
            "  cyclecoord extract 69_01.amc --frames 200:450 --max-scale 50 -o cycle.bvh "
            "--plot figures\n"
            "  cyclecoord render 69_01.amc --frames 200:450 -o walk.gif --side-by-side cycle.bvh\n"
            "  cyclecoord blend 69_01.amc 143_01.amc --window 200:450 --window 0:96 "
            "--max-scale 50 \\\n"
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

    for name in COMMAND_MODULES:
        importlib.import_module(f".{name}", __package__).add_parser(sub)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command line; returns the exit code (errors become one line on stderr)."""
    try:  # a Ctrl-C anywhere in it is one line (also while the parser imports the commands,
        # and while the paths are checked: CI once caught one there, a traceback)
        return _run(argv)
    except KeyboardInterrupt:
        print("cyclecoord: interrupted", file=sys.stderr)
        return 130


def _run(argv: Sequence[str] | None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "command", None):
        parser.print_help()
        return EXIT_USAGE
    try:
        check_paths(args)  # no output may name an input: refused before anything runs
    except CycleCoordError as exc:  # names the output, its option and the input already
        print(f"cyclecoord: error: {exc}", file=sys.stderr)
        return EXIT_ERROR
    try:
        # readers and generators refuse what would not fit (cyclecoord.io._limits)
        with memory_limit(getattr(args, "memory_limit", None)):
            return int(args.func(args))
    except CycleCoordError as exc:
        print(f"cyclecoord: error: {named(getattr(args, 'input', None), exc)}", file=sys.stderr)
        return EXIT_ERROR
    except FileNotFoundError as exc:
        print(f"cyclecoord: error: {exc}", file=sys.stderr)
        return EXIT_ERROR
    except PermissionError as exc:
        print(f"cyclecoord: error: {exc}", file=sys.stderr)
        return EXIT_ERROR
    except BrokenPipeError:  # output piped into `head` and the like
        import os

        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_OK


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
