"""Bones and the distances between them: a skeleton's segments, the pairs that share no
joint, and their closest distances per frame (what :mod:`.plausibility` checks limbs with).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..motion import Motion

__all__ = ["Bones", "bones", "segment_distances", "segment_parameters"]

#: Frames x bone pairs per chunk in the distance computation.
_CHUNK = 400_000


@dataclass(frozen=True)
class Bones:
    """The bones of a skeleton as segments between forward-kinematics points.

    Attributes
    ----------
    names : list of str
        One per bone: the joint whose bone it is (ASF naming: bone ``lfemur`` runs from
        the hip to the knee), ``"parent>child"`` where a joint has several bones.
    start, end : ndarray of int, shape (B,)
        Point indices (into :attr:`JointPositions.positions`) of each bone's ends.
    pairs : ndarray of int, shape (Q, 2)
        Bone pairs that are checked: bones sharing no joint (after merging joints that
        coincide at rest), i.e. neither parent and child nor siblings at one joint.
    rest_distance : ndarray, shape (Q,)
        Distance of each pair in the rest pose (all channels 0).
    second_neighbours : ndarray of bool, shape (Q,)
        Pairs joined through one other bone (a bone touching both).
    """

    names: list
    start: np.ndarray
    end: np.ndarray
    pairs: np.ndarray
    rest_distance: np.ndarray
    second_neighbours: np.ndarray

    def pair_names(self) -> list[tuple[str, str]]:
        """``(bone, bone)`` names of each pair (made once; a copy of the list)."""
        known = self.__dict__.get("_pair_names")
        if known is None:
            known = [(self.names[i], self.names[j]) for i, j in self.pairs.tolist()]
            object.__setattr__(self, "_pair_names", known)
        return list(known)


def bones(motion: Motion) -> Bones:
    """Segments and checkable pairs of a motion's skeleton.

    Points that coincide in the rest pose (zero-length offsets such as CMU's
    ``lhipjoint`` at the root, or siblings starting at one place such as CMU's
    ``lowerneck`` and clavicles at the end of ``thorax``) are one node; every
    pair of distinct nodes joined by a parent link is a bone; two bones are adjacent
    when they share a node.

    Raises
    ------
    ParameterError
        If the motion has no skeleton or fewer than two bones.
    """
    if motion.skeleton is None:
        raise ParameterError(
            "plausibility checks need a skeleton (forward kinematics); this motion has none"
        )
    skel = motion.skeleton
    rest = Motion(np.zeros((1, 0)), (), skeleton=skel).positions()
    pos = rest.positions[0]
    parents = rest.parents
    n = pos.shape[0]
    scale = max(skel.total_length(), 1e-12)
    node = np.arange(n)

    def find(i: int) -> int:
        while node[i] != i:
            node[i] = node[node[i]]
            i = node[i]
        return i

    tol = 1e-6 * scale
    for i in range(n):  # zero-length links: child and parent are one point
        p = parents[i]
        if p >= 0 and np.linalg.norm(pos[i] - pos[p]) <= tol:
            node[find(i)] = find(p)
    for i in range(n):  # siblings starting at one place (CMU's neck and clavicles)
        for k in range(i + 1, n):
            if (
                parents[i] >= 0
                and parents[k] >= 0
                and find(int(parents[i])) == find(int(parents[k]))
                and np.linalg.norm(pos[i] - pos[k]) <= tol
            ):
                node[find(k)] = find(i)
    roots = np.array([find(i) for i in range(n)])
    keys: list[tuple[int, int]] = []
    links: list[tuple[int, int]] = []
    for i in range(n):
        p = parents[i]
        if p < 0 or roots[i] == roots[p]:
            continue
        key = (int(roots[p]), int(roots[i]))
        if key in keys:
            continue
        keys.append(key)
        links.append((int(p), int(i)))
    per_parent = np.bincount([p for p, _ in links], minlength=n)
    point_names = rest.names
    names = [
        point_names[p] if per_parent[p] == 1 else f"{point_names[p]}>{point_names[i].split('/')[0]}"
        for p, i in links
    ]
    start = [p for p, _ in links]
    end = [i for _, i in links]
    if len(names) < 2:
        raise ParameterError("the skeleton has fewer than two bones; nothing can collide")
    s = np.array(start)
    e = np.array(end)
    ns, ne = roots[s], roots[e]
    ii, jj = np.triu_indices(len(names), k=1)
    share = (ns[ii] == ns[jj]) | (ns[ii] == ne[jj]) | (ne[ii] == ns[jj]) | (ne[ii] == ne[jj])
    pairs = np.column_stack([ii[~share], jj[~share]])
    # bones one bone apart (a bone touches both): fingers and thumb, neck and clavicles
    nb = len(names)
    adj = np.zeros((nb, nb), dtype=bool)
    adj[ii[share], jj[share]] = True
    adj = adj | adj.T
    near = (adj.astype(int) @ adj.astype(int)) > 0
    second = near[pairs[:, 0], pairs[:, 1]]
    rest_d = segment_distances(pos[None, s[pairs[:, 0]]], pos[None, e[pairs[:, 0]]],
                               pos[None, s[pairs[:, 1]]], pos[None, e[pairs[:, 1]]])[0]
    return Bones(
        names=names, start=s, end=e, pairs=pairs, rest_distance=rest_d, second_neighbours=second
    )


def segment_parameters(
    p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Where segments ``p0-p1`` and ``q0-q1`` come closest, elementwise: the fractions
    ``s`` and ``t`` (0 to 1) along each, so that the closest points are ``p0 + s (p1 -
    p0)`` and ``q0 + t (q1 - q0)`` (:func:`segment_distances` says how).

    Parameters
    ----------
    p0, p1, q0, q1 : ndarray, shape (..., 3)

    Returns
    -------
    s, t : ndarray, shape (...)
    """
    return _parameters(p0, p1, q0, q1)[:2]


def _parameters(p0, p1, q0, q1):
    """``s, t`` of :func:`segment_parameters` and the vectors ``p1 - p0``, ``q1 - q0``,
    ``p0 - q0``."""
    u = p1 - p0
    v = q1 - q0
    w = p0 - q0
    a = np.einsum("...i,...i->...", u, u)
    b = np.einsum("...i,...i->...", u, v)
    c = np.einsum("...i,...i->...", v, v)
    d = np.einsum("...i,...i->...", u, w)
    e = np.einsum("...i,...i->...", v, w)
    denom = a * c - b * b
    tiny = 1e-12 * np.maximum(a * c, 1e-300)
    safe_a = np.where(a > 0, a, 1.0)
    safe_c = np.where(c > 0, c, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        # closest point of the first line to the second, clamped (any s if parallel)
        s = np.where(denom > tiny, (b * e - c * d) / np.where(denom > tiny, denom, 1.0), 0.0)
        s = np.clip(s, 0.0, 1.0)
        # the second segment's point closest to it, clamped; then the first's again
        t = (b * s + e) / safe_c
        s_low = np.clip(-d / safe_a, 0.0, 1.0)
        s_high = np.clip((b - d) / safe_a, 0.0, 1.0)
    s = np.where(t < 0.0, s_low, np.where(t > 1.0, s_high, s))
    t = np.clip(t, 0.0, 1.0)
    # degenerate segments: a point against a segment (or a point)
    point_q = c <= 0
    s = np.where(point_q, s_low, s)
    t = np.where(point_q, 0.0, t)
    point_p = a <= 0
    s = np.where(point_p, 0.0, s)
    t = np.where(point_p, np.clip(e / safe_c, 0.0, 1.0), t)
    return s, t, u, v, w


def segment_distances(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """Closest distance between segments ``p0-p1`` and ``q0-q1``, elementwise.

    Parameters
    ----------
    p0, p1, q0, q1 : ndarray, shape (..., 3)
        Segment end points (broadcast together).

    Returns
    -------
    ndarray, shape (...)
        Distances.  The closest points are found by minimising over the first
        segment's parameter with the second's clamped, then re-clamping the first (the
        exact solution for segments); degenerate (zero-length) segments work as points.
    """
    s, t, u, v, w = _parameters(p0, p1, q0, q1)
    diff = w + s[..., None] * u - t[..., None] * v
    return np.sqrt(np.einsum("...i,...i->...", diff, diff))


def _pair_distances(motion: Motion, bn: Bones, which: np.ndarray | None = None) -> np.ndarray:
    """Distances ``(T, Q)`` of every checked bone pair (or of pairs ``which``) in every
    frame."""
    pos = motion.positions().positions  # (T, P, 3)
    T = pos.shape[0]
    pairs = bn.pairs if which is None else bn.pairs[which]
    Q = pairs.shape[0]
    out = np.empty((T, Q))
    a, b = pairs[:, 0], pairs[:, 1]
    sa, ea, sb, eb = bn.start[a], bn.end[a], bn.start[b], bn.end[b]
    step = max(1, _CHUNK // max(Q, 1))
    for lo in range(0, T, step):
        p = pos[lo : lo + step]
        out[lo : lo + step] = segment_distances(p[:, sa], p[:, ea], p[:, sb], p[:, eb])
    return out


def _near_elements(
    pos: np.ndarray, bn: Bones, threshold: float, pairs: np.ndarray | None = None,
    frames: np.ndarray | None = None,
) -> np.ndarray:
    """(T, Q) frames and pairs whose bones come within ``threshold`` of each other's
    bounding sphere (centred on the bone's midpoint, radius half its length): on the
    others the two bones are farther apart than ``threshold``.  With ``pairs`` (Q,)
    or ``frames`` (T,) bool, only those pairs and frames are tested (the others read
    False).

    The midpoints' squared distances come from one Gram matrix per frame (a batched
    product, about ten times faster than gathering both midpoints of every pair); the
    sphere test is widened by a millionth of the body's extent so that the product's
    rounding can only add elements, never drop one.
    """
    T = pos.shape[0]  # (pos: the motion's points (T, P, 3), forward kinematics)
    rows = np.ones(T, bool) if frames is None else np.asarray(frames, bool)
    pos = pos[rows]
    mid = 0.5 * (pos[:, bn.start] + pos[:, bn.end])  # (t, B, 3)
    mid = mid - mid.mean(axis=1, keepdims=True)  # about the body: no travel in the sums
    half = 0.5 * np.linalg.norm(pos[:, bn.end] - pos[:, bn.start], axis=-1)  # (T, B)
    sq = np.einsum("tbi,tbi->tb", mid, mid)
    which = np.ones(bn.pairs.shape[0], bool) if pairs is None else np.asarray(pairs, bool)
    a, b = bn.pairs[which, 0], bn.pairs[which, 1]
    gram = mid @ mid.transpose(0, 2, 1)  # (T, B, B)
    d2 = sq[:, a] + sq[:, b] - 2.0 * gram[:, a, b]
    slack = 1e-6 * (float(np.sqrt(sq.max())) + threshold) if sq.size else 0.0
    reach = threshold + slack + half[:, a] + half[:, b]
    out = np.zeros((T, bn.pairs.shape[0]), dtype=bool)
    out[np.ix_(rows, which)] = d2 < reach * reach
    return out


def _element_distances(pos: np.ndarray, bn: Bones, which: np.ndarray) -> np.ndarray:
    """Distances ``(T, Q)`` of the bone pairs on the frames ``which`` (T, Q) marks, for
    points ``pos`` (T, P, 3); infinity elsewhere."""
    out = np.full(which.shape, np.inf)
    t, q = np.nonzero(which)
    a, b = bn.pairs[q, 0], bn.pairs[q, 1]
    step = max(1, _CHUNK // 4)
    for lo in range(0, t.size, step):
        tt, aa, bb = t[lo : lo + step], a[lo : lo + step], b[lo : lo + step]
        out[tt, q[lo : lo + step]] = segment_distances(
            pos[tt, bn.start[aa]], pos[tt, bn.end[aa]], pos[tt, bn.start[bb]], pos[tt, bn.end[bb]]
        )
    return out
