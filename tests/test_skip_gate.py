"""The skip gate (tests/_skips.py, tests/conftest.py, .ci/check_skips.py): only a missing
external program or missing shared data may skip a test, and only when it is missing."""

import subprocess
import sys
from pathlib import Path

import pytest

import _skips
from _skips import allowed, data_reason, program_reason

ROOT = Path(__file__).resolve().parents[1]


def test_a_missing_program_may_skip_only_when_it_is_missing(monkeypatch):
    reason = program_reason("ffmpeg")
    assert "apt-get install -y" in reason and "ffmpeg" in reason
    monkeypatch.setattr(_skips.shutil, "which", lambda exe: None)
    assert allowed(reason) and allowed("Skipped: " + reason)
    monkeypatch.setattr(_skips.shutil, "which", lambda exe: f"/usr/bin/{exe}")
    assert not allowed(reason)  # it is installed: the test should have run
    assert not allowed(program_reason("blender").replace("blender", "maya"))  # not ours


def test_missing_data_may_skip_only_when_it_is_missing(tmp_path):
    assert allowed(data_reason(tmp_path / "absent" / "69_01.amc"))
    assert not allowed(data_reason(tmp_path))  # it is there


@pytest.mark.parametrize("reason", [
    "usd-core (the optional 'usd' extra) is not installed",
    "could not import 'pxr': No module named 'pxr'",
    "not written yet",
    "the random walk happened to give a periodic result",
    "",
])
def test_any_other_reason_is_refused(reason):
    assert not allowed(reason)


def _junit(tmp_path, *messages):
    cases = "".join(
        f'<testcase classname="t" name="c{i}"><skipped type="pytest.skip" message="{m}"/></testcase>'
        for i, m in enumerate(messages))
    path = tmp_path / "junit.xml"
    path.write_text(f'<testsuites><testsuite name="pytest">{cases}'
                    f'<testcase classname="t" name="ok"/></testsuite></testsuites>')
    return path


def _check(path):
    return subprocess.run([sys.executable, str(ROOT / ".ci" / "check_skips.py"), str(path)],
                          capture_output=True, text=True)


def test_ci_check_fails_a_run_with_a_skip_it_does_not_accept(tmp_path):
    ok = _check(_junit(tmp_path, data_reason(tmp_path / "absent")))
    assert ok.returncode == 0, ok.stdout + ok.stderr
    assert "1 skipped, 0 for a reason not accepted" in ok.stdout and "absent" in ok.stdout
    bad = _check(_junit(tmp_path, "could not import 'pxr'"))
    assert bad.returncode == 1 and "NOT ACCEPTED" in bad.stdout and "pxr" in bad.stdout


def test_ci_check_fails_a_run_without_tests(tmp_path):
    path = tmp_path / "junit.xml"
    path.write_text('<testsuites><testsuite name="pytest"/></testsuites>')
    run = _check(path)
    assert run.returncode == 1 and "no test ran" in run.stderr
