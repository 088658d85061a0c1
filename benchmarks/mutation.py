"""Mutation score of the tests over periodic/, quality/, io's readers and writers (issue 27) and
synthesis/carry.py (the feet that carry generated motion, issue 24).

A small AST mutation tester of our own, rather than mutmut or cosmic-ray: it samples the
mutants deterministically (every k-th of a fixed order, so a run of a few hundred fits in
an hour or two on 2 cores, where all of them would take days), and runs for each mutant
only the tests of the mutated module (``TESTS`` below), stopping at the first failure.
mutmut 3 runs the whole suite once to map tests to functions and has no sampling;
cosmic-ray needs a session database and one configuration per module to select tests.

Each mutant changes one thing in one module: an arithmetic operator (``+ -``, ``* /``,
``// /``, ``% //``, ``** *``, and the same in ``+=``...), a comparison (``< <=``,
``> >=``, ``== !=``, ``is``/``is not``, ``in``/``not in``), ``and``/``or``, a dropped
``not`` or unary minus, a number (an int n to n + 1, a float x to 2x, 0.0 to 1.0) or a
boolean constant.  Strings, docstrings, f-strings (messages), annotations and ``__all__``
are left alone.  The mutated module is written (``ast.unparse``) into a private copy of
``src/`` that the tests import through ``PYTHONPATH``; no ``.pyc`` is written or read
there, so no stale bytecode hides a mutant.

A mutant is *killed* when its tests fail (or run past the time limit: a mutant that
hangs is caught too), *survives* when they pass.  Survivors judged equivalent (no test
could tell: the behaviour is the same) are listed in ``mutation_equivalent.json`` with
why; the score is killed over the mutants not judged equivalent.

    python benchmarks/mutation.py --list                  # mutants per module
    python benchmarks/mutation.py --every 25 --jobs 2 --out mutation.json
    python benchmarks/mutation.py --report mutation.json  # score, survivors
    python benchmarks/mutation.py --show ID               # one mutant's diff
    python benchmarks/mutation.py --run ID [--tests T..]  # one mutant: killed or not

Not part of the test suite: a sampled run takes an hour or more.
"""

from __future__ import annotations

import argparse
import ast
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
EQUIVALENT = Path(__file__).resolve().parent / "mutation_equivalent.json"

P, Q, IO = "cyclecoord/periodic/", "cyclecoord/quality/", "cyclecoord/io/"
T = "tests/"
COORDS = [T + "periodic/test_coordinates.py", T + "periodic/test_landmarks.py", T + "periodic/test_rips.py",
          T + "periodic/test_estimator_conventions.py"]
PIPE = [T + "periodic/test_windings.py", T + "periodic/test_pipeline.py"]  # fast first: -x stops early
ASFAMC = [T + "io/test_asfamc_known.py", T + "io/test_asfamc.py", T + "io/test_convert.py", T + "io/test_hostile_files.py"]

#: Module (under src/) -> the tests that are its own (run for each of its mutants).
TESTS: dict[str, list[str]] = {
    P + "_cochain.py": [T + "periodic/test_cochain_known.py", T + "periodic/test_barcode_known.py"] + COORDS,
    P + "_estimator.py": COORDS,
    P + "_kernel.py": [T + "periodic/test_density.py", T + "periodic/test_cycle.py"],
    P + "_rips.py": [T + "periodic/test_barcode_known.py"] + COORDS + [T + "periodic/test_memory_guard.py"],
    P + "barcode.py": [T + "periodic/test_barcode_known.py"] + COORDS,
    P + "clip.py": [T + "periodic/test_clip_known.py"] + PIPE + [T + "periodic/test_planted_travel.py",
                                                             T + "quality/test_cycle_figures.py"],
    P + "coordinates.py": [T + "periodic/test_barcode_known.py", T + "periodic/test_cochain_known.py"] + COORDS,
    P + "cycle.py": [T + "periodic/test_cycle.py"],
    P + "density.py": [T + "periodic/test_density.py"],
    P + "fitting.py": [T + "periodic/test_fitting_known.py"] + PIPE,
    P + "landmarks.py": [T + "periodic/test_landmarks_known.py"] + COORDS + [T + "periodic/test_memory_guard.py"],
    P + "phase_model.py": [T + "periodic/test_phase_model_known.py", T + "periodic/test_landmarks.py"],
    P + "pipeline.py": [T + "periodic/test_pipeline_known.py"] + PIPE,
    P + "preprocess.py": [T + "periodic/test_preprocess.py", T + "periodic/test_rotations.py"],
    P + "registration.py": [T + "periodic/test_registration_known.py", T + "periodic/test_windings.py",
                            T + "periodic/test_pipeline.py"],
    P + "results.py": [T + "periodic/test_pipeline_known.py"] + PIPE,
    P + "root.py": [T + "periodic/test_root_known.py", T + "periodic/test_root.py", T + "periodic/test_pipeline.py"],
    P + "rotations.py": [T + "periodic/test_rotations_known.py", T + "periodic/test_rotations.py"],
    P + "steady.py": [T + "periodic/test_steady_known.py", T + "periodic/test_steady.py"],
    P + "suggest.py": [T + "periodic/test_suggest.py"],
    P + "windings.py": PIPE,
    **{P + "detection/" + m: [T + "periodic/test_detect_known.py", T + "periodic/test_detect.py"]
       for m in ("_segments.py", "classes.py", "cycles.py", "detector.py", "scoring.py")},
    P + "detection/result.py": [T + "periodic/test_detect.py"],
    P + "detection/windows.py": [T + "periodic/test_windows.py", T + "periodic/test_detect.py"],
    Q + "contacts.py": [T + "quality/test_contacts.py"],
    Q + "cycle_quality.py": [T + "quality/test_cycle_quality_known.py", T + "quality/test_reference.py",
                             T + "quality/test_cycle_figures.py"],
    Q + "generated.py": [T + "quality/test_generated.py"],
    Q + "legs.py": [T + "quality/test_legs.py", T + "quality/test_contacts.py"],
    Q + "metrics.py": [T + "quality/test_metrics.py", T + "quality/test_one_definition.py"],
    Q + "plausibility.py": [T + "quality/test_plausibility.py"],
    Q + "pose_space.py": [T + "quality/test_pose_space.py"],
    Q + "reference.py": [T + "quality/test_reference.py", T + "quality/test_cycle_figures.py"],
    IO + "_acclaim.py": ASFAMC,
    IO + "amc_read.py": ASFAMC,
    IO + "asf_read.py": ASFAMC,
    IO + "asfamc_write.py": ASFAMC,
    IO + "bvh.py": [T + "io/test_bvh_known.py", T + "io/test_bvh.py", T + "io/test_convert.py", T + "io/test_hostile_files.py"],
    IO + "gltf.py": [T + "io/test_gltf_write.py", T + "io/test_gltf.py", T + "io/test_rig_export.py", T + "io/test_hostile_gltf_usd.py"],
    IO + "gltf_read.py": [T + "io/test_gltf_read.py", T + "io/test_gltf.py", T + "io/test_rig_export.py", T + "io/test_hostile_gltf_usd.py"],
    IO + "tabular.py": [T + "io/test_tabular_known.py", T + "io/test_tabular.py", T + "io/test_hostile_files.py"],
    IO + "usd.py": [T + "io/test_usd_read.py", T + "io/test_usd.py", T + "io/test_rig_export.py", T + "io/test_hostile_gltf_usd.py"],
    "cyclecoord/synthesis/carry.py": [T + "synthesis/test_carry_known.py", T + "synthesis/test_footlock.py",
                                      T + "synthesis/test_latent_gait.py"],
}

_BINOP = {ast.Add: ast.Sub, ast.Sub: ast.Add, ast.Mult: ast.Div, ast.Div: ast.Mult,
          ast.FloorDiv: ast.Div, ast.Mod: ast.FloorDiv, ast.Pow: ast.Mult}
_CMP = {ast.Lt: ast.LtE, ast.LtE: ast.Lt, ast.Gt: ast.GtE, ast.GtE: ast.Gt, ast.Eq: ast.NotEq,
        ast.NotEq: ast.Eq, ast.Is: ast.IsNot, ast.IsNot: ast.Is, ast.In: ast.NotIn, ast.NotIn: ast.In}
_BOOL = {ast.And: ast.Or, ast.Or: ast.And}


@dataclass
class Mutant:
    module: str
    index: int  # among the module's mutants, in the order of candidates()
    line: int
    col: int
    operator: str
    #: 2, 3... for the later mutants that would share an id (``a - b - c`` has two
    #: subtractions at one column, ``1 <= n <= T`` two comparisons): their id ends ``#2``...
    dup: int = 0

    @property
    def id(self) -> str:
        plain = f"{self.module}:{self.line}:{self.col}:{self.operator}"
        return f"{plain}#{self.dup}" if self.dup else plain


def _sites(tree: ast.AST) -> list[tuple[ast.AST, str, object]]:
    """Every mutation site of a module, in a fixed order: (node, operator name, detail)."""
    out: list[tuple[ast.AST, str, object]] = []

    def visit(node: ast.AST, skip: bool) -> None:
        if isinstance(node, ast.JoinedStr):  # messages
            return
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            for d in node.decorator_list:
                visit(d, skip)
            for d in node.args.defaults + [d for d in node.args.kw_defaults if d is not None]:
                visit(d, skip)
            for stmt in node.body:
                visit(stmt, skip)
            return  # annotations left alone
        if isinstance(node, ast.AnnAssign):
            if node.value is not None:
                visit(node.value, skip)
            return
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets
        ):
            return
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant):
            return  # docstrings
        if isinstance(node, ast.If) and _is_main_guard(node):
            return
        if not skip:
            if isinstance(node, ast.BinOp) and type(node.op) in _BINOP:
                out.append((node, f"{type(node.op).__name__}->{_BINOP[type(node.op)].__name__}", None))
            elif isinstance(node, ast.AugAssign) and type(node.op) in _BINOP:
                out.append((node, f"{type(node.op).__name__}=->{_BINOP[type(node.op)].__name__}=", None))
            elif isinstance(node, ast.Compare):
                for k, op in enumerate(node.ops):
                    if type(op) in _CMP:
                        out.append((node, f"{type(op).__name__}->{_CMP[type(op)].__name__}", k))
            elif isinstance(node, ast.BoolOp):
                out.append((node, f"{type(node.op).__name__}->{_BOOL[type(node.op)].__name__}", None))
            elif isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.Not, ast.USub)):
                out.append((node, f"drop {type(node.op).__name__}", None))
            elif isinstance(node, ast.Constant):
                v = node.value
                if isinstance(v, bool):
                    out.append((node, f"{v}->{not v}", None))
                elif isinstance(v, (int, float)) and not isinstance(v, complex):
                    out.append((node, f"{v!r}->{_number(v)!r}", None))
        for child in ast.iter_child_nodes(node):
            visit(child, skip)

    visit(tree, False)
    return out


def _is_main_guard(node: ast.If) -> bool:
    t = node.test
    return (isinstance(t, ast.Compare) and isinstance(t.left, ast.Name) and t.left.id == "__name__")


def _number(v):
    if isinstance(v, int):
        return v + 1
    return 1.0 if v == 0 else 2.0 * v


class _Replace(ast.NodeTransformer):
    def __init__(self, target: ast.AST, new: ast.AST):
        self.target, self.new = target, new

    def generic_visit(self, node):
        if node is self.target:
            return self.new
        return super().generic_visit(node)


def mutate(source: str, index: int) -> str:
    """The module's source with its ``index``-th mutation applied."""
    tree = ast.parse(source)
    node, op, detail = _sites(tree)[index]
    if isinstance(node, (ast.BinOp, ast.AugAssign)):
        node.op = _BINOP[type(node.op)]()
    elif isinstance(node, ast.Compare):
        node.ops[detail] = _CMP[type(node.ops[detail])]()
    elif isinstance(node, ast.BoolOp):
        node.op = _BOOL[type(node.op)]()
    elif isinstance(node, ast.UnaryOp):
        tree = _Replace(node, node.operand).visit(tree)
    elif isinstance(node, ast.Constant):
        node.value = (not node.value) if isinstance(node.value, bool) else _number(node.value)
    return ast.unparse(ast.fix_missing_locations(tree))


def mutants(modules: list[str]) -> list[Mutant]:
    out = []
    for module in modules:
        tree = ast.parse((SRC / module).read_text())
        seen: dict[str, int] = {}
        for i, (node, op, _) in enumerate(_sites(tree)):
            m = Mutant(module, i, node.lineno, node.col_offset, op)
            seen[m.id] = seen.get(m.id, 0) + 1
            if seen[m.id] > 1:
                m.dup = seen[m.id]
            out.append(m)
    return out


# ----------------------------------------------------------------------------- running
def _env(copy_src: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(copy_src), PYTHONDONTWRITEBYTECODE="1",
               MPLBACKEND="Agg", OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1",
               MKL_NUM_THREADS="1")
    return env


def run_tests(copy_src: Path, tests: list[str], timeout: float) -> tuple[str, float, str]:
    """('passed' | 'failed' | 'timeout', seconds, first failure line)."""
    cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", "-o",
           "addopts=", *tests]
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(cmd, cwd=ROOT, env=_env(copy_src), capture_output=True, text=True,
                              timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout", time.perf_counter() - t0, ""
    seconds = time.perf_counter() - t0
    first = next((ln for ln in proc.stdout.splitlines() if ln.startswith(("FAILED", "ERROR"))), "")
    return ("passed" if proc.returncode == 0 else "failed"), seconds, first


class Worker:
    """A private copy of src/ for one mutant at a time."""

    def __init__(self, base: Path, k: int):
        self.src = base / f"w{k}" / "src"
        shutil.copytree(SRC, self.src, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))

    def run(self, m: Mutant, timeout: float, tests: list[str] | None = None) -> dict:
        path = self.src / m.module
        original = path.read_text()
        try:
            path.write_text(mutate(original, m.index))
            status, seconds, first = run_tests(self.src, tests or TESTS[m.module], timeout)
        finally:
            path.write_text(original)
        killed = status != "passed"
        return dict(asdict(m), id=m.id, status=status, killed=killed, seconds=round(seconds, 1),
                    failure=first)


def baseline(base: Path, modules: list[str]) -> dict[str, float]:
    """Seconds each module's tests take unmutated (they must pass)."""
    w = Worker(base, "baseline")
    times = {}
    for tests in sorted({tuple(TESTS[m]) for m in modules}):
        status, seconds, first = run_tests(w.src, list(tests), 3600)
        if status != "passed":
            sys.exit(f"the tests {' '.join(tests)} fail before any mutation: {first}")
        times[tests] = seconds
        print(f"baseline {seconds:6.1f} s  {' '.join(t.removeprefix('tests/') for t in tests)}",
              flush=True)
    return {m: times[tuple(TESTS[m])] for m in modules}


def score(results: list[dict]) -> dict:
    equivalent = json.loads(EQUIVALENT.read_text()) if EQUIVALENT.is_file() else {}
    judged = [r for r in results if not r["killed"] and r["id"] in equivalent]
    counted = [r for r in results if r["id"] not in equivalent or r["killed"]]
    killed = sum(r["killed"] for r in counted)
    return {
        "mutants": len(results),
        "killed": killed,
        "timeouts": sum(r["status"] == "timeout" for r in results),
        "equivalent": len(judged),
        "survived": [r for r in counted if not r["killed"]],
        "score": killed / len(counted) if counted else float("nan"),
        "equivalent_reasons": {r["id"]: equivalent[r["id"]] for r in judged},
    }


def report(results: list[dict]) -> None:
    s = score(results)
    print(f"{s['mutants']} mutants: {s['killed']} killed ({s['timeouts']} by the time limit), "
          f"{s['equivalent']} judged equivalent, {len(s['survived'])} survived; "
          f"score {100 * s['score']:.1f} % of the non-equivalent mutants killed")
    by_module: dict[str, list[int]] = {}
    for r in results:
        by_module.setdefault(r["module"], [0, 0])
        by_module[r["module"]][0] += 1
        by_module[r["module"]][1] += r["killed"]
    for m, (n, k) in sorted(by_module.items()):
        print(f"  {m:40s} {k:4d} / {n:<4d} killed")
    for r in s["survived"]:
        print(f"  survived {r['id']}")
    for mid, why in s["equivalent_reasons"].items():
        print(f"  equivalent {mid}: {why}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--modules", nargs="*", default=None, help="modules under src/ (default all)")
    ap.add_argument("--every", type=int, default=25, help="take every k-th mutant (25)")
    ap.add_argument("--offset", type=int, default=0, help="start at this mutant of each k")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--out", type=Path, default=None, help="JSON results (resumed if present)")
    ap.add_argument("--list", action="store_true", help="count the mutants and stop")
    ap.add_argument("--report", type=Path, default=None, help="print the score of a results file")
    ap.add_argument("--show", default=None, help="print the diff of one mutant id")
    ap.add_argument("--run", default=None, help="run the tests of one mutant id (exit 0 if killed)")
    ap.add_argument("--tests", nargs="+", default=None,
                    help="with --run: these tests (pytest ids) instead of the module's own")
    args = ap.parse_args(argv)
    if args.report:
        report(json.loads(args.report.read_text())["results"])
        return 0
    modules = args.modules or sorted(TESTS)
    every = mutants(modules)
    one = args.show or args.run
    if one:
        found = [m for m in every if m.id == one]
        if not found:
            sys.exit(f"no mutant {one!r} in the current source (see --list; ids carry line numbers)")
        (m,) = found
    if args.run:
        base = Path(tempfile.mkdtemp(prefix="mutation-"))
        try:
            r = Worker(base, 0).run(m, timeout=3600, tests=args.tests)
        finally:
            shutil.rmtree(base, ignore_errors=True)
        print(f"{'killed' if r['killed'] else 'SURVIVED'} {m.id} ({r['seconds']} s) {r['failure']}")
        return 0 if r["killed"] else 1
    if args.show:
        original = ast.unparse(ast.parse((SRC / m.module).read_text())).splitlines()
        changed = mutate((SRC / m.module).read_text(), m.index).splitlines()
        import difflib

        print("\n".join(difflib.unified_diff(original, changed, m.module, m.id, lineterm="", n=2)))
        return 0
    if args.list:
        counts: dict[str, int] = {}
        for m in every:
            counts[m.module] = counts.get(m.module, 0) + 1
        for mod, n in sorted(counts.items()):
            print(f"{n:6d} {mod}")
        print(f"{len(every):6d} mutants; every {args.every}th: {len(every[args.offset::args.every])}")
        return 0
    chosen = every[args.offset :: args.every]
    done = {}
    if args.out and args.out.is_file():
        done = {r["id"]: r for r in json.loads(args.out.read_text())["results"]}
    todo = [m for m in chosen if m.id not in done]
    print(f"{len(chosen)} mutants sampled (every {args.every}th of {len(every)}), {len(todo)} to run",
          flush=True)
    base = Path(tempfile.mkdtemp(prefix="mutation-"))
    try:
        limits = baseline(base, sorted({m.module for m in todo}))
        workers = [Worker(base, k) for k in range(args.jobs)]
        free = list(workers)
        results = dict(done)

        def one(m: Mutant) -> dict:
            w = free.pop()
            try:
                return w.run(m, timeout=3 * limits[m.module] + 30)
            finally:
                free.append(w)

        t0 = time.perf_counter()
        with ThreadPoolExecutor(args.jobs) as pool:
            for i, r in enumerate(pool.map(one, todo), 1):
                results[r["id"]] = r
                print(f"[{i}/{len(todo)} {time.perf_counter() - t0:7.0f} s] "
                      f"{'killed  ' if r['killed'] else 'SURVIVED'} {r['id']} ({r['seconds']} s)",
                      flush=True)
                if args.out:
                    args.out.write_text(json.dumps({
                        "command": " ".join([Path(sys.argv[0]).name, *(argv or sys.argv[1:])]),
                        "every": args.every, "offset": args.offset, "total_mutants": len(every),
                        "results": [results[m.id] for m in chosen if m.id in results],
                    }, indent=1))
        report([results[m.id] for m in chosen if m.id in results])
    finally:
        shutil.rmtree(base, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
