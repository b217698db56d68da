"""Code generation and compile times of a machine (writes docs/codegen_speed.md and .json).

Cold: each measurement runs in a fresh Python process with an empty ``WINDER_CACHE_DIR``
(and, on route cpp, an empty model cache of the pin_casadi generator, which is itself
built and only linked in): ``winder.model.codegen.generate(machine, route=..., directory=...)``
split into the SX graph build with C generation (Pinocchio's ABA/RNEA on symbols, the force
elements, the Jacobian, ``casadi.Function``, the C of each function; the compiler starts on
each function's C as soon as it is written) and the wait for the compilers and the link
after it. Cached:
a second fresh process loading the same directory (``from_cache``), and the whole
``MachineSystem(scene)`` construction from the cache (model, load, static balance).

Run:  python benchmarks/codegen_speed.py [--quick]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
DOCS = ROOT / "docs"
SCENES = (("paper_winding (single drum)", MODELS / "paper_winding.toml"),
          ("two_drum_winder", MODELS / "two_drum_winder.toml"))
GENERATOR_BUILD = "about 3 min (162 s CPU, 4.0 GB peak), once per pin/casadi/eigen version"


def child(scene_path: str, route: str, directory: str) -> dict[str, Any]:
    """One ``generate`` in this process, timed by phases (monkeypatched timers)."""
    import time

    import winder
    from winder.model import codegen
    from winder.model.machine import Machine

    t_all = time.perf_counter()
    scene = winder.load_scene(scene_path)
    t0 = time.perf_counter()
    machine = Machine(scene)
    t_machine = time.perf_counter() - t0
    phases = {"source": 0.0}
    source_orig = codegen._c_source

    def timed_source(*a: Any, **k: Any) -> Any:
        t = time.perf_counter()
        try:
            return source_orig(*a, **k)
        finally:
            phases["source"] += time.perf_counter() - t

    codegen._c_source = timed_source  # type: ignore[assignment]
    try:
        g = codegen.generate(machine, route=route, directory=Path(directory))
    finally:
        codegen._c_source = source_orig  # type: ignore[assignment]
    # the compilers start as each function's C is written: "source" (the SX build and C
    # generation) overlaps the first compiles; "gcc" is the wait after it and the link
    phases["cgen"], phases["gcc"] = 0.0, (g.build_seconds - phases["source"]
                                         if not g.from_cache else 0.0)
    out: dict[str, Any] = {"total": g.build_seconds, "from_cache": g.from_cache,
                           "machine": t_machine, "route": g.route,
                           "cgen": phases["cgen"], "gcc": phases["gcc"],
                           "states": machine.n_states}
    out["sx"] = phases["source"]
    src = list(Path(directory).glob("*.so"))
    out["so_bytes"] = src[0].stat().st_size if src else 0
    if g.from_cache:  # the whole system from the cache: model, load, static balance
        from winder.solve.system import MachineSystem

        t0 = time.perf_counter()
        MachineSystem(scene).initial_state()
        out["system_from_cache"] = time.perf_counter() - t0
    out["process"] = time.perf_counter() - t_all
    return out


def run_child(scene_path: Path, route: str, directory: Path, pin_dir: Path) -> dict[str, Any]:
    env = dict(os.environ, WINDER_CACHE_DIR=str(directory / "cache"),
               WINDER_PIN_CASADI_DIR=str(pin_dir))
    proc = subprocess.run([sys.executable, __file__, "--child", str(scene_path), route,
                           str(directory / "gen")], capture_output=True, text=True, env=env,
                          check=False)
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr[-2000:])
    return json.loads(proc.stdout.strip().splitlines()[-1])


def fresh_pin_dir(tmp: Path) -> Path:
    """A pin_casadi folder with the built generator linked in and an empty model cache."""
    from winder.model import pin_casadi

    binary = pin_casadi.generator_path(build=False)
    base = tmp / "pin"
    if binary is not None:
        key = base / binary.parent.name
        key.mkdir(parents=True)
        (key / binary.name).symlink_to(binary)
    return base


def main(quick: bool = False) -> dict[str, Any]:
    from winder.model.backends import default_route

    repeats = 1 if quick else 2
    routes = ["py"] + (["cpp"] if default_route() == "cpp" else [])
    rows = []
    load = os.getloadavg()
    for label, path in SCENES:
        for route in routes:
            cold, cached = [], []
            for _ in range(repeats):
                with tempfile.TemporaryDirectory() as d:
                    tmp = Path(d)
                    pin_dir = fresh_pin_dir(tmp)
                    cold.append(run_child(path, route, tmp, pin_dir))
                    cached.append(run_child(path, route, tmp, pin_dir))
            best = min(cold, key=lambda r: r["total"])
            row = {"scene": label, "route": route, **{k: best[k] for k in (
                "total", "sx", "cgen", "gcc", "machine", "states", "so_bytes")},
                "cold_process": min(r["process"] for r in cold),
                "cached_load": min(r["total"] for r in cached),
                "system_from_cache": min(r["system_from_cache"] for r in cached),
                "cached_process": min(r["process"] for r in cached),
                "all_cold_totals": [r["total"] for r in cold]}
            assert all(r["from_cache"] for r in cached) and not any(r["from_cache"] for r in cold)
            rows.append(row)
            print(f"{label} route {route}: cold {row['total']:.2f} s (SX {row['sx']:.2f}, C "
                  f"{row['cgen']:.2f}, gcc {row['gcc']:.2f}); cached {row['cached_load']:.4f} s",
                  file=sys.stderr, flush=True)
    out = {"rows": rows, "repeats": repeats, "load_before": load,
           "load_after": os.getloadavg(), "generator_build": GENERATOR_BUILD}
    write_docs(out)
    return out


def write_docs(out: dict[str, Any]) -> None:
    from winder.io.files import atomic_write

    la, lb = out["load_before"], out["load_after"]
    lines = ["# Code generation and compile times", "",
             "Regenerate with `python benchmarks/codegen_speed.py`. Each number is the best of "
             f"{out['repeats']} fresh processes on a shared 2-core machine (load average "
             f"{la[0]:.1f} before, {lb[0]:.1f} after). *Cold*: empty `WINDER_CACHE_DIR` (and "
             "empty pin_casadi model cache on route cpp): `generate()` = SX graph build and C "
             "generation (the machine's dynamics on `casadi.SX`: Pinocchio's ABA/RNEA, force "
             "elements, exact Jacobian, `casadi.Function` with CSE, one C file per function) "
             "+ the wait for gcc after it (each function's C compiles as soon as it is "
             "written, at its level, `winder.model.codegen.OPTIMISE`) and the link. The "
             "flexible machine side by side with the rigid one: build_speed.md. *Cached*: "
             "loading the compiled library "
             "(`from_cache`), and the whole `MachineSystem(scene)` from the cache (pin model, "
             "load, static balance).", "",
             f"Route cpp needs the pin_casadi generator, built once: {out['generator_build']} "
             "(measured by another helper; not re-measured here).", "",
             "| scene | route | states | SX build + C [s] | (C generation) [s] | gcc after "
             "[s] | cold "
             "total [s] | cold, whole process [s] | cached load [s] | MachineSystem from "
             "cache [s] | library [kB] |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in out["rows"]:
        lines.append(f"| {r['scene']} | {r['route']} | {r['states']} | {r['sx']:.2f} | "
                     f"{r['cgen']:.4f} | {r['gcc']:.2f} | {r['total']:.2f} | "
                     f"{r['cold_process']:.2f} | {r['cached_load']:.4f} | "
                     f"{r['system_from_cache']:.3f} | {r['so_bytes'] / 1024:.0f} |")
    lines += ["", "*cold, whole process*: from the start of the measuring function to the "
              "end, including `import winder`-time work done lazily (casadi, the scene, the "
              "Machine); Python's start-up itself is not included. *MachineSystem from cache*: "
              "in a fresh process, mostly first imports — `scipy.optimize` for the static "
              "balance took 1.4 s of the two-drum winder's 1.5 s in a profile (loaded "
              "machine); model, library load and balance themselves take about 0.08 s, and a "
              "second construction in the same process 0.01 s.", ""]
    text = "\n".join(lines)
    atomic_write(DOCS / "codegen_speed.md", lambda tmp: tmp.write_text(text, encoding="utf-8"))
    js = json.dumps(out, indent=1, default=float)
    atomic_write(DOCS / "codegen_speed.json", lambda tmp: tmp.write_text(js, encoding="utf-8"))


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        print(json.dumps(child(*sys.argv[2:5]), default=float))
    else:
        ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
        ap.add_argument("--quick", action="store_true", help="one repeat")
        main(ap.parse_args().quick)
