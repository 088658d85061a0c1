"""Foot locking: sliding feet are pinned, only the legs move, and by little."""

import numpy as np
import pytest

from cyclecoord.errors import ParameterError
from cyclecoord.motion import Motion
from cyclecoord.quality.contacts import foot_contacts, foot_skating
from cyclecoord.synthesis.footlock import lock_feet


from _legs import legs_skeleton, make_motion  # tests/ is on the path (rootdir conftest)


def _walkish(T=120, fps=60.0):
    """Legs swinging so each foot in turn slides slowly on the floor while the other swings."""
    skel = legs_skeleton()
    m = make_motion(skel, T=T, fps=fps, root_speed=2.0)
    frames = m.frames.copy()
    col = {c: i for i, c in enumerate(m.channels)}
    t = np.arange(T) / fps
    phase = 2 * np.pi * t / 1.0
    frames[:, col[("lfemur", "rx")]] = -25 * np.clip(np.sin(phase), 0, None)
    frames[:, col[("rfemur", "rx")]] = -25 * np.clip(-np.sin(phase), 0, None)
    return m.with_frames(frames)


def test_lock_removes_skating_and_touches_only_legs():
    m = _walkish()
    c = foot_contacts(m)
    assert c.planted.any()
    before = foot_skating(m, c)
    assert before.skating_frames > 0  # the root slides at 0.25 leg lengths/s
    r = lock_feet(m, c)
    assert r.after.skating_frames == 0
    assert r.max_error < 1e-3 * c.leg_length
    root_cols = [i for i, (j, _) in enumerate(m.channels) if j == "root"]
    assert np.array_equal(r.motion.frames[:, root_cols], m.frames[:, root_cols])
    changed = {k for k, v in r.joint_change.items() if v > 0}
    assert changed <= {"lfemur", "ltibia", "lfoot", "rfemur", "rtibia", "rfoot"}
    assert r.joint_change["ltoes"] == 0 and r.joint_change["root"] == 0
    # locked feet are pinned: horizontal positions constant over each contact
    pos = r.motion.positions()["ltoes"]
    runs = np.flatnonzero(c.planted[:, 1])
    assert np.ptp(pos[runs[:5]][:, [0, 2]], axis=0).max() < 1e-3


def test_lock_errors():
    m = _walkish()
    bare = Motion(m.frames, m.channels, fps=m.fps)
    with pytest.raises(ParameterError, match="skeleton"):
        lock_feet(bare)
    with pytest.raises(ParameterError, match="blend"):
        lock_feet(m, blend=-1)
    with pytest.raises(ParameterError, match="cover"):
        lock_feet(m[:50], foot_contacts(m))


def test_lock_69_01_window(walk_69_01):
    """The raw capture: stance runs are long, heel and toe locks nearly agree."""
    m = walk_69_01[200:450]
    r = lock_feet(m)
    assert r.before.skating_frames > 100
    assert r.after.skating_frames <= 2
    legs = ("lfemur", "ltibia", "lfoot", "rfemur", "rtibia", "rfoot")
    assert all(v == 0 for k, v in r.joint_change.items() if k not in legs)
    assert r.mean_joint_change < 1.0


@pytest.mark.slow
def test_lock_69_01_extracted_cycle(walk_69_01):
    """The README's figures: the 200:450 cycle skates; locked, no frame does and the legs
    move less than a degree on average."""
    from cyclecoord.periodic.pipeline import extract

    cycle = extract(walk_69_01, frames=(200, 450), max_scale=50).cycle
    r = lock_feet(cycle, cyclic=True)
    assert r.before.skating_frames > 20
    # the capture-timed cycle has a four-frame contact of the left heel beside the seam
    # that one pass does not pin (a second pass does, but moves a leg 10 degrees)
    assert r.after.skating_frames <= 0.05 * cycle.n_frames
    legs = ("lfemur", "ltibia", "lfoot", "rfemur", "rtibia", "rfoot")
    assert all(v == 0 for k, v in r.joint_change.items() if k not in legs)
    # the leg chains bend to pin the feet: 1.6-7 degrees on average per joint on this cycle
    # (0.4-0.9 on the paper-timed cycle, which slid its feet 2.6x faster before locking)
    assert np.mean([r.joint_change[k] for k in legs]) < 5.0
