"""The README's quoted numbers of the two-drum winder, the winder line and the flexible
two-drum winder, computed from the demo's results (``make readme-numbers``): prints a table
to paste.

Reads ``out/two_drum_winder.npz``, ``out/winder_line.npz`` and
``out/two_drum_winder_flexible.npz`` (written by ``make demo``)
where they exist and were run from the current scene files at the default settings;
otherwise runs the scene (minutes on a loaded machine) and writes the result there. The
three rider-load variants the README compares are kept the same way as
``out/two_drum_winder_variant<i>.npz``.

With ``--json docs/numbers.json`` it also writes the numbers the pages quote (raw, in SI
units), from which ``benchmarks/doc_numbers.py`` fills the pages' blocks; the calibration
example (``examples/calibrate_nip.py``'s fit and resonance maps) is run for it.

The bounce of a body is its height less its centred moving mean over 0.5 s, taken only
where the whole window lies inside the run (no edge artefact: the old measure, less the
interpolated means of consecutive windows, held the last mean over the last half window
and spiked there wherever the body moves, as every bounce panel did).

Run:  python benchmarks/readme_numbers.py [--out out] [--rerun] [--json docs/numbers.json]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

import winder
from winder.plots.figures import normal_force_envelope, window_mean

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"


#: The rider-load variants of the two-drum winder the README compares: name -> the
#: rider's line-load schedule [[set radius m, N/m], ...].
VARIANTS = {"load held at 3 kN/m": [[0.05, 3000.0]],
            "light rider, 0.3 kN/m throughout": [[0.05, 300.0]],
            "no applied load": [[0.05, 0.0]]}


def result_of(model: str, out: Path, *, rerun: bool = False, load: list | None = None,
              tag: str = "") -> winder.Result:
    """The default run of ``models/<model>.toml`` (with the rider's ``load`` schedule
    replaced, if given, saved as ``<model>_<tag>.npz``): ``out/<model>.npz`` if it holds
    that run (same scene, default method and tolerances, whole duration), else a new run,
    saved there."""
    scene = winder.load_scene(MODELS / f"{model}.toml")
    if load is not None:
        scene = scene.replace(rider={scene.riders[0].name: {"load": load}})
    path = out / (f"{model}_{tag}.npz" if tag else f"{model}.npz")
    if path.is_file() and not rerun:
        res = winder.load_result(path)
        same = (json.dumps(res.meta.get("scene_dict"), sort_keys=True)
                == json.dumps(scene.to_dict(), sort_keys=True)
                and res.meta.get("rtol") == scene.solver.rtol
                and abs(float(res.t[-1]) - scene.scene.duration) < 1e-9)
        if same:
            print(f"{path}: reused", file=sys.stderr)
            return res
        print(f"{path}: from another scene or settings; running again", file=sys.stderr)
    print(f"running {path.stem} (a few minutes) ...", file=sys.stderr, flush=True)
    res = winder.simulate(scene, progress=sys.stderr.isatty())
    out.mkdir(parents=True, exist_ok=True)
    res.to_npz(path)
    return res


def centred_mean(t: np.ndarray, y: np.ndarray, window: float = 0.5
                  ) -> tuple[np.ndarray, np.ndarray]:
    """``(index, mean)``: the mean of ``y`` over the ``w`` samples centred on each sample
    (``w`` odd, about ``window`` [s]), only at the samples whose whole window lies in the
    run (the first and last ``w // 2`` have none)."""
    dt = float(np.median(np.diff(t)))
    w = max(1, int(round(window / dt)) // 2 * 2 + 1)
    if len(y) < w:
        return np.arange(0), np.zeros(0)
    c = np.concatenate([[0.0], np.cumsum(y, dtype=float)])
    mean = (c[w:] - c[:-w]) / w
    return np.arange(w // 2, len(y) - w // 2), mean


def bounce_range(t: np.ndarray, z: np.ndarray, band: slice, window: float = 0.5
                 ) -> tuple[float, float]:
    """``(least, largest)`` of ``z`` less its centred ``window`` mean [m] over the samples
    of ``band`` that have a whole window (:func:`centred_mean`)."""
    idx, mean = centred_mean(t, z, window)
    keep = (idx >= band.start) & (idx < band.stop)
    d = z[idx[keep]] - mean[keep]
    return (float(np.min(d)), float(np.max(d))) if d.size else (0.0, 0.0)


def two_drum_numbers(res: winder.Result) -> list[tuple[str, str]]:
    """The two-drum winder section: nip forces, the bounce band, its open shares, peaks,
    bounces."""
    t = res.t
    nips = ("front_nip", "rear_nip", "rider_nip")
    f = {n: res[f"{n}_normal_force"] for n in nips}
    r = res["set_radius"]
    rows: list[tuple[str, str]] = []
    rows.append(("nip forces at rest (t = 0) [kN]",
                 ", ".join(f"{n} {f[n][0] / 1e3:.1f}" for n in nips)))
    opened = {n: np.flatnonzero(f[n] <= 0.0) for n in nips}
    firsts = {n: int(o[0]) for n, o in opened.items() if len(o)}
    if not firsts:
        rows.append(("bounce band", "no nip opens"))
        return rows
    i0 = min(firsts.values())
    i1 = max(int(o[-1]) for o in opened.values() if len(o))
    band = slice(i0, i1 + 1)
    rows.append(("bounce band: first to last opening of any nip",
                 f"t = {t[i0]:.1f}–{t[i1]:.1f} s, r = {r[i0]:.3f}–{r[i1]:.3f} m"))
    rows.append(("first opening per nip (set radius) [m]",
                 ", ".join(f"{n} {r[i]:.3f}" for n, i in sorted(firsts.items(),
                                                                  key=lambda kv: kv[1]))))
    rows.append(("share of samples open, inside the band [%]",
                 ", ".join(f"{n} {100 * np.mean(f[n][band] <= 0):.1f}" for n in nips)))
    rows.append(("share of samples open, whole run [%]",
                 ", ".join(f"{n} {100 * np.mean(f[n] <= 0):.1f}" for n in nips)))
    rows.append(("force peak inside the band [kN]",
                 ", ".join(f"{n} {np.max(f[n][band]) / 1e3:.1f}" for n in nips)))
    tm = window_mean(t, t)[0]
    winding = (tm > 65.0) & ((tm < t[i0]) | (tm > t[i1]))  # after the ramp, off the band
    rows.append(("nip force while winding outside the band (t > 65 s), 0.5 s means [kN]",
                 ", ".join(f"{n} {np.min(window_mean(t, f[n])[1][winding]) / 1e3:.1f}–"
                           f"{np.max(window_mean(t, f[n])[1][winding]) / 1e3:.1f}"
                           for n in nips)))
    for body in ("rider", "set"):
        lo, hi = bounce_range(t, res[f"{body}_z"], band)
        rows.append((f"{body} bounce in the band, z less its centred 0.5 s mean [mm]",
                     f"+{1e3 * hi:.2f} / {1e3 * lo:.2f}"))
    x = res["set_x"]
    rows.append(("set x in the band, relative to its value at the band's start [mm]",
                 f"{1e3 * (np.min(x[band]) - x[i0]):+.2f} to "
                 f"{1e3 * (np.max(x[band]) - x[i0]):+.2f} (front drum at x < 0)"))
    after = t > t[i1]
    if np.any(after):
        half = []
        for n in nips:
            _, lo, hi, _ = normal_force_envelope(res, force=f"{n}_normal_force",
                                                 radius="set_radius")
            tw = window_mean(t, t)[0]
            k = tw[: len(hi)] > t[i1]
            half.append(np.max((hi - lo)[k]) / 2 if np.any(k) else 0.0)
        rows.append(("above the band: largest half peak-to-peak force over 0.5 s [kN]",
                     ", ".join(f"{n} {h / 1e3:.1f}" for n, h in zip(nips, half, strict=True))))
    return rows


NIPS = ("front_nip", "rear_nip", "rider_nip")


def two_drum_values(res: winder.Result) -> dict:
    """The two-drum winder's numbers the pages quote, raw and in SI units: the nips'
    forces at rest, the bounce band (first to last opening of any nip), the shares open and
    the peaks inside it, the rider's and the set's bounce there, the set's sideways travel,
    the half peak-to-peak force above it, the final radius and the run's cost."""
    t, r = res.t, res["set_radius"]
    f = {n: res[f"{n}_normal_force"] for n in NIPS}
    out: dict = {"final_radius": float(r[-1]),
                 "rest": {n: float(f[n][0]) for n in NIPS},
                 "balance_residual": float(res.meta["static_residual"]),
                 "balance_scale": float(res.meta["static_scale"]),
                 "run": {k: res.meta[k] for k in ("method", "rtol", "wall_time",
                                                  "rhs_evaluations", "events")}}
    opened = np.flatnonzero(np.any(np.array(list(f.values())) <= 0.0, axis=0))
    if not len(opened):
        return out
    i0, i1 = int(opened[0]), int(opened[-1])
    band = slice(i0, i1 + 1)
    out["band"] = {"t": [float(t[i0]), float(t[i1])], "r": [float(r[i0]), float(r[i1])]}
    out["open_share_band"] = {n: float(np.mean(f[n][band] <= 0)) for n in NIPS}
    out["open_share_run"] = {n: float(np.mean(f[n] <= 0)) for n in NIPS}
    out["peak_band"] = {n: float(np.max(f[n][band])) for n in NIPS}
    out["bounce_band"] = {b: list(bounce_range(t, res[f"{b}_z"], band))
                          for b in ("rider", "set")}
    x = res["set_x"]
    out["set_x_band"] = [float(np.min(x[band]) - x[i0]), float(np.max(x[band]) - x[i0])]
    tw = window_mean(t, t)[0]
    half = {}
    for n in NIPS:
        _, lo, hi, _ = normal_force_envelope(res, force=f"{n}_normal_force",
                                             radius="set_radius")
        k = tw[: len(hi)] > t[i1]
        half[n] = float(np.max((hi - lo)[k]) / 2) if np.any(k) else 0.0
    out["half_p2p_above_band"] = half
    return out


def flex_rotary_values() -> dict:
    """docs/model.md §9's table: the first two bending frequencies [Hz] of the 6 m drum of
    ``tests/parts/test_flex_rotary.py`` (its scene and its eigenvalues, written once there)
    at N = 8 and 16 segments, with the sections' rotary inertia on and off, on stiff
    bearings (1e15 N/m: simply supported) and on 1e9 N/m."""
    import importlib.util

    from winder.solve.system import MachineSystem

    spec = importlib.util.spec_from_file_location(
        "test_flex_rotary", ROOT / "tests" / "parts" / "test_flex_rotary.py")
    ft = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ft)
    out: dict = {}
    for label, kb in (("stiff", 1e15), ("1e9", 1e9)):
        for key, rotary in (("on", True), ("off", False)):
            for n in (8, 16):
                w = ft.frequencies(MachineSystem(ft.scene(n, bearings=kb, rotary=rotary),
                                                 backend="pinocchio"), n)[:2]
                out.setdefault(label, {}).setdefault(key, {})[str(n)] = \
                    [float(x / (2 * np.pi)) for x in w]
    return out


def tension_loop_values() -> dict:
    """The unwind tension loop of ``examples/tension_loop_design.py`` (its scene, plant
    and tuning rule, imported from it): per parent radius the phase margin [°] and its
    crossover [rad/s], the gain margin (None: infinite), the tension loop's three
    closed-loop poles [rad/s] and their largest relative distance from the linearised
    tension-controlled machine's; the poles' spread over the radii [rad/s]; the +20 N
    set-point step against the nonlinear line (largest difference and the response's
    peak [N])."""
    import importlib.util

    import control as ct

    spec = importlib.util.spec_from_file_location(
        "tension_loop_design", ROOT / "examples" / "tension_loop_design.py")
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    scene = winder.load_scene(ex.SCENE)
    span = scene.web.span
    wc = next(r for r in scene.rolls if r.name == span.source).drive.bandwidth
    out: dict = {"bandwidth": wc, "parents": {}}
    for label, r in ex.PARENTS.items():
        plant = winder.linearise(ex.line(r, torque=True), ex.SET_RADIUS,
                                 inputs=["parent_torque"],
                                 outputs=["span_tension", "parent_inertia"])
        K, J = ex.controller(plant, r, wc, span.EA, span.length)
        loop = -ct.tf(plant[0, 0]) * K
        gm, pm, _, wp = ct.margin(loop)
        closed = np.sort_complex(ct.feedback(loop, 1).poles())
        slow = closed[np.abs(closed) < 4 * wc]
        inside = np.linalg.eigvals(np.asarray(winder.linearise(
            ex.line(r, torque=False), ex.SET_RADIUS, inputs=["parent_tension_setpoint"],
            outputs=["span_tension"]).A))
        out["parents"][label] = {
            "radius": r, "inertia": float(J), "phase_margin": float(pm),
            "crossover": float(wp), "gain_margin": float(gm) if np.isfinite(gm) else None,
            "poles": [[float(p.real), float(p.imag)] for p in slow],
            "machine_agree": float(max(np.min(np.abs(inside - p)) / abs(p) for p in slow))}
    poles = {k: np.array([complex(*p) for p in v["poles"]])
             for k, v in out["parents"].items()}
    out["spread"] = float(max(np.max(np.abs(poles[k] - poles["full"])) for k in poles))
    err, peak = ex.closed_loop_check(wc, False)
    out["step_error"], out["step_peak"] = err, peak
    return out


def calibration_values(out: Path) -> dict:
    """The calibration example (``examples/calibrate_nip.py``): its fit of the nip from
    the guess, and the fitted machine's bounce frequency against the true one (largest
    relative difference above r = 0.3 m and 0.5 m; both at the core)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("calibrate_nip",
                                                  ROOT / "examples" / "calibrate_nip.py")
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    from winder.analysis.fit_model import scene_with

    true = winder.load_scene(ex.SCENE)
    print("running the calibration example's fit (about a minute) ...", file=sys.stderr)
    res = winder.fit(scene_with(true, ex.GUESS), ex.record(true), list(ex.TRUTH))
    path = out / "calibrate_nip.json"
    out.mkdir(parents=True, exist_ok=True)
    res.to_json(path)
    values = json.loads(path.read_text("utf-8"))
    fitted, mt = winder.mode_map(res.fitted_scene(), n=40), winder.mode_map(true, n=40)
    rel = np.abs(fitted.bounce_frequency / mt.bounce_frequency - 1)
    values["modes"] = {"above_0.3": float(np.max(rel[mt.radius >= 0.3])),
                       "above_0.5": float(np.max(rel[mt.radius >= 0.5])),
                       "core_radius": float(mt.radius[0]),
                       "true_core": float(mt.bounce_frequency[0]),
                       "fitted_core": float(fitted.bounce_frequency[0])}
    return {k: values[k] for k in ("parameters", "channels", "iterations", "evaluations",
                                   "wall_time", "converged", "modes")}


def variant_numbers(res: winder.Result) -> str:
    """Whether and where a variant's nips open: first opening radius, shares open (whole
    run and inside its band), the peak force."""
    nips = ("front_nip", "rear_nip", "rider_nip")
    f = {n: res[f"{n}_normal_force"] for n in nips}
    peak = max(float(np.max(v)) for v in f.values())
    tpeak = res.t[int(np.argmax(np.max(np.array(list(f.values())), axis=0)))]
    opened = np.flatnonzero(np.any(np.array(list(f.values())) <= 0.0, axis=0))
    if not len(opened):
        return f"no nip opens; peak force {peak / 1e3:.1f} kN at t = {tpeak:.1f} s"
    i0, i1 = int(opened[0]), int(opened[-1])
    r = res["set_radius"]
    band = slice(i0, i1 + 1)
    return (f"band r = {r[i0]:.3f}–{r[i1]:.3f} m; open, whole run: "
            + ", ".join(f"{n} {100 * np.mean(f[n] <= 0):.1f} %" for n in nips)
            + "; inside the band: "
            + ", ".join(f"{n} {100 * np.mean(f[n][band] <= 0):.1f} %" for n in nips)
            + f"; peak force {peak / 1e3:.1f} kN")


def line_numbers(res: winder.Result, ramp_end: float) -> list[tuple[str, str]]:
    """The winder line section: the tension error at the ramp's start and end, its RMS,
    inside the bounce band, and the unwind torque."""
    t, e = res.t, res["tension_error"]
    rows: list[tuple[str, str]] = []
    start = t < 5.0
    i = int(np.argmax(np.abs(np.where(start, e, 0.0))))
    rows.append(("tension error peak at the ramp's start (t < 5 s) [N]",
                 f"{e[i]:+.3f} at t = {t[i]:.2f} s"))
    end = np.abs(t - ramp_end) < 5.0
    j = int(np.argmax(np.abs(np.where(end, e, 0.0))))
    rows.append((f"tension error peak at the ramp's end ({ramp_end:.2f} ± 5 s) [N]",
                 f"{e[j]:+.3f} at t = {t[j]:.2f} s"))
    rows.append(("tension error RMS over the run [N]", f"{np.sqrt(np.mean(e ** 2)):.3g}"))
    f = [res[f"{n}_normal_force"] for n in ("front_nip", "rear_nip", "rider_nip")]
    open_any = np.flatnonzero(np.any(np.array(f) <= 0.0, axis=0))
    if len(open_any):
        band = slice(int(open_any[0]), int(open_any[-1]) + 1)
        rows.append((f"largest |tension error| in the bounce band (t = {t[open_any[0]]:.1f}–"
                     f"{t[open_any[-1]]:.1f} s) [N]", f"{np.max(np.abs(e[band])):.2g}"))
    tau = res["parent_torque"] / 1e3
    late = t > ramp_end + 5.0
    rows.append(("unwind torque: peak during the ramp; range after it [kN m]",
                 f"{np.max(tau[t <= ramp_end]):+.2f}; {np.min(tau[late]):+.2f} to "
                 f"{np.max(tau[late]):+.2f}"))
    return rows


def flex_numbers(res: winder.Result, mm) -> list[tuple[str, str]]:  # noqa: ANN001
    """The flexible two-drum winder (issue #25): per nip the line load along the width at
    the run's end (least, largest, mean; the slices' ``F_i N/L``, ``L = ΣF_i / mean``),
    where it is least uniform, and where a harmonic of the roll's rotation meets an order-1
    bending mode of the resonance map ``mm`` (:class:`winder.ModeMap`)."""
    rows: list[tuple[str, str]] = []
    t_end = float(res.t[-1])
    spread = {}
    for nip in ("front_nip", "rear_nip", "rider_nip"):
        f = []
        while f"{nip}_s{len(f)}_normal_force" in res:
            f.append(float(res[f"{nip}_s{len(f)}_normal_force"][-1]))
        f = np.array(f)
        mean = float(res[f"{nip}_line_load_mean"][-1])
        n, length = len(f), float(f.sum()) / mean
        q = f * n / length
        y = (np.arange(n) + 0.5) * length / n
        lo, hi = int(np.argmin(q)), int(np.argmax(q))
        spread[nip] = (q[hi] - q[lo]) / mean
        rows.append((f"{nip} line load at t = {t_end:g} s: least, largest, mean [kN/m]",
                     f"{q[lo] / 1e3:.3f} at y = {y[lo]:.2f} m, {q[hi] / 1e3:.3f} at "
                     f"y = {y[hi]:.2f} m, {mean / 1e3:.3f}; (max − min)/mean "
                     f"{100 * spread[nip]:.2f} %"))
    worst = max(spread, key=spread.get)
    rows.append(("least uniform line load", f"{worst} ({100 * spread[worst]:.2f} %)"))
    first = [c for c in mm.shown() if c.endswith(("bend.x1", "bend.z1"))]
    found = [(c, h, rc) for c, h, rc in mm.crossings(first) if h.endswith("x")]
    rows.append((f"harmonics meeting an order-1 bending mode at {mm.web_speed:g} m/s [m]",
                 "; ".join(f"{h} meets {c} at r = {rc:.3f}" for c, h, rc in
                           sorted(found, key=lambda x: x[2])) or "none"))
    return rows


def pages_numbers(out: Path, *, rerun: bool = False, two: winder.Result | None = None
                  ) -> dict:
    """The numbers the pages quote (docs/numbers.json): the paper's cycle, the two-drum
    winder, the calibration example, the flexible drum's rotary inertia."""
    paper = result_of("paper_winding", out, rerun=rerun)
    two = two if two is not None else result_of("two_drum_winder", out, rerun=rerun)
    return {"generated_by": "benchmarks/readme_numbers.py --json",
            "paper_winding": {"final_radius": float(paper["radius"][-1])},
            "two_drum_winder": two_drum_values(two),
            "calibration": calibration_values(out),
            "flex_rotary": flex_rotary_values(),
            "tension_loop": tension_loop_values()}


def write_json(numbers: dict, path: Path) -> None:
    """``numbers`` to ``path`` atomically (sorted keys, one space of indent)."""
    text = json.dumps(numbers, indent=1, sort_keys=True, ensure_ascii=False) + "\n"
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(text, "utf-8")
    tmp.replace(path)
    print(f"{path}: written", file=sys.stderr)


#: Numbers that are round-off (a balance's residual [N], the poles' spread over the radii
#: [rad/s]): compared absolutely, to these bounds.
ROUND_OFF = {"balance_residual": 1e-6, "spread": 1e-9}


def differences(old, new, *, rtol: float = 1e-3, where: str = "") -> list[str]:  # noqa: ANN001
    """Where two sets of numbers (docs/numbers.json's) differ: every number within ``rtol``
    relative (or 1e-12 absolute), except wall times (not compared), event counts (within
    2 %) and round-off (:data:`ROUND_OFF`); strings and flags equal; the same keys."""
    if isinstance(old, dict) and isinstance(new, dict):
        if set(old) != set(new):
            return [f"{where}: keys {sorted(set(old) ^ set(new))} in one only"]
        return [d for k in old for d in differences(old[k], new[k], rtol=rtol,
                                                    where=f"{where}.{k}")]
    if isinstance(old, list) and isinstance(new, list) and len(old) == len(new):
        return [d for i, (a, b) in enumerate(zip(old, new, strict=True))
                for d in differences(a, b, rtol=rtol, where=f"{where}[{i}]")]
    if isinstance(old, bool) or not isinstance(old, int | float) \
            or not isinstance(new, int | float):
        return [] if old == new else [f"{where}: {old!r} against {new!r}"]
    if where.endswith(("wall_time", "cpu_time", "load_average", "generated_by")):
        return []
    for key, atol in ROUND_OFF.items():  # numbers at round-off: absolute
        if where.endswith(key):
            return [] if abs(new - old) <= atol else [f"{where}: {old!r} against {new!r}"]
    tol = 0.02 if where.endswith(("events", "evaluations", "rhs_evaluations")) else rtol
    if abs(new - old) <= max(tol * abs(old), 1e-12):
        return []
    return [f"{where}: {old!r} against {new!r}"]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=ROOT / "out",
                    help="the demo's output folder (default out/)")
    ap.add_argument("--rerun", action="store_true", help="run the scenes even if out/ has them")
    ap.add_argument("--json", type=Path, default=None,
                    help="also write the pages' numbers here (docs/numbers.json)")
    args = ap.parse_args(argv)
    two = result_of("two_drum_winder", args.out, rerun=args.rerun)
    line = result_of("winder_line", args.out, rerun=args.rerun)
    drive = winder.load_scene(MODELS / "two_drum_winder.toml").drums[0].drive
    ramp_end = drive.web_speed / drive.web_acceleration
    variants = [(name, variant_numbers(result_of("two_drum_winder", args.out,
                                                 rerun=args.rerun, load=load,
                                                 tag=f"variant{i}")))
                for i, (name, load) in enumerate(VARIANTS.items())]
    runs = [(f"{name}: run", f"{r.meta['method']} at rtol {r.meta['rtol']:g}: "
             f"{r.meta['wall_time']:.1f} s wall, {r.meta['rhs_evaluations'] / 1e6:.1f} M "
             f"evaluations, {r.meta['events']:,} located events")
            for name, r in (("two_drum_winder", two), ("winder_line", line))]
    flex = result_of("two_drum_winder_flexible", args.out, rerun=args.rerun)
    flex_map = winder.mode_map(winder.load_scene(MODELS / "two_drum_winder_flexible.toml"),
                               radius_max=0.6, n=40)  # as make demo: the cycle's radii
    if args.json is not None:
        write_json(pages_numbers(args.out, rerun=args.rerun, two=two), args.json)
    print("| quantity | value |\n|---|---|")
    for title, rows in (("two_drum_winder", two_drum_numbers(two)),
                        ("two_drum_winder, rider load", variants),
                        ("winder_line", line_numbers(line, ramp_end)),
                        ("two_drum_winder_flexible", flex_numbers(flex, flex_map)),
                        ("integration", runs)):
        for name, value in rows:
            print(f"| {title}: {name} | {value} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
