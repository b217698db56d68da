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


def test_html_is_standalone_and_plays_the_result(tmp_path: Path, paper_scene,
                                                 capfd) -> None:
    """The animation data in the HTML are the result's channels at the frame times:
    frame k of ``playback·fps + 1`` shows t_k = k·t_end/(playback·fps); the paper's scale is
    the radius (unit cylinder), the roll's height is z, the drum does not move. Writing it
    opens no viewer and prints no viewer address."""
    res = _short_result(paper_scene)
    capfd.readouterr()
    html = export_html(WinderGraph(paper_scene), res, tmp_path / "a.html", playback=4.0,
                       fps=10)
    printed = capfd.readouterr()
    assert "visualizer" not in printed.out + printed.err
    assert "http" not in printed.out + printed.err
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


# ---- machines of parts: the two-drum winder ----------------------------------------------

MODELS = Path(__file__).resolve().parents[2] / "models"


@pytest.fixture(scope="module")
def two_drum() -> winder.Scene:
    return winder.load_scene(MODELS / "two_drum_winder.toml")


@pytest.fixture(scope="module")
def two_drum_run(two_drum) -> winder.Result:
    """The first 3 s of the two-drum winder (the set turns hundreds of radians)."""
    return winder.simulate(two_drum.replace(scene={"duration": 3.0, "output_step": 0.01}))


def _quat_matrix(q: list[float]) -> np.ndarray:
    """Rotation matrix of a three.js quaternion ``[x, y, z, w]``."""
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _rot_y(theta: float) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _embedded_readout(text: str) -> list[str]:
    import json
    import re

    return json.loads(re.search(r"var texts = (\[.*?\]), fps", text, re.S).group(1)
                      .replace("<\\/", "</"))


def test_two_drum_html_poses_every_body_from_its_channels(tmp_path: Path, two_drum,
                                                          two_drum_run) -> None:
    """In the HTML's animation, frame k (t_k = k·t_end/(playback·fps)) places every body
    at its centre channels (fixed coordinates from the scene), turned about +y by
    θ = sense · NAME_angle · spin_gain (drums +1, set −1, rider +1); the web's last
    segment ends at the entry nip point p_b = c_b − r_b n (n from the rear drum to the
    set); its arc lies on the rear drum; the readout of frame k shows t_k, the set's
    radius and every nip force. Measured errors: positions 0, rotations 4e-16, web end
    3e-16 m."""
    from winder.viewer import plan_animation

    res, graph = two_drum_run, WinderGraph(two_drum)
    plan = plan_animation(res, playback=3.0, fps=10, scene=two_drum)
    assert 0 < plan.spin_gain < 1
    text = export_html(graph, res, tmp_path / "td.html", playback=3.0, fps=10).read_text()
    tracks = _tracks(text)
    times = np.arange(31) * float(res.t[-1]) / 30

    def ch(name: str) -> np.ndarray:
        return np.interp(times, res.t, res[name])
    fixed = {"front": (-0.525, 0.0), "rear": (0.525, 0.0)}
    centre = {"front": (np.full(31, -0.525), np.zeros(31)),
              "rear": (np.full(31, 0.525), np.zeros(31)),
              "set": (ch("set_x"), ch("set_z")), "rider": (np.zeros(31), ch("rider_z"))}
    sense = {"front": 1, "rear": 1, "set": -1, "rider": 1}
    assert fixed["rear"] == two_drum.drums[1].centre
    for body in ("front", "rear", "set", "rider"):
        pos = np.array([k["value"] for k in tracks[(f"/meshcat/winder/{body}", ".position")]])
        assert pos.shape == (31, 3)
        np.testing.assert_allclose(pos[:, 0], centre[body][0], rtol=1e-12, atol=1e-15)
        np.testing.assert_array_equal(pos[:, 1], 0.0)
        np.testing.assert_allclose(pos[:, 2], centre[body][1], rtol=1e-12, atol=1e-15)
        quats = [k["value"] for k in tracks[(f"/meshcat/winder/{body}", ".quaternion")]]
        theta = sense[body] * ch(f"{body}_angle") * plan.spin_gain
        for q, th in zip(quats, theta, strict=True):
            np.testing.assert_allclose(_quat_matrix(q), _rot_y(th), atol=1e-12)
    assert np.ptp(ch("set_angle") * plan.spin_gain) > 1.0  # the set turns visibly
    # the web: segment i is a unit strip scaled along its own x by its length
    segs = sorted(p for p, name in tracks if p.startswith("/meshcat/winder/web/s")
                  and name == ".position")
    ends = []
    for seg in segs:
        mid = np.array([k["value"] for k in tracks[(seg, ".position")]])
        quat = [k["value"] for k in tracks[(seg, ".quaternion")]]
        length = np.array([k["value"][0] for k in tracks[(seg + "/strip", ".scale")]])
        half = np.array([_quat_matrix(q)[:, 0] for q in quat]) * (0.5 * length)[:, None]
        ends.append((mid - half, mid + half))
    for (_, b), (a, _) in zip(ends[:-1], ends[1:], strict=True):
        np.testing.assert_allclose(a, b, atol=1e-12)  # the segments join
    c_b = np.column_stack([ch("set_x"), ch("set_z")])
    d = c_b - [0.525, 0.0]
    n = d / np.hypot(d[:, 0], d[:, 1])[:, None]
    p_b = c_b - ch("set_radius")[:, None] * n
    end = ends[-1][1]
    np.testing.assert_allclose(end[:, [0, 2]], p_b, atol=1e-12)
    np.testing.assert_allclose(end[:, 1], 0.0, atol=1e-12)
    for _, b in ends[1:-1]:  # arc points on the rear drum's surface
        np.testing.assert_allclose(np.hypot(b[:, 0] - 0.525, b[:, 2]), 0.5, atol=1e-12)
    assert np.all(ends[0][0][:, 0] > 10.0)  # it comes from far off to the rear
    texts = _embedded_readout(text)
    assert len(texts) == 31
    for k in (0, 17, 30):  # each value printed to its last digit
        lines = [line.split() for line in texts[k].splitlines()]
        assert lines[0] == ["t", f"{times[k]:.2f}", "s"]
        assert lines[1] == ["set", "r", f"{ch('set_radius')[k]:.4f}", "m"]
        speeds = {w[0]: w[1:] for w in lines[2:6]}
        for body, radius in (("front", 0.5), ("set", ch("set_radius")[k]), ("rider", 0.15)):
            w = ch(f"{body}_speed")[k]
            assert speeds[body] == [f"{w:.2f}", "rad/s", f"{w * radius:.2f}", "m/s"]
        forces = {w[0]: w[1:] for w in lines[6:]}
        for nip in ("front_nip", "rear_nip", "rider_nip"):
            assert forces[nip] == ["N", f"{ch(nip + '_normal_force')[k] / 1e3:.3f}", "kN"]


def test_two_drum_checks_name_the_bad_channel(two_drum, two_drum_run) -> None:
    from winder.viewer import check_drawable

    res = two_drum_run
    check_drawable(res)  # the scene stored in the result
    base = {k: np.array(res[k]) for k in res}
    for name, value, message in [("set_radius", np.nan, "'set_radius' is not finite"),
                                 ("set_radius", 0.0, "set_radius 0.0 m"),
                                 ("rider_z", np.inf, "'rider_z' is not finite")]:
        ch = dict(base)
        ch[name] = ch[name].copy()
        ch[name][5] = value
        bad = winder.Result(ch, dict(res.meta))
        with pytest.raises(winder.WinderError, match=message):
            check_drawable(bad, "x.npz")
    ch = {k: v for k, v in base.items() if k != "set_x"}
    with pytest.raises(winder.WinderError, match="x.npz: no channel set_x"):
        check_drawable(winder.Result(ch, dict(res.meta)), "x.npz")


def _synthetic_two_drum(scene: winder.Scene) -> winder.Result:
    """The set grows 0.1 → 0.3 → 0.5 m between the drums, the rider on top of it."""
    from winder.viewer._motion import drawn_channels, nip_channels

    from winder.model.machine import Machine

    t = np.array([0.0, 1.0, 2.0])
    r = np.array([0.1, 0.3, 0.5])
    m = Machine(scene)
    ch = {c: np.zeros(3) for c in (*drawn_channels(scene, m),
                                   *nip_channels(scene, m).values())}
    z = np.sqrt((0.5 + r) ** 2 - 0.525**2)
    ch.update(t=t, set_radius=r, set_z=z, rider_z=z + r + 0.15)
    return winder.Result(ch, {"scene": scene.name, "scene_dict": scene.to_dict()})


def _face_mask(img: np.ndarray, hex_rgb: int, shade: float = 0.88, tol: int = 8
               ) -> np.ndarray:
    """Pixels of a flat face lit by meshcat's lights: the colour times ``shade`` (measured
    0.88: drum (58, 110, 165) drawn (51, 97, 146)); the background gradient is far."""
    rgb = shade * np.array([(hex_rgb >> 16) & 255, (hex_rgb >> 8) & 255, hex_rgb & 255])
    return np.all(np.abs(img[..., :3].astype(float) - rgb) <= tol, axis=-1)


@pytest.mark.browser
def test_two_drum_snapshots_are_where_the_camera_projects_them(tmp_path: Path,
                                                               two_drum) -> None:
    """Pinhole oracle: meshcat's camera (75° vertical field of view, at (x_c, −d, z_c)
    looking along +y, from WinderGraph.camera) projects the top of the rider's front face
    and the bottom and left of the front drum's face to the rows and column where their
    colours end in the 1000×750 snapshot; the web reaches the image's right edge (it comes
    from off-screen). Measured: rider top +0.2…+0.6 px, drum bottom −1.9 px, drum left
    +0.6 px (the mask leaves out the blended edge pixels); tolerance 4 px = 1.7 % of the
    drum's 231 px diameter (the camera aimed at the wrong point was 43 px off)."""
    _needs_chromium()
    import matplotlib.image as mpimg

    res = _synthetic_two_drum(two_drum)
    graph = WinderGraph(two_drum)
    paths = snapshots(graph, res, tmp_path / "snaps", every=1.0)
    from winder.viewer import motion

    xc, zc, d = graph.camera(motion(two_drum, res, res.t).extent())
    f = 375.0 / np.tan(np.radians(37.5))

    def project(x: float, y: float, z: float) -> tuple[float, float]:
        return 500.0 + f * (x - xc) / (y + d), 375.0 - f * (z - zc) / (y + d)

    for k, png in enumerate(paths):
        img = np.round(255 * mpimg.imread(png)).astype(np.uint8)[..., :3]
        assert img.shape == (750, 1000, 3)
        rider = _face_mask(img, COLOURS["rider"])
        _, top = project(0.0, -2.5, res["rider_z"][k] + 0.15)
        assert abs(np.nonzero(rider)[0].min() - top) <= 4.0, (k, top)
        drum = _face_mask(img, COLOURS["drum"])
        drum[:, 500:] = False  # the front drum only
        _, bottom = project(-0.525, -2.625, -0.5)
        left, _ = project(-1.025, -2.625, 0.0)
        rows, cols = np.nonzero(drum)
        assert abs(rows.max() - bottom) <= 4.0, (k, bottom)
        assert abs(cols.min() - left) <= 4.0, (k, left)
        assert _colour_mask(img, COLOURS["web"], tol=60)[:, -1].sum() > 5  # off-screen


@pytest.mark.browser
def test_readout_follows_the_animation_in_chromium(tmp_path: Path, two_drum,
                                                   two_drum_run) -> None:
    """After a few seconds of (virtual) playback in headless Chromium the readout shows the
    text of a later frame, exactly one of the frames' texts: the overlay script follows
    meshcat's animation clock."""
    _needs_chromium()
    import html as html_lib
    import re
    import subprocess

    from winder.viewer._export import CHROMIUM_FLAGS

    page = export_html(WinderGraph(two_drum), two_drum_run, tmp_path / "td.html",
                       playback=10.0, fps=10)
    texts = _embedded_readout(page.read_text())
    profile = tmp_path / "profile"
    dom = subprocess.run([find_chromium(), *CHROMIUM_FLAGS, f"--user-data-dir={profile}",
                          "--window-size=800,600", "--virtual-time-budget=4000",
                          "--dump-dom", page.resolve().as_uri()],
                         capture_output=True, text=True, timeout=120,
                         env=dict(os.environ, HOME=str(profile))).stdout
    shown = html_lib.unescape(re.search(r'<pre id="winder-readout">(.*?)</pre>', dom,
                                        re.S).group(1))
    assert shown in texts
    # it moved on from the first frame: how far depends on when Chromium starts the
    # animation clock (frames 5 to 82 of 101 seen after the same virtual 4 s)
    assert texts.index(shown) > 0, shown


# ---- the winder line: the parent roll and the web span between it and the winder ---------

@pytest.fixture(scope="module")
def line() -> winder.Scene:
    return winder.load_scene(MODELS / "winder_line.toml")


def _synthetic_line(scene: winder.Scene) -> winder.Result:
    """The parent shrinks 1.25 → 0.45 m about its fixed centre while the set grows
    0.1 → 0.5 m between the drums; the span's tension varies."""
    from winder.viewer._motion import drawn_channels, nip_channels

    from winder.model.machine import Machine

    t = np.linspace(0.0, 4.0, 5)
    r = np.linspace(0.1, 0.5, 5)
    m = Machine(scene)
    ch = {c: np.zeros(5) for c in (*drawn_channels(scene, m),
                                   *nip_channels(scene, m).values())}
    z = np.sqrt((0.5 + r) ** 2 - 0.525**2)
    ch.update(t=t, set_radius=r, set_z=z, set_x=0.01 * t, rider_z=z + r + 0.15,
              parent_radius=np.linspace(1.25, 0.45, 5), parent_angle=0.3 * t,
              parent_speed=np.full(5, 0.3), span_tension=np.array([1e3, 950.0, 1234.5,
                                                                    0.0, 1001.25]))
    return winder.Result(ch, {"scene": scene.name, "scene_dict": scene.to_dict()})


def _web_segments(tracks: dict) -> list[tuple[np.ndarray, np.ndarray]]:
    """Ends ``(start, end)`` [m] (frames × xyz) of the web's segments, in path order."""
    segs = sorted(p for p, name in tracks if p.startswith("/meshcat/winder/web/s")
                  and name == ".position")
    ends = []
    for seg in segs:
        mid = np.array([k["value"] for k in tracks[(seg, ".position")]])
        quat = [k["value"] for k in tracks[(seg, ".quaternion")]]
        length = np.array([k["value"][0] for k in tracks[(seg + "/strip", ".scale")]])
        half = np.array([_quat_matrix(q)[:, 0] for q in quat]) * (0.5 * length)[:, None]
        ends.append((mid - half, mid + half))
    return ends


def test_line_html_draws_the_parent_and_the_web_span(tmp_path: Path, line) -> None:
    """In the HTML of a winder line, frame k (t_k = k·t_end/(playback·fps)): the parent
    roll stays at its scene centre (3.2, 0.8) and its paper is scaled to parent_radius;
    the web is one path whose first point is the parent's exit point
    p_u = c_u + s·r_u·(−t_z, t_x) (t_u the unit vector from c_u to the rear drum's
    centre, s = +1; machines spec §5), whose straight run touches the rear drum
    tangentially, whose arc lies on the rear drum and whose last point is the entry nip
    point p_b = c_b − r_b n; the readout shows the parent's radius and the span's
    tension. Measured errors: radius 0, p_u 4e-16 m, tangency 4e-16 m², p_b 3e-16 m."""
    from winder.viewer import plan_animation

    res = _synthetic_line(line)
    plan = plan_animation(res, playback=2.0, fps=10, scene=line)
    text = export_html(WinderGraph(line), res, tmp_path / "line.html", playback=2.0,
                       fps=10).read_text()
    tracks = _tracks(text)
    times = np.arange(21) * 4.0 / 20
    np.testing.assert_allclose(plan.times, times, rtol=1e-15)

    def ch(name: str) -> np.ndarray:
        return np.interp(times, res.t, res[name])
    r_u = ch("parent_radius")
    assert np.ptp(r_u) > 0.7  # it shrinks visibly
    scale = np.array([k["value"] for k in tracks[("/meshcat/winder/parent/paper", ".scale")]])
    np.testing.assert_allclose(scale[:, 0], r_u, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(scale[:, 2], r_u, rtol=1e-12, atol=1e-12)
    pos = np.array([k["value"] for k in tracks[("/meshcat/winder/parent", ".position")]])
    np.testing.assert_allclose(pos, np.tile([3.2, 0.0, 0.8], (21, 1)), atol=1e-15)
    ends = _web_segments(tracks)
    for (_, b), (a, _) in zip(ends[:-1], ends[1:], strict=True):
        np.testing.assert_allclose(a, b, atol=1e-12)  # one path: the segments join
    c_u, c_a = np.array([3.2, 0.8]), np.array([0.525, 0.0])
    t_u = (c_a - c_u) / np.hypot(*(c_a - c_u))
    p_u = c_u + r_u[:, None] * np.array([-t_u[1], t_u[0]])  # s = +1
    start = ends[0][0]
    np.testing.assert_allclose(start[:, [0, 2]], p_u, atol=1e-12)
    np.testing.assert_allclose(start[:, 1], 0.0, atol=1e-12)
    touch = ends[0][1][:, [0, 2]]  # where the span meets the rear drum
    np.testing.assert_allclose(np.hypot(*(touch - c_a).T), 0.5, atol=1e-12)
    np.testing.assert_allclose(np.einsum("ij,ij->i", touch - c_a, touch - p_u), 0.0,
                               atol=1e-12)  # tangent: radius ⟂ span
    assert np.all(touch[:, 1] < -0.45)  # on the drum's underside (the web runs below)
    for _, b in ends[:-1]:
        np.testing.assert_allclose(np.hypot(b[:, 0] - 0.525, b[:, 2]), 0.5, atol=1e-12)
    c_b = np.column_stack([ch("set_x"), ch("set_z")])
    n = (c_b - c_a) / np.hypot(*(c_b - c_a).T)[:, None]
    np.testing.assert_allclose(ends[-1][1][:, [0, 2]], c_b - ch("set_radius")[:, None] * n,
                               atol=1e-12)
    texts = _embedded_readout(text)
    for k in (0, 7, 13, 20):
        lines = [line.split() for line in texts[k].splitlines()]
        assert ["parent", "r", f"{r_u[k]:.4f}", "m"] in lines
        assert lines[-1] == ["span", "T", f"{ch('span_tension')[k]:.1f}", "N"]
    assert len({t.splitlines()[-1] for t in texts}) > 10  # the tension changes


def test_line_camera_frames_the_parent_roll(line) -> None:
    """Pinhole oracle: with the camera of WinderGraph.camera over the run's extent, the
    parent roll's near face (y = −w/2) at its largest radius projects inside the
    1000×750 image (75° vertical field of view), as do the set and both drums."""
    from winder.viewer import motion

    res = _synthetic_line(line)
    graph = WinderGraph(line)
    m = motion(line, res, res.t)
    xc, zc, d = graph.camera(m.extent())
    f = 375.0 / np.tan(np.radians(37.5))
    for name, y in (("parent", -2.5), ("set", -2.5), ("front", -2.625), ("rear", -2.625)):
        b = m.bodies[name]
        for x, z in ((b.x - b.radius, b.z), (b.x + b.radius, b.z), (b.x, b.z - b.radius),
                     (b.x, b.z + b.radius)):
            u = 500.0 + f * (x - xc) / (y + d)
            v = 375.0 - f * (z - zc) / (y + d)
            assert np.all((0 < u) & (u < 1000) & (0 < v) & (v < 750)), (name, u, v)


def test_line_run_motion_from_its_channels(line) -> None:
    """On a real (1 s) run of the line: the drawn web starts at the engine's exit point
    recomputed here from the channels and ends at p_b; the drawn parent radius is its
    channel at the sampled frames; the readout prints span_tension. Measured: 0, 3e-16 m."""
    from winder.viewer import check_drawable, motion, readout_text

    res = winder.simulate(line.replace(scene={"duration": 1.0, "output_step": 0.05}))
    check_drawable(res)
    k = np.arange(0, len(res.t), 4)
    m = motion(line, res, res.t[k])
    np.testing.assert_allclose(m.bodies["parent"].radius, res["parent_radius"][k],
                               rtol=1e-12, atol=1e-12)
    c_u, c_a = np.array([3.2, 0.8]), np.array([0.525, 0.0])
    t_u = (c_a - c_u) / np.hypot(*(c_a - c_u))
    for i, j in enumerate(k):
        path = m.web(i)
        p_u = c_u + res["parent_radius"][j] * np.array([-t_u[1], t_u[0]])
        np.testing.assert_allclose(path[0], p_u, atol=1e-12)
        c_b = np.array([res["set_x"][j], res["set_z"][j]])
        p_b = c_b - res["set_radius"][j] * (c_b - c_a) / np.hypot(*(c_b - c_a))
        np.testing.assert_allclose(path[-1], p_b, atol=1e-12)
        assert readout_text(m, i).splitlines()[-1].split() == [
            "span", "T", f"{res['span_tension'][j]:.1f}", "N"]


def test_view_html_prints_only_what_it_wrote(tmp_path: Path, paper_scene, capfd) -> None:
    """`winder view --html` says where the animation went and nothing about a viewer."""
    from winder.cli import main

    src = _short_result(paper_scene).to_npz(tmp_path / "r.npz")
    capfd.readouterr()
    assert main(["view", str(src), "--html", str(tmp_path / "a.html"), "--playback",
                 "2"]) == 0
    printed = capfd.readouterr()
    assert printed.out.splitlines() == [f"animation (2 s playback) written to "
                                        f"{tmp_path / 'a.html'}"]
    assert "visualizer" not in printed.err and "http" not in printed.err
