"""The channels figure: the capture's busiest joint angles with the extracted cycle laid over
them at the matching phase, and the jerk of both below (:func:`plot_channels`)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from ..errors import ParameterError
from ._canvas import check_result, new_figure

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..motion import Motion
    from ..periodic.pipeline import ExtractionResult

__all__ = ["plot_channels"]

_ORIGINAL_COLOUR = "#1f77b4"
_CYCLE_COLOUR = "#d62728"


# ----------------------------------------------------------------- channels
def _resolve_channels(
    motion: "Motion", channels: Any, exclude: set[int], default_count: int
) -> list[int]:
    if channels is None or (isinstance(channels, str) and channels == "all"):
        cols = [i for i in range(motion.n_channels) if i not in exclude]
        if not cols:
            cols = list(range(motion.n_channels))
        if channels is None:
            var = motion.frames[:, cols].var(axis=0)
            order = np.argsort(-var, kind="stable")[:default_count]
            cols = sorted(cols[i] for i in order)
        return cols
    single_pair = (
        isinstance(channels, tuple) and len(channels) == 2
        and all(isinstance(x, str) and "." not in x for x in channels)
    )
    if isinstance(channels, (str, int, np.integer)) or single_pair:
        channels = [channels]
    cols = []
    for c in channels:
        if isinstance(c, (int, np.integer)):
            if not 0 <= int(c) < motion.n_channels:
                raise ParameterError(
                    f"channel index {c} out of range for {motion.n_channels} channels"
                )
            cols.append(int(c))
            continue
        if isinstance(c, str):
            if "." not in c:
                raise ParameterError(
                    f"channel names look like 'joint.dof' (e.g. 'lfemur.rx'), got {c!r}"
                )
            j, d = c.rsplit(".", 1)
        else:
            try:
                j, d = c
            except (TypeError, ValueError):
                raise ParameterError(
                    f"a channel is 'joint.dof', (joint, dof) or a column index, got {c!r}"
                ) from None
        try:
            cols.append(motion.channel_index(str(j), str(d)))
        except KeyError:
            raise ParameterError(f"no channel {j}.{d} in this motion") from None
    return cols


def _best_offset(motion: "Motion", cycle: "Motion", root: set[int]) -> int:
    """Cycle frame that best matches the clip's first frame, judged over one period.

    The looped cycle is compared with the clip's first ``P`` frames at every offset
    (non-root channels, angle differences wrapped) and the closest offset is returned;
    a phase lookup would be ambiguous where the coordinate plateaus (slow poses).
    """
    cols = [i for i in range(motion.n_channels) if i not in root] or list(range(motion.n_channels))
    ccols = [cycle.channel_index(*motion.channels[c]) for c in cols]
    P = cycle.n_frames
    n = min(P, motion.n_frames)
    a = motion.frames[:n, cols]
    c = np.asarray(cycle.frames[:, ccols], dtype=float)
    rot = np.array([motion.channels[i][1].startswith("r") for i in cols])
    costs = np.empty(P)
    for j in range(P):
        d = a - c[(j + np.arange(n)) % P]
        d[:, rot] = (d[:, rot] + 180.0) % 360.0 - 180.0
        costs[j] = float(np.mean(d**2))
    return int(np.argmin(costs))


def _cycle_frames_at_phase(res: Any, s0: int, n: int, P: int) -> np.ndarray | None:
    """Cycle frame index at the capture's phase of frames ``s0 .. s0 + n - 1`` (-1 where a
    frame has no phase), or None when the result has no capture-timed phase."""
    phase = getattr(res, "phase", None)
    phases = np.asarray(getattr(res.typical, "phases", []), dtype=float)
    if phase is None or phases.size != P or res.parameters.get("timing", "capture") != "capture":
        return None
    seg = np.asarray(phase, dtype=float)[s0 : s0 + n]
    ok = np.isfinite(seg)
    if not ok.any():
        return None
    k = np.full(seg.size, -1)
    k[ok] = np.mod(np.round((seg[ok] - phases[0]) * P).astype(int), P)
    return k


def plot_channels(
    result: "ExtractionResult",
    channels: Any = None,
    *,
    periods: float = 3.0,
    fig: "Figure | None" = None,
    ax: "Sequence[Axes] | None" = None,
    max_channels: int = 6,
) -> "Figure":
    """Original channels against the typical cycle over a few periods, and their jerk.

    Each frame of the clip shows the cycle's frame at that frame's phase (the capture-timed
    ``result.phase``), so the curves stay in step over repetitions of different lengths;
    frames without a phase, and results timed by the coordinate, play the cycle at its
    own constant rate from the phase of the clip's first frame (paper Fig. 6).  The right panel is
    the jerk as the console and the report give it: with a skeleton on joint positions in the
    root's frame, metres / s³ (:func:`~cyclecoord.quality.pose_space.point_jerk`), without one
    on the prepared channels (:func:`~cyclecoord.quality.metrics.jerk_summary`); the cycle
    looped so its seam counts, per frame over one period of each; the title gives the means
    over the frames the cycle was made from and the whole cycle, ``result.jerk``.

    Parameters
    ----------
    result : ExtractionResult
    channels : None, "all", or list of "joint.dof" / (joint, dof) / column index
        Default: the ``max_channels`` non-root channels varying most in the clip.
    periods : float, default 3
        How many periods of the clip to show (capped at the clip's length).
    fig : Figure, optional
    ax : pair of Axes, optional
        ``(channels axes, jerk axes)``.
    max_channels : int, default 6

    Returns
    -------
    Figure
        Channel axes: for every channel a solid line (original) labelled
        ``"<joint>.<dof>"`` and a dashed one (cycle) labelled ``"<joint>.<dof> (cycle)"``.
        Jerk axes: lines labelled ``"original"`` and ``"cycle"``.
    """
    res = check_result(result, "plot_channels")
    if not np.isfinite(periods) or periods <= 0:
        raise ParameterError(f"periods must be a positive number, got {periods!r}")
    motion = res.motion
    cycle = res.cycle
    root = set(int(i) for i in motion.root_channels())
    cols = _resolve_channels(motion, channels, root, max_channels)
    names = [f"{motion.channels[c][0]}.{motion.channels[c][1]}" for c in cols]
    ccols = [cycle.channel_index(*motion.channels[c]) for c in cols]
    period = float(res.period_frames)
    # the capture from its first steady frame (a whole take's standing start is not the cycle's)
    used = getattr(res, "used_frames", None) or [(0, motion.n_frames)]
    s0 = int(used[0][0])
    n_show = int(min(motion.n_frames - s0, max(8, round(periods * period))))
    orig = motion.frames[s0 : s0 + n_show, cols]
    cyc_frames = np.asarray(cycle.frames[:, ccols], dtype=float)
    P = cyc_frames.shape[0]
    j0 = _best_offset(motion.window((s0, None)) if s0 else motion, cycle, root)
    idx = (j0 + np.arange(n_show)) % P
    at_phase = _cycle_frames_at_phase(res, s0, n_show, P)
    if at_phase is not None:
        # each frame shows the cycle's frame at its own phase: the two stay in step over
        # repetitions of different lengths (a constant rate drifts by their differences)
        idx = np.where(at_phase >= 0, at_phase, idx)
    cyc = cyc_frames[idx]
    # angles: the cycle and the clip may sit a whole turn apart; align each channel to the clip
    for k, c in enumerate(cols):
        if motion.channels[c][1].startswith("r"):
            turn = np.round((orig[0, k] - cyc[0, k]) / 360.0) * 360.0
            cyc[:, k] += turn

    if ax is None:
        fig = new_figure((11.0, 4.2), fig)
        ax_c, ax_j = fig.subplots(1, 2, gridspec_kw={"width_ratios": [2.2, 1.0]})
    else:
        if len(ax) != 2:
            raise ParameterError("ax must be a pair (channels axes, jerk axes)")
        ax_c, ax_j = ax
        fig = ax_c.figure
    import matplotlib as mpl

    palette = mpl.colormaps["tab10"] if len(cols) <= 10 else mpl.colormaps["turbo"]
    t = np.arange(n_show) + motion.start_frame + s0
    for k, name in enumerate(names):
        colour = palette(k % 10) if len(cols) <= 10 else palette(k / max(1, len(cols) - 1))
        lw = 1.4 if len(cols) <= 10 else 0.7
        ax_c.plot(t, orig[:, k], color=colour, linewidth=lw, label=name)
        ax_c.plot(t, cyc[:, k], color=colour, linewidth=lw, linestyle="--", label=f"{name} (cycle)")
    ax_c.set_xlabel("frame")
    ax_c.set_ylabel("channel value (degrees / length units)")
    ax_c.set_title(
        f"original (solid) vs cycle (dashed, at each frame's phase), {n_show / period:.1f} periods",
        fontsize=10,
    )
    if len(cols) <= 10:
        ax_c.legend(handles=[h for h in ax_c.get_lines() if not h.get_label().endswith("(cycle)")],
                    fontsize=7, loc="upper right", ncol=2)

    _draw_jerk(ax_j, res, s0, j0, P, period)
    return fig

def _point_jerks(res, s0: int, n_j: int, metres: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame jerk on joint positions: ``n_j`` frames of the capture from ``s0`` and
    the looped cycle (metres / s³)."""
    from ..quality.pose_space import point_jerk, root_frame_points
    from ..rig import describe_rig

    motion = res.motion
    seg = motion.window((s0, min(motion.n_frames, s0 + n_j + 3)))
    jo = point_jerk(root_frame_points(seg, describe_rig(motion)), motion.fps, False)[:n_j]
    # the cycle is written in the capture's own rig: read with its own description
    cyc = root_frame_points(res.cycle, describe_rig(res.cycle))
    jc = point_jerk(cyc, res.cycle.fps, True)
    return jo * metres, jc * metres


def _channel_jerks(res, s0: int, n_j: int) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame jerk on the prepared channels (4th-order stencil), capture and cycle."""
    from ..quality.metrics import jerk

    fps = res.motion.fps
    stencil = 7
    poses = np.asarray(res.prepared.poses, dtype=float)[s0:]
    typ = np.asarray(res.typical.frames, dtype=float)
    seg_o = poses[: n_j + stencil - 1]
    jo = (
        np.linalg.norm(jerk(seg_o, fps), axis=1)[:n_j] if seg_o.shape[0] >= stencil else np.zeros(0)
    )
    Pt = typ.shape[0]
    jc = np.linalg.norm(jerk(typ, fps, cyclic=True), axis=1) if Pt >= stencil else np.zeros(Pt)
    return jo, jc


def _draw_jerk(
    ax_j: "Axes", res: "ExtractionResult", s0: int, j0: int, P: int, period: float
) -> None:
    """The jerk panel: one period of the capture from frame ``s0`` and of the cycle from its
    frame ``j0`` (of ``P``), in the space ``result.jerk`` is measured in."""
    motion = res.motion
    # jerk in the space result.jerk is measured in (one definition everywhere), one period
    n_j = int(min(motion.n_frames - s0, max(8, round(period))))
    pq = getattr(res, "pose_quality", None)
    if pq is not None and pq.figures is not None:
        jo, jc_all = _point_jerks(res, s0, n_j, pq.figures.metres_per_unit)
        unit = "m / s³, joint positions"
    else:
        jo, jc_all = _channel_jerks(res, s0, n_j)
        unit = "units / s³, all channels"
    Pt = jc_all.size
    jc = jc_all[(j0 * Pt // max(P, 1) + np.arange(min(n_j, Pt))) % Pt] if Pt else np.zeros(0)
    ax_j.plot(
        np.arange(jo.size) + motion.start_frame + s0,
        jo,
        color=_ORIGINAL_COLOUR,
        linewidth=1.2,
        label="original",
    )
    ax_j.plot(
        np.arange(jc.size) + motion.start_frame + s0,
        jc,
        color=_CYCLE_COLOUR,
        linewidth=1.2,
        label="cycle",
    )
    ax_j.set_xlabel("frame")
    ax_j.set_ylabel(f"jerk norm ({unit})")
    jr = res.jerk
    ratio = jr["cycle"] / jr["original"] if jr.get("original", 0) > 0 else float("nan")
    ax_j.set_title(
        f"jerk: cycle {jr['cycle']:.3g} vs original {jr['original']:.3g}\n(ratio {ratio:.2f})",
        fontsize=9,
    )
    ax_j.legend(fontsize=8, loc="upper right")
    if jo.size and jc.size and min(jo.min(), jc.min()) > 0:
        ax_j.set_yscale("log")
