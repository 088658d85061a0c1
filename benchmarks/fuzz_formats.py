#!/usr/bin/env python
"""Mutation fuzzer for the inputs added after the first five readers: glTF (its JSON and its
binary chunk), USD (usda text, and usdc through usd-core), latent models and animation
scripts (issue 26 part 3).

Usage::

    python benchmarks/fuzz_formats.py --fmt gltf --start 100000 --n 5000 --workers 2
    python benchmarks/fuzz_formats.py --fmt script --dump 123      # write case 123's files

Every mutator starts from small valid files the project writes itself (:func:`make_seeds`:
a walk of the built-in example as .glb, .gltf + .bin, .usda and .usdc, a latent model fitted
on it and a script using it).  Case ``i`` of format ``F`` is generated from
``random.Random(f"{F}:{i}")`` alone, so any case can be made again.  Each case writes its
files into a folder and runs the real command lines on them, in-process through
:func:`cyclecoord.cli.main.main`: ``convert`` and one of ``extract``, ``feet`` and ``view``
for glTF and USD, ``animate`` (under ``--memory-limit 256M``) for models and scripts.  A worker process runs the cases
under an address-space limit; a case fails on any exception that escapes ``main`` (a
traceback: an error that is not the project's one-line error), on a hang (more than
``--timeout`` seconds), on a worker that dies, or when an input file was changed.

Results go to ``<out>/results/<fmt>.jsonl`` and the summary line to stdout; the files of
failing cases to ``<out>/failures/<fmt>/<index>/``.
"""

from __future__ import annotations

import argparse
import base64
import contextlib
import hashlib
import io
import copy
import json
import multiprocessing as mp
import os
import random
import re
import resource
import shutil
import signal
import struct
import sys
import time
import traceback
import warnings
from dataclasses import dataclass, field
from multiprocessing.connection import wait
from pathlib import Path

FORMATS = ("gltf", "usd", "model", "script")
#: --memory-limit of every animate case (see make_case).
ANIMATE_MEMORY = "256M"

# ------------------------------------------------------------------------------ values
HOSTILE_NUMBERS = [
    0, -0.0, 1, -1, 2, 3, 0.5, 1e-7, -1e-7, 1e-300, 5e-324, 1e12, -1e12, 1e300, -1e300,
    float("nan"), float("inf"), float("-inf"), 2**31, 2**32, 2**53 + 1, 2**63, 2**64, -(2**63),
    10**30, 4096, 4097, 10_000_001, 1_000_000_000,
]
HOSTILE_VALUES = [
    None, True, False, "", "x", "NaN", "1e309", "\u0000", "\U0001F600" * 3, [], {}, [None],
    [[]], {"a": None}, [1, 2], [0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1], [[1, 0, 0], [0, 1, 0]],
    "A" * 5000,
]
BAD_FLOATS = [float("nan"), float("inf"), float("-inf"), 1e38, -1e38, 3.4e38, 0.0, -0.0, 1e-45,
              1e9, 123456.0, -1.0]
USDA_NUMBERS = ["nan", "inf", "-inf", "1e308", "-1e308", "1e9", "0", "-1", "1e-300", "99999999999",
                "3.4e38", "-0", "1e12", "7"]


def hostile_value(rng: random.Random):
    """A number or a value of another type that a reader must refuse or take."""
    if rng.random() < 0.55:
        v = rng.choice(HOSTILE_NUMBERS)
        return -v if rng.random() < 0.1 and isinstance(v, (int, float)) else v
    if rng.random() < 0.1:
        value: list = []
        for _ in range(rng.choice([10, 70, 300])):
            value = [value]
        return value
    # a copy: a list or dict placed twice in one case (or mutated later) must not be shared,
    # nor change the constant for the cases after it (it made a script nest inside itself)
    return copy.deepcopy(rng.choice(HOSTILE_VALUES))


# ------------------------------------------------------------------------------ bytes
def byte_flip(rng, data: bytes) -> tuple[bytes, str]:
    if not data:
        return data, "byte_flip(empty)"
    b = bytearray(data)
    k = rng.randint(1, 8)
    for _ in range(k):
        i = rng.randrange(len(b))
        b[i] = b[i] ^ (1 << rng.randrange(8)) if rng.random() < 0.5 else rng.randrange(256)
    return bytes(b), f"byte_flip x{k}"


def truncate(rng, data: bytes) -> tuple[bytes, str]:
    i = rng.randrange(len(data) + 1) if data else 0
    return data[:i], f"truncate@{i}"


def splice(rng, data: bytes) -> tuple[bytes, str]:
    """Duplicate, delete or zero a run of bytes."""
    if not data:
        return data, "splice(empty)"
    a = rng.randrange(len(data))
    n = rng.randint(1, min(4096, len(data) - a))
    kind = rng.choice(["dup", "del", "zero", "ff"])
    if kind == "dup":
        return data[: a + n] + data[a : a + n] + data[a + n :], f"dup {a}+{n}"
    if kind == "del":
        return data[:a] + data[a + n :], f"del {a}+{n}"
    fill = b"\0" if kind == "zero" else b"\xff"
    return data[:a] + fill * n + data[a + n :], f"{kind} {a}+{n}"


def mutate_bytes(rng, data: bytes) -> tuple[bytes, str]:
    return rng.choice([byte_flip, byte_flip, truncate, splice])(rng, data)


# ------------------------------------------------------------------------------ JSON
def _paths(doc, limit: int = 20000) -> list[tuple]:
    """Paths (tuples of keys and indices) to every value of a JSON document."""
    out: list[tuple] = []
    stack = [((), doc)]
    while stack and len(out) < limit:
        path, v = stack.pop()
        out.append(path)
        if isinstance(v, dict):
            stack.extend((path + (k,), x) for k, x in v.items())
        elif isinstance(v, list):
            stack.extend((path + (k,), x) for k, x in enumerate(v))
    return out


def _get(doc, path):
    for k in path:
        doc = doc[k]
    return doc


def mutate_json(rng, doc, prefer: tuple[str, ...] = ()) -> tuple[object, str]:
    """One structural or value change anywhere in a JSON document (``prefer``: keys whose
    subtrees are picked more often)."""
    paths = _paths(doc)
    chosen = [p for p in paths if any(k in p for k in prefer)] if prefer else []
    path = rng.choice(chosen if chosen and rng.random() < 0.6 else paths)
    if not path:
        return hostile_value(rng), "document replaced"
    parent = _get(doc, path[:-1])
    key = path[-1]
    old = parent[key]
    kind = rng.random()
    if kind < 0.45:
        parent[key] = hostile_value(rng)
        what = "value"
    elif kind < 0.6 and isinstance(old, (int, float)) and not isinstance(old, bool):
        parent[key] = rng.choice([old + 1, old - 1, -old, old * 1000, old / 1000, old * 1e9,
                                  len(str(old))])
        what = "nudge"
    elif kind < 0.7:
        if isinstance(parent, dict):
            del parent[key]
        else:
            parent.pop(key)
        what = "delete"
    elif kind < 0.8 and isinstance(parent, list):
        parent.insert(key, json.loads(json.dumps(old)))
        what = "duplicate"
    elif kind < 0.87 and isinstance(old, list) and old:
        del old[rng.randrange(len(old)) :]
        what = "truncate list"
    elif kind < 0.93 and isinstance(old, list):
        old.extend(json.loads(json.dumps(old)) * rng.choice([1, 10]))
        what = "grow list"
    elif isinstance(old, str):
        parent[key] = rng.choice(["", old * 3, old[::-1], old + "\u0000", "x" + old])
        what = "string"
    else:
        parent[key] = [old] if rng.random() < 0.5 else {"v": old}
        what = "wrap"
    return doc, f"json {what} at {'/'.join(map(str, path))[:80]}"


def dump_json(rng, doc) -> bytes:
    text = json.dumps(doc, allow_nan=True, indent=rng.choice([None, 1]))
    if rng.random() < 0.02:  # deeper than any recursive parser goes
        depth = rng.choice([2000, 100_000])
        text = '{"deep": ' + "[" * depth + text + "]" * depth + "}"
    return text.encode("utf-8")


# ------------------------------------------------------------------------------ glTF
def glb_split(data: bytes) -> tuple[dict, bytes]:
    (n,) = struct.unpack("<I", data[12:16])
    doc = json.loads(data[20 : 20 + n])
    (m,) = struct.unpack("<I", data[20 + n : 24 + n])
    return doc, data[28 + n : 28 + n + m]


def glb_join(text: bytes, blob: bytes) -> bytes:
    text += b" " * (-len(text) % 4)
    blob += b"\0" * (-len(blob) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text
    body += struct.pack("<I4s", len(blob), b"BIN\0") + blob
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def mutate_blob(rng, doc: dict, blob: bytes) -> tuple[bytes, str]:
    """Hostile floats into one accessor's values (key times, translations, quaternions,
    matrices), or raw bytes of the binary chunk changed."""
    accessors = doc.get("accessors") or []
    views = doc.get("bufferViews") or []
    if rng.random() < 0.25 or not accessors:
        return mutate_bytes(rng, blob)
    k = rng.randrange(len(accessors))
    acc = accessors[k]
    try:
        view = views[acc["bufferView"]]
        start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        count = acc["count"] * {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}[acc["type"]]
    except (KeyError, IndexError, TypeError):
        return mutate_bytes(rng, blob)
    if acc.get("componentType") != 5126 or count == 0:
        return mutate_bytes(rng, blob)
    b = bytearray(blob)
    kind = rng.choice(["one", "run", "all", "scale", "reverse"])
    if kind == "reverse":
        vals = list(struct.unpack_from(f"<{count}f", b, start))
        struct.pack_into(f"<{count}f", b, start, *vals[::-1])
    elif kind == "scale":
        factor = rng.choice([0.0, 1e-7, 1e7, -1.0, 1e30])
        vals = [v * factor for v in struct.unpack_from(f"<{count}f", b, start)]
        vals = [max(min(v, 3.4e38), -3.4e38) for v in vals]
        struct.pack_into(f"<{count}f", b, start, *vals)
    else:
        n = {"one": 1, "run": min(count, rng.randint(2, 16)), "all": count}[kind]
        a = rng.randrange(count - n + 1)
        value = rng.choice(BAD_FLOATS)
        struct.pack_into(f"<{n}f", b, start + 4 * a, *([value] * n))
    return bytes(b), f"blob accessor {k} {kind}"


def gltf_case(rng, seeds: dict) -> tuple[dict[str, bytes], str, list[str]]:
    """Files of one glTF case and the name of the capture."""
    log = []
    if rng.random() < 0.7:  # .glb: the JSON chunk, the binary chunk or the container
        doc, blob = glb_split(seeds["seed.glb"])
        where = rng.random()
        if where < 0.55:
            for _ in range(rng.choice([1, 1, 2, 3])):
                doc, what = mutate_json(rng, doc, ("extras", "accessors", "bufferViews", "nodes",
                                                   "animations", "skins"))
                log.append(what)
            data = glb_join(dump_json(rng, doc), blob)
        elif where < 0.85:
            blob, what = mutate_blob(rng, doc, blob)
            log.append(what)
            data = glb_join(dump_json(rng, doc), blob)
        else:
            data, what = mutate_bytes(rng, seeds["seed.glb"])
            log.append("container " + what)
        return {"case.glb": data}, "case.glb", log
    doc = json.loads(seeds["seed.gltf"])
    blob = seeds["seed.bin"]
    if rng.random() < 0.7:
        for _ in range(rng.choice([1, 1, 2])):
            doc, what = mutate_json(rng, doc, ("extras", "accessors", "buffers", "nodes"))
            log.append(what)
    else:
        blob, what = mutate_blob(rng, doc, blob)
        log.append(what)
    if rng.random() < 0.1 and isinstance(doc, dict) and doc.get("buffers"):
        try:  # the buffer inline, as a data URI (sometimes broken)
            uri = "data:application/octet-stream;base64," + base64.b64encode(blob).decode()
            if rng.random() < 0.5:
                uri = uri[: rng.randrange(len(uri))] + rng.choice(["@", "=", "", "%%"])
            doc["buffers"][0]["uri"] = uri
            log.append("data uri")
        except (TypeError, KeyError, IndexError):
            pass
    return {"case.gltf": dump_json(rng, doc), "case.bin": blob}, "case.gltf", log


# ------------------------------------------------------------------------------ USD
_USDA_NUMBER = re.compile(r"-?\d+(?:\.\d*)?(?:e[-+]?\d+)?")


def mutate_usda(rng, text: str) -> tuple[str, str]:
    kind = rng.random()
    if kind < 0.25:  # stage metadata
        key = rng.choice(["startTimeCode", "endTimeCode", "timeCodesPerSecond", "framesPerSecond",
                          "metersPerUnit"])
        value = rng.choice(USDA_NUMBERS)
        new, n = re.subn(rf"{key} = [^\n]*", f"{key} = {value}", text, count=1)
        return new, f"{key} = {value}" if n else "metadata (none)"
    if kind < 0.4:  # the customData JSON
        a = text.find("string cyclecoord = '")
        if a >= 0:
            a += len("string cyclecoord = '")
            b = text.index("'", a)
            try:
                doc = json.loads(text[a:b])
                doc, what = mutate_json(rng, doc, ("skeleton", "channels", "start_frame"))
                body = json.dumps(doc, allow_nan=True).replace("'", "")
            except ValueError:
                body, what = "{", "broken"
            if rng.random() < 0.15:
                body = rng.choice(["{not json", "[" * 500, "", "null", "1e999"])
                what = f"customData {body[:10]!r}"
            return text[:a] + body + text[b:], f"customData {what}"
    if kind < 0.65:  # numbers in arrays and time samples
        spans = [m.span() for m in _USDA_NUMBER.finditer(text)]
        out = text
        k = rng.randint(1, 6)
        for a, b in sorted(rng.sample(spans, min(k, len(spans))), reverse=True):
            out = out[:a] + rng.choice(USDA_NUMBERS) + out[b:]
        return out, f"numbers x{k}"
    if kind < 0.8:  # arrays shortened or emptied
        starts = [m.end() for m in re.finditer(r"\[\s*[\"(]", text)]
        if starts:
            a = rng.choice(starts) - 1
            b = text.find("]", a)
            if b > a:
                inner = text[a:b]
                cut = rng.randrange(len(inner) + 1)
                if rng.random() < 0.5:
                    cut = 0
                return text[:a] + inner[:cut].rsplit(",", 1)[0] + text[b:], "array cut"
    lines = text.split("\n")
    i = rng.randrange(len(lines))
    op = rng.choice(["delete", "duplicate", "swap"])
    if op == "delete":
        del lines[i]
    elif op == "duplicate":
        lines.insert(i, lines[i])
    else:
        j = rng.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
    return "\n".join(lines), f"line {op} {i}"


def mutate_usdc(rng, seed: bytes, work: Path) -> tuple[bytes, str]:
    """A crate changed through usd-core (attributes, metadata, arrays), or its bytes."""
    if rng.random() < 0.3:
        return mutate_bytes(rng, seed)
    from pxr import Gf, Sdf, Usd, Vt

    src = work / "seed.usdc"
    src.write_bytes(seed)
    layer = Sdf.Layer.FindOrOpen(str(src))
    layer.Reload(force=True)
    stage = Usd.Stage.Open(layer)
    skel = stage.GetPrimAtPath("/Motion/Skeleton")
    anim = stage.GetPrimAtPath("/Motion/Skeleton/Animation")
    kind = rng.choice(["time", "rotations", "translations", "joints", "custom", "scales", "rest"])
    what = kind
    if kind == "time":
        v = rng.choice([float("nan"), float("inf"), -5.0, 1e9, 5e6, 0.0, 1e-300, 19.5])
        getattr(stage, rng.choice(["SetEndTimeCode", "SetStartTimeCode", "SetTimeCodesPerSecond"]))(v)
        what += f" {v}"
    elif kind in ("rotations", "translations", "scales"):
        attr = anim.GetAttribute(kind)
        times = attr.GetTimeSamples() or [Usd.TimeCode.Default()]
        t = rng.choice(times)
        value = list(attr.Get(t))
        if value:
            j = rng.randrange(len(value))
            bad = rng.choice(BAD_FLOATS)
            if kind == "rotations":
                value[j] = Gf.Quatf(bad, Gf.Vec3f(bad if rng.random() < 0.5 else 0, 0, 0))
            elif kind == "translations":
                value[j] = Gf.Vec3f(bad, 0, 0)
            else:
                value[j] = Gf.Vec3h(bad, 1, 1)
            if rng.random() < 0.2:
                value = value[: rng.randrange(len(value))]
        attr.Set(type(attr.Get(t))(value), t)
        if rng.random() < 0.2:
            attr.Set(type(attr.Get(t))(value), rng.choice([1e6, -3.0, 0.5]))
    elif kind == "joints":
        prim = rng.choice([skel, anim])
        attr = prim.GetAttribute("joints")
        joints = list(attr.Get())
        op = rng.choice(["empty", "cut", "dup", "rename", "reverse"])
        if op == "empty":
            joints = []
        elif op == "cut":
            joints = joints[: rng.randrange(len(joints))]
        elif op == "dup":
            joints.append(joints[rng.randrange(len(joints))])
        elif op == "rename":
            joints[rng.randrange(len(joints))] = rng.choice(["", "a/b", "root", "x" * 300])
        else:
            joints = joints[::-1]
        attr.Set(Vt.TokenArray(joints))
        what += f" {op}"
    elif kind == "custom":
        raw = skel.GetCustomDataByKey("cyclecoord")
        try:
            doc, w = mutate_json(rng, json.loads(raw), ("skeleton", "channels"))
            new = json.dumps(doc, allow_nan=True)
        except (ValueError, TypeError):
            new, w = raw, "unchanged"
        if rng.random() < 0.2:
            skel.SetCustomDataByKey("cyclecoord", rng.choice([5, 1.5, "{x", "[" * 300]))
            w = "replaced"
        else:
            skel.SetCustomDataByKey("cyclecoord", new)
        what += f" {w}"
    else:
        attr = skel.GetAttribute(rng.choice(["restTransforms", "bindTransforms"]))
        value = list(attr.Get())
        if value:
            value[rng.randrange(len(value))] = Gf.Matrix4d(rng.choice(BAD_FLOATS))
        attr.Set(Vt.Matrix4dArray(value))
    out = work / "mutated.usdc"
    stage.GetRootLayer().Export(str(out))
    return out.read_bytes(), f"usdc {what}"


def usd_case(rng, seeds: dict, work: Path) -> tuple[dict[str, bytes], str, list[str]]:
    if rng.random() < 0.6:
        text = seeds["seed.usda"].decode("utf-8")
        log = []
        for _ in range(rng.choice([1, 1, 2])):
            text, what = mutate_usda(rng, text)
            log.append(what)
        data = text.encode("utf-8")
        if rng.random() < 0.1:
            data, what = mutate_bytes(rng, data)
            log.append(what)
        return {"case.usda": data}, "case.usda", log
    data, what = mutate_usdc(rng, seeds["seed.usdc"], work)
    return {"case.usdc": data}, "case.usdc", [what]


# ------------------------------------------------------------------------------ models
def _npz_bytes(arrays: dict) -> bytes:
    import numpy as np

    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def mutate_model(rng, seed: bytes) -> tuple[bytes, str]:
    import numpy as np

    if rng.random() < 0.25:  # the archive itself
        data, what = mutate_bytes(rng, seed)
        return data, "zip " + what
    with np.load(io.BytesIO(seed), allow_pickle=False) as npz:
        arrays = {k: npz[k] for k in npz.files}
    key = rng.choice(sorted(arrays))
    a = arrays[key]
    kind = rng.choice(["value", "values", "shape", "dtype", "delete", "empty", "json", "swap",
                       "scale"])
    if kind == "value" and a.size and a.dtype.kind in "fiu":
        b = a.astype(float).copy()
        b.reshape(-1)[rng.randrange(b.size)] = rng.choice(BAD_FLOATS + [1e300, -1e300])
        arrays[key] = b if a.dtype.kind == "f" else b.astype(a.dtype) if np.isfinite(b).all() else b
    elif kind == "values" and a.size and a.dtype.kind in "fiu":
        arrays[key] = np.full(a.shape, rng.choice([0, -1, 1e9, np.nan, 7]), dtype=a.dtype
                              if a.dtype.kind == "f" else float)
    elif kind == "scale" and a.dtype.kind == "f":
        arrays[key] = a * rng.choice([0.0, -1.0, 1e-300, 1e300, 1e6])
    elif kind == "shape":
        op = rng.choice(["cut", "grow", "flat", "extra", "transpose"])
        if op == "cut" and a.ndim and a.shape[0]:
            arrays[key] = a[: rng.randrange(a.shape[0])]
        elif op == "grow" and a.ndim:
            arrays[key] = np.concatenate([a, a[: rng.randint(1, 5)]]) if a.shape[0] else a
        elif op == "flat":
            arrays[key] = a.reshape(-1)
        elif op == "extra":
            arrays[key] = a[..., None]
        else:
            arrays[key] = a.T
    elif kind == "dtype":
        arrays[key] = rng.choice([a.astype(str), a.astype(bool) if a.dtype.kind != "U" else a,
                                  np.array(a.tolist(), dtype=object).astype(str)])
    elif kind == "delete":
        del arrays[key]
    elif kind == "empty":
        arrays[key] = np.zeros((0,) + a.shape[1:], dtype=a.dtype)
    elif kind == "json" and a.dtype.kind == "U" and a.ndim == 0:
        try:
            doc, what = mutate_json(rng, json.loads(str(a)))
            arrays[key] = np.array(json.dumps(doc, allow_nan=True))
            kind = what
        except ValueError:
            arrays[key] = np.array(rng.choice(["", "{", "[" * 1000]))
    else:
        other = rng.choice(sorted(arrays))
        arrays[key], arrays[other] = arrays[other], a
        kind = f"swap with {other}"
    return _npz_bytes(arrays), f"model array {key}: {kind}"


SCRIPT = {
    "fps": 30,
    "seed": 0,
    "models": {"a": "m.npz", "b": "m2.npz"},
    "start": {"model": "a", "at": {"frame": 2}},
    "particle": {"radius": 0.15, "random": 2},
    "plant": "transitions",
    "commands": [
        {"command": "IDLE", "duration": 0.2},
        {"command": "MOVE", "to": {"segment": "b", "time": 0.2}, "path": "graph"},
        {"command": "IDLE", "at": [{"frame": 3}, {"frame": 9}], "duration": 0.3, "hover": 0.1},
        {"command": "TRANSITION", "to": "b", "blend": 0.2},
        {"command": "PLAY", "segment": "w2", "start": 0, "stop": 0.2},
        {"command": "MOVE", "to": [0.1, 0.0, 0.0], "duration": 0.2, "speed": 1.0},
    ],
}


def model_case(rng, seeds: dict) -> tuple[dict[str, bytes], str, list[str]]:
    data, what = mutate_model(rng, seeds["m.npz"])
    spec = json.loads(json.dumps(SCRIPT))
    spec["commands"] = [c for c in spec["commands"] if c["command"] != "TRANSITION"]
    spec["commands"][3]["segment"] = "a"
    spec["models"] = {"a": "m.npz"}
    return {"m.npz": data, "s.json": json.dumps(spec).encode()}, "s.json", [what]


def script_case(rng, seeds: dict) -> tuple[dict[str, bytes], str, list[str]]:
    spec = json.loads(json.dumps(SCRIPT))
    log = []
    if rng.random() < 0.1:
        data, what = mutate_bytes(rng, json.dumps(spec).encode())
        log.append(what)
    else:
        for _ in range(rng.choice([1, 1, 1, 2, 3])):
            spec, what = mutate_json(rng, spec, ("commands",))
            log.append(what)
        data = dump_json(rng, spec)
    files = {"s.json": data, "m.npz": seeds["m.npz"], "m2.npz": seeds["m2.npz"]}
    if rng.random() < 0.05:  # a model that is something else
        files["m2.npz"] = rng.choice([b"", b"PK\x03\x04", seeds["seed.glb"], seeds["m.npz"][:500]])
        log.append("m2.npz replaced")
    return files, "s.json", log


# ------------------------------------------------------------------------------ cases
@dataclass
class Case:
    fmt: str
    index: int
    files: dict[str, bytes]
    commands: list[list[str]]
    log: list[str] = field(default_factory=list)


def make_case(fmt: str, index: int, seeds: dict, work: Path) -> Case:
    """Case ``index`` of ``fmt``: its files (names relative to the case folder) and the
    command lines (``{d}`` the case folder, ``{o}`` the output folder)."""
    rng = random.Random(f"{fmt}:{index}")
    work.mkdir(parents=True, exist_ok=True)  # the usdc mutator saves its stage there
    if fmt in ("gltf", "usd"):
        files, name, log = (
            gltf_case(rng, seeds) if fmt == "gltf" else usd_case(rng, seeds, work)
        )
        second = rng.choice([
            ["feet", "{d}/" + name],
            ["extract", "{d}/" + name, "--report", "{o}/r.json"],
            ["view", "{d}/" + name, "-o", "{o}/v.html"],
            ["convert", "{d}/" + name, "-o", "{o}/c.glb"],
            ["latent", "fit", "{d}/" + name, "-o", "{o}/m.npz", "--step", "1", "--max-iter", "5",
             "--no-progress"],
        ])
        commands = [["convert", "{d}/" + name, "-o", "{o}/c.npz"], second]
    else:
        files, name, log = model_case(rng, seeds) if fmt == "model" else script_case(rng, seeds)
        commands = [["animate", "{d}/s.json", "-o", "{o}/a.bvh", "--report", "{o}/a.json"]]
        if rng.random() < 0.5:
            commands[0].append("--no-check")
        # a script may ask for any duration up to the frame limit (an IDLE of 4096 s is
        # 122,880 frames and minutes of work, valid and not a hang): the memory limit
        # bounds what one case may make (the frames a 256 MB limit allows take seconds)
        # (and no progress bar: a terminal redraws it, captured it reads as extra lines)
        commands[0] += ["--memory-limit", ANIMATE_MEMORY, "--no-progress"]
    return Case(fmt, index, files, commands, log)


def make_seeds(folder: Path) -> dict[str, bytes]:
    """The valid files every mutator starts from, written by cyclecoord itself."""
    import cyclecoord as cc
    from cyclecoord.cli.main import main

    folder.mkdir(parents=True, exist_ok=True)
    walk = cc.datasets.example_capture().motion
    short = walk[:24]
    cc.save(short, folder / "seed.glb")
    cc.save(short, folder / "seed.gltf")
    seeds = {}
    try:
        cc.save(short, folder / "seed.usda")
        cc.save(short, folder / "seed.usdc")
    except cc.errors.CycleCoordError:  # usd-core missing: no USD cases
        pass
    capture = cc.datasets.make_periodic_capture(kind="walk", n_frames=160, random_state=0).motion
    cc.save(capture, folder / "walk.bvh")
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        for out, takes in (("m.npz", ["walk.bvh:0:80=a", "walk.bvh:80:160=b"]),
                           ("m2.npz", ["walk.bvh:20:120=w2"])):
            code = main(["latent", "fit", *[str(folder / t) for t in takes], "-o",
                         str(folder / out), "--max-iter", "15"])
            assert code == 0, out
    for name in ("seed.glb", "seed.gltf", "seed.bin", "seed.usda", "seed.usdc", "m.npz", "m2.npz"):
        if (folder / name).exists():
            seeds[name] = (folder / name).read_bytes()
    if "seed.bin" in seeds:  # the .gltf names its buffer seed.bin; cases name it case.bin
        seeds["seed.gltf"] = seeds["seed.gltf"].replace(b'"seed.bin"', b'"case.bin"')
    return seeds


# ------------------------------------------------------------------------------ running
def _signature(exc: BaseException) -> str:
    frames = traceback.extract_tb(exc.__traceback__)
    own = [f for f in frames if "cyclecoord" in f.filename]
    inner = own[-1] if own else (frames[-1] if frames else None)
    where = f"{Path(inner.filename).name}:{inner.lineno}:{inner.name}" if inner else "?"
    return f"{type(exc).__name__}@{where}"


class _Captured:
    text = ""


@contextlib.contextmanager
def _native_stderr():
    """What is written to file descriptor 2 in the body (by C and C++ code such as
    usd-core's diagnostics, which ``sys.stderr`` does not see), as ``.text``."""
    import tempfile

    out = _Captured()
    sys.__stderr__.flush()
    with tempfile.TemporaryFile() as fh:
        saved = os.dup(2)
        os.dup2(fh.fileno(), 2)
        try:
            yield out
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            fh.seek(0)
            out.text = fh.read().decode("utf-8", "replace")


def run_case(case: Case, work: Path) -> dict:
    """Write the case's files, run its command lines in-process; the outcome."""
    from cyclecoord.cli.main import main

    d, o = work / "case", work / "out"
    for folder in (d, o):
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
    for name, data in case.files.items():
        (d / name).write_bytes(data)
    digest = {n: hashlib.sha256(data).hexdigest() for n, data in case.files.items()}
    rec: dict = {"fmt": case.fmt, "id": case.index, "muts": case.log, "codes": []}
    t0 = time.perf_counter()
    for argv in case.commands:
        argv = [a.replace("{d}", str(d)).replace("{o}", str(o)) for a in argv]
        err = io.StringIO()
        try:
            with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()), \
                    contextlib.redirect_stderr(err), _native_stderr() as native:
                warnings.simplefilter("ignore")
                code = main(argv)
        except KeyboardInterrupt:
            raise
        except BaseException as exc:  # noqa: BLE001 - what escapes main is the finding
            rec["cls"] = "memory" if isinstance(exc, MemoryError) else "traceback"
            rec["command"] = argv[0]
            rec["exc"] = f"{type(exc).__name__}: {str(exc)[:300]}"
            rec["sig"] = _signature(exc)
            rec["tb"] = [
                f"{Path(f.filename).name}:{f.lineno} {f.name}"
                for f in traceback.extract_tb(exc.__traceback__)[-5:]
            ]
            break
        rec["codes"].append(code)
        lines = [m for m in (err.getvalue() + native.text).splitlines() if m.strip()]
        if code == 1:
            # a refusal: one line on stderr (nothing printed by a library besides) that
            # names a file of the case
            if len(lines) == 1 and lines[0].startswith("cyclecoord: error: "):
                rec.setdefault("errors", []).append(lines[0][:300])
                if str(work) not in lines[0]:
                    rec["unnamed"] = True  # names no file of the case: worth a look
            else:
                rec["cls"] = "bad_refusal"
                rec["command"] = argv[0]
                rec["stderr"] = [m[:300] for m in lines[:6]]
                break
        elif code not in (0, 3):
            rec["cls"] = "bad_exit"
            rec["command"] = argv[0]
            rec["stderr"] = [m[:300] for m in lines[:6]]
            break
    else:
        rec["cls"] = "ok"
    for name, h in digest.items():
        f = d / name
        if not f.is_file() or hashlib.sha256(f.read_bytes()).hexdigest() != h:
            rec["cls"] = "input_modified"
            rec["file"] = name
    rec["t"] = round(time.perf_counter() - t0, 3)
    return rec


def _worker(conn, wid: int, out: Path, fmt: str, memory: int) -> None:
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    # folders of this format and worker: runs of other formats may share ``out``
    work = out / "work" / f"{fmt}-w{wid}"
    seeds = make_seeds(out / "seeds" / f"{fmt}-w{wid}")
    while True:
        msg = conn.recv()
        if msg is None:
            return
        try:
            case = make_case(fmt, msg, seeds, work)
        except Exception as exc:  # noqa: BLE001 - a generator bug, not a reader outcome
            conn.send({"fmt": fmt, "id": msg, "cls": "gen_error", "exc": repr(exc)[:300]})
            continue
        conn.send(run_case(case, work))


class _Slot:
    def __init__(self, wid: int, out: Path, fmt: str, memory: int) -> None:
        self.args = (wid, out, fmt, memory)
        self.start()

    def start(self) -> None:
        self.conn, child = mp.Pipe()
        self.proc = mp.get_context("fork").Process(target=_worker, args=(child, *self.args),
                                                   daemon=True)
        self.proc.start()
        child.close()
        self.case = None
        self.t0 = 0.0
        self.ready = False  # seeds written (the first case's clock starts after them)

    def kill(self) -> None:
        with contextlib.suppress(ProcessLookupError):
            os.kill(self.proc.pid, signal.SIGKILL)
        self.proc.join()
        self.conn.close()


FAILURES = ("traceback", "memory", "hang", "crash", "input_modified", "gen_error", "bad_refusal",
            "bad_exit")


def run(fmt: str, start: int, n: int, workers: int = 2, timeout: float = 60.0,
        out: Path = Path("fuzz-out"), memory: int = 4 * 1024**3, quiet: bool = False) -> dict:
    """Cases ``start .. start + n - 1`` of ``fmt``; the summary (counts per outcome)."""
    out = Path(out).resolve()
    (out / "results").mkdir(parents=True, exist_ok=True)
    slots = [_Slot(k, out, fmt, memory) for k in range(max(1, workers))]
    todo = iter(range(start, start + n))
    counts: dict[str, int] = {}
    failures: list[dict] = []
    t_start = time.time()
    with open(out / "results" / f"{fmt}.jsonl", "a") as fh:

        def emit(rec: dict) -> None:
            fh.write(json.dumps(rec) + "\n")
            counts[rec["cls"]] = counts.get(rec["cls"], 0) + 1
            if rec["cls"] in FAILURES:
                failures.append(rec)
                _save_failure(out, fmt, rec)

        def feed(slot: _Slot) -> bool:
            i = next(todo, None)
            if i is None:
                slot.conn.send(None)
                return False
            slot.case, slot.t0 = i, time.perf_counter()
            slot.conn.send(i)
            return True

        active = [s for s in slots if feed(s)]
        first = {id(s): True for s in slots}
        while active:
            ready = wait([s.conn for s in active], timeout=0.2)
            now = time.perf_counter()
            for s in list(active):
                if s.conn in ready:
                    try:
                        rec = s.conn.recv()
                    except (EOFError, OSError):  # the worker died
                        rec = {"fmt": fmt, "id": s.case, "cls": "crash",
                               "exitcode": s.proc.exitcode}
                        s.kill()
                        s.start()
                    first[id(s)] = False
                    emit(rec)
                    if not feed(s):
                        active.remove(s)
                # a worker's first case includes writing its seeds (fitting two models)
                elif now - s.t0 > timeout * (3 if first[id(s)] else 1):
                    emit({"fmt": fmt, "id": s.case, "cls": "hang", "t": round(now - s.t0, 1)})
                    s.kill()
                    s.start()
                    first[id(s)] = True
                    if not feed(s):
                        active.remove(s)
    for s in slots:
        s.proc.join(timeout=10)
        if s.proc.is_alive():
            s.kill()
    summary = {
        "fmt": fmt, "start": start, "n": n, "wall_s": round(time.time() - t_start, 1),
        "counts": counts, "failures": len(failures),
        "signatures": sorted({f.get("sig") or f["cls"] for f in failures}),
    }
    if not quiet:
        print(json.dumps(summary), flush=True)
    return summary


def _save_failure(out: Path, fmt: str, rec: dict) -> None:
    folder = out / "failures" / fmt / str(rec["id"])
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "result.json").write_text(json.dumps(rec, indent=1))


def dump(fmt: str, index: int, out: Path) -> Path:
    """Write case ``index``'s files and command lines into ``<out>/dump/<fmt>_<index>``."""
    out = Path(out).resolve()
    seeds = make_seeds(out / "seeds" / "dump")
    folder = out / "dump" / f"{fmt}_{index}"
    case = make_case(fmt, index, seeds, out / "work" / "dump")
    folder.mkdir(parents=True, exist_ok=True)
    for name, data in case.files.items():
        (folder / name).write_bytes(data)
    lines = [" ".join(["cyclecoord"] + [a.replace("{d}", str(folder))
                                         .replace("{o}", str(folder / "out")) for a in argv])
             for argv in case.commands]
    (folder / "commands.txt").write_text("\n".join(lines + ["# " + "; ".join(case.log)]) + "\n")
    return folder


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fmt", required=True, choices=FORMATS)
    ap.add_argument("--start", type=int, default=0)
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds a case may take")
    ap.add_argument("--memory", type=float, default=4.0, help="GiB of address space a worker has")
    ap.add_argument("--out", default="fuzz-out", help="results, failures and work files")
    ap.add_argument("--dump", type=int, help="write this case's files and commands, and stop")
    args = ap.parse_args(argv)
    if args.dump is not None:
        print(dump(args.fmt, args.dump, Path(args.out)))
        return 0
    summary = run(args.fmt, args.start, args.n, args.workers, args.timeout, Path(args.out),
                  int(args.memory * 1024**3))
    return 1 if summary["failures"] else 0


if __name__ == "__main__":
    sys.exit(main())
