"""Purpose: closed-loop tension control of the winder line through its FMU, a whole parent roll.

The FMU is exported from ``models/winder_line_fmu.toml`` (the small line, its parent roll
torque-driven: input ``parent_torque``) as a native FMU (``winder fmu``: the
compiled machine, no Python inside). Every
communication step the controller reads the FMU's outputs (span tension, the parent's
radius and speed, the entry drum's speed and acceleration) and writes the unwind torque
by the rule of
``src/winder/forces/tension_control.py`` (the model's own controller, here outside it)::

    τ = J(r) ω̇_ref − r T* − k_p e − k_i ∫e dt + k_d dT/dt,      e = T* − T
    g = EA r / (L_s J(r)),  k_d = 3 ω_c / g,  k_p = 3 ω_c² / g − r,  k_i = ω_c³ / g

``J(r)`` from the paper-roll law, ``dT/dt`` from the span's equation, ``∫e`` by the
trapezoidal rule over the samples; the torque is held over each step. The entry drum's
web-speed rate in ``ω̇_ref`` is, by default, the mean over the coming step of the line's
speed reference ``min(a_w t, v_w)`` (the drive master's, known ahead);
``--feedforward measured`` takes the drum's acceleration output at the step's start
instead, which holds the ramp's feed-forward one step past the ramp's end. The run goes
on until the parent reaches its core: the FMU then refuses the step (fmi2Discard) and
terminates at the run-out time, which is printed as the planned end it is.
Writes ``tension_control_fmu.png`` and ``tension_control_fmu.npz`` to ``--out``.

    python examples/tension_control_fmu.py [--t-end 60] [--step 0.002] [--out out]
                                           [--fmu FILE.fmu]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "models" / "winder_line_fmu.toml"
#: FMU outputs the controller and the log read.
READS = ("t", "span_tension", "parent_radius", "parent_speed", "rear_speed", "rear_accel",
         "set_radius", "set_speed", "parent_inertia")


class TensionLaw:
    """The unwind's tension controller, from the FMU's outputs (gains by the rule of
    ``winder.forces.tension_control``). The rule puts the three poles of its two-state
    design model (the span's compliance, the parent's speed) at ``−ω_c``; on the machine
    the span's transport and the nips move them (``examples/tension_loop_design.py``
    computes them for the winder line; docs/control.md quotes them)."""

    def __init__(self, scene: Any, tension: float, bandwidth: float,
                 feedforward: str = "profile") -> None:
        span = scene.web.span
        parent = next(r for r in scene.rolls if r.name == span.source)
        entry = next(n for n in scene.nips if n.name == scene.web.entry_nip)
        drum = next(d for d in scene.drums if d.name == entry.a)
        self.T_set, self.wc = tension, bandwidth  # [N], [rad/s]
        self.EA, self.L, self.T_in = span.EA, span.length, span.T_in  # [N], [m], [N]
        self.R = drum.radius  # entry drum [m]
        d = drum.drive  # its speed profile: ratio · min(a_w t, v_w) [m/s]
        self.profile = (d.ratio * d.web_acceleration, d.ratio * d.web_speed)
        self.feedforward = feedforward
        self.rc, self.mc, self.Jc = parent.core_radius, parent.core_mass, parent.core_inertia
        self.k = math.pi * parent.density * parent.width  # [kg/m²]
        self.h = parent.caliper  # [m]

    def inertia(self, r: float) -> float:
        """``J(r)`` [kg·m²] of the parent roll (the paper-roll law)."""
        from winder.model.mass_law import paper_roll_mass

        return float(paper_roll_mass(r, self.rc, self.mc, self.Jc, self.k)[1])

    def web_speed_reference(self, t: float) -> float:
        """The entry drum's web speed [m/s] at ``t`` [s] by its profile."""
        a, v = self.profile
        return min(a * t, v) if a > 0 else v

    def torque(self, y: dict[str, float], integral: float, dt: float
               ) -> tuple[float, float]:
        """``(τ [N·m], e [N])`` to hold over the step of ``dt`` [s] from the outputs
        ``y`` and ``∫e dt`` [N·s]."""
        T, r, w = y["span_tension"], y["parent_radius"], y["parent_speed"]
        v1, v2 = r * w, self.R * y["rear_speed"]  # web speeds [m/s]: unwind, entry drum
        if self.feedforward == "profile":  # the reference's mean rate over the step
            t = y["t"]
            v2_dot = (self.web_speed_reference(t + dt) - self.web_speed_reference(t)) / dt
        else:
            v2_dot = self.R * y["rear_accel"]
        r_dot = -self.h * w / (2.0 * math.pi)
        w_ref_dot = (v2_dot * r - v2 * r_dot) / (r * r)
        T_dot = (self.EA * (v2 - v1) + v1 * self.T_in - v2 * T) / self.L  # the span
        J = self.inertia(r)
        g = self.EA * r / (self.L * J)
        kd, kp, ki = 3.0 * self.wc / g, 3.0 * self.wc ** 2 / g - r, self.wc ** 3 / g
        e = self.T_set - T
        return J * w_ref_dot - r * self.T_set - kp * e - ki * integral + kd * T_dot, e


#: The FMU's message of the planned run-out (logged with status fmi2Discard).
RUN_OUT = "ran out of web"


class RunOutLog:
    """FMPy's callbacks for the FMU's log (FMI 2.0) that keep the planned run-out's
    message (status fmi2Discard, :data:`RUN_OUT`) instead of printing it, and print every
    other message as FMPy does: the run-out is reported once, as planned."""

    def __init__(self) -> None:
        from ctypes import byref

        from fmpy.fmi2 import (
            defaultCallbacks,
            fmi2CallbackFunctions,
            fmi2CallbackLoggerTYPE,
            printLogMessage,
        )

        self.planned: list[str] = []

        def logger(component, instance, status, category, message) -> None:
            text = message.decode("utf-8", "replace")
            if status == 2 and RUN_OUT in text:  # fmi2Discard: the planned run-out
                self.planned.append(text)
            else:
                printLogMessage(component, instance, status, category, message)

        self._logger = fmi2CallbackLoggerTYPE(logger)  # kept alive while the FMU runs
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = self._logger
        self.callbacks.allocateMemory = defaultCallbacks.allocateMemory
        self.callbacks.freeMemory = defaultCallbacks.freeMemory
        try:  # FMPy's proxy formats the message's printf arguments
            from fmpy.logging import addLoggerProxy

            addLoggerProxy(byref(self.callbacks))
        except Exception:  # noqa: BLE001 - without it the message comes unformatted
            pass


def run(fmu_file: Path, law: TensionLaw, t_end: float, dt: float
        ) -> tuple[dict[str, np.ndarray], float | None]:
    """The closed loop until ``t_end`` [s] or the parent's run-out: the log by name
    (``tau``, ``e`` and the outputs :data:`READS`), and the time [s] of the run-out
    (None: none). The run-out is the FMU's step refused with fmi2Discard and the FMU
    terminated (fmi2Terminated) at its last successful time; any other failure of a step
    is raised."""
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import fmi2LastSuccessfulTime, fmi2Terminated

    from winder.fmu.host import loaded_fmu, start_fmu

    rows: list[list[float]] = []
    ended = None
    log = RunOutLog()
    with loaded_fmu(fmu_file, instance_name="tension") as (fmu, refs, _):
        instantiate = fmu.instantiate  # with the callbacks that keep the planned message
        fmu.instantiate = lambda **kw: instantiate(**kw, callbacks=log.callbacks)
        start_fmu(fmu, refs, logging=False)
        vr, u = [refs[k] for k in READS], [refs["parent_torque"]]
        integral, e_prev, i = 0.0, None, 0
        while True:
            y = dict(zip(READS, fmu.getReal(vr), strict=True))
            e = law.T_set - y["span_tension"]
            if e_prev is not None:
                integral += 0.5 * dt * (e + e_prev)
            tau, e = law.torque(y, integral, dt)
            rows.append([tau, e, *y.values()])
            e_prev = e
            if ended is not None or y["t"] >= t_end - 0.5 * dt:
                break
            fmu.setReal(u, [tau])
            try:
                fmu.doStep(currentCommunicationPoint=i * dt, communicationStepSize=dt)
            except FMICallException as exc:  # fmi2Discard and terminated: the run-out
                if exc.status != 2 or not fmu.getBooleanStatus(fmi2Terminated):
                    raise
                ended = fmu.getRealStatus(fmi2LastSuccessfulTime)
                # the outputs are those of the run-out time (read once more above)
            i += 1
        fmu.terminate()
        fmu.freeInstance()
    table = np.array(rows)
    return dict(zip(("tau", "e", *READS), table.T, strict=True)), ended


def plot(log: dict[str, np.ndarray], T_set: float, path: Path) -> None:
    """Tension, error, unwind torque and radii against time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = log["t"]
    fig, ax = plt.subplots(4, 1, figsize=(8, 9), sharex=True)
    ax[0].plot(t, log["span_tension"], label="span tension")
    ax[0].axhline(T_set, color="k", lw=0.8, ls="--", label="set-point")
    ax[0].set_ylabel("T [N]")
    ax[0].legend(loc="lower right")
    ax[1].plot(t, log["e"], color="C3")
    ax[1].set_ylabel("error T* − T [N]")
    ax[2].plot(t, log["tau"], color="C2")
    ax[2].set_ylabel("unwind torque [N·m]")
    ax[3].plot(t, log["parent_radius"], label="parent")
    ax[3].plot(t, log["set_radius"], label="set")
    ax[3].set_ylabel("radius [m]")
    ax[3].set_xlabel("t [s]")
    ax[3].legend()
    ax[0].set_title("Tension control through the winder-line FMU")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    import winder
    from winder.fmu.native import build_fmu

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=60.0,
                    help="end time [s] (the parent runs out at about 56.2 s)")
    ap.add_argument("--step", type=float, default=2e-3, help="communication step [s]")
    ap.add_argument("--tension", type=float, default=1000.0, help="set-point T* [N]")
    ap.add_argument("--bandwidth", type=float, default=10.0, help="ω_c [rad/s]")
    ap.add_argument("--feedforward", choices=("profile", "measured"), default="profile",
                    help="the drum's web-speed rate in J(r)·ω̇_ref: the profile's mean over "
                         "the step, or the measured acceleration at its start")
    ap.add_argument("--out", type=Path, default=ROOT / "out", help="output folder")
    ap.add_argument("--fmu", type=Path,
                    help="a native FMU of models/winder_line_fmu.toml already built (winder "
                         "fmu models/winder_line_fmu.toml -o FILE): run it, build none")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    scene = winder.load_scene(SCENE)
    law = TensionLaw(scene, args.tension, args.bandwidth, args.feedforward)
    wall0 = time.perf_counter()
    if args.fmu is not None:
        fmu_file = args.fmu
    else:
        fmu_file = build_fmu(SCENE, args.out / "winder_line_fmu.fmu")
    wall1 = time.perf_counter()
    log, ended = run(fmu_file, law, args.t_end, args.step)
    wall = time.perf_counter() - wall1
    t, e = log["t"], log["e"]
    k = int(np.argmax(np.abs(e)))
    settled = t >= 1.0
    k1 = int(np.argmax(np.abs(e) * settled))
    print(f"{t[-1]:.4f} s simulated in {wall:.1f} s wall ({t[-1] / wall:.2f}× real time; "
          "native FMU "
          + (f"{args.fmu}" if args.fmu is not None else f"built in {wall1 - wall0:.1f} s")
          + f"), {args.step * 1e3:g} ms steps, "
          f"{len(t) - 1} steps, feed-forward: {args.feedforward}")
    print(f"run-out at t = {ended:.4f} s (planned: the parent reached its core)"
          if ended is not None else "the parent did not run out")
    print(f"parent radius {log['parent_radius'][-1]:.6f} m, set radius "
          f"{log['set_radius'][-1]:.6f} m at the end")
    print(f"tension error: peak {abs(e[k]):.3f} N at t = {t[k]:.3f} s, "
          f"RMS {float(np.sqrt(np.mean(e ** 2))):.4f} N")
    print(f"tension error after 1 s: peak {abs(e[k1]):.3f} N at t = {t[k1]:.3f} s, "
          f"RMS {float(np.sqrt(np.mean(e[settled] ** 2))):.4f} N")
    np.savez(args.out / "tension_control_fmu.npz", **log)
    plot(log, args.tension, args.out / "tension_control_fmu.png")
    print(f"wrote {args.out / 'tension_control_fmu.png'} and "
          f"{args.out / 'tension_control_fmu.npz'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
