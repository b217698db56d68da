"""Issue #33's table, this tree beside an older one in one run: the rigid and the flexible
two-drum winder's cold build and a window of their cycle (writes docs/cost_side_by_side.md
and .json).

Every measurement runs in a fresh Python process that imports winder from the tree's
``src/`` (the same interpreter and packages for both trees), and the trees take turns
(before, this tree, before, ...), so both see the same load on the shared machine:

- **cold build**: ``benchmarks/build_speed.py``'s child (``codegen.generate`` in an empty
  ``WINDER_CACHE_DIR``: the symbolic build, the C written and compiled; wall, and CPU of
  the compiler processes plus the Python process);
- **a window of the cycle**: ``simulate`` of the scene from its start to ``--window``
  seconds, rtol 1e-6, sampled every 0.25 s, after a warm-up run that builds the machine
  (in the tree's own cache) and solves its balance; the integration's wall time
  (``meta["wall_time"]``), the process's CPU time around ``simulate``, right-hand-side
  evaluations, located events and the set's radius at the window's end. ``--method``: the
  method of both trees (default: each scene's ``[solver] method``, what a user gets).

The whole cycle (414.5 s) of this tree alone is ``benchmarks/flex_cycle.py``'s (the older
flexible winder's whole cycle takes hours: the window is what both can run).

Run:  python benchmarks/cost_side_by_side.py --before DIR [--window 5] [--rounds 2]
      [--method NAME] [--no-docs]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
sys.path.insert(0, str(ROOT / "benchmarks"))
from build_speed import SCENES, run_child  # noqa: E402  (the cold build's child)


def cycle_child(scene_path: str, window: float, method: str) -> dict[str, Any]:
    """A window of the cycle in this process (the machine is built by a warm-up run)."""
    import time

    import winder

    scene = winder.load_scene(scene_path)
    kw = {} if method == "scene" else {"method": method}
    winder.simulate(scene, t_end=1e-3, rtol=1e-6, **kw)  # build or load; balance
    c0 = time.process_time()
    res = winder.simulate(scene, t_end=window, rtol=1e-6, output_step=0.25, **kw)
    cpu = time.process_time() - c0
    auto = res.meta.get("auto")
    return {"wall": float(res.meta["wall_time"]), "cpu": cpu,
            "rhs": int(res.meta["rhs_evaluations"]), "events": int(res.meta.get("events", -1)),
            "radius": float(res["set_radius"][-1]),
            "method": auto["method"] if isinstance(auto, dict) else res.meta.get("method", "")}


def run_cycle(scene: Path, src: Path, cache: str, window: float, method: str) -> dict[str, Any]:
    env = dict(os.environ, WINDER_CACHE_DIR=cache, PYTHONPATH=str(src),
               OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run([sys.executable, __file__, "--cycle-child", str(scene), str(window),
                           method], capture_output=True, text=True, env=env, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"{src}: {scene.name}: {proc.stderr[-2000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def _median(rows: list[dict[str, Any]], key: str) -> float:
    return statistics.median(r[key] for r in rows)


def write_docs(data: dict[str, Any]) -> str:
    w = data["window"]
    lines = [
        "# Cost with the machine: rigid and flexible, before and after, side by side", "",
        "`python benchmarks/cost_side_by_side.py --before DIR`: the rigid "
        "(`models/two_drum_winder.toml`) and the flexible (`models/two_drum_winder_flexible"
        f".toml`) two-drum winder, the tree `{data['before_label']}` and this tree "
        f"(`{data['label']}`) in turns, {data['rounds']} rounds, medians shown; load "
        f"{data['load'][0]:.1f} at the start, {data['load_after'][0]:.1f} at the end (2 cores).",
        "", f"Cold build (empty cache, the C integrators apart) and the cycle's first {w:g} s "
        "(rtol 1e-6, each scene's own method: "
        f"{data['method']}); CPU: compiler and Python processes for the build, the process "
        "for the run.", "",
        "| tree | machine | build wall [s] | build CPU [s] | run wall [s] | run CPU [s] | "
        "rhs evaluations | events | method | set radius at the end [m] |",
        "|---|---|---|---|---|---|---|---|---|---|"]
    for label in (data["before_label"], data["label"]):
        for kind in ("rigid", "flexible"):
            b, c = data["build"][label][kind], data["cycle"][label][kind]
            lines.append(
                f"| {label} | {kind} | {_median(b, 'wall'):.2f} | {_median(b, 'cpu'):.2f} | "
                f"{_median(c, 'wall'):.2f} | {_median(c, 'cpu'):.2f} | {c[0]['rhs']:,} | "
                f"{c[0]['events']:,} | {c[0]['method']} | {c[0]['radius']:.6f} |")
    lines += ["", "| ratio flexible ÷ rigid | build wall | build CPU | run wall | run CPU | "
              "rhs evaluations |", "|---|---|---|---|---|---|"]
    for label in (data["before_label"], data["label"]):
        r = data["ratios"][label]
        lines.append(f"| {label} | {r['build_wall']:.1f} | {r['build_cpu']:.1f} | "
                     f"{r['run_wall']:.1f} | {r['run_cpu']:.1f} | {r['rhs']:.2f} |")
    md = "\n".join(lines) + "\n"
    if not data.get("no_docs"):
        from winder.io.files import atomic_write_all
        js = json.dumps(data, indent=1)
        atomic_write_all([(DOCS / "cost_side_by_side.md", lambda p: Path(p).write_text(md)),
                          (DOCS / "cost_side_by_side.json", lambda p: Path(p).write_text(js))])
    return md


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "--cycle-child":
        print(json.dumps(cycle_child(sys.argv[2], float(sys.argv[3]), sys.argv[4])))
        return
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", type=Path, required=True, help="an older tree (its root)")
    ap.add_argument("--before-label", default=None, help="its label (default: its commit)")
    ap.add_argument("--label", default=None, help="this tree's label (default: its commit)")
    ap.add_argument("--window", type=float, default=5.0, help="simulated time [s]")
    ap.add_argument("--rounds", type=int, default=2, help="turns of both trees")
    ap.add_argument("--method", default="scene", help="both trees' method (default: scene)")
    ap.add_argument("--no-docs", action="store_true", help="print only")
    args = ap.parse_args()

    def commit(tree: Path) -> str:
        return subprocess.run(["git", "-C", str(tree), "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True, check=False).stdout.strip()

    trees = [(args.before_label or commit(args.before), args.before.resolve()),
             (args.label or commit(ROOT), ROOT)]
    data: dict[str, Any] = {
        "before_label": trees[0][0], "label": trees[1][0], "window": args.window,
        "rounds": args.rounds, "method": args.method, "load": os.getloadavg(),
        "build": {lb: {k: [] for k, _ in SCENES} for lb, _ in trees},
        "cycle": {lb: {k: [] for k, _ in SCENES} for lb, _ in trees}}
    with tempfile.TemporaryDirectory() as c0, tempfile.TemporaryDirectory() as c1:
        caches = dict(zip((lb for lb, _ in trees), (c0, c1), strict=True))
        for _ in range(args.rounds):
            for label, tree in trees:
                for kind, scene in SCENES:
                    b = run_child(scene, tree / "src")
                    b["cpu"] = b["compiler_cpu"] + b["python_cpu"]
                    data["build"][label][kind].append(b)
                    c = run_cycle(scene, tree / "src", caches[label], args.window,
                                  args.method)
                    data["cycle"][label][kind].append(c)
                    print(label, kind, json.dumps({"build": b, "cycle": c}), file=sys.stderr,
                          flush=True)
    data["load_after"] = os.getloadavg()
    data["ratios"] = {}
    for label, _ in trees:
        b, c = data["build"][label], data["cycle"][label]
        data["ratios"][label] = {
            "build_wall": _median(b["flexible"], "wall") / _median(b["rigid"], "wall"),
            "build_cpu": _median(b["flexible"], "cpu") / _median(b["rigid"], "cpu"),
            "run_wall": _median(c["flexible"], "wall") / _median(c["rigid"], "wall"),
            "run_cpu": _median(c["flexible"], "cpu") / _median(c["rigid"], "cpu"),
            "rhs": c["flexible"][0]["rhs"] / c["rigid"][0]["rhs"]}
    data["no_docs"] = args.no_docs
    print(write_docs(data))


if __name__ == "__main__":
    main()
