"""Shared fixtures: where the real CMU and other-rig BVH captures live (beside the
checkout); and the skip gate: a test may skip only for a missing external program or
missing shared data (``tests/_skips.py``), anything else fails."""

from pathlib import Path

import pytest

from _skips import allowed, need_data, skip_reason

SHARED_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
CMU = SHARED_DATA / "cmu"
BVH = SHARED_DATA / "bvh"

_GATE = (
    "skipped for a reason the suite does not accept: {reason!r}. A test may skip only when "
    "an external program is missing (tests/_skips.py need_program) or the shared data is "
    "(need_data), and then only if it really is missing; every Python package a test needs "
    "is in the 'test' extra."
)


def _gate(report) -> None:
    if report.skipped and not hasattr(report, "wasxfail"):
        reason = skip_reason(report.longrepr)
        if not allowed(reason):
            report.outcome = "failed"
            report.longrepr = _GATE.format(reason=reason)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item, call):
    report = yield
    _gate(report)
    return report


@pytest.hookimpl(wrapper=True)
def pytest_make_collect_report(collector):
    report = yield
    _gate(report)
    return report


@pytest.fixture(scope="session")
def cmu_dir() -> Path:
    return need_data(CMU)


@pytest.fixture(scope="session")
def bvh_dir() -> Path:
    """Real BVH captures of other rigs (Bandai Namco, Xsens MVN): internal testing only."""
    return need_data(BVH)


@pytest.fixture(scope="session")
def walk_69_01(cmu_dir):
    import cyclecoord as cc

    return cc.load(cmu_dir / "69" / "69_01.amc")
