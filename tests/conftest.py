"""Shared fixtures: where the real CMU and other-rig BVH captures live (beside the checkout)."""

from pathlib import Path

import pytest

SHARED_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
CMU = SHARED_DATA / "cmu"
BVH = SHARED_DATA / "bvh"


@pytest.fixture(scope="session")
def cmu_dir() -> Path:
    if not CMU.is_dir():
        pytest.skip(f"real CMU captures not found at {CMU} (../shared/data beside the checkout)")
    return CMU


@pytest.fixture(scope="session")
def bvh_dir() -> Path:
    """Real BVH captures of other rigs (Bandai Namco, Xsens MVN): internal testing only."""
    if not BVH.is_dir():
        pytest.skip(f"real BVH captures not found at {BVH} (../shared/data beside the checkout)")
    return BVH


@pytest.fixture(scope="session")
def walk_69_01(cmu_dir):
    import cyclecoord as cc

    return cc.load(cmu_dir / "69" / "69_01.amc")
