"""µs per evaluation of a machine's dynamics (writes docs/rhs_speed.md and .json).

For each scene: the generated right-hand side and exact Jacobian called the way the
compiled integrators call them (from C through the function address, in the machine's
library: ``MachineSystem.kernels.repeat``), the generated right-hand side called from
Python (``MachineSystem.rhs``, ctypes) and the numeric Pinocchio path
(``MachineSystem(scene, backend="pinocchio").rhs``: ``pin.aba`` on numbers with the same
force elements). Scenes: the single-drum paper scene, the two-drum winder, and machines of
growing size (:mod:`machines`: 1–4 drum–roll units, 0–3 riders) whose costs give a linear
fit per body and per nip. Timings are the best of N repeats (the machine may be loaded).

Run:  python benchmarks/rhs_speed.py [--quick]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import winder
from winder.io.files import atomic_write
from winder.solve import integrators as integ
from winder.solve.system import MachineSystem

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machines import counts, machine_scene  # noqa: E402  (the sibling module)

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
DOCS = ROOT / "docs"
GROWN = ((1, 0), (2, 0), (3, 0), (4, 0), (1, 1), (1, 2), (1, 3))


def best_us(f: Callable[[], Any], n: int, repeats: int) -> float:
    """Best of ``repeats`` of ``n`` calls of ``f`` [µs per call]."""
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        best = min(best, (time.perf_counter() - t0) / n * 1e6)
    return best


def state_of(system: MachineSystem) -> np.ndarray:
    """The static initial state with the bodies turning (rolls −10 rad/s, others 5)."""
    y = system.initial_state()
    for i, name in enumerate(system.state_names):
        if name.endswith(".theta_dot"):
            y[i] = -10.0 if name.split(".")[0] in {r.name for r in system.scene.rolls} else 5.0
    return y


def measure(scene: winder.Scene, label: str, *, n_loop: int, n_py: int, repeats: int,
            pinocchio: bool = True) -> dict[str, Any]:
    """µs per evaluation for one scene (compiled: from C, from Python; Pinocchio). The C
    loops run ``4 × repeats`` times: short loops, many repeats, so that the best catches
    a moment with a whole core on a loaded machine."""
    system = MachineSystem(scene)
    y, t = state_of(system), 5.0
    p, m = system.params, system.modes.copy()
    lib = system.kernels
    lib.modes(system.fns, system.table, t, y, p, m, contact_auto=False)
    n = system.n_states
    out_r, out_j = np.empty(n), np.empty(n * n)

    def _loop(fns: np.ndarray, which: int, t: float, y: np.ndarray, p: np.ndarray,
              m: np.ndarray, out: np.ndarray, count: int) -> float:
        return lib.repeat(fns, which, count, t, y, p, m, out)

    row: dict[str, Any] = {
        "scene": label, "states": n, "bodies": len(system.machine.bodies),
        "nips": len(scene.nips), "route": system.generated.route,
        "rhs_us": best_us(lambda: _loop(system.fns, integ.F_RHS, t, y, p, m, out_r, n_loop),
                          n_loop, 4 * repeats),
        "jac_us": best_us(lambda: _loop(system.fns, integ.F_JAC, t, y, p, m,
                                        out_j, n_loop // 4), n_loop // 4, 4 * repeats),
    }
    system.modes[:] = m

    def py_loop() -> None:
        for _ in range(n_py):
            system.rhs(t, y)

    row["rhs_python_us"] = best_us(py_loop, n_py, repeats)
    if pinocchio:
        numeric = MachineSystem(scene, backend="pinocchio")
        numeric.modes[:] = m
        diff = np.max(np.abs(numeric.rhs(t, y) - system.rhs(t, y)))
        row["pinocchio_vs_compiled"] = float(diff / max(1.0, np.max(np.abs(system.rhs(t, y)))))
        k = max(20, n_py // 50)

        def pin_loop() -> None:
            for _ in range(k):
                numeric.rhs(t, y)

        row["pinocchio_us"] = best_us(pin_loop, k, repeats)
    return row


def linear_fit(rows: list[dict[str, Any]], key: str) -> dict[str, float]:
    """Least squares ``µs = c0 + c_body · bodies + c_nip · nips`` over the grown machines,
    and the slopes per unit (drum + roll + nip, riders 0) and per rider (+ its nip, 1 unit)."""
    A = np.array([[1.0, r["bodies"], r["nips"]] for r in rows])
    b = np.array([r[key] for r in rows])
    c, *_ = np.linalg.lstsq(A, b, rcond=None)
    resid = float(np.max(np.abs(A @ c - b)))
    units = [r for r in rows if r["riders"] == 0]
    riders = [r for r in rows if r["units"] == 1]
    per_unit = np.polyfit([r["units"] for r in units], [r[key] for r in units], 1)[0]
    per_rider = np.polyfit([r["riders"] for r in riders], [r[key] for r in riders], 1)[0]
    return {"c0": float(c[0]), "per_body": float(c[1]), "per_nip": float(c[2]),
            "max_residual": resid, "per_unit": float(per_unit),
            "per_rider": float(per_rider)}


def main(quick: bool = False, write: bool = True) -> dict[str, Any]:
    n_loop, n_py, repeats = (20_000, 2_000, 3) if quick else (10_000, 5_000, 15)
    load = os.getloadavg()
    rows = [measure(winder.load_scene(MODELS / "paper_winding.toml"),
                    "paper_winding (single drum)", n_loop=n_loop, n_py=n_py, repeats=repeats),
            measure(winder.load_scene(MODELS / "two_drum_winder.toml"), "two_drum_winder",
                    n_loop=n_loop, n_py=n_py, repeats=repeats)]
    grown = []
    with tempfile.TemporaryDirectory() as tmp:
        for units, riders in GROWN:
            assert counts(units, riders)[1] == units + riders
            r = measure(machine_scene(units, riders, Path(tmp)),
                        f"{units} unit(s), {riders} rider(s)", n_loop=n_loop, n_py=n_py,
                        repeats=repeats)
            r["units"], r["riders"] = units, riders
            grown.append(r)
            print(f"{r['scene']}: rhs {r['rhs_us']:.3f} µs, jac {r['jac_us']:.3f} µs, "
                  f"pinocchio {r['pinocchio_us']:.1f} µs", file=sys.stderr, flush=True)
    fits = {k: linear_fit(grown, k) for k in ("rhs_us", "jac_us", "pinocchio_us")}
    out = {"rows": rows, "grown": grown, "fits": fits,
           "load_before": load, "load_after": os.getloadavg(),
           "n_loop": n_loop, "repeats": repeats}
    for r in rows:
        print(f"{r['scene']}: rhs {r['rhs_us']:.3f} µs (from C), jac {r['jac_us']:.3f} µs, "
              f"from Python {r['rhs_python_us']:.2f} µs, Pinocchio {r['pinocchio_us']:.1f} µs")
    if write:
        write_docs(out)
        plot(out, DOCS / "rhs_speed.png")
    return out


def plot(out: dict[str, Any], path: Path) -> None:
    """µs per call against the number of states (grown machines, and the two models)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for key, label, mark in (("rhs_us", "rhs (from C)", "o"), ("jac_us", "jac (from C)", "s")):
        for rows, face, what in ((out["grown"], None, "grown"), (out["rows"], "none", "models")):
            x = [r["states"] for r in rows]
            a1.plot(x, [r[key] for r in rows], mark, mfc=face,
                    label=f"{label}, {what}", color="C0" if key == "rhs_us" else "C1")
    a1.set_xlabel("states")
    a1.set_ylabel("µs per call")
    a1.set_title("generated code, called from C")
    a1.legend(fontsize=8)
    a1.grid(alpha=0.3)
    for rows, face, what in ((out["grown"], None, "grown"), (out["rows"], "none", "models")):
        x = [r["states"] for r in rows]
        a2.plot(x, [r["pinocchio_us"] for r in rows], "o", mfc=face, color="C2",
                label=f"Pinocchio rhs, {what}")
        a2.plot(x, [r["rhs_python_us"] for r in rows], "^", mfc=face, color="C3",
                label=f"generated rhs from Python, {what}")
    a2.set_yscale("log")
    a2.set_xlabel("states")
    a2.set_ylabel("µs per call")
    a2.set_title("called from Python")
    a2.legend(fontsize=8)
    a2.grid(alpha=0.3, which="both")
    fig.tight_layout()
    atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=100, format="png"))
    plt.close(fig)


def write_docs(out: dict[str, Any]) -> None:
    la, lb = out["load_before"], out["load_after"]
    lines = ["# Evaluation cost of the generated dynamics", "",
             "Regenerate with `python benchmarks/rhs_speed.py`. µs per call, best of "
             f"{4 * out['repeats']} repeats of {out['n_loop']:,} calls (from C; "
             f"{out['repeats']} repeats from Python) on a shared "
             f"2-core machine; load average {la[0]:.1f} before and {lb[0]:.1f} after "
             "(best-of-N filters most of the load, the absolute numbers still carry it).", "",
             "- *rhs / jac from C*: the generated C called through its address from a C "
             "loop, as the compiled integrators (DOPRI5, RK4, ROS2) call it "
             "(`MachineSystem.kernels.repeat`); the Jacobian is the exact dense n×n one.",
             "- *rhs from Python*: `MachineSystem.rhs` (ctypes, argument conversion), as scipy's "
             "methods call it.",
             "- *Pinocchio*: `MachineSystem(scene, backend=\"pinocchio\").rhs` — `pin.aba` on "
             "numbers with the same force elements (the reference path); its agreement with "
             "the generated code is the last column (relative, largest component).", "",
             "| scene | states | bodies | nips | route | rhs from C [µs] | jac from C [µs] | "
             "rhs from Python [µs] | Pinocchio rhs [µs] | Pinocchio vs generated |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in out["rows"] + out["grown"]:
        lines.append(f"| {r['scene']} | {r['states']} | {r['bodies']} | {r['nips']} | "
                     f"{r['route']} | {r['rhs_us']:.3f} | {r['jac_us']:.3f} | "
                     f"{r['rhs_python_us']:.2f} | {r['pinocchio_us']:.0f} | "
                     f"{r['pinocchio_vs_compiled']:.0e} |")
    lines += ["", "## Cost per body and per nip", "",
              "Least-squares fit `µs = c0 + c_body · bodies + c_nip · nips` over the grown "
              "machines (a unit adds two bodies — a speed-profile drum without states and a "
              "roll free in z — and one nip; a rider adds one body and one nip):", "",
              "| quantity | c0 [µs] | per body [µs] | per nip [µs] | largest residual [µs] | "
              "slope per unit [µs] | slope per rider [µs] |",
              "|---|---|---|---|---|---|---|"]
    for k, label in (("rhs_us", "rhs from C"), ("jac_us", "jac from C"),
                     ("pinocchio_us", "Pinocchio rhs")):
        f = out["fits"][k]
        lines.append(f"| {label} | {f['c0']:.3f} | {f['per_body']:.3f} | {f['per_nip']:.3f} | "
                     f"{f['max_residual']:.3f} | {f['per_unit']:.3f} | {f['per_rider']:.3f} |")
    lines += ["", "![µs per call against states](rhs_speed.png)", ""]
    text = "\n".join(lines)
    atomic_write(DOCS / "rhs_speed.md", lambda tmp: tmp.write_text(text, encoding="utf-8"))
    js = json.dumps(out, indent=1)
    atomic_write(DOCS / "rhs_speed.json", lambda tmp: tmp.write_text(js, encoding="utf-8"))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer calls and repeats")
    main(ap.parse_args().quick)
