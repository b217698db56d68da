"""The elastic and damping forces of flexible bodies (issue #25): bending between the
segments of each flexible body through the condensed beam, its bearings and its Rayleigh
damping (:mod:`winder.model.beam`), and torsion between neighbouring segments.

Called for by every segment of a flexible body (its ``drives``: ``("flex_beam",)``), so a
machine without flexible bodies never builds it. Per flexible body ``NAME`` with segments
``NAME_s0 … NAME_s{N−1}`` (deflections ``u_i = c_i − c`` from its ``centre`` [m], rates
``u̇_i`` [m/s]; angles ``θ_i`` [rad] and rates ``θ̇_i`` [rad/s] about ``+y``):

    f_x,i = −Σ_j Kx_ij u_x,j − Σ_j Cx_ij u̇_x,j     (and in z with Kz, Cz)     [N]
    τ_i   = k_t (θ_{i+1} − θ_i) + c_t (θ̇_{i+1} − θ̇_i)  on i, its reaction on i + 1  [N·m]

with the run-time parameters ``NAME.flex.Kx_i_j`` [N/m], ``NAME.flex.Cx_i_j`` [N·s/m]
(``i ≤ j``, symmetric; ``Kz``, ``Cz`` likewise), ``NAME.flex.k_t`` [N·m/rad] and
``NAME.flex.c_t = β_t k_t`` [N·m·s/rad] (the chain's own Rayleigh ``β_t = 2ζ/ω_t1``,
:func:`~winder.model.beam.torsion_damping`; a paper roll's ``β_t(r)`` from its ``J(r)`` at
run time). With the sections' rotary inertia (``flex.rotary_inertia``,
the default; issue #32) each segment has the states ``NAME_s{i}.tilt_x``, ``.tilt_z``
[rad] and ``.tilt_rate_x``, ``.tilt_rate_z`` [rad/s] and the bending is that of
:func:`~winder.model.beam.rotary_beam_matrices` (parameters ``Kx`` as above, ``Tx``,
``Kwpx``, ``Kppx``, ``Cwwx``, ``Cwpx``, ``Cppx``, ``beta_bendx`` and their ``z``:
:meth:`_rotary_bending`). The bearings hold the axes a segment lists in
``bearing_axes`` (a drum: ``x`` and ``z``; a rider: ``x``; a roll on chucks: its free
axes); along the others the beam is free–free (it rests on its nip). A paper roll's
``EI(r)`` changes at run time: its stiffness is ``EI(r)`` times the unit beam's, on chucks
the Woodbury form of :func:`_chuck_tables`. The
torsion torques go in as spatial forces (they are not part of a segment's ``NAME_s{i}_torque``
channel, which keeps machines.md §9's meaning). Channel ``NAME_twist`` [rad]: the drive
end's angle minus the far end's, operation sense.

A scene nip ``NIP`` against a flexible body is sliced (:mod:`winder.model.slices`): its
slices ``NIP_s{i}`` have the generic nip channels; this element writes the scene nip's own:
``NIP_normal_force`` and ``NIP_friction_force`` the sums over its slices,
``NIP_slip_velocity`` their mean, ``NIP_penetration`` their largest, and the line load
``F_i / (L/N)`` [N/m] of its slices, ``NIP_line_load_min``, ``_max`` and ``_mean``. It runs
after the contact and the slip relaxation (``uses`` their ``steady_friction``). The
whole body's channels of its rigid self (``NAME_speed``, ``NAME_torque``, ...):
:mod:`winder.model.whole_body`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from winder._schema import Channel
from winder.forces._base import ForceElement
from winder.model.channels import NIP_CHANNELS

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine

__all__ = ["FlexBeam", "TWIST", "LINE_LOAD"]

#: A flexible body's twist.
TWIST = Channel(name="BODY_twist", unit="rad",
                doc="flexible drum or rider: twist, angle of segment 0 (drive end) minus that "
                    "of the last segment, operation sense")

#: A sliced nip's line load along its width: least, largest and mean over its slices.
LINE_LOAD = (
    Channel(name="NIP_line_load_min", unit="N/m",
            doc="nip against a flexible body: least line load of its slices, F_i/(L/N)"),
    Channel(name="NIP_line_load_max", unit="N/m",
            doc="nip against a flexible body: largest line load of its slices"),
    Channel(name="NIP_line_load_mean", unit="N/m",
            doc="nip against a flexible body: mean line load of its slices"),
)


def _chuck_tables(n: int, length: float) -> tuple[Any, Any, Any, float]:
    """A roll on chucks (``k_b`` per end): the stations' flexibility is ``A/EI + U Uᵀ/k_b``
    (``A`` the beam's on rigid supports at unit ``EI``, ``U = [1 − y/L, y/L]`` the chucks'
    rigid-body shapes, :func:`~winder.model.beam.station_flexibility`), so by Woodbury
    ``K(EI) = EI K_s − EI² W (k_b I + EI G)⁻¹ Wᵀ`` with ``K_s = A⁻¹`` [N/m per N·m²],
    ``W = K_s U`` and ``G = Uᵀ K_s U``: exact for the ``EI(r)`` of a growing roll at run
    time with a 2 × 2 inverse. Returns ``(K_s, W, G, μ₁)``, ``μ₁`` the least eigenvalue
    of ``K_s`` (the first mode on rigid chucks at unit ``EI`` and segment mass: the
    Rayleigh damping's ``ω₁² = EI μ₁/(m/N)``)."""
    import numpy as np  # not for checking a scene

    from winder.model.beam import station_flexibility

    y = (np.arange(n) + 0.5) * length / n
    Ks = np.linalg.inv(station_flexibility(n, length, 1.0, None, math.inf))
    Ks = 0.5 * (Ks + Ks.T)
    U = np.column_stack([1.0 - y / length, y / length])
    W = Ks @ U
    return Ks, W, U.T @ W, float(np.linalg.eigvalsh(Ks)[0])


def _deviation(values: list[Any]) -> list[Any]:
    """Each value minus their mean."""
    mean = sum(values) / len(values)
    return [v - mean for v in values]


class FlexBeam(ForceElement):
    """Bending (condensed beam, bearings, Rayleigh damping) and torsion of flexible
    bodies."""

    name = "flex_beam"
    doc = "bending and torsion between the segments of a flexible body"
    provides = frozenset({"spatial_force"})
    uses = frozenset({"steady_friction"})
    CHANNELS = (TWIST, *LINE_LOAD)

    def __init__(self) -> None:
        #: the segment bodies of each flexible body, by its name, drive end first
        self.groups: dict[str, list[Any]] = {}
        #: the slices of each sliced scene nip, by its name
        self.sliced: dict[str, list[Any]] = {}
        #: whether each flexible drum or rider has its sections' rotary inertia
        self.rotary: dict[str, bool] = {}

    @staticmethod
    def _declare_rotary(machine: Machine, body: str, segs: list[Any], axis: str,
                        bm: Any) -> None:
        """The parameters of a beam with its sections' rotary inertia along ``axis``
        (:class:`~winder.model.beam.RotaryBeamMatrices`): the band ``|i − j| ≤ 1`` of
        ``K̂`` (``Kww``, ``Kwp``, ``Kpp``) and ``C`` (``Cww``, ``Cwp``, ``Cpp``), and the
        factors of ``K_ψψ = L D Lᵀ`` (``L`` unit lower bidiagonal: ``Pl_i = L[i, i−1]``,
        ``Pd_i = 1/D[i]``), so that the condensed stiffness ``K = K_ww + K_wψ T`` and the
        static rotations ``T w = −K_ψψ⁻¹ K_ψw w`` are applied in O(N) (never formed: they
        are dense); and each segment's states ``tilt_{axis}`` (``φ``) and
        ``tilt_rate_{axis}`` (``s = ψ̇``), 0 at the start."""
        n = len(segs)
        bend = bm.beta - bm.beta_rock  # on K w: C_ww = bend K + its band (module text)
        machine.parameter(f"{body}.flex.beta_bend{axis}", bend)
        for kind, matrix, sym in (("Kww", bm.K_ww, True), ("Kwp", bm.K_wp, False),
                                  ("Kpp", bm.K_pp, True), ("Cww", bm.C_ww - bend * bm.K, True),
                                  ("Cwp", bm.C_wp, False), ("Cpp", bm.C_pp, True)):
            for i in range(n):
                for j in range(i if sym else max(i - 1, 0), min(i + 2, n)):
                    machine.parameter(f"{body}.flex.{kind}{axis}_{i}_{j}", matrix[i, j])
        d = float(bm.K_pp[0, 0])
        machine.parameter(f"{body}.flex.Pd{axis}_0", 1.0 / d)
        for i in range(1, n):  # LDLᵀ of the symmetric tridiagonal K_ψψ
            low = float(bm.K_pp[i, i - 1]) / d
            d = float(bm.K_pp[i, i]) - low * float(bm.K_pp[i - 1, i])
            machine.parameter(f"{body}.flex.Pl{axis}_{i}", low)
            machine.parameter(f"{body}.flex.Pd{axis}_{i}", 1.0 / d)
        for seg in segs:
            machine.state(f"{seg.name}.tilt_{axis}", 0.0)
            machine.state(f"{seg.name}.tilt_rate_{axis}", 0.0)

    def declare(self, machine: Machine) -> None:
        # NumPy: not for checking a scene
        from winder.model.beam import (
            beam_matrices,
            rotary_beam_matrices,
            torsion_damping,
            torsion_eigenvalue,
        )

        self.groups = {}
        self.rotary = {}
        for b in machine.bodies:
            seg = b.segment
            if self.name in b.drives and seg is not None:
                self.groups.setdefault(seg.segment_of, []).append(seg)
        for body, segs in self.groups.items():
            segs.sort(key=lambda s: s.index)
            first = segs[0]
            flex, part, n = first.flex, first.part, len(segs)
            if first.roles.paper:  # a paper roll: EI(r), no bearings or chucks
                unit = beam_matrices(n, first.length, float(n), 1.0, None, 0.0, 0.0, 0.0,
                                     flex.GJ)
                K1, mu1 = unit.K, unit.omega1 ** 2
                if first.bearing_axes:  # on chucks: K(EI) by Woodbury, module text
                    K1, W, G, mu1 = _chuck_tables(n, first.length)
                    for i in range(n):
                        for e in range(2):
                            machine.parameter(f"{body}.flex.W{e}_{i}", W[i, e])
                    for a, b in ((0, 0), (0, 1), (1, 1)):
                        machine.parameter(f"{body}.flex.G_{a}_{b}", G[a, b])
                    machine.parameter(f"{body}.flex.chuck_stiffness", flex.chuck_stiffness)
                for i in range(n):
                    for j in range(i, n):
                        machine.parameter(f"{body}.flex.K1_{i}_{j}", K1[i, j])
                machine.parameter(f"{body}.flex.mu1", mu1)
                machine.parameter(f"{body}.flex.damping_ratio", flex.damping_ratio)
                machine.parameter(f"{body}.flex.core_EI", flex.core_EI)
                machine.parameter(f"{body}.flex.paper_E", flex.paper_E)
                machine.parameter(f"{body}.flex.k_t", unit.k_t)
                machine.parameter(f"{body}.flex.nu_t1",
                                  torsion_eigenvalue(n, held=first.prescribed))
                machine.channel(TWIST, body)
                continue
            self.rotary[body] = flex.rotary_inertia
            for axis in ("x", "z"):
                held = axis in first.bearing_axes
                args = (flex.EI, flex.kGA if flex.shear else None,
                        flex.bearing_stiffness if held else 0.0,
                        flex.bearing_damping if held else 0.0, flex.damping_ratio, flex.GJ)
                if flex.rotary_inertia:
                    bm = rotary_beam_matrices(n, first.length, part.mass, part.inertia,
                                              *args)
                    self._declare_rotary(machine, body, segs, axis, bm)
                    continue
                bm = beam_matrices(n, first.length, part.mass, *args)
                for kind, matrix in (("K", bm.K), ("C", bm.C)):
                    for i in range(n):
                        for j in range(i, n):
                            machine.parameter(f"{body}.flex.{kind}{axis}_{i}_{j}",
                                              matrix[i, j])
            machine.parameter(f"{body}.flex.k_t", bm.k_t)  # the same for x and z
            _, c_t = torsion_damping(n, bm.k_t, part.inertia / n, flex.damping_ratio,
                                     held=first.prescribed)
            machine.parameter(f"{body}.flex.c_t", c_t)
            machine.channel(TWIST, body)
        self.sliced = {}
        for nip in machine.nips:
            if nip.whole is not None:
                self.sliced.setdefault(nip.whole, []).append(nip)
        for whole in self.sliced:
            for ch in (*NIP_CHANNELS, *LINE_LOAD):
                machine.channel(ch, whole)

    def structure_tag(self, machine: Machine) -> str:
        return ",".join(f"{body}:{len(segs)}" for body, segs in self.groups.items())

    @staticmethod
    def _roll_bending(ev: Evaluation, body: str, segs: list[Any], states: list[Any],
                      ux: list[Any], uz: list[Any]) -> tuple[Any, Any]:
        """A paper roll's bending, ``EI(r) K₁ (u + β u̇)`` with ``EI(r) = core_EI +
        paper_E·π (r⁴ − r_c⁴)/4`` [N·m²] and ``β = 2ζ/ω₁(r)``, ``ω₁² = EI μ₁ / (m/N)``
        (``K₁``, ``μ₁``: the free–free chain of unit ``EI`` and unit segment mass); its
        torsion spring and damper ``(k_t, β_t k_t)``, ``β_t = 2ζ/ω_t1(r)``, ``ω_t1² = ν₁
        k_t/I_d(r)`` (``I_d`` a segment's share of ``J(r)``, ``ν₁`` parameter ``nu_t1``:
        :func:`~winder.model.beam.torsion_damping`)."""
        p = ev.p
        r, rc = states[0].r, p(f"{body}.core_radius")
        r2, rc2 = r * r, rc * rc
        ei = p(f"{body}.flex.core_EI") + p(f"{body}.flex.paper_E") * math.pi \
            * (r2 * r2 - rc2 * rc2) / 4.0
        beta = 2.0 * p(f"{body}.flex.damping_ratio") \
            / ev.mathns.sqrt(ei * p(f"{body}.flex.mu1") / states[0].mass)
        free = segs[0].free
        chucks = bool(segs[0].bearing_axes)
        vx, vz = [bs.vx for bs in states], [bs.vz for bs in states]
        if not chucks:  # free–free: K₁ holds a common motion of the stations at zero
            # force, but its row sums carry round-off; taken out here, that round-off
            # (× EI) does not act on the roll's height or speed
            ux, uz, vx, vz = (_deviation(u) for u in (ux, uz, vx, vz))
        if chucks:  # (k_b I + EI G)⁻¹, 2 × 2
            kb = p(f"{body}.flex.chuck_stiffness")
            m00 = kb + ei * p(f"{body}.flex.G_0_0")
            m11 = kb + ei * p(f"{body}.flex.G_1_1")
            m01 = ei * p(f"{body}.flex.G_0_1")
            det = m00 * m11 - m01 * m01
            inv = ((m11 / det, -m01 / det), (-m01 / det, m00 / det))
            w = [[p(f"{body}.flex.W{e}_{i}") for e in range(2)] for i in range(len(segs))]
        for i, seg in enumerate(segs):
            fx: Any = 0.0
            fz: Any = 0.0
            for j in range(len(states)):
                k = ei * p(f"{body}.flex.K1_{min(i, j)}_{max(i, j)}")
                if chucks:
                    k = k - ei * ei * sum(w[i][a] * inv[a][b] * w[j][b]
                                          for a in range(2) for b in range(2))
                fx = fx - k * (ux[j] + beta * vx[j])
                fz = fz - k * (uz[j] + beta * vz[j])
            ev.add_force(seg.name, fx if "x" in free else 0.0, fz if "z" in free else 0.0)
        kt = p(f"{body}.flex.k_t")
        beta_t = 2.0 * p(f"{body}.flex.damping_ratio") \
            / ev.mathns.sqrt(p(f"{body}.flex.nu_t1") * kt / states[0].inertia)
        return kt, beta_t * kt

    @staticmethod
    def _rotary_bending(ev: Evaluation, body: str, segs: list[Any], axis: str,
                        u: list[Any], v: list[Any]) -> list[Any]:
        """Bending along ``axis`` with the sections' rotary inertia
        (:func:`~winder.model.beam.rotary_beam_matrices`): the rates of the segments'
        ``tilt_{axis}`` (``φ̇ = s − T ẇ``) and ``tilt_rate_{axis}`` (``ṡ = (−K_ψψ φ −
        C_ψw ẇ − C_ψψ s)/j_r``, ``j_r`` half the segment's polar inertia); returns the
        forces on the segments ``−K (w + b ẇ) − K_wψ φ − C'_ww ẇ − C_wψ s`` [N]: the
        damping ``C_ww = b K + C'_ww`` split into the dense ``b K`` (``b = β − β_φ``,
        parameter ``beta_bend{axis}``) and the band ``C'_ww = β_φ K_ww + C_b``. ``K`` and
        ``T`` are dense: applied as ``K w = K_ww w + K_wψ T w`` and ``T w = −K_ψψ⁻¹ K_ψw w``
        (banded products and the tridiagonal ``L D Lᵀ`` of ``K_ψψ``), so the cost grows
        with N, not N² (issue #33)."""
        p, n = ev.p, len(segs)

        def par(kind: str, i: int, j: int, sym: bool = False) -> Any:
            if j < 0:  # a vector: Pl_i, Pd_i
                return p(f"{body}.flex.{kind}{axis}_{i}")
            a, b = (min(i, j), max(i, j)) if sym else (i, j)
            return p(f"{body}.flex.{kind}{axis}_{a}_{b}")

        phi = [ev.x(f"{s.name}.tilt_{axis}") for s in segs]
        rate = [ev.x(f"{s.name}.tilt_rate_{axis}") for s in segs]
        bend = p(f"{body}.flex.beta_bend{axis}")
        lead = [uj + bend * vj for uj, vj in zip(u, v, strict=True)]

        def static_rotation(values: list[Any]) -> list[Any]:
            """``−T values = K_ψψ⁻¹ K_ψw values`` (banded product, then ``L D Lᵀ``)."""
            z = []
            for i in range(n):
                acc: Any = 0.0
                for j in range(max(i - 1, 0), min(i + 2, n)):
                    acc = acc + par("Kwp", j, i) * values[j]
                z.append(acc)
            for i in range(1, n):
                z[i] = z[i] - par("Pl", i, -1) * z[i - 1]
            z = [zi * par("Pd", i, -1) for i, zi in enumerate(z)]
            for i in range(n - 2, -1, -1):
                z[i] = z[i] - par("Pl", i + 1, -1) * z[i + 1]
            return z

        y = static_rotation(lead)  # −T (w + b ẇ): b K rides on K's product
        lag = static_rotation(v)  # −T ẇ
        forces = []
        for i, seg in enumerate(segs):
            f: Any = 0.0
            g: Any = 0.0
            for j in range(max(i - 1, 0), min(i + 2, n)):
                f = f - par("Kww", i, j, True) * lead[j] - par("Kwp", i, j) * (phi[j] - y[j]) \
                    - par("Cww", i, j, True) * v[j] - par("Cwp", i, j) * rate[j]
                g = g - par("Kpp", i, j, True) * phi[j] - par("Cwp", j, i) * v[j] \
                    - par("Cpp", i, j, True) * rate[j]
            forces.append(f)
            ev.set_rate(f"{seg.name}.tilt_{axis}", rate[i] + lag[i])
            ev.set_rate(f"{seg.name}.tilt_rate_{axis}", 2.0 * g / p(f"{seg.name}.inertia"))
        return forces

    def _nip_channels(self, ev: Evaluation) -> None:
        """The sliced scene nips' own channels (see the module text)."""
        mathns = ev.mathns
        normal, friction, slip, penetration = NIP_CHANNELS
        for whole, slices in self.sliced.items():
            states = [ev.nips[s.name] for s in slices]
            n, h = len(states), slices[0].slice_length
            fn = [ns.normal_force for ns in states]
            total, least, most, deepest = fn[0], fn[0], fn[0], states[0].delta
            ft, vs = states[0].friction_force, states[0].v_s
            for ns, f in zip(states[1:], fn[1:], strict=True):
                total, ft, vs = total + f, ft + ns.friction_force, vs + ns.v_s
                least, most = mathns.fmin(least, f), mathns.fmax(most, f)
                deepest = mathns.fmax(deepest, ns.delta)
            ev.output(normal, whole, total)
            ev.output(friction, whole, ft)
            ev.output(slip, whole, vs / n)
            ev.output(penetration, whole, deepest)
            lo, hi, mean = LINE_LOAD
            ev.output(lo, whole, least / h)
            ev.output(hi, whole, most / h)
            ev.output(mean, whole, total / (n * h))

    def apply(self, ev: Evaluation) -> None:
        for body, segs in self.groups.items():
            n = len(segs)
            states = [ev.bodies[s.name] for s in segs]
            cx, cz = segs[0].centre
            ux = [bs.cx - cx for bs in states]
            uz = [bs.cz - cz for bs in states]

            def entry(kind: str, i: int, j: int, body: str = body) -> Any:
                return ev.p(f"{body}.flex.{kind}_{min(i, j)}_{max(i, j)}")

            if segs[0].roles.paper:
                kt, ct = self._roll_bending(ev, body, segs, states, ux, uz)
            elif self.rotary[body]:
                fx = self._rotary_bending(ev, body, segs, "x", ux, [bs.vx for bs in states])
                fz = self._rotary_bending(ev, body, segs, "z", uz, [bs.vz for bs in states])
                for seg, f, g in zip(segs, fx, fz, strict=True):
                    ev.add_force(seg.name, f, g)
                kt, ct = ev.p(f"{body}.flex.k_t"), ev.p(f"{body}.flex.c_t")
            else:
                for i, seg in enumerate(segs):
                    fx: Any = 0.0
                    fz: Any = 0.0
                    for j, bs in enumerate(states):
                        fx = fx - entry("Kx", i, j) * ux[j] - entry("Cx", i, j) * bs.vx
                        fz = fz - entry("Kz", i, j) * uz[j] - entry("Cz", i, j) * bs.vz
                    ev.add_force(seg.name, fx, fz)
                kt, ct = ev.p(f"{body}.flex.k_t"), ev.p(f"{body}.flex.c_t")
            for i in range(n - 1):
                a, b = states[i], states[i + 1]
                tq = kt * (b.theta - a.theta) + ct * (b.omega - a.omega)
                ev.add_spatial_force(segs[i].name, [0.0, 0.0, 0.0, 0.0, tq, 0.0])
                ev.add_spatial_force(segs[i + 1].name, [0.0, 0.0, 0.0, 0.0, -tq, 0.0])
            ev.output(TWIST, body, segs[0].sense * (states[0].theta - states[-1].theta))
        self._nip_channels(ev)
