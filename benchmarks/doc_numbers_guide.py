"""The renderers of the user guide's web-line page (docs/guide/idlers-dancers-spans.md),
merged into ``benchmarks/doc_numbers.py``'s ``RENDER``: from ``docs/guide_numbers.json``
(``benchmarks/guide_numbers.py``), the shipped dancer line's scene file and the dancer
design's closed form."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

DANCER_SCENE = "winder_line_dancer"


def _g(s) -> dict:  # noqa: ANN001 - doc_numbers.Sources
    return s.bench("guide_numbers")


def _minus(x: float, fmt: str) -> str:
    return ("−" if x < 0 else "") + format(abs(x), fmt)


def _poles(poles: list) -> str:
    """``−a, −b ± cj`` [rad/s], two decimals."""
    return ", ".join(_minus(re, ".2f") + (f" ± {im:.2f}j" if im > 0 else "")
                     for re, im in poles)


def _j(x: float) -> str:
    """An inertia [kg·m²] with a thin space between the thousands: 12 633."""
    return f"{x:,.0f}".replace(",", " ")


def _gain(gm: float | None, w: float | None, tail: str = "") -> str:
    if gm is None:
        return "none (the phase never reaches −180°)" if tail == "first" else "none"
    return f"{gm:.3g} ({20 * math.log10(gm):.1f} dB) at {w:.1f} rad/s{tail}"


def _span_row(s, label: str, gain_tail: str) -> str:  # noqa: ANN001
    c = _g(s)["tension_span"]["cases"][label]
    parent = label.split("_")[0]
    if c["web_speed"] is None:  # the scene's: its drums' web speed
        where = f"{parent}, {s.scene('winder_line').drums[0].drive.web_speed:g} m/s"
    else:
        where = (f"{parent}, r = {c['radius']:.2f} m (J = {_j(c['inertia'])} kg m²), "
                 f"{c['web_speed']:g} m/s")
    gain = _gain(c["gain_margin"], c["gain_crossover"], gain_tail)
    return (f"| {where} | {_poles(c['poles'])} | {c['phase_margin']:.1f}° at "
            f"{c['crossover']:.1f} rad/s | {gain} |")


def span_table(s) -> str:  # noqa: ANN001
    """tension_control on span 1: the closed-loop poles nearest −ω_c and the margins."""
    return "\n".join([
        "| parent, web speed | closed-loop poles nearest −ω_c [rad/s] | phase margin "
        "| gain margin |", "|---|---|---|---|",
        _span_row(s, "full_5", " (the roller mode)"), _span_row(s, "empty_5", "first"),
        _span_row(s, "full", ""), _span_row(s, "empty", "")])


def dancer_table(s) -> str:  # noqa: ANN001
    """The shipped dancer loop's margins at a full and a nearly empty parent."""
    rows = ["| parent | phase margin | crossover | gain margin |", "|---|---|---|---|"]
    for label, name in (("full", "full"), ("empty", "nearly empty")):
        p = _g(s)["dancer_control"]["parents"][label]
        rows.append(f"| {name}, r = {p['radius']:.2f} m (J = {_j(p['inertia'])} kg m²) "
                    f"| {p['phase_margin']:.1f}° | {p['crossover']:.2f} rad/s "
                    f"| {_gain(p['gain_margin'], p['gain_crossover'])} |")
    return "\n".join(rows)


def design_phase_margin() -> float:
    """The dancer design's phase margin [°]: its loop ``(3ω_c s² + 3ω_c² s + ω_c³)/s³``
    (``d'' = g δτ`` closed by the PID of the page; ``g`` cancels) at ``|L| = 1``, the same
    at every radius and bandwidth (in ``x = ω/ω_c``: ``x⁶ = (1 − 3x²)² + 9x²``)."""
    y = max(r.real for r in np.roots([1.0, -9.0, -3.0, -1.0]) if abs(r.imag) < 1e-12)
    jx = 1j * math.sqrt(y)
    loop = (3 * jx ** 2 + 3 * jx + 1) / jx ** 3
    return 180.0 + math.degrees(np.angle(loop))


def _modes(s, case: str) -> dict:  # noqa: ANN001
    return _g(s)["line_modes"][case]


def _mode_cell(s, coord: str, parent: str) -> str:  # noqa: ANN001
    f, z = _modes(s, "dancer_control")[coord][parent]
    return f"{f:.2f} Hz, ζ = {z:.3f}" if f >= 1 else f"{f:.3f} Hz, ζ = {z:.3f}"


def modes_table(s) -> str:  # noqa: ANN001
    """The shipped line's modes under dancer_control at a full and an empty parent."""
    rows = ["| mode | full parent, r = 1.25 m | empty, r = 0.45 m |", "|---|---|---|"]
    for coord, name in (("dancer.carriage", "`dancer.carriage`"),
                        ("guide3.roller", "`guide3.roller`")):
        rows.append(f"| {name} | {_mode_cell(s, coord, 'full')} "
                    f"| {_mode_cell(s, coord, 'empty')} |")
    three = ("guide1.roller", "dancer.roller", "guide2.roller")
    rows.append("| " + " / ".join(f"`{c}`" for c in three) + " | "
                + " / ".join(f"{_modes(s, 'dancer_control')[c]['full'][0]:.2f}"
                             for c in three) + " Hz | the same |")
    rows.append(f"| `parent.unwind` (the dancer loop) | {_mode_cell(s, 'parent.unwind', 'full')} "
                f"| {_mode_cell(s, 'parent.unwind', 'empty')} |")
    return "\n".join(rows)


def _carriage_mode(s, case: str, parent: str) -> float:  # noqa: ANN001
    return _modes(s, case)["dancer.carriage"][parent][0]


def _dancer(s):  # noqa: ANN001, ANN202 - the dancer's IdlerPart
    return next(i for i in s.scene(DANCER_SCENE).idlers if i.dancer is not None)


def held_carriage(s) -> str:  # noqa: ANN001
    """``sqrt((k + EA/L_up + EA/L_down) / m_d) / 2π`` of the shipped dancer [Hz]."""
    sc, d = s.scene(DANCER_SCENE), _dancer(s)
    spans = sc.web.spans
    i = next(k for k, sp in enumerate(spans) if sp.to == d.name)
    k = d.dancer.stiffness + spans[i].EA / spans[i].length + spans[i + 1].EA / spans[i + 1].length
    return f"{math.sqrt(k / (d.dancer.mass + d.mass)) / (2 * math.pi):.0f}"


def _parent_weight(s, parent: str) -> str:  # noqa: ANN001
    """The parent's ``J/r²`` [t]."""
    p = _g(s)["dancer_control"]["parents"][parent]
    return f"{p['inertia'] / p['radius'] ** 2 / 1e3:.1f} t"


def _brake_tensions(s) -> str:  # noqa: ANN001
    """The first span's tension under the tests' 1000 N·m brake, ``1000 N·m / r`` [N], to
    100 N."""
    radii = {k: p["radius"] for k, p in _g(s)["dancer_control"]["parents"].items()}
    return ", ".join(f"{round(1000.0 / radii[k], -2):.0f} N {k}" for k in ("full", "empty"))


RENDER: dict[str, Callable] = {
    "line.span_table": span_table,
    "line.span_settle": lambda s: f"{_g(s)['tension_span']['step']['settled']:.2f} s",
    "line.dancer_decay": lambda s: f"{-_g(s)['dancer_control']['decay']['rate']:.2f} 1/s",
    "line.dancer_table": dancer_table,
    "line.dancer_design_pm": lambda s: f"{design_phase_margin():.0f}°",
    "line.modes_table": modes_table,
    "line.carriage_mode": lambda s: f"{_carriage_mode(s, 'dancer_control', 'full'):.2f} Hz",
    "line.guides_mass": lambda s: " / ".join(sorted({
        f"{i.inertia / i.radius ** 2:.0f}" for i in s.scene(DANCER_SCENE).idlers
        if i.dancer is None})) + " kg each",
    "line.carriage_mass": lambda s: f"{_dancer(s).dancer.mass + _dancer(s).mass:.0f} kg",
    "line.held_carriage": held_carriage,
    "line.brake_tensions": _brake_tensions,
    "line.brake_weights": lambda s: (f"{_parent_weight(s, 'full')} full, "
                                     f"{_parent_weight(s, 'empty')} empty"),
    "line.brake_unwind": lambda s: (
        f"{_modes(s, 'brake')['parent.unwind']['full'][0]:.2f} Hz (full) to "
        f"{_modes(s, 'brake')['parent.unwind']['empty'][0]:.2f} Hz (empty)"),
    "line.brake_carriage": lambda s: (
        f"{_carriage_mode(s, 'brake', 'full'):.1f} Hz mode at full and in the "
        f"{_carriage_mode(s, 'brake', 'empty'):.1f} Hz one"),
}
