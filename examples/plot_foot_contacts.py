"""
Foot contacts of a cycle, before and after locking
==================================================

:func:`cyclecoord.quality.contacts.foot_contacts` marks each foot point as planted
when it is near its contact level and moving slowly.  Planted points of an averaged
cycle still slide a little; :func:`cyclecoord.synthesis.footlock.lock_feet` pins them.
"""

import matplotlib.pyplot as plt
import numpy as np

import cyclecoord as cc
from cyclecoord.quality.contacts import foot_contacts, foot_skating
from cyclecoord.synthesis.footlock import lock_feet

cycle = cc.extract(cc.datasets.example_capture().motion).cycle
contacts = foot_contacts(cycle)
locked = lock_feet(cycle).motion
print("skating frames:", foot_skating(cycle, contacts).skating_frames,
      "->", foot_skating(locked).skating_frames)

fig, ax = plt.subplots(figsize=(7, 2.4))
ax.imshow(contacts.planted.T, aspect="auto", interpolation="nearest", cmap="Greens")
ax.set_yticks(np.arange(len(contacts.feet)), contacts.feet)
ax.set_xlabel("cycle frame")
ax.set_title("planted (green) per foot point")
fig.tight_layout()
plt.show()
