"""Values of a parsed document (glTF JSON, USD customData, a script) fetched with their
expected type and range.

Each helper takes the value and ``where`` it is (``"accessors[3].count"``) and returns it
converted, or raises :class:`Invalid` whose message names ``where`` and what was wrong;
the reader turns that into its own one-line error naming the file.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ParseError
from ._limits import MAX_MAGNITUDE

__all__ = ["Invalid", "mapping", "number", "numbers", "rotation", "sequence", "text", "whole"]


class Invalid(ValueError):
    """A value of the wrong type or range; ``str()`` is ``"<where>: <what was wrong>"``."""


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def whole(value: Any, where: str, low: int, high: int) -> int:
    """A whole number in ``low..high`` (a float with no fraction counts; a bool does not)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise Invalid(f"{where}: expected a whole number, got {_shown(value)}")
    if isinstance(value, (float, np.floating)):
        if not math.isfinite(value) or value != math.floor(value):
            raise Invalid(f"{where}: expected a whole number, got {_shown(value)}")
        if abs(value) > 2.0**62:
            raise Invalid(f"{where}: {value!r} is not in {low:,}..{high:,}")
        value = int(value)
    value = int(value)
    if not low <= value <= high:
        raise Invalid(f"{where}: {value:,} is not in {low:,}..{high:,}")
    return value


def number(
    value: Any, where: str, low: float = -MAX_MAGNITUDE, high: float = MAX_MAGNITUDE
) -> float:
    """A finite number in ``low..high``."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise Invalid(f"{where}: expected a number, got {_shown(value)}")
    try:
        v = float(value)
    except OverflowError:
        raise Invalid(f"{where}: {value} is not in {low:g}..{high:g}") from None
    if not math.isfinite(v):
        raise Invalid(f"{where}: expected a finite number, got {v}")
    if not low <= v <= high:
        raise Invalid(f"{where}: {v!r} is not in {low:g}..{high:g}")
    return v


def numbers(value: Any, shape: tuple[int, ...], where: str, allow_inf: bool = False
            ) -> np.ndarray:
    """An array of ``shape`` of finite numbers of at most :data:`MAX_MAGNITUDE` (infinite
    ones too with ``allow_inf``) from nested lists."""
    size = int(np.prod(shape))
    if not _nested_shape(value, shape):
        raise Invalid(f"{where}: expected {'x'.join(map(str, shape))} numbers, got {_shown(value)}")
    flat = list(value)
    while flat and isinstance(flat[0], (list, tuple)):  # as deep as the shape, no deeper
        flat = [v for row in flat for v in row]
    out = np.empty(size)
    for k, v in enumerate(flat):
        if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
            raise Invalid(f"{where}: expected numbers, got {_shown(v)}")
        try:
            out[k] = float(v)
        except OverflowError:
            raise Invalid(f"{where}: {_shown(v)} is beyond {MAX_MAGNITUDE:g}") from None
        if math.isnan(out[k]) or (math.isinf(out[k]) and not allow_inf) or (
            math.isfinite(out[k]) and abs(out[k]) > MAX_MAGNITUDE
        ):
            raise Invalid(
                f"{where}: {_shown(v)} is not a finite number of at most {MAX_MAGNITUDE:g} in "
                "magnitude"
            )
    return out.reshape(shape)


def _nested_shape(value: Any, shape: tuple[int, ...]) -> bool:
    """Whether nested lists have exactly ``shape`` (a flat list of the size counts too)."""
    if not isinstance(value, (list, tuple)):
        return False
    if len(value) == int(np.prod(shape)) and all(not isinstance(v, (list, tuple)) for v in value):
        return True
    if len(value) != shape[0]:
        return False
    if len(shape) == 1:
        return all(not isinstance(v, (list, tuple)) for v in value)
    return all(_nested_shape(v, shape[1:]) and len(v) == shape[1] for v in value)


def rotation(matrix: np.ndarray, where: str, tol: float = 1e-4) -> np.ndarray:
    """A 3x3 rotation (orthonormal, determinant +1 within ``tol``)."""
    m = np.asarray(matrix, dtype=float).reshape(3, 3)
    if not np.all(np.isfinite(m)) or np.max(np.abs(m @ m.T - np.eye(3))) > tol or (
        np.linalg.det(m) <= 0
    ):
        raise Invalid(f"{where}: not a rotation matrix (orthonormal, determinant +1)")
    return m


def text(value: Any, where: str, max_length: int = 100_000) -> str:
    """A string of at most ``max_length`` characters."""
    if not isinstance(value, str):
        raise Invalid(f"{where}: expected a string, got {_shown(value)}")
    if len(value) > max_length:
        raise Invalid(f"{where}: {len(value):,} characters; at most {max_length:,} are supported")
    return value


def mapping(value: Any, where: str) -> dict:
    """A dict (a JSON object)."""
    if not isinstance(value, dict):
        raise Invalid(f"{where}: expected an object, got {_shown(value)}")
    return value


def sequence(value: Any, where: str, max_length: int) -> list:
    """A list (a JSON array) of at most ``max_length`` items."""
    if not isinstance(value, (list, tuple)):
        raise Invalid(f"{where}: expected a list, got {_shown(value)}")
    if len(value) > max_length:
        raise Invalid(f"{where}: {len(value):,} items; at most {max_length:,} are supported")
    return list(value)


class NpzArrays:
    """The arrays of an NPZ motion, each fetched with its expected kind and shape.

    Every failure is a :class:`ParseError` naming the file and the key.
    """

    def __init__(self, data: dict[str, np.ndarray], spath: str, prefix: str = "") -> None:
        self.data = data
        self.spath = spath
        self.prefix = prefix  # how the archive names the keys ("motion_" in a latent model)

    def error(self, key: str, message: str) -> ParseError:
        return ParseError(f"array {self.prefix + key!r}: {message}", self.spath)

    def get(self, key: str) -> np.ndarray:
        if key not in self.data:
            raise ParseError(f"missing array {self.prefix + key!r}", self.spath)
        return self.data[key]

    def _one(self, key: str, kinds: str, what: str):
        a = self.get(key)
        if a.size != 1 or a.ndim > 1:
            raise self.error(key, f"expected a single {what}, got shape {a.shape}")
        if a.dtype.kind not in kinds:
            raise self.error(key, f"expected a single {what}, got dtype {a.dtype}")
        return a.reshape(()).item()

    def real(self, key: str) -> float:
        value = float(self._one(key, "iuf", "number"))
        if not np.isfinite(value) or abs(value) > MAX_MAGNITUDE:
            raise self.error(key, f"expected a finite number, got {value!r}")
        return value

    def integer(self, key: str, low: int, high: int) -> int:
        value = self._one(key, "iuf", "whole number")
        if isinstance(value, float) and not (np.isfinite(value) and value == int(value)):
            raise self.error(key, f"expected a whole number, got {value!r}")
        value = int(value)
        if not low <= value <= high:
            raise self.error(key, f"expected a whole number in {low:,}..{high:,}, got {value:,}")
        return value

    def flag(self, key: str) -> bool:
        return bool(self._one(key, "b", "boolean (True or False)"))

    def text(self, key: str) -> str:
        return str(self._one(key, "U", "string"))

    def strings(self, key: str, n: int | None = None, per: str = "") -> list[str]:
        a = self.get(key)
        if a.ndim != 1 or (a.size and a.dtype.kind != "U"):
            raise self.error(key, f"expected a 1-D array of strings, got {a.dtype} {a.shape}")
        if n is not None and a.shape[0] != n:
            raise self.error(key, f"expected {n} strings{per}, got {a.shape[0]}")
        return [str(v) for v in a]

    def reals(self, key: str, shape: tuple[int, ...], allow_nan: bool = False,
              allow_inf: bool = False) -> np.ndarray:
        a = self.get(key)
        if a.dtype.kind not in "iuf":
            raise self.error(key, f"expected real numbers, got dtype {a.dtype}")
        if a.shape != shape:
            raise self.error(key, f"expected shape {shape}, got {a.shape}")
        out = a.astype(float)
        with np.errstate(invalid="ignore"):
            bad = np.abs(out) > MAX_MAGNITUDE
            if not allow_inf:
                bad |= np.isinf(out)
            else:
                bad &= np.isfinite(out)
        if not allow_nan:
            bad |= np.isnan(out)
        if bad.any():
            at = tuple(int(v) for v in np.argwhere(bad)[0])
            raise self.error(
                key, f"entry {at} is {out[at]!r}; expected a finite number of at most "
                f"{MAX_MAGNITUDE:g} in magnitude"
            )
        return out

    def integers(self, key: str, n: int, low: int, high: int) -> list[int]:
        a = self.get(key)
        if a.dtype.kind not in "iu" and not (a.dtype.kind == "f" and a.size == 0):
            raise self.error(key, f"expected whole numbers, got dtype {a.dtype}")
        if a.shape != (n,):
            raise self.error(key, f"expected shape ({n},), got {a.shape}")
        out = [int(v) for v in a]
        for k, v in enumerate(out):
            if not low <= v <= high:
                raise self.error(key, f"entry {k} is {v}; expected {low}..{high}")
        return out
