"""The renderers of the user guide's web-line page (docs/guide/idlers-dancers-spans.md)
and of docs/control.md, merged into ``benchmarks/doc_numbers.py``'s ``RENDER``: from
``docs/guide_numbers.json`` (``benchmarks/guide_numbers.py``), the shipped dancer line's
scene file and the dancer design's closed form."""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
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


def _sci(x: float, digits: int = 2) -> str:
    """``x`` to ``digits`` significant digits, the exponent short: 1.7e-3."""
    mant, exp = f"{x:.{digits - 1}e}".split("e")
    return f"{mant}e{int(exp)}"


def _mpc(s) -> dict:  # noqa: ANN001
    return _g(s)["tension_mpc"]


def _n(x: float) -> str:
    """An error [N] as the page writes it: two significant digits, small ones as 1.7e-3."""
    return _sci(x) if x < 0.01 else f"{x:.2g}" if x < 1 else f"{x:.3g}" if x < 10 else f"{x:.0f}"


def _mpc_steps(s) -> str:  # noqa: ANN001
    m = _mpc(s)
    return (f"{m['steps']} MPC steps, the line's step included, take "
            f"{m['loop_cpu_time']:.1f} s of CPU ({1e3 * m['loop_cpu_time'] / m['steps']:.1f} ms "
            f"each; {m['loop_wall_time']:.0f} s wall at a load average of "
            f"{m['load_average']:.1f} on 2 cores)")


@functools.cache
def second_spectrum() -> float:
    """The cutoff of Timoshenko's second spectrum, ``sqrt(κGA / ρI) / 2π`` [Hz], of the 6 m
    drum of tests/parts/test_flex_rotary.py (model.md §9): the sections' own rotation
    lies above it."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "test_flex_rotary", ROOT / "tests" / "parts" / "test_flex_rotary.py")
    ft = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ft)
    return math.sqrt(ft.KGA / ft.RHO_I) / (2 * math.pi)


def _link(s) -> str:  # noqa: ANN001
    """The link each machine adds to the integrators' objects [s] (docs/compiled_machine.json,
    this tree's row)."""
    cm = s.bench("compiled_machine")
    tree = next(v for k, v in cm.items() if k.startswith("this tree"))
    links = [m["link_only"] for m in tree["compile"]["machines"].values()]
    lo, hi = f"{min(links):.3f}", f"{max(links):.3f}"
    return f"{lo} s each" if lo == hi else f"{lo}–{hi} s each"


def _python_call(s) -> str:  # noqa: ANN001
    """The generated rhs called from Python (ctypes) and inside the compiled loop [µs]
    (docs/rhs_speed.json, its shipped scenes' rows)."""
    rows = s.bench("rhs_speed")["rows"]
    py, c = ([r[k] for r in rows] for k in ("rhs_python_us", "rhs_us"))
    return (f"{min(py):.0f}–{max(py):.0f} µs a call against {min(c):.2f}–{max(c):.2f} µs "
            "inside the compiled loop")


RENDER: dict[str, Callable] = {
    # docs/c-integrators.md (the benchmarks' JSON)
    "cint.link": _link,
    "cint.python_call": _python_call,
    # docs/guide/modes.md: the sections' rotation modes
    "modes.second_spectrum": lambda s: f"{second_spectrum() / 1e3:.2f} kHz",
    # docs/control.md: casadi_model's build, the MPC example (examples/tension_mpc.py)
    "control.casadi_build": lambda s: (
        f"{_g(s)['casadi_model']['first_cpu_time']:.2f} s of CPU in a fresh process (its "
        "machine's code from the disk cache), "
        f"{_g(s)['casadi_model']['cached_cpu_time']:.2f} s once the machine is cached in "
        "the process"),
    "control.mpc_ramp": lambda s: (
        f"{_n(_mpc(s)['mpc_ramp_max'])} N (rms {_n(_mpc(s)['mpc_ramp_rms'])} N), the built-in "
        f"controller's {_n(_mpc(s)['builtin_ramp_max'])} N"),
    "control.builtin_ramp_rms": lambda s: f"{_n(_mpc(s)['builtin_ramp_rms'])} N",
    "control.torque_drop": lambda s: f"{round(_mpc(s)['torque_drop'], -2):.0f} N·m",
    "control.mpc_end": lambda s: (f"{_n(_mpc(s)['mpc_end_max'])} N against "
                                  f"{_n(_mpc(s)['builtin_end_max'])} N"),
    "control.mpc_steps": _mpc_steps,
    "control.move_scales": lambda s: "; ".join(
        f"{k} N·m: {_n(_mpc(s)['move_scales'][k]['end_max'])} N"
        + (" there" if k == "10" else "") for k in ("10", "1000")),
    # docs/guide/idlers-dancers-spans.md
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
