"""Oracles of ``winder.fit_modes``: the eigenvalues' exact derivatives against central
differences of ``winder modes``' own modes, and modes of a known scene fitted back."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import MODELS

import winder
from winder.analysis.fit_model import scene_with
from winder.analysis.fit_modes import ModeModel, read_modes

RADII = [0.1, 0.3, 0.6]


@pytest.fixture(scope="module")
def paper() -> winder.Scene:
    return winder.load_scene(MODELS / "paper_winding.toml")


def _measured(scene: winder.Scene) -> dict[str, list]:
    """The roll's bounce mode at each radius, as ``winder modes`` (``modes_at``) gives it."""
    rows: dict[str, list] = {"radius": [], "mode": [], "frequency": [], "damping": []}
    for r in RADII:
        m = next(m for m in winder.modes_at(scene, r) if m.coordinate == "roll.z")
        for k, v in zip(rows, (r, m.coordinate, m.frequency, m.damping_ratio), strict=True):
            rows[k].append(v)
    return rows


def test_derivatives_match_central_differences(paper):
    """∂f/∂θ and ∂ζ/∂θ of the bounce mode (through the operating point's implicit
    function and the Jacobian's directional derivative) against central differences of
    the frequencies and dampings (measured: 6e-9 relative)."""
    keys = ["contact.stiffness", "contact.damping", "paper.density"]
    mm = ModeModel(paper, keys, np.array(RADII), ["roll.z"] * 3, None)
    th = np.array([2e7, 2e4, 800.0])
    f, z, df, dz = mm.evaluate(th)
    ref = _measured(paper)
    np.testing.assert_allclose(f, ref["frequency"], rtol=1e-12)  # winder modes' own
    np.testing.assert_allclose(z, ref["damping"], rtol=1e-12)
    for j in range(len(keys)):
        h = 1e-4 * th[j]
        a, b = th.copy(), th.copy()
        a[j] += h
        b[j] -= h
        fa, za, _, _ = mm.evaluate(a)
        fb, zb, _, _ = mm.evaluate(b)
        np.testing.assert_allclose((fa - fb) / (2 * h), df[:, j], rtol=1e-7)
        np.testing.assert_allclose((za - zb) / (2 * h), dz[:, j], rtol=1e-7, atol=1e-20)


def test_modes_fitted_back(paper, tmp_path):
    """Frequencies and dampings of the true scene's bounce mode at three radii; the fit
    from a nip 40 % stiff and half as damped recovers both to 1e-6."""
    rows = _measured(paper)
    path = tmp_path / "modes.csv"
    lines = ["radius [m],mode,frequency [Hz],damping"]
    lines += [f"{r!r},{m},{f!r},{d!r}" for r, m, f, d in zip(*rows.values(), strict=True)]
    path.write_text("\n".join(lines) + "\n")
    assert read_modes(path)["frequency"].tolist() == rows["frequency"]
    guess = scene_with(paper, {"contact.stiffness": 2.8e7, "contact.damping": 1e4})
    res = winder.fit_modes(guess, path, ["contact.stiffness", "contact.damping"])
    assert res.converged
    assert res["contact.stiffness"] == pytest.approx(2e7, rel=1e-6)
    assert res["contact.damping"] == pytest.approx(2e4, rel=1e-6)
    assert res.abscissa == ("radius", "m") and res.channels == ("frequency", "damping")


def test_unknown_mode_is_named(paper):
    data = {"radius": [0.3], "mode": ["rider.z"], "frequency": [30.0]}
    with pytest.raises(winder.ArgumentError,
                       match="mode 'rider.z' is not a mode of this scene at radius 0.3 m; "
                             "valid: roll.z, nip.friction"):
        winder.fit_modes(paper, data, ["contact.stiffness"])
