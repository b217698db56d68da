"""Purpose: two PI drum-speed controllers drive the two-drum winder FMU through FMPy, one
torque input per drum.

The FMU is exported from ``models/two_drum_winder.toml`` with both drums torque-driven
(``drive = { kind = "torque" }``) as a native FMU (the compiled machine, no Python
inside): its inputs are ``front_torque`` and
``rear_torque``.
Each controller reads its drum's speed and writes its torque every communication step,
following the scene's web-speed ramp ``min(a_w t, v_w)``; the set and the rider ride on
the two drums and share their load through the nips.

    python examples/two_drum_speed_control_fmu.py [--t-end 20] [--step 0.01] [--out out]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DRUMS = ("front", "rear")


class PI:
    """``u = Kp e + Ki ∫e``, clamped to ``±limit`` with conditional integration
    (anti-windup)."""

    def __init__(self, kp: float, ki: float, limit: float) -> None:
        self.kp, self.ki, self.limit = kp, ki, limit
        self.integral = 0.0

    def __call__(self, error: float, dt: float) -> float:
        u = self.kp * error + self.ki * (self.integral + error * dt)
        if abs(u) < self.limit:
            self.integral += error * dt
        return float(np.clip(u, -self.limit, self.limit))


def torque_driven_scene(out: Path) -> tuple[Any, float, float]:
    """The two-drum winder with both drums torque-driven from rest (a
    :class:`winder.Scene`, also written to ``out``), and the web-speed ramp its drums
    followed: acceleration [m/s²] and final speed [m/s]."""
    import tomli_w

    import winder

    base = winder.load_scene(ROOT / "models" / "two_drum_winder.toml")
    ramp = base.drums[0].drive
    data = base.to_dict()
    for drum in data["drum"]:
        drum["drive"] = {"kind": "torque", "torque": 0.0, "web_speed": 0.0}
    scene = winder.scene_from_dict(data)  # validated
    out.write_text(tomli_w.dumps(data), encoding="utf-8")
    return scene, ramp.web_acceleration, ramp.web_speed


def main(argv: list[str] | None = None) -> int:
    from winder.fmu.host import loaded_fmu, start_fmu
    from winder.fmu.native import build_fmu

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=20.0, help="end time [s]")
    ap.add_argument("--step", type=float, default=0.01, help="communication step [s]")
    ap.add_argument("--out", type=Path, default=ROOT / "out", help="output folder")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    scene_file = args.out / "two_drum_torque.toml"
    scene, a_w, v_w = torque_driven_scene(scene_file)
    drums = {d.name: (d.radius, d.inertia) for d in scene.drums}  # [m, kg·m²]
    fmu_file = build_fmu(scene_file, args.out / "two_drum_torque.fmu")

    bandwidth = 10.0      # speed loop crossover [rad/s]
    pis = {}
    for name, (R, J) in drums.items():
        kp = bandwidth * J / R  # [N·m per m/s]
        pis[name] = PI(kp=kp, ki=kp * bandwidth / 4.0, limit=20000.0)
    reads = [f"{d}_speed" for d in DRUMS] + ["set_speed", "set_radius",
                                             "front_nip_normal_force", "rear_nip_normal_force",
                                             "rider_nip_normal_force"]
    n = int(round(args.t_end / args.step))
    log = np.empty((n + 1, 1 + len(DRUMS) + len(reads)))
    wall0 = time.perf_counter()
    with loaded_fmu(fmu_file, instance_name="pi2") as (fmu, refs, _):
        start_fmu(fmu, refs)
        vr = [refs[k] for k in reads]
        inputs = [refs[f"{d}_torque"] for d in DRUMS]
        t, torques = 0.0, [0.0] * len(DRUMS)
        for i in range(n + 1):
            vals = fmu.getReal(vr)
            log[i] = [t, *torques, *vals]
            if i == n:
                break
            v_ref = min(a_w * (t + args.step), v_w)  # the speed to reach by the step's end
            torques = [pis[d](v_ref - drums[d][0] * vals[k], args.step)
                       for k, d in enumerate(DRUMS)]
            fmu.setReal(inputs, torques)
            fmu.doStep(currentCommunicationPoint=t, communicationStepSize=args.step)
            t = (i + 1) * args.step
        fmu.terminate()
        fmu.freeInstance()
    wall = time.perf_counter() - wall0

    T = log[:, 0]
    tau = dict(zip(DRUMS, log[:, 1:1 + len(DRUMS)].T, strict=True))
    cols = dict(zip(reads, log[:, 1 + len(DRUMS):].T, strict=True))
    v_ref = np.minimum(a_w * T, v_w)
    t_settle = min(2.0, 0.5 * args.t_end)  # [s] the loops' start-up left out
    settled = T > t_settle
    errs = {d: float(np.max(np.abs(v_ref - drums[d][0] * cols[f"{d}_speed"])[settled]))
            for d in DRUMS}
    print(f"{args.t_end:g} s in {wall:.1f} s wall, {args.step * 1e3:g} ms steps; "
          f"final set radius {cols['set_radius'][-1]:.5f} m")
    # paper on the set two ways: wound length ∫ r ω dt, and from the radius (ṙ = h ω / 2π
    # gives π (r² − r_c²) = h ∫ r ω dt)
    r, w = cols["set_radius"], cols["set_speed"]
    length = float(np.sum(0.5 * (r[1:] * w[1:] + r[:-1] * w[:-1]) * np.diff(T)))
    (roll,) = scene.rolls
    caliper, r_core = roll.caliper, roll.core_radius  # [m]
    print(f"paper wound: {length:.4f} m by the set's surface speed, "
          f"{np.pi * (r[-1] ** 2 - r_core ** 2) / caliper:.4f} m by its radius")
    for d in DRUMS:
        print(f"{d}: web-speed error after {t_settle:g} s: max {errs[d]:.2e} m/s; "
              f"mean torque after {t_settle:g} s {np.mean(tau[d][settled]):.0f} N·m")
    return 0


if __name__ == "__main__":
    sys.exit(main())
