"""Cold build of a machine's generated code, rigid against flexible, side by side (issue #33;
writes docs/build_speed.md and .json).

Each build runs in a fresh Python process with an empty ``WINDER_CACHE_DIR``: the scene is
loaded, its :class:`~winder.model.machine.Machine` made, and
``winder.model.codegen.generate(machine)`` timed (the symbolic build, the C written and
compiled into the machine's object and library; the C integrators are not linked in). The
two scenes run in turn (rigid, flexible, rigid, ...) and the ratio is taken pair by pair, so
that a machine whose load drifts still gives a meaningful ratio; the median pair is quoted.
Beside the wall time: the CPU seconds of the compiler processes (``RUSAGE_CHILDREN``) and
of the Python process itself. ``--src DIR``: the children import winder from ``DIR`` (an
older tree, for before/after).

Run:  python benchmarks/build_speed.py [--pairs 3] [--src DIR] [--label TEXT] [--no-docs]
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
MODELS = ROOT / "models"
DOCS = ROOT / "docs"
SCENES = (("rigid", MODELS / "two_drum_winder.toml"),
          ("flexible", MODELS / "two_drum_winder_flexible.toml"))


def child(scene_path: str) -> dict[str, Any]:
    """One cold ``generate`` in this process (the cache directory is empty)."""
    import resource
    import time

    import winder
    from winder.model import codegen
    from winder.model.machine import Machine

    machine = Machine(winder.load_scene(scene_path))
    c0, s0 = resource.getrusage(resource.RUSAGE_CHILDREN), resource.getrusage(
        resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    g = codegen.generate(machine)
    wall = time.perf_counter() - t0
    c1, s1 = resource.getrusage(resource.RUSAGE_CHILDREN), resource.getrusage(
        resource.RUSAGE_SELF)
    assert not g.from_cache
    return {"wall": wall, "states": machine.n_states,
            "compiler_cpu": c1.ru_utime + c1.ru_stime - c0.ru_utime - c0.ru_stime,
            "python_cpu": s1.ru_utime + s1.ru_stime - s0.ru_utime - s0.ru_stime}


def run_child(scene: Path, src: Path) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, WINDER_CACHE_DIR=d, PYTHONPATH=str(src))
        proc = subprocess.run([sys.executable, __file__, "--child", str(scene)],
                              capture_output=True, text=True, env=env, check=False)
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr[-2000:])
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    kb = [ln for ln in proc.stderr.splitlines() if "kB of C" in ln]
    out["kB_of_C"] = float(kb[-1].split("(")[-1].split()[0]) if kb else float("nan")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=3, help="rigid/flexible pairs")
    ap.add_argument("--src", type=Path, default=ROOT / "src", help="winder's source tree")
    ap.add_argument("--label", default="this tree", help="the row's label in the docs")
    ap.add_argument("--no-docs", action="store_true", help="print only")
    args = ap.parse_args()
    load = os.getloadavg()
    pairs = []
    for _ in range(args.pairs):
        pair = {label: run_child(path, args.src) for label, path in SCENES}
        pair["ratio"] = pair["flexible"]["wall"] / pair["rigid"]["wall"]
        pairs.append(pair)
        print(json.dumps(pair), file=sys.stderr, flush=True)
    med = sorted(pairs, key=lambda q: q["ratio"])[len(pairs) // 2]
    row = {"label": args.label, "pairs": pairs, "median_pair": med,
           "ratio_median": statistics.median(q["ratio"] for q in pairs),
           "load_before": load, "load_after": os.getloadavg()}
    print(json.dumps(row))
    if not args.no_docs:
        write_docs(row)


def write_docs(row: dict[str, Any]) -> None:
    from winder.io.files import atomic_write

    path = DOCS / "build_speed.json"
    rows = json.loads(path.read_text()) if path.exists() else []
    rows = [r for r in rows if r["label"] != row["label"]] + [row]
    lines = ["# Cold build: rigid and flexible two-drum winder side by side", "",
             "`python benchmarks/build_speed.py`: each build in a fresh process with an empty "
             "cache (`winder.model.codegen.generate`, without the C integrators); the rigid "
             "(`models/two_drum_winder.toml`) and the flexible "
             "(`models/two_drum_winder_flexible.toml`) winder built in turn, the ratio taken "
             "pair by pair, the median pair shown. Compiler CPU: the compiler processes' user + "
             "system seconds; Python CPU: the symbolic build and C generation. A shared "
             "2-core machine: wall times move with its load, the ratio and the CPU seconds much "
             "less.", "",
             "| tree | rigid wall [s] | flexible wall [s] | flexible ÷ rigid (median of pairs) "
             "| rigid compiler CPU [s] | flexible compiler CPU [s] | flexible Python CPU [s] | "
             "flexible C [kB] | load |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        m = r["median_pair"]
        ratios = ", ".join(f"{q['ratio']:.1f}" for q in r["pairs"])
        lines.append(f"| {r['label']} | {m['rigid']['wall']:.1f} | {m['flexible']['wall']:.1f} "
                     f"| **{r['ratio_median']:.1f}** ({ratios}) | "
                     f"{m['rigid']['compiler_cpu']:.1f} | {m['flexible']['compiler_cpu']:.1f} | "
                     f"{m['flexible']['python_cpu']:.1f} | {m['flexible']['kB_of_C']:.0f} | "
                     f"{r['load_before'][0]:.1f}–{r['load_after'][0]:.1f} |")
    text = "\n".join(lines) + "\n"
    atomic_write(DOCS / "build_speed.md", lambda p: p.write_text(text, encoding="utf-8"))
    js = json.dumps(rows, indent=1) + "\n"
    atomic_write(path, lambda p: p.write_text(js, encoding="utf-8"))


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "--child":
        print(json.dumps(child(sys.argv[2])))
    else:
        main()
