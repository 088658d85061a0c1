"""Undoing a capture's rig conventions for the analysis, and writing results back.

:func:`normalize_rig` gives the motion the analysis should see (a static root folded into
its child, constant position channels made offsets, Y up, a reference first frame
dropped) and a :class:`RigAdapter` whose :meth:`~RigAdapter.restore` writes any motion on
the analysis skeleton (a cycle, a blend) back with the original skeleton and channels.
What to undo comes from :func:`cyclecoord.rig.describe.describe_rig`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .._kinematics import local_transforms
from ..conventions import continuous_euler
from ..errors import ParameterError
from ..motion import Motion
from ..skeleton import AXIS_INDEX, Joint, Skeleton
from .describe import Z_TO_Y, RigInfo, _skeleton_of, describe_rig

__all__ = ["RigAdapter", "analysis_motion", "normalize_rig"]


# ------------------------------------------------------------------ normalising
def _full_order(joint: Joint) -> str:
    """The joint's Euler order completed to three axes (``"ZXY"`` for none)."""
    order = joint.rotation_order
    if len(order) == 3:
        return order
    if not order:
        return "ZXY"
    return order + "".join(a for a in "XYZ" if a not in order)


def _euler_columns(
    joint: Joint, order: str, rotations: np.ndarray, near: np.ndarray | None
) -> dict[str, np.ndarray]:
    """Rotation channel values ``{dof: (T,)}`` in ``order`` of local rotations ``(T, 3, 3)``,
    continuous over frames, first frame nearest ``near`` (degrees, in ``order``)."""
    rel = joint.axis.T @ rotations @ joint.axis
    angles = continuous_euler(rel[:, None], order, near=None if near is None else near[None])
    return {"r" + a.lower(): angles[:, 0, k] for k, a in enumerate(order)}


def _channel_values(motion: Motion, joint: Joint, order: str) -> np.ndarray | None:
    """The motion's first-frame angles of ``joint`` in ``order`` (None if it lacks any)."""
    col = {c: i for i, c in enumerate(motion.channels)}
    ks = [col.get((joint.name, "r" + a.lower())) for a in order]
    if any(k is None for k in ks):
        return None
    return np.array([motion.frames[0, k] for k in ks])


@dataclass(frozen=True, eq=False)
class RigAdapter:
    """How a capture's rig maps to the analysis rig, and back (:meth:`restore`).

    Attributes
    ----------
    info : RigInfo
        What was found on the capture.
    original : Skeleton
        The capture's skeleton.
    original_channels : tuple of (str, str)
        The capture's channels, in its order.
    analysis : Skeleton
        The skeleton of the analysis motion.
    analysis_channels : tuple of (str, str)
        The analysis motion's channels.
    folded_root : bool
        The static root was folded into its child (which is the analysis root).
    root_rotation : ndarray, shape (3, 3)
        The static root's constant local rotation ``R0`` (identity when not folded).
    root_translation : ndarray, shape (3,)
        Its constant local translation ``t0``, skeleton length units.
    root_values : dict
        ``{(joint, dof): value}`` of the static root's constant channels.
    position_values : dict
        ``{(joint, dof): value}`` of the dropped constant position channels (degrees /
        length units); each is the joint's offset component on the analysis skeleton.
    up_rotation : ndarray, shape (3, 3)
        Rotation premultiplied to the analysis root (``Z_TO_Y`` for a Z-up rig, else the
        identity).
    dropped_frames : int
        Frames dropped from the start (1 for a reference pose, else 0).
    root_near : ndarray of shape (3,) or None
        The original travelling joint's first-frame angles, so restored Euler channels
        start on the capture's own branch.
    """

    info: RigInfo
    original: Skeleton
    original_channels: tuple[tuple[str, str], ...]
    analysis: Skeleton
    analysis_channels: tuple[tuple[str, str], ...]
    folded_root: bool = False
    root_rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    root_translation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    root_values: dict = field(default_factory=dict)
    position_values: dict = field(default_factory=dict)
    up_rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    dropped_frames: int = 0
    root_near: np.ndarray | None = None

    @property
    def rotates_root(self) -> bool:
        """The analysis root's transform differs from the travelling joint's (a rotation)."""
        return not (
            np.array_equal(self.root_rotation, np.eye(3))
            and np.array_equal(self.up_rotation, np.eye(3))
        )

    @property
    def identity(self) -> bool:
        """Nothing was changed: the analysis motion is the capture itself."""
        return not (
            self.folded_root or self.position_values or self.rotates_root or self.dropped_frames
        )

    def changes(self) -> list[str]:
        """What :func:`normalize_rig` did, one short phrase per step."""
        out = []
        if self.dropped_frames:
            out.append("reference first frame dropped")
        if self.folded_root:
            out.append(f"static root {self.original.joints[0].name} folded into "
                       f"{self.analysis.joints[0].name}")
        if self.position_values:
            joints = sorted({j for j, _ in self.position_values})
            out.append(f"constant position channels of {len(joints)} joints made offsets")
        if not np.array_equal(self.up_rotation, np.eye(3)):
            out.append("turned Z-up to Y-up")
        return out

    def restore(self, motion: Motion) -> Motion:
        """A motion on the analysis skeleton written back in the capture's own rig.

        Parameters
        ----------
        motion : Motion
            Frames ``(T, D')`` with the analysis channels (any order): the analysis motion,
            or a cycle, blend or clip computed on it.

        Returns
        -------
        Motion
            Frames ``(T, D)`` with :attr:`original_channels` in their order and the
            original skeleton: the static root re-added with its constant channels, the
            position channels re-added with their constant values, the up axis turned
            back; Euler channels continuous over frames.  A dropped reference frame is
            not put back.  Rate, source, start frame and metadata are ``motion``'s.

        Raises
        ------
        ParameterError
            When ``motion`` does not have the analysis channels.
        """
        if not isinstance(motion, Motion):
            raise ParameterError(f"restore takes a Motion, got {type(motion).__name__}")
        have, want = set(motion.channels), set(self.analysis_channels)
        if have != want:
            missing = sorted(want - have)[:4]
            extra = sorted(have - want)[:4]
            raise ParameterError(
                "restore needs a motion with the analysis rig's channels "
                f"(missing {missing}, extra {extra})"
            )
        if self.identity:
            out = motion if motion.channels == self.original_channels else motion.select(
                self.original_channels
            )
            return out if out.skeleton is self.original else replace(out, skeleton=self.original)
        m = replace(motion, skeleton=self.analysis)
        T = m.n_frames
        col = {c: i for i, c in enumerate(m.channels)}
        values: dict[tuple[str, str], np.ndarray] = {}
        # every column that passes through unchanged
        for c, k in col.items():
            values[c] = m.frames[:, k]
        new_root = self.analysis.joints[0]
        old_k = 1 if self.folded_root else 0
        old = self.original.joints[old_k]
        if self.rotates_root or self.folded_root:
            for d in new_root.dofs:
                values.pop((new_root.name, d), None)
            if self.rotates_root:
                trans, rots = local_transforms(m)
                R = np.einsum("ba,tbc->tac", self.up_rotation, rots[:, 0])  # Q.T @ R
                p = trans[:, 0] @ self.up_rotation  # Q.T @ p
                R = np.einsum("ba,tbc->tac", self.root_rotation, R)  # R0.T @ R
                p = (p - self.root_translation) @ self.root_rotation  # R0.T (p - t0)
                order = _full_order(old)
                angles = _euler_columns(old, order, R, self.root_near)
                for d in old.dofs:
                    if d.startswith("t"):
                        values[(old.name, d)] = p[:, AXIS_INDEX[d[1]]]
                    else:
                        values[(old.name, d)] = angles[d]
            else:  # folded with identity rotation: channels copied, translation shifted
                for d in old.dofs:
                    k = col.get((new_root.name, d))
                    if k is None:
                        continue
                    v = m.frames[:, k]
                    if d.startswith("t"):
                        v = v - self.root_translation[AXIS_INDEX[d[1]]]
                    values[(old.name, d)] = v
        for c, v in list(self.root_values.items()) + list(self.position_values.items()):
            values[c] = np.full(T, v)
        frames = np.column_stack(
            [
                values[c] if c in values else np.zeros(T)
                for c in self.original_channels
            ]
        ) if self.original_channels else np.zeros((T, 0))
        return replace(
            m,
            frames=frames,
            channels=self.original_channels,
            skeleton=self.original,
        )


def normalize_rig(
    motion: Motion, info: RigInfo | None = None, *, drop_reference: bool = True
) -> tuple[Motion, RigAdapter]:
    """The motion the analysis should see, and the adapter that writes results back.

    Steps, each only where :func:`describe_rig` found it:

    1. a reference first frame is dropped (``start_frame`` advances);
    2. a static root is folded into its only child, which becomes the root: its
       transform becomes ``R0 @ R_child`` and ``t0 + R0 @ p_child`` (``R0``, ``t0`` the
       root's constant rotation and translation), written as the child's channels
       ``tx ty tz`` and three Euler angles in the child's order;
    3. constant position channels of the other joints are dropped, their values becoming
       the joints' offsets;
    4. a Z-up rig is turned Y-up by premultiplying the root's transform by
       :data:`Z_TO_Y`.

    Lengths keep the capture's unit.  Euler angles of a changed root are continuous over
    frames (:func:`cyclecoord.conventions.continuous_euler`) and start on the branch of
    the capture's own first frame; where the root's rotation is unchanged its channels
    are copied.  Forward kinematics of the result equals the capture's (reference frame
    aside).

    Parameters
    ----------
    motion : Motion
        A capture with a skeleton, frames ``(T, D)``.
    info : RigInfo, optional
        :func:`describe_rig` of ``motion`` when already computed.
    drop_reference : bool, default True
        Drop a reference first frame (False keeps every frame, e.g. for drawing).

    Returns
    -------
    analysis : Motion
        Frames ``(T', D')``, ``T' = T - 1`` when a reference frame was dropped; ``motion``
        itself when nothing needed changing.
    adapter : RigAdapter
        Its :meth:`~RigAdapter.restore` gives a motion on the analysis skeleton back in
        the capture's skeleton and channels.
    """
    skel = _skeleton_of(motion)
    if info is None:
        info = describe_rig(motion)
    channels = tuple(motion.channels)
    drop = drop_reference and info.reference_frame and motion.n_frames > 1
    m = motion[1:] if drop else motion
    fold = info.static_root
    up = Z_TO_Y if info.up_axis == "Z" else np.eye(3)
    col = {c: i for i, c in enumerate(m.channels)}
    first = 1 if fold else 0
    root_values, R0, t0 = _static_root_values(skel, m, col) if fold else ({}, np.eye(3),
                                                                          np.zeros(3))
    joints, position_values, columns = _analysis_joints(
        skel, m, col, first, set(info.constant_position_joints))
    new_root = skel.joints[first]
    rotates = not (np.array_equal(R0, np.eye(3)) and np.array_equal(up, np.eye(3)))
    if rotates or fold:
        joints[0] = _new_root(joints[0], new_root, m, col, columns, fold, R0, t0, up, rotates)

    analysis_skel = Skeleton(
        joints=tuple(joints),
        name=skel.name,
        length_unit=skel.length_unit,
        source_format=skel.source_format,
    )
    kept = [c for c in analysis_skel.channels if c in columns]
    extra = [c for c in m.channels if c[0] not in analysis_skel.names and c[0] not in skel.names]
    analysis_channels = tuple(kept + extra)
    adapter = RigAdapter(
        info=info,
        original=skel,
        original_channels=channels,
        analysis=analysis_skel,
        analysis_channels=analysis_channels,
        folded_root=fold,
        root_rotation=R0,
        root_translation=t0,
        root_values=root_values,
        position_values=position_values,
        up_rotation=np.array(up, dtype=float),
        dropped_frames=motion.n_frames - m.n_frames,
        root_near=_channel_values(m, new_root, _full_order(new_root)) if rotates else None,
    )
    if adapter.identity:
        return motion, replace(adapter, analysis=skel, analysis_channels=channels)
    frames = np.column_stack(
        [columns[c] for c in kept] + [m.frames[:, col[c]] for c in extra]
    ) if analysis_channels else np.zeros((m.n_frames, 0))
    out = replace(m, frames=frames, channels=analysis_channels, skeleton=analysis_skel)
    return out, adapter


def _static_root_values(skel: Skeleton, m: Motion, col: dict) -> tuple[dict, np.ndarray,
                                                                         np.ndarray]:
    """A static root's constant channel values and its local rotation ``R0`` and
    translation ``t0`` (``R0`` exactly the identity when it is one to 1e-15)."""
    root = skel.joints[0]
    root_values = {
        (root.name, d): float(m.frames[0, col[(root.name, d)]])
        for d in root.dofs
        if (root.name, d) in col
    }
    trans0, rots0 = local_transforms(m[:1])
    R0, t0 = rots0[0, 0], trans0[0, 0]
    if np.allclose(R0, np.eye(3), rtol=0, atol=1e-15):
        R0 = np.eye(3)
    return root_values, R0, t0


def _analysis_joints(
    skel: Skeleton, m: Motion, col: dict, first: int, constant: set
) -> tuple[list[Joint], dict, dict]:
    """The analysis skeleton's joints from index ``first`` on (constant position channels
    of joints below the new root made offsets), the dropped channels' values and the
    kept channels' columns ``{(joint, dof): (T,)}``."""
    joints: list[Joint] = []
    position_values: dict = {}
    columns: dict[tuple[str, str], np.ndarray] = {}
    for i, j in enumerate(skel.joints[first:], start=first):
        parent = -1 if i == first else j.parent - first
        offset = j.offset.copy()
        dofs = list(j.dofs)
        if i > first and j.name in constant:
            for d in j.dofs:
                if d.startswith("t"):
                    k = col.get((j.name, d))
                    if k is not None:
                        value = float(np.mean(m.frames[:, k]))
                        position_values[(j.name, d)] = value
                        offset[AXIS_INDEX[d[1]]] = value
                    dofs.remove(d)
        joints.append(
            Joint(
                name=j.name,
                parent=parent,
                offset=offset,
                dofs=tuple(dofs),
                rotation_order=j.rotation_order,
                axis=j.axis.copy(),
                end_site=None if j.end_site is None else j.end_site.copy(),
                limits=dict(j.limits),
            )
        )
        for d in dofs:
            k = col.get((j.name, d))
            if k is not None:
                columns[(j.name, d)] = m.frames[:, k]
    return joints, position_values, columns


def _new_root(
    joint0: Joint, new_root: Joint, m: Motion, col: dict, columns: dict, fold: bool, R0: np.ndarray,
    t0: np.ndarray, up: np.ndarray, rotates: bool,
) -> Joint:
    """The analysis root: the static root folded into ``new_root`` and/or the up axis
    turned (``joint0``, the analysis skeleton's first joint, with its new dofs); its
    channels are written into ``columns``."""
    T = m.n_frames
    t_dofs = [d for d in new_root.dofs if d.startswith("t")]
    if len(t_dofs) < 3:
        t_dofs = ["tx", "ty", "tz"]
    order = _full_order(new_root) if rotates else new_root.rotation_order
    r_dofs = ["r" + a.lower() for a in order]
    if [d for d in new_root.dofs if d.startswith("r")] == r_dofs and len(
        [d for d in new_root.dofs if d.startswith("t")]
    ) == 3:
        dofs = tuple(new_root.dofs)
    else:
        dofs = tuple(t_dofs + r_dofs)
    trans, rots = local_transforms(m)
    if fold:
        R = np.einsum("ab,tbc->tac", R0, rots[:, 1])
        p = t0 + np.einsum("ab,tb->ta", R0, trans[:, 1])
    else:
        R, p = rots[:, 0], trans[:, 0]
    for d in new_root.dofs:
        columns.pop((new_root.name, d), None)
    if rotates:
        R = np.einsum("ab,tbc->tac", up, R)
        p = p @ up.T
        near = _channel_values(m, new_root, order)
        angles = _euler_columns(new_root, order, R, near)
    else:  # only folded, R0 = I: rotation channels copied
        angles = {
            d: m.frames[:, col[(new_root.name, d)]]
            for d in r_dofs
            if (new_root.name, d) in col
        }
    for d in dofs:
        columns[(new_root.name, d)] = (
            p[:, AXIS_INDEX[d[1]]] if d.startswith("t") else angles.get(d, np.zeros(T))
        )
    return _replace_joint(joint0, dofs=dofs, rotation_order=order)


def _replace_joint(joint: Joint, **changes) -> Joint:
    """A copy of ``joint`` with some fields changed (re-validated)."""
    fields = {
        "name": joint.name,
        "parent": joint.parent,
        "offset": joint.offset.copy(),
        "dofs": joint.dofs,
        "rotation_order": joint.rotation_order,
        "axis": joint.axis.copy(),
        "end_site": None if joint.end_site is None else joint.end_site.copy(),
        "limits": dict(joint.limits),
    }
    fields.update(changes)
    return Joint(**fields)


def analysis_motion(motion: Motion) -> Motion:
    """The motion as the measures see it: :func:`normalize_rig` with every frame kept.

    The travelling joint is the root and Y is up, so a static root with moving hips (the
    Bandai rig) or a Z-up capture is measured like any other: no bone from a fixed
    origin to the hips, no travel among the pose's points. A motion without a skeleton,
    or one that needs no change, is returned as it is.
    """
    if motion.skeleton is None:
        return motion
    info = describe_rig(motion)
    if not (info.static_root or info.constant_position_joints or info.up_axis == "Z"):
        return motion  # what normalize_rig would give back (a tenth of an animate script)
    return normalize_rig(motion, info, drop_reference=False)[0]
