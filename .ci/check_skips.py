"""CI's skip gate over a pytest JUnit XML: print every skip with its reason, and fail when
no test ran or a test skipped for a reason the suite does not accept (tests/_skips.py:
only a missing external program, Blender, Chromium or ffmpeg, or missing shared data, and
then only if it really is missing). tests/conftest.py already fails such a skip; this
checks the run's own record as well, so a bypassed conftest cannot hide one.

    python .ci/check_skips.py junit.xml
"""

import sys
import xml.etree.ElementTree as ET
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from _skips import allowed  # noqa: E402


def main(path: str) -> int:
    root = ET.parse(path).getroot()
    cases = list(root.iter("testcase"))
    skips = [(f"{c.get('classname')}::{c.get('name')}", s.get("message", ""))
             for c in cases for s in c.findall("skipped") if s.get("type") != "pytest.xfail"]
    bad = [(name, why) for name, why in skips if not allowed(why)]
    print(f"skip gate: {len(cases)} tests, {len(skips)} skipped, {len(bad)} for a reason not accepted")
    for name, why in skips:
        print(f"  {'NOT ACCEPTED' if (name, why) in bad else 'accepted'}: {name}: {why}")
    if not cases:
        print("skip gate: no test ran", file=sys.stderr)
        return 1
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
