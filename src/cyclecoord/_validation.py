"""Parameter validation in one place: a table of constraints per function, as
scikit-learn's ``_parameter_constraints``.

A table maps each parameter name to the constraints it may satisfy (any one will do):

* :class:`Options` -- one of a few strings;
* :class:`Interval` -- a real or integral number within bounds (booleans are not numbers);
* ``None`` -- the value None;
* ``"boolean"`` -- True or False (numpy booleans too).

:func:`check_params` checks the values given against a table and raises one
:class:`~cyclecoord.errors.ParameterError` naming the function, the parameter, what it
must be and what it got.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np

from .errors import ParameterError

__all__ = ["Options", "Interval", "check_params", "describe"]


@dataclass(frozen=True)
class Options:
    """One of the given strings."""

    values: tuple[str, ...]

    def __init__(self, *values: str) -> None:
        object.__setattr__(self, "values", tuple(values))

    def accepts(self, value: Any) -> bool:
        return isinstance(value, str) and value in self.values

    def __str__(self) -> str:
        quoted = [repr(v) for v in self.values]
        return "one of " + ", ".join(quoted) if len(quoted) > 2 else " or ".join(quoted)


@dataclass(frozen=True)
class Interval:
    """A number of ``kind`` (``numbers.Real`` or ``numbers.Integral``) between ``low`` and
    ``high`` (None: unbounded); ``closed`` says which ends belong: ``"left"``, ``"right"``,
    ``"both"`` or ``"neither"``.  NaN is never inside."""

    kind: type
    low: float | None
    high: float | None
    closed: str = "both"

    def accepts(self, value: Any) -> bool:
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, self.kind):
            return False
        v = float(value)
        if math.isnan(v):
            return False
        if self.low is not None:
            if v < self.low or (v == self.low and self.closed not in ("left", "both")):
                return False
        if self.high is not None:
            if v > self.high or (v == self.high and self.closed not in ("right", "both")):
                return False
        return True

    def __str__(self) -> str:
        what = "an integer" if self.kind is numbers.Integral else "a number"
        parts = []
        if self.low is not None:
            parts.append((">= " if self.closed in ("left", "both") else "> ") + f"{self.low:g}")
        if self.high is not None:
            parts.append(("<= " if self.closed in ("right", "both") else "< ") + f"{self.high:g}")
        return what + (" " + " and ".join(parts) if parts else "")


def _accepts(constraint: Any, value: Any) -> bool:
    if constraint is None:
        return value is None
    if constraint == "boolean":
        return isinstance(value, (bool, np.bool_))
    return constraint.accepts(value)


def describe(constraints: Sequence[Any]) -> str:
    """The constraints in words: ``"a number > 0 or None"``."""
    words = []
    for c in constraints:
        words.append("None" if c is None else "True or False" if c == "boolean" else str(c))
    return " or ".join(words)


def check_params(
    values: Mapping[str, Any], constraints: Mapping[str, Sequence[Any]], where: str
) -> None:
    """Check ``values`` against a constraint table.

    Parameters
    ----------
    values : mapping of str to object
        Parameter values; names absent from ``constraints`` are not checked.
    constraints : mapping of str to sequence
        For each parameter, the constraints of which it must satisfy one.
    where : str
        The function's name, for the message.

    Raises
    ------
    ParameterError
        ``"extract(): travel must be one of 'keep', 'straight', 'in_place', got 'sideways'"``
        for the first parameter that satisfies none of its constraints.
    """
    for name, allowed in constraints.items():
        if name not in values:
            continue
        value = values[name]
        if not any(_accepts(c, value) for c in allowed):
            raise ParameterError(f"{where}: {name} must be {describe(allowed)}, got {value!r}")
