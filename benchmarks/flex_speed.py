"""µs per evaluation and build time of flexible machines (issues #25, #33; writes
docs/flex_speed.md, .json and .png).

The single-drum winder with a flexible drum of N segments (the roll rigid on it, the nip
sliced): N = 1 is the rigid drum. For each N: the build of its code into an empty cache
(what an explicit run needs: rhs, channels, switching functions) in wall seconds and in
CPU seconds of this process (the symbolic build, CSE, the C written) and of the compiler
processes, with each function's CasADi instructions; the Jacobian built on first use,
timed apart (up to ``--jac-max`` segments); the generated right-hand side and exact
Jacobian called the way the compiled integrators call them (the C loop of the machine's
library, best of repeats in the thread's CPU time); the numeric Pinocchio path
(``MachineSystem(scene, backend="pinocchio").rhs``, up to N = 32). The slopes of log cost
against log N: fitted over N >= 8 (least squares) and the issue's two points (issue #33:
at most log(4.5)/log(4) = 1.08 from N = 8 to 32); a log-log plot of them.

Where valgrind is installed, the rhs's cost is also counted in instructions per call
(``rhs_instr_per_call``: cachegrind over a small C program calling the library's
``SYMBOL_rhs_flat``, 200 calls less 0): the machine's load does not move it.

Run:  python benchmarks/flex_speed.py [--quick] [--sizes 1 4 8 16 32 64] [--no-numeric]
      [--jac-max 32] [--from-json]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import shutil
import sys
import tempfile
import time
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import winder
from winder.io.files import atomic_write
from winder.model.codegen import cache_dir
from winder.solve import integrators as integ
from winder.solve.system import MachineSystem

sys.path.insert(0, str(Path(__file__).resolve().parent))
from rhs_speed import best_us  # noqa: E402  (the sibling module)


def best_cpu_us(f: Callable[[], Any], n: int, repeats: int) -> float:
    """Best of ``repeats`` of ``n`` calls of ``f`` in this thread's CPU time [µs per call]
    (a loaded machine stretches wall time, not this)."""
    best = np.inf
    for _ in range(repeats):
        t0 = time.thread_time()
        f()
        best = min(best, (time.thread_time() - t0) / n * 1e6)
    return best

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

SCENE = """
[scene]
name = "flex_speed"
duration = 1.0
output_step = 0.01

[paper]
density = 650.0
caliper = 70e-6

[[drum]]
name = "drum"
radius = 0.5
inertia = 1400.0
mass = 5740.0
centre = [0.0, 0.0]
drive = { kind = "speed_profile", web_acceleration = 0.7, web_speed = 41.7 }
FLEX

[[roll]]
name = "roll"
centre = [0.0, 0.8]
free = ["z"]
core_radius = 0.05
core_mass = 40.0
core_inertia = 0.1
width = 8.0
initial_radius = 0.3

[[nip]]
name = "nip"
a = "drum"
b = "roll"
contact = { law = "linear", stiffness = 2.5e7, damping = 1.5e4 }
friction = { mu = 0.35, slip_velocity = 0.05, relaxation_length = 0.01, min_speed = 0.1 }

[web]
entry_nip = "nip"
tension = 1000.0
"""


def scene(n: int) -> winder.Scene:
    flex = "" if n == 1 else (
        f"length = 8.0\nflex = {{ segments = {n}, EI = 2.26e9, kGA = 3.7e9, GJ = 1.7e9, "
        "bearing_stiffness = 1e10, damping_ratio = 0.02 }")
    return winder.scene_from_dict(tomllib.loads(SCENE.replace("FLEX", flex)),
                                  source=f"flex_speed_{n}.toml")


def _cpu() -> float:
    """CPU seconds of this process and its finished children [s]."""
    return sum(r.ru_utime + r.ru_stime for r in (resource.getrusage(resource.RUSAGE_SELF),
                                                 resource.getrusage(resource.RUSAGE_CHILDREN)))


def _cpu_split() -> tuple[float, float]:
    """CPU seconds of this process and of its finished children (the compilers) [s]."""
    me, kids = (resource.getrusage(who) for who in (resource.RUSAGE_SELF,
                                                    resource.RUSAGE_CHILDREN))
    return me.ru_utime + me.ru_stime, kids.ru_utime + kids.ru_stime


def measure(n: int, quick: bool, numeric: bool = True, jac_max: int = 32) -> dict[str, Any]:
    sc = scene(n)
    nan = float("nan")
    row: dict[str, Any] = {"segments": n}
    with tempfile.TemporaryDirectory() as cache:
        # the C integrators' objects are built once per cache, not per machine: copied in
        shutil.copytree(cache_dir() / "integrators", Path(cache) / "integrators")
        old = os.environ.get("WINDER_CACHE_DIR")
        os.environ["WINDER_CACHE_DIR"] = cache
        try:
            t0, (p0, c0) = time.perf_counter(), _cpu_split()
            gen = MachineSystem(sc)
            (p1, c1), wall = _cpu_split(), time.perf_counter() - t0
            g = gen.generated
            row.update(states=gen.n_states, compile_s=wall, python_cpu_s=p1 - p0,
                       compiler_cpu_s=c1 - c0, compile_cpu_s=p1 - p0 + c1 - c0,
                       sizes=dict(g.sizes))
            y = gen.initial_state()
            fns, p, m = gen.fns, gen.params, gen.modes
            calls, reps = (200, 3) if quick else (2000, 5)
            out_rhs, out_jac = np.empty(gen.n_states), np.empty(gen.n_states ** 2)
            loop = gen.kernels.repeat  # the machine library's C loop
            loop(fns, integ.F_RHS, 1, 0.1, y, p, m, out_rhs)
            row["rhs_us"] = best_cpu_us(lambda: loop(fns, integ.F_RHS, calls, 0.1, y, p, m,
                                                     out_rhs), 1, 4 * reps) / calls
            row["rhs_instr_per_call"] = rhs_instructions_per_call(gen, y)
            row.update(jac_build_s=nan, jac_build_cpu_s=nan, jac_us=nan, jac_nnz=nan,
                       jac_structural=nan, jac_instructions=nan)
            if n <= jac_max:
                t0, (p0, c0) = time.perf_counter(), _cpu_split()
                g.jacobian()  # built on first use
                (p1, c1), wall = _cpu_split(), time.perf_counter() - t0
                k = max(calls // 10, 1)
                row.update(jac_build_s=wall, jac_build_cpu_s=p1 - p0 + c1 - c0,
                           jac_us=best_cpu_us(lambda: loop(fns, integ.F_JAC, k, 0.1, y, p, m,
                                                           out_jac), 1, 4 * reps) / k,
                           jac_nnz=_jac_nnz(gen, y),
                           jac_structural=int(g.jac_sparsity()[0][-1]),
                           jac_instructions=sum(v for w, v in g.sizes.items()
                                                if w.startswith("jac")))
        finally:
            if old is None:
                del os.environ["WINDER_CACHE_DIR"]
            else:
                os.environ["WINDER_CACHE_DIR"] = old
    row["numeric_rhs_us"] = nan
    if numeric and n <= 32:
        num = MachineSystem(sc, backend="pinocchio")
        k = 20 if quick or n >= 16 else 100
        row["numeric_rhs_us"] = best_us(lambda: [num.rhs(0.1, y) for _ in range(k)], k, reps)
    return row


#: The C program whose instructions valgrind counts: ``CALLS`` calls of the rhs's flat
#: entry point from the library (argv: library, symbol, inputs file, calls).
_COUNT_C = r"""
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
typedef int (*fn_t)(const double*, const double*, const double*, const double*, double*);
int main(int argc, char** argv) {
  void* h = dlopen(argv[1], RTLD_NOW); fn_t f = (fn_t) dlsym(h, argv[2]);
  FILE* in = fopen(argv[3], "rb"); long n[3];
  if (!h || !f || !in || fread(n, sizeof(long), 3, in) != 3) return 2;
  double* a = malloc(sizeof(double) * (1 + n[0] + n[1] + n[2] + n[0]));
  if (fread(a, sizeof(double), 1 + n[0] + n[1] + n[2], in) != (size_t)(1 + n[0] + n[1] + n[2]))
    return 2;
  for (int k = 0; k < atoi(argv[4]); k++)
    f(a, a + 1, a + 1 + n[0], a + 1 + n[0] + n[1], a + 1 + n[0] + n[1] + n[2]);
  return 0;
}
"""


def rhs_instructions_per_call(system: MachineSystem, y: np.ndarray,
                              calls: int = 200) -> float:
    """Instructions per call of the generated rhs under valgrind (cachegrind), ``calls``
    calls less none; NaN without valgrind or a C compiler."""
    import re
    import subprocess

    g = system.generated
    if shutil.which("valgrind") is None or g is None:
        return math.nan
    with tempfile.TemporaryDirectory() as d:
        src, exe, inp = Path(d) / "count.c", Path(d) / "count", Path(d) / "in.bin"
        src.write_text(_COUNT_C)
        if subprocess.run(["cc", "-O1", str(src), "-o", str(exe), "-ldl"],
                          capture_output=True).returncode != 0:
            return math.nan
        arrays = [np.array([0.1]), np.asarray(y, float), np.asarray(system.params, float),
                  np.asarray(system.modes, float)]
        inp.write_bytes(np.array([len(arrays[1]), len(arrays[2]), len(arrays[3])],
                                 dtype=np.int64).tobytes()
                        + np.concatenate(arrays).tobytes())
        counts = []
        for k in (0, calls):
            err = subprocess.run(["valgrind", "--tool=cachegrind", "--cache-sim=no",
                                  "--cachegrind-out-file=/dev/null", str(exe), str(g.path),
                                  f"{g.symbol}_rhs_flat", str(inp), str(k)],
                                 capture_output=True, text=True).stderr
            hit = re.search(r"I\s+refs:\s+([\d,]+)", err)
            if hit is None:
                return math.nan
            counts.append(int(hit.group(1).replace(",", "")))
    return (counts[1] - counts[0]) / calls


def _jac_nnz(system: MachineSystem, y: np.ndarray) -> int:
    """Nonzeros of the exact Jacobian at ``y`` (the structural ones that are not 0 there)."""
    return int(np.count_nonzero(system.jac(0.1, y)))


#: The costs whose growth with N is fitted: (row key, label).
COSTS = (("compile_cpu_s", "build CPU (explicit run)"), ("rhs_us", "rhs [µs]"),
         ("rhs_instr_per_call", "rhs [instructions per call, valgrind]"),
         ("rhs_instructions", "rhs instructions"), ("jac_build_cpu_s", "Jacobian build CPU"),
         ("jac_us", "Jacobian [µs]"), ("jac_nnz", "Jacobian nonzeros"))


def _rhs_size(sizes: dict[str, int]) -> float:
    """The rhs's CasADi instructions: its one file's, or the sum of its parts' (a large rhs
    is cut into parts: ``rhs1``, ``rhs2``, ..., ``rhs``; each part reads its inputs and
    carried values and writes its own, so the sum is a little over the one function's)."""
    parts = [v for k, v in sizes.items() if k.rstrip("0123456789") == "rhs"]
    return float(sum(parts)) if parts else math.nan


def _value(r: dict[str, Any], key: str) -> float:
    if key == "rhs_instructions":
        return _rhs_size(r.get("sizes", {}))
    return float(r.get(key, math.nan))


def slopes(rows: list[dict[str, Any]]) -> dict[str, dict[str, float]]:
    """log-log slopes of each cost of :data:`COSTS`: ``fit``, least squares over N >= 8;
    ``8-32``, the issue's two points; ``32-64`` where measured."""
    out: dict[str, dict[str, float]] = {}
    by_n = {r["segments"]: r for r in rows}
    for key, _ in COSTS:
        pts = [(math.log(r["segments"]), math.log(_value(r, key))) for r in rows
               if r["segments"] >= 8 and _value(r, key) > 0]
        res = {}
        if len(pts) >= 2:
            res["fit"] = float(np.polyfit(*zip(*pts, strict=True), 1)[0])
        for a, b in ((8, 32), (32, 64)):
            if a in by_n and b in by_n and _value(by_n[a], key) > 0 \
                    and _value(by_n[b], key) > 0:
                res[f"{a}-{b}"] = math.log(_value(by_n[b], key) / _value(by_n[a], key)) \
                    / math.log(b / a)
        out[key] = res
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer calls and repeats")
    ap.add_argument("--sizes", type=int, nargs="+", default=[1, 4, 8, 16, 32, 64],
                    help="segments per drum")
    ap.add_argument("--no-numeric", action="store_true", help="skip the Pinocchio path")
    ap.add_argument("--jac-max", type=int, default=32,
                    help="build and time the Jacobian up to this many segments")
    ap.add_argument("--from-json", action="store_true",
                    help="rewrite flex_speed.md and .png from flex_speed.json (no measurement)")
    args = ap.parse_args()
    if args.from_json:
        write_docs(json.loads((DOCS / "flex_speed.json").read_text())["rows"])
        return
    rows = []
    for n in args.sizes:
        rows.append(measure(n, args.quick, not args.no_numeric, args.jac_max))
        print(json.dumps(rows[-1]), flush=True)
        partial = Path(tempfile.gettempdir()) / "flex_speed.partial.json"
        partial.write_text(json.dumps(rows))
    write_docs(rows)


def _parts(sizes: dict[str, int]) -> str:
    """`` (in K parts)`` for a rhs cut into parts, else nothing."""
    k = sum(1 for w in sizes if w.rstrip("0123456789") == "rhs")
    return f" (in {k} parts)" if k > 1 else ""


def _cell(v: float, fmt: str) -> str:
    return "–" if not math.isfinite(v) else format(v, fmt)


def plot(rows: list[dict[str, Any]], slope: dict[str, dict[str, float]], path: Path) -> None:
    """Log-log plot of the costs of :data:`COSTS` against N (N >= 4), each normalised to
    its value at N = 8, with the fitted slopes and the line of slope 1."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 5.0))
    base = next(r for r in rows if r["segments"] == 8) if any(
        r["segments"] == 8 for r in rows) else rows[0]
    for key, label in COSTS:
        pts = [(r["segments"], _value(r, key) / _value(base, key)) for r in rows
               if r["segments"] >= 4 and _value(r, key) > 0]
        if len(pts) < 2:
            continue
        fit = slope.get(key, {}).get("fit", math.nan)
        ax.loglog(*zip(*pts, strict=True), "o-", label=f"{label}: slope {fit:.2f}")
    ns = np.array([4, max(r["segments"] for r in rows)], dtype=float)
    ax.loglog(ns, ns / 8, "k--", lw=1, label="slope 1 (linear)")
    ax.loglog(ns, (ns / 8) ** 2, "k:", lw=1, label="slope 2")
    ax.set_xlabel("segments per flexible drum N")
    ax.set_ylabel("cost ÷ cost at N = 8")
    ax.set_title("Flexible drum: growth with N (fitted over N ≥ 8)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    atomic_write(path, lambda p: fig.savefig(p, dpi=110, format="png"))
    plt.close(fig)


def write_docs(rows: list[dict[str, Any]]) -> None:
    slope = slopes(rows) if len(rows) > 1 else {}
    lines = ["# Flexible drum: cost per evaluation and build time", "",
             "`python benchmarks/flex_speed.py`: the single-drum winder with a flexible "
             "drum of N segments (N = 1: rigid), its nip sliced. The build (an empty cache) "
             "is what an explicit run needs (rhs, channels, switching functions), in wall "
             "seconds and CPU seconds (Python: the symbolic build, CSE and C; the compiler "
             "processes); the Jacobian is built on first use and timed apart. Generated code "
             "called in the C loop of its library (best of repeats in the thread's CPU "
             "time); the numeric Pinocchio path from Python (wall time). A shared 2-core "
             "machine: wall seconds move with its load.", "",
             "| N | states | build [s] | build CPU [s] (Python + compiler) | rhs / channels / "
             "switches [CasADi instructions] | rhs [µs] | rhs [instructions per call] | "
             "Jacobian build CPU [s] | Jacobian "
             "instructions | Jacobian nonzeros (structural) | Jacobian [µs] | numeric rhs "
             "[µs] |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        sz = r.get("sizes", {})
        lines.append(
            f"| {r['segments']} | {r['states']} | {r['compile_s']:.1f} | "
            f"{r['compile_cpu_s']:.1f} ({_cell(r.get('python_cpu_s', math.nan), '.1f')} + "
            f"{_cell(r.get('compiler_cpu_s', math.nan), '.1f')}) | "
            f"{_cell(_rhs_size(sz), '.0f')}{_parts(sz)} / {sz.get('out', '–')} / "
            f"{sz.get('sw', '–')} | "
            f"{r['rhs_us']:.2f} | {_cell(r.get('rhs_instr_per_call', math.nan), ',.0f')} | "
            f"{_cell(r['jac_build_cpu_s'], '.1f')} | "
            f"{_cell(r['jac_instructions'], '.0f')} | {_cell(r['jac_nnz'], '.0f')} "
            f"({_cell(r['jac_structural'], '.0f')}) | {_cell(r['jac_us'], '.1f')} | "
            f"{_cell(r['numeric_rhs_us'], '.0f')} |")
    if slope:
        lines += ["", "![growth with N](flex_speed.png)", "",
                  "log-log slopes (1: linear; issue #33 asks at most "
                  f"{math.log(4.5) / math.log(4):.2f} from N = 8 to 32):", "",
                  "| cost | fitted, N >= 8 | N = 8 → 32 | N = 32 → 64 |", "|---|---|---|---|"]
        for key, label in COSTS:
            sl = slope.get(key, {})
            lines.append(f"| {label} | {_cell(sl.get('fit', math.nan), '.2f')} | "
                         f"{_cell(sl.get('8-32', math.nan), '.2f')} | "
                         f"{_cell(sl.get('32-64', math.nan), '.2f')} |")
        lines += ["", GROWTH]
    text = "\n".join(lines) + "\n"
    atomic_write(DOCS / "flex_speed.md", lambda p: p.write_text(text, encoding="utf-8"))
    atomic_write(DOCS / "flex_speed.json",
                 lambda p: p.write_text(json.dumps({"rows": rows, "slopes": slope}, indent=1)
                                        + "\n", encoding="utf-8"))
    if slope:
        plot(rows, slope, DOCS / "flex_speed.png")
    print(text)


#: What grows faster than N, and why (measured 2026-11-27 by hand: the CasADi instructions
#: of the single drum's rhs with the bending forces taken out).
GROWTH = """## The build's growth: the rhs in parts (2026-11-28)

The compile of the rhs grew faster than N: one function at -O3, 0.5 / 1.7 / 2.9 / 7.8 s of
CPU at N = 8 / 16 / 32 / 64 (2.8 k / 5.6 k / 11.2 k / 22.3 k CasADi instructions; single
compiler runs, load ~3): register allocation over one function of thousands of values. Now
(`winder.model.c_split`, `codegen.RHS_PART`) a rhs of more than 4,000 instructions is cut
into parts of about 4,000 (2 / 3 / 6 at N = 16 / 32 / 64; the same operations, each once,
bitwise the same results), one C file each at -O1 -fstrict-aliasing
-finline-small-functions, compiled at once; and the joints' kinematics built once per
evaluation (they were built three times: velocities, ABA, RNEA). The table above is this
tree (18252f4, load 4-5); "parts only" is the run before it (f9da1c0), and the tree before
(1b64572) was measured with the same script right after that (load 4-5.5):

| N | build CPU [s]: before / parts only / now | rhs, instructions per call (valgrind) | rhs [µs] |
|---|---|---|---|
| 8 | 1.6 / 1.5 / 1.4 | 5,965 → 5,965 (one file at -O3, unchanged) | 0.71 / 0.65 / 0.65 |
| 16 | 3.4 / 2.4 / 2.1 | 11,556 → 11,336 | 2.69 / 1.85 / 1.80 |
| 32 | 6.4 / 3.7 / 4.3 | 23,007 → 21,505 | 5.08 / 3.69 / 3.57 |
| 64 | 18.3 / 9.8 / 8.5 | 46,517 → 42,851 | 7.62 / 9.55 / 7.77 |
| N = 32 ÷ N = 8 | 4.0 / 2.5 / 3.1 | 3.86 → 3.61 | 7.2 / 5.7 / 5.5 |

The issue's growth goals (N = 32 within 4.5 times N = 8) now hold for the build CPU (2.5
and 3.1 in two runs) and the rhs's instructions per call (3.6). The thread-CPU µs grow
faster than the instructions in both trees (5.5-7.2 times): the rhs is straight-line code,
at N = 8 about the size of the core's L1 instruction cache (36 kB of text against 32 kB),
at N = 32 four times it (130-143 kB), so each call streams its code from L2; and these µs
move by up to 40 % with the machine's load. The "rhs instructions" slope above sums the
parts' CasADi instructions, each part reading its inputs and carried values and writing its
own (N = 32: 13,056 in 3 parts against 11,187 in one); the operations are the same.

## What grew faster than N, and the fix

Measured 2026-11-27 by hand (CasADi instructions, which the compile time and the run time
follow). Before (afacf70), the rhs at N = 8 / 16 / 32 / 64: 3,045 / 7,405 / 20,349 / 63,133
(slope 1.46, towards 2). With the flexible drum's bending forces taken out (the tilts'
rates kept, no force): 1,578 / 3,002 / 5,850 at N = 8 / 16 / 32 (slope 0.95: the
articulated-body algorithm on the chain of segments, the nip's slices, the torsion
springs, CSE and the symbolic build all grow with N). The bending's own share, 1,467 /
4,403 / 14,499, grew as N²: `FlexBeam._rotary_bending` applied the condensed stiffness
`K = K_ww + K_wψ T` and the tilts' lag `φ̇ = s − T ẇ` as dense N × N products (`T =
−K_ψψ⁻¹ K_ψw` is dense: N² run-time parameters `K…_i_j`, `T…_i_j`, read in N² Python
steps too), and the channels function carried the same products.

Now (issue #33) neither is formed: `K w + K_wψ φ = K_ww w + K_wψ (φ + T w)` and `T v =
−K_ψψ⁻¹ (K_ψw v)` with the tridiagonal blocks and the `L D Lᵀ` factors of `K_ψψ` as
run-time parameters, a forward and a back substitution per use. The rhs: 2,801 / 5,553 /
11,057 / 22,065 instructions (slope 0.99), the channels 2,302 / 4,465 / 8,786 / 17,426; the
parameters 325 / 653 / 1,309 / 2,621 (were 465 / 1,313 / 4,161 / 16,705). The rates agree
with the dense form to 1e-15 relative per state. The Jacobian's structural nonzeros still
grow faster than N: the accelerations of a chain depend on every segment's deflection (the
inverse of `K_ψψ` is dense), which is what it is; it is built only on first use. Left: the
flexible body without rotary inertia (`rotary_inertia = false`) and the paper roll's
bending still use their dense condensed `K` (the same substitution applies).
"""


if __name__ == "__main__":
    main()
