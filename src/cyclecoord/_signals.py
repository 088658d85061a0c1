"""Ctrl-C held back over short critical stretches, never lost.

Two places need it:

* **Importing a library that swallows Ctrl-C.**  usd-core runs Python code from C++ while
  it post-processes each of its extension modules (``Tf_PyPostProcessModule``); a
  ``KeyboardInterrupt`` raised there is caught, printed as ``Warning: ... Error occurred
  postprocessing module pxr.Vt._vt!`` and cleared, and the import (and the command) goes
  on.  A Ctrl-C in the first second of ``cyclecoord convert x.bvh -o x.usda`` was lost that
  way in 11 of 24 tries (issue 26).
* **Moving a command's outputs into place** (:class:`cyclecoord.io.StagedOutputs`): a
  handful of renames that must happen all or not at all.

:func:`deferred_interrupt` replaces the SIGINT handler for the duration of its block by
one that only records the signal, and raises ``KeyboardInterrupt`` when the block ends
(after restoring the previous handler).  Outside the main thread, where Python delivers
no signals, it does nothing.
"""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager
from typing import Iterator

__all__ = ["deferred_interrupt"]


@contextmanager
def deferred_interrupt() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) back until the block ends, then raise ``KeyboardInterrupt``.

    The interrupt is raised even when the block itself raises (the block's exception
    becomes its context): a Ctrl-C is never swallowed.  When SIGINT is ignored, or a
    handler other than Python's default one is installed, that handler is called in the
    same way once the block ends.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.getsignal(signal.SIGINT)
    if previous in (signal.SIG_IGN, None):
        yield
        return
    received: list[int] = []

    def hold(signum, frame):  # noqa: ARG001 - the signal handler's signature
        received.append(signum)

    signal.signal(signal.SIGINT, hold)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        if received:
            if callable(previous):
                previous(signal.SIGINT, None)  # the default handler raises KeyboardInterrupt
            else:  # SIG_DFL: the process ends as an uncaught SIGINT would end it
                signal.raise_signal(signal.SIGINT)
