"""How well can any average cycle cover a short take, against a loop cut?

Issue 12 asks that our cycle's coverage (mean distance from every used frame to the
cycle's closed polyline, :func:`cyclecoord.quality.cycle_quality.coverage`) be no worse
than the best loop cut's.  The loop cut is one repetition of the take, so it covers its
own frames at distance 0.  This script measures, on simulated takes whose truth is known,
the loop cut's coverage over an ideal average's (the mean of the repetitions at each
phase, smoothed by the same one-frame Gaussian as ``extract``'s default), for takes of
``n`` repetitions that differ by

* **smooth deviations**: each repetition is the cycle plus its own slowly varying offset
  per channel (a different stride, arm swing, posture);
* **frame noise**: each frame is the cycle plus independent noise (marker jitter).

Below 1, the loop cut covers the take better than the average can.  No extraction runs:
the average is built from the true phases, so this is a bound on what any phase or
averaging method can reach, not a measure of ours.

Usage::

    python benchmarks/sim_coverage.py [--takes 20] [--seed 0]
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence

import numpy as np
from scipy.ndimage import gaussian_filter1d

from cyclecoord.quality.metrics import distance_to_cycle

P = 100  # frames per repetition
D = 56  # joint channels, as in a CMU capture
REPETITIONS = (2, 2.5, 3, 4, 6)


def base_cycle() -> np.ndarray:
    """A smooth closed cycle in ``D`` channels, amplitudes 10-30 degrees."""
    t = np.arange(P) / P
    return np.stack(
        [(10 + 10 * (k % 3)) * np.sin(2 * np.pi * (t + k / D)) for k in range(D)], axis=1
    )


def simulate(n: float, model: str, rng: np.random.Generator) -> float:
    """One take of ``n`` repetitions (a fraction: a partial last one): cut over average."""
    base = base_cycle()
    full = int(np.ceil(n))
    reps = []
    for _ in range(full):
        if model == "smooth":
            # a per-repetition offset that varies slowly over the cycle (two harmonics)
            t = np.arange(P)[:, None] / P
            c0, c1, c2 = rng.normal(0, 2.0, (3, D))
            dev = c0 + c1 * np.sin(2 * np.pi * t) + c2 * np.cos(2 * np.pi * t)
        else:
            dev = rng.normal(0, 1.0, (P, D))
        reps.append(base + dev)
    frames = np.concatenate(reps)[: int(round(n * P))]
    phase = np.arange(frames.shape[0]) % P
    # the ideal average: the frames' mean at each true phase, one-frame Gaussian
    total = np.zeros((P, D))
    count = np.zeros(P)
    np.add.at(total, phase, frames)
    np.add.at(count, phase, 1.0)
    avg = gaussian_filter1d(total / count[:, None], 1.0, axis=0, mode="wrap")
    # a loop cut is one whole repetition (the bench's is chosen by its seam, which says
    # nothing of coverage: here any one of the complete repetitions)
    cut = reps[int(rng.integers(int(np.floor(n))))]
    return float(distance_to_cycle(frames, cut).mean() / distance_to_cycle(frames, avg).mean())


def ratios(takes: int = 20, seed: int = 0) -> dict[tuple[float, str], list[float]]:
    """``{(repetitions, model): [cut over average per take]}`` for every cell."""
    rng = np.random.default_rng(seed)
    return {
        (n, model): [simulate(n, model, rng) for _ in range(takes)]
        for n in REPETITIONS
        for model in ("smooth", "noise")
    }


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--takes", type=int, default=20, help="simulated takes per cell (20)")
    ap.add_argument("--seed", type=int, default=0, help="random seed (0)")
    args = ap.parse_args(argv)
    if args.takes < 1:
        ap.error("--takes must be at least 1")
    c0, w0 = time.process_time(), time.perf_counter()
    print(f"loop cut's coverage over an ideal average's ({args.takes} takes each, "
          f"{D} channels, {P} frames per repetition; below 1 the cut covers better)")
    print(f"{'repetitions':>12}  {'smooth deviations':>18}  {'frame noise':>12}")
    table = ratios(args.takes, args.seed)
    for n in REPETITIONS:
        cells = []
        for model in ("smooth", "noise"):
            r = table[(n, model)]
            cells.append(f"{np.mean(r):.3f} ({np.min(r):.2f}-{np.max(r):.2f})")
        print(f"{n:>12}  {cells[0]:>18}  {cells[1]:>12}")
    print(f"{time.perf_counter() - w0:.1f} s wall, {time.process_time() - c0:.1f} s CPU")
    return 0


if __name__ == "__main__":
    sys.exit(main())
