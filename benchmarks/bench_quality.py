"""Our cycle against what people do by hand (issue 12, item 7).

Run from a checkout::

    python benchmarks/bench_quality.py [--json rows.json] [--plot DIR] [--synthetic] [--no-progress]

For every shared walk, whole and windowed (69_01 whole and 200:450; 35_07, 35_08, 35_13,
35_16 whole -- they walk from their first frame, so no window is needed; 143_01 whole
and 0:96) and for the six labelled exercises of 13_29 (``../shared/data/labels/13_29.csv``),
the take (the whole capture or the window) is given to ``cyclecoord.extract`` with its
default options, and three cycles are measured on it:

* **ours** -- ``result.cycle``;
* **loop cut** -- :func:`cyclecoord.quality.reference.best_loop_cut` around the
  autocorrelation period (ours' when the autocorrelation has no peak);
* **average** -- :func:`cyclecoord.quality.reference.average_cycle`: the take cut at our
  phase's wraps, each piece time-normalised to the median piece length, averaged.

Figures (joint angles = every non-root channel, unwrapped; see
:mod:`cyclecoord.quality.cycle_quality`): period (frames) and its error against the
autocorrelation of the (used) frames (lags 0.3-5 s, first strong peak), jerk over the
loop cut's, the smallest ratio of a leg channel's range to the loop cut's, seam, coverage
(mean distance of every used frame to the cycle, degrees), foot skating over the take's,
root pitch/roll closure (degrees, median steps) and heading change per cycle.  Ours is
judged against the issue's targets (``TARGETS``) and gets PASS or FAIL with the failed
targets named.  When ``extract`` gains ``used_frames`` and a per-frame ``phase`` (NaN
outside the used frames) they are used; today's result has neither.

Times are CPU and wall seconds (the machine is shared: look at the load average printed);
nothing here asserts speed.  ``tests/quality/test_reference.py`` runs one small synthetic
case.
"""

from __future__ import annotations

import argparse
import csv
import datetime as _dt
import json
import math
import os
import subprocess
import sys
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

import cyclecoord as cc
from cyclecoord.errors import CycleCoordError, NoPeriodicMotionError
from cyclecoord.io import atomic_path, atomic_write
from cyclecoord.quality.cycle_quality import TARGETS, coverage, cycle_quality, foot_skating_speed, targets
from cyclecoord.quality.reference import (
    autocorrelation_period,
    average_cycle,
    best_loop_cut,
    joint_angles,
    used_mask,
    wrap_times,
)

#: ``../shared/data`` beside the checkout (real CMU captures; never copied into the repo).
DATA_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "data"

#: Longest lag of the reference autocorrelation, seconds (the exercises of 13_29 take up
#: to about 4 s a cycle; walks about 1.1 s, and the first strong peak is taken).
MAX_LAG = 5.0

#: Walks: (label, path under cmu/, window or None).
WALKS = [
    ("69_01", "69/69_01.amc", None),
    ("69_01", "69/69_01.amc", (200, 450)),
    ("35_07", "35/35_07.amc", None),
    ("35_08", "35/35_08.amc", None),
    ("35_13", "35/35_13.amc", None),
    ("35_16", "35/35_16.amc", None),
    ("143_01", "143/143_01.amc", None),
    ("143_01", "143/143_01.amc", (0, 96)),
]


@dataclass(frozen=True)
class Case:
    """One take: a name and the frames handed to ``extract`` (a whole capture or a window)."""

    name: str
    take: cc.Motion


def real_cases(data_dir: Path = DATA_DIR) -> tuple[list[Case], list[str]]:
    """The shared walks and the 13_29 exercises; also the reasons for anything skipped."""
    cases, skipped = [], []
    cmu = data_dir / "cmu"
    for label, rel, window in WALKS:
        path = cmu / rel
        if not path.is_file():
            skipped.append(f"{label}: {path} not found, skipped")
            continue
        m = cc.load(path)
        name = f"{label} " + ("whole" if window is None else f"{window[0]}:{window[1]}")
        cases.append(Case(name, m.window(window)))
    labels = data_dir / "labels" / "13_29.csv"
    amc = cmu / "13" / "13_29.amc"
    if labels.is_file() and amc.is_file():
        m = cc.load(amc)
        with open(labels, newline="") as fh:
            for row in csv.DictReader(fh):
                a, b = int(row["start_frame"]), int(row["stop_frame"])
                cases.append(Case(f"13_29 {row['activity']} {a}:{b}", m.window((a, b))))
    else:
        skipped.append(f"13_29: {amc} or {labels} not found, skipped")
    return cases, skipped


def synthetic_cases(n_frames: int = 400, period: float = 100.0, seed: int = 0) -> list[Case]:
    """One synthetic walk (:func:`cyclecoord.datasets.make_periodic_capture`)."""
    cap = cc.datasets.make_periodic_capture(
        n_frames=n_frames, period=period, noise=0.5, random_state=seed
    )
    return [Case(f"synthetic walk {n_frames} (P={period:g})", cap.motion)]


# --------------------------------------------------------------------- one take
def _phase_of(result: Any) -> np.ndarray | None:
    """Per-frame phase in [0, 1) with NaN outside the used frames when the result has one."""
    for name in ("phase", "coordinate"):
        value = getattr(result, name, None)
        if value is not None and np.ndim(value) == 1:
            return np.asarray(value, dtype=float)
    return None


def _used_of(result: Any) -> list | None:
    used = getattr(result, "used_frames", None)
    return None if used is None else [[int(a), int(b)] for a, b in used]


def _take_skating(take: cc.Motion, used: list | None) -> float:
    """The take's own foot skating (units/s), over the used ranges weighted by length."""
    if used is None:
        return foot_skating_speed(take)
    values = [(foot_skating_speed(take[a:b]), b - a) for a, b in used]
    values = [(v, n) for v, n in values if np.isfinite(v)]
    return (
        float(sum(v * n for v, n in values) / sum(n for _, n in values)) if values else float("nan")
    )


def _coverage_outside(take: cc.Motion, clip: cc.Motion, used: list | None, start: int, stop: int) -> float:
    """Coverage (degrees) of the used frames of ``take`` outside ``start:stop``."""
    mask = used_mask(take.n_frames, used)
    take_x = joint_angles(take)
    cyc_x = joint_angles(clip, like=take_x[mask].mean(axis=0))
    mask[int(start) : int(stop)] = False
    return coverage(take_x, cyc_x, mask) if mask.any() else float("nan")


def run_case(case: Case, plot_dir: Path | None = None, bandwidth: float | None = None) -> dict:
    """Extract, build the references and measure all three cycles of one take; with
    ``plot_dir``, also draw them (:func:`plot_cycles`); ``bandwidth`` (frames) is handed to
    ``extract`` (None: its default)."""
    take = case.take
    clips: dict[str, cc.Motion] = {}
    row: dict[str, Any] = {"take": case.name, "frames": take.n_frames, "fps": take.fps}
    c0, w0 = time.process_time(), time.perf_counter()
    result = None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            options = {} if bandwidth is None else {"bandwidth": bandwidth}
            result = cc.extract(take, **options)
        row["status"] = "ok"
        row["warnings"] = list(result.warnings)
    except NoPeriodicMotionError as exc:
        row["status"] = "refused"
        row["reason"] = str(exc)
    row["extract_cpu"] = time.process_time() - c0
    row["extract_wall"] = time.perf_counter() - w0
    used = _used_of(result) if result is not None else None
    row["used_frames"] = used
    ac = autocorrelation_period(take, used_frames=used, max_lag=MAX_LAG)
    row["autocorrelation_period"] = ac
    skate_take = _take_skating(take, used)
    methods: dict[str, Any] = {}
    cut_period = (
        ac if np.isfinite(ac) else (result.period_frames if result is not None else float("nan"))
    )
    ref = None
    if np.isfinite(cut_period):
        try:
            cut = best_loop_cut(take, cut_period, used_frames=used)
            q = cycle_quality(
                cut.clip,
                take,
                method="loop cut",
                reference_period=ac,
                used_frames=used,
                skating_take=skate_take,
            )
            ref = cycle_quality(
                cut.clip,
                take,
                method="loop cut",
                reference_period=ac,
                reference=q,
                used_frames=used,
                skating_take=skate_take,
            )
            ref.extra.update(start=cut.start, stop=cut.stop, pose_distance=cut.distance)
            methods["loop cut"] = ref
            clips["loop cut"] = cut.clip
        except CycleCoordError as exc:
            row["loop_cut_error"] = str(exc)
    if result is not None:
        methods["ours"] = cycle_quality(
            result.cycle,
            take,
            method="ours",
            period_frames=result.period_frames,
            reference_period=ac,
            reference=ref,
            used_frames=used,
            skating_take=skate_take,
        )
        clips["ours"] = result.cycle
        phase = _phase_of(result)
        pieces = (
            [b - a for w in wrap_times(phase) for a, b in zip(w[:-1], w[1:])]
            if phase is not None
            else []
        )
        if pieces:
            avg = average_cycle(take, phase, int(round(float(np.median(pieces)))))
            q = cycle_quality(
                avg,
                take,
                method="average",
                period_frames=float(np.mean(pieces)),
                reference_period=ac,
                reference=ref,
                used_frames=used,
                skating_take=skate_take,
            )
            q.extra["pieces"] = len(pieces)
            methods["average"] = q
            clips["average"] = avg
        else:
            row["average_error"] = "our phase wraps fewer than twice: no complete piece to average"
    if ref is not None:
        # coverage of the used frames outside the loop cut: the cut covers its own frames at
        # distance 0 (a third to a half of a short take's), which no average can
        for name, q in methods.items():
            q.extra["cover_outside_cut"] = _coverage_outside(
                take, clips[name], used, ref.extra["start"], ref.extra["stop"]
            )
    row["methods"] = {k: v.to_dict() for k, v in methods.items()}
    if "ours" in methods:
        row["targets"] = targets(methods["ours"])
    if plot_dir is not None and clips:
        slug = "".join(ch if ch.isalnum() else "_" for ch in case.name)
        row["figure"] = str(
            plot_cycles(take, clips, Path(plot_dir) / f"quality_{slug}.png", case.name)
        )
    return row


#: Leg channels drawn by :func:`plot_cycles` (those present).
PLOT_CHANNELS = ("lfemur.rx", "rfemur.rx", "ltibia.rx", "rtibia.rx", "lfoot.rx", "rtoes.rx")


def plot_cycles(take: cc.Motion, clips: dict, path: Path, title: str = "", n: int = 200) -> Path:
    """Leg channels over one cycle for every clip, resampled to ``n`` points of the cycle
    and turned (circularly) to best match the loop cut (or the first clip); PNG at ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cyclecoord.quality.reference import joint_angles, joint_columns

    mean = joint_angles(take).mean(axis=0)
    names = ["{}.{}".format(*take.channels[c]) for c in joint_columns(take)]

    def resample(m: cc.Motion) -> np.ndarray:
        x = joint_angles(m, like=mean)
        t = np.arange(n) * len(x) / n
        k = np.floor(t).astype(int)
        f = (t - k)[:, None]
        return (1 - f) * x[k] + f * x[(k + 1) % len(x)]

    curves = {k: resample(m) for k, m in clips.items()}
    ref = curves.get("loop cut", next(iter(curves.values())))
    for k, c in curves.items():
        shift = int(np.argmin([np.linalg.norm(np.roll(c, -s, axis=0) - ref) for s in range(n)]))
        curves[k] = np.roll(c, -shift, axis=0)
    shown = [c for c in PLOT_CHANNELS if c in names]
    fig, axes = plt.subplots(2, 3, figsize=(14, 7))
    phase = np.arange(n) / n
    for ax, name in zip(axes.ravel(), shown):
        i = names.index(name)
        for (k, c), style in zip(curves.items(), ("-", "--", ":")):
            ax.plot(phase, c[:, i], style, label=f"{k} ({clips[k].n_frames} frames)")
        ax.set_title(name)
        ax.set_xlabel("fraction of the cycle (turned to match the loop cut)")
        ax.set_ylabel("degrees")
    for ax in axes.ravel()[len(shown) :]:
        ax.set_visible(False)
    axes.ravel()[0].legend()
    fig.suptitle(f"{title}: leg channels over one cycle")
    fig.tight_layout()
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=70)
    plt.close(fig)
    return path


# ------------------------------------------------------------------------ run
def _git_state() -> str | None:
    root = Path(__file__).resolve().parents[1]
    try:
        head = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"],
            cwd=root,
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            cwd=root,
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return head + ("+dirty" if dirty else "")


def _load() -> list[float] | None:
    return [round(v, 2) for v in os.getloadavg()] if hasattr(os, "getloadavg") else None


def run_benchmark(
    cases: Sequence[Case],
    progress: bool = True,
    skipped: Sequence[str] = (),
    plot_dir: Path | None = None,
    bandwidth: float | None = None,
) -> dict:
    """Every case; returns ``{"machine", "skipped", "rows", "cpu_seconds", "wall_seconds"}``."""
    machine = {
        "date": _dt.datetime.now().astimezone().isoformat(timespec="seconds"),
        "cyclecoord": cc.__version__,
        "git": _git_state(),
        "load_average_start": _load(),
        "bandwidth": bandwidth,
        "cpus": len(os.sched_getaffinity(0))
        if hasattr(os, "sched_getaffinity")
        else os.cpu_count(),
    }
    c0, w0 = time.process_time(), time.perf_counter()
    rows = []
    it = cases
    if progress:
        from tqdm import tqdm

        it = tqdm(cases, desc="takes", unit="take", file=sys.stderr)
    for case in it:
        rows.append(run_case(case, plot_dir, bandwidth))
    machine["load_average_end"] = _load()
    return {
        "machine": machine,
        "targets": TARGETS,
        "skipped": list(skipped),
        "rows": rows,
        "cpu_seconds": time.process_time() - c0,
        "wall_seconds": time.perf_counter() - w0,
    }


# ---------------------------------------------------------------------- print
def _f(x: Any, fmt: str = "{:.2f}") -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else fmt.format(x)


def _table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    widths = [
        max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(headers)
    ]
    out = [
        "  ".join(
            h.ljust(w) if i < 2 else h.rjust(w) for i, (h, w) in enumerate(zip(headers, widths))
        )
    ]
    out.append("  ".join("-" * w for w in widths))
    for r in rows:
        out.append(
            "  ".join(
                c.ljust(w) if i < 2 else c.rjust(w) for i, (c, w) in enumerate(zip(r, widths))
            )
        )
    return "\n".join(out)


HEADERS = [
    "take",
    "cycle",
    "period",
    "err%",
    "jerk/cut",
    "leg/cut",
    "low leg",
    "joint/cut",
    "low joint",
    "fem/tib",
    "seam",
    "p90/p10",
    "pop",
    "cover",
    "cover out",
    "skate/take",
    "root deg",
    "root st",
    "head",
    "verdict",
]


def _verdict(row: dict) -> str:
    t = row.get("targets")
    if not t:
        return "-"
    failed = [k for k, v in t.items() if v is False]
    missing = [k for k, v in t.items() if v is None]
    out = "PASS" if not failed else "FAIL " + ",".join(failed)
    return out + (f" (n/a {','.join(missing)})" if missing else "")


def table_rows(report: dict) -> list[list[str]]:
    """One line per (take, cycle) for :func:`format_report`."""
    lines = []
    for row in report["rows"]:
        first = True
        name = f"{row['take']} ({row['frames']}f, ac {_f(row['autocorrelation_period'], '{:.1f}')})"
        if row["status"] == "refused":
            lines.append([name, "ours", "refused"] + ["-"] * (len(HEADERS) - 3))
            first = False
        for method in ("ours", "loop cut", "average"):
            q = row["methods"].get(method)
            if q is None:
                continue
            err = q["period_error"]
            lines.append(
                [
                    name if first else "",
                    method,
                    _f(q["period_frames"], "{:.1f}"),
                    _f(None if err is None else 100 * err, "{:+.1f}"),
                    _f(q["jerk_ratio"]),
                    _f(q["min_leg_range_ratio"]),
                    q["min_leg_channel"] or "-",
                    _f(q["min_joint_range_ratio"]),
                    q["min_joint"] or "-",
                    _f(q["min_femur_tibia_ratio"]),
                    _f(q["seam"]),
                    _f(q["step_spread"], "{:.1f}"),
                    _f(q.get("largest_step")),
                    _f(q["coverage"]),
                    _f(q.get("extra", {}).get("cover_outside_cut")),
                    _f(q["skating_ratio"]),
                    _f(q["root_closure_degrees"]),
                    _f(q["root_closure_steps"], "{:.1f}"),
                    _f(q["heading_change"], "{:+.1f}"),
                    _verdict(row) if method == "ours" else "",
                ]
            )
            first = False
    return lines


def format_report(report: dict) -> str:
    m = report["machine"]
    lines = [
        f"cyclecoord {m['cyclecoord']} (git {m['git'] or 'unknown'})  {m['date']}  "
        f"cpus={m['cpus']}  "
        f"load average {m['load_average_start']} -> {m['load_average_end']}"
        + (f"  our bandwidth {m['bandwidth']} frames" if m.get("bandwidth") else ""),
        *report["skipped"],
        _table(HEADERS, table_rows(report)),
        "",
        "period: frames (ours: result.period_frames; loop cut: its length; average: mean piece);",
        "joint/cut: smallest ratio over leg joints of the joint's range of motion (all its dofs,\n"
        "1-2 frame marker spikes removed by a 5-frame running median; the 'legs' target);\n"
        "err%: vs the autocorrelation (ac) of the used frames; jerk/cut, leg/cut (smallest ratio",
        "of a leg channel's range, channel named), fem/tib (the same over femur and tibia only):",
        "over the loop cut's; p90/p10: spread of the cycle's frame steps (hold-and-snap; no",
        "target); pop: the cycle's largest step over the take's 99th-percentile step (no\n"
        "target; above about 1.3 a jump the capture hardly makes); cover: mean distance of the used frames to the cycle (deg); cover out: the same",
        "over the used frames outside the loop cut (no target); skate/take: foot",
        "skating over the take's; root deg / st: root pitch+roll last-to-first (deg / median",
        "steps); head: heading turn per cycle (deg).",
        "targets: " + ", ".join(f"{k} {v}" for k, v in TARGETS.items()),
    ]
    for row in report["rows"]:
        if row["status"] == "refused":
            lines.append(f"{row['take']}: refused: {row['reason']}")
        if row["autocorrelation_period"] is None or not np.isfinite(row["autocorrelation_period"]):
            lines.append(
                f"{row['take']}: no autocorrelation peak of r >= 0.3 at 0.3-{MAX_LAG:g} s: "
                "no reference period"
            )
        for key in ("loop_cut_error", "average_error"):
            if key in row:
                lines.append(f"{row['take']}: {key.replace('_', ' ')}: {row[key]}")
    ext_cpu = sum(r["extract_cpu"] for r in report["rows"])
    ext_wall = sum(r["extract_wall"] for r in report["rows"])
    lines.append(
        f"time: {report['cpu_seconds']:.1f} s CPU, {report['wall_seconds']:.1f} s wall in all "
        f"(extract {ext_cpu:.1f} s CPU, {ext_wall:.1f} s wall); the machine is shared: "
        "see the load average"
    )
    return "\n".join(lines)


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(float(x)) else None
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns the exit status (0; 1 when a take errored)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", metavar="PATH", help="also write every row as JSON")
    ap.add_argument(
        "--data", type=Path, default=DATA_DIR, help=f"shared data folder (default {DATA_DIR})"
    )
    ap.add_argument(
        "--synthetic", action="store_true", help="one synthetic walk instead of the real takes"
    )
    ap.add_argument("--no-progress", action="store_true", help="no progress bar")
    ap.add_argument(
        "--bandwidth",
        type=float,
        metavar="FRAMES",
        help="kernel width of our cycle in frames of time (extract's --bandwidth; default "
        "its own, 1 frame): smaller keeps more of the capture's detail (coverage) at the "
        "cost of jerk and pops",
    )
    ap.add_argument(
        "--plot", metavar="DIR", type=Path, help="draw leg channels of the three cycles per take"
    )
    args = ap.parse_args(argv)
    if args.json:
        out = Path(args.json)
        if not (out.parent if str(out.parent) else Path(".")).is_dir():
            ap.error(f"--json: folder {out.parent} does not exist")
    if args.plot is not None and not args.plot.is_dir():
        ap.error(f"--plot: folder {args.plot} does not exist")
    if args.synthetic:
        cases, skipped = synthetic_cases(), []
    else:
        cases, skipped = real_cases(args.data)
        if not cases:
            skipped.append("no real takes found: running the synthetic walk")
            cases = synthetic_cases()
    report = run_benchmark(
        cases,
        progress=not args.no_progress,
        skipped=skipped,
        plot_dir=args.plot,
        bandwidth=args.bandwidth,
    )
    print(format_report(report), flush=True)
    if args.json:
        with atomic_write(args.json, "w") as fh:
            json.dump(_jsonable(report), fh, indent=2)
            fh.write("\n")
        print(f"rows written to {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
