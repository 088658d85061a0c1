"""A two-legged test skeleton and motions on it (foot contacts and foot locking tests)."""

import numpy as np

from cyclecoord.motion import Motion
from cyclecoord.skeleton import Joint, Skeleton


def legs_skeleton(
    names=("lfemur", "ltibia", "lfoot", "ltoes", "rfemur", "rtibia", "rfoot", "rtoes"),
):
    """Root at hip height 10 over a floor at 3 (not 0); thigh 4, shin 4, foot 1, toes 0.5."""
    lf, lt, lfo, lto, rf, rt, rfo, rto = names
    joints = [Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX")]
    for side, (f, t, fo, to), x in (
        ("l", (lf, lt, lfo, lto), 1.0),
        ("r", (rf, rt, rfo, rto), -1.0),
    ):
        base = len(joints)
        joints += [
            Joint(f, 0, [x, -1, 0], ("rx", "ry", "rz"), "ZYX"),
            Joint(t, base, [0, -4, 0], ("rx",), "X"),
            Joint(fo, base + 1, [0, -4, 0], ("rx",), "X"),
            Joint(to, base + 2, [0, -0.5, 1], ("rx",), "X", end_site=[0, 0, 0.5]),
        ]
    return Skeleton(tuple(joints), name="legs")


def make_motion(skel, T=120, fps=60.0, root_speed=0.0, lift_left=None, bob=(0.0, 0.0)):
    """Standing legs; ``root_speed`` slides them forward, ``lift_left`` lifts the left foot
    on those frames, ``bob=(amplitude, hz)`` moves the whole body up and down."""
    channels = skel.channels
    frames = np.zeros((T, len(channels)))
    col = {c: i for i, c in enumerate(channels)}
    amplitude, hz = bob
    frames[:, col[("root", "ty")]] = 10.0 + amplitude * np.sin(2 * np.pi * hz * np.arange(T) / fps)
    frames[:, col[("root", "tz")]] = root_speed * np.arange(T) / fps
    if lift_left is not None:
        frames[lift_left, col[(skel.names[1], "rx")]] = -40.0  # swing the left thigh forward
    return Motion(frames, channels, fps=fps, skeleton=skel)


def swaying_legs(degrees, hz, T=90, fps=30.0):
    """Standing legs (root still) whose thighs sway in opposition, ``degrees`` each way
    at ``hz``: the feet slide back and forth under a held body."""
    m = make_motion(legs_skeleton(), T=T, fps=fps)
    frames = m.frames.copy()
    t = np.arange(T) / fps
    for side, sign in (("lfemur", 1.0), ("rfemur", -1.0)):
        frames[:, m.channels.index((side, "rx"))] = sign * degrees * np.sin(2 * np.pi * hz * t)
    return m.with_frames(frames)


def pins_pop_at(monkeypatch, frame: int) -> None:
    """``carry._accel`` made clean on the unpinned motion (its first call) and a pop of
    10 units/s^2 at ``frame`` on every pinned one after it (the lock's pop test by hand)."""
    from cyclecoord.synthesis import carry

    calls = []

    def fake(motion):
        calls.append(1)
        out = np.zeros(motion.n_frames)
        if len(calls) > 1:
            out[frame] = 10.0
        return out

    monkeypatch.setattr(carry, "_accel", fake)
