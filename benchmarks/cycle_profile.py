"""Where a cycle's time goes: a sampling profile of the rigid and the flexible two-drum
winder's integration (issue #33; writes docs/cycle_profile.md and .json).

Each machine runs in a fresh process: the machine is built (or loaded from the cache) and
balanced by a warm-up run, then ``perf record -e cpu-clock`` attaches to the process for
the integration alone (``simulate`` over a window of the cycle, compiled DOPRI5 at
rtol 1e-6, sampled every 0.25 s). The samples are grouped by where they fall: the
generated right-hand side, switching functions, channels and Jacobian of the machine's
library, the C integrators (``winder_*``), each libm function, and the rest (Python,
numpy, the kernel). With the evaluations counted by the run, the CPU per evaluation
follows.

Needs ``perf`` (Linux; ``cpu-clock``, a software event: no hardware counters needed);
without it the script says so and exits 0.

Run:  python benchmarks/cycle_profile.py [--rigid-window 100] [--flexible-window 10]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
SCENES = {"rigid": ROOT / "models" / "two_drum_winder.toml",
          "flexible": ROOT / "models" / "two_drum_winder_flexible.toml"}
#: Sample rate [Hz] of ``perf record``.
RATE = 4000


def child(scene_path: str, window: float, data: str) -> dict[str, Any]:
    """In the profiled process: warm up, attach perf, run the window, detach."""
    import winder
    from winder.solve.system import MachineSystem

    scene = winder.load_scene(scene_path)
    winder.simulate(scene, t_end=1e-3, rtol=1e-6, method="DOPRI5")
    perf = subprocess.Popen(["perf", "record", "-q", "-e", "cpu-clock", "-F", str(RATE),
                             "-p", str(os.getpid()), "-o", data],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    time.sleep(0.5)  # perf attached
    c0 = time.process_time()
    res = winder.simulate(scene, t_end=window, rtol=1e-6, output_step=0.25, method="DOPRI5")
    cpu = time.process_time() - c0
    perf.send_signal(signal.SIGINT)
    perf.wait(timeout=60)
    return {"cpu": cpu, "rhs": int(res.meta["rhs_evaluations"]),
            "events": int(res.meta["events"]), "states": MachineSystem(scene).n_states}


def _group(dso: str, sym: str) -> str:
    """The row a sample counts in."""
    if "plt" in sym:
        return "calls through the PLT"
    if "libm" in dso:
        return "libm " + re.sub(r"^__(ieee754_)?|_(fma|avx2|sse2|fma4)$", "", sym)
    gen = re.search(r"_(jac|rhs|sw|out)\d*(_|$)", sym)  # a rhs in parts: _rhs1, _rhs2, ...
    if gen is not None:
        return {"jac": "generated Jacobian", "rhs": "generated rhs",
                "sw": "generated switching functions", "out": "generated channels"}[gen[1]]
    if sym.startswith("winder_") or (dso.endswith(".so") and re.match(r"w[0-9a-f]{8}", dso)):
        return "C integrators, events (winder_*)"
    return "the rest (Python, numpy, kernel)"


def profile(kind: str, window: float) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as d:
        data = str(Path(d) / "perf.data")
        proc = subprocess.run([sys.executable, __file__, "--child", str(SCENES[kind]),
                               str(window), data], capture_output=True, text=True,
                              env=dict(os.environ, OPENBLAS_NUM_THREADS="1"), check=False)
        if proc.returncode != 0:
            raise RuntimeError(f"{kind}: {proc.stderr[-2000:]}")
        run = json.loads(proc.stdout.strip().splitlines()[-1])
        rep = subprocess.run(["perf", "report", "-i", data, "--stdio", "--sort", "dso,sym",
                              "--percent-limit", "0", "-q"], capture_output=True, text=True,
                             check=False).stdout
    rows: dict[str, float] = {}
    for line in rep.splitlines():
        m = re.match(r"\s*([\d.]+)%\s+(\S+)\s+\[[.k]\]\s+(\S+)", line)
        if m:
            g = _group(m.group(2), m.group(3))
            rows[g] = rows.get(g, 0.0) + float(m.group(1))
    return {"window": window, **run, "share": dict(sorted(rows.items(), key=lambda x: -x[1]))}


def write(data: dict[str, Any]) -> str:
    lines = ["# Where a cycle's time goes", "",
             "`python benchmarks/cycle_profile.py`: a sampling profile (`perf record -e "
             f"cpu-clock`, {RATE} Hz) of the integration alone (compiled DOPRI5, rtol 1e-6), "
             f"after the machine is built and balanced; load {data['load'][0]:.1f} (2 cores).",
             "", "| | " + " | ".join(data["runs"]) + " |", "|---|" + "---|" * len(data["runs"])]
    runs = data["runs"].values()
    lines.append("| window of the cycle [s] | " + " | ".join(f"{r['window']:g}" for r in runs)
                 + " |")
    lines.append("| rhs evaluations | " + " | ".join(f"{r['rhs']:,}" for r in runs) + " |")
    lines.append("| located events | " + " | ".join(f"{r['events']:,}" for r in runs) + " |")
    lines.append("| CPU [s] | " + " | ".join(f"{r['cpu']:.2f}" for r in runs) + " |")
    lines.append("| CPU per evaluation [µs] | "
                 + " | ".join(f"{1e6 * r['cpu'] / r['rhs']:.2f}" for r in runs) + " |")
    lines.append("| states | " + " | ".join(f"{r['states']}" for r in runs) + " |")
    lines.append("| CPU per evaluation and state [ns] | "
                 + " | ".join(f"{1e9 * r['cpu'] / r['rhs'] / r['states']:.1f}" for r in runs)
                 + " |")
    groups = sorted({g for r in runs for g in r["share"]},
                    key=lambda g: -max(r["share"].get(g, 0.0) for r in runs))
    for g in groups:
        if max(r["share"].get(g, 0.0) for r in runs) >= 0.5:
            lines.append(f"| {g} [% of samples] | "
                         + " | ".join(f"{r['share'].get(g, 0.0):.1f}" for r in runs) + " |")
    rg, fx = data["runs"]["rigid"], data["runs"]["flexible"]
    per = [r["cpu"] / r["rhs"] / r["states"] for r in (rg, fx)]
    lines += ["", f"Per evaluation and state the flexible machine costs {per[1] / per[0]:.2f} "
              f"times the rigid one: an evaluation of the flexible machine costs "
              f"{fx['cpu'] / fx['rhs'] / (rg['cpu'] / rg['rhs']):.1f} times the rigid one's "
              f"because it has {fx['states'] / rg['states']:.1f} times the states. A whole "
              "cycle's ratio is that times the ratio of evaluations "
              "([flex_cycle.md](flex_cycle.md))."]
    md = "\n".join(lines) + "\n"
    if not data.get("no_docs"):
        from winder.io.files import atomic_write_all
        js = json.dumps(data, indent=1)
        atomic_write_all([(DOCS / "cycle_profile.md", lambda p: Path(p).write_text(md)),
                          (DOCS / "cycle_profile.json", lambda p: Path(p).write_text(js))])
    return md


def main() -> int:
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        print(json.dumps(child(sys.argv[2], float(sys.argv[3]), sys.argv[4])))
        return 0
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rigid-window", type=float, default=100.0, help="simulated time [s]")
    ap.add_argument("--flexible-window", type=float, default=10.0, help="simulated time [s]")
    ap.add_argument("--no-docs", action="store_true", help="print only")
    args = ap.parse_args()
    if shutil.which("perf") is None:
        print("cycle_profile: perf is not installed (Linux perf, e.g. apt-get install "
              "linux-perf): no profile taken", file=sys.stderr)
        return 0
    data: dict[str, Any] = {"load": os.getloadavg(), "no_docs": args.no_docs, "runs": {
        "rigid": profile("rigid", args.rigid_window),
        "flexible": profile("flexible", args.flexible_window)}}
    print(write(data))
    return 0


if __name__ == "__main__":
    sys.exit(main())
