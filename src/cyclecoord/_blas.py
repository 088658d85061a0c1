"""One BLAS thread for the pipeline's many small linear-algebra calls.

The pipeline makes thousands of small BLAS calls (matrix-vector products in LSQR, one
distance row per greedy landmark, EM steps of a small mixture).  A multi-threaded BLAS
wakes its threads for each of them; on a machine whose cores are busy the threads wait
for each other and those calls run several times slower than on one thread (measured on
2 cores under load 2: 69_01's coordinate stage 0.29 s against 0.055 s, a 16,000-frame
extract 10.1 s against 4.2 s).  The limit is set only while a decorated call runs and
restored afterwards.  A decorated call made inside another one (``detect`` fitting a
hundred coordinates) runs under the outer limit without setting it again: each set-up
costs a few milliseconds of ``threadpoolctl`` introspection.
"""

from __future__ import annotations

from contextvars import ContextVar
from functools import wraps
from typing import Callable, TypeVar

F = TypeVar("F", bound=Callable)

__all__ = ["one_blas_thread"]

# True while a decorated call runs in this thread/context (restored on exit)
_LIMITED: ContextVar[bool] = ContextVar("cyclecoord_one_blas_thread", default=False)


def one_blas_thread(func: F) -> F:
    """Run ``func`` with BLAS limited to one thread (threadpoolctl; about 2 ms a call,
    nothing when an enclosing call already holds the limit)."""

    @wraps(func)
    def wrapper(*args, **kwargs):
        if _LIMITED.get():
            return func(*args, **kwargs)
        from threadpoolctl import threadpool_limits

        token = _LIMITED.set(True)
        try:
            with threadpool_limits(limits=1, user_api="blas"):
                return func(*args, **kwargs)
        finally:
            _LIMITED.reset(token)

    return wrapper  # type: ignore[return-value]
