"""The meshcat viewer: scene graph from Pinocchio kinematics, HTML animation in Chromium."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from winder.viewer import COLOURS, WinderGraph, export_html, find_chromium, screenshot

import winder


def _short_result(scene: winder.Scene) -> winder.Result:
    """A synthetic but consistent result: the roll grows from core to 0.84 m and rises."""
    t = np.linspace(0.0, 700.0, 141)
    r = np.sqrt(0.075**2 + (0.84**2 - 0.075**2) * t / 700.0)
    ch = {name: np.zeros_like(t) for name in winder.CHANNELS + winder.EXTRA_CHANNELS}
    ch.update(t=t, radius=r, z=0.5 + r, roll_speed=20.0 / r, drum_speed=np.full_like(t, 40.0))
    ch["roll_angle"] = np.concatenate([[0], np.cumsum(np.diff(t) * ch["roll_speed"][1:])])
    ch["drum_angle"] = 40.0 * t
    return winder.Result(ch, {"scene": scene.name, "scene_dict": scene.to_dict()})


def test_placements_come_from_pinocchio(paper_scene) -> None:
    graph = WinderGraph(paper_scene)
    Td, Tr = graph.poses(0.3, 1.2, 0.7)
    np.testing.assert_allclose(Tr[:3, 3], [0.0, 0.0, 1.2], atol=1e-15)
    # roll about −y by φ: x-axis → (cos φ, 0, sin φ) (spec §1: CoM at (e cos φ, ·, z + e sin φ))
    np.testing.assert_allclose(Tr[:3, 0], [np.cos(0.7), 0.0, np.sin(0.7)], atol=1e-15)
    # drum about +y by θ: top point moves to +x for θ > 0
    np.testing.assert_allclose(Td[:3, :3] @ [0, 0, 1], [np.sin(0.3), 0, np.cos(0.3)], atol=1e-15)


def test_html_is_standalone(tmp_path: Path, paper_scene) -> None:
    html = export_html(WinderGraph(paper_scene), _short_result(paper_scene),
                       tmp_path / "a.html", playback=4.0, fps=10)
    text = html.read_text()
    assert "<script" in text and "three" in text.lower()
    assert "src=\"http" not in text and "href=\"http" not in text  # nothing fetched


def _colour_mask(img: np.ndarray, hex_rgb: int, tol: int = 40) -> np.ndarray:
    rgb = np.array([(hex_rgb >> 16) & 255, (hex_rgb >> 8) & 255, hex_rgb & 255])
    return np.all(np.abs(img[..., :3].astype(int) - rgb) < tol, axis=-1)


@pytest.mark.browser
def test_animation_renders_in_headless_chromium(tmp_path: Path, paper_scene) -> None:
    if find_chromium() is None:
        pytest.skip("Chromium is not installed and could not be installed (make chromium "
                    "needs root and apt-get)")
    import matplotlib.image as mpimg

    html = export_html(WinderGraph(paper_scene), _short_result(paper_scene),
                       tmp_path / "anim.html", playback=20.0, fps=10)
    early = mpimg.imread(screenshot(html, tmp_path / "early.png", wait_ms=1500))
    late = mpimg.imread(screenshot(html, tmp_path / "late.png", wait_ms=15000))
    early, late = (np.round(255 * im).astype(np.uint8) for im in (early, late))
    h, w = early.shape[:2]
    for img in (early, late):
        drum = _colour_mask(img, COLOURS["drum"])
        assert drum.sum() > 2000, "drum not drawn"
        ys, xs = np.nonzero(drum)
        assert abs(xs.mean() - w / 2) < 0.1 * w  # the drum is centred
    paper_e, paper_l = (_colour_mask(im, COLOURS["paper"], tol=30) for im in (early, late))
    assert paper_e.sum() > 200, "roll not drawn at the start"
    assert paper_l.sum() > 10 * paper_e.sum(), "the roll did not grow"
    # the grown roll sits above the drum
    drum_top = np.nonzero(_colour_mask(late, COLOURS["drum"]))[0].min()
    assert np.nonzero(paper_l)[0].mean() < drum_top + 0.05 * h
    # the two playback times differ where the roll is
    region = paper_l | paper_e
    diff = np.abs(early.astype(int) - late.astype(int)).sum(axis=-1) > 30
    assert diff[region].mean() > 0.5
