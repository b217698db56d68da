"""Purpose: calibrate a winder's nip to a mill record, and see what it does to the resonance map.

The single-drum winder (``models/paper_winding.toml``) is the mill's machine; its nip
stiffness and damping (2e7 N/m, 2e4 N·s/m) are what the mill does not know. The record is
synthetic: the first 7 s of its run-up (``winder.simulate``, the solver's own path),
sampled every 2 ms, the roll's vertical position ``z`` (a displacement sensor, noise
σ = 1 µm) and the nip load ``normal_force`` (a load cell, σ = 2 N). The designer's scene
guesses the nip 50 % stiff and half as damped; :func:`winder.fit` brings the guesses to
the record on the exact sensitivities of both channels (noise levels estimated), and the
fitted machine's resonance map (``winder.mode_map``) is drawn against the true one's and
the guess's: the bounce frequency the calibration moves, the band where 1× crosses it.

Writes ``calibrate_nip_fit.png`` (measured against fitted channels, residuals),
``calibrate_nip_modes.png`` (the resonance maps), ``calibrate_nip.json`` (the fit) and the
record ``calibrate_nip_record.csv`` (units in its header, for ``winder fit --data``) to
``--out``.

    python examples/calibrate_nip.py [--out out]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "models" / "paper_winding.toml"
TRUTH = {"contact.stiffness": 2e7, "contact.damping": 2e4}
GUESS = {"contact.stiffness": 3e7, "contact.damping": 1e4}
NOISE = {"z": 1e-6, "normal_force": 2.0}


def record(scene, seed: int = 35) -> dict[str, np.ndarray]:
    """The mill's record: 7 s of the run-up every 2 ms with sensor noise (units in the
    column names, as a CSV header carries them)."""
    import winder

    run = winder.simulate(scene, t_end=7.0, output_step=0.002, rtol=1e-10, atol=1e-12,
                          method="DOP853")
    rng = np.random.default_rng(seed)
    keep = run.t > 0
    out = {"t": run.t[keep]}
    for name, sigma in NOISE.items():
        out[f"{name} [{run.units[name]}]"] = run[name][keep] + rng.normal(0, sigma,
                                                                         keep.sum())
    return out


def main() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import winder
    from winder.analysis.fit_model import scene_with

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out", type=Path)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if sys.stderr.isatty():  # what the next tens of seconds are
        print("calibrate_nip: simulating a record of the paper scene, then fitting the nip's "
              "stiffness and damping to it ...", file=sys.stderr, flush=True)
    true = winder.load_scene(SCENE)
    data = record(true)
    header = ",".join(data)
    np.savetxt(args.out / "calibrate_nip_record.csv", np.column_stack(list(data.values())),
               delimiter=",", header=header, comments="", fmt="%.17g")
    guess = scene_with(true, GUESS)
    start = time.perf_counter()
    res = winder.fit(guess, data, list(TRUTH))
    print(f"fit of the nip to {len(res.t)} samples of {', '.join(res.channels)} "
          f"({time.perf_counter() - start:.1f} s):")
    print(res.table())
    for k, v in TRUTH.items():
        j = res.keys.index(k)
        lo, hi = res.ci95[j]
        print(f"  {k}: truth {v:.6g}, fitted {res[k]:.6g} ± {res.std[j]:.2g}, 95 % "
              f"[{lo:.6g}, {hi:.6g}] {'holds' if lo <= v <= hi else 'misses'} the truth")
    res.plot(args.out / "calibrate_nip_fit.png")
    res.to_json(args.out / "calibrate_nip.json")
    fitted = res.fitted_scene()
    maps = {name: winder.mode_map(s, n=40) for name, s in
            (("true", true), ("fitted", fitted), ("guess", guess))}
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for (name, mm), style in zip(maps.items(), ("-", "--", ":"), strict=True):
        ax.plot(mm.radius, mm.bounce_frequency, style, lw=1.5, label=f"bounce, {name} nip")
        print(f"  bounce frequency at r = {mm.radius[0]:.3g} / {mm.radius[-1]:.3g} m "
              f"({name}): {mm.bounce_frequency[0]:.4g} / {mm.bounce_frequency[-1]:.4g} Hz")
    mm = maps["true"]
    ax.plot(mm.radius, mm.rotation_1x, color="0.4", lw=1, label="roll rotation 1×")
    ax.set_xlabel("wound roll radius [m]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title("Resonance map: the calibrated nip against the true one and the guess")
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.out / "calibrate_nip_modes.png", dpi=110)
    err = np.max(np.abs(maps["fitted"].bounce_frequency / maps["true"].bounce_frequency - 1))
    print(f"  fitted bounce frequency against the true one: largest relative error "
          f"{err:.2e} over the radii (the guess's: "
          f"{np.max(np.abs(maps['guess'].bounce_frequency / mm.bounce_frequency - 1)):.2e})")
    print(f"written to {args.out}/: calibrate_nip_fit.png, calibrate_nip_modes.png, "
          "calibrate_nip.json, calibrate_nip_record.csv")


if __name__ == "__main__":
    main()
