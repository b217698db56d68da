"""Purpose: a PI drum-speed controller drives the winder FMU through FMPy (paper's Fig. 17).

The native FMU (no Python inside) is exported from ``models/paper_winding.toml`` with
the drum freed (``speed_profile = false``, a build option: the free drum is another
machine): the controller reads the web-speed reference and the drum speed, and writes
``drum_torque_command`` every communication step while the roll grows.

    python examples/speed_control_fmu.py [--t-end 700] [--step 0.01] [--out out]
"""

from __future__ import annotations

import argparse
import shutil
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


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


NAMES = ["web_speed_reference", "drum_speed", "roll_speed", "radius", "normal_force",
         "friction_force"]
R = 0.5  # drum radius [m] (the scene's)


def build(out: Path) -> Path:
    """The paper scene's FMU with its drum freed, at ``out / winder.fmu``."""
    from winder.fmu.native import build_fmu
    return build_fmu(ROOT / "models" / "paper_winding.toml", out / "winder.fmu",
                     speed_profile=False)


def closed_loop(fmu_file: Path, t_end: float, step: float, progress: bool = False
                ) -> tuple[np.ndarray, float]:
    """The PI loop through the FMU: per communication point ``t``, the torque written
    and the outputs :data:`NAMES`; and the wall time [s]."""
    import fmpy
    from fmpy.fmi2 import FMU2Slave

    md = fmpy.read_model_description(str(fmu_file))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    unzip = fmpy.extract(str(fmu_file))
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip,
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="pi")
    fmu.instantiate(loggingOn=True)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setBoolean([refs["speed_profile"]], [False])  # free drum, torque input
    fmu.exitInitializationMode()

    J_d = 400.0      # drum inertia [kg m²]
    bandwidth = 10.0  # speed loop crossover [rad/s]
    kp = bandwidth * J_d / R            # [N·m per m/s]
    pi = PI(kp=kp, ki=kp * bandwidth / 4.0, limit=4000.0)
    names = NAMES
    n = int(round(t_end / step))
    log = np.empty((n + 1, len(names) + 2))
    vr = [refs[k] for k in names]
    wall0 = time.perf_counter()
    t, torque = 0.0, 0.0
    for i in range(n + 1):
        vals = fmu.getReal(vr)
        log[i] = [t, torque, *vals]
        if i == n:
            break
        v_ref, drum_speed = vals[0], vals[1]
        torque = pi(v_ref - drum_speed * R, step)
        fmu.setReal([refs["drum_torque_command"]], [torque])
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=step)
        t = (i + 1) * step
        if progress and i % 5000 == 0:
            end = "\r" if sys.stderr.isatty() else "\n"
            sys.stderr.write(f"t = {t:7.1f} s  radius {vals[3]:.3f} m{end}")
    wall = time.perf_counter() - wall0
    fmu.terminate()
    fmu.freeInstance()
    shutil.rmtree(unzip, ignore_errors=True)
    if progress and sys.stderr.isatty():
        sys.stderr.write("\n")
    return log, wall


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=700.0, help="end time [s]")
    ap.add_argument("--step", type=float, default=0.01, help="communication step [s]")
    ap.add_argument("--out", type=Path, default=ROOT / "out", help="output folder")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    if sys.stderr.isatty():  # the FMU's compile takes seconds
        print("speed_control_fmu: building the paper scene's FMU (its C code compiled) ...",
              file=sys.stderr, flush=True)
    fmu_file = build(args.out)
    log, wall = closed_loop(fmu_file, args.t_end, args.step, progress=True)
    names, step, t_end = NAMES, args.step, args.t_end

    T, tau = log[:, 0], log[:, 1]
    cols = dict(zip(names, log[:, 2:].T, strict=True))
    web = cols["drum_speed"] * R
    err = cols["web_speed_reference"] - web
    settled = T > 2.0
    print(f"{t_end:g} s in {wall:.1f} s wall (real-time factor {t_end / wall:.0f}), "
          f"{step * 1e3:g} ms steps; final radius {cols['radius'][-1]:.3f} m; "
          f"web-speed error after 2 s: max {np.max(np.abs(err[settled])):.2e} m/s")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    ax[0].plot(T, cols["web_speed_reference"], "k--", label="reference $v_{ref}$")
    ax[0].plot(T, web, label="drum surface $\\Omega R$")
    ax[0].plot(T, cols["roll_speed"] * cols["radius"], ":", label="roll surface $\\omega r$")
    ax[0].set_ylabel("speed [m/s]")
    ax[0].legend()
    ax[1].plot(T, err * 1e3)
    ax[1].set_ylabel("tracking error [mm/s]")
    ax[2].plot(T, tau)
    ax[2].set_ylabel("drum torque [N·m]")
    ax[2].set_xlabel("t [s]")
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle("PI drum-speed control of the winder FMU (FMPy host)")
    fig.tight_layout()
    png = args.out / "speed_control_fmu.png"
    fig.savefig(png, dpi=100)
    print(f"plot written to {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
