"""Standalone HTML export and PNG snapshots rendered by headless Chromium."""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import meshcat

from winder._errors import WinderError
from winder._result import Result, atomic_write

from ._animation import animate, plan_animation
from ._scene_graph import WinderGraph

__all__ = ["export_html", "snapshot_html", "find_chromium", "screenshot", "snapshots"]

CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu",
                  "--disable-background-networking", "--no-first-run",
                  "--disable-component-update", "--disable-sync", "--hide-scrollbars",
                  "--enable-unsafe-swiftshader", "--use-angle=swiftshader")


@contextmanager
def _built(graph: WinderGraph) -> Iterator[meshcat.Visualizer]:
    """A meshcat server with ``graph`` built in it; the server subprocess is stopped on
    exit (0.3.2's ViewerWindow has no close())."""
    try:
        vis = meshcat.Visualizer()
    except Exception as exc:  # the zmq server subprocess could not start
        raise WinderError(f"could not start the meshcat server: {exc}") from exc
    try:
        graph.build(vis)
        yield vis
    finally:
        proc = getattr(vis.window, "server_proc", None)
        if proc is not None:
            proc.kill()
            proc.wait(timeout=10)


def export_html(graph: WinderGraph, result: Result, path: str | Path, *,
                playback: float = 30.0, fps: int = 30) -> Path:
    """Write a standalone HTML file (three.js embedded, no network) that plays ``result``."""
    with _built(graph) as vis:
        animate(vis, graph, result, plan_animation(result, playback=playback, fps=fps))
        html = vis.static_html()
    return atomic_write(path, lambda tmp: tmp.write_text(html, encoding="utf-8"))


def snapshot_html(graph: WinderGraph, state: dict[str, float]) -> str:
    """Static HTML of the winder at one state (keys drum_angle, z, roll_angle, radius)."""
    with _built(graph) as vis:
        graph.show(vis, **state)
        return vis.static_html()


def find_chromium() -> str | None:
    """Path of a Chromium/Chrome executable, or ``None``."""
    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def screenshot(html: Path, png: str | Path, *, size: tuple[int, int] = (1000, 750),
               wait_ms: int = 3000, chromium: str | None = None) -> Path:
    """Render ``html`` in headless Chromium and save a PNG (atomically)."""
    exe = chromium or find_chromium()
    if exe is None:
        raise WinderError("no Chromium found for snapshots: install it (make chromium, or "
                          "apt-get install chromium)")
    target = Path(png)
    with tempfile.TemporaryDirectory(prefix="winder-chromium-") as profile:
        shot = Path(profile) / "shot.png"
        cmd = [exe, *CHROMIUM_FLAGS, f"--user-data-dir={profile}",
               f"--window-size={size[0]},{size[1]}", f"--virtual-time-budget={wait_ms}",
               f"--screenshot={shot}", Path(html).resolve().as_uri()]
        env = dict(os.environ, HOME=profile)
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120, env=env)
        if not shot.is_file():
            raise WinderError(f"Chromium wrote no screenshot of {html} (exit "
                              f"{proc.returncode}): {proc.stderr.strip()[-400:]}")
        atomic_write(target, lambda tmp: shutil.copyfile(shot, tmp))
    return target


def snapshots(graph: WinderGraph, result: Result, out_dir: str | Path, *, every: float,
              size: tuple[int, int] = (1000, 750)) -> list[Path]:
    """PNG images at t = 0, every, 2·every, … (like the paper's Figs. 9–16)."""
    import numpy as np

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t = result.t
    paths = []
    times = np.arange(0.0, t[-1] + 1e-9, every)
    with tempfile.TemporaryDirectory(prefix="winder-snap-") as tmp, _built(graph) as vis:
        for ti in times:  # one meshcat server, re-posed for each page
            def at(name: str, ti: float = ti) -> float:
                return float(np.interp(ti, t, result[name]))
            graph.show(vis, drum_angle=at("drum_angle") if "drum_angle" in result else 0.0,
                       z=at("z"), roll_angle=at("roll_angle"), radius=at("radius"))
            page = Path(tmp) / f"t{ti:g}.html"
            page.write_text(vis.static_html(), encoding="utf-8")
            paths.append(screenshot(page, out / f"snapshot_t{int(round(ti)):04d}s.png",
                                    size=size, wait_ms=1500))
    return paths
