"""What a result says about where every body of a machine is: centres, angles, radii,
speeds and nip forces at chosen times, read from the result's channels, and the path of
the web into its entry nip: from off-screen, or, on a winder line (a ``[web.span]``), from
the unwinding roll's exit point ``p_u`` along the span (machines spec §5), or, on a web
line (``[[web.span]]`` over rollers, spec §11), over each roller (:mod:`._line`), a
dancer's roller drawn where its ``NAME_position`` channel puts its carriage.

A scene of parts (machines spec §9) names its channels per body (``NAME_angle``,
``NAME_speed``, ``NAME_x``/``NAME_z`` where free, ``NAME_radius`` for a paper roll) and
per nip (``NIP_normal_force``); the viewer asks the scene's naming for them
(:attr:`winder.scene.Scene.naming`), and for a result without its scene the naming that
reads one (:func:`winder.scene.naming_of` ``(None)``, with the bodies it draws). The
model's rotation about ``+y`` of a body is ``θ = sense · angle`` (spec §1).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np
from winder.viewer._line import ROLLER_ARC_POINTS, Circle, dancer_axis, line_path

from winder._errors import WinderError
from winder.forces.web_tension import exit_point
from winder.io.result import Result
from winder.model.machine import Machine, Web
from winder.parts import BodyElement as Body
from winder.scene import Naming, naming_of
from winder.scene.load import Scene

__all__ = ["BodyMotion", "Motion", "body_channels", "nip_channels", "drawn_channels",
           "speed_channels",
           "check_drawable", "scene_of", "motion", "WebMotion", "web_path", "span_web_path",
           "exit_points", "web_points", "dancer_axes",
           "WEB_LEAD", "WEB_ARC_POINTS"]

#: Length of the web's straight run drawn before it meets the entry drum [m] (off-screen).
WEB_LEAD = 20.0
#: Points on the web's arc around the entry drum (the last one is replaced by ``p_b``).
WEB_ARC_POINTS = 25
#: Where the web meets the entry drum: this far past the drum's lowest point, against the
#: drum's motion [rad] (for sense +1 at the lower rear: the web comes from below, behind).
WEB_MEET = math.radians(15.0)

def scene_of(result: Result, scene: Scene | None = None) -> Scene | None:
    """``scene``, else the scene stored in ``result.meta["scene_dict"]``, else ``None``
    (the result is then read with :func:`~winder.scene.naming_of` ``(None)``'s names)."""
    if scene is not None:
        return scene
    stored = result.meta.get("scene_dict")
    if isinstance(stored, dict):
        from winder.scene.load import scene_from_dict

        return scene_from_dict(stored)
    return None


def _naming(scene: Scene | None) -> Naming:
    # a result without its scene is read with the names of the naming that reads one
    return naming_of(scene)


def _without_scene() -> dict[str, dict[str, str]]:
    """The channels of a result without its scene: body → role → channel
    (:attr:`Naming.bodies_without_scene <winder.scene.Naming.bodies_without_scene>`)."""
    naming = naming_of(None)
    return {body: {role: naming.output_name(f"{body}_{role}") for role in roles}
            for body, roles in naming.bodies_without_scene.items()}


def body_channels(scene: Scene | None, body: Body) -> dict[str, str]:
    """Channel of each role (``x``, ``z``, ``angle``, ``speed``, ``radius``) of ``body``
    that the result carries, as the scene names it; a role without a channel is constant
    (fixed coordinate, constant radius)."""
    roles = [*body.free, "angle", "speed", *(("radius",) if body.radius_state else ()),
             *(("position",) if body.roles.dancer is not None else ())]
    return {role: _naming(scene).output_name(f"{body.name}_{role}") for role in roles}


def nip_channels(scene: Scene | None, machine: Machine) -> dict[str, str]:
    """Normal-force channel of every nip [N]."""
    return {n.name: _naming(scene).output_name(f"{n.name}_normal_force")
            for n in machine.nips}


def _optional(scene: Scene | None, role: str, body: Body) -> bool:
    # a channel an older result may lack (the old format's drum angle: drawn still)
    return body_channels(scene, body)[role] in _naming(scene).optional


def speed_channels(scene: Scene | None) -> list[str]:
    """The speed channel of every body [rad/s], as the scene names it; for a result
    without its scene (``None``) those of :func:`~winder.scene.naming_of` ``(None)``'s
    bodies."""
    if scene is None:
        return [roles["speed"] for roles in _without_scene().values() if "speed" in roles]
    return [body_channels(scene, b)["speed"] for b in Machine(scene).bodies]


def drawn_channels(scene: Scene | None, machine: Machine) -> list[str]:
    """Channels the viewer needs (optional ones and nip forces excluded)."""
    return [ch for b in machine.bodies for role, ch in body_channels(scene, b).items()
            if not _optional(scene, role, b)]


def check_drawable(result: Result, where: str = "result", scene: Scene | None = None
                   ) -> None:
    """Raise :class:`~winder.WinderError` (prefixed by ``where``, e.g. the file) unless
    ``result`` can be drawn: at least two samples on an increasing, finite time axis, the
    channels of :func:`drawn_channels` present and finite, and every roll radius > 0.
    ``scene`` defaults to the one stored in the result; without one the channels of
    :func:`~winder.scene.naming_of` ``(None)``'s bodies are checked."""
    t = np.asarray(result.t, dtype=float)
    if len(t) < 2:
        raise WinderError(f"{where}: {len(t)} sample(s); the viewer needs at least 2")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise WinderError(f"{where}: the time axis is not finite and increasing")
    scene = scene_of(result, scene)
    if scene is None:  # the bodies of the naming that reads a result without its scene
        bodies = _without_scene()
        required = [c for roles in bodies.values() for c in roles.values()
                    if c not in _naming(None).optional]
        radii = [roles["radius"] for roles in bodies.values() if "radius" in roles]
    else:
        m = Machine(scene)
        required = drawn_channels(scene, m)
        radii = [body_channels(scene, b)["radius"] for b in m.bodies if b.radius_state]
    missing = [c for c in required if c not in result]
    if missing:
        raise WinderError(f"{where}: no channel {', '.join(missing)} (the viewer draws "
                          f"{', '.join(required)})")
    optional = [c for c in sorted(_naming(scene).optional) if c in result]
    for c in (*required, *optional):
        bad = np.flatnonzero(~np.isfinite(result[c]))
        if len(bad):
            raise WinderError(f"{where}: channel {c!r} is not finite at t = {t[bad[0]]:g} s "
                              f"(sample {bad[0]}: {float(result[c][bad[0]])!r})")
    for c in radii:
        small = np.flatnonzero(result[c] <= 0)
        if len(small):
            raise WinderError(f"{where}: {c} {float(result[c][small[0]])!r} m at t = "
                              f"{t[small[0]]:g} s; a roll radius is > 0")


@dataclass(frozen=True)
class BodyMotion:
    """One body at the sample times: centre ``x``, ``z`` [m], model angle ``theta`` about
    ``+y`` [rad] (``sense · angle``), ``radius`` [m], ``speed`` [rad/s] (operation
    sense); ``role`` how it is drawn (:attr:`winder.parts.BodyElement.role`),
    ``radius_state`` whether its radius changes (a channel of its own)."""

    name: str
    role: str
    sense: int
    x: np.ndarray
    z: np.ndarray
    theta: np.ndarray
    radius: np.ndarray
    speed: np.ndarray
    radius_state: bool = False
    #: a segment of a flexible body: that body's name (the readout aggregates them)
    segment_of: str | None = None
    #: a flexible drum's segment: the centre of its bearings' line ``(x, z)`` [m], which
    #: its deflection is taken from (None: from its segments' mean)
    support: tuple[float, float] | None = None
    #: a dancer's roller: its carriage position ``d`` [m] (its ``NAME_position``; the
    #: centre is ``home + d · axis``), the unit ``axis`` of its travel, its ``home`` (the
    #: scene's centre, ``d = 0``) and the ``travel`` ends ``(lo, hi)`` [m]; else None
    position: np.ndarray | None = None
    axis: tuple[float, float] | None = None
    home: tuple[float, float] | None = None
    travel: tuple[float, float] | None = None


@dataclass(frozen=True)
class WebMotion:
    """One web of a machine at the samples: its ``name``, its entry nip's ``(a, b)`` body
    names; on a winder line its unwinding roll ``unwind``, exit points ``exit`` [m]
    (``(len(times), 2)``) and span tension ``span_tension`` [N] (``None`` without the
    channel); all three ``None`` without a span."""

    name: str
    entry: tuple[str, str]
    unwind: str | None = None
    exit: np.ndarray | None = None
    span_tension: np.ndarray | None = None
    #: a web line's rollers in order from the unwinding roll (machines spec §11)
    rollers: tuple[str, ...] = ()
    #: every span's tension [N] in order (``None`` where the result lacks its channel)
    span_tensions: tuple[np.ndarray | None, ...] = ()


@dataclass(frozen=True)
class Motion:
    """Every body and nip of a machine at ``times`` [s]: ``bodies`` by name, nip normal
    forces [N] by nip name (``None`` when the result has no such channel) and the entry
    nip's ``(a, b)`` body names (``None`` without a web). On a winder line, ``unwind`` is
    the unwinding roll's name, ``exit`` its exit points ``p_u`` [m] (``(len(times), 2)``,
    :func:`exit_points`) and ``span_tension`` the span's tension [N] (``None`` when the
    result has no ``span_tension`` channel); all three are ``None`` without a span. These
    are the first web's; ``webs`` has every web (one per wound roll). ``units``: the
    result's channel units (:attr:`winder.Result.units`; empty for a result without)."""

    times: np.ndarray
    bodies: dict[str, BodyMotion]
    normal_forces: dict[str, np.ndarray | None]
    entry: tuple[str, str] | None
    unwind: str | None = None
    exit: np.ndarray | None = None
    span_tension: np.ndarray | None = None
    webs: tuple[WebMotion, ...] = ()
    units: Mapping[str, str] = field(default_factory=dict)
    #: the slices of a sliced nip (against a flexible body): slice name → the scene's nip
    slices: Mapping[str, str] = field(default_factory=dict)

    def web(self, k: int) -> np.ndarray | None:
        """The first web's path at sample ``k`` (:meth:`web_paths`), or ``None``."""
        if self.entry is None:
            return None
        return self._path(WebMotion("", self.entry, self.unwind, self.exit), k)

    def web_paths(self, k: int) -> list[np.ndarray]:
        """Every web's path at sample ``k``: :func:`span_web_path` from the exit point on
        a line, else :func:`web_path` from off-screen."""
        if not self.webs:  # a Motion built with the first web's fields only
            return [] if self.entry is None else [self.web(k)]
        return [self._path(w, k) for w in self.webs]

    def _path(self, w: WebMotion, k: int) -> np.ndarray:
        a, b = (self.bodies[n] for n in w.entry)
        if w.rollers:
            return self._line(w, a, b, k)
        if w.exit is not None:
            return span_web_path(w.exit[k], (a.x[k], a.z[k]), a.radius[k], a.sense,
                                 (b.x[k], b.z[k]), b.radius[k])
        return web_path((a.x[k], a.z[k]), a.radius[k], a.sense, (b.x[k], b.z[k]),
                        b.radius[k])

    def _line(self, w: WebMotion, a: BodyMotion, b: BodyMotion, k: int) -> np.ndarray:
        """A web line's path at sample ``k``: :func:`._line.line_path` from the unwinding
        roll over the rollers, then around the entry drum ``a`` into the nip with roll
        ``b`` (:func:`_wrap`)."""
        def circle(body: BodyMotion) -> Circle:
            return Circle(float(body.x[k]), float(body.z[k]), float(body.radius[k]),
                          1 if body.sense >= 0 else -1)
        drum = circle(a)
        points, meet = line_path(circle(self.bodies[w.unwind]),
                                 [circle(self.bodies[n]) for n in w.rollers], drum)
        alpha = math.atan2(meet[1] - drum.z, meet[0] - drum.x)
        return np.vstack([points, _wrap(drum.c, drum.r, float(drum.s), alpha,
                                        (b.x[k], b.z[k]), b.radius[k])])

    def extent(self) -> tuple[float, float, float, float]:
        """``(x_min, x_max, z_min, z_max)`` [m] of every body over all samples."""
        xs = [v for b in self.bodies.values() for v in (np.min(b.x - b.radius),
                                                         np.max(b.x + b.radius))]
        zs = [v for b in self.bodies.values() for v in (np.min(b.z - b.radius),
                                                         np.max(b.z + b.radius))]
        return float(min(xs)), float(max(xs)), float(min(zs)), float(max(zs))


def motion(scene: Scene, result: Result, times: np.ndarray, *,
           spin_gain: float = 1.0) -> Motion:
    """The bodies of ``scene`` at ``times`` [s], interpolated linearly in ``result``;
    drawn angles are the true ones times ``spin_gain``."""
    times = np.asarray(times, dtype=float)
    m = Machine(scene)

    def sample(name: str) -> np.ndarray:
        return np.interp(times, result.t, result[name])

    bodies = {}
    axes = dancer_axes(m)
    for b in m.bodies:
        ch = body_channels(scene, b)
        const = {"x": b.centre[0], "z": b.centre[1], "angle": 0.0, "speed": 0.0,
                 "position": 0.0,
                 "radius": math.nan if b.radius_state else b.part.radius}

        def get(role: str, ch: dict = ch, const: dict = const) -> np.ndarray:
            if role in ch and ch[role] in result:
                return sample(ch[role])
            return np.full_like(times, const[role])
        segment_of = getattr(b, "segment_of", None)
        support = tuple(b.part.centre) if segment_of and \
            type(b.part).__name__ == "DrumPart" else None
        x, z, carriage = get("x"), get("z"), {}
        if b.name in axes:  # a dancer: its roller where its carriage is
            d, e = get("position"), axes[b.name]
            x, z = b.centre[0] + d * e[0], b.centre[1] + d * e[1]
            carriage = {"position": d, "axis": e, "home": tuple(b.centre),
                        "travel": tuple(b.roles.dancer.travel)}
        bodies[b.name] = BodyMotion(b.name, b.role, b.sense, x, z,
                                    b.sense * get("angle") * spin_gain, get("radius"),
                                    get("speed"), b.radius_state, segment_of, support,
                                    **carriage)
    forces = {n: (sample(c) if c in result else None)
              for n, c in nip_channels(scene, m).items()}
    webs = []
    for w in m.webs:
        unwind = exit_ = tension = None
        if w.unwind is not None:
            unwind = w.unwind.name
            exit_ = exit_points(m, bodies, w)
            ch = f"{w.span_channel}span_tension"
            tension = sample(ch) if ch in result else None
        names = [f"{s.channel}tension" for s in w.spans]
        webs.append(WebMotion(w.name, (w.entry.a.name, w.entry.b.name), unwind, exit_,
                              tension, _rollers(w),
                              tuple(sample(c) if c in result else None for c in names)))
    slices = {n.name: n.whole for n in m.nips if getattr(n, "whole", None)}
    if not webs:
        return Motion(times, bodies, forces, None, units=dict(result.units), slices=slices)
    first = webs[0]
    return Motion(times, bodies, forces, first.entry, first.unwind, first.exit,
                  first.span_tension, tuple(webs), units=dict(result.units), slices=slices)


def exit_points(machine: Machine, bodies: dict[str, BodyMotion], web: Web | None = None
                ) -> np.ndarray:
    """The exit points ``p_u`` [m] of ``web``'s unwinding roll (default: the first web
    with a span), one row ``(x, z)`` per sample of ``bodies``: the engine's
    :func:`winder.forces.web_tension.exit_point` (direction ``t_u`` towards the entry
    drum's centre, ``p_u = c_u + s·r_u·(−t_z, t_x)``) evaluated on the drawn centres and
    radii with numpy."""
    def kin(b: BodyMotion, body: Body) -> SimpleNamespace:
        return SimpleNamespace(cx=b.x, cz=b.z, r=b.radius, body=body)

    if web is None:
        web = next(w for w in machine.webs if w.unwind is not None)
    u = web.unwind
    first = web.spans[0].downstream if web.spans else None  # a line's first roller
    a = first if first is not None else web.entry.a
    ev = SimpleNamespace(machine=machine, mathns=np, bodies={
        u.name: kin(bodies[u.name], u), a.name: kin(bodies[a.name], a)})
    _, _, ox, oz = exit_point(ev, web)
    return np.column_stack([bodies[u.name].x + ox, bodies[u.name].z + oz])


def _rollers(web: Web) -> tuple[str, ...]:
    """The rollers of ``web``'s line in order from its unwinding roll (none: one span)."""
    return tuple(s.downstream.name for s in web.spans if s.downstream is not None)


def web_points(web: Web) -> int:
    """How many points the drawn path of ``web`` has (the same at every sample): the
    unwinding roll's exit point or the lead, :data:`ROLLER_ARC_POINTS` per roller and
    :data:`WEB_ARC_POINTS` around the entry drum."""
    return 1 + ROLLER_ARC_POINTS * len(_rollers(web)) + WEB_ARC_POINTS


def dancer_axes(machine: Machine) -> dict[str, tuple[float, float]]:
    """The unit axis ``(e_x, e_z)`` of each dancer's travel (:func:`._line.dancer_axis`),
    on the scene's layout: bodies at their scene centres and initial radii, every
    carriage at ``d = 0``."""
    def circle(body: Body) -> Circle:
        return Circle(float(body.centre[0]), float(body.centre[1]),
                      float(body.initial_radius), 1 if body.sense >= 0 else -1)
    out = {}
    for w in machine.webs:
        for s in w.spans[1:]:
            roller = s.upstream
            if roller.roles.dancer is None:
                continue
            down = s.downstream if s.downstream is not None else w.entry.a
            e = dancer_axis(circle(w.spans[s.index - 1].upstream), circle(roller),
                            circle(down))
            out[roller.name] = (float(e[0]), float(e[1]))
    return out


def web_path(c_a: tuple[float, float], r_a: float, sense_a: int,
             c_b: tuple[float, float], r_b: float) -> np.ndarray:
    """Points ``(x, z)`` [m] of the web entering the nip between drum ``a`` (centre
    ``c_a``, radius ``r_a``, sense ``sense_a``) and roll ``b``: a straight run of
    :data:`WEB_LEAD` coming tangentially from off-screen, meeting the drum
    :data:`WEB_MEET` past its lowest point, wrapping it in its direction of motion
    (``θ̇ = sense · speed > 0``: clockwise seen from ``−y``) up to the nip direction
    ``n = (c_b − c_a)/|c_b − c_a|``, ending at the roll's contact point
    ``p_b = c_b − r_b n`` (machines spec §2)."""
    s = 1.0 if sense_a >= 0 else -1.0
    alpha_s = -0.5 * math.pi - s * WEB_MEET
    arc = _wrap(c_a, r_a, s, alpha_s, c_b, r_b)
    return np.vstack([arc[0] - WEB_LEAD * _travel(s, alpha_s), arc])


def span_web_path(p_u: tuple[float, float] | np.ndarray, c_a: tuple[float, float],
                  r_a: float, sense_a: int, c_b: tuple[float, float], r_b: float
                  ) -> np.ndarray:
    """Points ``(x, z)`` [m] of the web of a winder line: from the unwinding roll's exit
    point ``p_u`` straight along the span to where it touches drum ``a`` (the tangent from
    ``p_u`` along which the drum's surface moves away from ``p_u``), then as
    :func:`web_path` around the drum into the nip, ending at ``p_b = c_b − r_b n``."""
    p, ca = np.asarray(p_u, dtype=float), np.asarray(c_a, dtype=float)
    s = 1.0 if sense_a >= 0 else -1.0
    v = p - ca
    beta = math.atan2(v[1], v[0])
    phi = math.acos(min(1.0, r_a / max(float(np.hypot(*v)), 1e-12)))
    # of the two tangent points, the one where the web runs on in the drum's direction
    alpha_s = max((beta + phi, beta - phi), key=lambda al: float(
        np.dot(ca + r_a * np.array([math.cos(al), math.sin(al)]) - p, _travel(s, al))))
    return np.vstack([p, _wrap(c_a, r_a, s, alpha_s, c_b, r_b)])


def _travel(s: float, alpha: float) -> np.ndarray:
    """Travel direction of a drum's surface at angle ``alpha`` [rad] (``θ̇ > 0`` about
    ``+y`` moves the point at angle α along ``(sin α, −cos α)``), for sense ``s``."""
    return s * np.array([math.sin(alpha), -math.cos(alpha)])


def _wrap(c_a: tuple[float, float], r_a: float, s: float, alpha_s: float,
          c_b: tuple[float, float], r_b: float) -> np.ndarray:
    """:data:`WEB_ARC_POINTS` points around drum ``a`` from angle ``alpha_s`` [rad] in
    its direction of motion up to the nip direction ``n = (c_b − c_a)/|c_b − c_a|``, the
    last one replaced by the roll's contact point ``p_b = c_b − r_b n``."""
    ca, cb = np.asarray(c_a, dtype=float), np.asarray(c_b, dtype=float)
    d = cb - ca
    n = d / max(float(np.hypot(*d)), 1e-12)
    alpha_n = math.atan2(n[1], n[0])
    wrap = (s * (alpha_s - alpha_n)) % (2.0 * math.pi)
    alpha = alpha_s - s * wrap * np.linspace(0.0, 1.0, WEB_ARC_POINTS)
    arc = ca + r_a * np.column_stack([np.cos(alpha), np.sin(alpha)])
    arc[-1] = cb - r_b * n
    return arc
