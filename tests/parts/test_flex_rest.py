"""A body held by bearings starts in its static balance whether or not something rests on
it (issue 32, item 3): with ``[effects] contact = false`` (or no nip at all) the static
balance still solves the coordinates an elastic support holds (a flexible drum's bearings,
a roll's chucks), so a lone flexible drum starts in its sag instead of straight (it would
then swing through twice its sag).

Oracle: every station's sag at ``t = 0`` against the closed form of the beam on its two
bearings under its own weight, ``F · (qL/N)`` (:func:`~winder.model.beam.station_flexibility`,
the helper of the roll-on-chucks oracle in ``test_flex_roll.py``: bending, shear and the
bearings' springs); and the run stays at rest, its largest deviation tiny against the sag.
"""

from __future__ import annotations

import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

import winder
from winder.model.beam import station_flexibility
from winder.solve.system import MachineSystem

sys.path.insert(0, str(Path(__file__).resolve().parent))
import test_flex_roll as roll  # noqa: E402

# the front drum of models/two_drum_winder_flexible.toml, alone
L, MASS, EI, KGA, KB, G = 5.0, 3000.0, 2.26e9, 3.7e9, 1e9, 9.81


def lone_drum(n: int, *, effects: str = "contact = false\nslip_relaxation = false",
              drive: str = '{ kind = "speed_profile", web_acceleration = 0.7, '
                           'web_speed = 41.7 }') -> winder.Scene:
    """The front drum of the flexible two-drum winder on its bearings, no nip, no web."""
    text = f"""
[scene]
name = "lone_flexible_drum"
duration = 0.05
output_step = 0.001
gravity = {G}

[effects]
{effects}

[[drum]]
name = "front"
radius = 0.5
inertia = 600.0
mass = {MASS}
centre = [-0.525, 0.0]
drive = {drive}
length = {L}
flex = {{ segments = {n}, EI = {EI}, kGA = {KGA}, GJ = 1.7e9, bearing_stiffness = {KB}, \
bearing_damping = 1e4, damping_ratio = 0.02 }}
"""
    return winder.scene_from_dict(tomllib.loads(text), source="lone.toml")


def beam_sag(n: int) -> np.ndarray:
    """Each station's sag [m] of the beam on its bearings under its weight ``q = m g/L``,
    lumped at the stations: ``F · (qL/N)``."""
    return station_flexibility(n, L, EI, KGA, KB) @ np.full(n, MASS * G / n)


@pytest.mark.parametrize("n", [5, 8])
def test_lone_flexible_drum_starts_in_its_sag_without_contact(n: int) -> None:
    """Contact off, no nip: every station of the drum starts in the beam's sag (measured
    relative error 2.2e-15 at N = 5, 1.0e-14 at N = 8), ``x`` on the bearings' line, and the
    run of the speed profile stays there (measured largest deviation 1.9e-13 m against a
    4.1e-5 m sag at N = 8, 4.6e-9 of it: the sections' rocking, damped at its own
    frequency since #33 (4.2e-19 m when it was overdamped), answers the spin-up; before
    the fix it started straight and swung through 7.9e-5 m)."""
    sc = lone_drum(n)
    sys_ = MachineSystem(sc, backend="pinocchio")
    y = sys_.initial_state()
    want = beam_sag(n)
    sag = -np.array([y[sys_.index(f"front_s{i}.z")] for i in range(n)])
    assert np.max(np.abs(sag / want - 1)) < 1e-12, (sag, want)
    assert np.max(np.abs([y[sys_.index(f"front_s{i}.x")] + 0.525 for i in range(n)])) < 1e-15
    res = winder.simulate(sc, t_end=0.05)
    z = np.array([res[f"front_s{i}_z"] for i in range(n)])
    deviation = float(np.max(np.abs(z + want[:, None])))
    assert deviation < 5e-8 * float(np.max(want)), (deviation, float(np.max(want)))


def test_contact_on_or_off_the_same_sag() -> None:
    """Nothing rests on the drum: the balance with contact on (every free coordinate) and
    the one with contact off (those its bearings hold) are the same state."""
    from winder.solve.equilibrium import balance_unknowns

    on = MachineSystem(lone_drum(8, effects="contact = true"), backend="pinocchio")
    off = MachineSystem(lone_drum(8), backend="pinocchio")
    assert [u[:2] for u in balance_unknowns(off.machine)] == \
        [u[:2] for u in balance_unknowns(on.machine)]
    assert np.max(np.abs(on.initial_state() - off.initial_state())) < 1e-20


def test_roll_on_chucks_sags_without_contact() -> None:
    """A roll on its chucks, contact off: it starts in the sag of the beam on its chucks
    (``EI(r)``, ``q = m(r) g/L``, every station; measured 1.1e-13) and stays there (measured
    largest deviation 1.0e-9 of the sag over 0.02 s: the integrator's tolerance on a
    3 m coordinate)."""
    n, r0 = 5, 0.3
    sc = roll.chucked(n, r0, effects="imbalance = false\ncontact = false\n"
                                      "slip_relaxation = false")
    sys_ = MachineSystem(sc, backend="pinocchio")
    y = sys_.initial_state()
    z0 = 2.7 + r0
    q = roll.mass(r0) * G / roll.W
    want = station_flexibility(n, roll.W, roll.ei(r0), None, roll.KC) @ np.full(n, q * roll.W / n)
    sag = z0 - np.array([y[sys_.index(f"roll_s{i}.z")] for i in range(n)])
    assert np.max(np.abs(sag / want - 1)) < 2e-11, (sag, want)
    res = winder.simulate(sc, t_end=0.02)
    z = np.array([res[f"roll_s{i}_z"] for i in range(n)])
    deviation = float(np.max(np.abs(z0 - z - want[:, None])))
    assert deviation < 1e-8 * float(np.max(want)), (deviation, float(np.max(want)))


def test_a_free_body_without_contact_still_starts_at_its_centre() -> None:
    """machines.md §7: with contact off, a free roll on no bearings starts at its
    ``centre`` (only the coordinates an elastic support holds are balanced)."""
    from winder.solve.equilibrium import balance_unknowns

    sc = roll.scene(3, effects="imbalance = false\ncontact = false\nslip_relaxation = false")
    sys_ = MachineSystem(sc, backend="pinocchio")
    assert balance_unknowns(sys_.machine) == []
    y = sys_.initial_state()
    assert [y[sys_.index(f"roll_s{i}.z")] for i in range(3)] == [0.8] * 3
