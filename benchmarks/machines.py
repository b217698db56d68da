"""Scenes of growing size for the speed benchmarks, written as TOML text (machines spec §8).

``machine_toml(units, riders)``: ``units`` single-drum winding units side by side (a drum,
a wound roll free in ``z`` on it and their nip; a ``[[web]]`` enters each unit's roll), and
``riders`` rider rolls on the first roll (each with its own nip), spread over its top.
"""

from __future__ import annotations

from pathlib import Path

import winder

__all__ = ["machine_toml", "machine_scene", "counts"]

_HEAD = """[scene]
name = "grown_{units}u_{riders}r"
duration = 10.0
output_step = 0.01
gravity = 9.81

[paper]
density = 800.0
caliper = 1e-4
"""

_UNIT = """
[[drum]]
name = "drum{i}"
radius = 0.5
inertia = 50.0
mass = 500.0
centre = [{x:.3f}, 0.0]
drive = {{ kind = "speed_profile", web_acceleration = 1.0, web_speed = 20.0 }}

[[roll]]
name = "roll{i}"
centre = [{x:.3f}, 0.8]
free = ["z"]
core_radius = 0.05
core_mass = 5.0
core_inertia = 0.01
width = 2.0
initial_radius = 0.3
initial_speed = 0.0
com_offset = 0.0005

[[nip]]
name = "nip{i}"
a = "drum{i}"
b = "roll{i}"
contact = {{ law = "linear", stiffness = 1e7, damping = 5e3 }}
friction = {{ mu = 0.3, slip_velocity = 0.05, relaxation_length = 0.01, min_speed = 0.1 }}
"""

_RIDER = """
[[rider]]
name = "rider{j}"
rides = "roll0"
radius = 0.1
mass = 100.0
inertia = 1.0
x = {x:.4f}
load = [[0.05, 1000.0], [0.5, 200.0]]

[[nip]]
name = "rider_nip{j}"
a = "roll0"
b = "rider{j}"
contact = {{ law = "linear", stiffness = 1e7, damping = 5e3 }}
friction = {{ mu = 0.3, slip_velocity = 0.05, relaxation_length = 0.01, min_speed = 0.1 }}
"""


def machine_toml(units: int, riders: int = 0) -> str:
    """The scene text of ``units`` drum–roll units and ``riders`` riders on the first roll."""
    parts = [_HEAD.format(units=units, riders=riders)]
    parts += [_UNIT.format(i=i, x=3.0 * i) for i in range(units)]
    for j in range(riders):  # spread over the top of roll0 (|x| < 0.25 m)
        x = 0.0 if riders == 1 else -0.2 + 0.4 * j / (riders - 1)
        parts.append(_RIDER.format(j=j, x=x))
    for i in range(units):  # every wound roll is fed by its own web
        parts.append(f'\n[[web]]\nentry_nip = "nip{i}"\ntension = 200.0\n')
    return "".join(parts)


def machine_scene(units: int, riders: int, folder: Path) -> winder.Scene:
    """The scene of :func:`machine_toml`, written into ``folder`` and loaded."""
    path = Path(folder) / f"grown_{units}u_{riders}r.toml"
    path.write_text(machine_toml(units, riders), encoding="utf-8")
    return winder.load_scene(path)


def counts(units: int, riders: int) -> tuple[int, int]:
    """(bodies, nips) of the scene."""
    return 2 * units + riders, units + riders

