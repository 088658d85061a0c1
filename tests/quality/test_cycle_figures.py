"""Our cycle of a whole synthetic take against the animator's loop cut, on every figure
benchmarks/bench_quality.py reads on the real takes (period, jerk, leg ranges, seam,
largest step, coverage, foot skating), each at its measured value plus 30 % (no shared
data needed)."""

import warnings

import pytest

import cyclecoord as cc
from cyclecoord.quality.cycle_quality import cycle_quality
from cyclecoord.quality.reference import autocorrelation_period, best_loop_cut
from _measured import at_least, at_most, frame

#: Measured (tests/_measured.py RUN), ours against the loop cut: period error against the
#: autocorrelation period, jerk ratio, smallest leg joint range ratio, seam, largest step
#: (over the take's p99), coverage ratio, foot skating over the take's.
MEASURED = {
    "walk": dict(period_error=0.0004, jerk_ratio=0.0434, min_joint_range_ratio=0.9957, seam=0.2718,
                 largest_step=0.6503, coverage_ratio=0.9018, skating_ratio=0.5665),
    "jog": dict(period_error=0.0023, jerk_ratio=0.0601, min_joint_range_ratio=0.9977, seam=0.2113,
                largest_step=0.8312, coverage_ratio=0.8972, skating_ratio=1.0435),
}
SEEDS = {"walk": 0, "jog": 1}


@pytest.fixture(scope="module", params=sorted(MEASURED))
def figures(request):
    kind = request.param
    take = cc.datasets.make_whole_take(kind, random_state=SEEDS[kind]).motion
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = cc.extract(take)
    ref = autocorrelation_period(take, res.used_frames)
    cut = best_loop_cut(take, ref, used_frames=res.used_frames)
    q_cut = cycle_quality(cut.clip, take, method="loop cut", reference_period=ref,
                          used_frames=res.used_frames)
    q = cycle_quality(res.cycle, take, method="ours", period_frames=res.period_frames,
                      reference_period=ref, reference=q_cut, used_frames=res.used_frames)
    return MEASURED[kind], q, q_cut


def test_period_and_smoothness(figures):
    m, q, _ = figures
    assert abs(q.period_error) <= at_most(m["period_error"], frame(q.reference_period))
    assert q.jerk_ratio <= at_most(m["jerk_ratio"])


def test_legs_keep_their_range(figures):
    m, q, _ = figures
    assert q.min_joint_range_ratio >= at_least(m["min_joint_range_ratio"])


def test_seam_and_largest_step(figures):
    m, q, q_cut = figures
    assert q.seam <= at_most(m["seam"]) and q.seam < q_cut.seam
    assert q.largest_step <= at_most(m["largest_step"])


def test_coverage_of_the_take(figures):
    m, q, _ = figures
    assert q.coverage_ratio <= at_most(m["coverage_ratio"])


def test_foot_skating(figures):
    m, q, _ = figures
    assert q.skating_ratio <= at_most(m["skating_ratio"])
