"""The closing step of a stand after a gait (``synthesis.stance``), on a synthetic walk and
run: the feet end side by side, planted, without a pop; a stand that more frames follow
steps out again into them; a stand not after a stride, or one the legs cannot reach, is
left as it was and says why."""

from __future__ import annotations

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.quality.contacts import foot_contacts
from cyclecoord.quality.generated import measure_generated
from _gait_models import gait_pair, stop  # tests/ is on the path (rootdir conftest)
from cyclecoord.synthesis.latent import Synthesizer
from cyclecoord.synthesis.latent.script import training_takes
from cyclecoord.synthesis.stance import STEP_CLEARANCE, TOGETHER, close_stands


@pytest.fixture(scope="module")
def models():
    return gait_pair()


def _gaps(motion, model, frames):
    """Along and across the body (leg lengths): the ankles' horizontal distance along the
    line square to the hips, and across it, on ``frames``."""
    c = foot_contacts(model.training_motion())
    J = motion.positions()
    legs = list(dict.fromkeys(c.leg_labels))
    ank = np.stack([J[c.feet[list(c.leg_labels).index(g)]][frames] for g in legs], axis=1)
    hips = np.stack([J["lfemur"][frames], J["rfemur"][frames]], axis=1)
    across = hips[:, 1] - hips[:, 0]
    across[:, 1] = 0.0
    across /= np.linalg.norm(across, axis=1, keepdims=True)
    d = ank[:, 1] - ank[:, 0]
    d[:, 1] = 0.0
    side = np.abs(np.einsum("ta,ta->t", d, across))
    along = np.linalg.norm(d - side[:, None] * across * np.sign(
        np.einsum("ta,ta->t", d, across))[:, None], axis=1)
    return along / c.leg_length, side / c.leg_length


@pytest.mark.parametrize("part", ["walk", "run"])
def test_a_stop_ends_with_the_feet_side_by_side(models, part):
    """Stopped at double support a walk stood a stride apart for the whole IDLE (0.39-0.55
    leg lengths along the body on this walk, 0.56-0.72 on subject 35's); the closing step
    brings the trailing foot beside the other one, the hips' width apart."""
    closed, along, apart = 0, [], []
    for seed in range(6):
        syn, motion = stop(models, part, seed)
        (a, b), = syn.stands
        stands = [n for n in syn.notes if n.startswith("stands:")]
        assert stands, syn.notes
        if "feet with one more step" not in stands[0]:
            assert "kept its stance" in stands[0]
            continue
        closed += 1
        (entry,) = syn.stand_steps  # (the report's "stands")
        assert entry["start"] == a and entry["stop"] == b and entry["closed"]
        assert entry["gap"] > TOGETHER
        g_along, g_side = _gaps(motion, models[part], np.arange(b - 30, b))
        along.append(g_along.max())
        apart.append(g_side.min())
    assert closed >= 5
    assert max(along) < TOGETHER, np.round(along, 3)
    assert min(apart) > 0.05, np.round(apart, 3)  # side by side, not one on the other


def test_the_closing_step_lifts_the_foot_and_leaves_it_planted(models):
    """The trailing foot clears the floor on its way and then stays where it landed; the
    stand's accelerations stay within the training takes' 99th percentile."""
    syn, motion = stop(models, "walk", 2)
    (a, b), = syn.stands
    c = foot_contacts(models["walk"].training_motion())
    J = motion.positions()
    legs = list(dict.fromkeys(c.leg_labels))
    ank = np.stack([J[c.feet[list(c.leg_labels).index(g)]] for g in legs], axis=1)
    travelled = np.linalg.norm(ank[b - 1] - ank[a], axis=1)
    mover = int(np.argmax(travelled))
    assert travelled[mover] > 0.3 * c.leg_length  # the trailing foot stepped up
    # the other one stood (landing still at the stand's first frames: from where it lay)
    assert travelled[1 - mover] < 0.1 * c.leg_length
    assert np.linalg.norm(ank[b - 1, 1 - mover] - ank[a + 15, 1 - mover]) < 0.01 * c.leg_length
    rise = ank[a : a + 15, mover, 1] - ank[b - 1, mover, 1]
    assert rise.max() > 0.5 * STEP_CLEARANCE * c.leg_length
    speed = np.linalg.norm(np.diff(ank[a + 16 : b][:, :, [0, 2]], axis=0), axis=-1) * 30
    assert speed.max() * cc.rig.metres_per_unit(motion) < 0.02  # m/s: planted
    q = measure_generated(motion[a:b], training_takes(models, ["walk"]))
    assert q.largest_accel <= 1.0


def test_a_stand_that_frames_follow_steps_out_into_them(models):
    """An IDLE between two walks: the feet close, then the leading foot steps out by the
    same gap and the walk goes on from there, without a jump at the stand's end."""
    syn, motion = stop(models, "walk", 1, then=3)
    (a, b), = syn.stands
    assert any("feet with one more step" in n for n in syn.notes), syn.notes
    g_along, _ = _gaps(motion, models["walk"], np.arange(a + 20, b - 20))
    assert g_along.max() < TOGETHER
    q = measure_generated(motion[a - 15 : b + 30], training_takes(models, ["walk"]))
    assert q.largest_step <= 1.2 and q.largest_accel <= 1.2
    assert q.longest_freeze_s <= 2.0  # (the stand itself was asked for)
    # the step lands on the stand's last frame in the pose the walk goes on from: landing
    # on the frame after, the stepping knee was 13.5 degrees more bent than that frame's
    legs = [i for i, (j, c) in enumerate(motion.channels)
            if j in ("lfemur", "rfemur", "ltibia", "rtibia", "lfoot", "rfoot")]
    jump = np.abs(motion.frames[b, legs] - motion.frames[b - 1, legs])
    assert jump.max() < 6.0, dict(zip([motion.channels[i] for i in legs], jump.round(1)))


def test_a_stand_from_a_start_frame_mid_stride_closes_its_feet_and_ends_the_script(models):
    """A script that starts on a walk frame mid-stride and stands there to its end stood
    a stride wide, a heel up: it takes the closing step (forward from the toes, each foot
    point at its planted height).  With frames after it, whose stride its opening step
    would have to start again (7 random scripts popped, up to 3.7x), it is left alone."""
    syn = Synthesizer(models, fps=30, seed=0)
    syn.start("walk", {"frame": 0})
    syn.command += 1
    syn.idle(duration=2.0)  # a stand with no stride before it
    motion = syn.motion()
    (a, b), = syn.stands
    assert [n for n in syn.notes if n.startswith("stands: 1 stand closed its feet")]
    g_along, _ = _gaps(motion, models["walk"], np.arange(b - 15, b))
    assert g_along.max() < TOGETHER
    assert measure_generated(motion, training_takes(models, ["walk"])).largest_accel <= 1.0
    then = Synthesizer(models, fps=30, seed=0)
    then.start("walk", {"frame": 0})
    then.command += 1
    then.idle(duration=2.0)
    then.command += 1
    then.move({"ahead": 0.5})
    then.motion()
    assert not [n for n in then.notes if n.startswith("stands:")]


def test_stands_out_of_reach_are_left_alone(models):
    feet = Synthesizer(models, fps=30, seed=0).feet_of(models["walk"].training_motion())
    # after a stride, with every leg angle held where it is: the legs cannot step
    syn, _ = stop(models, "walk", 0)
    motion = syn._untangled()
    frozen = (motion.frames.min(axis=0), motion.frames.min(axis=0))
    out = close_stands(motion, feet, syn.stands, cycle=1.1, bounds=frozen)
    assert out.motion is motion and not out.closed
    (a, why), = out.kept
    assert a == syn.stands[0][0] and "could not reach" in why
    assert out.line.startswith(f"stands: the stand at frame {a} kept its stance")
    assert out.to_dict() == [{"start": a, "closed": False, "why": why}]


def test_a_step_that_pops_is_not_made(models):
    """With a ``limit``, a step that takes a frame past it (and past the motion given) is
    not made: a Bandai walk's knee, held straight at its bound for three frames of a
    closing step, bent 30 degrees in the next (2.0x its p99)."""
    from cyclecoord.synthesis.carry import _accel

    feet = Synthesizer(models, fps=30, seed=0).feet_of(models["walk"].training_motion())
    syn, _ = stop(models, "walk", 0)
    motion = syn._untangled()
    free = close_stands(motion, feet, syn.stands, cycle=1.1)
    assert free.closed  # (this stand's step is made without a limit)
    a, b = syn.stands[0]
    given, stepped = _accel(motion), _accel(free.motion)
    # a limit the step stays under where it moves the frames, and one it passes
    roomy = close_stands(motion, feet, syn.stands, cycle=1.1, limit=1.01 * stepped.max())
    assert roomy.closed and np.array_equal(roomy.motion.frames, free.motion.frames)
    tight = np.maximum(given, 1e-9)  # (the motion given's own: any rise of over 5 % is past it)
    assert (stepped[a - 1 : b + 2] > 1.05 * given[a - 1 : b + 2]).any()
    out = close_stands(motion, feet, syn.stands, cycle=1.1, limit=tight)
    assert out.motion is motion and not out.closed
    (first, why), = out.kept
    assert first == a and "its step made a joint accelerate" in why


def test_the_benchmark_reports_how_far_apart_a_stop_stands(models, tmp_path, capsys):
    """``bench_latent_gait.stops`` prints the ankles' distance at the stand's end (it
    crashed on its first run: a name reused for the folder)."""
    import re

    from _bench import load_bench

    bench = load_bench("bench_latent_gait")
    for name, m in models.items():
        m.save(tmp_path / f"{name}.npz")
    bench.stops(models, tmp_path, n=1)
    out = capsys.readouterr().out
    apart = [float(x) for x in re.findall(r"ankles apart at the end ([0-9.]+) leg lengths", out)]
    assert len(apart) == 2 and max(apart) < 0.35, out


def test_a_step_that_crosses_limbs_is_not_taken(models, monkeypatch):
    """Stepped straight forward, a narrow walk's trailing foot ran through the other
    shin and ``animate`` refused the whole script; a step whose limbs come closer than
    the training takes' is now left out, and the stand keeps its stance."""
    import cyclecoord.synthesis.carry as carry

    seen = []

    def crossed(motion, references, cache=None, base=None, analysed=False):
        seen.append(base is not None)
        out = np.zeros(motion.n_frames, dtype=bool)
        if base is not None:  # (the step's trial, checked against the motion it changes)
            out[-10:] = True
        return out

    monkeypatch.setattr(carry, "_crossed", crossed)
    syn, motion = stop(models, "walk", 0)
    (entry,) = syn.stand_steps
    assert not entry["closed"] and "closer than the training takes" in entry["why"]
    assert True in seen and False in seen
    g_along, _ = _gaps(motion, models["walk"], np.arange(motion.n_frames - 30, motion.n_frames))
    assert g_along.max() > TOGETHER  # the stride's stance, as it was


def test_idles_one_after_another_are_one_stand(models):
    """Two IDLEs in a row close the feet once and do not step out between them."""
    syn = Synthesizer(models, fps=30, seed=4)
    syn.start("walk", {"frame": 0})
    syn.command += 1
    syn.move({"ahead": 1.2})
    for _ in range(2):
        syn.command += 1
        syn.idle(duration=1.5)
    motion = syn.motion()
    assert len(syn.stands) == 2
    (entry,) = syn.stand_steps
    assert entry["closed"] and entry["start"] == syn.stands[0][0]
    assert entry["stop"] == syn.stands[1][1]
    g_along, _ = _gaps(motion, models["walk"], np.arange(syn.stands[0][1] - 10,
                                                         syn.stands[1][0] + 10))
    assert g_along.max() < TOGETHER  # no step out and back in between


def test_the_opening_step_ends_where_the_frames_after_the_stand_have_the_feet(models,
                                                                           monkeypatch):
    """A stand whose feet shift in the motion given (here the root drifts 0.2 leg lengths
    over the stand, and the frames after keep the drift): the opening step takes the feet
    to where the frames after the stand have them, with no jump at the stand's end (a
    random subject 35 script jumped both feet 1.5-2 units there, 7.9x the median
    acceleration)."""
    import cyclecoord.synthesis.stance as stance
    from cyclecoord.periodic.root import root_layout

    seen = {}
    real = stance.close_stands

    def spy(motion, feet, stands, **kw):
        seen.update(motion=motion, feet=feet, stands=stands, kw=kw)
        return real(motion, feet, stands, **kw)

    monkeypatch.setattr(stance, "close_stands", spy)
    syn, _ = stop(models, "walk", 1, then=3)
    motion, (a, b) = seen["motion"], seen["stands"][0]
    leg = foot_contacts(models["walk"].training_motion()).leg_length
    frames = motion.frames.copy()
    t = np.arange(motion.n_frames)
    drift = 0.2 * leg * np.clip((t - (a + 20)) / (b - a - 30), 0.0, 1.0)
    frames[:, root_layout(motion).column("tx")] += drift
    done = real(motion.with_frames(frames), seen["feet"], seen["stands"], **seen["kw"])
    assert done.closed == [(a, b)]
    J = done.motion.positions()
    ank = np.stack([J[f] for f in seen["feet"][::2]], axis=1)  # (T, 2, 3)
    step = np.linalg.norm(np.diff(ank, axis=0), axis=-1) / leg  # leg lengths a frame
    assert step[b - 1].max() < 0.05, np.round(step[b - 4 : b + 2], 3)
    assert step[b - 1].max() < 2.0 * step[b - 10 : b - 1].max() + 0.01


def test_the_closing_steps_pelvis_drop_eases_in_from_the_stands_first_frame(models,
                                                                          monkeypatch):
    """Where the step's legs cannot reach at the pelvis's height it is lowered; on the
    stand's first frame, whose pose is the motion's own, the drop eases in (taken at once,
    a Bandai walk stopped from an in-step blend lowered 0.9 cm in a frame and bent a knee
    15 degrees, 1.6x the walk's 99th percentile of acceleration)."""
    from types import SimpleNamespace

    import cyclecoord.synthesis.stance as S

    lowered = 0
    for part in ("walk", "run"):
        for seed in (0, 1, 2):
            syn, motion = stop(models, part, seed)
            with monkeypatch.context() as mp:
                mp.setattr(S, "close_stands", lambda out, *a, **k: SimpleNamespace(
                    motion=out, line="", to_dict=lambda: {}))
                _, plain = stop(models, part, seed)
            (a, b), = syn.stands
            ty = motion.channel_index(motion.skeleton.joints[0].name, "ty")
            drop = motion.frames[:, ty] - plain.frames[:, ty]
            assert np.abs(drop[:a]).max() == 0.0
            if drop[a : a + 6].min() < -0.05:
                lowered += 1
                # the first frame moves a third of the drop's first frames at most
                assert abs(drop[a]) < 0.35 * np.abs(drop[a : a + 6]).max(), np.round(drop, 3)
    assert lowered >= 4


def test_an_opening_step_frame_that_hops_is_solved_again_from_the_frame_before(
        models, monkeypatch):
    """The opening step is solved with the closing one, from the motion's own poses; a
    frame whose solution hops (here made to: one angle 30 degrees off on the third frame
    from the end) is solved again from the frame before it, turning at most OPENING_TURN
    from it: a Bandai run's ankle turned 35 degrees in one frame there (2.4x its p99)."""
    import cyclecoord.synthesis.footlock as footlock
    import cyclecoord.synthesis.stance as stance

    seen = {}
    real_close, real_solve = stance.close_stands, footlock._solve

    def spy(motion, feet, stands, **kw):
        seen.update(motion=motion, feet=feet, stands=stands, kw=kw)
        return real_close(motion, feet, stands, **kw)

    monkeypatch.setattr(stance, "close_stands", spy)
    stop(models, "walk", 1, then=3)
    (a, b), = seen["stands"]

    def hopping(ik, rows, *args, **kw):
        q = real_solve(ik, rows, *args, **kw)
        if rows.size > 1 and np.diff(rows).max() > 1:  # the steps' frames, solved at once
            q = q.copy()
            q[-3, 0] += 30.0
            seen.setdefault("hops", []).append((int(rows[-3]), ik.vars[0][2]))
        return q

    monkeypatch.setattr(footlock, "_solve", hopping)
    done = real_close(seen["motion"], seen["feet"], seen["stands"], **seen["kw"])
    assert done.closed == [(a, b)] and len(seen["hops"]) == 2  # both legs
    cap = stance.OPENING_TURN * 30.0 / seen["motion"].fps
    for row, col in seen["hops"]:
        assert b - 4 <= row < b
        steps = np.abs(np.diff(done.motion.frames[row - 1 : row + 2, col]))
        assert steps.max() <= cap + 1e-6, steps
