"""Which joints are a skeleton's legs and feet, on any rig: by name, else by geometry.

:func:`find_legs` reads the joint names first (:mod:`cyclecoord.joint_names`: CMU, Mixamo,
LAFAN1, Bandai, Xsens, SMPL, Rokoko, Unreal ... and quadruped names such as
``LeftFrontLeg``/``RightHindFoot``).  Each leg gives its foot points, the ankle then the
toe joint (either may be missing), so a biped's feet read ``("lfoot", "ltoes", "rfoot",
"rtoes")``.  When the names say nothing (joints named ``j0`` ... ``j20``), the legs are
found from the skeleton's geometry, in the motion (forward kinematics) or else in the
rest pose:

* the *ends* are the joints without children (end, tip and prop joints named so are left
  out, and the joint they hang from is an end instead);
* an end *reaches the ground* when it is low most of the time: its median height within
  0.3 and its 5 % low within 0.1 of the body's height above the floor (hands, a hand-held
  prop and the head do not);
* two legs are two such ends whose chains part high in the body (the pelvis, not an ankle
  or a wrist) and are about as long from there (within 30 %); the pair lowest and most
  alike is taken, and a second such pair makes a quadruped (legs paired by where their
  chains part: the hips, the shoulders);
* on each leg the ankle is the first joint up from the end whose own bone is long (over a
  quarter of the leg, the shin) and the toe the joint below it, so an end with a long
  bone is an ankle without toes;
* left and right come from the body's left axis, ``up x forward``, with forward the
  direction the feet point (ankle to toe) frame by frame, so turns do not confuse it;
  front and hind legs from their position along it.

A quadruped named like a human (front legs called arms, as in some dog rigs) is a biped
by name whose two other chains reach the ground in the motion: it gets four legs.

Foot points chosen by hand (:func:`legs_of_feet`, the CLI's ``--feet LEFT,RIGHT``) are
grouped into legs by the hierarchy and given sides by name, else by the same geometry.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from itertools import combinations

import numpy as np

from ..errors import ParameterError
from ..joint_names import JointRole, classify_skeleton, is_ignored_name
from ..motion import Motion
from ..skeleton import Skeleton, forward_kinematics

__all__ = [
    "Leg",
    "Legs",
    "find_legs",
    "find_feet",
    "legs_of_feet",
    "resolve_feet",
    "feet_names",
    "check_feet",
    "nearest_joints",
]

#: At most this many frames of a motion are used to judge its geometry.
_GEOMETRY_FRAMES = 400
#: An end reaches the ground: median height within this fraction of the body height ...
_GROUND_MEDIAN = 0.3
#: ... and its 5 % low within this fraction.
_GROUND_LOW = 0.1
#: Two legs part above this fraction of the body height (the pelvis, the shoulders).
_PART_HEIGHT = 0.3
#: Two legs are alike when their lengths from where they part differ by at most this.
_LENGTH_SPREAD = 0.3
#: The ankle is the first joint up from the end whose bone exceeds this part of the leg.
_SHIN_FRACTION = 0.25
#: In a motion, further legs of a rig named as a biped must stay this low (median).
_EXTRA_MEDIAN = 0.15
_UP = {"x": 0, "y": 1, "z": 2}


# --------------------------------------------------------------------- results
@dataclass(frozen=True)
class Leg:
    """One leg and its foot points.

    Attributes
    ----------
    label : str
        ``"left"``, ``"right"``, ``"front left"``, ``"hind right"`` ..., or ``"leg 2"``
        when neither names nor geometry tell.
    side : str
        ``"left"``, ``"right"`` or ``"?"``.
    limb : str or None
        ``"front"`` or ``"hind"`` on a quadruped.
    points : tuple of str
        Foot point joint names: the ankle, then the toe (one of them may be missing).
    """

    label: str
    side: str
    limb: str | None
    points: tuple[str, ...]


@dataclass(frozen=True)
class Legs:
    """The legs of a skeleton and how they were found.

    Attributes
    ----------
    legs : tuple of Leg
        Left before right; front legs before hind ones.
    method : str
        ``"names"``, ``"geometry"``, ``"names and geometry"`` (a rig named as a biped
        with two more legs on the ground) or ``"given"``.
    """

    legs: tuple[Leg, ...]
    method: str

    @property
    def feet(self) -> tuple[str, ...]:
        """Foot point names, leg by leg (ankle then toe), e.g. ``("lfoot", "ltoes", ...)``."""
        return tuple(p for leg in self.legs for p in leg.points)

    @property
    def sides(self) -> tuple[str, ...]:
        """``"left"``/``"right"``/``"?"`` per foot point."""
        return tuple(leg.side for leg in self.legs for _ in leg.points)

    @property
    def labels(self) -> tuple[str, ...]:
        """The leg label per foot point."""
        return tuple(leg.label for leg in self.legs for _ in leg.points)

    def describe(self) -> str:
        """One line, e.g. ``"feet by names: left Foot_L+Toes_L, right Foot_R+Toes_R"``."""
        parts = ", ".join(f"{leg.label} {'+'.join(leg.points)}" for leg in self.legs)
        return f"feet by {self.method}: {parts}"


# --------------------------------------------------------------------- names
def nearest_joints(skeleton: Skeleton, name: str, n: int = 5) -> list[str]:
    """The joint names most like ``name`` (difflib), case-insensitively."""
    lower = {j.name.lower(): j.name for j in skeleton.joints}
    close = difflib.get_close_matches(name.lower(), list(lower), n=n, cutoff=0.3)
    return [lower[c] for c in close]


def _unknown_joint(skeleton: Skeleton, name: str) -> ParameterError:
    near = nearest_joints(skeleton, name)
    hint = f"; nearest: {', '.join(near)}" if near else ""
    return ParameterError(
        f"no joint {name!r} in skeleton {skeleton.name or '(unnamed)'} "
        f"({len(skeleton.joints)} joints){hint}"
    )


def check_feet(skeleton: Skeleton, feet) -> tuple[str, ...]:
    """``feet`` as a tuple of joint names of ``skeleton``.

    Raises
    ------
    ParameterError
        For an empty list or a name that is not a joint (the message lists the nearest
        joint names).
    """
    feet = tuple(str(f) for f in feet)
    if not feet:
        raise ParameterError("feet must name at least one joint")
    names = set(skeleton.names)
    for f in feet:
        if f not in names:
            raise _unknown_joint(skeleton, f)
    if len(set(feet)) != len(feet):
        raise ParameterError(f"feet name a joint twice: {', '.join(feet)}")
    return feet


def resolve_feet(skeleton: Skeleton, spec: str | tuple[str, ...] | list[str]) -> tuple[str, ...]:
    """Foot points from the command line's ``--feet`` text, checked against a skeleton.

    Parameters
    ----------
    skeleton : Skeleton
    spec : str or sequence of str
        ``"LEFT,RIGHT"`` (two legs) or four names for a quadruped, each a joint name or
        ``ANKLE:TOE`` (both points of the leg, toe below ankle).  A joint whose own name
        holds a colon (``mixamorig:LeftFoot``) is read whole; ``mixamorig:LeftFoot:``
        ``mixamorig:LeftToeBase`` is split where both halves are joints.

    Returns
    -------
    tuple of str
        Foot point names, leg by leg (ankle then toe), as :func:`find_legs` gives them.

    Raises
    ------
    ParameterError
        A name that is not a joint (with the nearest names), a toe not below its ankle,
        or neither 2 nor 4 legs.
    """
    items = [s.strip() for s in spec.split(",")] if isinstance(spec, str) else list(spec)
    if any(not s for s in items):
        raise ParameterError(
            f"--feet {spec!r}: an empty name; give joint names such as LEFT,RIGHT"
        )
    names = set(skeleton.names)
    out: list[str] = []
    for item in items:
        if item in names or ":" not in item:
            out.append(item)
            continue
        cuts = [i for i, ch in enumerate(item) if ch == ":"]
        pairs = [(item[:i], item[i + 1 :]) for i in cuts]
        good = [(a, t) for a, t in pairs if a in names and t in names]
        if not good:
            half = [t if a in names else a for a, t in pairs if (a in names) != (t in names)]
            raise _unknown_joint(skeleton, half[0] if half else item)
        ankle, toe = good[0]
        if ankle not in _ancestors(skeleton, skeleton.index(toe)):
            raise ParameterError(f"--feet {item}: {toe} is not below {ankle} (ANKLE:TOE)")
        out += [ankle, toe]
    feet = check_feet(skeleton, out)
    legs = _group(skeleton, feet)
    if len(legs) not in (2, 4):
        raise ParameterError(
            f"--feet {','.join(items)}: {len(legs)} legs; give two (LEFT,RIGHT) or four "
            "(a quadruped), each a joint or ANKLE:TOE"
        )
    return feet


def feet_names(skeleton: Skeleton, feet) -> tuple[str, ...]:
    """Foot point names from joint names or the command line's ``"LEFT,RIGHT"`` text.

    A string goes through :func:`resolve_feet`, a sequence through :func:`check_feet`.
    """
    if isinstance(feet, str):
        return resolve_feet(skeleton, feet)
    return check_feet(skeleton, feet)


def _ancestors(skeleton: Skeleton, index: int) -> list[str]:
    out = []
    p = skeleton.joints[index].parent
    while p >= 0:
        out.append(skeleton.joints[p].name)
        p = skeleton.joints[p].parent
    return out


def _group(skeleton: Skeleton, feet: tuple[str, ...]) -> list[list[str]]:
    """Foot points grouped into legs: points on one chain (one above the other) together,
    legs in order of their first point."""
    legs: list[list[str]] = []
    for f in feet:
        chain = set(_ancestors(skeleton, skeleton.index(f)))
        for leg in legs:
            if any(g in chain or f in _ancestors(skeleton, skeleton.index(g)) for g in leg):
                leg.append(f)
                break
        else:
            legs.append([f])
    depth = {f: len(_ancestors(skeleton, skeleton.index(f))) for f in feet}
    return [sorted(leg, key=lambda f: depth[f]) for leg in legs]


def _named_legs(skeleton: Skeleton, roles: dict[str, JointRole]) -> list[Leg]:
    """Legs whose joints are named: per (limb, side), the first ankle on a leg chain and
    the first toe below it (or the first toe alone)."""
    legs = []
    keys = []
    for r in roles.values():
        if r.role in ("ankle", "toe") and r.side and (r.limb, r.side) not in keys:
            keys.append((r.limb, r.side))
    for limb, side in keys:
        ankles = [n for n, r in roles.items() if (r.role, r.side, r.limb) == ("ankle", side, limb)]
        toes = [n for n, r in roles.items() if (r.role, r.side, r.limb) == ("toe", side, limb)]
        ankle = ankles[0] if ankles else None
        toe = None
        if ankle is not None:
            below = [t for t in toes if ankle in _ancestors(skeleton, skeleton.index(t))]
            toe = below[0] if below else None
        elif toes:
            toe = toes[0]
        points = tuple(p for p in (ankle, toe) if p is not None)
        legs.append(Leg(_label(side, limb), side, limb, points))
    return legs


def _label(side: str, limb: str | None) -> str:
    return f"{limb} {side}" if limb else side


def _ordered(legs: list[Leg]) -> tuple[Leg, ...]:
    rank = {"front": 0, None: 1, "hind": 2}
    side = {"left": 0, "right": 1}
    return tuple(sorted(legs, key=lambda g: (rank.get(g.limb, 1), side.get(g.side, 2))))


# --------------------------------------------------------------------- geometry
class _Geometry:
    """Heights and directions of a skeleton's joints, in a motion or its rest pose."""

    def __init__(self, skeleton: Skeleton, motion: Motion | None, up: str) -> None:
        self.skeleton = skeleton
        self.up = _UP[up]
        n = len(skeleton.joints)
        if motion is not None and motion.n_frames > 0 and np.isfinite(motion.frames).all():
            step = max(1, int(np.ceil(motion.n_frames / _GEOMETRY_FRAMES)))
            sub = motion[::step]  # (its positions, when kept, are the motion's rows)
            fk = sub.positions() if skeleton is sub.skeleton else forward_kinematics(sub, skeleton)
            pos = fk.positions
            self.in_motion = True
        else:
            rest = np.zeros((n, 3))
            ends = []
            for i, j in enumerate(skeleton.joints):
                rest[i] = j.offset + (rest[j.parent] if j.parent >= 0 else 0.0)
                if j.end_site is not None:
                    ends.append(rest[i] + j.end_site)
            pos = np.concatenate([rest, np.asarray(ends).reshape(-1, 3)])[None]
            self.in_motion = False
        self.pos = pos[:, :n]
        # each joint's lowest point: itself or its end site
        low = pos[:, :n, self.up].copy()
        k = n
        for i, j in enumerate(skeleton.joints):
            if j.end_site is not None:
                low[:, i] = np.minimum(low[:, i], pos[:, k, self.up])
                k += 1
        self.children = [skeleton.children(i) for i in range(n)]
        self.ends = self._ends()
        ground = low[:, self.ends] if self.ends else low
        self.floor = float(np.quantile(ground.min(axis=1), 0.05))
        self.median = np.median(low, axis=0) - self.floor
        self.low = np.quantile(low, 0.05, axis=0) - self.floor
        self.height = float(np.median(self.pos[:, :, self.up], axis=0).max() - self.floor)
        self.bone = np.array([np.linalg.norm(j.offset) for j in skeleton.joints])

    def _ends(self) -> list[int]:
        """Joints without children (children named as end, tip or prop joints not
        counted), themselves not so named."""
        names = self.skeleton.names
        ignored = [is_ignored_name(nm) for nm in names]
        return [
            i
            for i in range(len(names))
            if not ignored[i] and i > 0 and all(ignored[c] for c in self.children[i])
        ]

    def chain(self, i: int) -> list[int]:
        """Joint indices from the root down to ``i``."""
        out = [i]
        while self.skeleton.joints[out[-1]].parent >= 0:
            out.append(self.skeleton.joints[out[-1]].parent)
        return out[::-1]

    def part(self, a: int, b: int) -> int:
        """The joint where the chains of ``a`` and ``b`` part (their lowest common one)."""
        ca, cb = self.chain(a), self.chain(b)
        k = 0
        while k < min(len(ca), len(cb)) and ca[k] == cb[k]:
            k += 1
        return ca[k - 1]

    def length(self, top: int, end: int) -> float:
        """Bone length from joint ``top`` down to ``end``."""
        c = self.chain(end)
        return float(self.bone[c[c.index(top) + 1 :]].sum())

    @property
    def usable(self) -> bool:
        return self.height > 0 and np.isfinite(self.height)

    def grounded(self, median: float = _GROUND_MEDIAN) -> list[int]:
        """Ends that reach the ground, lowest first, one per foot (of two ends parting low,
        the lower).  An end reaches it when its median height is at most ``median`` and its
        5 % low at most :data:`_GROUND_LOW` of the body height (both bounds included)."""
        H = self.height
        cand = [
            e for e in self.ends
            if self.median[e] <= median * H and self.low[e] <= _GROUND_LOW * H
        ]
        cand.sort(key=lambda e: (self.median[e], self.low[e]))
        kept: list[int] = []
        for e in cand:
            if all(self.median[self.part(e, k)] > _PART_HEIGHT * H for k in kept):
                kept.append(e)
        return kept

    def pair_score(self, a: int, b: int) -> float | None:
        """How well ends ``a`` and ``b`` make a pair of legs (lower is better), None if not."""
        p = self.part(a, b)
        if self.median[p] <= _PART_HEIGHT * self.height:
            return None
        la, lb = self.length(p, a), self.length(p, b)
        if max(la, lb) <= 0 or abs(la - lb) > _LENGTH_SPREAD * max(la, lb):
            return None
        return (self.median[a] + self.median[b]) / self.height + abs(la - lb) / max(la, lb)

    def foot_points(self, top: int, end: int) -> tuple[int, ...]:
        """(ankle, toe) of the leg from ``top`` (where it parts) down to ``end``."""
        leg = self.length(top, end)
        c = self.chain(end)
        j = end
        while self.skeleton.joints[j].parent != top and self.bone[j] < _SHIN_FRACTION * leg:
            j = self.skeleton.joints[j].parent
        if j == end:
            return (end,)
        return (j, c[c.index(j) + 1])

    def forward(self, legs: list[tuple[int, ...]]) -> np.ndarray:
        """Horizontal forward direction per frame ``(T, 3)``: where the feet point (ankle
        to toe), else the root's travel, else +z.  Each row is a unit vector, however
        short the feet's horizontal extent on that frame, or zero where it is none.  A
        median extent, or a travel, of at most 1e-9 units is none."""
        horiz = [k for k in range(3) if k != self.up]
        T = self.pos.shape[0]
        fwd = np.zeros((T, 3))
        for pts in legs:
            if len(pts) == 2:
                fwd += self.pos[:, pts[1]] - self.pos[:, pts[0]]
        fwd[:, self.up] = 0.0
        norm = np.linalg.norm(fwd, axis=1)
        if np.median(norm) <= 1e-9 and T > 1:
            travel = self.pos[-1, 0] - self.pos[0, 0]
            travel[self.up] = 0.0
            fwd = np.broadcast_to(travel, (T, 3)).copy()
            norm = np.linalg.norm(fwd, axis=1)
        if np.median(norm) <= 1e-9:
            fwd = np.zeros((T, 3))
            fwd[:, horiz[-1] if self.up != 2 else 1] = 1.0
            norm = np.ones(T)
        return fwd / np.maximum(norm, 1e-12)[:, None]

    def mean_position(self, top: int, end: int) -> np.ndarray:
        """Mean position ``(T, 3)`` of a leg's joints below ``top``."""
        c = self.chain(end)
        return self.pos[:, c[c.index(top) + 1 :]].mean(axis=1)

    def left_of(self, a: np.ndarray, b: np.ndarray, fwd: np.ndarray) -> bool:
        """Whether positions ``a`` lie left of ``b`` on most frames (left = up x forward)."""
        up = np.zeros(3)
        up[self.up] = 1.0
        left = np.cross(up, fwd)
        return bool(np.median(np.einsum("tk,tk->t", a - b, left)) > 0)

    def ahead_of(self, a: np.ndarray, b: np.ndarray, fwd: np.ndarray) -> bool:
        return bool(np.median(np.einsum("tk,tk->t", a - b, fwd)) > 0)

    def upright(self, legs: list[tuple[int, int]]) -> bool:
        """Whether the legs ``(top, end)`` hang down from where they part (a rest pose
        with legs along the floor, as Bandai's, says nothing)."""
        return all(
            self.median[top] - self.median[end] > 0.5 * self.length(top, end) > 0
            for top, end in legs
        )

    def candidates(self, n: int = 6) -> list[str]:
        """The lowest ends, for messages: ``"name (height)"``."""
        order = sorted(self.ends, key=lambda e: self.median[e])[:n]
        names = self.skeleton.names
        return [f"{names[e]} ({self.median[e]:.3g})" for e in order]


def _label_pair(
    geo: _Geometry, pair: list[tuple[int, int]], fwd: np.ndarray
) -> list[str]:
    """``["left", "right"]`` or the reverse for two legs ``(top, end)``."""
    (ta, ea), (tb, eb) = pair
    a_left = geo.left_of(geo.mean_position(ta, ea), geo.mean_position(tb, eb), fwd)
    return ["left", "right"] if a_left else ["right", "left"]


def _geometric_legs(geo: _Geometry) -> list[Leg] | None:
    """Two or four legs from the geometry alone, or None."""
    if not geo.usable:
        return None
    ground = geo.grounded()[:6]
    names = geo.skeleton.names
    best4 = None
    for four in combinations(ground, 4):
        for p, q in _pairings(four):
            sp, sq = geo.pair_score(*p), geo.pair_score(*q)
            if sp is None or sq is None:
                continue
            depth = len(geo.chain(geo.part(*p))) + len(geo.chain(geo.part(*q)))
            key = (-depth, sp + sq)
            if best4 is None or key < best4[0]:
                best4 = (key, p, q)
    pairs: list[tuple[int, int]]
    if best4 is not None:
        pairs = [best4[1], best4[2]]
    else:
        scored = [(geo.pair_score(a, b), (a, b)) for a, b in combinations(ground, 2)]
        scored = [s for s in scored if s[0] is not None]
        if not scored:
            return None
        pairs = [min(scored)[1]]
    tops = [(geo.part(*p), p) for p in pairs]
    legs_idx = [(top, e) for top, p in tops for e in p]
    if not geo.in_motion and not geo.upright(legs_idx):
        return None
    points = [geo.foot_points(top, e) for top, e in legs_idx]
    fwd = geo.forward(points)
    out: list[Leg] = []
    limbs: list[str | None] = [None, None]
    if len(pairs) == 2:
        a = geo.mean_position(*legs_idx[0]) + geo.mean_position(*legs_idx[1])
        b = geo.mean_position(*legs_idx[2]) + geo.mean_position(*legs_idx[3])
        limbs = ["front", "hind"] if geo.ahead_of(a, b, fwd) else ["hind", "front"]
    for k in range(len(pairs)):
        two = legs_idx[2 * k : 2 * k + 2]
        sides = _label_pair(geo, two, fwd)
        for (top, e), side in zip(two, sides):
            pts = tuple(names[i] for i in geo.foot_points(top, e))
            out.append(Leg(_label(side, limbs[k]), side, limbs[k], pts))
    return out


def _pairings(four):
    a, b, c, d = four
    return [((a, b), (c, d)), ((a, c), (b, d)), ((a, d), (b, c))]


def _extra_legs(geo: _Geometry, named: list[Leg]) -> list[Leg] | None:
    """Two more legs reaching the ground beside a biped's named ones (a quadruped named
    like a human: front legs called arms), or None.  They must reach it in the motion and
    in the rest pose, so a person crawling or doing push-ups keeps two legs (a human rig's
    rest pose holds the arms up, a dog rig's stands on four)."""
    if not (geo.usable and geo.in_motion):
        return None
    sk = geo.skeleton
    rest = _Geometry(sk, None, "xyz"[geo.up])
    taken = [sk.index(p) for leg in named for p in leg.points]
    if not rest.usable or not rest.upright(
        [(rest.part(taken[0], taken[-1]), t) for t in (taken[0], taken[-1])]
    ):
        return None
    on_floor = set(rest.grounded(_EXTRA_MEDIAN))
    free = [
        e for e in geo.grounded(_EXTRA_MEDIAN)
        if e in on_floor
        and all(geo.median[geo.part(e, t)] > _PART_HEIGHT * geo.height for t in taken)
    ]
    scored = [(geo.pair_score(a, b), (a, b)) for a, b in combinations(free[:4], 2)]
    scored = [s for s in scored if s[0] is not None]
    if not scored:
        return None
    a, b = min(scored)[1]
    top = geo.part(a, b)
    pts = [geo.foot_points(top, a), geo.foot_points(top, b)]
    fwd = geo.forward(pts + [tuple(sk.index(p) for p in leg.points) for leg in named])
    sides = _label_pair(geo, [(top, a), (top, b)], fwd)
    named_pos = np.mean([geo.pos[:, sk.index(leg.points[0])] for leg in named], axis=0)
    new_pos = 0.5 * (geo.pos[:, pts[0][0]] + geo.pos[:, pts[1][0]])
    new_limb, old_limb = ("front", "hind") if geo.ahead_of(new_pos, named_pos, fwd) else (
        "hind", "front")
    out = [Leg(_label(leg.side, old_limb), leg.side, old_limb, leg.points) for leg in named]
    for p, side in zip(pts, sides):
        out.append(Leg(_label(side, new_limb), side, new_limb, tuple(sk.names[i] for i in p)))
    return out


def _no_feet(skeleton: Skeleton, geo: _Geometry) -> ParameterError:
    found = geo.candidates()
    lowest = [c.split(" (")[0] for c in found[:2]]
    example = ",".join(lowest) if len(lowest) == 2 else "LEFT,RIGHT"
    return ParameterError(
        f"skeleton {skeleton.name or '(unnamed)'}: no foot joints found: no joint is named as a "
        "foot "
        "(lfoot/ltoes, LeftFoot/LeftToeBase, Foot_L/Toes_L ...) and no two leg chains reach "
        f"the ground; pass --feet LEFT,RIGHT on the command line (feet=(...) in Python), "
        f"e.g. --feet {example}; lowest end joints (height above the floor): "
        + (", ".join(found) if found else "none")
    )


def find_legs(skeleton: Skeleton, motion: Motion | None = None, *, up: str = "y") -> Legs:
    """The legs of a skeleton and their foot points, by name, else by geometry.

    Parameters
    ----------
    skeleton : Skeleton
    motion : Motion, optional
        A motion of the skeleton: its poses (forward kinematics on up to 400 frames) judge
        the geometry, and the rest pose where they find no legs (a take spent climbing);
        without a motion the rest pose alone.
    up : {"x", "y", "z"}
        Up axis of the skeleton's world frame.

    Returns
    -------
    Legs
        Two legs (left, right) or four (front left, front right, hind left, hind right).

    Raises
    ------
    ParameterError
        When neither the names nor the geometry give two legs; the message lists the
        lowest end joints and says to pass ``--feet LEFT,RIGHT``.
    """
    if up not in _UP:
        raise ParameterError(f"up axis must be one of x, y, z, got {up!r}")
    if motion is None:
        return _find_legs(skeleton, None, up)
    # once per motion and skeleton (kept with the legs, so its id stays its own)
    return motion.derived(("legs", id(skeleton), up),
                          lambda: (skeleton, _find_legs(skeleton, motion, up)))[1]


def _find_legs(skeleton: Skeleton, motion: Motion | None, up: str) -> Legs:
    named = _named_legs(skeleton, classify_skeleton(skeleton))
    quad = {(g.limb, g.side): g for g in named if g.limb}
    if len(quad) == 4:
        return Legs(_ordered(list(quad.values())), "names")
    biped = {g.side: g for g in named if not g.limb}
    geo = _Geometry(skeleton, motion, up)
    if set(biped) == {"left", "right"}:
        two = [biped["left"], biped["right"]]
        more = _extra_legs(geo, two)
        if more is not None:
            return Legs(_ordered(more), "names and geometry")
        return Legs(tuple(two), "names")
    legs = _geometric_legs(geo)
    if legs is None and geo.in_motion:
        legs = _geometric_legs(_Geometry(skeleton, None, up))  # e.g. a climbing take
    if legs is None:
        raise _no_feet(skeleton, geo)
    return Legs(_ordered(legs), "geometry")


def find_feet(
    skeleton: Skeleton, motion: Motion | None = None, *, up: str = "y"
) -> tuple[str, ...]:
    """Foot point joint names of a skeleton: ankle then toe of each leg, left leg first.

    ``("lfoot", "ltoes", "rfoot", "rtoes")`` on a CMU skeleton, ``("Foot_L", "Toes_L",
    "Foot_R", "Toes_R")`` on Bandai's; four legs (front left, front right, hind left,
    hind right) on a quadruped.  See :func:`find_legs`.
    """
    return find_legs(skeleton, motion, up=up).feet


def legs_of_feet(
    skeleton: Skeleton,
    feet,
    motion: Motion | None = None,
    *,
    up: str = "y",
) -> Legs:
    """Given foot points grouped into legs, with sides from their names, else geometry.

    Parameters
    ----------
    skeleton : Skeleton
    feet : sequence of str, or str
        Foot point joint names (e.g. ``("j4", "j5", "j9", "j10")``), or the command
        line's text (``"j4:j5,j9:j10"``, :func:`resolve_feet`); points on one chain make
        one leg.
    motion : Motion, optional
        Poses for the geometry (else the rest pose).
    up : {"x", "y", "z"}

    Returns
    -------
    Legs
        Legs in the order given, with method ``"given"``.
    """
    feet = feet_names(skeleton, feet)
    groups = _group(skeleton, feet)
    roles = classify_skeleton(skeleton)

    def named(points: list[str]) -> JointRole | None:
        for p in points:
            chain = [p] + _ancestors(skeleton, skeleton.index(p))
            for n in chain:
                r = roles.get(n)
                if r is not None and r.side:
                    return r
        return None

    found = [named(g) for g in groups]
    sides = [r.side if r else None for r in found]
    limbs = [r.limb if r else None for r in found]
    if (None in sides or len(set(zip(sides, limbs))) < len(groups)) and len(groups) in (2, 4):
        geo = _Geometry(skeleton, motion, up)
        guess = _given_geometry(geo, groups) if geo.usable else None
        if guess is not None:
            sides, limbs = guess
    legs = []
    seen: set[str] = set()
    for k, (g, side, limb) in enumerate(zip(groups, sides, limbs)):
        label = _label(side, limb) if side else f"leg {k + 1}"
        if label in seen:
            label = f"{label} {k + 1}"
        seen.add(label)
        legs.append(Leg(label, side or "?", limb, tuple(g)))
    return Legs(tuple(legs), "given")


def _given_geometry(
    geo: _Geometry, groups: list[list[str]]
) -> tuple[list[str], list[str | None]] | None:
    """Sides (and front/hind for four) of given legs from the geometry."""
    sk = geo.skeleton
    idx = [[sk.index(p) for p in g] for g in groups]
    ends = [g[-1] for g in idx]
    pts = [tuple(g) for g in idx]
    fwd = geo.forward(pts)
    if len(groups) == 2:
        top = geo.part(ends[0], ends[1])
        if top in ends:
            return None
        sides = _label_pair(geo, [(top, ends[0]), (top, ends[1])], fwd)
        return sides, [None, None]
    def depth(pq) -> int:  # legs pair up where their chains part lowest in the tree
        return sum(len(geo.chain(geo.part(ends[a], ends[b]))) for a, b in pq)

    pairing = max(_pairings(range(4)), key=depth)
    sides: list[str] = ["?"] * 4
    limbs: list[str | None] = [None] * 4
    centre = []
    for pair in pairing:
        top = geo.part(ends[pair[0]], ends[pair[1]])
        if top in (ends[pair[0]], ends[pair[1]]):
            return None
        two = _label_pair(geo, [(top, ends[pair[0]]), (top, ends[pair[1]])], fwd)
        for k, s in zip(pair, two):
            sides[k] = s
        centre.append(geo.pos[:, [ends[k] for k in pair]].mean(axis=1))
    order = ("front", "hind") if geo.ahead_of(centre[0], centre[1], fwd) else ("hind", "front")
    for pair, limb in zip(pairing, order):
        for k in pair:
            limbs[k] = limb
    return sides, limbs
