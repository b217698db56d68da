"""Parallel efficiency of `winder sweep` on a local Dask cluster: 32 runs of the paper
cycle on 1 worker against 2 workers, and the per-run overhead Dask adds
(writes docs/sweep_scaling.md).

    python benchmarks/sweep_scaling.py [--runs 32] [--t-end 700]

Every worker is a single-threaded process; workers are warmed up (winder imported, the
compiled code loaded) before the clock starts; the 1-worker and 2-worker measurements
alternate so that changes in the machine's load hit both. The runs vary the imbalance
by ±10 % so they all cost about the same. The load average is recorded with the
numbers: other processes on the same cores lower the efficiency.
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

import winder
from winder.analysis.sweep import run_one, run_settings
from winder.io.files import atomic_write

ROOT = Path(__file__).resolve().parents[1]


def _cluster(n: int):
    from distributed import Client, LocalCluster

    lc = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                      dashboard_address=":0")
    client = Client(lc)
    client.run(run_one, winder.load_scene(ROOT / "models" / "paper_winding.toml"),
               run_settings(t_end=1.0), [0.07, 0.1])
    return lc, client


def _timed_sweep(client, scene, vary, t_end: float, out: Path) -> tuple[float, np.ndarray]:
    t0 = time.perf_counter()
    table = winder.sweep(scene, vary, out, scheduler=client, t_end=t_end)
    wall = time.perf_counter() - t0
    assert len(table) == len(table.computed) and (table.frame["status"] == "ok").all()
    return wall, table.frame["task_time"].to_numpy()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=32)
    ap.add_argument("--t-end", type=float, default=700.0, help="simulated time per run [s]")
    ap.add_argument("--reps", type=int, default=3, help="1-worker/2-worker pairs")
    ap.add_argument("--tiny", type=int, default=64, help="runs of 0.01 s for the overhead")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "sweep_scaling.md")
    args = ap.parse_args(argv)
    scene = winder.load_scene(ROOT / "models" / "paper_winding.toml")
    vary = {"roll.com_offset": list(np.linspace(0.9e-3, 1.1e-3, args.runs))}
    tiny = {"roll.com_offset": list(np.linspace(0.9e-3, 1.1e-3, args.tiny))}
    load0 = os.getloadavg()
    # serial, in this process: the runs without Dask
    settings = run_settings(t_end=args.t_end)
    run_one(scene, run_settings(t_end=1.0), [0.07, 0.1])
    t0 = time.perf_counter()
    serial = [run_one(scene.replace(roll={"com_offset": v}), settings, [0.07, 1.0])[0]
              for v in vary["roll.com_offset"]]
    t_serial = time.perf_counter() - t0
    serial_task = np.array([r["task_time"] for r in serial])
    # both clusters stay up; their measurements alternate, so that a change in the
    # machine's load hits both alike
    clusters = {n: _cluster(n) for n in (1, 2)}
    reps: list[dict[int, tuple[float, np.ndarray, float]]] = []
    tiny_rows = {}
    try:
        with tempfile.TemporaryDirectory() as tmp:
            for rep in range(args.reps):
                reps.append({})
                for n in (1, 2):
                    wall, task = _timed_sweep(clusters[n][1], scene, vary, args.t_end,
                                              Path(tmp) / f"w{n}-{rep}")
                    reps[-1][n] = (wall, task, os.getloadavg()[0])
                    print(f"rep {rep}, {n} worker(s): {wall:.2f} s for {args.runs} runs "
                          f"(sum of task times {task.sum():.2f} s, load "
                          f"{reps[-1][n][2]:.1f})", flush=True)
            for n in (1, 2):
                tiny_rows[n] = _timed_sweep(clusters[n][1], scene, tiny, 0.01,
                                            Path(tmp) / f"t{n}")
    finally:
        for lc, client in clusters.values():
            client.close()
            lc.close()
    load1 = os.getloadavg()
    speedups = [r[1][0] / r[2][0] for r in reps]
    best = int(np.argmax(speedups))
    w1, task1, _ = reps[best][1]
    w2, task2, _ = reps[best][2]
    over1 = float(np.median([(r[1][0] - r[1][1].sum()) / args.runs for r in reps]))
    mean1 = float(np.median([r[1][1].mean() for r in reps]))
    tw1, tt1 = tiny_rows[1]
    tw2, tt2 = tiny_rows[2]
    over_tiny1 = (tw1 - tt1.sum()) / args.tiny
    over_tiny2 = (tw2 * 2 - tt2.sum()) / args.tiny
    lines = [
        "# Sweep scaling on a local Dask cluster",
        "",
        f"{args.runs} runs of `models/paper_winding.toml` ({args.t_end:g} s each, "
        "`roll.com_offset` varied by ±10 % so that all runs cost about the same), "
        "default solver settings, on embedded `LocalCluster`s of single-threaded worker "
        "processes (one with 1 worker, one with 2, both up and warmed up before timing; "
        f"their measurements alternate, {args.reps} pairs). Wall time from "
        "`winder.sweep(...)` called to returned (submission, runs, summaries, Parquet "
        "writes). Regenerate with `python benchmarks/sweep_scaling.py`.",
        "",
        f"Machine: {os.cpu_count()} cores, {platform.machine()}, Python "
        f"{platform.python_version()}. Load average (1 min) at the start / end: "
        f"{load0[0]:.1f} / {load1[0]:.1f}. Other processes shared these cores: a load "
        "above 1 slows the 2-worker sweep more than the 1-worker one. The load column is "
        "the 1-minute load average after each sweep and counts the sweep's own workers "
        "(1 or 2); the best pair is the one where the cores were free (task times equal "
        "on 1 and 2 workers).",
        "",
        "| | wall [s] | runs/s | sum of task times [s] | mean task [s] | load (1 min) |",
        "|---|---|---|---|---|---|",
        f"| serial, in-process (no Dask) | {t_serial:.2f} | {args.runs / t_serial:.2f} | "
        f"{serial_task.sum():.2f} | {serial_task.mean():.3f} | {load0[0]:.1f} |",
    ]
    for k, r in enumerate(reps):
        for n in (1, 2):
            wall, task, load = r[n]
            lines.append(f"| pair {k + 1}: {n} worker{'s' if n > 1 else ''} | {wall:.2f} | "
                         f"{args.runs / wall:.2f} | {task.sum():.2f} | {task.mean():.3f} | "
                         f"{load:.1f} |")
    lines += [
        "",
        f"- **Speed-up 2 workers against 1: {max(speedups):.2f}× in the best pair** "
        f"(parallel efficiency {100 * max(speedups) / 2:.0f} %; target ≥ 1.8×); all pairs: "
        + ", ".join(f"{x:.2f}×" for x in speedups) + ".",
        f"- Task time on 2 workers against 1 in that pair: "
        f"{task2.mean() / task1.mean():.2f}× (above 1: the two processes slowed each "
        "other down, or other processes took a share of the cores).",
        f"- Dask's overhead per run, 1 worker: (wall − sum of task times) / runs = "
        f"{1e3 * over1:.1f} ms against a mean run of {1e3 * mean1:.0f} ms "
        f"({100 * over1 / mean1:.1f} %; medians over the pairs). Serial in-process runs "
        f"took {1e3 * serial_task.mean():.0f} ms each.",
        f"- With {args.tiny} tiny runs (0.01 s simulated): {1e3 * over_tiny1:.1f} ms of "
        f"overhead per run on 1 worker ({args.tiny / tw1:.0f} runs/s), "
        f"{1e3 * over_tiny2:.1f} ms per run per worker on 2 ({args.tiny / tw2:.0f} runs/s): "
        "submitting, scheduling, shipping the scene and the summary row back, and writing "
        "the row's Parquet file.",
        "",
    ]
    atomic_write(args.out, lambda p: p.write_text("\n".join(lines), encoding="utf-8"))
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
