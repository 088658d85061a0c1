"""periodic.root on roots whose answer is known by hand: a straight line and a circle at
known speed, a known tilt, a known heading; the layout's columns scrambled on purpose so
that a dof read from the wrong column shows."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from cyclecoord.motion import Motion
from cyclecoord.periodic.root import (
    RootLayout,
    compose_root,
    decompose_root,
    heading,
    planted_ground,
    root_layout,
    root_rotations,
)
from cyclecoord.skeleton import Joint, Skeleton

# dof -> column of an 8-column frame array (two columns belong to nothing)
COLS = {"tx": 6, "ty": 2, "tz": 4, "rz": 0, "ry": 7, "rx": 3}
DOFS = ["rz", "ty", "rx", "tz", "tx", "ry"]  # the layout's own order of its columns


def layout(order="ZYX", axis=None):
    return RootLayout(columns=np.array([COLS[d] for d in DOFS]), dofs=list(DOFS), order=order,
                      axis=np.eye(3) if axis is None else np.asarray(axis, dtype=float))


def frames_of(T, **values):
    f = np.full((T, 8), 999.0)  # the unused columns hold junk that must never be read
    for d, c in COLS.items():
        f[:, c] = np.broadcast_to(values.get(d, 0.0), (T,))
    return f


def circle_walk(T=40, omega=3.0, v=2.0, h0=30.0, tilt=10.0, start=(1.0, -2.0)):
    """A root turning ``omega`` degrees a frame while stepping ``v`` forward (along its
    heading, the local z projected on the ground) each frame, leaning ``tilt`` about its
    own x, bobbing in height."""
    h = h0 + omega * np.arange(T)
    pos = np.zeros((T, 2))
    pos[0] = start
    for t in range(T - 1):
        a = np.radians(h[t])
        pos[t + 1] = pos[t] + v * np.array([np.sin(a), np.cos(a)])
    height = 10.0 + np.sin(np.arange(T))
    return frames_of(T, tx=pos[:, 0], tz=pos[:, 1], ty=height, ry=h, rx=tilt), h, pos, height


def test_root_rotations_are_scipys_euler_conjugated_by_the_axis():
    axis = Rotation.from_euler("XYZ", [20.0, -35.0, 50.0], degrees=True).as_matrix()
    rng = np.random.default_rng(0)
    f = frames_of(5, rx=rng.uniform(-90, 90, 5), ry=rng.uniform(-90, 90, 5), rz=rng.uniform(-90, 90, 5))
    for order in ("ZYX", "XZY"):
        lay = layout(order, axis)
        vals = np.column_stack([f[:, COLS["r" + a.lower()]] for a in order])
        want = [axis @ Rotation.from_euler(order, v, degrees=True).as_matrix() @ axis.T for v in vals]
        np.testing.assert_allclose(root_rotations(f, lay), want, atol=1e-12)


def test_heading_is_the_yaw_unwrapped_over_several_turns():
    yaw = np.linspace(-170.0, 900.0, 60)  # past +-180 three times
    f = frames_of(60, ry=yaw, rx=25.0)  # a lean about x does not move the heading
    np.testing.assert_allclose(heading(f, layout()), yaw, atol=1e-9)
    # the local z axis's direction on the ground: a root yawed by 90 faces +x
    assert heading(frames_of(1, ry=90.0), layout())[0] == pytest.approx(90.0)
    assert heading(frames_of(1, ry=-45.0), layout())[0] == pytest.approx(-45.0)


def test_decompose_a_root_walking_a_circle():
    f, h, pos, height = circle_walk()
    x = decompose_root(f, layout("YXZ"))
    assert x.shape == (40, 7)
    np.testing.assert_allclose(x[:, 0], height)
    # the lean about the root's own x, the heading taken out: rotation vector (10, 0, 0)
    np.testing.assert_allclose(x[:, 1:4], np.tile([10.0, 0.0, 0.0], (40, 1)), atol=1e-9)
    np.testing.assert_allclose(x[:, 4], 3.0, atol=1e-9)  # degrees a frame, last repeats
    np.testing.assert_allclose(x[:, 5], 0.0, atol=1e-9)  # never sideways
    np.testing.assert_allclose(x[:, 6], 2.0, atol=1e-9)  # forward by v


def test_decompose_a_straight_sidestep_and_a_single_frame():
    """A root facing +x (heading 90) moving along -z by 1.5 a frame steps to its right:
    local x (sideways) is +1.5 in the heading's frame ((-z) rotated back by -90 is +x)."""
    T = 6
    f = frames_of(T, ry=90.0, tz=-1.5 * np.arange(T), tx=4.0, ty=7.0)
    x = decompose_root(f, layout())
    np.testing.assert_allclose(x[:, 5], 1.5, atol=1e-12)
    np.testing.assert_allclose(x[:, 6], 0.0, atol=1e-12)
    np.testing.assert_allclose(x[:, 4], 0.0, atol=1e-12)
    np.testing.assert_allclose(x[:, 0], 7.0)
    # the yaw matrix itself: a step along the heading (+x) is forward
    g = frames_of(T, ry=90.0, tx=0.5 * np.arange(T))
    np.testing.assert_allclose(decompose_root(g, layout())[:, 5:7], np.tile([0.0, 0.5], (T, 1)), atol=1e-12)
    # speeding up: each step its own, the last frame repeating the one before
    acc = frames_of(T, ry=0.0, tz=0.5 * np.arange(T) ** 2)
    np.testing.assert_allclose(decompose_root(acc, layout())[:, 6], [0.5, 1.5, 2.5, 3.5, 4.5, 4.5], atol=1e-12)
    turn = frames_of(T, ry=[0.0, 1.0, 3.0, 6.0, 10.0, 15.0])
    np.testing.assert_allclose(decompose_root(turn, layout())[:, 4], [1.0, 2.0, 3.0, 4.0, 5.0, 5.0], atol=1e-9)
    one = decompose_root(f[:1], layout())
    np.testing.assert_allclose(one[0, 4:], 0.0)
    assert one[0, 0] == 7.0


def test_compose_builds_the_circle_walk_from_its_features():
    f, h, pos, height = circle_walk()
    T = len(f)
    feats = np.column_stack([height, np.tile([10.0, 0.0, 0.0], (T, 1)), np.full(T, 3.0),
                             np.zeros(T), np.full(T, 2.0)])
    out = compose_root(feats, layout("YXZ"), 30.0, (1.0, -2.0))  # X in the middle: no gimbal lock
    assert out.shape == (T, 6)
    col = {d: DOFS.index(d) for d in DOFS}
    np.testing.assert_allclose(out[:, col["ry"]], h, atol=1e-9)
    np.testing.assert_allclose(out[:, col["rx"]], 10.0, atol=1e-9)
    np.testing.assert_allclose(out[:, col["rz"]], 0.0, atol=1e-9)
    np.testing.assert_allclose(out[:, col["tx"]], pos[:, 0], atol=1e-9)
    np.testing.assert_allclose(out[:, col["tz"]], pos[:, 1], atol=1e-9)
    np.testing.assert_allclose(out[:, col["ty"]], height)


def test_compose_straight_and_in_place_by_hand():
    """Heading steps 1, 2, 3 (mean 2): kept, the heading goes 0, 1, 3; straight, the mean
    is taken out (-1, 0, 1): 0, -1, -1; in place likewise, and no ground travel."""
    T = 3
    feats = np.zeros((T, 7))
    feats[:, 0] = 5.0
    feats[:, 4] = [1.0, 2.0, 3.0]
    feats[:, 6] = 1.0  # forward 1 a frame
    col = {d: DOFS.index(d) for d in DOFS}
    keep = compose_root(feats, layout(), 0.0, (0.0, 0.0))
    np.testing.assert_allclose(keep[:, col["ry"]], [0.0, 1.0, 3.0], atol=1e-9)
    straight = compose_root(feats, layout(), 0.0, (0.0, 0.0), travel="straight")
    np.testing.assert_allclose(straight[:, col["ry"]], [0.0, -1.0, -1.0], atol=1e-9)
    # the ground follows the heading of the step's first frame
    a = np.radians([0.0, -1.0])
    np.testing.assert_allclose(straight[:, col["tx"]], [0.0, np.sin(a[0]), np.sin(a[0]) + np.sin(a[1])], atol=1e-12)
    np.testing.assert_allclose(straight[:, col["tz"]], [0.0, np.cos(a[0]), np.cos(a[0]) + np.cos(a[1])], atol=1e-12)
    still = compose_root(feats, layout(), 20.0, (3.0, 4.0), travel="in_place")
    np.testing.assert_allclose(still[:, col["ry"]], [20.0, 19.0, 19.0], atol=1e-9)
    np.testing.assert_allclose(still[:, col["tx"]], 3.0)
    np.testing.assert_allclose(still[:, col["tz"]], 4.0)
    np.testing.assert_allclose(still[:, col["ty"]], 5.0)


def test_compose_is_continuous_past_180_and_inverts_decompose_with_an_axis():
    axis = Rotation.from_euler("XYZ", [0.0, 0.0, 30.0], degrees=True).as_matrix()
    lay = layout("ZYX", axis)
    T = 30
    f = frames_of(T, ry=160.0 + 2.0 * np.arange(T), rx=5.0, rz=-3.0,
                  tx=np.cumsum(np.full(T, 0.3)), tz=np.cumsum(np.full(T, -0.2)), ty=9.0)
    x = decompose_root(f, lay)
    start = float(heading(f[:1], lay)[0])
    back = compose_root(x, lay, start, (f[0, COLS["tx"]], f[0, COLS["tz"]]))
    g = f.copy()
    g[:, [COLS[d] for d in DOFS]] = back
    # the same rotations (Euler numbers may take the other branch) and the same track
    np.testing.assert_allclose(root_rotations(g, lay)[:-1], root_rotations(f, lay)[:-1], atol=1e-9)
    for d in ("tx", "ty", "tz"):
        np.testing.assert_allclose(g[:-1, COLS[d]], f[:-1, COLS[d]], atol=1e-9)
    # written continuously: no jump of a wrap anywhere
    assert np.abs(np.diff(back[:, [DOFS.index(d) for d in ("rx", "ry", "rz")]], axis=0)).max() < 5.0


# ------------------------------------------------------------------ root_layout


def _root_skeleton(dofs=("tx", "ty", "tz", "rx", "ry", "rz"), order="ZYX"):
    joints = (Joint("root", -1, [0, 0, 0], dofs, order),
              Joint("leg", 0, [0, -5, 0], ("rx",), "X", end_site=[0, -5, 0]))
    return Skeleton(joints, name="r")


def test_root_layout_needs_six_root_dofs():
    sk = _root_skeleton()
    m = Motion(np.zeros((3, 7)), sk.channels, fps=30.0, skeleton=sk)
    lay = root_layout(m)
    assert lay.order == "ZYX" and sorted(lay.dofs) == ["rx", "ry", "rz", "tx", "ty", "tz"]
    assert [m.channels[c] for c in lay.columns] == [("root", d) for d in lay.dofs]
    np.testing.assert_array_equal(lay.axis, np.eye(3))
    assert lay.column("ty") == m.channels.index(("root", "ty"))
    five = _root_skeleton(("tx", "ty", "tz", "ry", "rz"), "ZY")
    assert root_layout(Motion(np.zeros((3, 6)), five.channels, fps=30.0, skeleton=five)) is None


# ---------------------------------------------------------------- planted_ground


def _striding(T=40):
    from tests._legs import legs_skeleton, make_motion

    m = make_motion(legs_skeleton(), T=T)
    f = m.frames.copy()
    col = {c: i for i, c in enumerate(m.channels)}
    f[:, col[("lfemur", "rx")]] = np.linspace(-25.0, 25.0, T)
    f[:, col[("rfemur", "rx")]] = np.linspace(25.0, -25.0, T)
    return m.with_frames(f), col


FEET = ("lfoot", "ltoes", "rfoot", "rtoes")


def test_planted_ground_without_contacts_is_the_clips_own_track_in_x_and_z():
    """No foot planted: the root keeps its own ground steps, along x as well as z, while it
    bobs up and down (the height is not a ground coordinate)."""
    clip, col = _striding()
    f = clip.frames.copy()
    T = len(f)
    f[:, col[("root", "tx")]] = 2.0 + 0.4 * np.arange(T)
    f[:, col[("root", "tz")]] = -1.0 + 0.1 * np.arange(T) ** 1.5
    f[:, col[("root", "ty")]] = 10.0 + 2.0 * np.sin(np.arange(T))
    clip = clip.with_frames(f)
    lay = root_layout(clip)
    ground = planted_ground(clip, lay, FEET, np.zeros((T, 4)))
    np.testing.assert_allclose(ground, f[:, [col[("root", "tx")], col[("root", "tz")]]], atol=1e-9)


def test_planted_ground_shares_steps_between_feet_and_the_clip():
    """Left foot planted at weight 0.25 per point (0.5 together): each step is half minus
    the left points' mean displacement relative to the root, half the root's own step.
    Frame 0 planted at weight 1 alone: the first step's weight is their mean, 0.5 each,
    summing to 1, so the first step follows the feet alone; a weight over 1 in total is
    shared out so it sums to 1."""
    clip, col = _striding()
    f = clip.frames.copy()
    T = len(f)
    f[:, col[("root", "tx")]] = 0.2 * np.arange(T)
    f[:, col[("root", "ty")]] = 10.0 + np.cos(np.arange(T))
    clip = clip.with_frames(f)
    lay = root_layout(clip)
    pos = clip.positions()
    root = pos["root"][:, [0, 2]]
    rel = {p: pos[p][:, [0, 2]] - root for p in FEET}
    drel = {p: np.diff(rel[p], axis=0) for p in FEET}
    own = np.diff(root, axis=0)
    start = f[0, [col[("root", "tx")], col[("root", "tz")]]]

    w = np.tile([0.25, 0.25, 0.0, 0.0], (T, 1))
    steps = -0.25 * (drel["lfoot"] + drel["ltoes"]) + 0.5 * own
    want = start + np.vstack([[0.0, 0.0], np.cumsum(steps, axis=0)])
    np.testing.assert_allclose(planted_ground(clip, lay, FEET, w), want, atol=1e-9)

    first = np.zeros((T, 4))
    first[0, :2] = 1.0
    steps = own.copy()
    steps[0] = -0.5 * (drel["lfoot"][0] + drel["ltoes"][0])
    want = start + np.vstack([[0.0, 0.0], np.cumsum(steps, axis=0)])
    np.testing.assert_allclose(planted_ground(clip, lay, FEET, first), want, atol=1e-9)

    # every point at weight 1 (total 4): a quarter each, nothing left for the clip's step;
    # weights outside [0, 1] are clipped into it (2 reads 1, -1 reads 0)
    allw = np.tile([2.0, 1.0, 1.0, 1.0], (T, 1))
    steps = -0.25 * sum(drel[p] for p in FEET)
    want = start + np.vstack([[0.0, 0.0], np.cumsum(steps, axis=0)])
    np.testing.assert_allclose(planted_ground(clip, lay, FEET, allw), want, atol=1e-9)
    neg = np.tile([-1.0, 0.0, 0.0, 0.0], (T, 1))
    np.testing.assert_allclose(planted_ground(clip, lay, FEET, neg), f[:, [col[("root", "tx")], col[("root", "tz")]]],
                               atol=1e-9)
