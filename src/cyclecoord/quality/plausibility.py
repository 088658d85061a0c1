"""Plausibility checks for synthesised motion: limbs passing through each other, joint ranges.

The paper warns (§4.5, §7) that blending cycles may produce "impossible motions with
self-intersecting skeleta" and that such frames "could be detected using forward
kinematics".  :func:`self_intersections` does that: every bone is a segment from a joint
to its child (a capsule of zero radius), and frames where two bones that do not touch
in the skeleton come closer than a clearance threshold are flagged.
:func:`joint_range_violations` flags joint angles outside the range the inputs showed.
:func:`check_plausibility` runs both against the input motions and reports only what is
*new*: real captures have near-contacts of their own (hands brushing the hips), which a
blend of them may repeat without being implausible.
"""

from __future__ import annotations

import copy

from dataclasses import dataclass, field, replace
from typing import Any, Sequence

import numpy as np

from ..errors import ImplausibleMotionError, ParameterError
from ..motion import Motion
from .bones import (
    Bones, _element_distances, _near_elements, _pair_distances, bones, segment_distances,
)
from .joint_ranges import (
    JointRangeViolation, _channel_ranges, _in_convention_of, _near_rotations,
    _range_violations, joint_range_violations,
)

__all__ = [
    "Bones",
    "bones",
    "segment_distances",
    "SelfIntersections",
    "self_intersections",
    "JointRangeViolation",
    "joint_range_violations",
    "PlausibilityReport",
    "check_plausibility",
    "ImplausibleMotionError",
    "DEFAULT_CLEARANCE",
]

#: Default clearance between bone centre lines, as a fraction of the skeleton's total
#: bone length (about 10 cm on a CMU skeleton, whose bones add up to about 90 units of
#: 5.6 cm).
DEFAULT_CLEARANCE = 0.02
#: A contact is new when the output goes this fraction of the threshold closer than
#: the inputs' own closest approach.
_NEW_TOLERANCE = 0.1

# ---------------------------------------------------------------- intersections
@dataclass
class SelfIntersections:
    """Bone pairs closer than the clearance, per frame.

    Attributes
    ----------
    threshold : float
        Clearance in skeleton length units.
    bones : Bones
    min_distance : ndarray, shape (Q,)
        Closest approach of each checked pair over the motion.
    flagged : ndarray of bool, shape (T, Q)
        Pair closer than ``threshold`` in that frame (pairs ignored because they are
        within the threshold at rest are never flagged).
    ignored : ndarray of bool, shape (Q,)
        Pairs one bone apart and already closer than the threshold in the rest pose
        (e.g. thumb and fingers), which are not checked.
    distances : ndarray, shape (T, Q)
        Distance of every checked pair in every frame, length units.
    start_frame : int
        The motion's first frame number, for reports.
    """

    threshold: float
    bones: Bones
    min_distance: np.ndarray
    flagged: np.ndarray
    ignored: np.ndarray
    distances: np.ndarray
    start_frame: int = 0

    @property
    def frames(self) -> np.ndarray:
        """0-based indices of frames with at least one flagged pair."""
        return np.flatnonzero(self.flagged.any(axis=1))

    def contacts(self) -> list[dict[str, Any]]:
        """One entry per flagged pair: names, frame count, first frame, closest distance."""
        out = []
        names = self.bones.pair_names()
        for q in np.flatnonzero(self.flagged.any(axis=0)):
            fr = np.flatnonzero(self.flagged[:, q])
            out.append({
                "bones": list(names[q]),
                "frames": int(fr.size),
                "first_frame": int(fr[0] + self.start_frame),
                "min_distance": float(self.min_distance[q]),
            })
        return out


def self_intersections(
    motion: Motion,
    threshold: float | None = None,
    *,
    ignore_rest_contacts: bool = True,
    far: str = "measure",
    bones_: Bones | None = None,
) -> SelfIntersections:
    """Frames where two bones that share no joint come closer than a clearance.

    Each bone is the segment from a joint to its child (from forward kinematics); the
    distance between two bones is the closest distance between their segments,
    computed for all frames and pairs at once.  A skeleton has no flesh, so the
    threshold is a clearance between bone centre lines: below it, limbs of ordinary
    thickness interpenetrate.

    Parameters
    ----------
    motion : Motion
        With a skeleton.
    threshold : float, optional
        Clearance in skeleton length units; default :data:`DEFAULT_CLEARANCE` (2 %) of
        the skeleton's total bone length.
    ignore_rest_contacts : bool, default True
        Do not flag pairs that are one bone apart (a third bone touches both) and
        already closer than the threshold in the rest pose: short bones side by side
        such as fingers and thumb, or the upper neck and the clavicles.  Pairs further
        apart in the skeleton (a hand and a thigh) are always checked, even if they
        touch at rest.
    far : {"measure", "skip"}, default "measure"
        ``"skip"``: a pair is measured only on the frames where its bones come within
        ``threshold`` of each other's bounding sphere (``bones._near_elements``);
        elsewhere its distance reads infinity, and its closest approach is over the
        measured frames (infinity when none).  Every flag, and every distance under the
        threshold, is as measured (:func:`check_plausibility` needs no more; a latent
        script's checks spent half their time on pairs a body apart, and the pairs
        that do come near are measured on about half their frames).
    bones_ : Bones, optional
        :func:`bones` of the motion's skeleton, already made.

    Returns
    -------
    SelfIntersections
    """
    if not isinstance(motion, Motion):
        raise ParameterError(f"expected a Motion, got {type(motion).__name__}")
    bn = bones(motion) if bones_ is None else bones_
    if threshold is None:
        threshold = DEFAULT_CLEARANCE * motion.skeleton.total_length()  # type: ignore[union-attr]
    if not np.isfinite(threshold) or threshold <= 0:
        raise ParameterError(f"threshold must be a positive length, got {threshold!r}")
    if far not in ("measure", "skip"):
        raise ParameterError(f"far must be 'measure' or 'skip', got {far!r}")
    if far == "skip":
        pos = motion.positions().positions
        dist = _element_distances(pos, bn, _near_elements(pos, bn, float(threshold)))
    else:
        dist = _pair_distances(motion, bn)
    if ignore_rest_contacts:
        ignored = (bn.rest_distance < threshold) & bn.second_neighbours
    else:
        ignored = np.zeros(bn.pairs.shape[0], dtype=bool)
    flagged = (dist < threshold) & ~ignored[None, :]
    return SelfIntersections(
        threshold=float(threshold),
        bones=bn,
        min_distance=dist.min(axis=0) if dist.size else np.zeros(0),
        flagged=flagged,
        ignored=ignored,
        distances=dist,
        start_frame=int(motion.start_frame),
    )


# -------------------------------------------------------------------- the report
@dataclass
class PlausibilityReport:
    """Self-intersections and joint ranges of a motion, relative to reference motions.

    Attributes
    ----------
    n_frames : int
    threshold : float
        Clearance between bone centre lines, skeleton length units.
    margin_deg : float
    contacts : list of dict
        Bone pairs closer than the threshold: ``bones``, ``frames``, ``first_frame``,
        ``min_distance``, ``reference_min_distance`` (closest the references came) and
        ``new`` (the motion comes clearly closer than any reference did).
    new_contact_frames : list of int
        Frames with at least one new contact.
    joint_range : list of JointRangeViolation
    notes : list of str
        Plain-language explanation of the findings.
    """

    n_frames: int
    threshold: float
    margin_deg: float
    contacts: list = field(default_factory=list)
    new_contact_frames: list = field(default_factory=list)
    joint_range: list = field(default_factory=list)
    notes: list = field(default_factory=list)

    @property
    def clean(self) -> bool:
        """No new contact and no joint outside its range."""
        return not self.new_contact_frames and not self.joint_range

    def to_dict(self) -> dict[str, Any]:
        return {
            "clean": self.clean,
            "n_frames": self.n_frames,
            "threshold": self.threshold,
            "margin_deg": self.margin_deg,
            "contacts": self.contacts,
            "new_contact_frames": [int(f) for f in self.new_contact_frames],
            "joint_range_violations": [v.to_dict() for v in self.joint_range],
            "notes": list(self.notes),
        }

    def summary(self) -> str:
        """One or a few lines for the terminal."""
        if self.clean:
            head = "plausibility: clean"
        else:
            parts = []
            if self.new_contact_frames:
                parts.append(f"new limb contacts in {len(self.new_contact_frames)} frames")
            if self.joint_range:
                parts.append(f"{len(self.joint_range)} joint angles outside the inputs' range")
            head = "plausibility: " + "; ".join(parts)
        return "\n".join([head] + [f"  {n}" for n in self.notes])


def _reference_views(reference: Motion, motion: Motion) -> list[Motion]:
    """The reference on its own skeleton and, when compatible, played on ``motion``'s.

    A blend is posed on one skeleton; an input from a performer with other proportions
    (narrower hips for the same legs) brings limbs closer on that skeleton than on its
    own.  Playing the reference's channels on the output's skeleton (root translation
    scaled by the ratio of sizes) shows what the input itself does there.
    """
    reference = _in_convention_of(reference, motion)
    views = [reference]
    skel, rskel = motion.skeleton, reference.skeleton
    if skel is None or rskel is None or skel is rskel:
        return views
    same = [j.name for j in skel.joints] == [j.name for j in rskel.joints] and all(
        a.dofs == b.dofs for a, b in zip(skel.joints, rskel.joints)
    )
    if not same:
        return views
    frames = np.array(reference.frames, dtype=float)
    rsize = rskel.total_length()
    if rsize > 0:
        root = skel.joints[0].name
        cols = [
            i
            for i, (j, d) in enumerate(reference.channels)
            if j == root and d in ("tx", "ty", "tz")
        ]
        frames[:, cols] *= skel.total_length() / rsize
    views.append(replace(reference, frames=frames, skeleton=skel))
    return views


def _signature(motion: Motion, joints_only: bool) -> tuple:
    """A content key of a motion for :func:`check_plausibility`'s ``cache``: its frames
    (only the non-root channels with ``joints_only``: the root's motion moves no bone
    against another; on a static-root rig the travelling hips' channels count, which
    only costs hits), frame numbers and skeleton."""
    import hashlib

    frames = np.asarray(motion.frames, dtype=float)
    skel = motion.skeleton
    if joints_only and skel is not None and skel.joints:
        root = skel.joints[0].name
        cols = [i for i, (j, _) in enumerate(motion.channels) if j != root]
        frames = frames[:, cols]
    h = hashlib.blake2b(np.ascontiguousarray(frames).tobytes(), digest_size=16)
    if skel is not None:
        for jt in skel.joints:
            h.update(jt.name.encode())
            h.update(np.asarray(jt.offset, dtype=float).tobytes())
    h.update(repr(list(motion.channels)).encode())
    return (motion.n_frames, int(motion.start_frame), h.hexdigest())


def _cached_bones(motion: Motion, cache: dict | None) -> Bones:
    """:func:`bones` of a motion's skeleton, kept in ``cache`` under its joints and
    offsets (a latent script asked for the same skeleton's some twenty times)."""
    if cache is None:
        return bones(motion)
    skel = motion.skeleton
    key = ("bones", None if skel is None else tuple(
        (j.name, int(j.parent), tuple(np.asarray(j.offset, dtype=float).tolist()))
        for j in skel.joints
    ))
    if key not in cache:
        cache[key] = bones(motion)
    return cache[key]


def _cached_views(
    reference: Motion, rkey, motion: Motion, cache: dict | None
) -> list[tuple[Motion, Any]]:
    """:func:`_reference_views` of ``reference`` with each view's content key (None
    without ``cache``); with ``cache``, made once per reference and skeleton of
    ``motion`` (the skeleton is kept in the cache, so its ``id`` stays its own)."""
    if cache is None:
        return [(view, None) for view in _reference_views(reference, motion)]
    skel = motion.skeleton
    cache.setdefault(("skeleton", id(skel)), skel)
    key = ("views", rkey, id(skel))
    if key not in cache:
        cache[key] = [(view, _signature(view, False)[2])
                      for view in _reference_views(reference, motion)]
    return cache[key]


def _reference_key(reference: Motion, cache: dict) -> tuple:
    """:func:`_signature` of a reference, found once per reference object in ``cache``
    (which keeps the object, so its ``id`` stays its own): references are not changed
    in place between checks."""
    entry = cache.get(("signature", id(reference)))
    if entry is None or entry[0] is not reference:
        entry = (reference, _signature(reference, False))
        cache[("signature", id(reference))] = entry
    return entry[1]


def _reference_minima(
    motion: Motion, references: Sequence[Motion], ref_keys: list, wanted: set,
    cache: dict | None,
) -> dict[tuple[str, str], float]:
    """The references' closest approach of each bone pair in ``wanted`` (by bone names),
    scaled to ``motion``'s size, over each reference's views (:func:`_reference_views`);
    with ``cache``, each pair of each view measured once."""
    size = motion.skeleton.total_length()  # type: ignore[union-attr]
    ref_min: dict[tuple[str, str], float] = {}
    for r, rkey in zip(references, ref_keys) if wanted else ():
        if r.skeleton is None:
            continue
        for v, (view, vsig) in enumerate(_cached_views(r, rkey, motion, cache)):
            rb = _cached_bones(view, cache)
            rnames = rb.pair_names()
            which = np.array([k in wanted for k in rnames], dtype=bool)
            if not which.any():
                continue
            rsize = view.skeleton.total_length()  # type: ignore[union-attr]
            scale = size / rsize if rsize > 0 else 1.0
            names_in = [k for k, w in zip(rnames, which) if w]
            if cache is not None:  # each pair's closest approach in this view, once
                vkey = ("reference pairs", rkey, v, vsig, size)
                known = cache.setdefault(vkey, {})
                todo = np.array([w and k not in known for k, w in zip(rnames, which)])
                if todo.any():
                    rd = _pair_distances(view, rb, todo).min(axis=0) * scale
                    known.update(zip([k for k, t in zip(rnames, todo) if t], map(float, rd)))
                dists = [known[k] for k in names_in]
            else:
                dists = list(_pair_distances(view, rb, which).min(axis=0) * scale)
            for pair, d in zip(names_in, dists):
                ref_min[pair] = min(ref_min.get(pair, np.inf), float(d))
    return ref_min


def _intersections(
    motion: Motion, threshold: float | None, cache: dict | None, keys: tuple | None
) -> SelfIntersections:
    """:func:`self_intersections` with ``far="skip"`` of an analysed motion; with
    ``cache``, kept under the joint signature ``keys[0]`` of the motion as given, and
    measured again only where the motion changes the one under ``keys[1]`` (``base``
    of :func:`check_plausibility`), when that one is kept, else the last one kept."""
    bn = _cached_bones(motion, cache)
    if cache is None or keys is None:
        return self_intersections(motion, threshold, far="skip", bones_=bn)
    prior = None if keys[1] is None else cache.get(("intersections", keys[1], threshold))
    if prior is None:  # (no base: this motion's joint angles checked before, else the
        # last motion checked, when comparable)
        prior = cache.get(("intersections", keys[0], threshold)) or cache.get(
            ("last intersections", threshold))
    inter = None if prior is None else _changed_only(motion, bn, *prior)
    if inter is None:
        inter = self_intersections(motion, threshold, far="skip", bones_=bn)
    cache[("intersections", keys[0], threshold)] = cache[("last intersections", threshold)] = (
        motion, inter)
    return inter


def _changed_only(
    motion: Motion, bn: Bones, before: Motion, old: SelfIntersections
) -> SelfIntersections | None:
    """``old`` (of the analysed motion ``before``) with the pairs a changed joint moves
    measured again on the frames it changes; None when the motions are not comparable
    (other skeleton, channels or length)."""
    if (motion.skeleton is not before.skeleton or list(motion.channels) != list(before.channels)
            or motion.frames.shape != before.frames.shape):
        return None
    root = motion.skeleton.joints[0].name  # type: ignore[union-attr]
    cols = [i for i, (j, _) in enumerate(motion.channels) if j != root]
    diff = motion.frames[:, cols] != before.frames[:, cols]
    rows = diff.any(axis=1)
    changed = {motion.channels[cols[c]][0] for c in np.flatnonzero(diff.any(axis=0))}
    fk = motion.positions()
    moved = np.zeros(len(fk.names), dtype=bool)
    for p, name in enumerate(fk.names):  # parents come before their children
        par = fk.parents[p]
        moved[p] = name in changed or (par >= 0 and moved[par])
    bone = moved[bn.start] | moved[bn.end]
    pairs = bone[bn.pairs[:, 0]] | bone[bn.pairs[:, 1]]
    redo = rows[:, None] & pairs[None, :]
    near = _near_elements(fk.positions, bn, old.threshold, pairs, rows) & redo
    dist = np.where(redo, _element_distances(fk.positions, bn, near), old.distances)
    return SelfIntersections(
        threshold=old.threshold, bones=bn,
        min_distance=dist.min(axis=0) if dist.size else np.zeros(0),
        flagged=(dist < old.threshold) & ~old.ignored[None, :], ignored=old.ignored,
        distances=dist, start_frame=int(motion.start_frame),
    )


def _cached_violations(
    motion: Motion, references: Sequence[Motion], ref_keys: list, margin_deg: float,
    cache: dict | None,
) -> list[JointRangeViolation]:
    """:func:`joint_range_violations`; with ``cache``, the references' ranges are found
    once per set of references and convention of the motion (a latent script's checks
    spent a fifth of their time unwrapping the same training takes)."""
    if cache is None:
        return joint_range_violations(motion, references, margin_deg)
    skel = motion.skeleton
    key = ("ranges", tuple(ref_keys), float(margin_deg), tuple(motion.channels),
           None if skel is None else tuple(
               (j.name, j.rotation_order, np.asarray(j.axis, float).tobytes())
               for j in skel.joints))
    if key not in cache:
        cache[key] = _channel_ranges(motion, references, margin_deg)
    ranges = cache[key]
    return _range_violations(motion, ranges, _near_rotations(
        motion, references, ranges, margin_deg, cache, ("rotations",) + key[1:]))


def check_plausibility(
    motion: Motion,
    references: Sequence[Motion] = (),
    threshold: float | None = None,
    margin_deg: float = 5.0,
    *,
    cache: dict | None = None,
    base: Motion | None = None,
    analysed: bool = False,
) -> PlausibilityReport:
    """Self-intersections and joint ranges of ``motion`` compared with ``references``.

    A bone pair closer than the threshold is *new* when no reference has it that close:
    its distance is below the references' own closest approach of the same pair (by
    bone names) minus 10 % of the threshold.  Each reference is measured on its own
    skeleton (distances scaled to ``motion``'s size) and, when the skeletons have the
    same joints, also played on ``motion``'s skeleton: a performer's pose on another
    performer's proportions can bring limbs closer by itself, which is not the
    blend's doing.  Pairs a reference also brings within the
    threshold are listed but explained, not counted against the motion.  Without
    references every contact is new and joint ranges are not checked.

    Parameters
    ----------
    motion : Motion
        With a skeleton.
    references : sequence of Motion
        The inputs (e.g. the cycles blended); each with a skeleton of the same joint
        names.
    threshold : float, optional
        Clearance (default 2 % of ``motion``'s total bone length); the references are
        checked with the same clearance scaled by their skeleton's size.
    margin_deg : float, default 5
    cache : dict, optional
        Kept by the caller between calls (an empty dict to start): a motion whose joint
        angles and skeleton match an earlier call's, checked against the same
        references, gets that call's report (the root's motion moves no bone against
        another), and the references' closest approach of each bone pair is measured
        once.  A latent script checks its motion up to seven times (limbs kept apart,
        each round of foot pinning, the report).  References are known by their
        content the first time a cache meets them and by identity after that: do not
        change a reference's frames in place between checks sharing a cache.
    base : Motion, optional
        A motion checked before with the same ``cache`` whose frames ``motion`` changes
        in some joints' channels only (foot pinning's trial against the motion it pins):
        the bone pairs those joints move are measured again on the frames they change,
        every other distance is ``base``'s (the same numbers: a point's position depends
        on its ancestors' channels alone).  Without ``cache`` it changes nothing.  With
        ``cache`` and no ``base``, the motion the cache checked last stands for it when
        it has the same skeleton, channels and length (a latent script's pins follow
        pulls of a few frames after its last check).
    analysed : bool, default False
        ``motion`` and ``references`` are already in the analysis rig
        (:func:`~cyclecoord.rig.analysis_motion`), as a latent model's output and
        training takes are: their rig is not looked for again.

    Returns
    -------
    PlausibilityReport
    """
    from ..rig import analysis_motion

    cache_key = None
    ref_keys: list = [None] * len(references)
    if cache is None:
        references = list(references) if analysed else [analysis_motion(r) for r in references]
    else:  # each reference's analysis rig once, under its own content
        ref_keys = [_reference_key(r, cache) for r in references]
        cache_key = (_signature(motion, True), tuple(ref_keys), threshold, float(margin_deg))
        if cache_key in cache:
            return copy.deepcopy(cache[cache_key])
        refs = list(references)
        for i, (r, k) in enumerate(zip(references, ref_keys)):
            if not analysed:
                if ("analysis", k) not in cache:
                    cache[("analysis", k)] = analysis_motion(r)
                refs[i] = cache[("analysis", k)]
        references = refs
    # in the analysis rig: a static root at the origin is no bone to the travelling hips
    motion = motion if analysed else analysis_motion(motion)
    inter = _intersections(motion, threshold, cache, None if cache_key is None else (
        cache_key[0], None if base is None else _signature(base, True)))
    thr = inter.threshold
    names = inter.bones.pair_names()
    # the references' closest approach matters for the pairs the motion brings close only
    wanted = {names[q] for q in np.flatnonzero(inter.flagged.any(axis=0))}
    wanted |= {(k[1], k[0]) for k in wanted}
    ref_min = _reference_minima(motion, references, ref_keys, wanted, cache)
    contacts = []
    new_mask = np.zeros(inter.flagged.shape[0], dtype=bool)
    notes: list[str] = []
    explained = 0
    for q in np.flatnonzero(inter.flagged.any(axis=0)):
        key = names[q]
        rmin = ref_min.get(key, ref_min.get((key[1], key[0]), np.inf))
        frames = np.flatnonzero(inter.flagged[:, q])
        if references:
            limit = min(thr, rmin) - _NEW_TOLERANCE * thr
            new_frames = np.flatnonzero(inter.distances[:, q] < limit)
        else:
            new_frames = frames
        is_new = bool(new_frames.size)
        if is_new:
            new_mask[new_frames] = True
        else:
            explained += 1
        contacts.append({
            "bones": list(key),
            "frames": int(frames.size),
            "first_frame": int(frames[0] + motion.start_frame),
            "min_distance": float(inter.min_distance[q]),
            "reference_min_distance": None if not np.isfinite(rmin) else float(rmin),
            "new": bool(is_new),
        })
    if inter.ignored.any():
        notes.append(
            f"{int(inter.ignored.sum())} pairs of neighbouring bones are within the clearance "
            f"{thr:.3g} already at rest (e.g. fingers and thumb) and are not checked"
        )
    if explained:
        notes.append(
            f"{explained} bone pairs come within the clearance {thr:.3g}, but "
            "the inputs come as close (their own near-contacts, not new)"
        )
    n_new = sum(1 for c in contacts if c["new"])
    if n_new:
        worst = min((c for c in contacts if c["new"]), key=lambda c: c["min_distance"])
        ref = worst["reference_min_distance"]
        notes.append(
            f"{n_new} bone pairs come closer than the inputs ever do, e.g. "
            f"{worst['bones'][0]} and {worst['bones'][1]} at {worst['min_distance']:.3g} "
            f"(clearance {thr:.3g}, inputs' closest {'n/a' if ref is None else f'{ref:.3g}'})"
        )
    violations: list[JointRangeViolation] = []
    if references:
        violations = _cached_violations(motion, references, ref_keys, margin_deg, cache)
        if violations:
            v = violations[0]
            notes.append(
                f"{len(violations)} joint angles leave the inputs' range "
                f"(+-{margin_deg:g} deg), worst {'.'.join(v.channel)} at "
                f"{v.worst:.1f} (allowed {v.low:.1f} to {v.high:.1f})"
            )
    if not contacts and not violations:
        notes.append(
            f"no bones closer than {thr:.3g} and every joint angle within the inputs' range"
        )
    report = PlausibilityReport(
        n_frames=motion.n_frames, threshold=thr, margin_deg=float(margin_deg), contacts=contacts,
        new_contact_frames=[int(f + motion.start_frame) for f in np.flatnonzero(new_mask)],
        joint_range=violations, notes=notes,
    )
    if cache is not None:
        cache[cache_key] = copy.deepcopy(report)
    return report
