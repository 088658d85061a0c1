"""What reading any rig costs: extract's CPU time now against a named earlier commit, one run.

Issue 23's time target: at most 1.5x the CPU time before it on CMU 69_01 whole and on the
256k-frame synthetic walk (``make_periodic_capture(n_frames=256_000, period=120,
noise=0.5, random_state=0)``, as ``bench_scaling.py`` builds it).  The new stages are the
rig's reading (``cyclecoord.rig``), the joint-rotation map (``periodic/rotations.py``) and
the cycle's quality on joint positions (``quality/pose_space.py``).

The baseline is the same library at another commit, checked out with ``git worktree`` into
a temporary folder and imported in a child process; both run in children one after the
other, ``--repeat`` times, and the best CPU time (user + system of the child) is kept.

Usage::

    python benchmarks/bench_rig_cost.py                 # baseline: 23559c5 (before issue 23)
    python benchmarks/bench_rig_cost.py --baseline HEAD~5 --repeat 3 --no-256k
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
DATA = ROOT.parent / "shared" / "data" / "cmu"
#: The last commit before issue 23's work.
BASELINE = "23559c5"

CHILD = r"""
import json, resource, sys, time, warnings
warnings.simplefilter("ignore")
import cyclecoord as cc
case = sys.argv[1]
if case == "69_01":
    m = cc.load(sys.argv[2])
else:
    m = cc.datasets.make_periodic_capture(n_frames=int(case), period=120.0, noise=0.5,
                                          random_state=0).motion
r0 = resource.getrusage(resource.RUSAGE_SELF)
t0 = time.perf_counter()
res = cc.extract(m)
r1 = resource.getrusage(resource.RUSAGE_SELF)
print(json.dumps({"cpu": (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime),
                  "wall": time.perf_counter() - t0, "period": float(res.period_frames),
                  "peak_mb": r1.ru_maxrss / 1024.0}))
"""


def run(src: Path, case: str, path: str) -> dict:
    env = {**os.environ, "PYTHONPATH": str(src)}
    out = subprocess.run([sys.executable, "-c", CHILD, case, path], env=env, check=True,
                         capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def best(src: Path, case: str, path: str, repeat: int) -> dict:
    runs = [run(src, case, path) for _ in range(repeat)]
    return min(runs, key=lambda r: r["cpu"])


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--baseline", default=BASELINE, help="commit to compare with")
    p.add_argument("--repeat", type=int, default=2)
    p.add_argument("--no-256k", action="store_true", help="skip the 256k-frame walk")
    args = p.parse_args(argv)
    cases = []
    amc = DATA / "69" / "69_01.amc"
    if amc.is_file():
        cases.append(("69_01", str(amc), "CMU 69_01 whole (469 frames)"))
    else:
        print(f"skipped CMU 69_01: {amc} not found")
    if not args.no_256k:
        cases.append(("256000", "", "synthetic walk, 256,000 frames"))
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp) / "baseline"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "-q", "--detach", str(base),
                        args.baseline], check=True)
        try:
            rows = []
            for case, path, label in cases:
                old = best(base / "src", case, path, args.repeat)
                new = best(ROOT / "src", case, path, args.repeat)
                rows.append((label, old, new))
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(base)],
                           check=False)
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                          capture_output=True, text=True).stdout.strip()
    print(f"extract CPU time, best of {args.repeat}: {head} against {args.baseline}")
    print(f"{'case':34} {'before s':>9} {'now s':>9} {'ratio':>6} {'target':>7}  periods")
    for label, old, new in rows:
        ratio = new["cpu"] / old["cpu"]
        print(f"{label:34} {old['cpu']:9.2f} {new['cpu']:9.2f} {ratio:6.2f} "
              f"{'<= 1.5':>7}  {old['period']:.1f} / {new['period']:.1f}"
              f"  {'PASS' if ratio <= 1.5 else 'FAIL'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
