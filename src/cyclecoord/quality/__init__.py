"""Quality: measures of a motion (jerk, loop closure, distances) and plausibility checks."""
