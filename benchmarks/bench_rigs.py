"""Every shared rig through ``extract``, judged with the benchmark's own kinematics (issue 23, part 6).

Run from a checkout::

    python benchmarks/bench_rigs.py [--json rows.json] [--data DIR] [--only TEXT]

Files: every ``*.bvh`` under ``../shared/data/bvh`` (Bandai Namco walks, run and turning
walks; an Xsens walk) and the CMU takes 69_01, 143_01, 35_07, 35_08, 35_13 and 35_16
(``../shared/data/cmu``), each whole.  Each is loaded with ``cyclecoord.load`` and given to
``cyclecoord.extract`` with its default options (CPU and wall seconds are timed around
that call alone).  Everything else is measured here, with this file's own code:

* **Own parsers and forward kinematics.**  :func:`parse_bvh` and :func:`parse_asf` /
  :func:`parse_amc` read the files again; :func:`forward_kinematics` poses them.  BVH: a
  joint's rotation channels compose in the order they are listed (``Zrotation Xrotation
  Yrotation`` is ``Rz @ Rx @ Ry``), position channels replace the joint's OFFSET on their
  axis.  ASF/AMC: a bone's dofs compose in reverse listed order (``rx ry rz`` is ``Rz @
  Ry @ Rx``), its local rotation is ``C @ R(dofs) @ C.T`` with ``C`` its ``axis``, and the
  bone's end is its start plus the global rotation times ``length * direction``.  The
  cycle (``result.cycle``, a Motion) is posed with the same rig, its channel values looked
  up by ``(joint, dof)`` name.  The library's own ``motion.positions()`` is never used for
  a figure; it is compared with ours once per file (``fk check``, JSON only, and a note
  when they differ).
* **Body root, up, legs.**  The body root is the file's root, or, while that joint does
  not move and has one child, its child (the Bandai rig's static ``joint_Root`` ->
  ``Hips``).  Up is the axis of the figure's largest extent (sign +).  The legs are the two
  lowest leaf chains that leave the body root away from the chain of the highest leaf
  (the head); in each, the two adjacent longest bones are thigh and shin (hip, knee,
  ankle points), the leaf is the toe.
* **Root frame.**  Every point minus the body root's position, turned about up by minus
  the heading (the horizontal direction of the left-hip-minus-right-hip vector).  Pose
  distance = RMS over points of the 3-D point distance, in the file's length units; a
  frame step is the pose distance of consecutive frames.
* **Steady frames.**  The longest run of frames whose pose speed (frame steps, averaged
  over about a second) is at least half its 90th percentile: it drops the Xsens file's
  standing parts and reference pose, and keeps turns.  All capture figures below are
  over the steady frames.

Columns (per file):

* **rig** -- ``cyclecoord.rig.describe_rig(motion).summary()`` when that module exists;
  otherwise (``fallback``) the root's name, the joint count, fps and the units guessed from
  the figure's height (the median over frames of its vertical extent).
* **extract** -- ``ok``, ``REFUSED`` (``NoPeriodicMotionError``; the reason is printed
  below the table) or ``error``; CPU / wall seconds of the call.
* **period** -- ``result.period_frames``; **ac** and **ac%**: the period by the
  autocorrelation of the joint rotations (:func:`rotation_autocorrelation_period`: the
  entries of every non-root joint's local rotation matrix, which neither wrap nor flip,
  over the steady frames; first normalised-correlation peak at 0.3-3 s reaching 0.85 of
  the highest, refined by a parabola) and ours' difference from it; **strike** and
  **str%**: the median interval between same-foot strikes (:func:`foot_strikes`: the ankle,
  having risen above half its height range (p5-p95), comes down through the lowest
  quarter of it -- time interpolated between frames -- and its horizontal speed then
  drops under half its 90th percentile before it rises again) and ours' difference from
  it.
* **step/p99** -- the cycle's largest frame step, its seam (last to first frame) included,
  over the 99th percentile of the capture's steps.
* **near max**, **near med** -- each cycle pose's distance to its nearest captured pose,
  largest and median, over the capture's **spread**: the 90th percentile, over captured
  frames, of the distance to the nearest captured pose at least half a period away in
  time (how far one cycle's pose lies from the same pose in another cycle; the period is
  the strike period, or the autocorrelation's when no strikes were found), and at least
  the capture's median frame step (repetitions closer than that are as close as the
  sampling shows: a keyframed loop played over has a spread of 0).  At most 1
  means the cycle pose is as close to the capture as nine in ten captured poses are to
  another cycle (the median was tried first: on a take of two or three strides, half the
  captured poses are themselves farther than it from every other stride).  This is the
  definition of ``cyclecoord.quality.pose_space``, computed here with this file's own
  forward kinematics and search.
* **seam** -- the cycle's last-to-first step over the median of its own steps.
* **jerk/cut** -- mean jerk (third difference, cyclic, RMS over points, units/s^3) of the
  cycle over the best loop cut's; the **best loop cut** (:func:`loop_cut`, the rule of
  ``cyclecoord.quality.reference.best_loop_cut`` on the root-frame positions) is the
  captured stretch within 15 % of the period, among moving steady frames, whose end pose
  is closest to its start pose.
* **legs/cut** -- hip, knee and ankle angle of each leg (between bone vectors from the
  FK, signed about the hip-to-hip axis: hip = trunk-down (head to body root) to thigh,
  knee = thigh to shin, ankle = shin to the ankle-to-ball vector), the p1-p99 range in
  the cycle over the best cut's; the smallest ratio and its leg (named by its thigh
  joint) and angle.
* **cut pct**, **legs/med** -- context for legs/cut, not a target: the share of the
  one-period windows of the steady frames (one per starting frame) whose range of that
  lowest angle is below the cut's (the cut is one stride; at 90 % it is one of the
  widest), and the smallest range ratio of the cycle against the median window instead.

Targets (issue 23): ``TARGETS``, PASS/FAIL per file and target in a second table, and a
summary line.  CMU takes also carry the issue's "nothing lost on CMU" targets (period
within 2 % of the autocorrelation, jerk at most 1.5x the loop cut's).  Printed, never
asserted; many FAIL while the pipeline is being fixed.  ``tests/test_bench_rigs.py``
checks the measuring functions on synthetic data with known answers.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import math
import os
import subprocess
import sys
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import cyclecoord as cc  # noqa: E402
from cyclecoord.errors import NoPeriodicMotionError  # noqa: E402
from cyclecoord.io import atomic_write  # noqa: E402

#: ``../shared/data`` beside the checkout (never copied into the repo).
DATA_DIR = ROOT.parent / "shared" / "data"
#: The CMU takes, whole.
CMU_TAKES = ("69_01", "143_01", "35_07", "35_08", "35_13", "35_16")

#: Issue 23's targets: name -> (what, test on the row's figures).
TARGETS = {
    "not refused": "no walk or run refused with default options",
    "period~strikes": "period within 3 % of the foot-strike period",
    "step": "largest cycle step at most 2x the capture's p99 step",
    "near": "every cycle pose within the capture's spread of its nearest captured pose",
    "seam": "seam at most 1.5",
    "legs": "leg ranges at least 0.85 of the best loop cut's",
}
#: CMU only ("nothing lost on CMU").
CMU_TARGETS = {
    "period~ac": "period within 2 % of the autocorrelation",
    "jerk": "jerk at most 1.5x the loop cut's",
}
LIMITS = {"period~strikes": 3.0, "step": 2.0, "near": 1.0, "seam": 1.5, "legs": 0.85,
          "period~ac": 2.0, "jerk": 1.5}

#: Names of the translation and rotation dofs (cyclecoord's channel names).
_BVH_DOF = {"xposition": "tx", "yposition": "ty", "zposition": "tz",
            "xrotation": "rx", "yrotation": "ry", "zrotation": "rz"}
_AXIS = {"x": 0, "y": 1, "z": 2}


# ------------------------------------------------------------------ the rig
@dataclass
class RigJoint:
    """One joint: it sits at its parent's origin plus ``offset`` (parent frame, rest), and
    turns by ``axis @ R(channels) @ axis.T``; ``dofs`` in file order; ``compose`` the
    product order of the rotation matrices (``"ZXY"``: ``Rz @ Rx @ Ry``)."""

    name: str
    parent: int
    offset: np.ndarray
    dofs: list[str] = field(default_factory=list)
    compose: str = ""
    axis: np.ndarray = field(default_factory=lambda: np.eye(3))


@dataclass
class Rig:
    """Joints plus the points we measure: ``points[k] = (joint, vector)``, the point at the
    joint's origin plus its global rotation times ``vector``; ``point_parents`` make them a
    tree.  ``channels`` are ``(joint, dof)`` in the column order of the rig's frames."""

    joints: list[RigJoint]
    points: list[tuple[int, np.ndarray]]
    point_names: list[str]
    point_parents: list[int]
    fmt: str
    length_unit: float = 1.0

    @property
    def channels(self) -> list[tuple[str, str]]:
        return [(j.name, d) for j in self.joints for d in j.dofs]


def _elementary(axis: str, degrees: np.ndarray) -> np.ndarray:
    a = np.radians(np.asarray(degrees, dtype=float))
    c, s = np.cos(a), np.sin(a)
    m = np.zeros(a.shape + (3, 3))
    i = _AXIS[axis.lower()]
    j, k = (i + 1) % 3, (i + 2) % 3
    m[..., i, i] = 1.0
    m[..., j, j] = c
    m[..., k, k] = c
    m[..., j, k] = -s
    m[..., k, j] = s
    return m


def _compose(compose: str, values: dict[str, np.ndarray], n: int) -> np.ndarray:
    """``R = R_a @ R_b @ ...`` for the letters of ``compose``; angles by axis letter."""
    out = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
    for letter in compose:
        out = out @ _elementary(letter, values[letter.lower()])
    return out


def parse_bvh(text: str) -> tuple[Rig, np.ndarray, float]:
    """Our own BVH reader: ``(rig, frames (T, channels), fps)``."""
    tokens = text.split()
    joints: list[RigJoint] = []
    points: list[tuple[int, np.ndarray]] = []
    names: list[str] = []
    parents: list[int] = []
    stack: list[int] = []  # joint indices
    i = 0
    pending: tuple[str, int] | None = None
    end_site = False
    while i < len(tokens):
        t = tokens[i]
        if t in ("ROOT", "JOINT"):
            pending = (tokens[i + 1], stack[-1] if stack else -1)
            i += 2
        elif t == "End":
            end_site, i = True, i + 2
        elif t == "{":
            if pending is not None:
                name, parent = pending
                joints.append(RigJoint(name, parent, np.zeros(3)))
                stack.append(len(joints) - 1)
                pending = None
            i += 1
        elif t == "}":
            if end_site:
                end_site = False
            else:
                stack.pop()
            i += 1
        elif t == "OFFSET":
            v = np.array([float(x) for x in tokens[i + 1 : i + 4]])
            if end_site:
                j = stack[-1]
                points.append((j, v))
                names.append(f"{joints[j].name}/end")
                parents.append(names.index(joints[j].name))
            else:
                j = stack[-1]
                joints[j].offset = v
                points.append((j, np.zeros(3)))
                names.append(joints[j].name)
                parents.append(-1 if joints[j].parent < 0 else names.index(joints[joints[j].parent].name))
            i += 4
        elif t == "CHANNELS":
            n = int(tokens[i + 1])
            dofs = [_BVH_DOF[x.lower()] for x in tokens[i + 2 : i + 2 + n]]
            j = joints[stack[-1]]
            j.dofs = dofs
            j.compose = "".join(d[1].upper() for d in dofs if d[0] == "r")
            i += 2 + n
        elif t == "MOTION":
            break
        else:
            i += 1
    # MOTION: Frames: n, Frame Time: dt, then numbers
    k = tokens.index("MOTION", i)
    n_frames = int(tokens[k + 2])
    dt = float(tokens[k + 5])
    values = np.array(tokens[k + 6 :], dtype=float)
    width = sum(len(j.dofs) for j in joints)
    frames = values[: n_frames * width].reshape(n_frames, width)
    rig = Rig(joints, points, names, parents, "bvh")
    return rig, frames, 1.0 / dt


def parse_asf(text: str) -> Rig:
    """Our own ASF reader: bones become joints at their start; points are the root and
    every bone's end."""
    lines = [ln.split("#")[0].strip() for ln in text.splitlines()]
    section, bones, hierarchy, bone = None, {}, [], None
    root = {"order": [], "axis": "XYZ", "orientation": [0.0, 0.0, 0.0]}
    length_unit = 1.0
    radians = False
    for ln in lines:
        if not ln:
            continue
        if ln.startswith(":"):
            parts = ln.split()
            section = parts[0][1:]
            continue
        w = ln.split()
        if section == "units" and w[0] == "length":
            length_unit = float(w[1])
        elif section == "units" and w[0] == "angle":
            radians = w[1].lower().startswith("rad")
        elif section == "root":
            if w[0] == "order":
                root["order"] = [x.lower() for x in w[1:]]
            elif w[0] == "axis":
                root["axis"] = w[1]
            elif w[0] == "orientation":
                root["orientation"] = [float(x) for x in w[1:4]]
        elif section == "bonedata":
            if w[0] == "begin":
                bone = {"dof": [], "axis": ([0.0, 0.0, 0.0], "XYZ")}
            elif w[0] == "end":
                bones[bone["name"]] = bone
            elif w[0] == "name":
                bone["name"] = w[1]
            elif w[0] == "direction":
                bone["direction"] = np.array([float(x) for x in w[1:4]])
            elif w[0] == "length":
                bone["length"] = float(w[1])
            elif w[0] == "axis":
                bone["axis"] = ([float(x) for x in w[1:4]], w[4])
            elif w[0] == "dof":
                bone["dof"] = [x.lower() for x in w[1:]]
        elif section == "hierarchy" and w[0] not in ("begin", "end"):
            hierarchy.append(w)
    if radians:
        raise ValueError("ASF angles in radians are not handled by this benchmark")

    def axis_matrix(angles, order):
        vals = dict(zip("xyz", ([a] for a in angles)))
        return _compose(order[::-1].upper(), vals, 1)[0]  # "XYZ": x applied first

    parent_of = {c: p for w in hierarchy for p in w[:1] for c in w[1:]}
    order = ["root"]
    for w in hierarchy:  # parents listed before their children
        for c in w[1:]:
            if c not in order:
                order.append(c)
    rdofs = [d for d in root["order"]]
    joints = [RigJoint("root", -1, np.zeros(3), rdofs,
                       "".join(d[1].upper() for d in reversed(rdofs) if d[0] == "r"),
                       axis_matrix(root["orientation"], root["axis"]))]
    index = {"root": 0}
    points: list[tuple[int, np.ndarray]] = [(0, np.zeros(3))]
    names, parents = ["root"], [-1]
    for name in order[1:]:
        b = bones[name]
        p = parent_of[name]
        # the bone starts where its parent bone ends (the root: at the root)
        offset = np.zeros(3) if p == "root" else bones[p]["length"] * bones[p]["direction"]
        dofs = [d for d in b["dof"] if d in ("rx", "ry", "rz")]
        joints.append(RigJoint(name, index[p], offset, dofs,
                               "".join(d[1].upper() for d in reversed(dofs)),
                               axis_matrix(*b["axis"])))
        index[name] = len(joints) - 1
        points.append((index[name], b["length"] * b["direction"]))
        names.append(name)
        parents.append(0 if p == "root" else names.index(p))
    return Rig(joints, points, names, parents, "asf", length_unit)


def parse_amc(text: str, rig: Rig) -> np.ndarray:
    """Our own AMC reader: frames ``(T, channels)`` in ``rig.channels`` order."""
    col = {c: k for k, c in enumerate(rig.channels)}
    rows: list[np.ndarray] = []
    cur = None
    dofs = {j.name: j.dofs for j in rig.joints}
    for ln in text.splitlines():
        w = ln.split()
        if not w or w[0].startswith((":", "#")):
            continue
        if len(w) == 1 and w[0].isdigit():
            cur = np.zeros(len(col))
            rows.append(cur)
            continue
        if cur is None or w[0] not in dofs:
            continue
        for d, v in zip(dofs[w[0]], w[1:]):
            cur[col[(w[0], d)]] = float(v)
    return np.array(rows)


def rig_from_skeleton(skeleton) -> Rig:
    """A rig from a cyclecoord ``Skeleton`` (synthetic captures, which have no file):
    joints at their origins, plus end sites."""
    joints, points, names, parents = [], [], [], []
    for k, j in enumerate(skeleton.joints):
        joints.append(RigJoint(j.name, j.parent, np.array(j.offset, dtype=float), list(j.dofs),
                               j.rotation_order, np.array(j.axis, dtype=float)))
        points.append((k, np.zeros(3)))
        names.append(j.name)
        parents.append(j.parent)
    for k, j in enumerate(skeleton.joints):
        if j.end_site is not None:
            points.append((k, np.array(j.end_site, dtype=float)))
            names.append(f"{j.name}/end")
            parents.append(k)
    return Rig(joints, points, names, parents, skeleton.source_format or "synthetic",
               float(skeleton.length_unit))


def rig_frames(rig: Rig, motion) -> tuple[np.ndarray, int]:
    """A Motion's values in the rig's channel order, by ``(joint, dof)`` name; channels the
    motion lacks are NaN (offset / no rotation).  Also the number missing."""
    col = {c: k for k, c in enumerate(motion.channels)}
    out = np.full((motion.n_frames, len(rig.channels)), np.nan)
    missing = 0
    for k, c in enumerate(rig.channels):
        if c in col:
            out[:, k] = motion.frames[:, col[c]]
        else:
            missing += 1
    return out, missing


@dataclass
class Posed:
    """Forward kinematics: ``points (T, P, 3)`` world positions, ``local (T, J, 3, 3)``
    local rotations, ``rot (T, J, 3, 3)`` global rotations."""

    points: np.ndarray
    local: np.ndarray
    rot: np.ndarray
    origins: np.ndarray


def forward_kinematics(rig: Rig, frames: np.ndarray) -> Posed:
    """Our own FK: world position of every rig point for every frame."""
    frames = np.asarray(frames, dtype=float)
    T = frames.shape[0]
    J = len(rig.joints)
    local = np.empty((T, J, 3, 3))
    rot = np.empty((T, J, 3, 3))
    org = np.empty((T, J, 3))
    k = 0
    for i, j in enumerate(rig.joints):
        vals = {d: frames[:, k + m] for m, d in enumerate(j.dofs)}
        k += len(j.dofs)
        t = np.broadcast_to(j.offset, (T, 3)).copy()
        for d, v in vals.items():
            if d[0] == "t":
                t[:, _AXIS[d[1]]] = np.where(np.isfinite(v), v, t[:, _AXIS[d[1]]])
        angles = {d[1]: np.nan_to_num(v) for d, v in vals.items() if d[0] == "r"}
        r = _compose(j.compose, angles, T)
        local[:, i] = j.axis @ r @ j.axis.T
        if j.parent < 0:
            rot[:, i] = local[:, i]
            org[:, i] = t
        else:
            rot[:, i] = rot[:, j.parent] @ local[:, i]
            org[:, i] = org[:, j.parent] + np.einsum("tab,tb->ta", rot[:, j.parent], t)
    pts = np.stack(
        [org[:, j] + np.einsum("tab,b->ta", rot[:, j], v) for j, v in rig.points], axis=1
    )
    return Posed(pts, local, rot, org)


# ------------------------------------------------------------- body layout
@dataclass
class Body:
    """What the measures need of a rig: up axis, body root point, legs."""

    up: int
    root_joint: int
    root_point: int
    legs: list[dict]  # name, hip, knee, ankle, ball, toe (point indices)
    head: int
    height: float


def _chain(rig: Rig, point: int) -> list[int]:
    out = [point]
    while rig.point_parents[out[-1]] >= 0:
        out.append(rig.point_parents[out[-1]])
    return out[::-1]


def body_layout(rig: Rig, posed: Posed) -> Body:
    """Up axis, body root, head and the two legs of a rig, from its posed points."""
    # body root: descend while the joint stays put and has one child
    size = sum(float(np.linalg.norm(j.offset)) for j in rig.joints) + sum(
        float(np.linalg.norm(v)) for _, v in rig.points)
    rj = 0
    while True:
        kids = [i for i, j in enumerate(rig.joints) if j.parent == rj]
        moves = np.ptp(posed.origins[:, rj], axis=0).max() > 1e-6 * max(size, 1e-9)
        if len(kids) != 1 or moves:
            break
        rj = kids[0]
    rp = next(k for k, (j, v) in enumerate(rig.points) if j == rj and not np.any(v))
    # the figure: the body root and every point below it (not a static root at the origin)
    figure = [k for k in range(len(rig.points)) if rp in _chain(rig, k)]
    pts = posed.points
    fig = pts[:, figure]
    extent = np.median(fig.max(axis=1) - fig.min(axis=1), axis=0)
    up = int(np.argmax(extent))
    height = float(extent[up])
    rel_h = (pts[:, :, up] - pts[:, rp : rp + 1, up]).mean(axis=0)
    leaves = [k for k in range(len(rig.points)) if k not in rig.point_parents]
    below = {k: _chain(rig, k) for k in leaves}
    below = {k: c[c.index(rp) + 1 :] for k, c in below.items() if rp in c and c[-1] != rp}
    head = max(below, key=lambda k: rel_h[k])
    head_branch = below[head][0]
    legs, used = [], set()
    for k in sorted(below, key=lambda k: rel_h[k]):
        c = below[k]
        if not c or c[0] == head_branch or c[0] in used:
            continue
        chain = [rp] + c
        seg = [np.linalg.norm(pts[:, b] - pts[:, a], axis=1).mean() for a, b in zip(chain, chain[1:])]
        if len(seg) < 2:
            continue
        m = int(np.argmax([seg[s] + seg[s + 1] for s in range(len(seg) - 1)]))
        # named by the joint that turns the thigh: the knee point's own joint when the
        # point is a bone's end (ASF), else that joint's parent (the knee joint's origin)
        j, v = rig.points[chain[m + 1]]
        thigh = j if np.any(v) else rig.joints[j].parent
        legs.append({"name": rig.joints[thigh].name, "hip": chain[m], "knee": chain[m + 1],
                     "ankle": chain[m + 2], "ball": chain[min(m + 3, len(chain) - 1)],
                     "toe": chain[-1]})
        used.add(c[0])
        if len(legs) == 2:
            break
    if len(legs) < 2:
        raise ValueError("could not find two legs below the body root")
    # left leg first: the one on the body's left (+ cross of up and forward is arbitrary,
    # so order by name only for a stable output)
    legs.sort(key=lambda leg: leg["name"])
    return Body(up, rj, rp, legs, head, height)


def _horizontal(up: int) -> list[int]:
    return [a for a in range(3) if a != up]


def heading(points: np.ndarray, body: Body) -> np.ndarray:
    """Heading per frame (radians): the angle of the horizontal hip-to-hip vector."""
    a, b = _horizontal(body.up)
    v = points[:, body.legs[0]["hip"]] - points[:, body.legs[1]["hip"]]
    return np.arctan2(v[:, b], v[:, a])


def root_frame(points: np.ndarray, body: Body) -> np.ndarray:
    """Points ``(T, P, 3)`` relative to the body root, heading removed."""
    rel = points - points[:, body.root_point : body.root_point + 1]
    h = heading(points, body)
    a, b = _horizontal(body.up)
    c, s = np.cos(-h)[:, None], np.sin(-h)[:, None]
    out = rel.copy()
    out[:, :, a] = c * rel[:, :, a] - s * rel[:, :, b]
    out[:, :, b] = s * rel[:, :, a] + c * rel[:, :, b]
    return out


def pose_vectors(points: np.ndarray, body: Body) -> np.ndarray:
    """Root-frame poses flattened to ``(T, 3P)``, scaled so the Euclidean distance of two
    rows is the RMS point distance.  Points before the body root (a static root above a
    travelling hips: its ancestors, which come first in file order) are left out: relative
    to the hips they travel with the walk."""
    x = root_frame(points, body)[:, body.root_point:]
    return x.reshape(len(x), -1) / math.sqrt(x.shape[1])


# ------------------------------------------------------------- the measures
def steps(x: np.ndarray, cyclic: bool = False) -> np.ndarray:
    """Pose distance of consecutive rows (and last to first when ``cyclic``)."""
    y = np.concatenate([x, x[:1]]) if cyclic else x
    return np.linalg.norm(np.diff(y, axis=0), axis=1)


def steady_frames(x: np.ndarray, fps: float) -> tuple[int, int]:
    """The longest run of frames moving at least half the 90th percentile of the pose
    speed averaged over about a second (at most a third of the take)."""
    s = steps(x)
    if s.size < 3:
        return 0, len(x)
    w = max(1, min(int(round(fps)), len(s) // 3))
    avg = np.convolve(s, np.ones(w) / w, mode="same")
    moving = avg >= 0.5 * np.percentile(avg, 90)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], moving.astype(int), [0]])))
    runs = list(zip(edges[::2], edges[1::2]))
    a, b = max(runs, key=lambda r: r[1] - r[0])
    return int(a), int(b) + 1  # steps a..b-1 join frames a..b


def _parabola(y0: float, y1: float, y2: float) -> float:
    den = y0 - 2 * y1 + y2
    return float(np.clip(0.5 * (y0 - y2) / den, -0.5, 0.5)) if den < 0 else 0.0


def rotation_autocorrelation_period(
    local: np.ndarray, joints: Sequence[int], fps: float, min_lag: float = 0.3,
    max_lag: float = 3.0, share: float = 0.85,
) -> float:
    """Period (frames) from the autocorrelation of the local rotation matrices of
    ``joints`` (their 9 entries each: no wraps, no Euler flips); NaN when no peak."""
    x = local[:, list(joints)].reshape(len(local), -1)
    x = x - x.mean(axis=0)
    T = len(x)
    lo = max(2, int(math.floor(min_lag * fps)))
    hi = min(int(math.ceil(max_lag * fps)), int(0.75 * T))
    if hi - lo < 3:
        return float("nan")
    lags = np.arange(lo - 1, hi + 2)
    r = np.full(lags.size, np.nan)
    for n, lag in enumerate(lags):
        a, b = x[: T - lag], x[lag:]
        den = math.sqrt(float(np.sum(a * a)) * float(np.sum(b * b)))
        r[n] = float(np.sum(a * b)) / den if den > 0 else np.nan
    inner = np.arange(1, lags.size - 1)
    peaks = inner[(r[inner] >= r[inner - 1]) & (r[inner] > r[inner + 1]) & (r[inner] > 0.3)]
    if peaks.size == 0:
        return float("nan")
    k = int(peaks[np.argmax(r[peaks] >= share * r[peaks].max())])
    return float(lags[k] + _parabola(r[k - 1], r[k], r[k + 1]))


def foot_strikes(height: np.ndarray, speed: np.ndarray, fps: float, low: float = 0.25,
                 high: float = 0.5, slow: float = 0.5) -> np.ndarray:
    """Strike times (frames, fractional) of one foot.

    The foot is up once its height rises above ``high`` of its range (p5-p95) and comes
    down when it falls through ``low`` of it (the crossing is interpolated between
    frames); the two levels keep wobbles in stance from counting twice.  A landing
    counts when the horizontal speed drops under ``slow`` times its 90th percentile
    before the foot is up again (a foot still at the floor when the frames begin is no
    landing).  ``fps`` is unused: the rule has no time constant."""
    del fps
    h = np.asarray(height, dtype=float)
    v = np.asarray(speed, dtype=float)
    p5, p95 = np.percentile(h, [5, 95])
    lo, hi = p5 + low * (p95 - p5), p5 + high * (p95 - p5)
    vthr = slow * np.percentile(v, 90)
    out, up, landed = [], False, None
    for t in range(len(h)):
        if h[t] > hi:
            up = True
        elif up and h[t] <= lo:
            up = False
            frac = (h[t - 1] - lo) / (h[t - 1] - h[t]) if h[t - 1] != h[t] else 1.0
            landed = t - 1 + float(np.clip(frac, 0.0, 1.0))
        if landed is not None and not up and v[t] <= vthr:
            out.append(landed)
            landed = None
        if up:
            landed = None  # lifted again without slowing down: no strike
    return np.array(out)


def strike_period(points: np.ndarray, body: Body, fps: float) -> tuple[float, int]:
    """Median interval between same-foot strikes (frames) and the number of strikes,
    from world positions (the ankle's height and horizontal speed)."""
    horiz = _horizontal(body.up)
    intervals, count = [], 0
    for leg in body.legs:
        p = points[:, leg["ankle"]]
        speed = np.linalg.norm(np.gradient(p[:, horiz], axis=0), axis=1) * fps
        t = foot_strikes(p[:, body.up], speed, fps)
        count += len(t)
        d = np.diff(t)
        intervals.extend(d[d >= 0.3 * fps])
    return (float(np.median(intervals)) if intervals else float("nan")), count


def _signed_angle(u: np.ndarray, v: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Degrees from ``u`` to ``v`` about ``axis`` (all (T, 3)), in the plane normal to it."""
    n = axis / np.linalg.norm(axis, axis=1, keepdims=True)
    u = u - np.sum(u * n, axis=1, keepdims=True) * n
    v = v - np.sum(v * n, axis=1, keepdims=True) * n
    return np.degrees(np.arctan2(np.sum(np.cross(u, v) * n, axis=1), np.sum(u * v, axis=1)))


def leg_angles(points: np.ndarray, body: Body) -> dict[str, np.ndarray]:
    """Hip, knee and ankle flexion (degrees) of each leg, from bone vectors."""
    lateral = points[:, body.legs[0]["hip"]] - points[:, body.legs[1]["hip"]]
    down = points[:, body.root_point] - points[:, body.head]
    out = {}
    for leg in body.legs:
        hip, knee, ankle, ball = (points[:, leg[k]] for k in ("hip", "knee", "ankle", "ball"))
        thigh, shin, foot = knee - hip, ankle - knee, ball - ankle
        out[f"{leg['name']} hip"] = _signed_angle(down, thigh, lateral)
        out[f"{leg['name']} knee"] = _signed_angle(thigh, shin, lateral)
        out[f"{leg['name']} ankle"] = _signed_angle(shin, foot, lateral)
    return out


def angle_range(a: np.ndarray) -> float:
    a = np.unwrap(np.radians(a))
    lo, hi = np.percentile(np.degrees(a), [1, 99])
    return float(hi - lo)


def mean_jerk(x: np.ndarray, fps: float) -> float:
    """Mean norm of the cyclic third difference of ``x`` (a loop), per s^3."""
    j = np.roll(x, -2, axis=0) - 3 * np.roll(x, -1, axis=0) + 3 * x - np.roll(x, 1, axis=0)
    return float(np.mean(np.linalg.norm(j, axis=1)) * fps**3)


def nearest_distances(a: np.ndarray, b: np.ndarray, exclude_within: float | None = None) -> np.ndarray:
    """For each row of ``a`` its distance to the nearest row of ``b``; with
    ``exclude_within`` (a = b, frames), rows closer in time than that are skipped."""
    out = np.empty(len(a))
    idx = np.arange(len(b))
    bb = np.sum(b * b, axis=1)
    for s in range(0, len(a), 512):
        blk = a[s : s + 512]
        d2 = np.sum(blk * blk, axis=1)[:, None] + bb[None] - 2 * blk @ b.T
        if exclude_within is not None:
            near = np.abs(np.arange(s, s + len(blk))[:, None] - idx[None]) < exclude_within
            d2[near] = np.inf
        k = d2.argmin(axis=1)  # the expansion finds the nearest; its distance is recomputed
        dist = np.linalg.norm(blk - b[k], axis=1)
        dist[~np.isfinite(d2[np.arange(len(blk)), k])] = np.nan  # every row excluded
        out[s : s + len(blk)] = dist
    return out


def loop_cut(poses: np.ndarray, period: float, steady: tuple[int, int],
             tolerance: float = 0.15) -> tuple[int, int, float]:
    """The best loop cut: frames ``i .. j-1`` of the steady frames, ``j - i`` within
    ``tolerance`` of the period, whose end pose ``j`` is nearest its start pose ``i``,
    among stretches moving at least half the steady frames' median step (no standing).
    Returns ``(i, j, distance)``; ties go to the length nearest the period.

    The rule of ``cyclecoord.quality.reference.best_loop_cut``, on the root-frame
    positions, except for its moving test (a cut's mean step at least the take's median
    step): on an exactly periodic walk the mean step is below the median, so that test
    turns down every one-period cut."""
    a, b = steady
    x = poses[a:b]
    if not np.isfinite(period) or period < 2:
        raise ValueError(f"no loop cut: period {period!r} frames")
    s = steps(x)
    csum = np.concatenate([[0.0], np.cumsum(s)])
    floor = 0.5 * float(np.median(s))
    best = (np.inf, np.inf, -1, -1)
    for n in range(max(2, math.ceil(period * (1 - tolerance))), math.floor(period * (1 + tolerance)) + 1):
        if n >= len(x):
            break
        i = np.arange(len(x) - n)
        ok = (csum[i + n] - csum[i]) / n >= floor
        if not ok.any():
            continue
        d = np.linalg.norm(x[i[ok] + n] - x[i[ok]], axis=1)
        k = int(np.argmin(d))
        key = (float(d[k]), abs(n - period))
        if key < best[:2]:
            best = (*key, int(i[ok][k]), int(i[ok][k]) + n)
    if best[2] < 0:
        raise ValueError(f"no loop cut of {period:.1f} frames +-{100 * tolerance:g} % fits in "
                         f"the {len(x)} steady frames")
    return a + best[2], a + best[3], best[0]


def _ratio(a: float, b: float) -> float:
    """``a / b``, with 0 / 0 = 0 (an exactly periodic capture has no spread)."""
    return 0.0 if a == 0 else (float(a / b) if b > 0 else float("inf"))


@dataclass
class Capture:
    """A capture posed by our FK: everything the measures of a cycle compare against."""

    rig: Rig
    body: Body
    fps: float
    points: np.ndarray
    local: np.ndarray
    poses: np.ndarray
    steady: tuple[int, int]


def prepare_capture(rig: Rig, frames: np.ndarray, fps: float) -> Capture:
    posed = forward_kinematics(rig, frames)
    body = body_layout(rig, posed)
    poses = pose_vectors(posed.points, body)
    return Capture(rig, body, fps, posed.points, posed.local, poses, steady_frames(poses, fps))


def references(cap: Capture) -> dict[str, Any]:
    """The two periods of the steady frames: rotation autocorrelation and foot strikes."""
    a, b = cap.steady
    joints = [i for i, j in enumerate(cap.rig.joints)
              if i > cap.body.root_joint and j.compose and _below(cap.rig, i, cap.body.root_joint)]
    ac = rotation_autocorrelation_period(cap.local[a:b], joints, cap.fps)
    strike, n = strike_period(cap.points[a:b], cap.body, cap.fps)
    return {"ac_period": ac, "strike_period": strike, "strikes": n}


def _below(rig: Rig, joint: int, ancestor: int) -> bool:
    while joint >= 0:
        joint = rig.joints[joint].parent
        if joint == ancestor:
            return True
    return False


def measure_cycle(cap: Capture, cycle_frames: np.ndarray, cycle_fps: float,
                  period: float) -> dict[str, Any]:
    """Quality of a cycle (channel values in the rig's order) against the capture's
    steady frames, all in root-frame FK positions; ``period`` (frames) sets the quarter
    period of the spread's exclusion and the loop cut's length."""
    a, b = cap.steady
    x = cap.poses[a:b]
    posed = forward_kinematics(cap.rig, cycle_frames)
    y = pose_vectors(posed.points, cap.body)
    cap_steps = steps(x)
    p99 = float(np.percentile(cap_steps, 99))
    cyc_steps = steps(y, cyclic=True)
    spread = float(np.nanpercentile(nearest_distances(x, x, exclude_within=period / 2), 90))
    spread = max(spread, float(np.median(cap_steps)))  # no finer than the sampling
    near = nearest_distances(y, x)
    out: dict[str, Any] = {
        "cycle_frames": int(len(y)),
        "capture_p99_step": p99,
        "capture_median_step": float(np.median(cap_steps)),
        "largest_step": float(cyc_steps.max()),
        "step_over_p99": float(cyc_steps.max() / p99),
        "spread": spread,
        "near_max": _ratio(near.max(), spread),
        "near_median": _ratio(np.median(near), spread),
        "near_max_units": float(near.max()),
        "seam": float(cyc_steps[-1] / np.median(cyc_steps[:-1])),
        "seam_units": float(cyc_steps[-1]),
    }
    try:
        start, stop, gap = loop_cut(cap.poses, period, cap.steady)
    except ValueError as exc:
        out["cut_error"] = str(exc)
        return out
    out.update(cut_start=start, cut_stop=stop, cut_gap=gap)
    cut_pts = cap.points[start:stop]
    out["jerk_cycle"] = mean_jerk(y, cycle_fps)
    out["jerk_cut"] = mean_jerk(cap.poses[start:stop], cap.fps)
    out["jerk_over_cut"] = out["jerk_cycle"] / out["jerk_cut"]
    ours, theirs = leg_angles(posed.points, cap.body), leg_angles(cut_pts, cap.body)
    ratios = {k: angle_range(ours[k]) / angle_range(theirs[k]) for k in ours}
    worst = min(ratios, key=ratios.get)
    out.update(leg_ratios=ratios, legs_min=ratios[worst], legs_min_joint=worst)
    # context, not a target: the same ratios against the median over every one-period
    # window of the steady frames, and where the cut's range sits among those windows
    windows = window_leg_ranges(cap, stop - start)
    if windows:
        med = {k: angle_range(ours[k]) / float(np.median(v)) for k, v in windows.items()}
        low = min(med, key=med.get)
        cut_rank = {k: float(np.mean(np.asarray(windows[k]) < angle_range(theirs[k])))
                    for k in windows}
        out.update(legs_over_median_window=med, legs_median_min=med[low],
                   legs_median_min_joint=low, cut_percentile=cut_rank,
                   cut_percentile_of_worst=cut_rank[worst])
    return out


def window_leg_ranges(cap: Capture, length: int) -> dict[str, list[float]]:
    """The p1-p99 range of each leg angle over every window of ``length`` frames (one
    per starting frame) inside the steady frames: how much one stride's range varies."""
    a, b = cap.steady
    if length < 2 or b - a <= length:
        return {}
    angles = leg_angles(cap.points[a:b], cap.body)
    return {k: [angle_range(v[i : i + length]) for i in range(0, b - a - length + 1)]
            for k, v in angles.items()}


# ----------------------------------------------------------------- one file
@dataclass(frozen=True)
class Case:
    name: str
    path: Path | None
    kind: str  # "bvh", "cmu" or "synthetic"
    motion: Any = None  # synthetic: the Motion itself


def cases(data_dir: Path = DATA_DIR) -> tuple[list[Case], list[str]]:
    out, skipped = [], []
    bvh = sorted((data_dir / "bvh").rglob("*.bvh")) if (data_dir / "bvh").is_dir() else []
    if not bvh:
        skipped.append(f"no BVH files under {data_dir / 'bvh'}")
    for p in bvh:
        out.append(Case(str(p.relative_to(data_dir / "bvh")), p, "bvh"))
    for take in CMU_TAKES:
        p = data_dir / "cmu" / take.split("_")[0] / f"{take}.amc"
        if p.is_file():
            out.append(Case(f"cmu/{take}", p, "cmu"))
        else:
            skipped.append(f"cmu/{take}: {p} not found, skipped")
    return out, skipped


def load_own(case: Case) -> tuple[Rig, np.ndarray, float]:
    """Our own reading of the file (or the synthetic motion's skeleton)."""
    if case.kind == "synthetic":
        m = case.motion
        rig = rig_from_skeleton(m.skeleton)
        return rig, rig_frames(rig, m)[0], m.fps
    text = case.path.read_text()
    if case.path.suffix.lower() == ".bvh":
        return parse_bvh(text)
    asf = next(case.path.parent.glob("*.asf"))
    rig = parse_asf(asf.read_text())
    return rig, parse_amc(text, rig), 120.0


def units_guess(height: float, rig: Rig) -> str:
    """The length unit that makes the figure 1.2-2.2 m tall."""
    if rig.fmt == "asf":
        metres = height / rig.length_unit * 0.0254
        return f"ASF length {rig.length_unit:g} (1/{rig.length_unit:g} inch): {metres:.2f} m"
    for unit, scale in (("m", 1.0), ("cm", 0.01), ("mm", 0.001), ("inch", 0.0254)):
        if 1.2 <= height * scale <= 2.2:
            return f"{unit} ({height * scale:.2f} m)"
    return "unknown"


def describe(motion, rig: Rig, body: Body) -> tuple[str, str]:
    """``(source, line)``: the library's rig summary when it has one, else ours."""
    try:
        from cyclecoord.rig import describe_rig  # being written (issue 23 part 2)

        return "cyclecoord.rig", str(describe_rig(motion).summary())
    except (ImportError, AttributeError):
        pass
    root = rig.joints[0].name
    moving = "" if body.root_joint == 0 else f", static root, {rig.joints[body.root_joint].name} travels"
    return "fallback", (f"root {root} ({len(rig.joints)} joints{moving}), {motion.fps:g} fps, "
                        f"{'XYZ'[body.up]}-up, height {body.height:.4g} -> {units_guess(body.height, rig)}")


def fk_check(motion, rig: Rig, own_points: np.ndarray) -> float | None:
    """Largest distance between our FK of the file and the library's ``positions()`` of
    its loaded motion, at the points both name (None when it cannot be computed)."""
    try:
        lib = motion.positions()
    except Exception:  # noqa: BLE001 - a check, never a reason to stop
        return None
    names = {n: k for k, n in enumerate(lib.names)}
    worst = 0.0
    for k, name in enumerate(rig.point_names):
        if rig.fmt == "asf" and name != "root":
            # our point is the bone's end: the library's "<bone>/end" or a child's start
            kids = [rig.joints[i].name for i, j in enumerate(rig.joints)
                    if j.parent == rig.points[k][0]]
            name = f"{name}/end" if f"{name}/end" in names else (kids[0] if kids else None)
        if name not in names:
            continue
        d = np.linalg.norm(lib.positions[:, names[name]] - own_points[:, k], axis=1).max()
        worst = max(worst, float(d))
    return worst


def _reason(exc: Exception, motion) -> str:
    """The error's first line without the file name it starts with."""
    text = str(exc).splitlines()[0]
    for prefix in (f"{motion.source}: ", f"{Path(str(motion.source)).name}: "):
        if motion.source and text.startswith(prefix):
            return text[len(prefix):]
    return text


def run_case(case: Case) -> dict[str, Any]:
    """Everything for one file."""
    row: dict[str, Any] = {"file": case.name, "kind": case.kind}
    motion = case.motion if case.kind == "synthetic" else cc.load(case.path)
    rig, frames, fps = load_own(case)
    if case.kind == "cmu":
        fps = motion.fps  # AMC files store no rate
    cap = prepare_capture(rig, frames, fps)
    row.update(frames=int(len(frames)), fps=fps, steady=list(cap.steady))
    row["rig_source"], row["rig"] = describe(motion, rig, cap.body)
    row["legs"] = [leg["name"] for leg in cap.body.legs]
    row["fk_check"] = fk_check(motion, rig, cap.points)
    row["fk_check_relative"] = None if row["fk_check"] is None else row["fk_check"] / cap.body.height
    row.update(references(cap))
    c0, w0 = time.process_time(), time.perf_counter()
    result = None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = cc.extract(motion)
        row["status"] = "ok"
    except NoPeriodicMotionError as exc:
        row["status"], row["reason"] = "refused", _reason(exc, motion)
    except cc.CycleCoordError as exc:
        row["status"], row["reason"] = "error", f"{type(exc).__name__}: {_reason(exc, motion)}"
    row["cpu_s"] = time.process_time() - c0
    row["wall_s"] = time.perf_counter() - w0
    ref = row["strike_period"] if np.isfinite(row["strike_period"]) else row["ac_period"]
    if result is None:
        return row
    row["period"] = float(result.period_frames)
    row["used_frames"] = [list(map(int, u)) for u in result.used_frames]
    row["warnings"] = list(result.warnings)
    for key, name in (("ac_period", "ac_pct"), ("strike_period", "strike_pct")):
        row[name] = 100.0 * (row["period"] / row[key] - 1.0) if np.isfinite(row[key]) else None
    cyc, missing = rig_frames(rig, result.cycle)
    row["cycle_missing_channels"] = missing
    if not np.isfinite(ref):
        ref = row["period"]
    row["quality"] = measure_cycle(cap, cyc, result.cycle.fps, ref)
    return row


def verdicts(row: dict) -> dict[str, bool | None]:
    """PASS (True) / FAIL (False) / not measured (None) per target."""
    q = row.get("quality", {})
    ok = row.get("status") == "ok"

    def at_most(x, lim):
        return None if x is None or not np.isfinite(x) else bool(x <= lim)

    out = {
        "not refused": ok,
        "period~strikes": at_most(None if row.get("strike_pct") is None else abs(row["strike_pct"]),
                                  LIMITS["period~strikes"]) if ok else None,
        "step": at_most(q.get("step_over_p99"), LIMITS["step"]),
        "near": at_most(q.get("near_max"), LIMITS["near"]),
        "seam": at_most(q.get("seam"), LIMITS["seam"]),
        "legs": None if q.get("legs_min") is None else bool(q["legs_min"] >= LIMITS["legs"]),
    }
    if row.get("kind") == "cmu":
        out["period~ac"] = at_most(None if row.get("ac_pct") is None else abs(row["ac_pct"]),
                                   LIMITS["period~ac"]) if ok else None
        out["jerk"] = at_most(q.get("jerk_over_cut"), LIMITS["jerk"])
    return out


def run_benchmark(selected: Sequence[Case], skipped: Sequence[str] = ()) -> dict:
    machine = {
        "date": _dt.datetime.now().astimezone().isoformat(timespec="seconds"),
        "cyclecoord": cc.__version__,
        "git": _git_state(),
        "load_average_start": _load(),
    }
    c0, w0 = time.process_time(), time.perf_counter()
    rows = []
    for case in selected:
        try:
            row = run_case(case)
        except Exception as exc:  # noqa: BLE001 - one broken file must not stop the table
            row = {"file": case.name, "kind": case.kind, "status": "benchmark error",
                   "reason": f"{type(exc).__name__}: {exc}"}
        row["targets"] = verdicts(row)
        rows.append(row)
    machine["load_average_end"] = _load()
    return {"machine": machine, "skipped": list(skipped), "rows": rows,
            "targets": {**TARGETS, **{f"CMU {k}": v for k, v in CMU_TARGETS.items()}},
            "cpu_seconds": time.process_time() - c0, "wall_seconds": time.perf_counter() - w0}


# -------------------------------------------------------------------- print
def _git_state() -> str | None:
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                              capture_output=True, text=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT,
                               capture_output=True, text=True, timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return head + ("+dirty" if dirty else "")


def _load() -> list[float] | None:
    return [round(v, 2) for v in os.getloadavg()] if hasattr(os, "getloadavg") else None


def _f(x: Any, fmt: str = "{:.2f}") -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else fmt.format(x)


def _table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    widths = [max([len(h)] + [len(r[i]) for r in rows]) for i, h in enumerate(headers)]

    def line(cells):
        return "  ".join(c.ljust(w) if i == 0 else c.rjust(w)
                         for i, (c, w) in enumerate(zip(cells, widths))).rstrip()

    return "\n".join([line(headers), line(["-" * w for w in widths]), *map(line, rows)])


FIGURE_HEADERS = ["file", "frames", "steady", "extract", "cpu s", "wall s", "period", "ac",
                  "ac%", "strike", "str%", "step/p99", "near max", "near med", "seam",
                  "jerk/cut", "legs/cut", "lowest leg joint", "cut pct", "legs/med"]


def figure_rows(report: dict) -> list[list[str]]:
    out = []
    for r in report["rows"]:
        q = r.get("quality", {})
        st = r.get("steady")
        status = {"ok": "ok", "refused": "REFUSED"}.get(r.get("status"), "error")
        out.append([
            r["file"], _f(r.get("frames"), "{}"), "-" if not st else f"{st[0]}:{st[1]}", status,
            _f(r.get("cpu_s")), _f(r.get("wall_s")), _f(r.get("period"), "{:.1f}"),
            _f(r.get("ac_period"), "{:.1f}"), _f(r.get("ac_pct"), "{:+.1f}"),
            _f(r.get("strike_period"), "{:.1f}"), _f(r.get("strike_pct"), "{:+.1f}"),
            _f(q.get("step_over_p99")), _f(q.get("near_max")), _f(q.get("near_median")),
            _f(q.get("seam")), _f(q.get("jerk_over_cut")), _f(q.get("legs_min")),
            q.get("legs_min_joint") or "-", _f(q.get("cut_percentile_of_worst"), "{:.0%}"),
            _f(q.get("legs_median_min")),
        ])
    return out


TARGET_HEADERS = ["file", *TARGETS, *(f"CMU {k}" for k in CMU_TARGETS), "verdict"]


def target_rows(report: dict) -> list[list[str]]:
    word = {True: "PASS", False: "FAIL", None: "-"}
    out = []
    for r in report["rows"]:
        t = r["targets"]
        cells = [word[t.get(k)] for k in (*TARGETS, *CMU_TARGETS)]
        failed = [k for k, v in t.items() if v is False]
        unmeasured = [k for k, v in t.items() if v is None]
        verdict = "FAIL" if failed else ("PASS" if not unmeasured else "incomplete")
        out.append([r["file"], *cells, verdict])
    return out


def format_report(report: dict) -> str:
    m = report["machine"]
    lines = [f"cyclecoord {m['cyclecoord']} (git {m['git'] or 'unknown'})  {m['date']}  "
             f"load average {m['load_average_start']} -> {m['load_average_end']}",
             *report["skipped"], "", "rigs:"]
    for r in report["rows"]:
        lines.append(f"  {r['file']}: [{r.get('rig_source', '-')}] {r.get('rig', '-')}; "
                     f"legs {', '.join(r.get('legs', [])) or '-'}")
    lines += ["", _table(FIGURE_HEADERS, figure_rows(report)), "",
              "period/ac/strike: frames; ac%, str%: ours against the rotation autocorrelation /",
              "foot strikes; step/p99: cycle's largest step (seam included) over the capture's",
              "p99 step; near max/med: cycle pose to nearest captured pose over the spread (p90",
              "distance of captured poses to their nearest pose >= half a period away); seam:",
              "last-to-first step over the cycle's median step; jerk/cut, legs/cut: against the",
              "best loop cut (legs: smallest p1-p99 range ratio of hip/knee/ankle flexion). All",
              "in root-frame joint positions from this benchmark's own FK, steady frames only.",
              "cut pct: the share of one-period windows of the steady frames whose range of that",
              "lowest leg angle is below the cut's (a cut at 90 % took one of the widest strides);",
              "legs/med: the smallest range ratio against the median window instead (context:",
              "the targets are against the cut).",
              "", _table(TARGET_HEADERS, target_rows(report)), "",
              "targets: " + "; ".join(f"{k}: {v}" for k, v in TARGETS.items()),
              "CMU only: " + "; ".join(f"{k}: {v}" for k, v in CMU_TARGETS.items())]
    for r in report["rows"]:
        if r.get("status") != "ok":
            lines.append(f"{r['file']}: {r.get('status')}: {r.get('reason')}")
        if "cut_error" in r.get("quality", {}):
            lines.append(f"{r['file']}: no loop cut: {r['quality']['cut_error']}")
        rel = r.get("fk_check_relative")
        if rel is not None and rel > 1e-4:
            lines.append(f"{r['file']}: the library's positions() differ from ours by up to "
                         f"{r['fk_check']:.3g} units ({100 * rel:.2g} % of the height)")
        if r.get("cycle_missing_channels"):
            lines.append(f"{r['file']}: the cycle lacks {r['cycle_missing_channels']} of the "
                         "file's channels (posed at their offsets / no rotation)")
    n_t = sum(v is not None for r in report["rows"] for v in r["targets"].values())
    n_pass = sum(v is True for r in report["rows"] for v in r["targets"].values())
    files_ok = sum(all(v is True for v in r["targets"].values()) for r in report["rows"])
    refused = sum(r.get("status") != "ok" for r in report["rows"])
    lines.append(
        f"summary: {n_pass} of {n_t} measured targets met; {files_ok} of {len(report['rows'])} "
        f"files pass all; {refused} refused or failed; extract "
        f"{sum(r.get('cpu_s', 0) for r in report['rows']):.1f} s CPU / "
        f"{sum(r.get('wall_s', 0) for r in report['rows']):.1f} s wall; whole run "
        f"{report['cpu_seconds']:.1f} s CPU / {report['wall_seconds']:.1f} s wall")
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
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", metavar="OUT", help="also write every figure as JSON")
    ap.add_argument("--data", type=Path, default=DATA_DIR, help=f"shared data (default {DATA_DIR})")
    ap.add_argument("--only", metavar="TEXT", help="only files whose name contains TEXT")
    args = ap.parse_args(argv)
    selected, skipped = cases(args.data)
    if args.only:
        selected = [c for c in selected if args.only in c.name]
    if not selected:
        print("no files to run: " + "; ".join(skipped))
        return 1
    report = run_benchmark(selected, skipped)
    print(format_report(report), flush=True)
    if args.json:
        with atomic_write(args.json, "w") as fh:
            json.dump(_jsonable(report), fh, indent=1)
            fh.write("\n")
        print(f"figures written to {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
