"""Standalone HTML export and PNG snapshots rendered by headless Chromium.

Every child process (the meshcat server, Chromium) is stopped when the call ends, on an
error, and when a command is stopped by a signal (:mod:`winder.io.interrupt`)."""

from __future__ import annotations

import io
import math
import os
import shutil
import signal
import subprocess
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager, redirect_stdout
from pathlib import Path

import meshcat
import numpy as np
from winder.viewer._animation import animate, plan_animation
from winder.viewer._motion import check_drawable, motion
from winder.viewer._readout import readout_text, with_readout
from winder.viewer._scene_graph import WinderGraph

from winder._errors import ArgumentError, WinderError
from winder.io.files import atomic_write, scratch_dir
from winder.io.interrupt import deferred, on_abort
from winder.io.result import Result

__all__ = ["export_html", "snapshot_html", "find_chromium", "screenshot", "snapshots",
           "snapshot_names", "served", "MAX_SNAPSHOTS", "NAME_RESOLUTION"]

CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu",
                  "--disable-background-networking", "--no-first-run",
                  "--disable-component-update", "--disable-sync", "--hide-scrollbars",
                  "--enable-unsafe-swiftshader", "--use-angle=swiftshader")
#: Most snapshots one call writes (each is a Chromium run of about a second).
MAX_SNAPSHOTS = 1000
#: Finest snapshot interval the file names tell apart [s].
NAME_RESOLUTION = 1e-6


def _stop(proc: subprocess.Popen | None) -> None:
    """Kill ``proc`` and its process group (it was started in a session of its own)."""
    if proc is None or proc.poll() is not None:
        return
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except OSError:
        proc.kill()
    proc.wait(timeout=10)


@contextmanager
def served(graph: WinderGraph) -> Iterator[meshcat.Visualizer]:
    """A meshcat server with ``graph`` built in it; the server subprocess is stopped on
    exit, on an error and on a signal (0.3.2's ViewerWindow has no close()).

    meshcat prints "You can open the visualizer by visiting the following URL" on stdout
    as its server starts: that text is kept from stdout (an HTML export or a snapshot opens
    no viewer; the live view prints its own address, ``vis.url()``) and goes into the
    message if the server cannot start."""
    with ExitStack() as stack:
        with deferred():  # a signal while the server starts is acted on once it is known
            said = io.StringIO()
            try:
                with redirect_stdout(said):
                    vis = meshcat.Visualizer()
            except Exception as exc:  # the zmq server subprocess could not start
                told = " ".join(said.getvalue().split())[-400:]
                raise WinderError(f"could not start the meshcat server: {exc}"
                                  + (f" (it said: {told})" if told else "")) from exc
            proc = getattr(vis.window, "server_proc", None)
            stack.callback(_stop, proc)
            stack.enter_context(on_abort(lambda: _stop(proc)))
        graph.build(vis)
        yield vis


def export_html(graph: WinderGraph, result: Result, path: str | Path, *,
                playback: float = 30.0, fps: int = 30) -> Path:
    """Write a standalone HTML file (three.js embedded, no network) that plays ``result``,
    with the readout (:mod:`._readout`) of the frame shown."""
    plan = plan_animation(result, playback=playback, fps=fps, scene=graph.scene)
    with served(graph) as vis:
        texts = animate(vis, graph, result, plan)
        html = with_readout(vis.static_html(), texts, plan.fps)
    return atomic_write(path, lambda tmp: tmp.write_text(html, encoding="utf-8"))


def snapshot_html(graph: WinderGraph, result: Result, t: float) -> str:
    """Static HTML of the machine at time ``t`` [s] of ``result`` (true angles), with its
    readout; the camera frames every body over the whole run."""
    check_drawable(result, scene=graph.scene)
    extent = motion(graph.scene, result, result.t).extent()
    m = motion(graph.scene, result, np.array([t]))
    with served(graph) as vis:
        graph.set_camera(vis, extent)
        graph.show(vis, m, 0)
        return with_readout(vis.static_html(), [readout_text(m, 0)])


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
    with scratch_dir("winder-chromium-") as profile:
        shot = profile / "shot.png"
        cmd = [exe, *CHROMIUM_FLAGS, f"--user-data-dir={profile}",
               f"--window-size={size[0]},{size[1]}", f"--virtual-time-budget={wait_ms}",
               f"--screenshot={shot}", Path(html).resolve().as_uri()]
        env = dict(os.environ, HOME=str(profile))
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                text=True, env=env, start_new_session=True)
        with on_abort(lambda: _stop(proc)):
            try:
                _, err = proc.communicate(timeout=120)
            except subprocess.TimeoutExpired:
                raise WinderError(f"Chromium took more than 120 s to render {html}") \
                    from None
            finally:
                _stop(proc)
        if not shot.is_file():
            raise WinderError(f"Chromium wrote no screenshot of {html} (exit "
                              f"{proc.returncode}): {err.strip()[-400:]}")
        atomic_write(target, lambda tmp: shutil.copyfile(shot, tmp))
    return target


def snapshot_names(t_end: float, every: float) -> list[tuple[float, str]]:
    """Times ``0, every, 2·every, … ≤ t_end`` [s] and their PNG file names, unique and in
    time order when sorted as text (``snapshot_t0100s.png``, ``snapshot_t0000.5s.png``:
    zero-padded, with as many decimals as ``every`` needs).

    Raises :class:`~winder.ArgumentError` when ``every`` is not finite and > 0, finer than
    :data:`NAME_RESOLUTION`, or gives more than :data:`MAX_SNAPSHOTS` snapshots."""
    if not (isinstance(every, int | float) and math.isfinite(every) and every > 0):
        raise ArgumentError(f"every must be a finite number > 0 [s], got {every!r}")
    if not (math.isfinite(t_end) and t_end >= 0):
        raise ArgumentError(f"t_end must be finite and >= 0 [s], got {t_end!r}")
    if every < NAME_RESOLUTION:
        raise ArgumentError(f"every = {every!r} s is finer than the {NAME_RESOLUTION:g} s "
                            "resolution of the snapshot names; valid: every >= "
                            f"{NAME_RESOLUTION:g} s")
    n = math.floor(t_end / every + 1e-9) + 1
    if n > MAX_SNAPSHOTS:
        raise ArgumentError(f"every = {every:g} s gives {n} snapshots of a {t_end:g} s run; "
                            f"at most {MAX_SNAPSHOTS}: valid: every >= "
                            f"{t_end / (MAX_SNAPSHOTS - 1):.3g} s")
    decimals = next((d for d in range(7) if abs(round(every, d) - every) <= 1e-9 * every), 6)
    width = max(4, len(str(int(t_end)))) + (decimals + 1 if decimals else 0)
    times = [min(k * every, t_end) for k in range(n)]
    names = [f"snapshot_t{ti:0{width}.{decimals}f}s.png" for ti in times]
    if len(set(names)) != n:  # cannot happen with the rules above; never overwrite
        raise ArgumentError(f"every = {every!r} s: snapshot names would collide")
    return list(zip(times, names, strict=True))


def snapshots(graph: WinderGraph, result: Result, out_dir: str | Path, *, every: float,
              size: tuple[int, int] = (1000, 750)) -> list[Path]:
    """PNG images at t = 0, every, 2·every, … (like the paper's Figs. 9–16), named by
    :func:`snapshot_names`."""
    check_drawable(result, scene=graph.scene)
    plan = snapshot_names(float(result.t[-1]), every)
    out = Path(out_dir)
    # one camera for all pictures (same scale in each): every body over the whole run
    extent = motion(graph.scene, result, result.t).extent()
    m = motion(graph.scene, result, np.array([ti for ti, _ in plan]))
    paths = []
    with scratch_dir("winder-snap-") as tmp, served(graph) as vis:
        graph.set_camera(vis, extent)
        for k, (_, name) in enumerate(plan):  # one meshcat server, re-posed for each page
            graph.show(vis, m, k)
            page = tmp / f"page{k}.html"
            page.write_text(with_readout(vis.static_html(), [readout_text(m, k)]),
                            encoding="utf-8")
            paths.append(screenshot(page, out / name, size=size, wait_ms=1500))
    return paths
