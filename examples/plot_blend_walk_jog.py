"""
Blending a walk and a jog
=========================

Two cycles are aligned in phase and blended as rotations.  The left knee's flexion over
one cycle: the walk, the jog and their half-and-half blend between them.
"""

import matplotlib.pyplot as plt
import numpy as np

import cyclecoord as cc
from cyclecoord import datasets

walk = cc.extract(datasets.example_capture().motion)
jog = cc.extract(datasets.make_periodic_capture(kind="jog", n_frames=480, random_state=0).motion)
both = cc.blend([walk, jog], [0.5, 0.5])

fig, ax = plt.subplots(figsize=(6, 3))
for label, m in (("walk", walk.cycle), ("blend 0.5, 0.5", both), ("jog", jog.cycle)):
    k = m.channel_index("ltibia", "rx")
    ax.plot(np.linspace(0, 1, m.n_frames, endpoint=False), m.frames[:, k], label=label)
ax.set_xlabel("phase")
ax.set_ylabel("left knee rx (degrees)")
ax.legend()
fig.tight_layout()
plt.show()
