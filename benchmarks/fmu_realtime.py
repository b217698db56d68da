"""Real-time factor of the FMU (FMPy host) and of the in-process Stepper, at 1 ms and
10 ms communication steps (writes docs/fmu_realtime.md).

    python benchmarks/fmu_realtime.py [--t-end 60]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import winder
from winder.fmu.build import build_fmu
from winder.io.files import atomic_write

ROOT = Path(__file__).resolve().parents[1]


def fmu_run(fmu_file: Path, t_end: float, step: float) -> float:
    from winder.fmu.host import loaded_fmu, start_fmu

    with loaded_fmu(fmu_file, instance_name="rt") as (fmu, refs, _):
        start_fmu(fmu, refs, logging=False)
        out = [refs[k] for k in winder.CHANNELS[1:]]
        n = int(round(t_end / step))
        t0 = time.perf_counter()
        for i in range(n):  # a host reads every output each step
            fmu.doStep(currentCommunicationPoint=i * step, communicationStepSize=step)
            fmu.getReal(out)
        wall = time.perf_counter() - t0
        fmu.terminate()
        fmu.freeInstance()
    return wall


def stepper_run(scene: winder.Scene, t_end: float, step: float) -> float:
    sim = winder.Stepper(scene)
    n = int(round(t_end / step))
    t0 = time.perf_counter()
    for _ in range(n):
        sim.step(step)
        sim.outputs()
    return time.perf_counter() - t0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=60.0, help="simulated time [s]")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "fmu_realtime.md")
    args = ap.parse_args(argv)
    scene_file = ROOT / "models" / "paper_winding.toml"
    scene = winder.load_scene(scene_file)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        fmu_file = build_fmu(scene_file, Path(tmp) / "winder.fmu")
        for step in (1e-3, 1e-2):
            w_fmu = fmu_run(fmu_file, args.t_end, step)
            w_st = stepper_run(scene, args.t_end, step)
            rows.append((step, w_fmu, w_st))
            print(f"step {step * 1e3:g} ms: FMU {args.t_end / w_fmu:.1f}x real time, "
                  f"Stepper {args.t_end / w_st:.1f}x", file=sys.stderr)
    lines = ["# Real-time factor of the FMU", "",
             f"`models/paper_winding.toml`, speed-profile configuration, first {args.t_end:g} s "
             "(ramp, then the bouncing phase from 20.6 s). The FMU is driven by FMPy's "
             "`FMU2Slave` step API and all 15 spec channels are read each step; the Stepper "
             "is the same model in-process. Internal integrator: compiled DOPRI5, rtol 1e-8. "
             "Real-time factor = simulated time / wall time. Regenerate with "
             "`python benchmarks/fmu_realtime.py`.", "",
             "| communication step | FMU wall [s] | FMU real-time factor | Stepper wall [s] "
             "| Stepper real-time factor |", "|---|---|---|---|---|"]
    for step, w_fmu, w_st in rows:
        lines.append(f"| {step * 1e3:g} ms | {w_fmu:.2f} | {args.t_end / w_fmu:.1f} | {w_st:.2f} "
                     f"| {args.t_end / w_st:.1f} |")
    text = "\n".join(lines) + "\n"
    atomic_write(args.out, lambda p: p.write_text(text, encoding="utf-8"))
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
