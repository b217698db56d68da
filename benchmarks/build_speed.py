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

``--before DIR``: an older tree built in the same rounds (before, then this tree, each
round), so that both rows share the machine's load. With the Jacobian built on first use
(issue #33) ``generate`` builds what an explicit run needs; the Jacobian's build is timed
after it (``jac_wall``, ``jac_cpu``: compiler and Python CPU).

Run:  python benchmarks/build_speed.py [--pairs 3] [--src DIR] [--label TEXT]
      [--before DIR --before-label TEXT] [--no-docs]
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
    out = {"wall": wall, "states": machine.n_states,
           "compiler_cpu": c1.ru_utime + c1.ru_stime - c0.ru_utime - c0.ru_stime,
           "python_cpu": s1.ru_utime + s1.ru_stime - s0.ru_utime - s0.ru_stime}
    if hasattr(g, "jacobian"):  # built on first use (issue #33): timed apart
        t0 = time.perf_counter()
        g.jacobian()
        c2 = resource.getrusage(resource.RUSAGE_CHILDREN)
        s2 = resource.getrusage(resource.RUSAGE_SELF)
        out.update(jac_wall=time.perf_counter() - t0,
                   jac_cpu=c2.ru_utime + c2.ru_stime - c1.ru_utime - c1.ru_stime
                   + s2.ru_utime + s2.ru_stime - s1.ru_utime - s1.ru_stime)
    return out


def run_child(scene: Path, src: Path) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, WINDER_CACHE_DIR=d, PYTHONPATH=str(src))
        proc = subprocess.run([sys.executable, __file__, "--child", str(scene)],
                              capture_output=True, text=True, env=env, check=False)
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr[-2000:])
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    kb = [ln for ln in proc.stderr.splitlines() if "code built in" in ln and "kB of C" in ln]
    out["kB_of_C"] = float(kb[-1].split("(")[-1].split()[0]) if kb else float("nan")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=3, help="rigid/flexible pairs")
    ap.add_argument("--src", type=Path, default=ROOT / "src", help="winder's source tree")
    ap.add_argument("--label", default="this tree", help="the row's label in the docs")
    ap.add_argument("--no-docs", action="store_true", help="print only")
    ap.add_argument("--before", type=Path, default=None,
                    help="an older tree's src/, built in the same rounds (side by side)")
    ap.add_argument("--before-label", default="before", help="its row's label")
    args = ap.parse_args()
    load = os.getloadavg()
    trees = [(args.label, args.src)]
    if args.before is not None:
        trees.insert(0, (args.before_label, args.before))
    pairs: dict[str, list[dict[str, Any]]] = {label: [] for label, _ in trees}
    for _ in range(args.pairs):  # each round: every tree's rigid and flexible in turn
        for label, src in trees:
            pair = {kind: run_child(path, src) for kind, path in SCENES}
            pair["ratio"] = pair["flexible"]["wall"] / pair["rigid"]["wall"]
            pairs[label].append(pair)
            print(label, json.dumps(pair), file=sys.stderr, flush=True)
    after = os.getloadavg()
    for label, _ in trees:
        ps = pairs[label]
        med = sorted(ps, key=lambda q: q["ratio"])[len(ps) // 2]
        row = {"label": label, "pairs": ps, "median_pair": med,
               "ratio_median": statistics.median(q["ratio"] for q in ps),
               "load_before": load, "load_after": after}
        print(json.dumps(row))
        if not args.no_docs:
            write_docs(row)


#: Where the flexible winder's build spends its time: measured once by hand (2026-11-27, gcc
#: 12.2, CPU seconds of single compiler runs: a loaded machine stretches wall time, not
#: these), the study behind the layout of :mod:`winder.model.codegen`.
STUDY = """
## The right-hand side in parts (issue #33, 2026-11-28)

Measured by hand (gcc 12.2, CasADi 3.8.2; CPU seconds of single compiler runs; run cost in
instructions per call under valgrind (cachegrind), which the machine's load does not move,
and thread CPU µs in a C loop; a 2-core machine at load 2-5). The flexible two-drum winder
(309 states) before: symbolic build 0.63 s, the rhs's Function with CSE 0.04 s and its C
0.03 s, then the rhs (10,050 instructions, 205 kB of C) at -O3 2.2-3.5 s, channels (8,776,
-O0) 0.56 s, switching functions (889, -O3) 0.2 s, the links 0.02 s. The rigid winder:
symbolic 0.09 s, compilers 0.3-0.5 s (three processes of 0.1-0.2 s: mostly each compiler's
fixed cost), so no fixed cost hides in the ratio's denominator. `-ftime-report` on the
flexible rhs at -O3: 92 % in the passes after RTL expansion, register allocation (IRA, LRA)
and post-reload CSE and scheduling the largest; -O2 compiles in the same time.

| flexible winder's rhs | compile CPU [s] | run: instructions per call | bitwise |
|---|---|---|---|
| -O3, one file (before) | 2.2-3.5 | 1 (about 22 k) | – |
| -O2 | 2.3-2.9 | 1.000 | same |
| -O1 | 1.7-1.9 | 1.07 (`sq`, `fmax`, `fabs` not inlined) | same |
| -O1 -fstrict-aliasing -finline-small-functions (-O1+) | 1.4-1.5 | 1.007 | same |
| -O2 without sched2, gcse, PRE; -fira-region=one | 2.3-2.5 | 1.000 | same |
| -O2 -fira-algorithm=priority | 3.1 | 1.03 | same |
| -O1+, 2 / 3 / 4 / 6 parts | 1.2 / 1.1-1.2 / 1.2-1.5 / 1.4-1.6 | .998 / 1 / 1.004 / 1.009 | same |

-O1+ on one large function does not carry to larger machines: on the flexible drum's rhs at
N = 32 (11,187 instructions) LRA's hard-register assignment grew to a third of the time,
-O1+ 3.1 s against -O3 2.9 s; in 4 parts 1.4 s against 2.1-2.4 s at -O3 in 4 parts, and
25.6 k instructions per call at -O3 in one against 24.3 k in parts. The compiler's time on
one function grows faster than the function (the flexible drum's rhs at -O3: 0.5 s at
N = 8, 2.9 s at N = 32, 7.8 s at N = 64 for 2.8 k / 11.2 k / 22.3 k instructions): parts
of bounded size make it linear.

Now (`winder.model.c_split`, `codegen.RHS_PART`): a rhs of more than 4,000 CasADi
instructions is cut into parts of about 4,000 (the flexible winder's in 3: 3,619 + 3,418 +
4,296 instructions, 305 values carried between them), its CSE'd algorithm replayed on fresh
symbols with CasADi's simplification on the fly off, so that every part holds exactly the
operations of the whole, each once (the parts' operations add up to the whole's; the
carried values are stored and read through one array on the stack); one C file per part
at `OPTIMISE["part"]` (-O1+), all compiled at once with the channels and switching
functions. A smaller rhs (the rigid winder's, 516) is one file at -O3 as before. Every
result is bitwise the same as before: the flexible winder's rhs, channels, switching
functions and Jacobian at four states (385,640 values) against the tree before (1b64572),
and the parts on CasADi's virtual machine against the whole (tests/model). The split costs
0.1 s of Python and each part's Function and C about 0.03 s. A build of more than 4,000
instructions now says, once its C is written, what it compiles and how big (functions,
instructions, files, kB of C, compiler processes).

The symbolic build (`winder.model.spatial`): the joints' kinematics (placements,
velocities) were built three times per evaluation (the velocities the force elements read,
ABA, the channels' RNEA) and each body's inertia, velocity-product acceleration and bias
force twice (ABA, RNEA), on the same symbols; now once, kept for the next call on the same
symbols. The flexible winder's symbolic build: 0.72-0.78 → 0.50-0.52 s CPU. The generated C
of four shipped scenes (the two-drum winder, rigid and flexible, the dancer line, the paper
winding; rhs, Jacobian, channels and switching functions) is byte for byte the same.

Side by side with the tree before (1b64572), three runs of five pairs (the last six rows):
the wall ratio, median of pairs, 9.4 → 6.2 (load 3.6-3.8, the rhs in parts only), 10.2 →
6.1 (load 6.1-6.6, the same) and 10.6 → 6.1 (load 3.8-4.8, the kinematics shared too;
pairs 6.5, 5.7, 6.1, 6.3, 5.9); the CPU ratio 9.7 → 7.6, 9.0 → 7.0 and 10.1 → 6.4. The
flexible build's CPU in the last run 3.1-4.0 s (compilers 2.0-3.1 s, Python 0.8-1.1 s),
the rigid's 0.5-0.6 s. Not yet reliably under 6: what is left of the flexible build
(single runs, load ~4): the rhs's three parts 1.1-1.2 s, the channels at -O0 (8,776
instructions) 0.56 s, the switching functions at -O3 0.2-0.3 s, the symbolic build 0.5 s,
the Functions, CSE, cut and C 0.4 s (the cut 0.1 s). Of the rigid build's 0.5 s, 0.3-0.45 s
are three compiler processes of 0.1-0.2 s each (their fixed cost: an empty file compiles in
0.01 s, a 115-instruction one in 0.1 s).

## Where the build goes (the flexible two-drum winder, 213 states)

Measured 2026-11-27 by hand (gcc 12.2, CasADi 3.8.2; CPU seconds of one compiler run
each, µs in the thread's CPU time in a C loop; a shared 2-core machine). Before this
change, one C file held the four functions, compiled at -O3; each result written through
`if (res[0]!=0)` and each argument read through `arg[i]? ... : 0` (CasADi's null checks),
and the Jacobian dense (`densify`: 45,369 entries, 4,800 of them nonzero).

| function | CasADi instructions | C [kB] | compile CPU [s] | run [µs] |
|---|---|---|---|---|
| rhs, -O3, with null checks (before) | 8,099 | 179 | 6.1 | 2.76 |
| rhs, -O3, without (now) | 8,099 | 179 | 2.5 | 2.72 |
| rhs, -O2 / -O1, without | | | 2.6 / 1.7 | 2.73 / 2.8–2.9 |
| Jacobian, dense, -O1, with null checks | 99,394 | 2,901 | 76.3 | |
| Jacobian, nonzeros, with null checks, -O3 | 58,825 | 1,426 | 57.6 | |
| Jacobian, nonzeros, with null checks, -O1 / -O0 | 58,825 | 1,426 | 13.1 / 3.8 | 22 / 54 |
| Jacobian, nonzeros, without, -O3 / -O2 | 58,825 | 1,426 | 24.7 / 21.9 | |
| Jacobian, nonzeros, without, -O1 / -Og | 58,825 | 1,426 | 10.9 / 7.8 | 21 / 20 |
| Jacobian, nonzeros, without, -O0 (now) | 58,825 | 1,426 | 3.9 | 48 |
| channels, -O3 / -O1, with null checks | 8,394 | 189 | 4.6 / 2.4 | |
| channels, -O1 / -O0, without (now: -O0) | 8,394 | 189 | 2.0 / 0.7 | |
| switching functions, -O3 | 889 | 24 | 0.3–0.9 | |

The symbolic side (Python, CPU): the machine's dynamics on SX 1.24 s, the Jacobian 0.20 s,
its `casadi.Function` with CSE 0.70 s (without CSE 0.02 s but 78,575 instructions, a third
more C to compile), its C 0.28 s, the rhs 0.06 s. For the rigid two-drum winder: rhs 516,
Jacobian 2,316 (88 nonzeros), channels 571, switching functions 115 instructions.

`gcc -O1 -ftime-report` on the Jacobian: 89 % of the time in RTL expansion and the passes
after it; register allocation and its data flow (LRA, IRA, live registers) about 40 %. The
dense Jacobian's 40,000 written zeros each behind a null check were most of the old build
(76 s at -O1 against 13 s for the nonzeros alone); the null checks alone made the rhs
2.4 times dearer to compile at -O3 (one branch per element).

What the build does now (`winder.model.codegen`): one C file per function, each handed to
its own compiler process as soon as it is written (the rhs first: it compiles while the
Jacobian is generated), the objects joined into one relocatable object (`-r`, the cache
keeps one `.o` per machine; the Jacobian now apart, below); no null checks (the functions
are only called through their flat entry points, which pass every argument); the Jacobian on
its nonzeros, moved to their dense column-major places by its flat entry point (every caller
keeps the dense interface: the C integrators, `MachineSystem.jac`, the FMU's directional
derivatives); optimisation by function: rhs and switching functions -O3, Jacobian -Og,
channels -Og and -O0 over 5,000 instructions (`OPTIMISE`, `LARGE`); a Jacobian of 2,000
nonzeros or more in two column blocks of about half the nonzeros each, two files compiled at
once (`JAC_SPLIT`; the flexible winder's: 34,550 + 29,015 instructions, 1.08 times the one
function's 58,825). Every result is bitwise the same as before (rhs, Jacobian, channels and
switching functions of four shipped scenes at four states each). Run-time cost through the
library, old and new libraries measured in turn (thread CPU, best of 30, two rounds each,
the Jacobian in two blocks): two-drum rhs 0.251/0.131 → 0.136/0.127 µs, Jacobian 1.20/0.70 →
0.83/0.82 µs; flexible rhs 3.47/2.44 → 3.16/2.53 µs, Jacobian 51.5/35.2 → 51.0/36.2 µs (the
rounds differ by the machine's load: compare within a round). At -O0 the flexible Jacobian
compiled in 3.9 s rather than 7.8 s but ran in 88 µs (13 against 5 µs at N = 8): not taken.

The Jacobian on first use (issue #33, the next step): the machine's object and library
hold the rhs, channels and switching functions, all an explicit run (DOPRI5, RK4, the
Stepper, channels) needs; the Jacobian is generated and compiled when first asked for
(ROS2 and the stiff methods, `MachineSystem.jac`, linearisation, modes) into its own
library beside the first (`SYMBOL_jac.so`, the same key), and loaded with the machine
whenever it is in the cache. The symbols of the first build are kept for it (else the
machine is made on symbols again: 0.8 s for the flexible winder). Every result is bitwise
the same as before (rhs, Jacobian, channels and switching functions of four shipped scenes,
the flexible winder among them, at three states each: 291,600 values). The flexible
two-drum winder (now 309 states: rotary inertia, issue #32) then builds, for an explicit
run, rhs 10,675 instructions (-O3, 2.2 s CPU), channels 8,729 (-O0, 0.4 s), switching
functions 889 (-O3, 0.2 s) after 0.8 s of symbolic build; its Jacobian (5,652 nonzeros,
about 7 s CPU) only when used.

The flexible bodies' bending in O(N) (0998891, `flex_speed.md`): at the shipped winder's
N = 8 it trims the rhs only from 10,675 to 9,943 instructions (the dense products were
small at N = 8); it is the growth with N that it fixes.

Side by side (the last four rows, two runs, load 6–11 on 2 cores): the flexible ÷ rigid
wall ratio 17 → 6.5 (pairs 7.7, 6.0, 6.5) and 14 → 8.3 (8.7, 6.3, 8.3; its quietest pair:
flexible 4.1 s, rigid 0.5 s), CPU 16 → 8 and 16 → 7.7. The wall ratio moves with the load
(the earlier pair of rows, the same code but the bending, gave 11.2 at load 5–8): the CPU
seconds are the steadier measure; the issue's goal (6) is not reached. What is left, for an
explicit run of the flexible winder (CPU at load ~10): the rhs at -O3 (9,943 instructions,
2.2 s at low load, 4.6 s at load 11), the symbolic build (0.8–1.5 s: the articulated-body
and RNEA passes over 32 bodies, `spatial.py`; the channels' RNEA alone 0.7 s of 2.5 s under
cProfile) and the channels at -O0 (0.4–0.5 s). The rigid winder's build is 0.6 s of CPU,
so a CPU ratio of 6 needs the flexible build under 3.6 s: a cheaper symbolic pass (casadi
`shape` checks are 0.4 s of it) or the rhs at -O2 above a size are the next steps. The
flexible winder's rhs (9,943 instructions) measured in turn, compile CPU and the best of
15 × 2000 calls in a C loop (thread CPU): -O3 3.59 / 3.98 / 3.26 s, -O2 2.64 / 3.58 /
2.98 s (8–26 % less), -O1 2.08 s; run 3.35 / 3.43 / 3.19 / 3.21 µs at -O3 against 3.39 /
3.44 / 3.21 / 3.20 µs at -O2 (the same), -O1 3.49–4.99 µs (slower). Not taken yet: the gain
is 0.3–0.9 s of about 5 s, within this machine's noise.
"""


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
             "flexible ÷ rigid, CPU | flexible C [kB] | flexible Jacobian on first use, CPU "
             "[s] | load |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        m = r["median_pair"]
        ratios = ", ".join(f"{q['ratio']:.1f}" for q in r["pairs"])
        cpu = [(q["flexible"]["compiler_cpu"] + q["flexible"]["python_cpu"])
               / (q["rigid"]["compiler_cpu"] + q["rigid"]["python_cpu"]) for q in r["pairs"]]
        jac = m["flexible"].get("jac_cpu")
        lines.append(f"| {r['label']} | {m['rigid']['wall']:.1f} | {m['flexible']['wall']:.1f} "
                     f"| **{r['ratio_median']:.1f}** ({ratios}) | "
                     f"{m['rigid']['compiler_cpu']:.1f} | {m['flexible']['compiler_cpu']:.1f} | "
                     f"{m['flexible']['python_cpu']:.1f} | {statistics.median(cpu):.1f} | "
                     f"{m['flexible']['kB_of_C']:.0f} | "
                     f"{'–' if jac is None else format(jac, '.1f')} | "
                     f"{r['load_before'][0]:.1f}–{r['load_after'][0]:.1f} |")
    text = "\n".join(lines) + "\n" + STUDY
    atomic_write(DOCS / "build_speed.md", lambda p: p.write_text(text, encoding="utf-8"))
    js = json.dumps(rows, indent=1) + "\n"
    atomic_write(path, lambda p: p.write_text(js, encoding="utf-8"))


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "--child":
        print(json.dumps(child(sys.argv[2])))
    else:
        main()
