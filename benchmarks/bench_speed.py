"""The paper's example end to end: warm in-process, with 100 landmarks, and from a cold process.

Three measurements on CMU 69_01 frames 200:450 at max scale 50 (the paper's Fig. 7), each
printed as wall seconds beside CPU seconds (this process's, or the child's), with the
machine's load average and the commit, so figures taken on a busy machine can be compared:

* **warm**: ``cc.extract`` in this process after one untimed call; the median of
  ``--repeat`` runs, per stage, and ripser's share of the total (the ``_rips`` call).
* **landmarks**: the same with ``landmarks=100`` (greedy max-min landmarks; the
  coordinate extended to every frame), against the full complex: the mean and largest
  circular phase difference after the best rotation, the bar's birth on the landmarks
  and the full-resolution birth the pipeline reports (``selection.full_birth``).
* **cold**: ``python -m cyclecoord extract ... -o OUT.bvh`` in a fresh process (bytecode
  already cached by one untimed run, as after an install), and the imports the command
  needs on their own.

Nothing is asserted; the issue's targets are printed with PASS/FAIL beside the figures.

    python benchmarks/bench_speed.py [--repeat 7] [--cold 5] [--json OUT]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from collections.abc import Sequence

import numpy as np

_HERE = Path(__file__).resolve().parent
if str(_HERE) not in sys.path:
    sys.path.insert(0, str(_HERE))

import bench_extract as bx

import cyclecoord as cc
from cyclecoord.io import atomic_write

FRAMES = (200, 450)
MAX_SCALE = 50.0
LANDMARKS = 100
#: Issue 17's targets (seconds; CPU seconds are compared where the machine is busy).
TARGET_WARM = 0.35
TARGET_RIPSER_SHARE = 0.8
TARGET_LANDMARKS = 0.1
TARGET_PHASE = 0.01
TARGET_BIRTH = 0.05
TARGET_COLD = 1.5
#: What `cyclecoord extract` imports, timed on their own in a fresh process.
COMMAND_IMPORTS = "import cyclecoord.cli.main, cyclecoord.io.asfamc, cyclecoord.periodic.pipeline"


def _timed(fn, repeat: int):
    """Median wall and CPU seconds of ``fn()`` over ``repeat`` runs after one warm-up."""
    out = fn()
    walls, cpus, runs = [], [], []
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
        runs.append(out)
    return statistics.median(walls), statistics.median(cpus), runs


def warm(motion: cc.Motion, repeat: int) -> dict:
    """The full-complex extract in this process; ripser's CPU share via a wrapped call."""
    from cyclecoord.periodic import _rips

    spent = []
    real = _rips.rips_cohomology

    def clocked(*a, **k):
        c0 = time.process_time()
        try:
            return real(*a, **k)
        finally:
            spent.append(time.process_time() - c0)

    _rips.rips_cohomology = clocked
    try:
        wall, cpu, runs = _timed(lambda: cc.extract(motion, frames=FRAMES, max_scale=MAX_SCALE), repeat)
    finally:
        _rips.rips_cohomology = real
    stages = {s: statistics.median(r.timings[s] for r in runs) for s in bx.STAGES}
    ripser_cpu = statistics.median(spent[1:]) if len(spent) > 1 else spent[0]
    return {"wall": wall, "cpu": cpu, "stages": stages, "ripser_cpu": ripser_cpu,
            "ripser_share": ripser_cpu / cpu if cpu > 0 else None, "result": runs[-1]}


def with_landmarks(motion: cc.Motion, full: cc.ExtractionResult, repeat: int) -> dict:
    """``landmarks=LANDMARKS`` against the full complex."""
    wall, cpu, runs = _timed(
        lambda: cc.extract(motion, frames=FRAMES, max_scale=MAX_SCALE, landmarks=LANDMARKS), repeat)
    r = runs[-1]
    diff = np.mod(r.coordinate - full.coordinate + 0.5, 1.0) - 0.5
    rot = float(np.angle(np.mean(np.exp(2j * np.pi * diff))) / (2 * np.pi))
    d = np.abs(np.mod(diff - rot + 0.5, 1.0) - 0.5)
    fb = r.selection.full_birth
    birth = full.selection.birth
    return {
        "wall": wall, "cpu": cpu, "landmarks": int(len(r.estimator.landmarks_)),
        "phase_mean": float(d.mean()), "phase_max": float(d.max()), "rotation": rot,
        "birth_full": float(birth), "birth_landmarks": float(r.selection.birth),
        "full_birth_reported": None if fb is None else float(fb),
        "birth_error": None if fb is None else abs(fb - birth) / birth,
        "period_full": float(full.period_frames), "period_landmarks": float(r.period_frames),
    }


def _child_seconds(cmd: list[str], env: dict) -> tuple[float, float]:
    """Wall and CPU (user + system) seconds of a child process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    w0 = time.perf_counter()
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - w0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def cold(path: Path, n: int) -> dict:
    """The command and its imports in fresh processes (median of ``n`` after one untimed run)."""
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # as installed: bytecode cached after the first run
    src = str(Path(cc.__file__).resolve().parents[1])
    env["PYTHONPATH"] = src + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    with tempfile.TemporaryDirectory(prefix="bench_speed_") as tmp:
        out = str(Path(tmp) / "cycle.bvh")
        cmd = [sys.executable, "-m", "cyclecoord", "extract", str(path), "--frames", f"{FRAMES[0]}:{FRAMES[1]}",
               "--max-scale", f"{MAX_SCALE:g}", "-o", out]
        imp = [sys.executable, "-c", COMMAND_IMPORTS]
        _child_seconds(cmd, env)
        runs = [_child_seconds(cmd, env) for _ in range(n)]
        imports = [_child_seconds(imp, env) for _ in range(n)]
    return {
        "command": " ".join(["cyclecoord"] + cmd[3:-1] + ["OUT.bvh"]),
        "wall": statistics.median(r[0] for r in runs), "cpu": statistics.median(r[1] for r in runs),
        "imports_wall": statistics.median(r[0] for r in imports),
        "imports_cpu": statistics.median(r[1] for r in imports),
    }


def _verdict(ok: bool | None) -> str:
    return {True: "PASS", False: "FAIL", None: "n/a"}[ok]


def format_report(rep: dict) -> str:
    m, w, lm, c = rep["machine"], rep["warm"], rep["landmarks"], rep["cold"]
    lines = [
        f"cyclecoord {m['cyclecoord']} (git {m.get('git') or 'unknown'})  {m['date']}  cpus={m['cpus']}",
        f"load average before {m['load_average']}, after {rep['load_after']}  "
        "(a busy machine stretches wall time; compare CPU seconds)",
        "",
        f"69_01 [{FRAMES[0]}:{FRAMES[1]}] max_scale={MAX_SCALE:g}, median of {rep['repeat']} warm runs",
        "  stages (wall s): " + "  ".join(f"{s} {w['stages'][s]:.3f}" for s in bx.STAGES),
        f"  warm full complex: wall {w['wall']:.3f} s, CPU {w['cpu']:.3f} s; ripser {w['ripser_cpu']:.3f} CPU-s = "
        f"{w['ripser_share']:.0%} of it",
        f"    {_verdict(w['cpu'] < TARGET_WARM)}: under {TARGET_WARM} s (CPU)   "
        f"{_verdict(w['ripser_share'] <= TARGET_RIPSER_SHARE)}: ripser at most {TARGET_RIPSER_SHARE:.0%}",
        f"  {lm['landmarks']} landmarks: wall {lm['wall']:.3f} s, CPU {lm['cpu']:.3f} s; phase vs full complex: "
        f"mean {lm['phase_mean']:.4f}, max {lm['phase_max']:.4f} cycles (after a rotation of {lm['rotation']:+.4f}); "
        f"birth on landmarks {lm['birth_landmarks']:.3f}, reported full-resolution birth "
        f"{lm['full_birth_reported']} vs {lm['birth_full']:.3f}; period {lm['period_landmarks']:.1f} vs "
        f"{lm['period_full']:.1f} frames",
        f"    {_verdict(lm['cpu'] < TARGET_LANDMARKS)}: under {TARGET_LANDMARKS} s (CPU)   "
        f"{_verdict(lm['phase_mean'] <= TARGET_PHASE)}: mean phase within {TARGET_PHASE}   "
        f"{_verdict(None if lm['birth_error'] is None else lm['birth_error'] <= TARGET_BIRTH)}: "
        f"birth within {TARGET_BIRTH:.0%}",
        f"  cold: `{c['command']}`: wall {c['wall']:.2f} s, CPU {c['cpu']:.2f} s (median of {rep['cold_runs']}); "
        f"its imports alone: wall {c['imports_wall']:.2f} s, CPU {c['imports_cpu']:.2f} s",
        f"    {_verdict(c['cpu'] < TARGET_COLD)}: under {TARGET_COLD} s (CPU; the target is wall time on an "
        "idle machine)",
    ]
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=7, help="warm runs (median; default 7)")
    ap.add_argument("--cold", type=int, default=5, help="cold command runs (median; default 5)")
    ap.add_argument("--data", type=Path, default=bx.DATA_DIR, help=f"shared data folder (default {bx.DATA_DIR})")
    ap.add_argument("--json", metavar="OUT", help="also write the figures as JSON")
    args = ap.parse_args(argv)
    if args.repeat < 1 or args.cold < 1:
        ap.error("--repeat and --cold must be at least 1")
    path = args.data / "cmu" / "69" / "69_01.amc"
    if not path.is_file():
        print(f"69_01 not found at {path} (the real captures live in ../shared/data beside the checkout)")
        return 1
    machine = bx.machine_info()
    motion = cc.load(path)
    w = warm(motion, args.repeat)
    lm = with_landmarks(motion, w.pop("result"), args.repeat)
    c = cold(path, args.cold)
    load_after = [round(v, 2) for v in os.getloadavg()] if hasattr(os, "getloadavg") else None
    rep = {"machine": machine, "repeat": args.repeat, "cold_runs": args.cold, "warm": w, "landmarks": lm,
           "cold": c, "load_after": load_after}
    print(format_report(rep), flush=True)
    if args.json:
        with atomic_write(args.json, "w") as fh:
            json.dump(bx._jsonable(rep), fh, indent=2)
            fh.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
