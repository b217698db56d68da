"""The compiled machine (issue #23): this tree side by side with a baseline checkout, in one
run on one machine (writes docs/compiled_machine.md and .json).

Measures, each taken alternately on this tree and on the baseline (A, B, A, B, ...), so
both see the same load:

- **paper cycle, in process**: ``simulate`` of ``models/paper_winding.toml`` (700 s,
  DOPRI5, its tolerances); the integration alone (``result.meta["wall_time"]``), best of
  the repeats, after a warm-up run;
- **two-drum cycle, in process**: the same for ``models/two_drum_winder.toml``;
- **overhead per evaluation above the generated rhs**: ``wall / (nfev · t_rhs) − 1``,
  ``t_rhs`` the generated rhs's mean cost over 100 states of the run, each timed in a
  compiled loop (the C loop of the machine's library here, the numba loop in a baseline
  that has numba);
- **``winder run`` paper cycle, whole process**: ``winder run models/paper_winding.toml
  --out r.npz`` from start to exit, median of the repeats;
- **``import winder.cli`` plus parsing a scene**: ``python -c "import winder.cli, winder;
  winder.load_scene(...)"``, median;
- **compile time added per machine by the integrators** (this tree only): in an empty
  cache the integrators' objects (once per installation), each machine's generated object,
  then its library relinked alone (what the integrators add per machine).

Run:  python benchmarks/compiled_machine.py [--baseline DIR] [--repeats N] [--quick]

``DIR``: a checkout of the baseline commit with its own ``.venv`` (``make venv`` there);
without it only this tree is measured.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from winder.io.files import atomic_write_all

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
SCENES = {"paper": "models/paper_winding.toml", "two_drum": "models/two_drum_winder.toml"}

#: Run by each side's interpreter in its own checkout: a cycle's integration time,
#: evaluations and the generated rhs's cost per evaluation in a compiled loop.
_CYCLE = r"""
import json, math, sys, time
import numpy as np
import winder
from winder.solve import integrators as integ
from winder.solve.system import MachineSystem
scene = winder.load_scene(sys.argv[1])
repeats = int(sys.argv[2])
winder.simulate(scene)  # warm-up: build or load the machine, the kernels
walls, cpus, nfev = [], [], 0
for _ in range(repeats):
    c0 = time.process_time()
    res = winder.simulate(scene)
    cpus.append(time.process_time() - c0)
    walls.append(res.meta["wall_time"])
    nfev = res.meta["rhs_evaluations"]
system = MachineSystem(scene)
fns, table, p = system.fns, system.table, system.params
lib = getattr(system, "kernels", None)
if lib is not None:
    dopri5 = lib.dopri5
    def modes(t, y, m):
        lib.modes(fns, table, t, y, p, m, contact_auto=False)
    def loop(which, t, y, m, out, count):
        return lib.repeat(fns, which, count, t, y, p, m, out)
else:  # a baseline with the numba kernels
    from numba import njit
    try:  # the numba DOPRI5's module: solve/dopri5.py (3f69a51), integrators.py (3a29466)
        from winder.solve.dopri5 import dopri5
    except ImportError:
        dopri5 = integ.dopri5
    g = integ.switch_buffer(table)
    def modes(t, y, m):
        integ.modes_of(fns, table, np.empty(1), t, y, p, m, g, False)
    @njit
    def _loop(fns, which, t, y, p, m, out, n):
        tb = np.empty(1)
        acc = 0.0
        for _ in range(n):
            integ.evaluate(fns, which, tb, t, y, p, m, out)
            acc += out[0]
        return acc
    def loop(which, t, y, m, out, count):
        return _loop(fns, which, t, y, p, m, out, count)
# the states of the run (100 samples): the rhs's cost along the trajectory
t_end = float(res.t[-1])
t_out = np.linspace(0.0, t_end, 100)
y = system.initial_state()
Y = np.full((len(y), len(t_out)), np.nan)
stats = np.zeros(5, dtype=np.int64)
m = system.modes.copy()
t, h, k = 0.0, 0.0, 0
while t < t_end:
    status, t, h, k = dopri5(fns, table, t, t_end, y, p, m, scene.solver.rtol,
                             scene.solver.atol, h, math.inf, t_out, Y, k, 10**9, stats)
    if status not in (integ.DONE, integ.PAUSED):
        break
out = np.empty(system.n_states)
count, per_state = 20000, []
for i in range(k):
    yi = np.ascontiguousarray(Y[:, i])
    mi = system.modes.copy()
    modes(float(t_out[i]), yi, mi)
    loop(0, float(t_out[i]), yi, mi, out, 10)
    best = math.inf
    for _ in range(5):
        t0 = time.perf_counter()
        loop(0, float(t_out[i]), yi, mi, out, count)
        best = min(best, time.perf_counter() - t0)
    per_state.append(best / count * 1e6)
print(json.dumps({"wall": min(walls), "walls": walls, "cpu": min(cpus), "cpus": cpus,
                  "nfev": nfev,
                  "rhs_us": float(np.mean(per_state)), "rhs_us_min": float(np.min(per_state)),
                  "rhs_us_max": float(np.max(per_state)), "states": len(per_state)}))
"""

_IMPORT = "import winder.cli, winder; winder.load_scene({scene!r})"

_COMPILE = r"""
import json, sys, time
import winder
from winder.model import codegen
from winder.model.machine import Machine
from winder.solve import cint
t0 = time.perf_counter(); link = cint.link(); t_int = time.perf_counter() - t0
rows = {}
for label, path in json.loads(sys.argv[1]).items():
    machine = Machine(winder.load_scene(path))
    t0 = time.perf_counter(); g = codegen.generate(machine, link=link)
    t_first = time.perf_counter() - t0
    g.path.unlink()
    t0 = time.perf_counter(); codegen.generate(machine, link=link)
    rows[label] = {"generated_and_linked": t_first, "link_only": time.perf_counter() - t0}
print(json.dumps({"integrators": t_int, "machines": rows}))
"""


class Side:
    """One tree: its checkout and its interpreter."""

    def __init__(self, label: str, root: Path) -> None:
        self.label, self.root = label, root
        self.python = root / ".venv" / "bin" / "python"
        if not self.python.exists():
            self.python = Path(sys.executable)
        self.winder = self.python.parent / "winder"
        # each side imports its own tree: a PYTHONPATH inherited from the caller (the shared
        # venv's `PYTHONPATH=$PWD/src`) would make the baseline's interpreter import this
        # tree's winder and the comparison measure this tree against itself
        self.env = {**os.environ, "PYTHONPATH": str(root / "src")}
        found = self.json("import json, winder; print(json.dumps(winder.__file__))")
        if not Path(found).resolve().is_relative_to(root.resolve()):
            raise SystemExit(f"{label}: {self.python} imports winder from {found}, not from "
                             f"{root}")

    def json(self, code: str, *args: str, env: dict[str, str] | None = None) -> Any:
        proc = subprocess.run([str(self.python), "-c", code, *args], cwd=self.root,
                              capture_output=True, text=True, env={**self.env, **(env or {})},
                              check=False)
        if proc.returncode != 0:
            raise SystemExit(f"{self.label}: {proc.stderr[-2000:]}")
        return json.loads(proc.stdout.strip().splitlines()[-1])

    def seconds(self, args: list[str]) -> float:
        t0 = time.perf_counter()
        subprocess.run(args, cwd=self.root, capture_output=True, env=self.env, check=True)
        return time.perf_counter() - t0


def measure(sides: list[Side], repeats: int, process_repeats: int) -> dict[str, Any]:
    out: dict[str, Any] = {s.label: {} for s in sides}
    for name, scene in SCENES.items():
        for _ in range(2):  # alternate: A, B, A, B
            for s in sides:
                row = s.json(_CYCLE, scene, str(repeats))
                best = out[s.label].get(name)
                cpu = row["cpu"] if best is None else min(row["cpu"], best["cpu"])
                if best is None or row["wall"] < best["wall"]:
                    out[s.label][name] = row
                out[s.label][name]["cpu"] = cpu
                print(f"{s.label} {name}: {row['wall']:.3f} s (CPU {row['cpu']:.3f} s), "
                      f"{row['nfev']:,} evaluations, "
                      f"rhs {row['rhs_us']:.3f} µs", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        runs: dict[str, list[float]] = {s.label: [] for s in sides}
        imports: dict[str, list[float]] = {s.label: [] for s in sides}
        for s in sides:  # warm the caches (library, byte code)
            s.seconds([str(s.winder), "run", SCENES["paper"], "--out", f"{tmp}/w.npz"])
        for _ in range(process_repeats):
            for s in sides:
                runs[s.label].append(s.seconds([str(s.winder), "run", SCENES["paper"],
                                                "--out", f"{tmp}/{s.label}.npz"]))
                imports[s.label].append(s.seconds(
                    [str(s.python), "-c", _IMPORT.format(scene=SCENES["paper"])]))
    for s in sides:
        out[s.label]["winder_run"] = statistics.median(runs[s.label])
        out[s.label]["winder_run_all"] = runs[s.label]
        out[s.label]["import_parse"] = statistics.median(imports[s.label])
        print(f"{s.label}: winder run {out[s.label]['winder_run']:.2f} s, import+parse "
              f"{out[s.label]['import_parse']:.3f} s", flush=True)
    with tempfile.TemporaryDirectory() as cache:
        env = {"WINDER_CACHE_DIR": cache}
        out[sides[0].label]["compile"] = sides[0].json(_COMPILE, json.dumps(SCENES), env=env)
    return out


def overhead(row: dict[str, Any]) -> float:
    """Time per evaluation above the generated rhs (its mean cost over 100 states of the
    run), as a fraction of the rhs."""
    return row["wall"] / (row["nfev"] * row["rhs_us"] * 1e-6) - 1.0


def table(out: dict[str, Any], labels: list[str]) -> list[str]:
    a = out[labels[0]]
    b = out[labels[1]] if len(labels) > 1 else None
    head = "| measure | " + " | ".join(labels) + (" | ratio |" if b else " |")
    lines = [head, "|---" * (len(labels) + 1 + bool(b)) + "|"]

    def row(name: str, fa: str, fb: str | None, ratio: float | None) -> None:
        cells = [fa] + ([fb] if fb is not None else [])
        end = f" | {ratio:.2f}× |" if ratio is not None else (" | – |" if b else " |")
        lines.append(f"| {name} | " + " | ".join(cells) + end)

    for key, name in (("paper", "paper cycle, in process"),
                      ("two_drum", "two-drum cycle, in process")):
        row(name, f"{a[key]['wall']:.3f} s", f"{b[key]['wall']:.3f} s" if b else None,
            b[key]["wall"] / a[key]["wall"] if b else None)
    for key, name in (("paper", "paper cycle, in process, CPU time"),
                      ("two_drum", "two-drum cycle, in process, CPU time")):
        row(name, f"{a[key]['cpu']:.3f} s", f"{b[key]['cpu']:.3f} s" if b else None,
            b[key]["cpu"] / a[key]["cpu"] if b else None)
    for key, name in (("paper", "overhead per evaluation above the rhs, paper"),
                      ("two_drum", "overhead per evaluation above the rhs, two-drum")):
        row(name, f"{100 * overhead(a[key]):.0f} %",
            f"{100 * overhead(b[key]):.0f} %" if b else None, None)
    for key, name in (("paper", "generated rhs per evaluation, paper"),
                      ("two_drum", "generated rhs per evaluation, two-drum")):
        row(name, f"{a[key]['rhs_us']:.3f} µs", f"{b[key]['rhs_us']:.3f} µs" if b else None,
            None)
    row("`winder run` paper cycle, whole process", f"{a['winder_run']:.2f} s",
        f"{b['winder_run']:.2f} s" if b else None,
        b["winder_run"] / a["winder_run"] if b else None)
    row("`import winder.cli` plus parsing a scene", f"{a['import_parse']:.3f} s",
        f"{b['import_parse']:.3f} s" if b else None,
        b["import_parse"] / a["import_parse"] if b else None)
    c = a["compile"]
    for label, m in c["machines"].items():
        row(f"link added per machine by the integrators ({label})",
            f"{m['link_only']:.3f} s", "–" if b else None, None)
    return lines


def goal(out: dict[str, Any], labels: list[str]) -> list[str]:
    """Issue #33's form of the two-drum comparison: this tree's cycle over the baseline's
    (goal <= 0.60), wall and CPU time; nothing without a baseline."""
    if len(labels) < 2:
        return []
    a, b = out[labels[0]]["two_drum"], out[labels[1]]["two_drum"]
    return [f"Two-drum cycle, this tree ÷ baseline (issue #33, goal ≤ 0.60): "
            f"{a['cpu'] / b['cpu']:.3f} in CPU time (of the whole `simulate` call: set-up, "
            "balance, integration and channels, a small fixed share of a cycle) "
            f"({a['wall'] / b['wall']:.3f} in wall time of the integration alone, which, "
            "where more processes run than there are cores, measures the "
            "machine's load as much as the code: the best of a few runs of either side may "
            f"or may not have been descheduled); evaluations {a['nfev']:,} against "
            f"{b['nfev']:,}.", ""]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", type=Path, help="a checkout of the baseline commit")
    ap.add_argument("--repeats", type=int, default=3, help="cycle runs per side and round")
    ap.add_argument("--process-repeats", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="1 cycle run, 3 processes")
    args = ap.parse_args()
    if args.quick:
        args.repeats, args.process_repeats = 1, 3
    sides = [Side("this tree", ROOT)]
    if args.baseline is not None:
        sides.append(Side("baseline", args.baseline.resolve()))
    commits = {s.label: subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=s.root,
                                       capture_output=True, text=True).stdout.strip()
               for s in sides}
    la = os.getloadavg()
    out = measure(sides, args.repeats, args.process_repeats)
    lb = os.getloadavg()
    labels = [f"{s.label} ({commits[s.label]})" for s in sides]
    out = {lab: out[s.label] for lab, s in zip(labels, sides, strict=True)}
    c = out[labels[0]]["compile"]
    lines = ["# The compiled machine: this tree against a baseline", "",
             "Regenerate with `python benchmarks/compiled_machine.py --baseline DIR` (DIR: a "
             "checkout of the baseline with its own `.venv`). Each measure alternates the "
             "two sides so both see the same load; cycles: the integration alone "
             "(`result.meta[\"wall_time\"]`), best of the runs; whole processes: median. "
             f"Load average {la[0]:.1f} before and {lb[0]:.1f} after on this "
             f"{os.cpu_count()}-core machine.", "", *table(out, labels), "",
             "Ratio: baseline time over this tree's (> 1: this tree is faster). Generated rhs "
             "per evaluation: its cost in a compiled loop (the machine's C loop here, a numba "
             "loop in the baseline), the mean over 100 states of the run (each the best of 5 "
             "loops of 20 000 calls). Overhead: the cycle's time per evaluation above that, as "
             "a fraction of it. CPU time: the process's (`time.process_time`) around "
             "`simulate`, the least of the runs: less sensitive than the wall time to other "
             "processes on the machine.", "", *goal(out, labels),
             f"Compile times in an empty cache (this tree): the integrators' objects "
             f"{c['integrators']:.2f} s once per installation; per machine, generating, "
             "compiling and linking: " + ", ".join(
                 f"{k} {m['generated_and_linked']:.2f} s (of which the link "
                 f"{m['link_only']:.3f} s)" for k, m in c["machines"].items()) + "."]
    text = "\n".join(lines) + "\n"
    atomic_write_all([
        (DOCS / "compiled_machine.md", lambda tmp: tmp.write_text(text, encoding="utf-8")),
        (DOCS / "compiled_machine.json",
         lambda tmp: tmp.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8"))])
    print(text)


if __name__ == "__main__":
    main()
