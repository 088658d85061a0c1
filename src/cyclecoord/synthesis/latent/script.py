"""JSON scripts of latent-synthesis commands: models by name, commands, frame rate, seed.

A script is a JSON object::

    {
      "fps": 30, "seed": 0,
      "models": {"jumpjack": "jumpjack.npz", "twist": "twist.npz"},
      "start": {"model": "jumpjack", "at": {"frame": 0}},
      "particle": {"radius": 0.15, "random": 6},
      "bridge_threshold": null,
      "plant": "all", "lock_feet": true,
      "commands": [
        {"command": "IDLE", "duration": 1.5},
        {"command": "MOVE", "to": {"segment": "JumpJack", "time": 2.0}, "path": "graph"},
        {"command": "TRANSITION", "to": "twist", "blend": 0.4},
        {"command": "PLAY", "segment": "Twist", "start": 0, "stop": 2},
        {"command": "IDLE", "at": [{"frame": 10}, {"frame": 40}], "duration": 3, "hover": 1}
      ]
    }

Model paths are relative to the script's folder.  Every problem is reported as one
:class:`~cyclecoord.errors.ParameterError` line naming the script and the entry
(``commands[2] (TRANSITION)``, ``models.twist``, ...).
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..._blas import one_blas_thread
from ...errors import CycleCoordError, ParameterError, ParseError
from ...quality.contacts import skating_report
from .commands import Synthesizer, _isfinite
from .model import LatentModel
from .particle import ParticleParams

__all__ = ["COMMANDS", "TOP_KEYS", "load_script", "model_file", "run_script", "script_files"]

#: Shortest run of one model's frames (s) that the report measures on its own.
MIN_SECTION = 0.5

TOP_KEYS = {
    "fps",
    "seed",
    "models",
    "start",
    "particle",
    "bridge_threshold",
    "plant",
    "lock_feet",
    "gait_detail",
    "feet",
    "commands",
}
#: Each command's allowed keys (besides "command").
COMMANDS = {
    "MOVE": {"to", "path", "duration", "speed", "radius"},
    "IDLE": {"at", "duration", "radius", "hover", "sway"},
    "TRANSITION": {"to", "blend", "radius", "route", "in_step"},
    "PLAY": {"segment", "start", "stop"},
}
_REQUIRED = {"MOVE": {"to"}, "IDLE": {"duration"}, "TRANSITION": {"to"}, "PLAY": {"segment"}}


def _fail(path: Path, where: str, message: str) -> ParameterError:
    return ParameterError(f"{path}: {where}: {message}")


def model_file(script: Path, entry: str) -> Path:
    """The model file a script's ``models`` entry names (relative to the script's folder)."""
    return (script.parent / entry) if not Path(entry).is_absolute() else Path(entry)


def script_files(path: str | Path) -> list[Path]:
    """Every file a run of the script reads: the script and the model files it names.

    Only files that exist; a script that cannot be read or parsed gives itself alone
    (:func:`load_script` reports what is wrong).  For the output rule of ``animate``: no
    output may replace one of these.
    """
    p = Path(path)
    if not p.is_file():
        return []
    files = [p]
    try:
        spec = _read_spec(p)
    except CycleCoordError:
        return files
    models = spec.get("models") if isinstance(spec, dict) else None
    for entry in models.values() if isinstance(models, dict) else ():
        if not isinstance(entry, str):
            continue
        try:
            if model_file(p, entry).is_file():
                files.append(model_file(p, entry))
        except (OSError, ValueError):  # a name the OS refuses (NUL, too long)
            pass
    return files


#: Commands in one script, models it names, and targets one IDLE hovers between.
MAX_COMMANDS = 10_000
MAX_MODELS = 64
MAX_TARGETS = 1_000
#: Longest TRANSITION blend asked for, seconds (blends are capped at MAX_BLEND anyway).
MAX_BLEND_ASKED = 3600.0


def _number(p: Path, where: str, value: Any, low: float, high: float, what: str) -> float:
    """A finite number in ``(low, high]`` (``what`` says what it is, for the message)."""
    if (
        not isinstance(value, (int, float))
        or isinstance(value, bool)
        or not _isfinite(value)
        or not low < value <= high
    ):
        raise _fail(p, where, f"{what} must be a number in ({low:g}, {high:g}], got {value!r}")
    return float(value)


def _read_spec(p: Path) -> Any:
    """The script's JSON, its size and nesting checked before it is parsed."""
    from ...io._limits import MAX_METADATA_BYTES, metadata_problem

    try:
        size = p.stat().st_size
        if size > MAX_METADATA_BYTES:
            raise ParseError(
                f"the script is {size:,} bytes; at most {MAX_METADATA_BYTES:,} are supported", p
            )
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ParameterError(f"{p}: script not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ParseError(f"cannot read the script: {exc}", p) from None
    problem = metadata_problem(text)
    if problem is not None:
        raise ParseError(f"the script's JSON is {problem}", p)
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise ParseError(f"not valid JSON: {exc.msg}", p, line=exc.lineno) from None
    except (ValueError, RecursionError) as exc:
        raise ParseError(f"not valid JSON: {str(exc)[:100]}", p) from None


def _check_command(p: Path, where: str, kind: str, c: dict, fps: float) -> float:
    """The command's values checked for their types and ranges; the seconds it asks for
    (0 when its length depends on the models)."""
    from ...io._limits import MAX_FRAMES, MAX_MAGNITUDE

    longest = MAX_FRAMES / fps  # seconds the frame limit allows at the script's rate
    seconds = 0.0
    if "duration" in c:
        seconds = _number(p, where, c["duration"], 0.0, longest, "duration (seconds)")
    if "radius" in c and c["radius"] is not None:
        _number(p, where, c["radius"], 0.0, MAX_MAGNITUDE, "radius")
    if kind == "MOVE":
        if c.get("path", "line") not in ("line", "graph"):
            raise _fail(p, where, f"path must be 'line' or 'graph', got {c['path']!r}")
        if "speed" in c:
            _number(p, where, c["speed"], 1e-6, 1e6, "speed")
    elif kind == "IDLE":
        if "hover" in c:
            _number(p, where, c["hover"], 1e-3, longest, "hover (seconds)")
        if "sway" in c and c["sway"] != 0:  # (0: no random force, a still stand)
            _number(p, where, c["sway"], 0.0, 1.0, "sway (share of the random force)")
        at = c.get("at")
        if isinstance(at, list) and len(at) > MAX_TARGETS:
            raise _fail(p, where, f"{len(at):,} targets; at most {MAX_TARGETS:,} are supported")
    elif kind == "TRANSITION":
        if not isinstance(c["to"], str):
            raise _fail(p, where, f"to must name a model, got {c['to']!r}")
        if "blend" in c:
            _number(p, where, c["blend"], 0.0, MAX_BLEND_ASKED, "blend (seconds)")
        if not isinstance(c.get("route", True), bool):
            raise _fail(p, where, f"route must be true or false, got {c['route']!r}")
    else:  # PLAY
        if not isinstance(c["segment"], str):
            raise _fail(p, where, f"segment must be a segment's name, got {c['segment']!r}")
        start = c.get("start", 0.0)
        if start != 0:
            start = _number(p, where, start, 0.0, longest, "start (seconds)")
        if c.get("stop") is not None:
            seconds = _number(p, where, c["stop"], float(start), longest, "stop (seconds)") - start
    return seconds


def load_script(path: str | Path) -> tuple[dict[str, Any], dict[str, LatentModel]]:
    """Read and check a script and load its models (nothing is run).

    Every value is checked for its type and range before a model is loaded: numbers
    finite, durations, times and the frames they ask for within
    :data:`~cyclecoord.io._limits.MAX_FRAMES` and the memory limit
    (:func:`~cyclecoord.io._limits.check_memory`), models that exist and are models.
    """
    from ...io._limits import MAX_FPS, MAX_FRAMES, MIN_FPS

    p = Path(path)
    spec = _read_spec(p)
    if not isinstance(spec, dict):
        raise _fail(p, "top level", "a script is a JSON object")
    unknown = sorted(set(spec) - TOP_KEYS)
    if unknown:
        raise _fail(p, "top level", f"unknown key(s) {unknown}; known: {sorted(TOP_KEYS)}")
    fps = spec.get("fps", 30)
    if (
        not isinstance(fps, (int, float))
        or isinstance(fps, bool)
        or not _isfinite(fps)
        or not MIN_FPS <= fps <= MAX_FPS
    ):
        raise _fail(p, "fps", f"must be a number of frames a second in {MIN_FPS:g}..{MAX_FPS:g}, "
                    f"got {fps!r}")
    seed = spec.get("seed", 0)
    if not isinstance(seed, int) or isinstance(seed, bool) or not 0 <= seed < 2**63:
        raise _fail(p, "seed", f"must be a whole number in 0..2**63-1, got {seed!r}")
    models_spec = spec.get("models")
    if not isinstance(models_spec, dict) or not models_spec:
        raise _fail(p, "models", "must map model names to .npz files")
    if len(models_spec) > MAX_MODELS:
        raise _fail(p, "models", f"{len(models_spec)} models; at most {MAX_MODELS} are supported")
    commands = spec.get("commands")
    if not isinstance(commands, list) or not commands:
        raise _fail(p, "commands", "must be a non-empty list")
    if len(commands) > MAX_COMMANDS:
        raise _fail(p, "commands", f"{len(commands):,} commands; at most {MAX_COMMANDS:,} are "
                    "supported")
    total = 0.0
    for i, c in enumerate(commands):  # types and lengths, before any model is loaded
        if isinstance(c, dict) and isinstance(c.get("command"), str):
            kind = c["command"].upper()
            if kind in COMMANDS and not _REQUIRED[kind] - set(c):
                where = f"commands[{i}] ({c['command']})"
                total += _check_command(p, where, kind, c, float(fps))
                if total * fps > MAX_FRAMES:
                    raise _fail(
                        p, where, f"the commands up to here last {total:.6g} s, "
                        f"{total * fps:.4g} frames at {fps:g} fps; at most {MAX_FRAMES:,} are "
                        "supported"
                    )
    models: dict[str, LatentModel] = {}
    for name, file in models_spec.items():
        if not isinstance(file, str):
            raise _fail(p, f"models.{name}", f"must be a path, got {file!r}")
        mp = model_file(p, file)
        try:
            found = mp.is_file()
        except (OSError, ValueError):  # a name the OS refuses (NUL, too long)
            found = False
        if not found:
            raise _fail(p, f"models.{name}", f"model file {mp} not found")
        try:
            models[name] = LatentModel.load(mp)
        except CycleCoordError as exc:
            raise _fail(p, f"models.{name}", str(exc)) from None
    start = spec.get("start", {"model": next(iter(models))})
    if not isinstance(start, dict) or "model" not in start or set(start) - {"model", "at"}:
        raise _fail(p, "start", 'must be {"model": NAME} with an optional "at" target')
    if not isinstance(start["model"], str) or start["model"] not in models:
        raise _fail(
            p, "start", f"unknown model {start['model']!r}; the script defines {sorted(models)}"
        )
    particle = spec.get("particle") or {}
    if not isinstance(particle, dict):
        raise _fail(p, "particle", f"must be an object of particle parameters, got {particle!r}")
    try:
        ParticleParams().replace(**particle)
    except (ParameterError, TypeError) as exc:
        raise _fail(p, "particle", str(exc)) from None
    thr = spec.get("bridge_threshold")
    if thr is not None:
        from ...io._limits import MAX_MAGNITUDE

        _number(p, "bridge_threshold", thr, 0.0, MAX_MAGNITUDE, "the threshold (skeleton units)")
    if spec.get("plant", "all") not in ("transitions", "all", "off"):
        raise _fail(p, "plant", f"must be transitions, all or off, got {spec['plant']!r}")
    if not isinstance(spec.get("lock_feet", True), bool):
        raise _fail(p, "lock_feet", f"must be true or false, got {spec['lock_feet']!r}")
    if not isinstance(spec.get("gait_detail", True), bool):
        raise _fail(p, "gait_detail", f"must be true or false, got {spec['gait_detail']!r}")
    feet = spec.get("feet")
    if feet is not None and (
        not isinstance(feet, list) or not feet or not all(isinstance(f, str) for f in feet)
    ):
        raise _fail(p, "feet", f"must be a list of joint names, got {feet!r}")
    for i, c in enumerate(commands):
        where = f"commands[{i}]"
        if not isinstance(c, dict) or not isinstance(c.get("command"), str):
            raise _fail(
                p, where, 'each command is an object with "command": MOVE, IDLE, TRANSITION or PLAY'
            )
        kind = c["command"].upper()
        where = f"commands[{i}] ({c['command']})"
        if kind not in COMMANDS:
            raise _fail(p, where, f"unknown command; use one of {sorted(COMMANDS)}")
        extra = sorted(set(c) - COMMANDS[kind] - {"command"})
        if extra:
            raise _fail(p, where, f"unknown key(s) {extra}; {kind} takes {sorted(COMMANDS[kind])}")
        missing = sorted(_REQUIRED[kind] - set(c))
        if missing:
            raise _fail(p, where, f"missing {missing}")
        _check_command(p, where, kind, c, float(fps))
        if kind == "TRANSITION" and c["to"] not in models:
            raise _fail(p, where, f"unknown model {c['to']!r}; the script defines {sorted(models)}")
    return spec, models


def training_takes(models: dict[str, LatentModel], names=None) -> list:
    """The training segments of ``models`` (all, or those in ``names``) as motions."""
    out = []
    for k in sorted(models if names is None else names):
        m = models[k]
        train = m.training_motion()
        train.positions()  # once per model: each take keeps its rows
        for seg in np.unique(m.segments_):
            rows = np.flatnonzero(m.segments_ == seg)
            if rows.size >= 3:
                out.append(train[rows])
    return out


def script_quality(syn, motion, commands: list, feet=None) -> tuple[dict | None, list[str]]:
    """The measure of generated motion (:mod:`cyclecoord.quality.generated`) against the
    training segments of the models the script used (over several, each model's figures
    weighted by the frames it made: :func:`~cyclecoord.quality.generated.mixed_reference`),
    IDLE frames counted as asked holds.

    The motion is found in the analysis rig once (:func:`~cyclecoord.rig.analysis_motion`:
    a model's output is in its training takes' rig, which the model was fitted in), and
    its sections are measured as slices of it."""
    from ...errors import CycleCoordError
    from ...quality.generated import (
        lead_lines,
        measure_generated,
        mixed_reference,
        source_figures,
    )
    from ...rig import analysis_motion

    motion = analysis_motion(motion)

    figures: dict = {}  # the sources' figures, once per set of models
    takes_seen: dict = {}  # each take's own figures, once (source_figures' cache)
    own: dict = {}  # each model's training takes

    def measured(names) -> tuple[list, Any]:
        key = tuple(sorted(names))
        if key not in figures:  # (each model's takes made once: the cache knows them)
            for k in key:
                if k not in own:
                    own[k] = training_takes(syn.models, [k])
            takes = [t for k in key for t in own[k]]
            try:
                # (the takes are in the analysis rig: the model was fitted on it)
                figures[key] = (takes, source_figures(takes, motion.fps, feet=feet,
                                                      analysed=True, cache=takes_seen))
            except CycleCoordError:
                figures[key] = (takes, None)  # measured (and refused) as before
        return figures[key]

    hold = syn.hold_mask(motion.n_frames, asked=True)
    sources, ref = measured({c.model for c in syn.chunks})
    runs = model_sections(syn, commands, shortest=0.0)
    sections = [s for s in runs if s["stop"] - s["start"] >= MIN_SECTION * syn.fps]
    # frames each model made, runs too short to be measured on their own counted too, one
    # model alone too (a jog's MOVEs then a TRANSITION to the walk was judged against the
    # walk's and the jog's takes pooled, the walk's many frames setting the slip: "feet
    # gliding (support foot 0.62 m/s, sources 0.06)" for a jog's 0.55), and each blend's
    # frames shared by its models (a walk that went into the run and back was judged
    # against the walk alone)
    made: dict[str, float] = {}
    for sec in runs:
        made[sec["model"]] = made.get(sec["model"], 0) + sec["stop"] - sec["start"]
    for win in transition_windows(syn, commands):
        for k in win["models"]:
            made[k] = made.get(k, 0) + (win["stop"] - win["start"]) / len(win["models"])
    parts = [(measured([k])[1], n) for k, n in sorted(made.items())]
    if ref is not None and parts and all(r is not None for r, _ in parts):
        # the whole motion against each model's takes, weighted by the frames it made
        ref = parts[0][0] if len(parts) == 1 else mixed_reference(parts)
    quality, lines = lead_lines(motion, sources, feet=feet, hold=hold, reference=ref,
                                analysed=True)
    if quality is not None and len({s["model"] for s in sections}) > 1:
        # a walk and a run judged against their pooled captures read the run's pops
        # against a 99th percentile the walk frames pull down: each gait on its own too
        quality["by_model"] = []
        lines.append("  each model's frames against its own training takes:")
        for sec in sections:
            a, b = sec["start"], sec["stop"]
            takes, ref = measured([sec["model"]])
            q, sub = lead_lines(motion[a:b], takes, feet=feet, hold=hold[a:b], reference=ref,
                                analysed=True)
            quality["by_model"].append({**sec, "quality": q})
            lines.append(f"    {sec['model']} frames {a}-{b}: "
                         + sub[0].replace("generated motion: ", ""))
    if quality is not None:
        # the model sections leave the blends out: each TRANSITION's window (and three
        # frames each side) judged against the faster of its two models' takes
        quality["transitions"] = []
        for win in transition_windows(syn, commands):
            a, b = max(win["start"] - 3, 0), min(win["stop"] + 3, motion.n_frames)
            if b - a < 3:
                continue
            pop = min(
                measure_generated(motion[a:b], measured([k])[0], feet=feet,
                                  reference=measured([k])[1], analysed=True).largest_accel
                for k in win["models"]
            )
            quality["transitions"].append({**win, "largest_accel_ratio": float(pop)})
            lines.append(
                f"  TRANSITION {' -> '.join(win['models'])} frames {a}-{b}: largest accel "
                f"{pop:.2f}x the faster model's p99"
            )
    return quality, lines


def transition_windows(syn, commands: list) -> list[dict[str, Any]]:
    """Each TRANSITION's frames ``[{"models": [from, to], "start", "stop"}]``."""
    out: list[dict[str, Any]] = []
    before = None
    for seg in syn.segments():
        k = seg["command"]
        kind = commands[k].get("command") if 0 <= k < len(commands) else None
        if kind == "TRANSITION":
            if out and out[-1]["command"] == k:
                out[-1]["stop"] = seg["stop"]
                if seg["model"] not in out[-1]["models"]:
                    out[-1]["models"].append(seg["model"])
            else:
                models = [before] if before is not None else []
                if seg["model"] not in models:
                    models.append(seg["model"])
                out.append({"command": k, "models": models, "start": seg["start"],
                            "stop": seg["stop"]})
        before = seg["model"]
    return out


def model_sections(syn, commands: list, shortest: float = MIN_SECTION) -> list[dict[str, Any]]:
    """Runs of frames that one model made, TRANSITIONs left out (a blend is two models'),
    of at least ``shortest`` seconds: ``[{"model", "start", "stop"}]``."""
    out: list[dict[str, Any]] = []
    for seg in syn.segments():
        k = seg["command"]
        kind = commands[k].get("command") if 0 <= k < len(commands) else None
        if kind == "TRANSITION":
            out.append({"model": None, "start": seg["start"], "stop": seg["stop"]})
        elif out and out[-1]["model"] == seg["model"] and out[-1]["stop"] == seg["start"]:
            out[-1]["stop"] = seg["stop"]
        else:
            out.append({"model": seg["model"], "start": seg["start"], "stop": seg["stop"]})
    return [s for s in out
            if s["model"] is not None and s["stop"] - s["start"] >= shortest * syn.fps]


@one_blas_thread
def run_script(
    path: str | Path,
    check: bool = True,
    progress: bool = False,
    feet: str | tuple[str, ...] | None = None,
):
    """Run a script: the synthesised :class:`~cyclecoord.motion.Motion` and a report dict.

    BLAS runs on one thread (its many small products and the models' Cholesky
    factorisations ran several times slower threaded on a busy machine: the walk-run
    benchmark script took 11.1 s wall threaded, 3.3 s on one thread).

    Parameters
    ----------
    path : path-like
    check : bool, default True
        Run the plausibility checks (joint ranges against the models' training frames,
        new limb contacts) for the report.
    progress : bool
        A tqdm bar over the commands.
    feet : str or tuple of str, optional
        Foot points for planting, locking and the skating figures: joint names, or the
        command line's ``"LEFT,RIGHT"`` text (:func:`~cyclecoord.quality.legs.feet_names`);
        default the script's ``"feet"`` list, else found.
    """
    from ...quality.legs import feet_names

    p = Path(path)
    spec, models = load_script(p)
    if feet is None and spec.get("feet") is not None:
        feet = tuple(spec["feet"])
    if feet is not None:
        skeleton = models[spec.get("start", {"model": next(iter(models))})["model"]].skeleton_
        try:
            feet = feet_names(skeleton, feet)
        except ParameterError as exc:
            raise _fail(p, "feet", str(exc)) from None
    params = ParticleParams().replace(**(spec.get("particle") or {}))
    syn = Synthesizer(
        models,
        fps=float(spec.get("fps", 30)),
        seed=int(spec.get("seed", 0)),
        params=params,
        bridge_threshold=spec.get("bridge_threshold"),
        plant=spec.get("plant", "all"),
        lock=spec.get("lock_feet", True),
        feet=feet,
        detail=spec.get("gait_detail", True),
    )
    for name, m in models.items():
        if m.gait_stale_:
            syn.notes.append(
                f"model {name!r} ({spec['models'][name]}): its gait phases were saved by an "
                "older cyclecoord and are computed again on every load (an extract per "
                "segment); fit it again, or load and save it (LatentModel.load(p).save(p)), "
                "to keep them")
    start = spec.get("start", {"model": next(iter(models))})
    t0 = time.perf_counter()
    try:
        syn.start(start["model"], start.get("at"))
    except ParameterError as exc:
        raise _fail(p, "start", str(exc)) from None
    commands = spec["commands"]
    if progress:
        from tqdm import tqdm

        iterator = tqdm(list(enumerate(commands)), desc="commands", unit="cmd", delay=2.0)
    else:
        iterator = enumerate(commands)
    for i, c in iterator:
        kind = c["command"].upper()
        syn.command = i
        args = {k: v for k, v in c.items() if k != "command"}
        following = commands[i + 1]["command"].upper() if i + 1 < len(commands) else None
        try:
            if kind == "MOVE":
                # a chain flows: the particle slows down only before IDLE, PLAY or the end
                syn.move(**args, stop=following not in ("MOVE", "TRANSITION"))
            elif kind == "IDLE":
                syn.idle(**args)
            elif kind == "TRANSITION":
                syn.transition(**args)
            else:
                syn.play(**args)
        except ParameterError as exc:
            raise _fail(p, f"commands[{i}] ({c['command']})", str(exc)) from None
    total = time.perf_counter() - t0
    motion = syn.motion()
    feet = syn.feet_of(motion)  # named, or found once for the whole script
    quality, quality_lines = script_quality(syn, motion, commands, feet)
    report: dict[str, Any] = {
        "motion_quality": quality,
        "motion_quality_lines": quality_lines,
        "notes": list(syn.notes),
        "script": str(p),
        "fps": syn.fps,
        "seed": syn.seed,
        "frames": motion.n_frames,
        "duration_s": motion.duration,
        "models": {k: m.describe() for k, m in models.items()},
        "output_skeleton_from": syn.skeleton_model,
        "commands": syn.segments(),
        "transitions": syn.events,
        "clamped_to_training_range": syn.clamped,
        "foot_skating": skating_report(motion, feet=feet),
        "stands": syn.stand_steps,
        "bridges": {f"{a}->{b}": br.to_dict() for (a, b), br in syn.bridges_found().items()},
        "timing": {
            "total_s": total,
            "particle_and_pose_s": syn.sim_seconds,
            "particle_and_pose_cpu_s": syn.sim_cpu_seconds,
            "frames_per_second": motion.n_frames / syn.sim_seconds if syn.sim_seconds > 0 else None,
            "frames_per_cpu_second": motion.n_frames / syn.sim_cpu_seconds
            if syn.sim_cpu_seconds > 0
            else None,
        },
    }
    sizes = {round(m.skeleton_.total_length(), 6) for m in models.values()}
    if len(sizes) > 1:
        report["notes"] += [
            "the models' skeletons have the same joints but different bone lengths; "
            f"the output uses {syn.skeleton_model!r}'s"
        ]
    if check:
        from ...quality.plausibility import check_plausibility

        used = {c.model for c in syn.chunks}
        refs = [models[k].training_motion() for k in sorted(used)]
        report["plausibility"] = check_plausibility(
            motion, refs, cache=syn._plausibility, analysed=True).to_dict()
    return motion, report
