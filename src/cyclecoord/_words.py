"""Numbers and counts in words a person reads at a glance (console lines)."""

from __future__ import annotations

import math

__all__ = ["plural", "si"]

_PREFIXES = {-12: "p", -9: "n", -6: "µ", -3: "m", 0: "", 3: "k", 6: "M", 9: "G", 12: "T", 15: "P"}


def plural(n: float, word: str, many: str | None = None) -> str:
    """``"1 segment"``, ``"2 segments"``, ``"1.50 cycles"`` (``many`` for irregular plurals).

    >>> plural(1, "segment"), plural(3, "segment"), plural(0, "bridge")
    ('1 segment', '3 segments', '0 bridges')
    """
    count = f"{n:g}" if isinstance(n, int) or float(n).is_integer() else f"{n:.2f}"
    return f"{count} {word if n == 1 else (many or word + 's')}"


def si(value: float, unit: str, digits: int = 3) -> str:
    """``value`` with an SI prefix on ``unit``: ``si(4.453e7, "deg/s³")`` is
    ``"44.5 Mdeg/s³"`` (three significant digits), never ``"4.453e+07"``.

    >>> si(4.453e7, "deg/s³"), si(0.0123, "m"), si(950, "deg/s³"), si(0, "m")
    ('44.5 Mdeg/s³', '12.3 mm', '950 deg/s³', '0 m')
    """
    if value is None or not math.isfinite(value):
        return f"{value} {unit}"
    if value == 0:
        return f"0 {unit}"
    exp = int(math.floor(math.log10(abs(value)) / 3) * 3)
    exp = max(min(exp, 15), -12)
    mantissa = value / 10**exp
    shown = round(abs(mantissa), max(0, digits - 1 - int(math.floor(math.log10(abs(mantissa))))))
    if shown >= 1000 and exp < 15:
        exp += 3
        mantissa = value / 10**exp
    return f"{mantissa:.{digits}g} {_PREFIXES[exp]}{unit}"
