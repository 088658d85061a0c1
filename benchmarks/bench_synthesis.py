"""Generated motion against the captures and two baselines everyone knows (issue 24, item 5).

Run from a checkout::

    python benchmarks/bench_synthesis.py [--frames 1200] [--json out.json] [--data DIR]
                                         [--no-limbs] [--jog-from 4] [--pairs 20]

For each set -- subject 35's walks (set w1: 35_16, 35_07, 35_08, 35_13; a walk of
``--frames`` frames) and the 143_01 jog (one 100-frame take, read at 60 fps: see
``JOG_FPS``; from its first stride, ``JOG_START``; a run of half as many frames) -- every method generates from the first
take's frame 0 and is measured with one measure,
:func:`cyclecoord.quality.generated.measure_generated`, against the set's captures:

* **graph (ours)**: ``cyclecoord graph``'s defaults: the phase-aware field
  (``delaunay+phase``), latent dims ``auto``, root carried by the feet, feet pinned
  where clean;
* **graph (paper, 2-D)**: Gauch & Peters' Delaunay field in 2 dims with the training
  frames' mean root step, at the captured speed (``step_scale=2``);
* **classic graph**: Kovar, Gleicher & Pighin 2002
  (:class:`cyclecoord.synthesis.classic_graph.ClassicMotionGraph`), random walk, seed 0;
* **nearest-take replay**: the training take nearest the start pose, cut to the nearest
  pose at each take's end (:func:`~cyclecoord.synthesis.classic_graph.replay_nearest`);
* **captures**: each training take itself (min-max over the takes).

Columns: support-foot slip (m/s), freezes (count, longest seconds), knee flexion p99
left / right (degrees), the smallest knee and hip p1-p99 range against the captures'
(target >= 0.9), largest acceleration against the sources' p99 (target <= 1.5), leg
cycle against the captures' at the same root speed, root speed (m/s), and frames where
limbs pass through each other that the captures never do (``--no-limbs`` skips that
check).  Then ratios of ours against each baseline measured in the same run, and CPU
seconds: fitting, and generating 1,200 frames (target under 1 CPU-s), with and without
the foot pinning.  The 143_01 jog is one take: our graph (two takes at least) is trained
on its two halves.  The graph takes no script: the walk, run, walk, idle script is the
latent method's (``bench_latent_gait.py``); here the walk-to-jog and jog-to-walk paths are
``--target`` pairs on subject 35's walks with the jog (another actor, put on 35's skeleton),
ours against the paper's shortest graph path (:func:`targets`), then ``--pairs`` random
start/target pairs on four sets (w1, walks with the jog, two actors, the Bandai turning
walks: :func:`random_targets`), pairs in a take's stand summed apart.  Without the CMU data
it runs on synthetic walks and says so.  Speed is printed, never asserted.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import cyclecoord as cc
from cyclecoord.errors import CycleCoordError
from cyclecoord.io import atomic_write
from cyclecoord.quality.generated import measure_generated, source_figures
from cyclecoord.synthesis.classic_graph import THRESHOLD, ClassicMotionGraph, replay_nearest
from cyclecoord.synthesis.graph import MotionGraphSynth
from cyclecoord.synthesis.graph.phase import moving_frames

DATA_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "data"
W1 = ("35_16", "35_07", "35_08", "35_13")
METHODS = ("graph (ours)", "graph (paper, 2-D)", "classic graph", "nearest-take replay")
#: 143_01 read at 60 fps (AMC files carry no rate): at 120 fps it runs at 5.9 m/s with
#: 338 steps a minute, faster than a sprinter's cadence; at 60 fps, 2.9 m/s and 169, a jog.
JOG_FPS = 60.0
#: 143_01 is used from its fifth frame: on frames 0-3 the runner stands before the first
#: stride (right knee at 0, 0, 2 and 13 degrees), which alone widened the take's right
#: knee p1-p99 range from 78 degrees over its strides to 98 and made every method's
#: strides read short (the take replayed: 0.80).  ``--jog-from 0`` keeps them.
JOG_START = 4
OURS = dict(method="delaunay+phase", dims="auto", step_scale=2.0)
PAPER = dict(method="delaunay", dims=2, step_scale=2.0, carry=False)


def load_sets(data: Path, frames: int, jog_from: int = JOG_START) -> list[dict]:
    """``[{name, takes, train, frames}]``: the shared walks and jog, or synthetic walks."""
    sets = []
    walks = [data / "cmu" / "35" / f"{n}.amc" for n in W1]
    if all(p.is_file() for p in walks):
        takes = [cc.load(p) for p in walks]
        sets.append({"name": "walk: CMU 35 (w1)", "takes": takes, "train": takes,
                     "frames": frames})
    jog = data / "cmu" / "143" / "143_01.amc"
    if jog.is_file():
        m = cc.load(jog, fps=JOG_FPS)[jog_from:]
        half = m.n_frames // 2
        sets.append({"name": f"run: CMU 143_01 jog from frame {jog_from} (our graph on its "
                     "halves)", "takes": [m],
                     "train": [m[:half], m[half:]], "frames": frames // 2})
    if not sets:
        print(f"NOTE: no CMU data under {data}; four synthetic walks instead")
        takes = [
            cc.datasets.make_periodic_capture(kind="walk", n_frames=n, period=130,
                                              random_state=s).motion
            for s, n in enumerate((443, 360, 455, 454))
        ]
        sets.append({"name": "synthetic walks", "takes": takes, "train": takes,
                     "frames": frames})
    return sets


def _cpu(fn):
    t = time.process_time()
    out = fn()
    return out, time.process_time() - t


def generate(s: dict) -> dict:
    """``label -> {"motion", "fit_cpu", "gen_cpu", "note"}`` (motion None when it fails)."""
    takes, train, n = s["takes"], s["train"], s["frames"]
    out = {}
    for label, kw in (("graph (ours)", OURS), ("graph (paper, 2-D)", PAPER)):
        synth, fit = _cpu(lambda kw=kw: MotionGraphSynth(**kw).fit(train))
        gen, cpu = _cpu(lambda synth=synth: synth.generate(n, 0, 0))
        out[label] = {"motion": gen.motion, "fit_cpu": fit, "gen_cpu": cpu,
                      "note": f"{synth.dims_} dims"}
    out["classic graph"] = {"motion": None, "note": ""}
    for threshold in (THRESHOLD, 2 * THRESHOLD):  # a short run has no close pair at 0.06
        try:
            g, fit = _cpu(lambda t=threshold: ClassicMotionGraph(threshold=t).fit(takes))
            walk, cpu = _cpu(lambda g=g: g.walk(n, g.nearest_frame(takes[0], 0), seed=0))
        except CycleCoordError as exc:
            out["classic graph"]["note"] = str(exc)
            continue
        out["classic graph"] = {"motion": walk.motion, "fit_cpu": fit, "gen_cpu": cpu,
                                "note": f"threshold {threshold:g} leg lengths, "
                                f"{g.n_transitions} transition points, "
                                f"{len(walk.transitions)} taken"}
        break
    rep, cpu = _cpu(lambda: replay_nearest(takes, n, takes[0], 0))
    out["nearest-take replay"] = {"motion": rep.motion, "fit_cpu": 0.0, "gen_cpu": cpu,
                                  "note": f"{len(rep.transitions)} cuts"}
    return out


def measure(motion, ref, takes, limbs: bool) -> dict:
    q = measure_generated(motion, reference=ref)
    d = q.to_dict()
    d["limb_frames"] = None
    if limbs:
        from cyclecoord.quality.plausibility import check_plausibility

        d["limb_frames"] = len(check_plausibility(motion, takes).new_contact_frames)
    return d


def _fmt(d: dict) -> list[str]:
    knee = d["knee_p99_deg"]
    ratio = min(d["knee_range_ratio"] + d["hip_range_ratio"])
    fr = d["freezes"]
    return [
        f"{d['support_slip_m_per_s']:.2f}",
        f"{len(fr)} ({d['longest_freeze_s']:.2f} s)",
        f"{knee[0]:.0f} / {knee[1]:.0f}",
        f"{ratio:.2f}",
        f"{d['largest_accel_ratio']:.2f}",
        "-" if d.get("largest_root_accel_ratio") is None
        else f"{d['largest_root_accel_ratio']:.2f}",
        f"{d['cadence_ratio']:.2f}" if d["cadence_ratio"] is not None else "-",
        f"{d['root_speed_m_per_s']:.2f}",
        "-" if d["limb_frames"] is None else str(d["limb_frames"]),
    ]


HEAD = ["method", "slip m/s", "freezes (longest)", "knee p99 L / R", "knee,hip range",
        "accel / p99", "root acc / p99", "cycle ratio", "root m/s", "limb frames"]


def _span(values: list[str]) -> str:
    """Min-max of the captures' cells: numbers, ``"a / b"`` pairs or ``"n (x s)"``."""
    if " / " in values[0]:
        return " / ".join(_span([v.split(" / ")[i] for v in values]) for i in range(2))
    nums = [float(v.split()[0]) for v in values if v != "-"]
    if not nums:
        return "-"
    lo, hi = min(nums), max(nums)
    digits = 0 if all(float(n).is_integer() for n in nums) else 2
    one = f"{lo:.{digits}f}"
    return one if abs(hi - lo) < 5e-3 else f"{one}-{hi:.{digits}f}"


def table(rows: list[tuple[str, list[str]]]) -> str:
    widths = [max(len(HEAD[i]), *(len(r[1][i - 1]) if i else len(r[0]) for r in rows))
              for i in range(len(HEAD))]
    line = " | ".join(h.ljust(w) for h, w in zip(HEAD, widths))
    out = [line, "-" * len(line)]
    for label, cells in rows:
        out.append(" | ".join(c.ljust(w) for c, w in zip([label, *cells], widths)))
    return "\n".join(out)


def run_set(s: dict, limbs: bool) -> dict:
    takes = s["takes"]
    ref = source_figures(takes, takes[0].fps)
    gens = generate(s)
    figures, rows = {}, []
    for label in METHODS:
        g = gens[label]
        if g["motion"] is None:
            rows.append((label, ["-"] * (len(HEAD) - 1)))
            figures[label] = {"note": g["note"]}
            continue
        figures[label] = measure(g["motion"], ref, takes, limbs)
        figures[label].update(fit_cpu=g["fit_cpu"], gen_cpu=g["gen_cpu"], note=g["note"])
        rows.append((label, _fmt(figures[label])))
    caps = [measure(m, ref, takes, limbs) for m in takes]
    figures["captures"] = caps
    cells = [_fmt(c) for c in caps]
    span = [_span([c[i] for c in cells]) for i in range(len(HEAD) - 1)]
    rows.append((f"captures ({len(takes)})", span))
    figures["stride windows"] = stride_control(takes, ref)
    return {"name": s["name"], "frames": s["frames"], "figures": figures, "rows": rows}


def stride_control(takes: list, ref) -> list[float]:
    """The control for the knee,hip range column: the smallest leg range ratio of every
    one-cycle window of the captures (one starting every eighth of a cycle), measured
    like a generated motion.  On a take of two or three strides the p1-p99 range is set
    by its widest stride (or the ends of two), which one captured stride does not reach."""
    out = []
    for t in takes:
        w = int(round(measure_generated(t, reference=ref).cycle_s * t.fps))
        if not 3 <= w <= t.n_frames:
            continue
        for a in range(0, t.n_frames - w + 1, max(1, w // 8)):
            q = measure_generated(t[a : a + w], reference=ref)
            out.append(float(min(q.knee_ratio + q.hip_ratio)))
    return out


def ratios(fig: dict) -> list[str]:
    """Ours against each baseline: slip, largest accel, smallest leg range, root speed."""
    ours = fig["graph (ours)"]
    caps = fig["captures"]
    cap_slip = float(np.median([c["support_slip_m_per_s"] for c in caps]))
    lines = [f"  ours: slip {ours['support_slip_m_per_s'] / cap_slip:.2f}x the captures' "
             f"median ({cap_slip:.2f} m/s; target <= 1.5)"]
    for label in METHODS[1:]:
        b = fig[label]
        if "support_slip_m_per_s" not in b:
            lines.append(f"  vs {label}: not generated ({b['note']})")
            continue
        rng = min(ours["knee_range_ratio"] + ours["hip_range_ratio"]) / max(
            min(b["knee_range_ratio"] + b["hip_range_ratio"]), 1e-9)
        lines.append(
            f"  vs {label}: slip {ours['support_slip_m_per_s'] / max(b['support_slip_m_per_s'], 1e-9):.2f}x, "
            f"largest accel {ours['largest_accel_ratio'] / b['largest_accel_ratio']:.2f}x, "
            f"smallest leg range {rng:.2f}x, root speed "
            f"{ours['root_speed_m_per_s'] / max(b['root_speed_m_per_s'], 1e-9):.2f}x")
    return lines


def speed(takes: list, n: int = 1200) -> dict:
    """CPU seconds of our graph: fit, then ``n`` frames with and without foot pinning."""
    synth, fit = _cpu(lambda: MotionGraphSynth(**OURS).fit(takes))
    _, full = _cpu(lambda: synth.generate(n, 0, 0))
    synth.lock = False
    _, carried = _cpu(lambda: synth.generate(n, 0, 0))
    from cyclecoord.synthesis.graph.phase import follow_phase

    x0 = synth.start_point(0, 0)
    _, path = _cpu(lambda: follow_phase(synth.phase_field_, x0, n, synth.step_scale))
    return {"fit": fit, "generate": full, "generate_no_lock": carried, "path": path}


#: ``--target`` pairs (take, frame) -> (take, frame) on set w1 (frames at 120 fps), and
#: on subject 35's walks 35_07 / 35_08 with the 143_01 jog (all at 60 fps; take 2 the jog).
W1_TARGETS = ((0, 100, 1, 300), (0, 50, 2, 200), (1, 100, 3, 250), (2, 30, 0, 330),
              (3, 80, 1, 150))
GAIT_TARGETS = ((0, 100, 2, 60), (2, 20, 1, 150), (0, 50, 2, 90), (1, 40, 2, 70),
                (2, 10, 0, 120))


def targets(data: Path) -> list[dict]:
    """``to_target`` with our default (the phase-aware field: walked in step) against the
    paper's shortest graph path (the same graph with ``delaunay``), both measured with
    one measure: largest acceleration and pose step over the sources' p99, frames, and
    frames where limbs pass closer than the takes (each pair in the same run)."""
    from cyclecoord.quality.plausibility import check_plausibility

    cmu = data / "cmu"
    w1 = [cmu / "35" / f"{n}.amc" for n in W1]
    jog = cmu / "143" / "143_01.amc"
    if not all(p.is_file() for p in w1 + [jog]):
        return []
    sets = [("w1", [cc.load(p) for p in w1], W1_TARGETS)]
    walks = [cc.load(cmu / "35" / f"35_{n}.amc")[::2] for n in ("07", "08")]
    walks = [m.with_frames(m.frames, fps=60.0) for m in walks]
    sets.append(("walks + jog", walks + [cc.load(jog, fps=JOG_FPS)], GAIT_TARGETS))
    rows = []
    for name, takes, pairs in sets:
        ours = MotionGraphSynth(**OURS).fit(takes)
        paper = MotionGraphSynth(method="delaunay", dims="auto", step_scale=2.0).fit(takes)
        for s, sf, t, tf in pairs:
            row = {"set": name, "pair": f"{s}:{sf} -> {t}:{tf}"}
            for label, synth in (("ours", ours), ("graph path", paper)):
                gen = synth.to_target(s, sf, t, tf)
                q = measure_generated(gen.motion, takes)
                row[label] = {
                    "kind": gen.path.kind, "frames": gen.motion.n_frames,
                    "accel": q.largest_accel, "step": q.largest_step,
                    "limbs": len(check_plausibility(gen.motion, takes).new_contact_frames),
                }
            rows.append(row)
    return rows


def target_sets(data: Path) -> list[tuple[str, list]]:
    """The sets :func:`random_targets` draws pairs on: subject 35's w1 walks, two walks
    with the 143_01 jog (60 fps), two actors' walks (35_07 and 69_01, which stands for
    its first 1.3 s), and the Bandai straight and turning walks; those whose files are
    there."""
    cmu, bandai = data / "cmu", data / "bvh" / "bandai"
    sets = []
    w1 = [cmu / "35" / f"{n}.amc" for n in W1]
    if all(p.is_file() for p in w1):
        sets.append(("w1", [cc.load(p) for p in w1]))
    jog = cmu / "143" / "143_01.amc"
    if all(p.is_file() for p in w1[1:3] + [jog]):
        walks = [cc.load(p) for p in w1[1:3]]
        walks = [m.with_frames(m.frames[::2], fps=60.0) for m in walks]
        sets.append(("walks + jog", walks + [cc.load(jog, fps=JOG_FPS)]))
    actors = [cmu / "35" / "35_07.amc", cmu / "69" / "69_01.amc"]
    if all(p.is_file() for p in actors):
        sets.append(("two actors", [cc.load(p) for p in actors]))
    turns = [bandai / f"{n}.bvh" for n in ("dataset-1_walk_normal_001",
                                         "dataset-2_walk-turn-left_normal_011",
                                         "dataset-2_walk-turn-right_normal_029")]
    if all(p.is_file() for p in turns):
        sets.append(("Bandai walks", [cc.load(p) for p in turns]))
    return sets


def random_targets(data: Path, pairs: int, seed: int = 1) -> list[dict]:
    """``to_target`` over ``pairs`` random start and target frames per set
    (:func:`target_sets`; any take to any take, seeded), ours against the paper's
    shortest graph path on the same graph: how often each pops (largest acceleration
    over 1.5x the sources' p99), freezes (:func:`measure_generated`'s), and, ours only,
    which path it took.  The fixed pairs of :func:`targets` were chosen once; these
    find what they miss (a take that begins with a stand, a target a few frames into
    its take)."""
    rng = np.random.default_rng(seed)
    out = []
    for name, takes in target_sets(data):
        ours = MotionGraphSynth(**OURS).fit(takes)
        paper = MotionGraphSynth(method="delaunay", dims="auto", step_scale=2.0).fit(takes)
        n = len(ours.takes_)
        figs: dict = {"ours": [], "graph path": [], "kinds": [], "stand": []}
        field, take = ours.phase_field_, ours.phase_field_.graph.take
        moving = [moving_frames(field.graph.points[take == i], field.rate[take == i])
                  for i in range(n)]
        for _ in range(pairs):
            s, t = int(rng.integers(n)), int(rng.integers(n))
            sf = int(rng.integers(ours.takes_[s].n_frames))
            tf = int(rng.integers(ours.takes_[t].n_frames))
            figs["stand"].append(not (moving[s][sf] and moving[t][tf]))
            for label, synth in (("ours", ours), ("graph path", paper)):
                gen = synth.to_target(s, sf, t, tf)
                if gen.motion.n_frames < 3:  # a target beside the start: nothing to pop
                    figs[label].append((0.0, False))
                else:
                    # (both judged alike: by the gaits the path drew on, ours' grouping)
                    # (a stand the target asked for is not a freeze: gen.hold)
                    q = measure_generated(gen.motion, reference=ours.reference(gen),
                                          hold=gen.hold)
                    figs[label].append((q.largest_accel, bool(q.freezes)))
                if label == "ours":
                    figs["kinds"].append(gen.path.kind.split(":")[-1] if gen.path.kind.startswith(
                        "field") else "graph path")
        out.append({"set": name, **figs})
    return out


def _random_lines(rows: list[dict]) -> list[str]:
    """Per set, the pairs whose start and target lie where their takes move, then (when
    there are any) those with one in a stand a take begins or ends with."""
    lines = []
    for r in rows:
        stand = np.array(r["stand"], dtype=bool)
        for part, keep in (("", ~stand), ("  with a stand", stand)):
            if not keep.any():
                continue
            cells = []
            for label in ("ours", "graph path"):
                acc = np.array([a for a, _ in r[label]])[keep]
                frozen = int(np.array([f for _, f in r[label]])[keep].sum())
                cells.append(f"{label} accel median {np.median(acc):.2f}, largest "
                             f"{acc.max():.2f}, over 1.5x {int((acc > 1.5).sum())}, freezes "
                             f"{frozen}")
            kinds = [k for k, x in zip(r["kinds"], keep) if x]
            count = {k: kinds.count(k) for k in sorted(set(kinds))}
            lines.append(f"  {r['set'] + part:26s} {int(keep.sum()):2d} pairs: "
                         + " | ".join(cells) + "; ours by "
                         + ", ".join(f"{k} {v}" for k, v in count.items()))
    return lines


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--frames", type=int, default=1200, help="walk length (the run: half)")
    p.add_argument("--data", type=Path, default=DATA_DIR, help="the shared data folder")
    p.add_argument("--json", default=None, help="also write every figure as JSON")
    p.add_argument("--no-limbs", action="store_true", help="skip the limb-contact check")
    p.add_argument("--pairs", type=int, default=20,
                   help="random --target pairs per set (0: none; default %(default)s)")
    p.add_argument("--jog-from", type=int, default=JOG_START,
                   help="first frame of 143_01 used (default %(default)s: its first stride)")
    args = p.parse_args(argv)
    warnings.simplefilter("ignore")
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"{os.cpu_count()} cores, load average {load:.1f} at start; CPU seconds")
    results = []
    for s in load_sets(args.data, args.frames, args.jog_from):
        r = run_set(s, not args.no_limbs)
        results.append(r)
        print(f"\n{r['name']}: {r['frames']} frames generated from the first take's frame 0")
        print(table(r["rows"]))
        print("ratios measured in this run:")
        print("\n".join(ratios(r["figures"])))
        ctl = r["figures"]["stride windows"]
        if ctl:
            print(f"  control: the captures' own one-cycle windows ({len(ctl)}), knee,hip range "
                  f"{np.median(ctl):.2f} median [{min(ctl):.2f}-{max(ctl):.2f}]")
        for label in METHODS:
            f = r["figures"][label]
            if "fit_cpu" in f:
                print(f"  {label}: fit {f['fit_cpu']:.2f} s, generate {f['gen_cpu']:.2f} s CPU "
                      f"({f['note']})")
    sp = speed(load_sets(args.data, args.frames, args.jog_from)[0]["train"])
    print(f"\nspeed, our graph on the first set: fit {sp['fit']:.2f} s CPU (phases from the "
          f"periodic pipeline); 1,200 frames {sp['generate']:.2f} s CPU with foot pinning, "
          f"{sp['generate_no_lock']:.2f} s without, path alone {sp['path']:.2f} s "
          "(target: 1,200 frames under 1 CPU-s)")
    tg = targets(args.data)
    if tg:
        print("\n--target: ours (phase-aware, walked in step) against the paper's shortest "
              "graph path, same graph; accel and step over the sources' p99, limb frames")
        for r in tg:
            o, g = r["ours"], r["graph path"]
            print(f"  {r['set']:11s} {r['pair']:17s} ours {o['frames']:4d} frames, accel "
                  f"{o['accel']:.2f}, step {o['step']:.2f}, limbs {o['limbs']} "
                  f"({o['kind']}) | graph path {g['frames']:4d} frames, accel {g['accel']:.2f}, "
                  f"step {g['step']:.2f}, limbs {g['limbs']}")
        worst = [max(r[k]["accel"] for r in tg) for k in ("ours", "graph path")]
        print(f"  largest accel over every pair: ours {worst[0]:.2f}, graph path {worst[1]:.2f} "
              f"({worst[0] / worst[1]:.2f}x)")
    rt = random_targets(args.data, args.pairs) if args.pairs > 0 else []
    if rt:
        print(f"\n--target over {args.pairs} random start/target pairs per set (seed 1), "
              "accel over the sources' p99 (target <= 1.5), freezes of over 0.2 s; pairs with "
              "a start or target in a take's stand apart (no capture walks into a stand)")
        print("\n".join(_random_lines(rt)))
    if args.json:
        with atomic_write(args.json, "w") as fh:
            json.dump({"sets": [{k: v for k, v in r.items() if k != "rows"} for r in results],
                       "speed": sp, "targets": tg, "random_targets": rt,
                       "python": sys.version}, fh, indent=1,
                      default=str)
        print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
