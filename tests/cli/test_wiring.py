"""Every command line option reaches the library call that uses it.

Each test runs ``cyclecoord ...`` with the option and catches the library function the
option is for (a spy in its place: it records the call and stops the run, or passes it on)
and checks the keyword or the data it received, against a run without the option.  The
registry of which test covers which option is ``tests/cli/wired_options.py``; the meta-test
``test_every_option_is_wired.py`` holds every parser's options to it.
"""

from __future__ import annotations

import importlib
import inspect
import json
from types import SimpleNamespace

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.cli import main


class Reached(Exception):
    """A spy stopped the run where the option should have arrived."""


class Spy:
    """Put in place of ``target`` (a dotted path: a function, a class or a method): records
    each call's positional and keyword arguments; raises :class:`Reached` (``stop``) or
    calls the original."""

    def __init__(self, monkeypatch, target: str, stop: bool = True, fake=None):
        module, _, name = target.rpartition(".")
        try:
            owner = importlib.import_module(module)
        except ImportError:  # a method: module.Class.name
            mod, _, cls = module.rpartition(".")
            owner = getattr(importlib.import_module(mod), cls)
            owner = getattr(owner, "original", owner)  # the class behind a spy on it
        self.original = getattr(owner, name)
        self.calls: list[tuple[tuple, dict]] = []
        self.stop = stop
        self.fake = fake  # called instead of the original, when given
        if inspect.isclass(owner):  # a method: keep it one, so `self` arrives
            def method(obj, *args, **kwargs):
                return self(obj, *args, **kwargs)

            monkeypatch.setattr(owner, name, method)
        else:
            monkeypatch.setattr(owner, name, self)

    def __call__(self, *args, **kwargs):
        self.calls.append((args, kwargs))
        if self.stop:
            raise Reached
        return (self.fake or self.original)(*args, **kwargs)

    @property
    def args(self) -> tuple:
        assert self.calls, "the spied call was never made"
        return self.calls[-1][0]

    @property
    def kwargs(self) -> dict:
        assert self.calls, "the spied call was never made"
        return self.calls[-1][1]


def _id(value):
    """Test ids: an option's argv as typed (``--pca 3``); pytest's own for the rest."""
    if isinstance(value, tuple) and value and all(isinstance(v, str) for v in value):
        if value[0].startswith("-"):
            return " ".join(value)
    return None


def reach(monkeypatch, target: str, *argv, stop: bool = True) -> Spy:
    """Run the command line with ``target`` spied; the spy (its last call) afterwards."""
    spy = Spy(monkeypatch, target, stop)
    argv = [str(a) for a in argv]
    if stop:
        with pytest.raises(Reached):
            main(argv)
    else:
        assert main(argv) == 0
    return spy


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A 150-frame BVH walk; the same walk as AMC whose skeleton is not where it would be
    found (``skeletons/rig.asf``, only through --skeleton); the whole 480-frame walk; a
    300-frame jog."""
    d = tmp_path_factory.mktemp("wiring")
    walk = cc.datasets.example_capture().motion
    cc.save(walk[:150], d / "walk.bvh")
    cc.save(walk[:150], d / "s_01.amc")
    (d / "skeletons").mkdir()
    (d / "s.asf").rename(d / "skeletons" / "rig.asf")
    cc.save(walk, d / "long.bvh")
    jog = cc.datasets.make_periodic_capture(kind="jog", n_frames=300, random_state=0).motion
    cc.save(jog, d / "jog.bvh")
    return SimpleNamespace(dir=d, walk=d / "walk.bvh", amc=d / "s_01.amc", asf=d / "skeletons" / "rig.asf",
                           long=d / "long.bvh", jog=d / "jog.bvh",
                           joints=[j.name for j in walk.skeleton.joints])


# ------------------------------------------------------ extract, detect: the pipeline call
#: option argv -> (keyword of extract/detect, value it must carry)
ANALYSIS = {
    ("--frames", "10:140"): ("frames", (10, 140)),
    ("--pca", "3"): ("pca", 3),
    ("--normalize",): ("normalize", True),
    ("--rotations", "rotvec"): ("rotations", "rotvec"),
    ("--temporal",): ("temporal", True),
    ("--no-root-diff",): ("difference_root", False),
    ("--prime", "53"): ("prime", 53),
    ("--max-scale", "2.5"): ("max_scale", 2.5),
    ("--landmarks", "50"): ("landmarks", 50),
    ("--memory-limit", "500M"): ("memory_limit", 500 * 1024**2),
}
EXTRACT_ONLY = {
    ("--scale", "1.5"): ("scale", 1.5),
    ("--class", "1"): ("class_index", 1),
    ("--samples", "300"): ("n_samples", 300),
    ("--neighbors", "7"): ("n_neighbors", 7),
    ("--weighting", "mean"): ("weighting", "mean"),
    ("--sampling", "random"): ("sampling", "random"),
    ("--seed", "7"): ("random_state", 7),
    ("--delay", "0.5"): ("delay", 0.5),
    ("--no-steady",): ("steady", False),
    ("--timing", "coordinate"): ("timing", "coordinate"),
    ("--travel", "in_place"): ("travel", "in_place"),
    ("--min-turns", "2.5"): ("min_turns", 2.5),
    ("--bandwidth", "3"): ("bandwidth", 3.0),
    ("--cycle-start", "first"): ("cycle_start", "first"),
}
DETECT_ONLY = {
    ("--classes", "2"): ("n_classes", 2),
    ("--delay", "0.5"): ("delay", 0.5),
    ("--method", "windows"): ("method", "windows"),
    ("--no-progress",): ("progress", False),
}
PIPELINE = {"extract": "cyclecoord.periodic.pipeline.extract",
            "detect": "cyclecoord.periodic.detection.detect"}


@pytest.mark.parametrize(
    "command, option, keyword, value",
    [("extract", o, k, v) for o, (k, v) in {**ANALYSIS, **EXTRACT_ONLY}.items()]
    + [("detect", o, k, v) for o, (k, v) in {**ANALYSIS, **DETECT_ONLY}.items()],
    ids=_id,
)
def test_analysis_options_reach_the_pipeline(monkeypatch, files, command, option, keyword, value):
    """extract and detect: each option arrives as the pipeline's keyword, which it changes."""
    plain = reach(monkeypatch, PIPELINE[command], command, files.walk).kwargs
    got = reach(monkeypatch, PIPELINE[command], command, files.walk, *option).kwargs
    assert got[keyword] == value and plain[keyword] != value
    assert {k: v for k, v in got.items() if k != keyword} == {
        k: v for k, v in plain.items() if k != keyword}  # nothing else moved


@pytest.mark.parametrize("command", ["extract", "detect", "barcode", "convert", "render", "view",
                                     "feet"])
def test_skeleton_and_fps_reach_the_reader(monkeypatch, files, tmp_path, command):
    """--skeleton: an AMC whose ASF is not beside it reads with it (and not without it);
    --fps: the motion the library gets runs at that rate."""
    target, motion_of = {
        "extract": (PIPELINE["extract"], lambda s: s.args[0]),
        "detect": (PIPELINE["detect"], lambda s: s.args[0]),
        "barcode": ("cyclecoord.periodic.preprocess.Preprocessor.fit_transform", lambda s: s.args[1]),
        "convert": ("cyclecoord.cli._outputs.Outputs.save", lambda s: s.args[1]),
        "render": ("cyclecoord.plot.figures.render", lambda s: s.args[0]),
        "view": ("cyclecoord.plot.viewer.skeleton_figure", lambda s: s.args[0][0].motion),
        "feet": ("cyclecoord.quality.contacts.foot_contacts", lambda s: s.args[0]),
    }[command]
    out = {"convert": ["-o", tmp_path / "a.npz"], "render": ["-o", tmp_path / "a.gif"],
           "view": ["-o", tmp_path / "a.html"]}.get(command, [])
    assert main([command, str(files.amc), *map(str, out)]) == 1  # no s.asf beside it
    m = motion_of(reach(monkeypatch, target, command, files.amc, "--skeleton", files.asf, *out))
    assert [j.name for j in m.skeleton.joints] == files.joints and m.n_frames == 150
    assert m.fps == 120
    m = motion_of(reach(monkeypatch, target, command, files.walk, "--fps", "60", *out))
    assert m.fps == 60 and m.n_frames == 150


# --------------------------------------------------------------------------------- barcode
BARCODE_PREP = {
    ("--pca", "3"): ("pca", 3),
    ("--normalize",): ("normalize", True),
    ("--rotations", "rotvec"): ("rotations", "rotvec"),
    ("--no-root-diff",): ("difference_root", False),
}
BARCODE_FILTRATION = {
    ("--temporal",): ("temporal", True),
    ("--prime", "53"): ("prime", 53),
    ("--max-scale", "2.5"): ("max_scale", 2.5),
    ("--landmarks", "50"): ("landmarks", 50),
    ("--memory-limit", "500M"): ("memory_limit", 500 * 1024**2),
}


@pytest.mark.parametrize("option, keyword, value",
                         [(o, k, v) for o, (k, v) in {**BARCODE_PREP, **BARCODE_FILTRATION}.items()],
                         ids=_id)
def test_barcode_options_reach_preparation_and_filtration(monkeypatch, files, option, keyword, value):
    """barcode: preparation options reach Preprocessor, filtration options
    CircularCoordinates, whose fit_barcode then stops the run."""
    def run(*extra):  # a method's spy goes in before its class's
        Spy(monkeypatch, "cyclecoord.periodic.coordinates.CircularCoordinates.fit_barcode")
        prep = Spy(monkeypatch, "cyclecoord.periodic.preprocess.Preprocessor", stop=False)
        cc_ = Spy(monkeypatch, "cyclecoord.periodic.coordinates.CircularCoordinates", stop=False)
        with pytest.raises(Reached):
            main(["barcode", str(files.walk), *extra])
        return {**prep.kwargs, **cc_.kwargs}

    plain, got = run(), run(*option)
    assert got[keyword] == value and plain.get(keyword) != value


def test_barcode_frames_window_the_motion(monkeypatch, files):
    spy = reach(monkeypatch, "cyclecoord.periodic.preprocess.Preprocessor.fit_transform",
                "barcode", files.walk, "--frames", "10:140")
    m = spy.args[1]
    assert m.n_frames == 130 and m.start_frame == 10


# -------------------------------------------------------- detect --extract: cycle options
def test_detect_cycle_options_reach_motion_cycles(monkeypatch, files, tmp_path):
    target = "cyclecoord.periodic.detection.motion_cycles"
    argv = ["detect", files.long, "--method", "global", "--no-progress", "--extract", tmp_path / "c"]
    plain = reach(monkeypatch, target, *argv).kwargs
    got = reach(monkeypatch, target, *argv, "--timing", "coordinate", "--travel", "straight",
                "--bandwidth", "2.5", "--cycle-start", "first").kwargs
    want = {"timing": "coordinate", "travel": "straight", "bandwidth": 2.5, "cycle_start": "first"}
    assert {k: got[k] for k in want} == want and all(plain[k] != v for k, v in want.items())
    assert {k: v for k, v in got.items() if k not in want} == {
        k: v for k, v in plain.items() if k not in want}


def test_detect_extract_format_names_the_cycles_written(files, tmp_path, capsys):
    folder = tmp_path / "cycles"
    assert main(["detect", str(files.long), "--method", "global", "--no-progress", "--extract",
                 str(folder), "--extract-format", "npz"]) == 0
    written = sorted(p.name for p in folder.iterdir())
    assert written == ["motion0_cycle.npz"]
    assert cc.load(folder / written[0]).n_frames > 50


# -------------------------------------------------------------------- extract -v, --version
def test_verbose_adds_barcode_class_and_timings(files, capsys):
    assert main(["extract", str(files.long)]) == 0
    quiet = capsys.readouterr().out
    assert main(["extract", str(files.long), "-v"]) == 0
    loud = capsys.readouterr().out
    assert main(["extract", str(files.long), "--verbose"]) == 0
    timeless = [line for line in loud.splitlines() if not line.startswith("time:")]
    assert [line for line in capsys.readouterr().out.splitlines()
            if not line.startswith("time:")] == timeless
    assert "barcode" not in quiet and "barcode" in loud and "time:" in loud
    assert set(quiet.splitlines()) <= set(loud.splitlines())


def test_version_prints_the_package_version(capsys):
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out.strip() == f"cyclecoord {cc.__version__}"


# --------------------------------------------------------------------------------- convert
def test_convert_frames_reach_the_written_motion(monkeypatch, files, tmp_path):
    spy = reach(monkeypatch, "cyclecoord.cli._outputs.Outputs.save", "convert", files.walk,
                "-o", tmp_path / "a.npz", "--frames", "10:40")
    assert spy.args[1].n_frames == 30 and spy.args[2] == str(tmp_path / "a.npz")


# ---------------------------------------------------------------------------------- render
RENDER = {
    ("--view", "front"): ("view", "front"),
    ("--step", "3"): ("step", 3),
    ("--follow",): ("follow", True),
    ("--no-follow",): ("follow", False),
}


@pytest.mark.parametrize("option, keyword, value", [(o, k, v) for o, (k, v) in RENDER.items()],
                         ids=_id)
def test_render_options_reach_render(monkeypatch, files, tmp_path, option, keyword, value):
    target, out = "cyclecoord.plot.figures.render", ["-o", tmp_path / "a.gif"]
    plain = reach(monkeypatch, target, "render", files.walk, *out).kwargs
    got = reach(monkeypatch, target, "render", files.walk, *out, *option).kwargs
    assert got[keyword] == value and plain[keyword] != value


def test_render_no_progress_reaches_render(monkeypatch, files, tmp_path):
    target, out = "cyclecoord.plot.figures.render", ["-o", tmp_path / "a.gif"]
    assert reach(monkeypatch, target, "render", files.walk, *out).kwargs["progress"] is True
    got = reach(monkeypatch, target, "render", files.walk, *out, "--no-progress").kwargs
    assert got["progress"] is False


def test_render_frames_and_side_by_side(monkeypatch, files, tmp_path):
    spy = reach(monkeypatch, "cyclecoord.plot.figures.render", "render", files.walk, "-o",
                tmp_path / "a.gif", "--frames", "10:40", "--side-by-side", files.jog)
    assert spy.args[0].n_frames == 30 and spy.kwargs["other"].n_frames == 300


# ------------------------------------------------------------------------------------ view
def test_view_options_reach_the_figure(monkeypatch, files, tmp_path):
    target, out = "cyclecoord.plot.viewer.skeleton_figure", ["-o", tmp_path / "a.html"]
    plain = reach(monkeypatch, target, "view", files.walk, *out)
    (only,) = plain.args[0]
    assert only.cycle is False and only.motion.n_frames == 150
    assert plain.kwargs == {"contacts": True, "max_fps": 30.0}
    got = reach(monkeypatch, target, "view", files.walk, *out, "--frames", "10:40", "--cycle",
                "--side-by-side", files.jog, "--other-frames", "0:90", "--other-cycle",
                "--max-fps", "12", "--no-contacts")
    first, other = got.args[0]
    assert first.cycle is True and first.motion.n_frames == 30
    assert other.cycle is True and other.motion.n_frames == 90 and other.label == "jog.bvh"
    assert got.kwargs == {"contacts": False, "max_fps": 12.0}


# ------------------------------------------------------------------------------------ feet
def test_feet_thresholds_reach_contacts_and_skating(monkeypatch, files):
    contacts = Spy(monkeypatch, "cyclecoord.quality.contacts.foot_contacts", stop=False)
    skating = Spy(monkeypatch, "cyclecoord.quality.contacts.foot_skating", stop=False)
    assert main(["feet", str(files.walk)]) == 0
    plain = (contacts.kwargs, skating.kwargs)
    assert plain[0]["height"] == 0.05 and plain[0]["speed"] == 0.5
    assert plain[1]["skate_speed"] == 0.1
    assert main(["feet", str(files.walk), "--height", "0.08", "--speed", "0.7",
                 "--skate-speed", "0.2"]) == 0
    assert contacts.kwargs["height"] == 0.08 and contacts.kwargs["speed"] == 0.7
    assert skating.kwargs["skate_speed"] == 0.2


def test_feet_frames_cycle_and_lock_reach_lock_feet(monkeypatch, files, tmp_path):
    out = tmp_path / "locked.bvh"
    lock = reach(monkeypatch, "cyclecoord.synthesis.footlock.lock_feet", "feet", files.walk,
                 "--lock", "-o", out)
    assert lock.kwargs["cyclic"] is False and lock.args[0].n_frames == 150
    lock = reach(monkeypatch, "cyclecoord.synthesis.footlock.lock_feet", "feet", files.walk,
                 "--lock", "--cycle", "--frames", "0:120", "-o", out)
    assert lock.kwargs["cyclic"] is True and lock.args[0].n_frames == 120
    assert not out.exists()


@pytest.mark.parametrize("command", ["convert", "feet", "extract"])
def test_units_reach_the_gltf_and_usd_writers(monkeypatch, files, tmp_path, command):
    target = "cyclecoord.cli._outputs.Outputs.save"
    take = files.long if command == "extract" else files.walk  # extract needs 1.5 cycles
    save = reach(monkeypatch, target, command, take, "-o", tmp_path / "a.glb")
    assert "scale" not in save.kwargs  # auto: the writer measures the unit itself
    save = reach(monkeypatch, target, command, take, "-o", tmp_path / "a.glb", "--units", "cm")
    assert save.kwargs["scale"] == 0.01
    save = reach(monkeypatch, target, command, take, "-o", tmp_path / "a.usda", "--units",
                 "0.3048")
    assert save.kwargs["meters_per_unit"] == 0.3048


#: command -> (spied call, extra arguments, how to read the feet it received)
FEET = {
    "extract": (PIPELINE["extract"], [], lambda s: s.kwargs["feet"]),
    "detect": ("cyclecoord.periodic.detection.motion_cycles",
               ["--method", "global", "--no-progress", "--extract", "{tmp}/c"],
               lambda s: s.kwargs["feet"]),
    "blend": ("cyclecoord.synthesis.sources.as_cycle", [], lambda s: s.kwargs.get("feet")),
    "transition": ("cyclecoord.synthesis.sources.as_cycle", ["--cycles", "1"],
                   lambda s: s.kwargs.get("feet")),
    "batch": ("cyclecoord.batch.run_batch", ["-o", "{tmp}/out"],
              lambda s: s.kwargs["extract_options"].get("feet")),
    "view": ("cyclecoord.plot.viewer.skeleton_figure", ["-o", "{tmp}/a.html"],
             lambda s: s.args[0][0].feet),
    "feet": ("cyclecoord.quality.contacts.foot_contacts", [], lambda s: s.kwargs["feet"]),
}


@pytest.mark.parametrize("command", sorted(FEET))
def test_feet_reach_the_library(monkeypatch, files, tmp_path, command):
    """--feet: the named foot joints (here the toes, not the ankles found by default)
    reach the call that measures feet, checked against the skeleton where the command reads
    one; batch passes the text on for each capture to check."""
    target, extra, feet_of = FEET[command]
    extra = [a.replace("{tmp}", str(tmp_path)) for a in extra]
    take = files.dir if command == "batch" else files.long
    inputs = [take, files.jog] if command in ("blend", "transition") else [take]
    plain = feet_of(reach(monkeypatch, target, command, *inputs, *extra))
    got = feet_of(reach(monkeypatch, target, command, *inputs, *extra, "--feet", "ltoes,rtoes"))
    want = "ltoes,rtoes" if command == "batch" else ("ltoes", "rtoes")
    assert got == want and plain != want


def test_animate_feet_reach_the_script(monkeypatch, tmp_path):
    script = tmp_path / "s.json"
    script.write_text(json.dumps({"models": {}, "commands": []}))
    target = "cyclecoord.synthesis.latent.script.run_script"
    argv = ["animate", script, "-o", tmp_path / "a.bvh"]
    assert reach(monkeypatch, target, *argv).kwargs["feet"] is None
    assert reach(monkeypatch, target, *argv, "--feet", "ltoes,rtoes").kwargs["feet"] == "ltoes,rtoes"


def test_feet_lock_writes_the_locked_motion_and_the_report(files, tmp_path, capsys):
    out, rep = tmp_path / "locked.bvh", tmp_path / "feet.json"
    assert main(["feet", str(files.walk), "--lock", "-o", str(out), "--report", str(rep)]) == 0
    r = json.loads(rep.read_text())
    assert r["frames"] == cc.load(out).n_frames == 150
    assert r["locked"]["skating"]["skating_frames"] < r["skating"]["skating_frames"]
    assert not np.allclose(cc.load(out).frames, cc.load(files.walk).frames, atol=1e-3)


def test_view_writes_the_page(files, tmp_path, capsys):
    out = tmp_path / "walk.html"
    assert main(["view", str(files.walk), "-o", str(out)]) == 0
    html = out.read_text()
    assert html.lstrip().lower().startswith(("<html", "<!doctype")) and "plotly" in html.lower()


# ----------------------------------------------------------------------- blend, transition
MATCHING = {
    ("--allow-reverse",): ("allow_reverse", True),
    ("--no-heading",): ("align_heading", False),
    ("--up", "z"): ("up", "z"),
}
LENGTH = {"blend": [], "transition": ["--cycles", "1"]}
SYNTH = {"blend": "cyclecoord.synthesis.blend.blend",
         "transition": "cyclecoord.synthesis.blend.transition"}


@pytest.mark.parametrize(
    "command, option, keyword, value",
    [(c, o, k, v) for c in ("blend", "transition") for o, (k, v) in MATCHING.items()],
    ids=_id,
)
def test_matching_options_reach_blend_and_transition(monkeypatch, files, command, option, keyword,
                                                     value):
    argv = [command, files.long, files.jog, "--as-cycle", *LENGTH[command]]
    plain = reach(monkeypatch, SYNTH[command], *argv).kwargs
    got = reach(monkeypatch, SYNTH[command], *argv, *option).kwargs
    assert got[keyword] == value and plain[keyword] != value


def test_transition_length_options_reach_transition(monkeypatch, files):
    target, argv = SYNTH["transition"], ["transition", files.long, files.jog, "--as-cycle"]
    got = reach(monkeypatch, target, *argv, "--cycles", "2").kwargs
    assert got["cycles"] == 2 and got["frames"] is None
    got = reach(monkeypatch, target, *argv, "--frames", "30", "--lead-in", "7",
                "--lead-out", "9").kwargs
    assert (got["frames"], got["cycles"], got["lead_in"], got["lead_out"]) == (30, None, 7, 9)


@pytest.mark.parametrize("command", ["blend", "transition"])
def test_margin_reaches_the_plausibility_check(monkeypatch, files, command):
    target = "cyclecoord.quality.plausibility.check_plausibility"
    argv = [command, files.long, files.jog, "--as-cycle", *LENGTH[command]]
    assert reach(monkeypatch, target, *argv).kwargs["margin_deg"] == 5.0
    assert reach(monkeypatch, target, *argv, "--margin", "12.5").kwargs["margin_deg"] == 12.5


@pytest.mark.parametrize("command", ["blend", "transition"])
def test_input_options_reach_as_cycle(monkeypatch, files, command):
    """--as-cycle/--extract choose the mode; --window, --max-scale, --scale, --seed reach
    as_cycle (once for every input, or once per input in order); --fps the motion read."""
    target = "cyclecoord.synthesis.sources.as_cycle"

    from cyclecoord.synthesis.sources import as_cycle

    def calls(*extra):  # each input taken as it is, whatever was asked
        spy = Spy(monkeypatch, target, stop=False, fake=lambda m, **kw: as_cycle(m, mode="cycle"))
        Spy(monkeypatch, SYNTH[command])  # stop once both inputs are cycles
        with pytest.raises(Reached):
            main([command, str(files.long), str(files.jog), *LENGTH[command], *map(str, extra)])
        return spy.calls

    (a, ka), (b, kb) = calls()
    assert ka == kb == {"mode": "auto", "frames": None, "random_state": 0}
    assert calls("--as-cycle")[0][1]["mode"] == "cycle"
    (a, ka), (b, kb) = calls("--extract", "--window", "0:300", "--window", "20:280",
                             "--max-scale", "40", "--max-scale", "auto", "--scale", "9",
                             "--seed", "3", "--fps", "100")
    assert ka == {"mode": "extract", "frames": (0, 300), "random_state": 3, "max_scale": 40.0,
                  "scale": 9.0}
    assert kb == {"mode": "extract", "frames": (20, 280), "random_state": 3, "scale": 9.0}
    assert a[0].fps == b[0].fps == 100


# ----------------------------------------------------------------------------------- batch
BATCH = {
    ("--scheduler", "tcp://127.0.0.1:8786"): ("scheduler", "tcp://127.0.0.1:8786"),
    ("--force",): ("force", True),
    ("--pattern", "*.bvh"): ("pattern", ["*.bvh"]),
    ("--jobs", "2"): ("jobs", 2),
    ("-j", "2"): ("jobs", 2),
    ("--fps", "60"): ("fps", 60.0),
    ("--no-progress",): ("progress", False),
    ("--cycles", "none"): ("write_cycles", None),
}
BATCH_EXTRACT = {
    ("--pca", "3"): ("pca", 3),
    ("--normalize",): ("normalize", True),
    ("--rotations", "rotvec"): ("rotations", "rotvec"),
    ("--temporal",): ("temporal", True),
    ("--prime", "53"): ("prime", 53),
    ("--max-scale", "2.5"): ("max_scale", 2.5),
    ("--landmarks", "50"): ("landmarks", 50),
    ("--memory-limit", "500M"): ("memory_limit", 500 * 1024**2),
    ("--seed", "7"): ("random_state", 7),
    ("--no-steady",): ("steady", False),
    ("--timing", "coordinate"): ("timing", "coordinate"),
    ("--travel", "in_place"): ("travel", "in_place"),
    ("--min-turns", "2.5"): ("min_turns", 2.5),
    ("--bandwidth", "3"): ("bandwidth", 3.0),
    ("--cycle-start", "first"): ("cycle_start", "first"),
}


@pytest.mark.parametrize(
    "option, keyword, value",
    [(o, k, v) for o, (k, v) in BATCH.items()]
    + [(o, ("extract_options", k), v) for o, (k, v) in BATCH_EXTRACT.items()],
    ids=_id,
)
def test_batch_options_reach_run_batch(monkeypatch, files, tmp_path, option, keyword, value):
    """batch: each option reaches run_batch, the analysis ones inside extract_options (the
    keywords extract takes)."""
    argv = ["batch", files.dir, "-o", tmp_path / "out"]

    def get(kwargs):
        if isinstance(keyword, tuple):
            return kwargs[keyword[0]].get(keyword[1])
        return kwargs[keyword]

    plain = reach(monkeypatch, "cyclecoord.batch.run_batch", *argv)
    got = reach(monkeypatch, "cyclecoord.batch.run_batch", *argv, *option)
    assert get(got.kwargs) == value and get(plain.kwargs) != value
    assert plain.args == (str(files.dir), str(tmp_path / "out"))
    if isinstance(keyword, tuple):  # every analysis keyword is one extract takes
        from cyclecoord.periodic.pipeline import extract

        assert set(got.kwargs["extract_options"]) <= set(inspect.signature(extract).parameters)


# ----------------------------------------------------------------------------------- graph
@pytest.fixture(scope="module")
def takes(tmp_path_factory):
    folder = tmp_path_factory.mktemp("takes")
    paths = []
    for s, n in ((0, 150), (1, 130)):
        m = cc.datasets.make_periodic_capture(kind="walk", n_frames=n, period=60,
                                              random_state=s).motion
        cc.save(m, folder / f"walk{s}.bvh")
        paths.append(str(folder / f"walk{s}.bvh"))
    return paths


GRAPH = {
    ("-k", "5"): ("k", 5),
    ("--k", "5"): ("k", 5),
    ("--integrator", "rk4"): ("integrator", "rk4"),
    ("--step-scale", "1.5"): ("step_scale", 1.5),
    ("--dims", "3"): ("dims", 3),
    ("--method", "knn"): ("method", "knn"),
}


@pytest.mark.parametrize("option, keyword, value", [(o, k, v) for o, (k, v) in GRAPH.items()],
                         ids=_id)
def test_graph_options_reach_the_synthesiser(monkeypatch, takes, option, keyword, value):
    target = "cyclecoord.synthesis.graph.MotionGraphSynth"
    plain = reach(monkeypatch, target, "graph", *takes).kwargs
    got = reach(monkeypatch, target, "graph", *takes, *option).kwargs
    assert got[keyword] == value and plain[keyword] != value


@pytest.mark.parametrize("option, keyword, value",
                         [(o, k, v) for o, (k, v) in GRAPH.items() if k != "method"]
                         + [(("--no-topo",), "topo", False)],
                         ids=_id)
def test_graph_crossval_options_reach_cross_validate(monkeypatch, takes, option, keyword, value):
    target = "cyclecoord.synthesis.graph.cross_validate"
    plain = reach(monkeypatch, target, "graph", "crossval", *takes).kwargs
    got = reach(monkeypatch, target, "graph", "crossval", *takes, *option).kwargs
    assert got[keyword] == value and plain[keyword] != value


@pytest.mark.parametrize("option, keywords", [
    (("--no-carry",), {"carry": False, "lock": False}),
    (("--no-lock",), {"carry": True, "lock": False}),
], ids=_id)
def test_graph_carry_and_lock_reach_the_synthesiser(monkeypatch, takes, option, keywords):
    target = "cyclecoord.synthesis.graph.MotionGraphSynth"
    plain = reach(monkeypatch, target, "graph", *takes).kwargs
    got = reach(monkeypatch, target, "graph", *takes, *option).kwargs
    assert {k: plain[k] for k in keywords} == {"carry": True, "lock": True}
    assert {k: got[k] for k in keywords} == keywords


def test_graph_horizon_and_no_progress_reach_cross_validate(monkeypatch, takes):
    target = "cyclecoord.synthesis.graph.cross_validate"
    plain = reach(monkeypatch, target, "graph", "crossval", *takes).kwargs
    got = reach(monkeypatch, target, "graph", "crossval", *takes, "--horizon", "0",
                "--no-progress").kwargs
    assert (plain["horizon"], plain["progress"]) == (3, True)
    assert (got["horizon"], got["progress"]) == (0, False)


def test_graph_no_progress_reaches_the_loading_bar(monkeypatch, takes):
    """graph's loading bar (drawn from four takes on) is off with --no-progress."""
    import tqdm

    bars = Spy(monkeypatch, "tqdm.tqdm", stop=False)
    target = "cyclecoord.synthesis.graph.MotionGraphSynth"
    four = takes + takes
    reach(monkeypatch, target, "graph", *four)
    reach(monkeypatch, target, "graph", *four, "--no-progress")
    assert [kw["disable"] for _, kw in bars.calls] == [False, True]
    assert tqdm.tqdm is bars  # the command reads the bar at run time (from tqdm import tqdm)


def test_graph_fps_reaches_the_takes(monkeypatch, tmp_path):
    """--fps: once, every AMC input (which carries no rate) is read at it; once per input,
    each its own; the synthesiser gets the takes at those rates."""
    amcs = []
    for s, name in ((0, "a_01.amc"), (1, "b_01.amc")):
        m = cc.datasets.make_periodic_capture(kind="walk", n_frames=150, period=60,
                                              random_state=s).motion
        cc.save(m, tmp_path / name)
        amcs.append(tmp_path / name)
    target = "cyclecoord.synthesis.graph.MotionGraphSynth.fit"
    assert [m.fps for m in reach(monkeypatch, target, "graph", *amcs).args[1]] == [120, 120]
    fit = reach(monkeypatch, target, "graph", *amcs, "--fps", "60")
    assert [m.fps for m in fit.args[1]] == [60, 60]
    fit = reach(monkeypatch, target, "graph", *amcs, "--fps", "120", "--fps", "60")
    assert [m.fps for m in fit.args[1]] == [120, 60] and fit.args[1][0].n_frames == 150


def test_graph_start_target_and_frames_reach_the_walk(monkeypatch, takes, tmp_path):
    gen = reach(monkeypatch, "cyclecoord.synthesis.graph.MotionGraphSynth.generate", "graph",
                *takes, "--frames", "77", "--start", f"{takes[1]}:5")
    synth, n, start, frame = gen.args
    assert n == 77 and frame == 5 and start.n_frames == 130
    to = reach(monkeypatch, "cyclecoord.synthesis.graph.MotionGraphSynth.to_target", "graph",
               *takes, "--target", f"{takes[1]}:40", "--step-scale", "3")
    synth, start, frame, target, target_frame = to.args
    assert frame == 0 and target_frame == 40 and to.kwargs["speed"] == 1.5
    assert target.n_frames == 130 and start.n_frames == 150


def _implausible(monkeypatch):
    """check_plausibility says every output fails (what --strict must refuse to write)."""
    bad = SimpleNamespace(clean=False, summary=lambda: "plausibility: FAILS (test)",
                          to_dict=lambda: {"clean": False})
    monkeypatch.setattr("cyclecoord.quality.plausibility.check_plausibility",
                        lambda *a, **k: bad)


def test_graph_strict_refuses_an_implausible_motion(monkeypatch, takes, tmp_path):
    _implausible(monkeypatch)
    out = tmp_path / "g.bvh"
    argv = ["graph", *takes, "--frames", "40", "-o", str(out)]
    assert main(argv + ["--strict"]) == 1 and not out.exists()
    assert main(argv) == 0 and cc.load(out).n_frames == 40


def test_graph_generates_with_the_phase_aware_field_by_default(monkeypatch, takes):
    target = "cyclecoord.synthesis.graph.MotionGraphSynth"
    kw = reach(monkeypatch, target, "graph", *takes).kwargs
    assert kw["method"] == "delaunay+phase" and kw["dims"] == "auto"


def test_graph_refuses_limbs_through_each_other_unless_allowed(monkeypatch, takes, tmp_path):
    """A generated motion with new limb contacts is refused (report written, no motion)
    without --strict; --allow-contacts writes it."""
    bad = SimpleNamespace(clean=False, new_contact_frames=[7, 8, 9],
                          summary=lambda: "plausibility: new limb contacts in 3 frames",
                          to_dict=lambda: {"clean": False})
    monkeypatch.setattr("cyclecoord.quality.plausibility.check_plausibility",
                        lambda *a, **k: bad)
    out, rep = tmp_path / "g.bvh", tmp_path / "g.json"
    argv = ["graph", *takes, "--frames", "40", "-o", str(out), "--report", str(rep)]
    assert main(argv) == 1 and not out.exists()
    assert "limbs passing through" in json.loads(rep.read_text())["refused"]
    assert main(argv + ["--allow-contacts"]) == 0 and cc.load(out).n_frames == 40


# ---------------------------------------------------------------------- latent fit, animate
def test_latent_fit_options_reach_the_model(monkeypatch, takes, tmp_path):
    def run(*extra):  # a method's spy goes in before its class's
        fit = Spy(monkeypatch, "cyclecoord.synthesis.latent.model.LatentModel.fit")
        model = Spy(monkeypatch, "cyclecoord.synthesis.latent.model.LatentModel", stop=False)
        with pytest.raises(Reached):
            main(["latent", "fit", takes[0], "-o", str(tmp_path / "m.npz"), *extra])
        return model.kwargs, fit.args[1]

    kw, segments = run()
    assert kw == {"n_components": 3, "variance": 0.85, "gplvm": {"max_iter": 200}}
    assert [s.n_frames for s in segments] == [len(range(0, 150, 4))]
    kw, segments = run("--dims", "2", "--variance", "0.9", "--max-iter", "17", "--step", "3")
    assert kw == {"n_components": 2, "variance": 0.9, "gplvm": {"max_iter": 17}}
    assert [s.n_frames for s in segments] == [50]
    assert not (tmp_path / "m.npz").exists()


def test_latent_fit_default_step_trains_near_30_fps(monkeypatch, takes, tmp_path):
    """A 30 fps BVH keeps every frame by default (every 4th left 38 frames of a 150-frame
    walk, too few for a gait phase); a 120 fps one every 4th; --step overrides both."""
    slow = tmp_path / "walk30.bvh"
    cc.save(cc.load(takes[0])[::4], slow)  # 150 frames at 120 fps -> 38 frames at 30 fps

    def frames(path, *extra):
        fit = Spy(monkeypatch, "cyclecoord.synthesis.latent.model.LatentModel.fit")
        with pytest.raises(Reached):
            main(["latent", "fit", str(path), "-o", str(tmp_path / "m.npz"), *extra])
        return [(m.n_frames, m.fps) for m in fit.args[1]]

    assert cc.load(takes[0]).fps == 120.0
    assert frames(takes[0]) == [(38, 30.0)]
    assert frames(slow) == [(38, 30.0)]
    assert frames(slow, "--step", "2") == [(19, 15.0)]


def test_latent_fit_fps_reaches_the_takes(monkeypatch, tmp_path):
    """--fps: an AMC take (no rate of its own) read at it, once for all or once per take;
    the step to about 30 fps follows (60 fps: every 2nd frame)."""
    amcs = []
    for s, name in ((0, "a_01.amc"), (1, "b_01.amc")):
        m = cc.datasets.make_periodic_capture(kind="walk", n_frames=160, period=60,
                                              random_state=s).motion
        cc.save(m, tmp_path / name)
        amcs.append(str(tmp_path / name))

    def got(*extra):
        fit = Spy(monkeypatch, "cyclecoord.synthesis.latent.model.LatentModel.fit")
        with pytest.raises(Reached):
            main(["latent", "fit", *amcs, "-o", str(tmp_path / "m.npz"), *extra])
        return [(m.n_frames, m.fps) for m in fit.args[1]]

    assert got() == [(40, 30.0), (40, 30.0)]
    assert got("--fps", "60") == [(80, 30.0), (80, 30.0)]
    assert got("--fps", "120", "--fps", "60") == [(40, 30.0), (80, 30.0)]
    assert main(["latent", "fit", *amcs, "-o", str(tmp_path / "m.npz"), "--fps", "60",
                 "--fps", "60", "--fps", "60"]) == 1


def test_latent_fit_no_progress_reaches_fit(monkeypatch, takes, tmp_path):
    def progress(*extra):
        fit = Spy(monkeypatch, "cyclecoord.synthesis.latent.model.LatentModel.fit")
        with pytest.raises(Reached):
            main(["latent", "fit", takes[0], "-o", str(tmp_path / "m.npz"), *extra])
        return fit.kwargs["progress"]

    assert progress() is True and progress("--no-progress") is False


def test_latent_fit_writes_the_model_and_the_report(takes, tmp_path, capsys):
    model, rep = tmp_path / "m.npz", tmp_path / "fit.json"
    assert main(["latent", "fit", takes[0], "-o", str(model), "--max-iter", "5",
                 "--report", str(rep)]) == 0
    from cyclecoord.synthesis.latent.model import LatentModel

    assert LatentModel.load(model).n_components == 3
    assert json.loads(rep.read_text())["iterations"] <= 5


def test_animate_no_check_reaches_run_script(monkeypatch, tmp_path):
    script = tmp_path / "s.json"
    script.write_text(json.dumps({"models": {}, "commands": []}))
    target = "cyclecoord.synthesis.latent.script.run_script"
    assert reach(monkeypatch, target, "animate", script, "-o", tmp_path / "a.bvh").kwargs[
        "check"] is True
    assert reach(monkeypatch, target, "animate", script, "-o", tmp_path / "a.bvh",
                 "--no-check").kwargs["check"] is False


def test_animate_no_progress_reaches_run_script(monkeypatch, tmp_path):
    script = tmp_path / "s.json"
    script.write_text(json.dumps({"models": {}, "commands": []}))
    target, out = "cyclecoord.synthesis.latent.script.run_script", ["-o", tmp_path / "a.bvh"]
    assert reach(monkeypatch, target, "animate", script, *out).kwargs["progress"] is True
    assert reach(monkeypatch, target, "animate", script, *out, "--no-progress").kwargs[
        "progress"] is False


def test_animate_refuses_limbs_through_each_other_unless_allowed(monkeypatch, tmp_path):
    """A script whose motion keeps new limb contacts is refused (report written with the
    reason, no motion); --allow-contacts writes it."""
    import cyclecoord.synthesis.latent.script as S

    motion = cc.datasets.example_capture().motion[:40]
    report = {"plausibility": {"clean": False, "new_contact_frames": [7, 8, 9],
                               "notes": ["1 bone pairs come closer than the inputs ever do"]},
              "timing": {"frames_per_second": 0}, "frames": 40, "duration_s": 0.33,
              "fps": 120.0, "transitions": []}
    monkeypatch.setattr(S, "run_script", lambda *a, **k: (motion, dict(report)))
    script = tmp_path / "s.json"
    script.write_text(json.dumps({"models": {}, "commands": []}))
    out, rep = tmp_path / "a.bvh", tmp_path / "a.json"
    argv = ["animate", str(script), "-o", str(out), "--report", str(rep)]
    assert main(argv) == 1 and not out.exists()
    assert "limbs passing through each other in 3 frames" in json.loads(rep.read_text())["refused"]
    assert "another seed may avoid it" in json.loads(rep.read_text())["refused"]
    assert main(argv + ["--allow-contacts"]) == 0 and cc.load(out).n_frames == 40
    assert "refused" not in json.loads(rep.read_text())
    # inside a TRANSITION's blend the refusal names it and suggests another blend length
    report["transitions"] = [{"command": 21, "transition": ["run", "walk"], "start_frame": 4,
                              "blend_frames": 12}]
    assert main(argv) == 1
    why = json.loads(rep.read_text())["refused"]
    assert 'commands[21] TRANSITION run -> walk blends there' in why
    assert '"blend": 0.12 instead of 0.10' in why


def test_spy_sees_what_it_replaced(monkeypatch):
    """The helper itself: a method spy gets the instance, a function spy the arguments."""
    spy = Spy(monkeypatch, "cyclecoord.motion.Motion.window", stop=False)
    m = cc.datasets.example_capture().motion
    assert m.window((0, 10)).n_frames == 10 and spy.args[0] is m
    spy = Spy(monkeypatch, "cyclecoord.datasets.example_capture")
    with pytest.raises(Reached):
        cc.datasets.example_capture(noise=0.0)
    assert spy.kwargs == {"noise": 0.0} and np.isfinite(m.frames).all()


# ------------------------------------------------- --memory-limit: the limit readers see
#: command -> its argv before the option ({walk}: a BVH, {out}: a folder, {script}: a script)
MEMORY_LIMITED = {
    "convert": ["convert", "{walk}", "-o", "{out}/w.npz"],
    "view": ["view", "{walk}", "-o", "{out}/w.html"],
    "feet": ["feet", "{walk}"],
    "graph": ["graph", "{walk}", "-o", "{out}/g.bvh"],
    "latent fit": ["latent", "fit", "{walk}", "-o", "{out}/m.npz"],
    "animate": ["animate", "{script}", "-o", "{out}/a.bvh"],
}


@pytest.fixture(scope="module")
def script(files, tmp_path_factory):
    d = tmp_path_factory.mktemp("script")
    assert main(["latent", "fit", str(files.walk), "-o", str(d / "m.npz"),
                      "--max-iter", "3"]) == 0
    spec = {"models": {"w": "m.npz"}, "commands": [{"command": "IDLE", "duration": 0.5}]}
    (d / "s.json").write_text(json.dumps(spec))
    return d / "s.json"


@pytest.mark.parametrize("command", list(MEMORY_LIMITED))
def test_memory_limit_reaches_the_readers(monkeypatch, files, script, tmp_path, command):
    """--memory-limit 500M is the limit every memory check of the command sees (the first
    check, a reader's, stops the run)."""
    from cyclecoord.io import _limits

    seen = []

    def check(nbytes, what):
        seen.append(_limits.stated_memory_limit())
        raise Reached

    monkeypatch.setattr(_limits, "memory_problem", check)
    argv = [a.format(walk=files.walk, out=tmp_path, script=script)
            for a in MEMORY_LIMITED[command]]
    with pytest.raises(Reached):
        main(argv + ["--memory-limit", "500M"])
    assert seen == [500 * 1024**2]


def test_graph_crossval_dims_auto_reaches_cross_validate(monkeypatch, takes):
    """``graph crossval --dims auto`` passes "auto" (each fold's own dimensions); it was
    silently 2."""
    target = "cyclecoord.synthesis.graph.cross_validate"
    assert reach(monkeypatch, target, "graph", "crossval", *takes).kwargs["dims"] == 2
    got = reach(monkeypatch, target, "graph", "crossval", *takes, "--dims", "auto").kwargs
    assert got["dims"] == "auto"
