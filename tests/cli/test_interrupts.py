"""Ctrl-C is never swallowed, whatever library is loading, and an interrupted run leaves
every existing output as it was (issue 26, "Interrupted runs")."""

import signal
import sys
import threading
import time

import pytest

import cyclecoord as cc
from cyclecoord._signals import deferred_interrupt
from cyclecoord.cli import main


@pytest.fixture
def sigint_raises():
    """Python's own SIGINT handler (a shell's background job starts with SIGINT ignored)."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


@pytest.fixture(scope="module")
def walk_bvh(tmp_path_factory):
    p = tmp_path_factory.mktemp("walk") / "walk.bvh"
    cc.save(cc.datasets.example_capture().motion[:150], p)
    return p


def test_deferred_interrupt_raises_at_the_end_of_the_block(sigint_raises):
    done = []
    with pytest.raises(KeyboardInterrupt):
        with deferred_interrupt():
            signal.raise_signal(signal.SIGINT)
            done.append("the block went on")
    assert done == ["the block went on"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    with deferred_interrupt():  # no Ctrl-C: nothing raised
        pass


def test_deferred_interrupt_wins_over_the_blocks_own_error(sigint_raises):
    with pytest.raises(KeyboardInterrupt) as info:
        with deferred_interrupt():
            signal.raise_signal(signal.SIGINT)
            raise ImportError("the library failed to load")
    assert isinstance(info.value.__context__, ImportError)


def test_deferred_interrupt_outside_the_main_thread_does_nothing(sigint_raises):
    seen = []

    def body():
        with deferred_interrupt():
            seen.append(signal.getsignal(signal.SIGINT))

    t = threading.Thread(target=body)
    t.start()
    t.join()
    assert seen == [signal.default_int_handler]


def _fake_usd_core(folder, swallow: bool):
    """A ``pxr`` package whose import is hit by Ctrl-C and, like usd-core's C++
    ``Tf_PyPostProcessModule``, catches the KeyboardInterrupt, prints a warning and goes on
    (here: on to a failure to load, so a swallowed Ctrl-C shows as exit 1)."""
    pkg = folder / "pxr"
    pkg.mkdir()
    body = (
        "import signal, sys\n"
        "try:\n"
        "    signal.raise_signal(signal.SIGINT)\n"
        "    sum(range(1000))\n"
        "except KeyboardInterrupt:\n"
        "    sys.stderr.write('Warning: Error occurred postprocessing module pxr.Vt._vt!\\n')\n"
        "raise ImportError('fake usd-core: failed to load')\n"
    ) if swallow else "raise KeyboardInterrupt\n"
    (pkg / "__init__.py").write_text(body)


@pytest.mark.parametrize("swallow", [True, False], ids=["usd-core-swallows", "import-raises"])
def test_ctrl_c_while_usd_core_loads_exits_130(walk_bvh, tmp_path, monkeypatch, capsys,
                                               sigint_raises, swallow):
    _fake_usd_core(tmp_path, swallow)
    for name in [m for m in sys.modules if m == "pxr" or m.startswith("pxr.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.syspath_prepend(str(tmp_path))
    out = tmp_path / "walk.usda"
    code = main(["convert", str(walk_bvh), "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 130, err
    assert "interrupted" in err and "usd-core package" not in err
    assert not out.exists()


def _as_at_a_terminal():
    """Ctrl-C's default action, as in a terminal.  A job started in the background of a
    non-interactive shell (``.ci/run &``, ``nohup``) inherits SIGINT *ignored*, and
    Python then installs no handler: every Ctrl-C would be ignored as POSIX asks, which is
    what made this test fail in CI (exit 0, nothing on stderr), not a swallowed Ctrl-C."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_ctrl_c_while_usd_core_loads_in_a_real_process(walk_bvh, tmp_path):
    """The issue's run: Ctrl-C at random times in the first 60 % of a .usda convert
    (usd-core loading, the stage written): every run still going exits 130 with the one
    line "cyclecoord: interrupted", none with usd-core's warning that it caught the
    interrupt, and none with a traceback."""
    import os
    import random
    import subprocess

    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    code = ("import sys, time\nfrom cyclecoord.cli import main\nprint('ready', flush=True)\n"
            "rc = main(sys.argv[1:])\nprint('returned', time.time(), flush=True)\nsys.exit(rc)")
    rng = random.Random(26)
    argv = [sys.executable, "-c", code, "convert", str(walk_bvh), "-o"]

    def start(out):
        p = subprocess.Popen(argv + [str(out)], env=env, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, preexec_fn=_as_at_a_terminal)
        assert p.stdout.readline().strip() == "ready"
        return p, time.time()

    wholes = []
    for i in range(2):  # the second run is the measure (the first may warm caches)
        p, ready = start(tmp_path / f"whole{i}.usda")
        stdout, _ = p.communicate(timeout=120)
        done = [float(ln.split()[1]) for ln in stdout.splitlines() if ln.startswith("returned")]
        wholes.append(done[0] - ready)  # a run without Ctrl-C: ready to returned
    whole = wholes[-1]
    interrupted = 0
    for i in range(6):
        out = tmp_path / f"o{i}.usda"
        p, _ = start(out)
        time.sleep(rng.uniform(0.0, 0.6 * whole))
        sent = time.time()
        p.send_signal(signal.SIGINT)
        stdout, stderr = p.communicate(timeout=120)
        returned = [float(ln.split()[1]) for ln in stdout.splitlines() if ln.startswith("returned")]
        if p.returncode == 0 or (p.returncode == -signal.SIGINT and returned):
            # only a run whose main had returned before the signal was sent (one sent as
            # the interpreter shuts down ends it by the signal)
            assert returned and returned[0] < sent + 0.01, ("Ctrl-C lost", sent, returned)
            continue
        interrupted += 1
        assert p.returncode == 130, (p.returncode, stderr)
        assert stderr.strip().splitlines() == ["cyclecoord: interrupted"], stderr
        assert not out.exists()
    assert interrupted >= 3, wholes  # signals within the first 60 % of a run: most are hit


def test_ctrl_c_while_the_parser_is_built_is_one_line(monkeypatch, capsys):
    """main builds its parser (importing every command) before anything runs: a Ctrl-C
    there is the same one line and exit 130, not a traceback from argparse or an import."""
    def ctrl_c():
        raise KeyboardInterrupt

    monkeypatch.setattr(sys.modules["cyclecoord.cli.main"], "build_parser", ctrl_c)
    assert main(["convert", "x.bvh", "-o", "y.npz"]) == 130
    assert capsys.readouterr().err == "cyclecoord: interrupted\n"


def test_ctrl_c_while_the_paths_are_checked_is_one_line(monkeypatch, capsys):
    """Between parsing and the command main checks that no output names an input: a
    Ctrl-C there (CI's real-process run once caught one, inside pathlib) is the same one
    line and exit 130, not a traceback."""
    def ctrl_c(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(sys.modules["cyclecoord.cli.main"], "check_paths", ctrl_c)
    assert main(["convert", "x.bvh", "-o", "y.npz"]) == 130
    assert capsys.readouterr().err == "cyclecoord: interrupted\n"


@pytest.fixture(scope="module")
def walk300(tmp_path_factory):
    p = tmp_path_factory.mktemp("walk300") / "walk.bvh"
    cc.save(cc.datasets.example_capture().motion[:300], p)
    return p


def _listing(folder):
    return {p.relative_to(folder).as_posix(): p.read_bytes() if p.is_file() else None
            for p in folder.rglob("*")}


def test_extract_interrupted_after_the_cycle_changes_no_output(walk300, tmp_path, monkeypatch,
                                                                capsys):
    """The issue's run: `extract --plot DIR -o OUT.bvh` stopped by Ctrl-C after the cycle was
    written, while drawing the figures: OUT.bvh, the report and the model stay as they
    were, and neither the figure folder (barcode.png was drawn) nor a staging folder is
    left."""
    out, report, model = tmp_path / "OUT.bvh", tmp_path / "r.json", tmp_path / "m.npz"
    for p in (out, report, model):
        p.write_text(f"the existing {p.name}\n")
    before = _listing(tmp_path)

    def ctrl_c(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr("cyclecoord.plot.figures.plot_pca", ctrl_c)  # after barcode.png
    code = main(["extract", str(walk300), "-o", str(out), "--plot", str(tmp_path / "figs"),
                 "--report", str(report), "--save-model", str(model)])
    captured = capsys.readouterr()
    assert code == 130 and "interrupted" in captured.err
    assert "wrote" not in captured.out  # nothing was moved into place, nothing is claimed
    assert _listing(tmp_path) == before


def test_extract_writes_every_output_at_the_end(walk300, tmp_path, capsys):
    out, figs = tmp_path / "OUT.bvh", tmp_path / "new" / "figs"
    out.write_text("the existing OUT.bvh\n")
    code = main(["extract", str(walk300), "-o", str(out), "--plot", str(figs)])
    printed = capsys.readouterr().out
    assert code == 0 and cc.load(out).n_frames > 10
    assert sorted(p.name for p in figs.iterdir()) == sorted(
        ["barcode.png", "pca.png", "density.png", "coordinate.png", "channels.png"])
    assert f"wrote {out}" in printed and f"wrote {figs / 'pca.png'}" in printed
    assert sorted(p.name for p in tmp_path.rglob("*")) == sorted(
        ["OUT.bvh", "new", "figs", "barcode.png", "pca.png", "density.png", "coordinate.png",
         "channels.png"])  # no staging folder left


def test_feet_interrupted_before_the_report_keeps_the_motion(walk300, tmp_path, monkeypatch,
                                                              capsys):
    out, report = tmp_path / "locked.bvh", tmp_path / "feet.json"
    out.write_text("the existing locked.bvh\n")
    before = _listing(tmp_path)

    def ctrl_c(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr("cyclecoord.cli.report.write_json", ctrl_c)
    code = main(["feet", str(walk300), "-o", str(out), "--report", str(report)])
    assert code == 130, capsys.readouterr().err
    assert _listing(tmp_path) == before


def _reimport_cli_main(monkeypatch):
    """Make the next import of cyclecoord.cli.main run again. Importing a submodule binds
    it as its package's attribute, which here shadows the ``main`` function that
    ``cyclecoord.cli`` exports: both are put back when the test ends."""
    import cyclecoord.cli as package

    monkeypatch.delitem(sys.modules, "cyclecoord.cli.main")
    monkeypatch.setattr(package, "main", package.main)


def test_ctrl_c_while_the_console_script_loads_the_commands_is_one_line(monkeypatch, capsys):
    """The console script's entry point imports the command line (numpy, scipy, every
    reader: about a second) inside its own guard: a Ctrl-C there is the one line and exit
    130, not Python's KeyboardInterrupt traceback."""
    import importlib.abc

    from cyclecoord._console import main as console

    class CtrlC(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name == "cyclecoord.cli.main":
                raise KeyboardInterrupt
            return None

    _reimport_cli_main(monkeypatch)
    monkeypatch.setattr(sys, "meta_path", [CtrlC(), *sys.meta_path])
    assert console() == 130
    assert capsys.readouterr().err == "cyclecoord: interrupted\n"


def test_a_real_ctrl_c_while_the_console_script_loads_is_held_to_the_end(
        monkeypatch, capsys, sigint_raises):
    """A SIGINT that arrives in the middle of the imports (numpy turned one into an
    ImportError) is held until they end, then reported as the one line."""
    import importlib.abc
    import signal

    from cyclecoord._console import main as console

    seen = []

    class CtrlC(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name == "cyclecoord.cli.main" and not seen:
                seen.append(name)
                signal.raise_signal(signal.SIGINT)  # delivered now, the import goes on
            return None

    _reimport_cli_main(monkeypatch)
    monkeypatch.setattr(sys, "meta_path", [CtrlC(), *sys.meta_path])
    assert console() == 130
    assert seen and "cyclecoord.cli.main" in sys.modules  # the import itself completed
    assert capsys.readouterr().err == "cyclecoord: interrupted\n"


def test_the_console_script_runs_the_command_line(monkeypatch, capsys):
    from cyclecoord._console import main as console

    monkeypatch.setattr(sys, "argv", ["cyclecoord", "--version"])
    with pytest.raises(SystemExit) as exc:  # argparse's --version exits itself
        console()
    assert exc.value.code == 0 and capsys.readouterr().out.startswith("cyclecoord ")
