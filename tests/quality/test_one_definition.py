"""Jerk and loop closure mean one thing everywhere (issue 18): extract's result and
report, channels.png, and blend reading the cycle back from a file."""

import pytest

import cyclecoord as cc
from cyclecoord.plot.figures import plot_channels
from cyclecoord.synthesis.sources import cycle_summary


@pytest.fixture(scope="module")
def result():
    return cc.extract(cc.datasets.example_capture().motion)


def test_channels_figure_shows_the_reported_jerk(result):
    import matplotlib.pyplot as plt

    fig = plot_channels(result)
    title = fig.axes[1].get_title()
    plt.close(fig)
    j = result.jerk
    assert f"cycle {j['cycle']:.3g}" in title and f"original {j['original']:.3g}" in title
    assert f"ratio {j['cycle'] / j['original']:.2f}" in title


@pytest.mark.parametrize("suffix", [".npz", ".amc"])
def test_blend_reads_back_what_extract_reported(result, tmp_path, suffix):
    path = tmp_path / f"walk_cycle{suffix}"
    cc.save(result.cycle, path)
    back = cycle_summary(cc.load(path))
    assert back["loop_closure"] == pytest.approx(result.loop_closure, rel=0.02, abs=0.005)
    assert back["jerk"] == pytest.approx(result.jerk["cycle"], rel=0.02)
