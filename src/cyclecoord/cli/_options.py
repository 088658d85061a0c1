"""Exit codes, argument types and option groups shared by the subcommands of ``cyclecoord``."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..errors import ParameterError

EXIT_OK, EXIT_ERROR, EXIT_USAGE, EXIT_NO_PERIODIC = 0, 1, 2, 3

#: Every format cyclecoord reads and writes, as the help texts list them.
FORMATS = "ASF/AMC, BVH, NPZ, CSV, glTF (.glb/.gltf) and USD (.usda/.usdc/.usd)"

#: Help of the INPUT argument of the commands that read one capture.
INPUT_HELP = (
    "capture to read: .amc (its .asf found beside it), .bvh, .npz, .csv, .glb/.gltf or "
    ".usda/.usdc/.usd, or 'example' (example:jog, example:chain, example:take, ...) for a "
    "built-in synthetic capture"
)


def frame_range(text: str) -> tuple[int | None, int | None]:
    """Parse ``A:B`` (0-based, half-open; either side may be empty)."""
    if ":" not in text:
        raise argparse.ArgumentTypeError(f"expected A:B (0-based, half-open), got {text!r}")
    a, b = text.split(":", 1)
    try:
        start = int(a) if a.strip() else None
        stop = int(b) if b.strip() else None
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"frame range must be integers A:B, got {text!r}"
        ) from None
    if start is not None and start < 0 or stop is not None and stop < 0:
        raise argparse.ArgumentTypeError(f"frame numbers must be >= 0, got {text!r}")
    if start is not None and stop is not None and start >= stop:
        raise argparse.ArgumentTypeError(
            f"frame range {text!r} is reversed or empty: A:B means frames A to B-1, so A must be "
            f"below B (e.g. {min(start, stop)}:{max(start, stop) + (start == stop)})"
        )
    return start, stop


def positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"expected a number >= 1, got {v}")
    return v


def bandwidth(text: str) -> str | float:
    if text == "auto":
        return text
    try:
        return positive_float(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(
            f"expected 'auto' or a positive number of frames, got {text!r}"
        ) from None


def positive_float(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not np.isfinite(v) or v <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return v


def delay(text: str) -> str | float | None:
    if text == "auto":
        return "auto"
    v = _nonnegative_float(text)
    return v or None


def _nonnegative_float(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a number of seconds or 'auto', got {text!r}"
        ) from None
    if not np.isfinite(v) or v < 0:
        raise argparse.ArgumentTypeError(
            f"expected a number of seconds >= 0 or 'auto', got {text!r}"
        )
    return v


def landmarks(text: str) -> int | str | None:
    t = text.strip().lower()
    if t in ("auto",):
        return "auto"
    if t in ("none", "all", "full"):
        return None
    try:
        v = int(t)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a number, 'auto' or 'none', got {text!r}"
        ) from None
    if v < 10:
        raise argparse.ArgumentTypeError(f"need at least 10 landmarks, got {v}")
    return v


def byte_size(text: str) -> float:
    """Parse sizes such as 2G, 500M, 1.5GB or a plain number of bytes."""
    t = text.strip().upper().rstrip("B")
    mult = {"K": 1024, "M": 1024**2, "G": 1024**3, "T": 1024**4}
    try:
        if t and t[-1] in mult:
            v = float(t[:-1]) * mult[t[-1]]
        else:
            v = float(t)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a size such as 2G or 500M, got {text!r}"
        ) from None
    if not np.isfinite(v) or v <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive size, got {text!r}")
    return v


def units(text: str) -> str | float:
    """Parse ``--units``: ``auto``, ``m``, ``cm``, ``mm``, ``in`` or metres per unit."""
    from ..rig import parse_units

    try:
        value = parse_units(text)
    except ParameterError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return "auto" if value is None else (text.strip().lower() if text.strip().isalpha() else value)


def add_units_option(g: argparse._ActionsContainer) -> None:
    """``--units``: the capture's length unit, for every command that reads captures."""
    g.add_argument(
        "--units",
        type=units,
        default="auto",
        metavar="auto|m|cm|mm|in|M",
        help="length unit of the capture: auto (default: an ASF's own :units length, "
        "otherwise guessed from the body's height), m, cm, mm, in, or M metres per unit; "
        "reported on the first line and used to write glTF and USD in metres",
    )


def export_units(args: argparse.Namespace, path: str | None) -> dict:
    """Keyword arguments of :func:`cyclecoord.io.save` that carry ``--units`` to a glTF or
    USD output (none for ``auto``, where the writer measures the unit itself)."""
    from ..rig import parse_units

    mpu = parse_units(getattr(args, "units", "auto"))
    if mpu is None or not path:
        return {}
    suffix = Path(path).suffix.lower()
    if suffix in (".glb", ".gltf"):
        return {"scale": mpu}
    if suffix in (".usda", ".usdc", ".usd"):
        return {"meters_per_unit": mpu}
    return {}


def rig_line(motion, args: argparse.Namespace | None = None) -> str:
    """The console's first line: the rig found (:func:`cyclecoord.rig.rig_summary`), with
    ``--units`` when the command has it."""
    from ..rig import rig_summary

    return rig_summary(motion, getattr(args, "units", "auto") if args is not None else "auto")


def add_selection_options(
    p: argparse.ArgumentParser,
    title: str = "what to analyse and how",
    per_file: bool = True,
) -> argparse._ArgumentGroup:
    """The options that choose what is analysed and how, in one group (returned).

    ``per_file=False`` (batch: the same options for every capture) leaves out the ones
    that belong to one input: ``--skeleton``, ``--frames`` and ``--no-root-diff``.
    """
    g = p.add_argument_group(title)
    if per_file:
        g.add_argument(
            "--skeleton",
            metavar="ASF",
            help="ASF skeleton for an AMC input (default: found beside the AMC)",
        )
        g.add_argument(
            "--frames",
            type=frame_range,
            metavar="A:B",
            help="0-based half-open frame range, e.g. 200:450",
        )
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
        "--rotations",
        choices=("auto", "rotvec", "euler"),
        default="auto",
        help="how joint rotations enter the analysis: rotation vectors about each joint's mean "
        "(rotvec: Euler wraps and flips change nothing), the Euler channels as written (euler: "
        "the paper's space), or rotation vectors only for joints whose Euler channels wrap, "
        "flip or near gimbal lock (auto, default: CMU reads as in the paper)",
    )
    g.add_argument(
        "--temporal",
        action="store_true",
        help="time-aware metric: consecutive frames at distance 0",
    )
    if per_file:
        g.add_argument(
            "--no-root-diff",
            action="store_true",
            help="keep root translation/orientation as they are",
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
        help="build the filtration on N greedy landmarks and extend the coordinate to every frame "
        "(auto: every frame up to 1000 frames, 500 landmarks beyond; none: every frame)",
    )
    g.add_argument(
        "--memory-limit",
        type=byte_size,
        default=None,
        metavar="SIZE",
        help="memory for the run's large arrays, e.g. 500M: per-frame arrays and the filtration, "
        "whose landmarks are reduced to fit (default: 2G for the filtration alone; never more "
        "than the machine has)",
    )
    return g


def add_memory_option(g: argparse._ActionsContainer) -> None:
    """``--memory-limit`` of a command that reads captures, models or scripts and makes
    frames: what reading and generating may allocate (default: what the machine allows)."""
    g.add_argument(
        "--memory-limit",
        type=byte_size,
        default=None,
        metavar="SIZE",
        help="memory the command may use for its inputs and the frames it makes, e.g. 2G: "
        "an input, a frame count or a duration that would need more is refused before "
        "anything is allocated (default: what the machine allows)",
    )


def add_cycle_options(g: argparse._ArgumentGroup) -> None:
    """Options of the typical cycle, the same on extract, detect --extract and batch."""
    g.add_argument(
        "--no-steady",
        dest="steady",
        action="store_false",
        help="build the cycle from every frame (default: only the steady stretches of the take, "
        "leaving out standing, starting, turning and stopping)",
    )
    g.add_argument(
        "--timing",
        choices=("capture", "coordinate"),
        default="capture",
        help="capture (default): the cycle moves at the capture's pace (phase re-timed between "
        "the coordinate's crossings and aligned by time warping); coordinate: the paper's "
        "density-sampled coordinate (--samples, --neighbors, --weighting, --sampling)",
    )
    g.add_argument(
        "--travel",
        choices=("keep", "straight", "in_place"),
        default="keep",
        help="the cycle's root: travel and turn as captured on average (keep, default), walk "
        "along a line (straight: the heading change per cycle removed) or stay in place",
    )
    g.add_argument(
        "--min-turns",
        type=positive_float,
        default=1.5,
        metavar="N",
        help="fewer turns of the coordinate over the steady frames is no periodic motion, exit 3 "
        "(1.5)",
    )
    g.add_argument(
        "--bandwidth",
        type=bandwidth,
        default=None,
        metavar="auto|F",
        help="width of the average that builds the cycle, in frames of time: a number fixes it "
        "(default 1 with --timing capture), 'auto' picks it by leave-one-out cross-validation",
    )
    g.add_argument(
        "--cycle-start",
        choices=("slowest", "first"),
        default="slowest",
        help="begin the cycle at its slowest pose (default, hides the loop seam) or at phase 0",
    )


def cycle_options(args: argparse.Namespace) -> dict:
    """The typical-cycle keyword arguments of :func:`extract` from parsed options."""
    return {
        "steady": args.steady,
        "timing": args.timing,
        "travel": args.travel,
        "min_turns": args.min_turns,
        "bandwidth": args.bandwidth,
        "cycle_start": args.cycle_start,
    }


#: Help of ``--feet``, the same on every command that finds foot contacts.
FEET_HELP = (
    "foot joints: LEFT,RIGHT (four names for a quadruped), each a joint or ANKLE:TOE for both "
    "points of a leg, e.g. Foot_L,Foot_R or lfoot:ltoes,rfoot:rtoes (default: found by joint "
    "name on the common rigs, else as the lowest ends of two leg chains)"
)


def add_feet_option(g) -> None:
    """``--feet LEFT,RIGHT`` on a parser or group."""
    g.add_argument("--feet", metavar="LEFT,RIGHT", help=FEET_HELP)


def feet_option(args: argparse.Namespace, motion) -> tuple[str, ...] | None:
    """The foot points ``--feet`` names, checked on ``motion``'s skeleton (None: not given).

    Raises
    ------
    ParameterError
        A name that is not a joint (with the nearest names), or a motion without a
        skeleton.
    """
    from ..quality.legs import resolve_feet

    spec = getattr(args, "feet", None)
    if not spec:
        return None
    if motion.skeleton is None:
        raise ParameterError(
            f"--feet: {motion.source or 'the input'} has no skeleton (forward kinematics)"
        )
    return resolve_feet(motion.skeleton, spec)


def check_output(path: str | None, what: str = "output") -> None:
    """Fail fast, before any computation, on an output we could not write."""
    if not path:
        return
    from ..io import SUPPORTED_FORMATS

    out = Path(path)
    if what == "output" and out.suffix.lower() not in SUPPORTED_FORMATS:
        raise ParameterError(
            f"{path}: unknown output format {out.suffix or '(no suffix)'!r}; use one "
            f"of {', '.join(SUPPORTED_FORMATS)}"
        )
    if what == "report" and out.suffix.lower() != ".json":
        raise ParameterError(f"{path}: the report is JSON; give it a .json name")
    if what == "model" and out.suffix.lower() != ".npz":
        raise ParameterError(f"{path}: a model is saved as .npz; give it a .npz name")
    folder = out.parent if str(out.parent) else Path(".")
    if not folder.is_dir():
        raise ParameterError(f"{path}: folder {folder} does not exist")


def named(path: object, exc: BaseException) -> str:
    """The error's message, led by the input's name when it does not name it already."""
    text = str(exc)
    if isinstance(path, str) and path and path not in text and Path(path).name not in text:
        return f"{path}: {text}"
    return text
