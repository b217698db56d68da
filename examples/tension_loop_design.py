"""Purpose: Bode plot and margins of the unwind tension loop at a full, half and empty parent.

The winder line (``models/winder_line.toml``) with its parent roll torque-driven is the
open-loop plant ``P(s) = δT/δτ`` (span tension over unwind torque) at each parent radius
(full 1.25 m, half its paper 0.93 m, empty 0.41 m on the 0.4 m spool); the controller is
the model's own (``winder.forces.tension_control``)::

    δτ = K(s) δT,   K(s) = k_d s + k_p + k_i / s,   g = EA r / (L J(r)),
    k_d = 3 ω_c / g,   k_p = 3 ω_c² / g − r,   k_i = ω_c³ / g

The loop gain is ``L(s) = −P(s) K(s)``. The parent's inertia falls by 40× from full to
empty, but every gain carries ``1/g``: ``g`` cancels from the characteristic polynomial
``1 + L(s)``, so the closed-loop poles are the same at every diameter (the rule's
``(s + ω_c)³`` of the two-state span-and-roll model, moved by what that model lacks: the
span's transport ``v/L`` and the nips). Checked in closed loop: the loop closed here has
the poles of the linearised tension-controlled machine (the controller inside the
nonlinear model), and the linear closed loop's response to a set-point step equals the
nonlinear line's (:class:`winder.Stepper`, the built-in controller) at the half parent.

Writes ``tension_loop_design.png`` to ``--out``.

    python examples/tension_loop_design.py [--out out] [--quick]
"""

from __future__ import annotations

import argparse
import copy
import math
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "models" / "winder_line.toml"
#: Parent radii [m]: full, half its paper (√((R² + r_c²)/2)), nearly empty.
PARENTS = {"full": 1.25, "half": math.sqrt((1.25 ** 2 + 0.4 ** 2) / 2), "empty": 0.41}
SET_RADIUS = 0.2  # [m] the wound roll at the operating point


def line(parent_radius: float, *, torque: bool, web_speed: float | None = None,
         web_acceleration: float | None = None):
    """The winder line with its parent at ``parent_radius`` [m]: torque-driven (holding
    the set-point tension, ``τ = −r T*``) or tension-controlled; optionally a faster drum
    ramp to ``web_speed`` [m/s] (for the closed-loop run)."""
    import winder

    data = copy.deepcopy(winder.load_scene(SCENE).to_dict())
    for roll in data["roll"]:
        if roll["name"] == "parent":
            roll["initial_radius"] = parent_radius
            if torque:
                tension = roll["drive"]["tension"]
                roll["drive"] = {"kind": "torque", "torque": -parent_radius * tension}
    if web_speed is not None:
        for drum in data["drum"]:
            drum["drive"].update(web_speed=web_speed, web_acceleration=web_acceleration)
    return winder.scene_from_dict(data, source=str(SCENE))


def controller(plant, radius: float, bandwidth: float, EA: float, length: float):
    """``K(s)`` of the tuning rule at parent radius ``radius`` [m] (its inertia from the
    plant's operating point)."""
    import control as ct

    J = plant.operating_point["y"][list(plant.output_labels).index("parent_inertia")]
    g = EA * radius / (length * J)
    kd, kp, ki = 3 * bandwidth / g, 3 * bandwidth ** 2 / g - radius, bandwidth ** 3 / g
    s = ct.tf("s")
    return kd * s + kp + ki / s, J


def closed_loop_check(bandwidth: float, quick: bool) -> tuple[float, float]:
    """The half parent, the drums ramped to 10 m/s in 2 s, then a +20 N set-point step:
    the largest difference [N] between the Stepper's tension (the nonlinear line, its
    built-in controller) and the linear closed loop's prediction, and the step's peak
    response [N]."""
    import control as ct

    import winder

    v, step, dt, T = 10.0, 20.0, 2e-3, 0.6 if quick else 1.0
    scene = line(PARENTS["half"], torque=False, web_speed=v, web_acceleration=5.0)
    sim = winder.Stepper(scene)
    sim.step(4.0)
    set_r = sim.state["set.radius"]
    plant = winder.linearise(scene, set_r, web_speed=v, inputs=["parent_tension_setpoint"],
                             outputs=["span_tension"])
    T0 = sim.output("span_tension")
    sim.set_input("parent_tension_setpoint", 1000.0 + step)
    ts, got = [0.0], [T0]
    for _ in range(int(round(T / dt))):
        sim.step(dt)
        ts.append(ts[-1] + dt)
        got.append(sim.output("span_tension"))
    lin = T0 + step * ct.step_response(plant[0, 0], T=np.array(ts)).outputs
    return float(np.max(np.abs(np.array(got) - lin))), float(np.max(np.abs(lin - T0)))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out", help="output directory (default out)")
    ap.add_argument("--quick", action="store_true", help="fewer frequencies, a shorter "
                    "closed-loop run (for the tests)")
    args = ap.parse_args()
    import control as ct
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import winder

    scene = winder.load_scene(SCENE)
    span = scene.web.span
    parent = next(r for r in scene.rolls if r.name == span.source)
    wc = parent.drive.bandwidth  # [rad/s]
    omega = np.logspace(-1, 3, 200 if args.quick else 800)  # [rad/s]
    fig, (ax_m, ax_p, ax_z) = plt.subplots(3, 1, figsize=(8, 10))
    t0 = time.perf_counter()
    poles_by = {}
    for (label, r), colour in zip(PARENTS.items(), ("C0", "C1", "C2"), strict=True):
        plant = winder.linearise(line(r, torque=True), SET_RADIUS,
                                 inputs=["parent_torque"],
                                 outputs=["span_tension", "parent_inertia"])
        K, J = controller(plant, r, wc, span.EA, span.length)
        loop = -ct.tf(plant[0, 0]) * K
        gm, pm, wg, wp = ct.margin(loop)
        closed = np.sort_complex(ct.feedback(loop, 1).poles())
        slow = closed[np.abs(closed) < 4 * wc]  # the tension loop's three
        # the same loop closed inside the nonlinear model: the tension-controlled machine
        inside = np.linalg.eigvals(np.asarray(winder.linearise(
            line(r, torque=False), SET_RADIUS, inputs=["parent_tension_setpoint"],
            outputs=["span_tension"]).A))
        agree = max(np.min(np.abs(inside - p)) / abs(p) for p in slow)
        poles_by[label] = slow
        print(f"{label:5s} parent r = {r:.3f} m, J = {J:8.1f} kg·m²: gain margin "
              f"{'inf' if not np.isfinite(gm) else f'{20 * np.log10(gm):.1f} dB'}, phase "
              f"margin {pm:.1f}° at {wp:.2f} rad/s; closed-loop poles "
              + ", ".join(f"{p.real:.3f}{p.imag:+.3f}j" for p in slow)
              + f" (the tension-controlled machine's: {agree:.1e})")
        mag, phase, _ = ct.frequency_response(loop, omega)
        ax_m.semilogx(omega, 20 * np.log10(np.abs(mag)), colour, label=f"{label} ({r:.2f} m)")
        ax_p.semilogx(omega, np.degrees(np.unwrap(phase)), colour)
        ax_z.plot(slow.real, slow.imag, "o", color=colour, mfc="none", ms=8 + 4 * len(poles_by))
    spread = max(np.max(np.abs(poles_by[k] - poles_by["full"])) for k in poles_by)
    print(f"closed-loop poles equal at every diameter to {spread:.1e} rad/s")
    err, peak = closed_loop_check(wc, args.quick)
    print(f"closed loop against the nonlinear line (half parent, +20 N set-point step): max "
          f"difference {err:.3g} N of a {peak:.3g} N response")
    print(f"linearise and margins: {time.perf_counter() - t0:.1f} s")
    ax_m.axhline(0, color="k", lw=0.5)
    ax_m.set(ylabel="|L(jω)| [dB]", title="Unwind tension loop L(s) = −P(s) K(s)")
    ax_m.legend()
    ax_p.axhline(-180, color="k", lw=0.5)
    ax_p.set(xlabel="ω [rad/s]", ylabel="phase [°]")
    ax_z.axvline(-wc, color="k", lw=0.5, ls=":")
    ax_z.set(xlabel="Re [1/s]", ylabel="Im [1/s]",
             title=f"closed-loop poles (the rule's −ω_c = −{wc:g} rad/s dotted)")
    fig.tight_layout()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "tension_loop_design.png", dpi=100)
    print(f"figure written to {out / 'tension_loop_design.png'}")


if __name__ == "__main__":
    main()
