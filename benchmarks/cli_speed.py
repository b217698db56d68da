"""Where the time of ``winder run`` goes: ``import winder``, each phase of a run in one
process, and the whole command as a user starts it (median of N processes, warm caches).
Writes docs/cli_speed.md.

    python benchmarks/cli_speed.py [--repeat 10]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from winder.io.files import atomic_write

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "models" / "paper_winding.toml"

# One process: the phases of `winder run SCENE --out r.npz`, timed from the inside.
_PHASES = r"""
import json, sys, time
t0 = time.perf_counter()
import winder
t1 = time.perf_counter()
scene = winder.load_scene(sys.argv[1])
t2 = time.perf_counter()
result = winder.simulate(scene)
t3 = time.perf_counter()
result.save(sys.argv[2])
t4 = time.perf_counter()
integ = result.meta["wall_time"]
print(json.dumps({"import winder": t1 - t0, "load scene": t2 - t1,
                  "set-up, first calls and channels": t3 - t2 - integ,
                  "integration": integ, "write npz": t4 - t3}))
"""


def _wall(cmd: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True)
    return time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=10)
    parser.add_argument("--out", default=str(ROOT / "docs" / "cli_speed.md"))
    args = parser.parse_args()
    py = sys.executable
    with tempfile.TemporaryDirectory() as tmp:
        out = str(Path(tmp) / "r.npz")
        run = [py, "-m", "winder", "run", str(SCENE), "--out", out]
        subprocess.run(run, check=True, capture_output=True)  # warm the compilation cache
        rows = {
            "`python -c 'import winder'`": [_wall([py, "-c", "import winder"])
                                            for _ in range(args.repeat)],
            "`winder run paper_winding.toml --out r.npz`": [_wall(run)
                                                            for _ in range(args.repeat)],
        }
        phases: dict[str, list[float]] = {}
        for _ in range(args.repeat):
            proc = subprocess.run([py, "-c", _PHASES, str(SCENE), out], check=True,
                                  capture_output=True, text=True)
            for k, v in json.loads(proc.stdout.strip().splitlines()[-1]).items():
                phases.setdefault(k, []).append(v)
    lines = ["# Speed of the command line", "",
             f"`models/paper_winding.toml` (700 s cycle, rtol 1e-6), warm compilation cache, "
             f"median (min–max) of {args.repeat} processes. Regenerate with "
             "`python benchmarks/cli_speed.py`.", "",
             "| whole process | median [s] | min [s] | max [s] |", "|---|---|---|---|"]
    for name, v in rows.items():
        lines.append(f"| {name} | {statistics.median(v):.2f} | {min(v):.2f} | {max(v):.2f} |")
    lines += ["", "| phase of one run (in-process) | median [s] |", "|---|---|"]
    for name, v in phases.items():
        lines.append(f"| {name} | {statistics.median(v):.3f} |")
    text = "\n".join(lines) + "\n"
    atomic_write(args.out, lambda p: p.write_text(text, encoding="utf-8"))
    print(text)


if __name__ == "__main__":
    main()
