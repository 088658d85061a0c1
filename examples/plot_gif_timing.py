"""
GIF frame delays that keep the motion's rate
============================================

A GIF stores each frame's delay in whole centiseconds, so 30 frames per second cannot
be one delay: 3 cs plays 10 % fast.  :func:`cyclecoord.plot.animation.gif_delays`
alternates 3 and 4 cs so that every frame starts within half a centisecond of its time,
which is what :func:`cyclecoord.plot.render` writes.
"""

import matplotlib.pyplot as plt
import numpy as np

from cyclecoord.plot.animation import gif_delays

n, fps = 63, 30
delays = gif_delays(n, fps)
starts = np.cumsum([0] + delays[:-1])
print(f"{n} frames: {sum(delays)} ms (exact: {1000 * n / fps:.0f} ms)")

fig, ax = plt.subplots(figsize=(6, 3))
k = np.arange(n)
ax.plot(k, starts - k * 1000 / fps, "o-", markersize=3, label="alternating 3 and 4 cs")
ax.plot(k, k * 30 - k * 1000 / fps, "--", label="3 cs every frame")
ax.set_xlabel("frame")
ax.set_ylabel("start time error (ms)")
ax.legend()
fig.tight_layout()
plt.show()
