"""Every measured number of the README and the docs pages comes from a script: this one
fills them in and checks them (``make docs-numbers``; ``tests/test_doc_numbers.py``).

A page marks each measured number (a phrase, a table) as a block::

    the set reaches <!-- numbers: two_drum.final_radius -->0.60<!-- /numbers --> m

``NAME`` is an entry of :data:`RENDER`: a function of :class:`Sources` that returns the
block's text. The sources:

- ``docs/numbers.json``: the numbers of runs and analyses (the paper's cycle, the
  two-drum winder, the calibration example, the tension loop's design, the flexible
  drum's frequencies against the Timoshenko equation), written by
  ``benchmarks/readme_numbers.py --json`` (a minute or two: it runs the scenes where
  ``out/`` lacks them); a slow test checks it against a fresh run;
- ``docs/guide_numbers.json``: the web-line page's loops and modes, written by
  ``benchmarks/guide_numbers.py`` (a minute; renderers in ``doc_numbers_guide.py``);
- the benchmarks' JSON beside their pages (``docs/cycle_speed.json``,
  ``docs/build_speed.json``, ...), written by ``make bench``;
- cheap numbers computed here from the scene files, the code's constants and closed
  forms (milliseconds).

Run:  python benchmarks/doc_numbers.py            # check: exit 1 naming each stale block
      python benchmarks/doc_numbers.py --write    # fill every block from its source
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
NUMBERS_JSON = DOCS / "numbers.json"

#: ``<!-- numbers: NAME -->TEXT<!-- /numbers -->`` (TEXT may span lines; blocks do not nest).
BLOCK = re.compile(r"<!-- numbers: (?P<name>[\w.\-]+) -->(?P<text>.*?)<!-- /numbers -->",
                   re.DOTALL)
OPEN = re.compile(r"<!-- numbers: ([^>]*?) -->")
CLOSE = "<!-- /numbers -->"


def pages(root: Path = ROOT) -> list[Path]:
    """The pages checked: the README and every Markdown page under ``docs/``."""
    return [root / "README.md", *sorted((root / "docs").rglob("*.md"))]


class Sources:
    """The sources of the numbers, each read once: ``numbers`` (docs/numbers.json),
    ``bench(name)`` (docs/NAME.json), ``scene(model)`` (models/MODEL.toml)."""

    def __init__(self, root: Path = ROOT, numbers: dict | None = None) -> None:
        self.root = root
        self._numbers = numbers

    @functools.cached_property
    def numbers(self) -> dict:
        if self._numbers is None:
            self._numbers = json.loads((self.root / "docs" / "numbers.json").read_text("utf-8"))
        return self._numbers

    @functools.cache  # noqa: B019 - one Sources per check
    def bench(self, name: str) -> dict | list:
        return json.loads((self.root / "docs" / f"{name}.json").read_text("utf-8"))

    @functools.cache  # noqa: B019
    def scene(self, model: str):  # noqa: ANN201 - winder.Scene
        import winder

        return winder.load_scene(self.root / "models" / f"{model}.toml")


# --- the renderers: NAME -> text ------------------------------------------------------

def _build_pair(s: Sources) -> dict:
    """The latest cold build of the rigid and the flexible two-drum winder
    (docs/build_speed.json, benchmarks/build_speed.py): its median pair."""
    return s.bench("build_speed")[-1]["median_pair"]


def _cycle_row(s: Sources, section: str, method: str) -> dict:
    rows = s.bench("cycle_speed")["sections"][section]["rows"]
    return next(r for r in rows if r["method"] == method)


def _parent_mass(s: Sources) -> float:
    """The paper on the winder line's parent roll at its start [kg]: ``ρ π L (r² − r_c²)``."""
    line = s.scene("winder_line")
    parent = next(r for r in line.rolls if r.kind == "unwinding")
    return (line.paper.density * math.pi * parent.width
            * (parent.initial_radius ** 2 - parent.core_radius ** 2))


def _parent_inertia_ratio(s: Sources) -> float:
    """The winder line's parent roll: its polar inertia full over empty (at its core),
    ``J(r) = J_core + ½ ρ π L (r⁴ − r_c⁴)``."""
    line = s.scene("winder_line")
    p = next(r for r in line.rolls if r.kind == "unwinding")
    paper = 0.5 * line.paper.density * math.pi * p.width * (p.initial_radius ** 4
                                                              - p.core_radius ** 4)
    return (p.core_inertia + paper) / p.core_inertia


def _timoshenko(mode: int, *, length: float, ro: float, wall: float, rotary: bool) -> float:
    """The k-th bending frequency [Hz] of a simply supported steel tube (the issue's drum:
    E 210 GPa, G 80.8 GPa, shear coefficient 0.5, ρ 7850 kg/m³) by the Timoshenko
    frequency equation, with shear, with or without the rotary inertia (the smaller root of
    ``ρA ρI ω⁴/kGA − ω² (ρA + ρI κ² + ρA EI κ²/kGA) + EI κ⁴ = 0``, ``κ = kπ/L``)."""
    e, g, rho, kappa_s = 2.1e11, 8.08e10, 7850.0, 0.5
    area = math.pi * (ro ** 2 - (ro - wall) ** 2)
    i_area = math.pi / 4 * (ro ** 4 - (ro - wall) ** 4)
    ei, kga, rho_a = e * i_area, kappa_s * g * area, rho * area
    rho_i = rho * i_area if rotary else 0.0
    k = mode * math.pi / length
    a = rho_a * rho_i / kga
    b = rho_a + rho_i * k ** 2 + rho_a * ei * k ** 2 / kga
    c = ei * k ** 4
    w2 = c / b if a == 0.0 else (b - math.sqrt(b * b - 4 * a * c)) / (2 * a)
    return math.sqrt(w2) / (2 * math.pi)


def _rotary_drop(mode: int, length: float = 6.0) -> float:
    """How much the rotary inertia lowers mode ``mode`` of the 6 m × Ø 1 m × 30 mm tube
    (or one of ``length``), simply supported [%]."""
    kw = {"length": length, "ro": 0.5, "wall": 0.03}
    return 100 * (1 - _timoshenko(mode, rotary=True, **kw) / _timoshenko(mode, rotary=False,
                                                                         **kw))


@functools.cache
def _flex_oracle():  # noqa: ANN202 - the module
    """tests/parts/test_flex_rotary.py: the Timoshenko equation on bearings (its oracle,
    written once)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "test_flex_rotary", ROOT / "tests" / "parts" / "test_flex_rotary.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@functools.cache
def _on_bearings(kb: float, rotary: bool) -> tuple[float, float]:
    """The 6 m drum's first two bending frequencies [Hz] on bearings ``kb`` [N/m] (0:
    free–free), with or without the rotary inertia."""
    ft = _flex_oracle()
    w = ft.on_bearings(ft.RHO_I if rotary else 0.0, kb)
    return float(w[0] / (2 * math.pi)), float(w[1] / (2 * math.pi))


def _bearings_row(kb: float, rotary: bool) -> str:
    f1, f2 = _on_bearings(kb, rotary)
    text = f"{f1:.3f}, {f2:.2f}"
    if rotary:
        g1, g2 = _on_bearings(kb, False)
        text += f" (−{100 * (1 - f1 / g1):.2f} %, −{100 * (1 - f2 / g2):.2f} %)"
    return text


def _signed(x: float, fmt: str) -> str:
    """``x`` with its sign, the minus as the pages write it (−), the exponent short."""
    text = _sci(abs(x), 2) if fmt == "sci" else format(abs(x), fmt)
    return ("−" if x < 0 else "+") + text


def _machine_cell(s: Sources, bearings: str, key: str) -> str:
    """The machine's first two frequencies [Hz] at N = 8 / 16 (docs/numbers.json)."""
    m = s.numbers["flex_rotary"][bearings][key]
    return f"{m['8'][0]:.3f} / {m['16'][0]:.3f}, {m['8'][1]:.2f} / {m['16'][1]:.2f}"


def _machine_error(s: Sources, bearings: str, key: str) -> str:
    """The machine's frequencies at N = 8 / 16 against the full Timoshenko equation (with
    the rotary inertia): in % with the key off, relative with it on."""
    m = s.numbers["flex_rotary"][bearings][key]
    if bearings == "stiff":
        ref = [_timoshenko(k, length=6.0, ro=0.5, wall=0.03, rotary=True) for k in (1, 2)]
    else:
        ref = list(_on_bearings(1e9, True))
    cells = []
    for mode in (0, 1):
        errs = [m[n][mode] / ref[mode] - 1 for n in ("8", "16")]
        cells.append(" / ".join(_signed(100 * e, ".2f") + " %" if key == "off"
                                else _signed(e, "sci") for e in errs))
    return ", ".join(cells)


LENGTHS = (3.0, 6.0, 8.0, 10.0, 15.0, 20.0, 30.0)  #: the tube's lengths of the list [m]


def _shear_ratio(mode: int, length: float) -> float:
    """How much more shear lowers mode ``mode`` than the rotary inertia does (simply
    supported tube of ``length``): Euler–Bernoulli to shear only, over shear only to
    both."""
    ro, wall, e, rho = 0.5, 0.03, 2.1e11, 7850.0
    area = math.pi * (ro ** 2 - (ro - wall) ** 2)
    i_area = math.pi / 4 * (ro ** 4 - (ro - wall) ** 4)
    eb = (mode * math.pi / length) ** 2 * math.sqrt(e * i_area / (rho * area)) / (2 * math.pi)
    shear = _timoshenko(mode, length=length, ro=ro, wall=wall, rotary=False)
    return (1 - shear / eb) / (_rotary_drop(mode, length) / 100)


def _convergence(s: Sources) -> str:
    """The error's fall from N = 8 to 16 with the key on (both bearings, both modes)."""
    ratios = []
    for bearings in ("stiff", "1e9"):
        m = s.numbers["flex_rotary"][bearings]["on"]
        ref = ([_timoshenko(k, length=6.0, ro=0.5, wall=0.03, rotary=True) for k in (1, 2)]
               if bearings == "stiff" else list(_on_bearings(1e9, True)))
        ratios += [(m["8"][i] / ref[i] - 1) / (m["16"][i] / ref[i] - 1) for i in (0, 1)]
    return f"{min(ratios):.1f}–{max(ratios):.1f}"


def _extrapolation(s: Sources) -> str:
    """The largest error of ``(4 ω₁₆ − ω₈)/3`` against the equation (key on)."""
    worst = 0.0
    for bearings in ("stiff", "1e9"):
        m = s.numbers["flex_rotary"][bearings]["on"]
        ref = ([_timoshenko(k, length=6.0, ro=0.5, wall=0.03, rotary=True) for k in (1, 2)]
               if bearings == "stiff" else list(_on_bearings(1e9, True)))
        worst = max(worst, *(abs((4 * m["16"][i] - m["8"][i]) / 3 / ref[i] - 1)
                             for i in (0, 1)))
    return _sci(worst, 2)


def _rotary_states(s: Sources) -> int:
    """The states the sections' rotary inertia adds to the shipped flexible winder: four
    per segment of each flexible drum and rider (a wound roll has none)."""
    sc = s.scene("two_drum_winder_flexible")
    bodies = [*sc.drums, *sc.riders]
    return sum(4 * b.flex.segments for b in bodies
               if b.flex is not None and b.flex.rotary_inertia)


def _slenderness(length: float) -> float:
    ro, ri = 0.5, 0.47
    return length / math.sqrt((ro ** 2 + ri ** 2) / 4)


def _pct(x: float) -> str:
    return f"{x:.1f}" if x >= 1 else f"{x:.2f}"


def _two(s: Sources) -> dict:
    return s.numbers["two_drum_winder"]


def _nips(values: dict, fmt: str, scale: float = 1.0, sep: str = " / ") -> str:
    return sep.join(format(values[n] * scale, fmt) for n in ("front_nip", "rear_nip",
                                                             "rider_nip"))


def _sci(x: float, digits: int) -> str:
    """``x`` to ``digits`` significant digits as a scene file writes it: 2.2e4, not
    2.2e+04."""
    return re.sub(r"e([+-])0*(\d)", lambda m: "e" + m.group(1).replace("+", "") + m.group(2),
                  f"{x:.{digits - 1}e}")


def _fit_row(s: Sources, key: str, unit: str, truth: str) -> str:
    p = s.numbers["calibration"]["parameters"][key]
    lo, hi = p["ci95"]
    digits = 6 if key.endswith("stiffness") else 4
    return (f"| {key} [{unit}] | {truth} | {_sci(p['value'], digits)} ± {_sci(p['std'], 2)} "
            f"| [{_sci(lo, digits)}, {_sci(hi, digits)}] |")


def _calibration_table(s: Sources) -> str:
    return "\n".join(["| key | truth | fitted ± std | 95 % interval |", "|---|---|---|---|",
                      _fit_row(s, "contact.stiffness", "N/m", "2e7"),
                      _fit_row(s, "contact.damping", "N·s/m", "2e4")])


def _loop(s: Sources) -> dict:
    return s.numbers["tension_loop"]


def _poles(s: Sources) -> str:
    """The tension loop's closed-loop poles at the full parent: the real one and the pair
    [rad/s]."""
    poles = _loop(s)["parents"]["full"]["poles"]
    real = [p for p in poles if p[1] == 0.0]
    pair = [p for p in poles if p[1] > 0.0]
    return (" and ".join(f"−{-p[0]:.1f}" for p in real) + " and "
            + " and ".join(f"−{-p[0]:.2f} ± {p[1]:.2f}j" for p in pair) + " rad/s")


def _margins(s: Sources) -> str:
    parents = [_loop(s)["parents"][k] for k in ("full", "half", "empty")]  # as the page
    gains = [p["gain_margin"] for p in parents]
    return ("Phase margins " + ", ".join(f"{p['phase_margin']:.0f}°" for p in parents)
            + " at crossovers " + ", ".join(f"{p['crossover']:.1f}" for p in parents)
            + " rad/s; " + ("no finite gain margin" if all(g is None for g in gains) else
                            "gain margins " + ", ".join("∞" if g is None else f"{g:.2g}"
                                                        for g in gains)))


def _calibration(s: Sources) -> dict:
    return s.numbers["calibration"]


def _spread(s: Sources, key: str) -> str:
    """The half width of a fitted key's 95 % interval relative to its value [%]."""
    p = _calibration(s)["parameters"][key]
    return f"±{50 * (p['ci95'][1] - p['ci95'][0]) / p['value']:.0f} %"


def _sigmas(s: Sources, key: str, truth: float) -> str:
    """How many standard errors the fitted key lies from the truth, and on which side."""
    p = _calibration(s)["parameters"][key]
    z = (p["value"] - truth) / p["std"]
    return f"{abs(z):.1f} σ {'above' if z > 0 else 'below'}"


RENDER: dict[str, Callable[[Sources], str]] = {
    # the paper's single-drum cycle (models/paper_winding.toml)
    "paper.final_radius": lambda s: f"{s.numbers['paper_winding']['final_radius']:.2f}",
    "paper.cycle_wall": lambda s: f"{_cycle_row(s, 'paper', 'DOPRI5')['wall']:.1f} s",
    # the two-drum winder (models/two_drum_winder.toml), its flexible twin and the line
    "two_drum.final_radius": lambda s: f"{_two(s)['final_radius']:.1f}",
    "flex.segments": lambda s: str(s.scene("two_drum_winder_flexible").drums[0].flex.segments),
    "line.parent_mass": lambda s: f"{_parent_mass(s) / 1e3:.0f}",
    "line.inertia_ratio": lambda s: f"{_parent_inertia_ratio(s):.0f}",
    "two_drum.balance": lambda s: (
        f"initial static balance: residual {_two(s)['balance_residual']:.1e} N of "
        f"{_two(s)['balance_scale']:.1e} N"),
    "two_drum.band": lambda s: (
        f"r = {_two(s)['band']['r'][0]:.3f}–{_two(s)['band']['r'][1]:.3f} m "
        f"(t = {_two(s)['band']['t'][0]:.0f}–{_two(s)['band']['t'][1]:.0f} s)"),
    "two_drum.open_share": lambda s: _nips(_two(s)["open_share_band"], ".0f", 100),
    "two_drum.peaks": lambda s: _nips(_two(s)["peak_band"], ".1f", 1e-3),
    "two_drum.rest": lambda s: _nips(_two(s)["rest"], ".1f", 1e-3),
    "two_drum.rider_bounce": lambda s: " / ".join(
        _signed(1e3 * x, ".2f") for x in _two(s)["bounce_band"]["rider"][::-1]),
    "two_drum.set_bounce": lambda s: " / ".join(
        _signed(1e3 * x, ".2f") for x in _two(s)["bounce_band"]["set"][::-1]),
    "two_drum.set_x": lambda s: " to ".join(
        _signed(1e3 * x, ".2f") for x in _two(s)["set_x_band"]),
    "two_drum.above_band": lambda s: _nips(_two(s)["half_p2p_above_band"], ".1f", 1e-3),
    "two_drum.events": lambda s: f"{_two(s)['run']['events']:,}",
    "two_drum.wall": lambda s: f"{_two(s)['run']['wall_time']:.1f} s",
    # the cold build (benchmarks/build_speed.py) and the generator (codegen_speed.py)
    "build.rigid": lambda s: f"{_build_pair(s)['rigid']['wall']:.1f} s",
    "build.flexible": lambda s: f"{_build_pair(s)['flexible']['wall']:.0f} s",
    "codegen.generator": lambda s: s.bench("codegen_speed")["generator_build"].split(", once")[0],
    # the rotary inertia of a flexible drum's sections (closed form; docs/model.md §9)
    "rotary.drop": lambda s: f"{_rotary_drop(1):.1f} % and {_rotary_drop(2):.1f} %",
    "rotary.ss_shear": lambda s: (
        f"{_timoshenko(1, length=6.0, ro=0.5, wall=0.03, rotary=False):.3f}, "
        f"{_timoshenko(2, length=6.0, ro=0.5, wall=0.03, rotary=False):.2f}"),
    "rotary.ss_full": lambda s: (
        f"{_timoshenko(1, length=6.0, ro=0.5, wall=0.03, rotary=True):.3f}, "
        f"{_timoshenko(2, length=6.0, ro=0.5, wall=0.03, rotary=True):.2f} "
        f"(−{_rotary_drop(1):.2f} %, −{_rotary_drop(2):.2f} %)"),
    "rotary.bearings_shear": lambda s: _bearings_row(1e9, False),
    "rotary.bearings_full": lambda s: _bearings_row(1e9, True),
    "rotary.free_free": lambda s: " / ".join(
        f"{100 * (1 - a / b):.1f} %" for a, b in zip(_on_bearings(0.0, True),
                                                     _on_bearings(0.0, False), strict=True)),
    "rotary.before_stiff": lambda s: _machine_cell(s, "stiff", "off"),
    "rotary.before_1e9": lambda s: _machine_cell(s, "1e9", "off"),
    "rotary.before_stiff_error": lambda s: _machine_error(s, "stiff", "off"),
    "rotary.before_1e9_error": lambda s: _machine_error(s, "1e9", "off"),
    "rotary.now_stiff": lambda s: _machine_cell(s, "stiff", "on"),
    "rotary.now_1e9": lambda s: _machine_cell(s, "1e9", "on"),
    "rotary.now_stiff_error": lambda s: _machine_error(s, "stiff", "on"),
    "rotary.now_1e9_error": lambda s: _machine_error(s, "1e9", "on"),
    "rotary.tube": lambda s: (
        f"`EI` = {_sci(_flex_oracle().EI, 3)} N·m², `kGA` = {_sci(_flex_oracle().KGA, 3)} N, "
        f"`m` = {_flex_oracle().MASS:.0f} kg, `J` = {_flex_oracle().INERTIA:.0f} kg·m², "
        f"slenderness `L/r` = {_slenderness(6.0):.1f}"),
    "rotary.slenderness": lambda s: "; ".join(
        f"{_slenderness(length):.{1 if _slenderness(length) < 20 else 0}f}: "
        f"{_pct(_rotary_drop(1, length))} % / {_pct(_rotary_drop(2, length))} %"
        for length in LENGTHS),
    "rotary.shear_ratio": lambda s: "–".join(
        f"{f(_shear_ratio(k, length) for k in (1, 2) for length in LENGTHS):.{d}f}"
        for f, d in ((min, 1), (max, 0))),
    "rotary.convergence": _convergence,
    "rotary.extrapolation": _extrapolation,
    "rotary.states": lambda s: str(_rotary_states(s)),
    # the fit's speed (benchmarks/fit_speed.py, docs/fit_speed.json)
    "fit.samples": lambda s: (f"{s.bench('fit_speed')['samples']:,} samples of "
                              f"{s.bench('fit_speed')['channels']} channels"),
    "fit.wall": lambda s: (f"{s.bench('fit_speed')['wall']:.1f} s wall, "
                           f"{s.bench('fit_speed')['cpu']:.1f} s CPU"),
    "fit.evaluations": lambda s: (
        f"{s.bench('fit_speed')['evaluations']} evaluations with sensitivities, "
        f"{s.bench('fit_speed')['iterations']} iterations"),
    "fit.load": lambda s: f"{s.bench('fit_speed')['load']:.0f}",
    "fit.with_sensitivities": lambda s: (
        f"{s.bench('fit_speed')['with_sensitivities']:.2f} s "
        f"({s.bench('fit_speed')['without']:.2f} s without; building the CasADi functions "
        f"{s.bench('fit_speed')['build']:.1f} s, once)"),
    "fit.two_drum": lambda s: (
        f"{s.bench('fit_speed')['two_drum']['states']} states, "
        f"{s.bench('fit_speed')['two_drum']['t_end']:g} s of its start: "
        f"{s.bench('fit_speed')['two_drum']['with_sensitivities']:.1f} s per simulation with "
        f"sensitivities of two keys, {s.bench('fit_speed')['two_drum']['without']:.1f} s "
        "without"),
    # the unwind tension loop (examples/tension_loop_design.py)
    "loop.poles": _poles,
    "loop.inertia_ratio": lambda s: (
        f"{_loop(s)['parents']['full']['inertia'] / _loop(s)['parents']['empty']['inertia']:.0f}"),
    "loop.bandwidth": lambda s: f"{_loop(s)['bandwidth']:g}",
    "loop.spread": lambda s: _sci(_loop(s)["spread"], 1),
    "loop.margins": _margins,
    "loop.machine": lambda s: " … ".join(_sci(f(p["machine_agree"] for p in
                                                 _loop(s)["parents"].values()), 1)
                                         for f in (min, max)),
    "loop.step": lambda s: (f"{_sci(_loop(s)['step_error'], 2)} N of "
                            f"{_loop(s)['step_peak']:.1f} N"),
    # the calibration example (examples/calibrate_nip.py)
    "calibration.table": _calibration_table,
    "calibration.run": lambda s: (
        f"{_calibration(s)['iterations']} iterations, {_calibration(s)['evaluations']} "
        f"evaluations, {_calibration(s)['wall_time']:.1f} s, the noise estimated "
        f"({1e6 * _calibration(s)['channels']['z']['sigma']:.2f} µm, "
        f"{_calibration(s)['channels']['normal_force']['sigma']:.1f} N)"),
    "calibration.stiffness_error": lambda s: (
        f"{100 * abs(_calibration(s)['parameters']['contact.stiffness']['value'] / 2e7 - 1):.2f}"
        " %"),
    "calibration.damping_spread": lambda s: _spread(s, "contact.damping"),
    "calibration.damping_sigmas": lambda s: _sigmas(s, "contact.damping", 2e4),
    "calibration.modes": lambda s: (
        f"{100 * _calibration(s)['modes']['above_0.3']:.1f} % above r = 0.3 m "
        f"({100 * _calibration(s)['modes']['above_0.5']:.1f} % above 0.5 m)"),
    "calibration.core": lambda s: (
        f"{_calibration(s)['modes']['fitted_core']:.0f} against "
        f"{_calibration(s)['modes']['true_core']:.0f} Hz at "
        f"{_calibration(s)['modes']['core_radius']:.3f} m"),
}


def _more_renderers() -> dict[str, Callable[[Sources], str]]:
    """The renderers of other modules (benchmarks/doc_numbers_guide.py: the guide's pages)."""
    import importlib.util

    out: dict = {}
    for name in ("doc_numbers_guide",):
        spec = importlib.util.spec_from_file_location(name, ROOT / "benchmarks" / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        out.update(module.RENDER)
    return out


RENDER.update(_more_renderers())


# --- the blocks -----------------------------------------------------------------------

@dataclass(frozen=True)
class Stale:
    """A block whose text is not its source's: where, which, what it says and should."""

    page: str
    line: int
    name: str
    found: str
    want: str

    def __str__(self) -> str:
        return (f"{self.page}:{self.line}: <!-- numbers: {self.name} --> says "
                f"{self.found.strip()!r}, its source gives {self.want.strip()!r}")


def blocks(text: str) -> list[tuple[str, str, int]]:
    """``(NAME, TEXT, line)`` of every block of a page; ``ValueError`` for an opening
    without its close, a close without an opening, or a nested block."""
    found = [(m.group("name"), m.group("text"), text.count("\n", 0, m.start()) + 1)
             for m in BLOCK.finditer(text)]
    opens, closes = len(OPEN.findall(text)), text.count(CLOSE)
    if opens != len(found) or closes != len(found) or any(
            "<!-- numbers:" in t for _, t, _ in found):
        raise ValueError(f"{opens} '<!-- numbers: NAME -->' and {closes} '{CLOSE}' make "
                         f"{len(found)} whole blocks: each opening needs its close, "
                         "no nesting")
    for m in BLOCK.finditer(text):
        # Markdown takes a comment that starts a line for an HTML block of its own: inside
        # a paragraph that would cut it. A block starting a line stands on lines of its own.
        starts_line = m.start() == 0 or text[m.start() - 1] == "\n"
        if starts_line and not (m.group("text").startswith("\n\n")
                                and m.group("text").endswith("\n\n")):
            line = text.count("\n", 0, m.start()) + 1
            raise ValueError(f"line {line}: <!-- numbers: {m.group('name')} --> starts a "
                             "line inside a paragraph: keep it within the line, or give "
                             "the block lines of its own (blank lines around its text)")
    return found


def _render(name: str, sources: Sources) -> str:
    if name not in RENDER:
        raise KeyError(f"<!-- numbers: {name} -->: no such number; known: "
                       f"{', '.join(sorted(RENDER))}")
    return RENDER[name](sources)


def _same(found: str, want: str) -> bool:
    """Equal up to whitespace: a block may sit on lines of its own, or wrap with its
    paragraph."""
    return found.split() == want.split()


def check_text(text: str, page: str, sources: Sources) -> list[Stale]:
    """The stale blocks of one page."""
    out = []
    for name, found, line in blocks(text):
        want = _render(name, sources)
        if not _same(found, want):
            out.append(Stale(page, line, name, found, want))
    return out


def fill_text(text: str, sources: Sources) -> str:
    """The page with every stale block's text from its source (its surrounding whitespace
    kept; a block that differs only in whitespace is left as it is)."""
    blocks(text)

    def sub(m: re.Match) -> str:
        old = m.group("text")
        if _same(old, _render(m.group("name"), sources)):
            return m.group(0)
        lead = old[: len(old) - len(old.lstrip())]
        trail = old[len(old.rstrip()):]
        return (f"<!-- numbers: {m.group('name')} -->{lead}"
                f"{_render(m.group('name'), sources).strip()}{trail}{CLOSE}")

    return BLOCK.sub(sub, text)


def used(root: Path = ROOT) -> dict[str, list[str]]:
    """Page -> the names of its blocks (pages without one left out)."""
    out = {}
    for page in pages(root):
        names = [n for n, _, _ in blocks(page.read_text("utf-8"))]
        if names:
            out[page.relative_to(root).as_posix()] = names
    return out


#: A number with a unit or a decimal point, outside code: what ``--unmarked`` lists.
_NUMBER = re.compile(r"(?<![\w.`])[−+-]?\d[\d,.]*(?:e[−-]?\d+)?(?:\s?(?:%|°|s|ms|µs|Hz|kHz|kN|N|"
                     r"mm|m|GB|MB|min|t|µm|kg|rad/s|×|dB))?(?![\w`])")


#: ``<!-- dated record: DATE, COMMIT -->``: a page kept as the record of a past measurement
#: (its date and commit), whose numbers are not claims about today's code.
DATED = re.compile(r"<!-- dated record: (?P<date>\d{4}-\d\d-\d\d), (?P<commit>[0-9a-f]{7,40}) -->")


def unmarked(text: str) -> list[tuple[int, str]]:
    """``(line, number)`` of the numbers a page states outside its blocks, code spans and
    fences: the candidates to wire (a measured number) or to leave (an input). Bare
    small integers (counts of things, section numbers) are left out."""
    text = BLOCK.sub(lambda m: " " * len(m.group(0).split("\n")[0])
                     + "\n" * m.group(0).count("\n"), text)
    text = re.sub(r"```.*?```", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S)
    out = []
    for i, line in enumerate(text.splitlines(), 1):
        line = re.sub(r"`[^`]*`|\]\([^)]*\)|<[^>]*>", " ", line)
        for m in _NUMBER.finditer(line):
            token = m.group(0)
            if re.fullmatch(r"\d{1,2}\.?", token):
                continue
            out.append((i, token))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true",
                    help="fill every block from its source (default: check only)")
    ap.add_argument("--unmarked", nargs="*", metavar="PAGE",
                    help="list the numbers outside blocks of these pages (default every "
                    "page): the candidates to wire")
    args = ap.parse_args(argv)
    if args.unmarked is not None:
        for page in [ROOT / p for p in args.unmarked] or pages():
            text, rel = page.read_text("utf-8"), page.relative_to(ROOT).as_posix()
            if (m := DATED.search(text)) is not None:
                print(f"{rel}: a dated record ({m['date']}, {m['commit']}): its numbers "
                      "are that day's, left out", file=sys.stderr)
                continue
            for line, token in unmarked(text):
                print(f"{rel}:{line}: {token}")
        return 0
    sources = Sources()
    stale: list[Stale] = []
    for page in pages():
        text = page.read_text("utf-8")
        rel = page.relative_to(ROOT).as_posix()
        if args.write:
            new = fill_text(text, sources)
            if new != text:
                page.write_text(new, "utf-8")
                print(f"{rel}: filled", file=sys.stderr)
        else:
            stale += check_text(text, rel, sources)
    for s in stale:
        print(s)
    counts = used()
    print(f"{sum(map(len, counts.values()))} numbers in {len(counts)} pages "
          f"({'stale: ' + str(len(stale)) if stale else 'all from their sources'})",
          file=sys.stderr)
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
