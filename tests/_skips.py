"""The only reasons a test may skip, and the check that holds the suite to them.

A fresh ``pip install -e ".[test]"`` brings every Python package a test needs, so a test
may skip for two reasons only, each worded here:

* an external program is missing (Blender, Chromium, ffmpeg): :func:`need_program`, whose
  reason names the install line;
* the real captures beside the checkout (``../shared/data``) are missing:
  :func:`need_data`, whose reason names the missing path.

``tests/conftest.py`` turns any other skip into a failure, and so does a skip with one of
these reasons when what it names is there after all (a Chromium skip with Chromium on the
PATH, a data skip whose path exists): :func:`allowed`. ``.ci/check_skips.py`` applies the
same rule to the JUnit XML of a CI run.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

INSTALL = "apt-get install -y blender python3-numpy chromium ffmpeg"
SHARED = Path(__file__).resolve().parents[1].parent / "shared" / "data"

# program -> the names it is installed under
PROGRAMS = {"blender": ("blender",), "chromium": ("chromium", "chromium-browser"),
            "ffmpeg": ("ffmpeg",)}

_PROGRAM = re.compile(r"(\w+) is not installed \(apt-get install -y ")
_DATA = re.compile(r"shared data not found: (.+?) \(\.\./shared/data beside the checkout\)")


def program(name: str) -> str | None:
    """The program's path on the PATH, or None."""
    for exe in PROGRAMS[name]:
        found = shutil.which(exe)
        if found:
            return found
    return None


def program_reason(name: str) -> str:
    return f"{name} is not installed ({INSTALL})"


def need_program(name: str) -> str:
    """The program's path; skips, naming the install line, when it is not installed."""
    __tracebackhide__ = True  # the skip is reported at the test's line
    found = program(name)
    if found is None:
        pytest.skip(program_reason(name))
    return found


def needs_program(name: str) -> pytest.MarkDecorator:
    """``need_program`` as a mark, for a whole module or test."""
    return pytest.mark.skipif(program(name) is None, reason=program_reason(name))


def data_reason(path: Path) -> str:
    return f"shared data not found: {path} (../shared/data beside the checkout)"


def need_data(*paths: Path) -> Path:
    """The first path; skips, naming the first missing one, when any is missing."""
    __tracebackhide__ = True
    for p in paths:
        if not Path(p).exists():
            pytest.skip(data_reason(p))
    return paths[0]


def allowed(reason: str) -> bool:
    """Whether a skip with this reason is one the suite accepts here and now."""
    reason = reason.removeprefix("Skipped: ")
    m = _PROGRAM.match(reason)
    if m and m.group(1) in PROGRAMS:
        return program(m.group(1)) is None
    m = _DATA.match(reason)
    if m:
        return not Path(m.group(1)).exists()
    return False


def skip_reason(longrepr) -> str:
    """The reason of a skipped report (pytest keeps ``(path, line, "Skipped: why")``)."""
    if isinstance(longrepr, tuple) and len(longrepr) == 3:
        return str(longrepr[2]).removeprefix("Skipped: ")
    return str(longrepr)
