"""
A whole take: only the steady frames get a phase
================================================

A take as people record it stands, starts, walks, turns, pauses and stops.
``extract`` keeps the steady stretches (``used_frames``) and gives a phase to those
frames only; the period is the median length of the complete windings.
"""

import matplotlib.pyplot as plt
import numpy as np

import cyclecoord as cc

take = cc.datasets.make_whole_take(random_state=0)
result = cc.extract(take.motion)
print("steady frames:", result.used_frames)
print(f"period {result.period_frames:.1f} frames (true {take.period:.1f})")

fig, ax = plt.subplots(figsize=(7, 2.8))
t = np.arange(take.motion.n_frames) / take.motion.fps
ax.plot(t, result.phase, ".", markersize=2, label="phase (steady frames)")
for a, b in result.used_frames:
    ax.axvspan(a / take.motion.fps, b / take.motion.fps, color="C2", alpha=0.12)
ax.set_xlabel("time (s)")
ax.set_ylabel("phase")
ax.legend(loc="upper right")
fig.tight_layout()
plt.show()
