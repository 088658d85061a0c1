"""Figures of latent models: the latent points (Bailey et al. Fig. 2), a particle's path,
bridges between two models, and a strip of poses from a synthesised motion."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["plot_bridges", "plot_latent", "plot_pose_strip", "plot_transition_profile"]


def _axes3d(ax, fig=None, pos=111):
    import matplotlib.pyplot as plt

    if ax is not None:
        return ax.figure, ax
    fig = fig or plt.figure(figsize=(6, 5))
    return fig, fig.add_subplot(pos, projection="3d")


def plot_latent(
    model,
    ax=None,
    path: np.ndarray | None = None,
    title: str | None = None,
    bridges: np.ndarray | None = None,
):
    """A model's training latent points, coloured by time, one line per segment.

    Parameters
    ----------
    model : LatentModel
    ax : 3-D Axes, optional
    path : ndarray, shape (T, q), optional
        A particle's path drawn over the points.
    title : str, optional
    bridges : ndarray, shape (B, q), optional
        Bridge points marked with rings.

    Returns
    -------
    matplotlib Figure
    """
    import matplotlib.pyplot as plt

    fig, ax = _axes3d(ax)
    X = model.X_
    cmap = plt.get_cmap("viridis")
    markers = "o^sDvP*X"
    for s, name in enumerate(model.segment_names_):
        idx = np.flatnonzero(model.segments_ == s)
        t = model.times_[idx] / max(model.times_[idx].max(), 1e-9)
        ax.plot(X[idx, 0], X[idx, 1], X[idx, 2], color="0.7", lw=0.6)
        ax.scatter(
            X[idx, 0],
            X[idx, 1],
            X[idx, 2],
            c=cmap(t),
            s=10,
            marker=markers[s % len(markers)],
            label=name,
            depthshade=False,
        )
    if bridges is not None and len(bridges):
        ax.scatter(
            *np.asarray(bridges)[:, :3].T, s=60, facecolors="none", edgecolors="C3", label="bridges"
        )
    if path is not None:
        ax.plot(path[:, 0], path[:, 1], path[:, 2], color="C1", lw=1.5, label="particle")
        ax.scatter(*path[0, :3], color="C1", s=40, marker=">")
    ax.set_xlabel("x1")
    ax.set_ylabel("x2")
    ax.set_zlabel("x3")
    if len(model.segment_names_) <= 8:
        ax.legend(fontsize=7, loc="upper left")
    ax.set_title(title or f"{X.shape[0]} frames, colour = time in segment", fontsize=9)
    return fig


def plot_bridges(m1, m2, bridges, names: Sequence[str] = ("model 1", "model 2")):
    """Two models side by side with their bridges: matching points share a colour."""
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(10, 4.5))
    cols = plt.get_cmap("turbo")(np.linspace(0, 1, max(len(bridges), 1)))
    for k, (m, pts, name) in enumerate(
        ((m1, bridges.source_points, names[0]), (m2, bridges.target_points, names[1]))
    ):
        ax = fig.add_subplot(1, 2, k + 1, projection="3d")
        ax.scatter(*m.X_[:, :3].T, s=5, color="0.6", depthshade=False)
        if len(bridges):
            ax.scatter(
                *pts[:, :3].T, s=40, c=cols, edgecolors="k", linewidths=0.4, depthshade=False
            )
        ax.set_title(f"{name}: {len(bridges)} bridge points", fontsize=9)
    fig.suptitle(
        f"bridges {names[0]} -> {names[1]} (pose RMS < {bridges.threshold:.2g} units)", fontsize=10
    )
    return fig


def plot_pose_strip(motion, frames: Sequence[int], labels: Sequence[str] | None = None, ax=None):
    """Side-view stick figures of chosen frames, placed left to right (root-centred)."""
    import matplotlib.pyplot as plt

    jp = motion.positions()
    P = jp.positions
    if ax is None:
        fig, ax = plt.subplots(figsize=(1.6 * len(frames) + 1, 3.2))
    else:
        fig = ax.figure
    size = np.ptp(P[:, :, 1])
    gap = 0.7 * size
    for k, f in enumerate(frames):
        p = P[f] - P[f, 0] * np.array([1, 0, 1])
        for i, par in enumerate(jp.parents):
            if par >= 0:
                ax.plot(
                    [p[i, 0] + k * gap, p[par, 0] + k * gap],
                    [p[i, 1], p[par, 1]],
                    color="C0",
                    lw=1.2,
                )
        ax.text(
            k * gap,
            P[:, :, 1].max() + 0.05 * size,
            labels[k] if labels else str(f),
            ha="center",
            fontsize=7,
        )
    ax.set_aspect("equal")
    ax.axis("off")
    return fig


def plot_transition_profile(acc: np.ndarray, p99: float, windows: dict, fps: float, ax=None):
    """Largest joint acceleration per frame over the training 99th percentile, with the
    transition windows of each method shaded."""
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 3))
    else:
        fig = ax.figure
    t = (np.arange(acc.size) + 1) / fps
    ax.plot(t, acc / p99, color="C0", lw=1)
    for k, (name, (a, b)) in enumerate(windows.items()):
        ax.axvspan(a / fps, b / fps, color=f"C{k + 1}", alpha=0.2, label=name)
    ax.axhline(1.0, color="0.5", ls=":", lw=1)
    ax.axhline(1.5, color="C3", ls="--", lw=1, label="1.5 x training p99")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("max joint acc / p99")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig
