"""Oracle tests of the force elements on a machine of parts (machines.md §§1-7): the
two-drum winder's dynamics against its equations written out by hand from the spec (no
winder code), its static balance, its initial rates, and the generated code of route "py"
against Pinocchio on numbers.

The single-drum scene cannot see what only a second dimension or a moving body ``a``
shows: the web tension, the rider load, the ``x`` components of the nip forces, the
surface velocities ``ċ · t`` of moving bodies, a drive ratio, senses of −1 on drums.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import tomli_w

import winder
from winder.solve.system import MachineSystem

MODELS = Path(__file__).resolve().parents[2] / "models"
TWO_DRUM = MODELS / "two_drum_winder.toml"
FRONT_TORQUE = 500.0  # input torque of the torque-driven front drum of variant "mixed" [N·m]


def _scene(tmp_path: Path, variant: str) -> winder.Scene:
    """The two-drum winder (``plain``), or ``mixed``: the front drum torque-driven with
    sense −1, the rear drum with sense −1 and ratio 1.02, the set started at 10 rad/s."""
    data = tomllib.loads(TWO_DRUM.read_text(encoding="utf-8"))
    if variant == "mixed":
        data["drum"][0].update(sense=-1, drive={"kind": "torque", "torque": FRONT_TORQUE,
                                                "web_speed": 3.0})
        data["drum"][1].update(sense=-1)
        data["drum"][1]["drive"]["ratio"] = 1.02
        data["roll"][0]["initial_speed"] = 10.0
    path = tmp_path / f"{variant}.toml"
    path.write_text(tomli_w.dumps(data), encoding="utf-8")
    return winder.load_scene(path)


def _line_load(r: float, points: tuple[tuple[float, float], ...]) -> float:
    """``q(r)`` [N/m]: linear between the points, constant beyond them (spec §4)."""
    rs, qs = zip(*points, strict=True)
    return float(np.interp(r, rs, qs))


class Spec:
    """machines.md §§1-7 for the two-drum winder, written out by hand from the scene."""

    def __init__(self, scene: winder.Scene) -> None:
        self.scene = scene
        self.drums = {d.name: d for d in scene.drums}
        (self.roll,) = scene.rolls
        (self.rider,) = scene.riders
        self.g = scene.scene.gravity

    # bodies: centre, velocity, θ, θ̇, radius, ṙ
    def drum(self, d: Any, t: float, y: dict[str, float]) -> tuple:
        dr = d.drive
        if dr.kind == "torque":
            th, w, alpha = y[f"{d.name}.theta"], y[f"{d.name}.theta_dot"], math.nan
        else:  # Ω = ratio · min(a t, v) / R in the sense of the drum
            k = d.sense * dr.ratio / d.radius
            t_r = dr.web_speed / dr.web_acceleration
            if t < t_r:
                th, w, alpha = k * 0.5 * dr.web_acceleration * t * t, k * dr.web_acceleration * t, \
                    k * dr.web_acceleration
            else:
                th = k * (0.5 * dr.web_acceleration * t_r * t_r + dr.web_speed * (t - t_r))
                w, alpha = k * dr.web_speed, 0.0
        return (np.array(d.centre, float), np.zeros(2), th, w, d.radius, 0.0, alpha)

    def paper(self, r: float) -> tuple[float, float, float, float]:
        ro = self.roll
        k = math.pi * ro.density * ro.width
        return (ro.core_mass + k * (r * r - ro.core_radius ** 2),
                ro.core_inertia + 0.5 * k * (r ** 4 - ro.core_radius ** 4), 2 * k * r,
                2 * k * r ** 3)

    def set_state(self, y: dict[str, float]) -> tuple:
        ro = self.roll
        r, w = y["set.radius"], y["set.theta_dot"]
        speed = ro.sense * w
        rdot = 0.0 if (r <= ro.core_radius and speed < 0) else ro.caliper * speed / (2 * math.pi)
        return (np.array([y["set.x"], y["set.z"]]), np.array([y["set.x_dot"], y["set.z_dot"]]),
                y["set.theta"], w, r, rdot, math.nan)

    def rider_state(self, y: dict[str, float]) -> tuple:
        return (np.array([self.rider.x, y["rider.z"]]), np.array([0.0, y["rider.z_dot"]]),
                y["rider.theta"], y["rider.theta_dot"], self.rider.radius, 0.0, math.nan)

    def evaluate(self, t: float, y: dict[str, float], *, static: bool = False) -> dict:
        """Forces [N], torques about +y through the centres [N·m], rates and channels."""
        bodies = {n: self.drum(d, t, y) for n, d in self.drums.items()}
        bodies["set"] = self.set_state(y)
        bodies["rider"] = self.rider_state(y)
        F = {n: np.zeros(2) for n in bodies}
        tau = dict.fromkeys(bodies, 0.0)
        out: dict[str, float] = {}
        m, J, dm, dJ = self.paper(y["set.radius"])
        mdot = dm * bodies["set"][5]

        def push(body: str, f: np.ndarray, arm: np.ndarray) -> None:
            F[body] += f
            tau[body] += arm[1] * f[0] - arm[0] * f[1]

        for nip in self.scene.nips:
            ca, va, _, wa, ra, rda, _ = bodies[nip.a]
            cb, vb, _, wb, rb, rdb, _ = bodies[nip.b]
            d = cb - ca
            dist = math.hypot(*d)
            n = d / dist
            tg = np.array([n[1], -n[0]])
            delta = ra + rb - dist
            ddot = 0.0 if static else rda + rdb - n @ (vb - va)
            ua, ub = va @ tg + wa * ra, vb @ tg - wb * rb
            c = nip.contact
            fn = max(0.0, c.stiffness * delta + c.damping * ddot) if delta > 0 else 0.0
            fr = nip.friction
            fss = fr.mu * fn * math.tanh((ua - ub) / fr.slip_velocity)
            ft = y[f"{nip.name}.friction"]
            out[f"rate:{nip.name}.friction"] = (abs(ua) + fr.min_speed) \
                / fr.relaxation_length * (fss - ft)
            f = fn * n + ft * tg
            push(nip.b, f, -rb * n)
            push(nip.a, -f, ra * n)
            if nip.name == self.scene.web.entry_nip:  # momentum and tension (spec §3)
                fw = mdot * ua
                push(nip.b, (fw - self.scene.web.tension) * tg, -rb * n)
                out["web_force"] = fw
            out.update({f"{nip.name}_normal_force": fn, f"{nip.name}_friction_force": ft,
                        f"{nip.name}_slip_velocity": ua - ub,
                        f"{nip.name}_penetration": delta})
        load = self.roll.width * _line_load(y["set.radius"], self.rider.load)
        F["rider"] += np.array([0.0, -load])
        out["rider_load"] = load
        out["static"] = {"set": F["set"] + np.array([0.0, -m * self.g]),
                         "rider": F["rider"][1] - self.rider.mass * self.g}
        # the set: M q̈ = Q − (∂M/∂r ṙ) q̇ − C − G, q = (x, z, θ), CoM at c + e (cos θ, −sin θ)
        e = self.roll.com_offset
        _, v, th, w, r, rdot, _ = bodies["set"]
        s, co = math.sin(th), math.cos(th)
        M = np.array([[m, 0, -m * e * s], [0, m, -m * e * co], [-m * e * s, -m * e * co, J]])
        md, Jd = dm * rdot, dJ * rdot
        dM = np.array([[md, 0, -md * e * s], [0, md, -md * e * co],
                       [-md * e * s, -md * e * co, Jd]])
        C = np.array([-m * e * co * w * w, m * e * s * w * w, 0.0])
        G = np.array([0.0, m * self.g, -m * self.g * e * co])
        Q = np.array([*F["set"], tau["set"]])
        acc = np.linalg.solve(M, Q - dM @ np.array([*v, w]) - C - G)
        out.update({"rate:set.x_dot": acc[0], "rate:set.z_dot": acc[1],
                    "rate:set.theta_dot": acc[2], "rate:set.radius": rdot})
        rd = self.rider
        out["rate:rider.z_dot"] = F["rider"][1] / rd.mass - self.g
        out["rate:rider.theta_dot"] = tau["rider"] / rd.inertia
        for name, dr in self.drums.items():
            sense = dr.sense
            if dr.drive.kind == "torque":  # J Ω̇ = s τ_in + nip torques; channel τ_in
                out[f"rate:{name}.theta_dot"] = (sense * FRONT_TORQUE + tau[name]) / dr.inertia
                out[f"{name}_torque"] = FRONT_TORQUE
            else:  # inverse dynamics: τ = J α − nip torques, reported as s τ
                out[f"{name}_torque"] = sense * (dr.inertia * bodies[name][6] - tau[name])
        for name, b in bodies.items():
            sense = {"set": self.roll.sense, "rider": 1}.get(name) or self.drums[name].sense
            out[f"{name}_speed"], out[f"{name}_angle"] = sense * b[3], sense * b[2]
        out["set_torque"] = self.roll.sense * tau["set"]
        out["rider_torque"] = tau["rider"]
        return out


def _states(system: MachineSystem, spec: Spec, rng: np.random.Generator, n: int):
    """``n`` random ``(t, y)``: each nip's penetration and its rate of both signs over
    decades (in contact, pulling, out), slip of both signs, any angles, radii from the
    core to 0.6 m (a few at the core turning backwards), times on the ramp and after."""
    names = system.state_names
    y0 = system.initial_state()
    front, rear = spec.drums["front"], spec.drums["rear"]
    rR = spec.rider.radius

    def signed(lo: float, hi: float) -> float:
        return float(rng.choice((-1.0, 1.0)) * 10.0 ** rng.uniform(math.log10(lo),
                                                                    math.log10(hi)))

    for i in range(n):
        y = dict(zip(names, y0, strict=True))
        t = float(rng.uniform(0.0, 100.0))
        r = spec.roll.core_radius if i % 10 == 0 else float(rng.uniform(0.05, 0.6))
        # the centre where the front and rear nips have the drawn penetrations
        d1, d2 = (front.radius + r - signed(1e-7, 2e-3), rear.radius + r - signed(1e-7, 2e-3))
        a = np.array(front.centre, float)
        b = np.array(rear.centre, float)
        L = np.linalg.norm(b - a)
        u = (d1 * d1 - d2 * d2 + L * L) / (2 * L)
        h = math.sqrt(d1 * d1 - u * u)
        c = a + u * (b - a) / L + h * np.array([0.0, 1.0])
        dx = spec.rider.x - c[0]
        dz = math.sqrt((r + rR - signed(1e-7, 2e-3)) ** 2 - dx * dx)
        v_web = 20.0 * rng.uniform(0.0, 2.0)
        speed = -rng.uniform(0.0, 5.0) if i % 10 == 0 else (v_web + signed(1e-4, 3.0)) / r
        y.update({"set.x": c[0], "set.z": c[1], "set.theta": rng.uniform(-math.pi, math.pi),
                  "set.x_dot": signed(1e-4, 0.3), "set.z_dot": signed(1e-4, 0.3),
                  "set.theta_dot": spec.roll.sense * speed, "set.radius": r,
                  "rider.z": c[1] + dz, "rider.theta": rng.uniform(-math.pi, math.pi),
                  "rider.z_dot": signed(1e-4, 0.3),
                  "rider.theta_dot": (v_web + signed(1e-4, 3.0)) / rR})
        for nip in ("front_nip", "rear_nip", "rider_nip"):
            y[f"{nip}.friction"] = rng.normal(0.0, 500.0)
        if "front.theta" in y:
            y["front.theta"] = rng.uniform(-10.0, 10.0)
            y["front.theta_dot"] = rng.uniform(-50.0, 50.0)
        yield t, np.array([y[k] for k in names])


@pytest.mark.parametrize("variant", ["plain", "mixed"])
def test_two_drum_equals_spec_equations(tmp_path, variant) -> None:
    """The two-drum winder's rates and channels on random states (numeric Pinocchio path:
    the same force code as the generated one) against machines.md §§1-6 by hand."""
    scene = _scene(tmp_path, variant)
    system = MachineSystem(scene, backend="pinocchio")
    if variant == "mixed":
        system.set_input("front.torque", FRONT_TORQUE)
    spec = Spec(scene)
    states = list(_states(system, spec, np.random.default_rng(5), 60))
    regions = {"pressing": 0, "pulling": 0, "out": 0}
    got, ref, ch_ref = [], [], []
    for t, y in states:
        named = dict(zip(system.state_names, y, strict=True))
        out = spec.evaluate(t, named)
        for nip in scene.nips:
            pen = out[f"{nip.name}_penetration"]
            regions["out" if pen <= 0 else
                    "pressing" if out[f"{nip.name}_normal_force"] > 0 else "pulling"] += 1
        dy = system.rhs(t, y)
        rates = {n: v for n, v in zip(system.state_names, dy, strict=True)
                 if f"rate:{n}" in out}
        got.append([rates[n] for n in sorted(rates)])
        ref.append([out[f"rate:{n}"] for n in sorted(rates)])
        ch_ref.append(out)
    assert min(regions.values()) >= 10, regions
    got, ref = np.array(got), np.array(ref)
    # each rate relative to its largest value: measured 2.6e-13 (plain) and 1.1e-13 (mixed),
    # the friction rates (F_ss − F_t cancels); ≤ 1e-14 elsewhere
    err = np.max(np.abs(got - ref), axis=0) / np.max(np.abs(ref), axis=0)
    assert np.all(err < 3e-12), dict(zip(sorted(rates), err, strict=True))
    # every position rate is its velocity
    for t, y in states[:5]:
        dy = system.rhs(t, y)
        for n in system.state_names:
            if n.endswith((".x", ".z", ".theta")):
                assert dy[system.index(n)] == y[system.index(n + "_dot")]
    T = np.array([s[0] for s in states])
    ch = system.channels(T, np.stack([s[1] for s in states], axis=1))
    for name in ch_ref[0]:
        if name.startswith("rate:") or name == "static":
            continue
        want = np.array([o[name] for o in ch_ref])
        # relative to the channel's largest value: measured 2.4e-13 (rear_nip_normal_force,
        # k δ + c δ̇ cancels where the nip just lets go)
        scale = max(np.max(np.abs(want)), 1e-300)
        assert np.max(np.abs(ch[name] - want)) / scale < 3e-12, name


@pytest.mark.parametrize("variant", ["plain", "mixed"])
def test_two_drum_static_balance_and_initial_rates(tmp_path, variant) -> None:
    """machines.md §7: at the initial state the forces on the set (x and z) and on the
    rider (z) balance with δ̇ = 0, F_t = 0 and the web forces; speeds from the scene."""
    scene = _scene(tmp_path, variant)
    system = MachineSystem(scene, backend="pinocchio")
    spec = Spec(scene)
    y0 = system.initial_state()
    named = dict(zip(system.state_names, y0, strict=True))
    out = spec.evaluate(0.0, named, static=True)
    m = spec.paper(named["set.radius"])[0]
    weight = (m + spec.rider.mass) * spec.g
    # measured 6.7e-14 (set) and 2.8e-14 (rider) of the weight of set and rider
    assert np.max(np.abs(out["static"]["set"])) < 1e-12 * weight, out["static"]
    assert abs(out["static"]["rider"]) < 1e-12 * weight, out["static"]
    assert out["front_nip_normal_force"] > 0 and out["rider_nip_normal_force"] > 0
    assert named["set.theta_dot"] == scene.rolls[0].sense * scene.rolls[0].initial_speed
    assert named["rider.theta_dot"] == 0.0
    for d in scene.drums:
        if d.drive.kind == "torque":
            assert named[f"{d.name}.theta_dot"] == d.sense * d.drive.web_speed / d.radius


def test_route_py_equals_pinocchio(tmp_path) -> None:
    """The generated code of route "py" (Pinocchio's ABA and RNEA written over the model,
    winder.model.spatial) against ``pin.aba``/``pin.rnea`` on numbers: rates and channels
    of the two-drum winder on random states."""
    from winder.model.codegen import generate

    scene = _scene(tmp_path, "plain")
    system = MachineSystem(scene, backend="pinocchio")
    gen = generate(system.machine, directory=tmp_path / "gen", route="py")
    spec = Spec(scene)
    names = system.machine.channel_names
    for t, y in _states(system, spec, np.random.default_rng(6), 20):
        dy = system.rhs(t, y)
        # measured 5.8e-21 of the largest rate, 1.4e-18 of the largest channel (the same
        # operations up to their order: 1e-16, a few ulp, covers other compilers)
        np.testing.assert_allclose(gen.call("rhs", t, y, system.params, system.modes), dy,
                                   rtol=0, atol=1e-16 * np.max(np.abs(dy)))
        ev = system.evaluate_numeric(t, y)
        want = np.array([float(ev.channels.get(n, 0.0)) for n in names])
        np.testing.assert_allclose(gen.call("out", t, y, system.params, system.modes), want,
                                   rtol=0, atol=1e-16 * np.max(np.abs(want)))
