"""Purpose: the dancer loop's margins at a full and an empty parent roll (issue #34).

The shipped line with a dancer (models/winder_line_dancer.toml) is linearised
(:func:`winder.linearise`, the set at r = 0.3 m) with its unwind on a torque input, once
with the parent full (r = 1.25 m) and once nearly empty (r = 0.45 m); the plant from the
unwind torque to the dancer's position closes through the dancer controller of
docs/guide/idlers-dancers-spans.md (gains scheduled on the parent's r and J(r) for the
bandwidth ω_c), and
python-control gives the loop's gain and phase margins. The scheduling keeps the crossover
and the phase margin nearly the same over the 33× fall of the parent's inertia.

    python examples/dancer_loop_margins.py
"""

from __future__ import annotations

import math
from pathlib import Path

import control

import winder
from winder.model.paper_roll import paper_roll_mass

MODEL = Path(__file__).resolve().parents[1] / "models" / "winder_line_dancer.toml"


def margins(radius: float, bandwidth: float = 2.0) -> tuple[float, float, float, float]:
    """``(gain margin [-], phase margin [deg], their frequencies [rad/s])`` of the dancer
    loop with the parent at ``radius`` [m]."""
    data = winder.load_scene(MODEL).to_dict()
    parent = next(r for r in data["roll"] if r["name"] == "parent")
    parent["initial_radius"] = radius
    parent["drive"] = {"kind": "torque", "torque": -1000.0 * radius}
    scene = winder.scene_from_dict(data, source=str(MODEL))
    plant = winder.linearise(scene, 0.3, inputs=["parent_torque"], outputs=["dancer_position"])
    p = scene.rolls[1]
    _, J, _, _ = paper_roll_mass(radius, p.core_radius, p.core_mass, p.core_inertia,
                                 math.pi * p.density * p.width)
    g = radius / (2.0 * J)  # d'' = g δτ
    wc = bandwidth
    pid = control.tf([3.0 * wc / g, 3.0 * wc**2 / g, wc**3 / g], [1.0, 0.0])
    gm, pm, w_gm, w_pm = control.margin(pid * control.ss2tf(plant))
    return float(gm), float(pm), float(w_gm), float(w_pm)


def main() -> None:
    for label, radius in (("full", 1.25), ("empty", 0.45)):
        gm, pm, w_gm, w_pm = margins(radius)
        print(f"parent {label} (r = {radius} m): gain margin {gm:.3g} "
              f"({20 * math.log10(gm):.1f} dB) at {w_gm:.4g} rad/s, phase margin {pm:.3g}° "
              f"at {w_pm:.3g} rad/s")


if __name__ == "__main__":
    main()
