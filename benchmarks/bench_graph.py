"""Benchmark of the motion graph (``cyclecoord.synthesis.graph``) on set w1 (CMU 35).

Run from a checkout::

    python benchmarks/bench_graph.py [--repeat R] [--json out.json] [--data DIR]
                                     [--max-dims 5] [--table-dims 3]

Three measurements, each the median of ``R`` runs after one untimed warm-up, wall time
beside CPU time (the machine may be shared: CPU time shows the work, wall time what a
user waits):

* **generate**: PCA space, Delaunay graph, field and a 450-frame path on the four takes
  (1,712 frames), plus the playable motion (inverse PCA and root trajectory); target < 1 s;
* **crossval**: the whole leave-one-out table in 2 dims, the default methods (the paper's
  Delaunay and k-NN, our ``delaunay+ring+agree`` and k-Delaunay) x 4 folds with
  baselines and bottleneck distances; target < 10 s (the issue's 3 methods);
* **tables in more dims** (``--table-dims``, default 3): the same table untimed, to
  compare the methods where the walk's loop does not fold;
* **delaunay_dims**: for d = 2..5, Qhull's triangulation, the graph, and the cost of
  one field step (a 450-frame path, per step).

Without the CMU data it runs on four synthetic walks of the same lengths and says so.
Speed is printed, never asserted.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path
from typing import Any, Callable

import cyclecoord as cc
from cyclecoord.io import atomic_write
from cyclecoord.synthesis.graph import (
    MotionGraphSynth,
    PoseSpace,
    VectorField,
    build_graph,
    cross_validate,
    follow_field,
)

DATA_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "data"
W1 = ("35_16", "35_07", "35_08", "35_13")
LENGTHS = (443, 360, 455, 454)


def load_w1(data: Path) -> tuple[list, str]:
    paths = [data / "cmu" / "35" / f"{n}.amc" for n in W1]
    if all(p.is_file() for p in paths):
        return [cc.load(p) for p in paths], "CMU 35 (set w1)"
    print(
        f"NOTE: set w1 not found under {data}/cmu/35; "
        "using four synthetic walks of the same lengths"
    )
    walks = [
        cc.datasets.make_periodic_capture(
            kind="walk", n_frames=n, period=130, random_state=s
        ).motion
        for s, n in enumerate(LENGTHS)
    ]
    return walks, "synthetic walks"


def timed(fn: Callable[[], Any], repeat: int) -> tuple[dict, Any]:
    """Median wall and CPU seconds of ``repeat`` runs after a warm-up; the last result."""
    out = fn()
    walls, cpus = [], []
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    return {"wall": statistics.median(walls), "cpu": statistics.median(cpus)}, out


def bench_generate(takes: list, repeat: int) -> dict:
    def run():
        synth = MotionGraphSynth(method="delaunay", dims=2, step_scale=2.0).fit(takes)
        return synth.generate(450, takes[0], 0)

    t, gen = timed(run, repeat)
    return {**t, "frames": gen.motion.n_frames, "outside_hull_steps": gen.path.outside_hull_steps}


def bench_quality(takes: list, frames: int = 1200) -> dict:
    """The measure of generated motion (quality.generated) on a 1,200-frame walk: the
    paper's generator (2 dims, the training frames' mean root step) and ``cyclecoord
    graph``'s defaults (dims auto, root carried by the feet, feet pinned where clean)."""
    from cyclecoord.quality.generated import measure_generated, source_figures

    ref = source_figures(takes, takes[0].fps)
    out = {}
    for label, kw in (
        ("paper (2 dims, mean root step)", {"dims": 2, "carry": False}),
        ("graph defaults (auto dims, carried, pinned)", {"dims": "auto"}),
    ):
        gen = MotionGraphSynth(step_scale=2.0, **kw).fit(takes).generate(frames, takes[0], 0)
        out[label] = measure_generated(gen.motion, reference=ref)
    return out


def bench_crossval(takes: list, repeat: int) -> tuple[dict, Any]:
    t, cv = timed(lambda: cross_validate(takes), repeat)
    return t, cv


def bench_dims(takes: list, repeat: int, dims: tuple[int, ...] = (2, 3, 4, 5)) -> list[dict]:
    rows = []
    for d in dims:
        space = PoseSpace(d).fit(takes)
        latent = [space.transform(m) for m in takes]
        tg, graph = timed(lambda: build_graph(latent, "delaunay"), repeat)
        field = VectorField(graph)
        x0 = latent[0][0]
        follow_field(field, x0, 20)  # barycentric transforms computed once, outside the timing
        tp, path = timed(lambda: follow_field(field, x0, 450), repeat)
        rows.append(
            {
                "dims": d,
                "simplices": int(graph.delaunay.simplices.shape[0]),
                "edges": int(len(graph.edges)),
                "graph_wall": tg["wall"],
                "graph_cpu": tg["cpu"],
                "step_us_wall": 1e6 * tp["wall"] / 450,
                "step_us_cpu": 1e6 * tp["cpu"] / 450,
                "outside_hull_steps": path.outside_hull_steps,
            }
        )
    return rows


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--json", default=None)
    p.add_argument("--data", type=Path, default=DATA_DIR)
    p.add_argument("--max-dims", type=int, default=5, help="Delaunay cost for d = 2..MAX")
    p.add_argument(
        "--table-dims",
        default="3",
        help="comma list of further latent dims for an untimed cross-validation table "
        "('' for none)",
    )
    args = p.parse_args(argv)
    takes, what = load_w1(args.data)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(
        f"{what}: {sum(m.n_frames for m in takes)} frames; "
        f"{platform.processor() or platform.machine()}, "
        f"{os.cpu_count()} cores, load average {load:.1f} at start; medians of {args.repeat} runs"
    )
    quality = bench_quality(takes)
    for label, q in quality.items():  # the measure of generated motion leads
        print(f"{label}:")
        for line in q.summary():
            print("  " + line)
    gen = bench_generate(takes, args.repeat)
    print(
        f"graph + field + 450-frame path + playable motion: {gen['wall']:.3f} s wall, "
        f"{gen['cpu']:.3f} s CPU (target < 1 s)"
    )
    tcv, cv = bench_crossval(takes, args.repeat)
    print(
        f"cross-validation, 2 dims, {len(cv.median)} methods x {len(takes)} folds: "
        f"{tcv['wall']:.2f} s wall, {tcv['cpu']:.2f} s CPU (target < 10 s)"
    )
    print(cv.table())
    tables = {2: cv.median}
    for d in [int(x) for x in args.table_dims.split(",") if x.strip()]:
        cvd = cross_validate(takes, dims=d)
        print(f"cross-validation, {d} dims (untimed)")
        print(cvd.table(paper=False))
        tables[d] = cvd.median
    rows = bench_dims(takes, args.repeat, tuple(range(2, args.max_dims + 1)))
    print(
        f"{'dims':>4} {'simplices':>10} {'edges':>8} {'graph s':>9} {'(cpu)':>7} "
        f"{'step us':>8} {'(cpu)':>7}"
    )
    for r in rows:
        print(
            f"{r['dims']:>4} {r['simplices']:>10} {r['edges']:>8} "
            f"{r['graph_wall']:>9.3f} {r['graph_cpu']:>7.3f} "
            f"{r['step_us_wall']:>8.0f} {r['step_us_cpu']:>7.0f}"
        )
    load_end = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"load average {load_end:.1f} at the end (2 cores shared: wall times include waiting)")
    if args.json:
        with atomic_write(args.json, "w") as fh:
            json.dump(
                {
                    "data": what,
                    "motion_quality": {k: q.to_dict() for k, q in quality.items()},
                    "generate": gen,
                    "crossval": tcv,
                    "median": cv.median,
                    "median_by_dims": tables,
                    "delaunay_dims": rows,
                    "load": [load, load_end],
                    "python": sys.version,
                },
                fh,
                indent=1,
            )
        print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
