"""`make mutants`: run the fixed physics mutants of ``catalogue.toml`` against the tests.

Each mutant is applied to a *copy* of ``src/`` in a temporary directory (the real sources
are never written, so an interrupted run leaves them intact), imported through
``PYTHONPATH`` and checked by ``pytest -x`` on the mutant's suite of tests. A mutant is

- ``killed`` when a test fails or errors in its set-up (the first one is reported),
- ``SURVIVED`` when the suite passes,
- ``DID NOT APPLY`` when its text is not found exactly once in the sources (the sources
  changed; update the catalogue), or ``ERROR`` when pytest could not run the suite
  (collection error, crash, time-out).

Anything but ``killed`` fails the run. Before the mutants, every test the mutants name
must pass on the unmutated copy (this also fills each worker's caches).

Caches: the generated C of a machine is cached under ``$WINDER_CACHE_DIR``, keyed by a hash
of the source of ``winder/model``, ``winder/parts`` and ``winder/forces``; the C
integrators' objects (``solve/c/``) and each machine's library are keyed by the hash of
their own sources, so a mutant of the integrators builds its own. Every mutant gets its
own fresh cache directory (deleted afterwards), so no mutant runs code generated or
compiled from another source: a mutant of the generated sources starts with an empty
cache; the others start from a copy of the worker's unmutated cache.
The Pinocchio/CasADi generator of ``model/pin_casadi.py`` (built once
under the virtual environment, ``winder-pin-casadi``) is shared: it is Pinocchio's
algorithms, not winder's physics (``model/_pin_casadi.cpp`` is not mutated: a changed
source rebuilds it, ~160 s of g++ per mutant).
Never the project's own caches.

Usage: ``python tests/mutants/run.py [--jobs N] [--only SUBSTRING ...] [--list]
[--catalogue FILE]``
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CATALOGUE = Path(__file__).with_name("catalogue.toml")
#: Sources the generated code is keyed by (a mutant there must not see the clean cache).
GENERATED = ("src/winder/model/", "src/winder/parts/", "src/winder/forces/")
KINDS = {"drop": lambda x: "0.0", "double": lambda x: f"2.0 * ({x})",
         "flip": lambda x: f"-({x})"}
TIMEOUT = 300.0  # [s] per mutant
RUNNING: set[subprocess.Popen] = set()  # pytest processes, killed if the run is interrupted


@dataclass
class Mutant:
    """One mutant: text edits ``(file, find, replace)`` and the tests that must kill it."""

    name: str
    tests: list[str]
    edits: list[tuple[str, str, str]]
    status: str = ""
    killer: str = ""
    seconds: float = 0.0
    detail: list[str] = field(default_factory=list)

    @property
    def files(self) -> str:
        return ", ".join(dict.fromkeys(Path(f).name for f, _, _ in self.edits))

    @property
    def generated(self) -> bool:
        """An edit of the sources the generated code is keyed by."""
        return any(f.startswith(GENERATED) for f, _, _ in self.edits)


def _term_edits(spec: list[dict], kind: str) -> list[tuple[str, str, str]]:
    edits = []
    for e in spec:
        line, expr = e["line"], e["expr"]
        if line.count(expr) != 1:
            raise SystemExit(f"catalogue: expr {expr!r} must occur once in line {line!r}")
        new = e.get(kind, KINDS[kind](expr))
        edits.append((e["file"], line, line.replace(expr, new)))
    return edits


def _tests(entry: dict, suites: dict[str, list[str]]) -> list[str]:
    """The tests of a catalogue entry: its ``suite`` (a name of ``[suites]``) and/or its
    own ``tests`` (pytest node ids), in that order."""
    name = entry["name"]
    if "suite" in entry and entry["suite"] not in suites:
        raise SystemExit(f"catalogue: {name} names unknown suite {entry['suite']!r}")
    tests = list(suites.get(entry.get("suite", ""), [])) + list(entry.get("tests", []))
    if not tests:
        raise SystemExit(f"catalogue: {name} names no tests (suite or tests)")
    return list(dict.fromkeys(tests))


def load(path: Path = CATALOGUE) -> list[Mutant]:
    """The expanded list of mutants of the catalogue."""
    cat = tomllib.loads(path.read_text(encoding="utf-8"))
    suites = cat.get("suites", {})
    mutants = []
    for term in cat.get("term", []):
        spec = term.get("edits") or [{k: term[k] for k in ("file", "line", "expr", *KINDS)
                                      if k in term}]
        for kind in term.get("kinds", list(KINDS)):
            if kind not in KINDS:
                raise SystemExit(f"catalogue: term {term['name']}: kind {kind!r} is not one "
                                 f"of {', '.join(KINDS)}")
            mutants.append(Mutant(f"{term['name']}.{kind}", _tests(term, suites),
                                  _term_edits(spec, kind)))
    for m in cat.get("mutant", []):
        mutants.append(Mutant(m["name"], _tests(m, suites),
                              [(e["file"], e["find"], e["replace"]) for e in m["edits"]]))
    names = [m.name for m in mutants]
    if len(set(names)) != len(names):
        raise SystemExit("catalogue: mutant names repeat: "
                         + ", ".join(sorted({n for n in names if names.count(n) > 1})))
    return mutants


def check_applies(m: Mutant) -> bool:
    """Every edit's text is in the real sources exactly once (else: did not apply)."""
    for file, find, _ in m.edits:
        n = (ROOT / file).read_text(encoding="utf-8").count(find)
        if n != 1:
            m.status = "DID NOT APPLY"
            m.detail.append(f"{file}: {find!r} found {n} times (expected once)")
    return not m.detail


class Worker:
    """A private copy of ``src/`` and the cache (generated C, integrators, libraries) of its
    unmutated code."""

    def __init__(self, base: Path, index: int) -> None:
        self.dir = base / f"w{index}"
        self.src = self.dir / "src"
        self.clean_cache = self.dir / "cache-clean"
        shutil.copytree(ROOT / "src", self.src, copy_function=shutil.copy2,
                        ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))

    def restore(self, files: list[str]) -> None:
        for f in files:  # copy2 keeps the original stamp, so the clean cache stays valid
            shutil.copy2(ROOT / f, self.dir / f)

    def run(self, tests: list[str], cache: Path) -> tuple[int, str, float]:
        """pytest on ``tests`` with the cache under ``cache`` (``winder``)."""
        env = dict(os.environ, PYTHONPATH=str(self.src), WINDER_MUTANT_SRC=str(self.src),
                   WINDER_CACHE_DIR=str(cache / "winder"),
                   PYTHONDONTWRITEBYTECODE="1")
        cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-rfE", "--no-header",
               "-p", "no:cacheprovider", *tests]
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True)
        RUNNING.add(p)
        try:
            out, _ = p.communicate(timeout=TIMEOUT)
            rc = p.returncode
        except subprocess.TimeoutExpired:
            p.kill()
            out, _ = p.communicate()
            rc, out = -1, f"timed out after {TIMEOUT:.0f} s\n{out}"
        finally:
            RUNNING.discard(p)
        return rc, out, time.perf_counter() - t0

    def mutate(self, m: Mutant) -> None:
        files = list(dict.fromkeys(f for f, _, _ in m.edits))
        cache = self.dir / f"cache-{m.name}"
        try:
            for file, find, replace in m.edits:
                path = self.dir / file
                text = path.read_text(encoding="utf-8")
                path.write_text(text.replace(find, replace, 1), encoding="utf-8")
            # its own caches: empty, or a copy of the unmutated ones where they cannot
            # depend on the edit
            subs = [] if m.generated else ["winder"]
            for sub in subs:
                if (self.clean_cache / sub).is_dir():
                    shutil.copytree(self.clean_cache / sub, cache / sub, symlinks=True)
            rc, out, m.seconds = self.run(m.tests, cache)
        finally:
            self.restore(files)
            shutil.rmtree(cache, ignore_errors=True)
        # a failing test, or one whose set-up fails on the mutant (e.g. a scene the mutated
        # nip law cannot carry is refused by the loader the fixture calls)
        failed = re.findall(r"^(?:FAILED|ERROR) (\S+)", out, re.M)
        if rc == 1 and failed:
            m.status, m.killer = "killed", failed[0]
        elif rc == 0:
            m.status = "SURVIVED"
        else:
            m.status = "ERROR"
            m.detail.append(f"pytest exit status {rc}")
            m.detail += out.strip().splitlines()[-15:]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1),
                    help="mutants run in parallel (default: 2, or 1 on one CPU)")
    ap.add_argument("--only", nargs="*", default=[], help="run mutants whose name contains "
                    "one of these strings")
    ap.add_argument("--list", action="store_true", help="list the mutants and exit")
    ap.add_argument("--catalogue", type=Path, default=CATALOGUE, help="the mutants "
                    "(default: %(default)s)")
    args = ap.parse_args(argv)
    mutants = load(args.catalogue)
    if args.only:
        mutants = [m for m in mutants if any(s in m.name for s in args.only)]
    if args.list:
        for m in mutants:
            print(f"{m.name:36s} {m.files:24s} {' '.join(m.tests)}")
        return 0
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))  # run the clean-up below
    t_start = time.perf_counter()
    todo = [m for m in mutants if check_applies(m)]
    # the slowest mutants first, so that the last ones do not run alone
    todo.sort(key=lambda m: -len(m.tests))
    jobs = max(1, min(args.jobs, len(todo)))
    base = Path(tempfile.mkdtemp(prefix="winder-mutants-"))
    pool = ThreadPoolExecutor(jobs)
    try:
        workers = [Worker(base, i) for i in range(jobs)]
        # the tests must pass without a mutant (this also fills each worker's clean caches)
        tests = list(dict.fromkeys(t for m in todo for t in m.tests))
        base_runs = list(pool.map(lambda w: w.run(tests, w.clean_cache), workers))
        for rc, out, _ in base_runs:
            if rc != 0:
                print(out)
                print(f"mutants: the tests fail on the unmutated sources (status {rc}); "
                      "fix the tests first", file=sys.stderr)
                return 1
        print(f"baseline: {len(tests)} tests pass unmutated ({base_runs[0][2]:.0f} s)",
              flush=True)
        free = list(workers)

        def one(m: Mutant) -> Mutant:
            w = free.pop()
            try:
                w.mutate(m)
            finally:
                free.append(w)
            print(f"  {m.name:36s} {m.status:8s} {m.seconds:6.1f} s", flush=True)
            return m

        list(pool.map(one, todo))
    finally:  # also on Ctrl-C / SIGTERM: stop the tests, drop the copies
        pool.shutdown(wait=False, cancel_futures=True)
        for p in list(RUNNING):
            p.kill()
        pool.shutdown(wait=True)
        shutil.rmtree(base, ignore_errors=True)
    total = time.perf_counter() - t_start
    print()
    print(f"| {'mutant':36s} | {'file':32s} | {'killed by (test id)':84s} | time |")
    print(f"|{'-' * 38}|{'-' * 34}|{'-' * 86}|------|")
    for m in mutants:
        who = m.killer if m.status == "killed" else f"** {m.status} **"
        print(f"| {m.name:36s} | {m.files:32s} | {who:84s} | {m.seconds:4.0f} |")
    bad = [m for m in mutants if m.status != "killed"]
    for m in bad:
        print(f"\n{m.name}: {m.status}")
        for line in m.detail:
            print(f"    {line}")
    cpu = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(f"\n{len(mutants) - len(bad)} of {len(mutants)} mutants killed in {total:.0f} s "
          f"({jobs} jobs; the tests used {cpu.ru_utime + cpu.ru_stime:.0f} s of CPU)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
