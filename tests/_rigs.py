"""Rigs for tests: the shared BVH captures (skipped when absent) and synthetic rigs built here
from the synthetic walk (units, a Z-up world, a static root with 6 channels on every joint)."""

import warnings
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

import cyclecoord as cc
from cyclecoord.conventions import to_bvh_convention
from cyclecoord.motion import Motion
from cyclecoord.rig import CMU_UNIT, Z_TO_Y
from cyclecoord.skeleton import Joint, Skeleton
from _skips import need_data

BVH = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "bvh"
BANDAI = sorted((BVH / "bandai").glob("*.bvh")) if (BVH / "bandai").is_dir() else []
XSENS = BVH / "xsens" / "S02-Trial-Walk-1.bvh"


def shared(path: Path) -> Motion:
    need_data(path)
    return cc.load(path)


def bandai(k: int = 0) -> Motion:
    need_data(BVH / "bandai")
    return cc.load(BANDAI[k])


# ----------------------------------------------------------- synthetic rigs, built here
def walk() -> Motion:
    """The synthetic walk on a BVH skeleton (root tx ty tz rz rx ry, joints ZXY), 160 frames."""
    return to_bvh_convention(cc.datasets.example_capture().motion[:160], "ZXY")


def in_units(m: Motion, mpu: float) -> Motion:
    """The walk with its lengths in a unit of ``mpu`` metres, a BVH without a length unit."""
    k = CMU_UNIT / mpu
    joints = tuple(
        Joint(
            j.name,
            j.parent,
            j.offset * k,
            j.dofs,
            j.rotation_order,
            end_site=None if j.end_site is None else j.end_site * k,
        )
        for j in m.skeleton.joints
    )
    frames = np.array(m.frames)
    for i, (_, d) in enumerate(m.channels):
        if d.startswith("t"):
            frames[:, i] *= k
    skel = Skeleton(joints, name="scaled", source_format="bvh")
    return Motion(frames, m.channels, fps=m.fps, skeleton=skel, source="scaled")


def turn_root(m: Motion, rot: np.ndarray) -> Motion:
    """The root's transform premultiplied by ``rot``, Euler angles (ZXY) recomputed by SciPy."""
    root = m.skeleton.joints[0].name
    t = [m.channel_index(root, d) for d in ("tx", "ty", "tz")]
    r = [m.channel_index(root, d) for d in ("rz", "rx", "ry")]
    frames = np.array(m.frames)
    turned = Rotation.from_matrix(rot) * Rotation.from_euler("ZXY", frames[:, r], degrees=True)
    frames[:, r] = np.unwrap(turned.as_euler("ZXY", degrees=True), period=360, axis=0)
    frames[:, t] = frames[:, t] @ rot.T
    return m.with_frames(frames)


def static_root(m: Motion, rot: np.ndarray, shift, positions_everywhere: bool) -> Motion:
    """A static ``joint_Root`` (constant rotation ``rot`` and translation ``shift``) above the
    motion's root; with ``positions_everywhere`` every joint gets 6 channels, the positions of
    the joints below the old root constant and equal to their offsets (the Bandai layout)."""
    skel = m.skeleton
    order = "ZXY"
    six = ("tx", "ty", "tz", "rz", "rx", "ry")
    joints = [Joint("joint_Root", -1, [0, 0, 0], six, order)]
    for i, j in enumerate(skel.joints):
        dofs = six if (positions_everywhere or i == 0) else j.dofs
        joints.append(Joint(j.name, j.parent + 1, j.offset, dofs, j.rotation_order,
                            end_site=j.end_site))
    new = Skeleton(tuple(joints), name="static", source_format="bvh", length_unit=1.0)
    T = m.n_frames
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # gimbal lock: the angles still hold
        angles = Rotation.from_matrix(rot).as_euler(order, degrees=True)
    cols = {("joint_Root", "tx"): shift[0], ("joint_Root", "ty"): shift[1],
            ("joint_Root", "tz"): shift[2]}
    cols.update({("joint_Root", "r" + a.lower()): v for a, v in zip(order, angles)})
    columns = []
    for c in new.channels:
        if c in cols:
            columns.append(np.full(T, cols[c]))
        elif c in m.channels:
            columns.append(m.frames[:, m.channel_index(*c)])
        else:  # a constant position channel equal to the offset
            columns.append(np.full(T, new[c[0]].offset["xyz".index(c[1][1])]))
    return Motion(np.column_stack(columns), new.channels, fps=30.0, skeleton=new, source="static")


def z_up() -> Motion:
    """The walk (centimetres) on a Z-up rig: the root turned +90 degrees about x."""
    return turn_root(in_units(walk(), 0.01), Z_TO_Y.T)
