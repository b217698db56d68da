"""On-screen readout: time, roll radii (the unwinding roll's too), body speeds, nip normal
forces and, on a winder line, the span's tension (a web line: every span's on one line,
its rollers' speeds on one line, each dancer's position), as an HTML overlay on meshcat's
page;
the units are the result's (:attr:`winder.Result.units`, carried on the Motion).

meshcat 0.3.2 animates only numeric properties of objects, so the text is not part of the
3-D scene: the page gets a ``<div id="winder-readout">`` and, for an animation, one text
per frame and a script that shows the text of the frame the animation is at
(``viewer.animator.time`` [s of playback] times the frame rate).
"""

from __future__ import annotations

import html
import json
from types import SimpleNamespace

import numpy as np
from winder.viewer._motion import BodyMotion, Motion

from winder.forces import FORCES
from winder.model.channels import GENERIC_CHANNELS, WEB_SPEED
from winder.parts import PARTS

__all__ = ["readout_text", "deflections", "with_readout", "unit_of", "DEFAULT_UNITS",
           "SURFACE_SPEED_UNIT", "READOUT_ID", "MAX_LISTED_SPANS"]

READOUT_ID = "winder-readout"
#: A web line with more spans than this shows their least, mean and largest tension
#: instead of each.
MAX_LISTED_SPANS = 6

_STYLE = (f"#{READOUT_ID} {{position: fixed; left: 10px; top: 10px; margin: 0; "
          "padding: 6px 9px; background: rgba(255,255,255,0.82); color: #111; "
          "font: 13px/1.3 monospace; white-space: pre; border-radius: 4px; "
          "pointer-events: none; z-index: 10;}}")


def _declared_units() -> dict[str, str]:
    """Each channel's declared unit by its name after the part (``speed`` of
    ``BODY_speed``): the generic channels, the body elements' and the effects'."""
    declared = (*GENERIC_CHANNELS, *(c for cls in PARTS.values() for c in cls.CHANNELS),
                *(c for cls in FORCES.values() for c in cls.CHANNELS))
    return {c.suffix: c.unit for c in declared}


#: The readout's units where the result carries none (an old NPZ, a CSV): the channels'
#: declared units (:class:`winder._schema.Channel`), SI.
DEFAULT_UNITS = {q: unit for q, unit in _declared_units().items()
                 if q in ("t", "radius", "speed", "normal_force", "span_tension")}
#: The unit of a body's surface speed ``ω r``: a web speed's.
SURFACE_SPEED_UNIT = WEB_SPEED.unit


def unit_of(m: Motion, quantity: str, name: str = "") -> str:
    """The unit of ``quantity`` (``speed``, ``radius``, ...) of the part ``name`` from
    the result's units (:attr:`Motion.units`): its channel ``NAME_QUANTITY``, else the
    channel ``QUANTITY`` (the single-drum format's, a single span's), else
    :data:`DEFAULT_UNITS`."""
    for channel in (f"{name}_{quantity}" if name else "", quantity):
        if channel in m.units:
            return m.units[channel]
    return DEFAULT_UNITS[quantity]


def _groups(m: Motion) -> dict[str, list[BodyMotion]]:
    """The bodies of ``m`` by part: a flexible body's segments under its name."""
    out: dict[str, list[BodyMotion]] = {}
    for b in m.bodies.values():
        out.setdefault(b.segment_of or b.name, []).append(b)
    return out


def _mean(values: list[float]) -> float:
    """The mean of a flexible body's segments' values; a rigid body's own value (its
    sign of zero too)."""
    return float(values[0]) if len(values) == 1 else float(np.mean(values))


def deflections(segments: list[BodyMotion], k: int) -> np.ndarray:
    """The deflection [m] of each segment of a flexible body at sample ``k``: its
    distance in the ``x``–``z`` plane from its bearings' line (a drum), else from the
    segments' mean (its bending alone), as the figures take it."""
    xz = np.array([(b.x[k], b.z[k]) for b in segments])
    ref = segments[0].support if segments[0].support is not None else xz.mean(axis=0)
    return np.hypot(*(xz - np.asarray(ref)).T)


def readout_text(m: Motion, k: int) -> str:
    """The readout of sample ``k`` of ``m``: ``t``; per paper roll its radius; per body
    its speed and surface speed (:data:`SURFACE_SPEED_UNIT`); per nip its normal force
    (in thousands: kN); on a winder line the span's tension ``span  T … N`` (``-``
    without its channel). The units are the result's (:func:`unit_of`): [s], [m],
    [rad/s], [N] for a result of winder. A flexible body is one line (its segments'
    mean speed, their largest and mean deflection :func:`deflections` [mm]) and a sliced
    nip one (its slices' total force, their least and largest), whatever their number."""
    lines = [f"t  {m.times[k]:10.2f} {unit_of(m, 't')}"]
    spans = [w for w in m.webs if w.unwind is not None] or (
        [SimpleNamespace(name="", span_tension=m.span_tension, rollers=(),
                         span_tensions=())] if m.unwind is not None else [])
    labels = ["span" if len(spans) == 1 else f"{w.name} span" for w in spans]
    rollers = [n for w in spans for n in w.rollers]
    groups = {n: g for n, g in _groups(m).items() if n not in rollers}
    nips: dict[str, list[str]] = {}
    for name in m.normal_forces:
        nips.setdefault(m.slices.get(name, name), []).append(name)
    width = max(len(n) for n in (*groups, *nips, "span", *labels, *rollers,
                                 *(("rollers", "spans") if rollers else ())))
    for name, segs in groups.items():
        if segs[0].radius_state:
            r = _mean([b.radius[k] for b in segs])
            lines.append(f"{name:<{width}}  r {r:8.4f} {unit_of(m, 'radius', segs[0].name)}")
    for name, segs in groups.items():
        w = _mean([b.speed[k] for b in segs])
        v = _mean([b.speed[k] * b.radius[k] for b in segs])
        line = f"{name:<{width}}  {w:8.2f} {unit_of(m, 'speed', segs[0].name)} " \
            f"{v:7.2f} {SURFACE_SPEED_UNIT}"
        if segs[0].segment_of is not None:
            d = 1e3 * deflections(segs, k)
            line += f"  δ max {d.max():.3f} mean {d.mean():.3f} mm"
        lines.append(line)
    for name, parts in nips.items():
        forces = [m.normal_forces[p] for p in parts]
        if any(f is None for f in forces):
            value, more = "      -", ""
        else:
            each = np.array([f[k] for f in forces]) / 1e3
            value = f"{each.sum():8.3f}"
            more = f"  ({len(parts)} slices {each.min():.3f}–{each.max():.3f} kN)" \
                if len(parts) > 1 else ""
        lines.append(f"{name:<{width}}  N {value} k{unit_of(m, 'normal_force', parts[0])}"
                     + more)
    if rollers:
        lines.append(_rollers_line(m, k, rollers, width))
    for label, w in zip(labels, spans, strict=True):
        unit = unit_of(m, 'span_tension', w.name)
        if len(w.rollers) == 0:
            T = w.span_tension
            value = "      -" if T is None else f"{T[k]:8.1f}"
            lines.append(f"{label:<{width}}  T {value} {unit}")
            continue
        lines.append(f"{label + 's':<{width}}  T {_tensions(w.span_tensions, k)} {unit}")
    for name in rollers:
        b = m.bodies[name]
        if b.position is not None:
            lo, hi = (1e3 * v for v in b.travel)
            lines.append(f"{name:<{width}}  d {1e3 * b.position[k]:+8.1f} mm  "
                         f"(travel {lo:+.0f} … {hi:+.0f})")
    return "\n".join(lines)


def _rollers_line(m: Motion, k: int, names: list[str], width: int) -> str:
    """One line for a web line's rollers: their number, least and largest speed and
    surface speed."""
    w = np.array([m.bodies[n].speed[k] for n in names])
    v = np.array([m.bodies[n].speed[k] * m.bodies[n].radius[k] for n in names])
    unit = unit_of(m, "speed", names[0])
    return (f"{'rollers':<{width}}  ×{len(names)} {w.min():.2f}–{w.max():.2f} {unit} "
            f"{v.min():.2f}–{v.max():.2f} {SURFACE_SPEED_UNIT}")


def _tensions(tensions: tuple[np.ndarray | None, ...], k: int) -> str:
    """Every span's tension at sample ``k`` in order (``-`` without its channel), or,
    beyond :data:`MAX_LISTED_SPANS` spans, their least, mean and largest."""
    if len(tensions) > MAX_LISTED_SPANS and all(T is not None for T in tensions):
        each = np.array([T[k] for T in tensions])
        return f"×{len(each)} {each.min():.1f}–{each.max():.1f} mean {each.mean():.1f}"
    return " ".join("-" if T is None else f"{T[k]:.1f}" for T in tensions)


def with_readout(page: str, texts: list[str], fps: int | None = None) -> str:
    """``page`` (meshcat's static HTML) with the readout overlay: ``texts[0]`` fixed
    (``fps`` None) or ``texts[k]`` while the animation shows frame ``k``."""
    first = html.escape(texts[0])
    parts = [f"<style>{_STYLE}</style>", f'<pre id="{READOUT_ID}">{first}</pre>']
    if fps is not None and len(texts) > 1:
        data = json.dumps(texts).replace("</", "<\\/")
        parts.append(
            "<script>(function () {\n"
            f"  var texts = {data}, fps = {int(fps)};\n"
            f"  var el = document.getElementById('{READOUT_ID}');\n"
            "  function tick() {\n"
            "    var k = 0;\n"
            "    if (typeof viewer !== 'undefined' && viewer.animator) {\n"
            "      k = Math.round(viewer.animator.time * fps);\n"
            "    }\n"
            "    k = Math.max(0, Math.min(texts.length - 1, k));\n"
            "    if (el.textContent !== texts[k]) { el.textContent = texts[k]; }\n"
            "    window.requestAnimationFrame(tick);\n"
            "  }\n"
            "  tick();\n"
            "})();</script>")
    overlay = "\n".join(parts)
    at = page.rfind("</body>")
    if at < 0:
        return page + overlay
    return page[:at] + overlay + "\n" + page[at:]
