"""Latent-space synthesis (Bailey et al.) against motion-graph transitions (Kovar et al. 2002).

Run from a checkout::

    python benchmarks/bench_latent.py [--quick] [--json out.json]

Models (all at 30 fps, every 4th frame of the 120 fps captures; each trained on the first
80 % of every segment, the last 20 % left out): the six exercises of CMU 13_29 (labels
in ``../shared/data/labels/13_29.csv``), the subject 35 walks (35_07, 35_08, 35_13, 35_16)
and the 143_01 jog.  For every ordered pair of models (A, B):

* **coverage** -- fraction of A's training frames from which a transition to B can start
  within 1 s.  Motion graph: a candidate transition (local minimum of Kovar's aligned
  point-cloud distance over a 12-frame window, under the threshold) starts 0..1 s later
  in the same segment.  Bridges: a bridge's source point is (a) 0..1 s later in the same
  segment ("play", the same rule) or (b) within 1 s of latent travel at the model's
  median training speed ("move", what MOVE does).  One threshold for both: RMS joint
  distance 1.5 % of the skeleton's total bone length.
* **smoothness** -- one transition by each method with the same 12-frame blend (the
  latent TRANSITION command from A's first frame; the motion graph's best candidate,
  or its overall best window pair when none is under the threshold, marked ``*``): the
  largest joint acceleration and jerk (root-relative joint positions) inside the blend
  window +-2 frames, over the 99th percentile of the two models' training takes.
* **foot skating** -- with ``cyclecoord.quality.contacts`` (contacts found on the whole
  synthesised motion): the fraction of the window's frames on which a planted foot point
  slides and the planted points' mean speed (leg lengths/s); and a cruder toe measure,
  the mean horizontal speed of a toe while it is low (within 1.5 units of the training
  takes' 5th percentile toe height), skeleton units/s.

The latent TRANSITION always arrives: where no bridge is under the threshold it takes the
cheapest route of crossings over the models and crosses at the closest poses (the blend
lengthened when they are far apart).  Its acceleration is given for the blend windows and
for the whole transition (the approach MOVEs included).

Per model: fitting time, joint-angle RMS error (degrees) of training frames rebuilt from
their latent points and of the left-out frames, against PCA with as many components as
latent dimensions (3 numbers per frame).  A left-out frame's latent point is the one
whose pose is nearest its joint angles in least squares (``invert``, as PCA projects);
the ``(Eq.15)`` column is the bridges' search instead, which measures in the model's
influence-scaled PCA space and so is not the least-squares fit of the angles.  Fitting time on 100,
400 and 800 frames of 13_29; synthesis speed of a 60 s script on the walk model.
Nothing asserts speed; the machine is shared, so CPU time is printed beside wall time.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import cyclecoord as cc  # noqa: E402
from cyclecoord.synthesis.latent import (  # noqa: E402
    LatentModel,
    Synthesizer,
    find_bridges,
    invert,
    project,
)
from cyclecoord.synthesis.transitions import aligned_transform, window_distances  # noqa: E402

STEP = 4
FPS = 30.0
BLEND = 12
HOLD = 0.2
THRESHOLD = 0.015
PLANT = "transitions"


def default_data() -> Path:
    return ROOT.parent / "shared" / "data"


def load_segments(data: Path, quick: bool = False) -> dict[str, list[tuple[str, cc.Motion]]]:
    """Model name -> [(segment name, 120 fps motion)]."""
    cmu = data / "cmu"
    out: dict[str, list] = {}
    take = cc.load(cmu / "13" / "13_29.amc")
    with open(data / "labels" / "13_29.csv", newline="") as fh:
        for row in csv.DictReader(fh):
            out[row["activity"]] = [
                (row["activity"], take[int(row["start_frame"]) : int(row["stop_frame"])])
            ]
    if quick:
        return {k: out[k] for k in ("JumpJack", "Twist")}
    out["Walk35"] = [(p.stem, cc.load(p)) for p in sorted((cmu / "35").glob("35_*.amc"))]
    out["Jog143"] = [("143_01", cc.load(cmu / "143" / "143_01.amc"))]
    return out


def split(segments, keep: float = 0.8):
    """Training (first 80 % of each segment) and left-out parts, every STEP-th frame."""
    train, test = [], []
    for name, m in segments:
        sub = m[::STEP]
        k = int(round(keep * sub.n_frames))
        train.append((name, sub[:k]))
        test.append((name, sub[k:]))
    return train, test


def local_positions(motion: cc.Motion) -> np.ndarray:
    """Joint positions relative to the root, turned to the root's heading, (T, P, 3)."""
    from cyclecoord.synthesis.align import root_rotation

    pos = motion.positions().positions
    mats, _, _ = root_rotation(motion)
    fwd = mats[:, :, 2]
    th = np.arctan2(fwd[:, 0], fwd[:, 2])
    c, s = np.cos(th), np.sin(th)
    rel = pos - pos[:, :1]
    x = c[:, None] * rel[..., 0] - s[:, None] * rel[..., 2]
    z = s[:, None] * rel[..., 0] + c[:, None] * rel[..., 2]
    return np.stack([x, rel[..., 1], z], axis=-1)


def derivatives(local: np.ndarray, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame largest joint acceleration and jerk (units/s^2, units/s^3)."""
    acc = np.linalg.norm(np.diff(local, 2, axis=0), axis=2).max(axis=1) * fps**2
    jerk = np.linalg.norm(np.diff(local, 3, axis=0), axis=2).max(axis=1) * fps**3
    return acc, jerk


def toe_columns(motion: cc.Motion) -> list[int]:
    names = motion.positions().names
    return [i for i, n in enumerate(names) if n in ("ltoes/end", "rtoes/end")] or [
        i for i, n in enumerate(names) if "toe" in n
    ]


def foot_skating(motion: cc.Motion, low: float) -> float:
    """Mean horizontal toe speed (units/s) over frames where the toe is below ``low``."""
    pos = motion.positions().positions[:, toe_columns(motion)]
    speed = np.linalg.norm(np.diff(pos[..., [0, 2]], axis=0), axis=2) * motion.fps
    mask = pos[1:, :, 1] < low
    return float(speed[mask].mean()) if mask.any() else 0.0


def fit_models(segs: dict, quick: bool) -> tuple[dict, dict, list]:
    models, tests, rows = {}, {}, []
    iters = 60 if quick else 200
    for name, parts in segs.items():
        train, test = split(parts)
        t0, w0 = time.process_time(), time.perf_counter()
        m = LatentModel(gplvm={"max_iter": iters}).fit([s for _, s in train], [n for n, _ in train])
        rows.append(
            {
                "model": name,
                "frames": m.X_.shape[0],
                "pca": m.components_.shape[1],
                "fit_cpu_s": time.process_time() - t0,
                "fit_wall_s": time.perf_counter() - w0,
            }
        )
        models[name] = m
        tests[name] = [s for _, s in test]
    return models, tests, rows


def reconstruction(m: LatentModel, tests: list) -> dict:
    train = m.angles(m.frames_)
    left = m.angles(np.concatenate([t.frames for t in tests]))
    rms = lambda a, b: float(np.sqrt(((a - b) ** 2).mean()))  # noqa: E731
    X15, _ = project(m, m.pca_coordinates(left))
    X, _ = invert(m, left)
    q = m.X_.shape[1]
    mu = train.mean(0)
    _, _, Vt = np.linalg.svd(train - mu, full_matrices=False)
    V = Vt[:q].T
    pca = lambda a: mu + (a - mu) @ V @ V.T  # noqa: E731
    return {
        "gplvm_train": rms(m.pose(m.X_), train),
        "gplvm_left_out": rms(m.pose(X), left),
        "gplvm_left_out_eq15": rms(m.pose(X15), left),
        "pca_train": rms(pca(train), train),
        "pca_left_out": rms(pca(left), left),
    }


def seg_bounds(m: LatentModel) -> list[tuple[int, int]]:
    s = m.segments_
    starts = np.flatnonzero(np.r_[True, s[1:] != s[:-1]])
    return list(zip(starts, np.r_[starts[1:], len(s)]))


def coverage_play(m: LatentModel, starts: np.ndarray) -> float:
    """Fraction of frames with a start 0..1 s later in the same segment."""
    ok = np.zeros(m.X_.shape[0], bool)
    horizon = int(round(m.fps_))
    for a, b in seg_bounds(m):
        st = np.sort(starts[(starts >= a) & (starts < b)])
        for f in range(a, b):
            k = np.searchsorted(st, f)
            ok[f] = k < st.size and st[k] - f <= horizon
    return float(ok.mean())


def motion_of(m: LatentModel, frames: np.ndarray, skeleton=None, scale: float = 1.0) -> cc.Motion:
    fr = np.array(frames, dtype=float)
    for j, d in m.root_channels_:
        if d.startswith("t"):
            fr[:, m.all_channels_.index((j, d))] *= scale
    return cc.Motion(
        frames=fr, channels=m.all_channels_, fps=m.fps_, skeleton=skeleton or m.skeleton_
    )


def kovar(mA: LatentModel, mB: LatentModel, thr: float):
    """Window distances A->B (B played on A's skeleton, root scaled) and candidate starts."""
    from scipy import ndimage

    scale = mA.skeleton_.total_length() / mB.skeleton_.total_length()
    pa = motion_of(mA, mA.frames_).positions().positions
    pb = motion_of(mB, mB.frames_, mA.skeleton_, scale).positions().positions
    D = window_distances(pa, pb, BLEND)
    for m, axis in ((mA, 0), (mB, 1)):
        bad = np.ones(D.shape[axis], bool)
        for a, b in seg_bounds(m):
            bad[a : max(a, b - BLEND + 1)] = False
        if axis == 0:
            D[bad, :] = np.inf
        else:
            D[:, bad] = np.inf
    local = D == ndimage.minimum_filter(D, size=3, mode="nearest")
    hits = np.argwhere(local & (D < thr))
    return D, hits, local, pb, scale


def mg_transition(mA, mB, D, hits, scale) -> tuple[cc.Motion, int, bool]:
    """Kovar transition at the best candidate (or the best pair): A's frames, blend, B's frames."""
    from cyclecoord.conventions import continuous_euler
    from cyclecoord.synthesis.align import root_rotation

    under = len(hits) > 0
    i, j = (
        hits[np.argmin(D[hits[:, 0], hits[:, 1]])]
        if under
        else np.unravel_index(np.argmin(D), D.shape)
    )
    A = motion_of(mA, mA.frames_)
    B = motion_of(mB, mB.frames_, mA.skeleton_, scale)
    pre = int(HOLD * FPS)
    a0 = max(0, i - pre)
    fa, fb = A.frames[a0 : i + BLEND], B.frames[j : j + BLEND + pre]
    pa = A[i : i + BLEND].positions().positions
    pb = B[j : j + BLEND].positions().positions
    theta, t = aligned_transform(pa, pb)
    c, s = np.cos(theta), np.sin(theta)
    Ry = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    Bseg = B.with_frames(fb)
    rb, order, rcols = root_rotation(Bseg)
    rb = Ry @ rb
    tcols = [B.channel_index(B.skeleton.joints[0].name, d) for d in ("tx", "ty", "tz")]
    fb = fb.copy()
    fb[:, tcols] = fb[:, tcols] @ Ry.T + t
    ra, _, _ = root_rotation(A.with_frames(fa))
    n_pre = i - a0
    w = 1.0 - (
        2 * ((np.arange(BLEND) + 1) / BLEND) ** 3 - 3 * ((np.arange(BLEND) + 1) / BLEND) ** 2 + 1
    )
    out = np.concatenate([fa[:n_pre], np.zeros((BLEND, fa.shape[1])), fb[BLEND:]])
    mats = np.concatenate([ra[:n_pre], np.zeros((BLEND, 3, 3)), rb[BLEND:]])
    for k in range(BLEND):
        out[n_pre + k] = (1 - w[k]) * fa[n_pre + k] + w[k] * fb[k]
        U, _, Vt = np.linalg.svd((1 - w[k]) * ra[n_pre + k] + w[k] * rb[k])
        mats[n_pre + k] = U @ Vt
    out[:, rcols] = continuous_euler(mats[:, None], order)[:, 0]
    return A.with_frames(out), n_pre, bool(under)


def window_stats(
    motion: cc.Motion, start: int, n: int, p99: tuple[float, float, float], low: float
) -> dict:
    acc, jerk = derivatives(local_positions(motion), motion.fps)
    a = max(0, start - 2)
    b = start + n + 2
    # acc[k] is centred on frame k+1, jerk[k] spans k..k+3
    out = {
        "acc": float(acc[max(0, a - 1) : b].max() / p99[0]),
        "jerk": float(jerk[max(0, a - 2) : b].max() / p99[1]),
        "root_acc": float(root_acceleration(motion)[max(0, a - 1) : b].max() / p99[2]),
        "skate": foot_skating(motion[max(0, a) : b + 1], low),
    }
    contacts = contacts_skating(motion)
    if contacts is not None:
        # quality.contacts: fraction of the window's frames on which a planted foot point
        # slides, and the planted points' mean speed there (leg lengths/s), contacts found
        # on the whole synthesised motion
        fc, fs = contacts
        out["skating_frames_contacts"] = float(fs.skating[a : b + 1].any(axis=1).mean())
        planted = fc.planted[a : b + 1]
        out["skating_speed_contacts"] = (
            float(fc.speed[a : b + 1][planted].mean() / fc.leg_length) if planted.any() else 0.0
        )
    return out


def contacts_skating(motion: cc.Motion):
    """``(foot_contacts, foot_skating)`` of ``cyclecoord.quality.contacts``, None when
    the motion's feet cannot be found."""
    from cyclecoord.errors import CycleCoordError
    from cyclecoord.quality.contacts import foot_contacts, foot_skating

    try:
        fc = foot_contacts(motion)
    except CycleCoordError:
        return None
    return fc, foot_skating(motion, fc)


def root_acceleration(motion: cc.Motion) -> np.ndarray:
    """Horizontal acceleration of the root in the world, per frame (units/s^2)."""
    p = motion.positions().positions[:, 0, [0, 2]]
    return np.linalg.norm(np.diff(p, 2, axis=0), axis=1) * motion.fps**2


def training_stats(models: dict, tests: dict) -> dict:
    out = {}
    for k, m in models.items():
        accs, jerks, toes, roots = [], [], [], []
        for a, b in seg_bounds(m):
            mo = motion_of(m, m.frames_[a:b])
            ac, je = derivatives(local_positions(mo), FPS)
            accs.append(ac)
            jerks.append(je)
            roots.append(root_acceleration(mo))
            toes.append(mo.positions().positions[:, toe_columns(mo), 1].ravel())
        out[k] = {
            "acc": np.concatenate(accs),
            "jerk": np.concatenate(jerks),
            "toe": np.concatenate(toes),
            "root": np.concatenate(roots),
        }
    for k, m in models.items():
        low = float(np.percentile(out[k]["toe"], 5) + 1.5)
        out[k]["low"] = low
        out[k]["skate"] = float(
            np.mean([foot_skating(motion_of(m, m.frames_[a:b]), low) for a, b in seg_bounds(m)])
        )
    return out


def latent_transition(models, bridges, nA, nB, p99, low):
    """TRANSITION from A's first frame to B (the cheapest route of crossings: bridges, or
    the closest poses with a longer blend, possibly through other models); the worst
    blend window's statistics, the whole transition's acceleration and the route."""
    from cyclecoord.errors import ParameterError

    syn = Synthesizer(models, fps=FPS, seed=0, plant=PLANT)
    syn._bridges = dict(bridges)
    syn.start(nA)
    try:
        syn.transition(nB, blend=BLEND / FPS)
    except ParameterError:
        return None
    syn.idle(duration=HOLD)
    motion = syn.motion()
    stats = [
        window_stats(motion, ev["start_frame"], ev["blend_frames"], p99, low) for ev in syn.events
    ]
    acc, _ = derivatives(local_positions(motion), motion.fps)
    out = {
        "acc": max(s["acc"] for s in stats),
        "acc_all": float(acc.max() / p99[0]),
        "jerk": max(s["jerk"] for s in stats),
        "root_acc": max(s["root_acc"] for s in stats),
        "skate": float(np.mean([s["skate"] for s in stats])),
        "route": [syn.events[0]["transition"][0]] + [ev["transition"][1] for ev in syn.events],
        "distance_ratio": max(ev["bridge_distance"] / ev["threshold"] for ev in syn.events),
        "bridged": all(ev["under_threshold"] for ev in syn.events),
        "blend_frames": [ev["blend_frames"] for ev in syn.events],
        "frames": motion.n_frames,
    }
    for key in ("skating_frames_contacts", "skating_speed_contacts"):
        if key in stats[0]:
            out[key] = float(np.mean([s[key] for s in stats]))
    return out


def pair_rows(models: dict, stats: dict, progress: bool) -> list[dict]:
    from tqdm import tqdm

    names = list(models)
    pairs = [(a, b) for a in names for b in names if a != b]
    bridges = {
        (a, b): find_bridges(
            models[a],
            models[b],
            names=(a, b),
            threshold=THRESHOLD * models[a].skeleton_.total_length(),
        )
        for a, b in tqdm(pairs, desc="bridges", disable=not progress)
    }
    rows = []
    for a, b in tqdm(pairs, desc="pairs", disable=not progress):
        mA, mB = models[a], models[b]
        thr = THRESHOLD * mA.skeleton_.total_length()
        br = bridges[(a, b)]
        D, hits, local, _, scale = kovar(mA, mB, thr)
        hits2 = np.argwhere(local & (D < 2 * thr))
        p99 = (
            float(np.percentile(np.r_[stats[a]["acc"], stats[b]["acc"]], 99)),
            float(np.percentile(np.r_[stats[a]["jerk"], stats[b]["jerk"]], 99)),
            float(np.percentile(np.r_[stats[a]["root"], stats[b]["root"]], 99)),
        )
        low = stats[a]["low"]
        row = {
            "from": a,
            "to": b,
            "bridges": len(br),
            "mg_transitions": len(hits),
            "bridge_cov_play": coverage_play(mA, br.frames),
            "mg_cov_play": coverage_play(mA, hits[:, 0] if len(hits) else np.array([], int)),
            "best_bridge": float(br.best.min()),
            "best_mg": float(D.min()),
            "threshold": thr,
            "mg_transitions_2x": len(hits2),
            "bridges_2x": int((br.best < 2 * thr).sum()),
            "bridge_cov_play_2x": coverage_play(mA, np.flatnonzero(br.best < 2 * thr)),
            "mg_cov_play_2x": coverage_play(mA, hits2[:, 0] if len(hits2) else np.array([], int)),
        }
        if len(br):
            d = np.sqrt(((mA.X_[:, None] - br.source_points[None]) ** 2).sum(-1)).min(1)
            row["bridge_cov_move"] = float((d / mA.speed_ <= 1.0).mean())
        else:
            row["bridge_cov_move"] = 0.0
        row["latent"] = latent_transition(models, bridges, a, b, p99, low)
        motion, start, under = mg_transition(mA, mB, D, hits, scale)
        row["mg"] = window_stats(motion, start, BLEND, p99, low) | {"under_threshold": under}
        row["train_skate"] = stats[a]["skate"]
        rows.append(row)
    return rows


def fit_timing(data: Path, sizes=(100, 400, 800)) -> list[dict]:
    take = cc.load(data / "cmu" / "13" / "13_29.amc")[::STEP]
    bounds = [0, 114, 300, 477, 672, 948, 1146]
    out = []
    for n in sizes:
        parts, names = [], []
        for k in range(6):
            a, b = bounds[k], bounds[k + 1]
            have = sum(p.n_frames for p in parts)
            if have >= n:
                break
            parts.append(take[a : min(b, a + n - have)])
            names.append(f"s{k}")
        t0, w0 = time.process_time(), time.perf_counter()
        m = LatentModel().fit(parts, names)
        out.append(
            {
                "frames": m.X_.shape[0],
                "cpu_s": time.process_time() - t0,
                "wall_s": time.perf_counter() - w0,
                "iterations": m.gp_.n_iter_,
            }
        )
    return out


def synthesis_speed(m: LatentModel, name: str, seconds: float = 60.0) -> dict:
    syn = Synthesizer({name: m}, fps=FPS, seed=0)
    syn.start(name)
    rng = np.random.default_rng(0)
    while syn.t < seconds:
        syn.move({"frame": int(rng.integers(m.X_.shape[0]))}, path="line")
        syn.idle(duration=1.0)
    return {
        "frames": syn.n_frames,
        "seconds": syn.sim_seconds,
        "fps": syn.n_frames / syn.sim_seconds,
        "cpu_seconds": syn.sim_cpu_seconds,
        "cpu_fps": syn.n_frames / syn.sim_cpu_seconds,
        "training_frames": int(m.X_.shape[0]),
    }


def fmt(x, spec=".2f"):
    return "n/a" if x is None else format(x, spec)


def print_pairs(rows: list[dict]) -> None:
    """The pair table."""
    print("\n== transitions A -> B (threshold 1.5 % of bone length; blend 12 frames) ==")
    print(
        f"{'A':10} {'B':10} {'bridges':>7} {'MG':>4} | {'hops':>4} {'d/thr':>5} | coverage: "
        f"{'br play':>7} {'br move':>7} {'MG':>5} |"
        f" acc/p99: {'latent':>6} {'whole':>5} {'MG':>6} | jerk/p99: {'latent':>6} {'MG':>6} |"
        f" root acc: {'lat':>4} {'MG':>5} |"
        f" sliding: {'lat':>4} {'MG':>5} | toe skate: {'lat':>5} {'MG':>5} {'train':>5}"
    )
    for r in rows:
        lt, mg = r["latent"], r["mg"]
        star = "" if mg["under_threshold"] else "*"
        hops = "-" if lt is None else str(len(lt["route"]) - 1)
        slide_l = lt.get("skating_frames_contacts") if lt else None
        slide_m = mg.get("skating_frames_contacts")
        print(
            f"{r['from'][:10]:10} {r['to'][:10]:10} {r['bridges']:7d} {r['mg_transitions']:4d} |"
            f" {hops:>4} {fmt(lt and lt['distance_ratio']):>5} |"
            f"           {r['bridge_cov_play']:7.0%} {r['bridge_cov_move']:7.0%} "
            f"{r['mg_cov_play']:5.0%} |"
            f"          {fmt(lt and lt['acc']):>6} {fmt(lt and lt['acc_all']):>5} "
            f"{fmt(mg['acc']) + star:>6} |"
            f"           {fmt(lt and lt['jerk']):>6} {fmt(mg['jerk']) + star:>6} |"
            f"           {fmt(lt and lt['root_acc']):>4} {fmt(mg['root_acc']) + star:>5} |"
            f"          {fmt(slide_l, '.0%'):>4} {fmt(slide_m, '.0%') + star:>5} |"
            f"            {fmt(lt and lt['skate'], '.1f'):>5} {fmt(mg['skate'], '.1f') + star:>5} "
            f"{r['train_skate']:5.1f}"
        )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument(
        "--quick", action="store_true", help="two 13_29 models, short fits, no timing part"
    )
    ap.add_argument("--data", type=Path, default=default_data())
    ap.add_argument("--json", type=Path)
    ap.add_argument("--no-progress", action="store_true")
    ap.add_argument(
        "--plant",
        choices=("transitions", "all", "off"),
        default="transitions",
        help="where the latent root follows the planted feet (Synthesizer plant=)",
    )
    args = ap.parse_args(argv)
    global PLANT
    PLANT = args.plant
    if not (args.data / "cmu" / "13" / "13_29.amc").is_file():
        print(f"shared data not found at {args.data}; nothing to benchmark")
        return 0
    from threadpoolctl import threadpool_limits

    threadpool_limits(1)
    segs = load_segments(args.data, args.quick)
    models, tests, fits = fit_models(segs, args.quick)
    print("\n== models (30 fps, first 80 % of each segment) ==")
    print(
        f"{'model':15} {'frames':>6} {'pca':>4} {'fit cpu s':>9} {'wall s':>7} | RMS deg: "
        f"{'gplvm train':>11} {'left out':>8} {'(Eq.15)':>8} | {'pca3 train':>10} {'left out':>8}"
    )
    for r in fits:
        r.update(reconstruction(models[r["model"]], tests[r["model"]]))
        print(
            f"{r['model']:15} {r['frames']:6d} {r['pca']:4d} {r['fit_cpu_s']:9.1f} "
            f"{r['fit_wall_s']:7.1f} |"
            f"          {r['gplvm_train']:11.2f} {r['gplvm_left_out']:8.2f} "
            f"{r['gplvm_left_out_eq15']:8.2f} | "
            f"{r['pca_train']:10.2f} "
            f"{r['pca_left_out']:8.2f}"
        )
    stats = training_stats(models, tests)
    rows = pair_rows(models, stats, not args.no_progress)
    print_pairs(rows)
    n = len(rows)
    with_br = sum(r["bridges"] > 0 for r in rows)
    with_mg = sum(r["mg_transitions"] > 0 for r in rows)
    with_mg2 = sum(r["mg_transitions_2x"] > 0 for r in rows)
    with_br2 = sum(r["bridges_2x"] > 0 for r in rows)
    worst = max((r["latent"]["acc"] for r in rows if r["latent"]), default=None)
    reached = sum(r["latent"] is not None for r in rows)
    summary = {
        "pairs": n,
        "pairs_with_bridges": with_br,
        "pairs_with_mg": with_mg,
        "pairs_reached_latent": reached,
        "mean_cov_bridges_play": float(np.mean([r["bridge_cov_play"] for r in rows])),
        "mean_cov_bridges_move": float(np.mean([r["bridge_cov_move"] for r in rows])),
        "mean_cov_mg": float(np.mean([r["mg_cov_play"] for r in rows])),
        "pairs_with_mg_2x": with_mg2,
        "pairs_with_bridges_2x": with_br2,
        "mean_cov_bridges_play_2x": float(np.mean([r["bridge_cov_play_2x"] for r in rows])),
        "mean_cov_mg_2x": float(np.mean([r["mg_cov_play_2x"] for r in rows])),
        "latent_worst_acc_ratio": worst,
        "latent_pairs_over_1.5": sum(1 for r in rows if r["latent"] and r["latent"]["acc"] > 1.5),
        "mg_pairs_over_1.5": sum(1 for r in rows if r["mg"]["acc"] > 1.5),
    }
    print(
        f"\npairs with bridges {with_br}/{n}, with motion-graph transitions {with_mg}/{n}; mean "
        "coverage "
        f"bridges {summary['mean_cov_bridges_play']:.0%} (play) / "
        f"{summary['mean_cov_bridges_move']:.0%} (move), "
        f"motion graph {summary['mean_cov_mg']:.0%}"
    )
    print(
        f"motion graph at twice the threshold: {with_mg2}/{n} pairs, mean coverage "
        f"{summary['mean_cov_mg_2x']:.0%}"
    )
    print(
        f"bridges at twice the threshold: {with_br2}/{n} pairs, mean coverage (play) "
        f"{summary['mean_cov_bridges_play_2x']:.0%}"
    )
    lat = [r["latent"] for r in rows if r["latent"]]
    if lat and "skating_frames_contacts" in lat[0]:
        mg_r = [r["mg"] for r in rows if r["latent"]]
        summary["skating_contacts"] = {
            "latent_frames": float(np.mean([x["skating_frames_contacts"] for x in lat])),
            "mg_frames": float(np.mean([x["skating_frames_contacts"] for x in mg_r])),
            "latent_speed_legs": float(np.mean([x["skating_speed_contacts"] for x in lat])),
            "mg_speed_legs": float(np.mean([x["skating_speed_contacts"] for x in mg_r])),
        }
        sc = summary["skating_contacts"]
        print(
            f"quality.contacts in the blend windows: planted feet slide on "
            f"{sc['latent_frames']:.0%} of the latent frames (plant={args.plant}), "
            f"{sc['mg_frames']:.0%} of the motion graph's; planted points' mean speed "
            f"{sc['latent_speed_legs']:.3f} / {sc['mg_speed_legs']:.3f} leg lengths/s"
        )
    bridged = sum(1 for x in lat if x["bridged"])
    direct = sum(1 for x in lat if len(x["route"]) == 2)
    summary.update(
        {
            "latent_pairs_bridged": bridged,
            "latent_pairs_direct": direct,
            "latent_worst_distance_ratio": max((x["distance_ratio"] for x in lat), default=None),
            "latent_worst_acc_whole": max((x["acc_all"] for x in lat), default=None),
            "latent_pairs_whole_over_1.5": sum(1 for x in lat if x["acc_all"] > 1.5),
            "latent_longest_blend": max((max(x["blend_frames"]) for x in lat), default=None),
        }
    )
    print(
        f"latent TRANSITION reaches {reached}/{n} pairs: {direct} directly, "
        f"{reached - direct} through other models; {bridged} over bridges only, "
        f"{reached - bridged} crossing somewhere at the closest poses above the threshold "
        f"(worst {fmt(summary['latent_worst_distance_ratio'])}x it); longest blend "
        f"{summary['latent_longest_blend']} frames"
    )
    summary["latent_pairs_root_over_1.5"] = sum(1 for x in lat if x["root_acc"] > 1.5)
    summary["mg_pairs_root_over_1.5"] = sum(1 for r in rows if r["mg"]["root_acc"] > 1.5)
    print(
        "root's horizontal acceleration in the blend windows over 1.5x the takes' p99: latent "
        f"{summary['latent_pairs_root_over_1.5']} of {reached} (worst "
        f"{fmt(max((x['root_acc'] for x in lat), default=None))}), motion graph "
        f"{summary['mg_pairs_root_over_1.5']} of {n}"
    )
    print(
        "target 1.5x p99 acceleration: latent blend windows over it "
        f"{summary['latent_pairs_over_1.5']} of {reached} (worst {fmt(worst)}), whole transitions (approach MOVEs included) "
        f"{summary['latent_pairs_whole_over_1.5']} of {reached} "
        f"(worst {fmt(summary['latent_worst_acc_whole'])}); motion graph windows "
        f"{summary['mg_pairs_over_1.5']} of {n}"
    )
    out = {"models": fits, "pairs": rows, "summary": summary}
    if not args.quick:
        out["fit_timing"] = fit_timing(args.data)
        print("\n== fitting time (13_29 frames, 30 fps; target: 800 frames < 60 s) ==")
        for r in out["fit_timing"]:
            print(
                f"{r['frames']:5d} frames: {r['cpu_s']:6.1f} s CPU, {r['wall_s']:6.1f} s wall, "
                f"{r['iterations']} iterations"
            )
        out["synthesis"] = synthesis_speed(models["Walk35"], "Walk35")
        s = out["synthesis"]
        print(
            f"\n== synthesis: {s['frames']} frames on the walk model ({s['training_frames']} "
            "training frames): "
            f"{s['cpu_seconds']:.2f} s CPU = {s['cpu_fps']:,.0f} frames per CPU second (target "
            "1,000); "
            f"{s['seconds']:.2f} s wall = {s['fps']:,.0f} frames/s on this shared machine =="
        )
    if args.json:
        from cyclecoord.io import atomic_write

        with atomic_write(args.json) as fh:
            json.dump(out, fh, indent=2, default=float)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
