"""The ``cyclecoord`` console script: a Ctrl-C while the commands load is one line too.

The script's entry point must import nothing heavy itself: the command line
(:mod:`cyclecoord.cli.main`) imports numpy, scipy and every reader, about a second on a
busy machine, and a Ctrl-C in that second used to end in Python's KeyboardInterrupt
traceback, or worse: numpy turns a Ctrl-C inside its C extensions' import into an
ImportError ("Importing the numpy C-extensions failed").  Here the import runs with
Ctrl-C held back (:func:`cyclecoord._signals.deferred_interrupt`) and a Ctrl-C is the
same ``cyclecoord: interrupted`` line and exit 130 as anywhere later.  (Python's own
start-up, before this module runs, is not covered: about a tenth of a second.)
"""

from __future__ import annotations

import sys


def main() -> int:
    """Load the command line and run it on ``sys.argv``; exit 130 on a Ctrl-C."""
    try:
        from ._signals import deferred_interrupt

        with deferred_interrupt():
            from .cli.main import main as run
    except KeyboardInterrupt:
        print("cyclecoord: interrupted", file=sys.stderr)
        return 130
    return run()
