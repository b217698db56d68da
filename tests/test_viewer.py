"""The meshcat viewer: scene graph from Pinocchio kinematics, HTML animation in Chromium."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from winder.viewer import (
    COLOURS,
    WinderGraph,
    export_html,
    find_chromium,
    screenshot,
    snapshot_names,
    snapshots,
)
from winder.viewer._export import served

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
    T = graph.poses({"drum": (0.0, 0.0, 0.3), "roll": (0.0, 1.2, -0.7)})  # θ = sense·angle
    Td, Tr = T["drum"], T["roll"]
    np.testing.assert_allclose(Tr[:3, 3], [0.0, 0.0, 1.2], atol=1e-15)
    # roll about −y by φ: x-axis → (cos φ, 0, sin φ) (spec §1: CoM at (e cos φ, ·, z + e sin φ))
    np.testing.assert_allclose(Tr[:3, 0], [np.cos(0.7), 0.0, np.sin(0.7)], atol=1e-15)
    # drum about +y by θ: top point moves to +x for θ > 0
    np.testing.assert_allclose(Td[:3, :3] @ [0, 0, 1], [np.sin(0.3), 0, np.cos(0.3)], atol=1e-15)


def _tracks(html: str) -> dict[tuple[str, str], list[dict]]:
    """The animation tracks embedded in meshcat's static HTML (msgpack commands, base64)."""
    import base64
    import re

    import umsgpack

    tracks = {}
    for blob in re.findall(r"data:application/octet-binary;base64,([A-Za-z0-9+/=]+)", html):
        cmd = umsgpack.unpackb(base64.b64decode(blob))
        if cmd.get("type") == "set_animation":
            for anim in cmd["animations"]:
                for track in anim["clip"]["tracks"]:
                    tracks[(anim["path"], track["name"])] = track["keys"]
    return tracks


def test_html_is_standalone_and_plays_the_result(tmp_path: Path, paper_scene) -> None:
    """The animation data in the HTML are the result's channels at the frame times:
    frame k of ``playback·fps + 1`` shows t_k = k·t_end/(playback·fps); the paper's scale is
    the radius (unit cylinder), the roll's height is z, the drum does not move."""
    res = _short_result(paper_scene)
    html = export_html(WinderGraph(paper_scene), res, tmp_path / "a.html", playback=4.0,
                       fps=10)
    text = html.read_text()
    assert "<script" in text and "three" in text.lower()
    assert "src=\"http" not in text and "href=\"http" not in text  # nothing fetched
    tracks = _tracks(text)
    times = np.arange(41) * 700.0 / 40
    scale = tracks[("/meshcat/winder/roll/paper", ".scale")]
    assert [k["time"] for k in scale] == list(range(41))
    values = np.array([k["value"] for k in scale])
    r = np.interp(times, res.t, res["radius"])
    np.testing.assert_allclose(values[:, 0], r, rtol=1e-12)
    np.testing.assert_allclose(values[:, 2], r, rtol=1e-12)
    np.testing.assert_array_equal(values[:, 1], 1.0)
    pos = np.array([k["value"] for k in tracks[("/meshcat/winder/roll", ".position")]])
    np.testing.assert_allclose(pos[:, 2], np.interp(times, res.t, res["z"]), rtol=1e-12)
    np.testing.assert_array_equal(pos[:, :2], 0.0)
    drum = np.array([k["value"] for k in tracks[("/meshcat/winder/drum", ".position")]])
    np.testing.assert_array_equal(drum, 0.0)


def _colour_mask(img: np.ndarray, hex_rgb: int, tol: int = 40) -> np.ndarray:
    rgb = np.array([(hex_rgb >> 16) & 255, (hex_rgb >> 8) & 255, hex_rgb & 255])
    return np.all(np.abs(img[..., :3].astype(int) - rgb) < tol, axis=-1)


def _needs_chromium() -> None:
    if find_chromium() is None:
        pytest.skip("Chromium is not installed and could not be installed (make chromium "
                    "needs root and apt-get)")


@pytest.mark.browser
def test_animation_renders_in_headless_chromium(tmp_path: Path, paper_scene) -> None:
    """Whatever frame Chromium shows: the drum is drawn, centred, and the roll with it."""
    _needs_chromium()
    import matplotlib.image as mpimg

    html = export_html(WinderGraph(paper_scene), _short_result(paper_scene),
                       tmp_path / "anim.html", playback=20.0, fps=10)
    img = np.round(255 * mpimg.imread(screenshot(html, tmp_path / "a.png", wait_ms=1500)))
    img = img.astype(np.uint8)
    w = img.shape[1]
    drum = _colour_mask(img, COLOURS["drum"])
    assert drum.sum() > 2000, "drum not drawn"
    assert abs(np.nonzero(drum)[1].mean() - w / 2) < 0.1 * w  # the drum is centred
    assert _colour_mask(img, COLOURS["paper"], tol=30).sum() > 200, "roll not drawn"


def _roll_width(png: Path) -> int:
    """Widest horizontal extent [px] of the object around the roll's centre row (the red
    face mark): pixels that differ from the row's background (a vertical gradient)."""
    import matplotlib.image as mpimg

    img = np.round(255 * mpimg.imread(png)).astype(int)[30:, :, :3]  # below the controls
    yc = int(round(np.nonzero(_colour_mask(img, COLOURS["mark"]))[0].mean()))
    widths = []
    for y in range(yc - 8, yc + 9):
        xs = np.nonzero(np.abs(img[y] - img[y, 0]).sum(axis=1) > 30)[0]
        widths.append(xs.max() - xs.min() + 1)
    return max(widths)


@pytest.mark.browser
def test_snapshots_draw_the_radius_to_scale(tmp_path: Path, paper_scene) -> None:
    """Snapshots every 0.5 s of a roll growing 0.4 → 0.8 m about a fixed centre: the drawn
    diameter in pixels follows the radius (the centre is fixed, so the perspective scale
    is the same in each picture). Measured: 121, 182, 242 px (ratios 1.504, 2.000); one
    pixel is 0.8 % of the smallest. Names are unique and sort in time order."""
    _needs_chromium()
    t = np.array([0.0, 0.5, 1.0])
    ch = {name: np.zeros_like(t) for name in winder.CHANNELS + winder.EXTRA_CHANNELS}
    ch.update(t=t, radius=np.array([0.4, 0.6, 0.8]), z=np.full(3, 1.3),
              roll_speed=np.full(3, 10.0), drum_speed=np.full(3, 10.0))
    res = winder.Result(ch, {"scene": paper_scene.name})
    paths = snapshots(WinderGraph(paper_scene), res, tmp_path / "snaps", every=0.5)
    assert [p.name for p in paths] == ["snapshot_t0000.0s.png", "snapshot_t0000.5s.png",
                                       "snapshot_t0001.0s.png"]
    assert sorted(p.name for p in (tmp_path / "snaps").iterdir()) == [p.name for p in paths]
    w = [_roll_width(p) for p in paths]
    assert w[1] / w[0] == pytest.approx(1.5, abs=0.05), w
    assert w[2] / w[0] == pytest.approx(2.0, abs=0.05), w


@pytest.mark.parametrize(("t_end", "every", "names"), [
    (700.0, 100.0, ["snapshot_t0000s.png", "snapshot_t0100s.png", "snapshot_t0700s.png"]),
    (1.0, 0.5, ["snapshot_t0000.0s.png", "snapshot_t0000.5s.png", "snapshot_t0001.0s.png"]),
    (12345.0, 5000.0, ["snapshot_t00000s.png", "snapshot_t05000s.png", "snapshot_t10000s.png"]),
    (3e-6, 1e-6, ["snapshot_t0000.000000s.png", "snapshot_t0000.000001s.png",
                  "snapshot_t0000.000003s.png"]),
])
def test_snapshot_names_are_unique_and_sorted(t_end, every, names) -> None:
    got = snapshot_names(t_end, every)
    assert [got[0][1], got[1][1], got[-1][1]] == names
    assert len({n for _, n in got}) == len(got)
    assert [n for _, n in sorted(got, key=lambda x: x[1])] == [n for _, n in got]
    np.testing.assert_allclose([ti for ti, _ in got], np.arange(len(got)) * every)


@pytest.mark.parametrize(("t_end", "every", "message"), [
    (700.0, 1e-7, "resolution"), (700.0, 0.5, "at most 1000"), (1.0, 0.0, "every"),
    (1.0, float("nan"), "every"), (1.0, -1.0, "every"), (1.0, float("inf"), "every")])
def test_snapshot_names_refuse(t_end, every, message) -> None:
    with pytest.raises(winder.ArgumentError, match=message):
        snapshot_names(t_end, every)


def _meshcat_servers() -> list[int]:
    me = str(os.getpid())
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            cmd = (stat.parent / "cmdline").read_bytes()
        except OSError:
            continue
        if fields[1] == me and fields[0] != "Z" and b"meshcat.servers.zmqserver" in cmd:
            found.append(int(stat.parent.name))
    return found


def test_meshcat_server_stopped_on_error_and_on_success(tmp_path: Path, paper_scene,
                                                       monkeypatch) -> None:
    from winder.viewer import _export

    graph = WinderGraph(paper_scene)
    with served(graph):
        assert len(_meshcat_servers()) == 1
    assert _meshcat_servers() == []

    def broken(*args, **kw):
        raise RuntimeError("drawing failed")
    monkeypatch.setattr(_export, "animate", broken)
    with pytest.raises(RuntimeError, match="drawing failed"):
        export_html(graph, _short_result(paper_scene), tmp_path / "a.html")
    assert _meshcat_servers() == [] and list(tmp_path.iterdir()) == []
