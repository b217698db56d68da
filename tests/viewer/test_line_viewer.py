"""The viewer on a web line (machines spec §11, models/winder_line_dancer.toml): the web's
spans as tangents between the circles on the wrapped side, the dancer's roller where its
position channel puts it, the web's length change with the dancer's travel, the readout."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from test_viewer import _embedded_readout, _quat_matrix, _rot_y, _tracks, _web_segments
from winder.viewer import WinderGraph, export_html, motion, plan_animation, readout_text
from winder.viewer._line import Circle, dancer_axis, line_path, roller_arc, span_tangent

import winder

ROOT = Path(__file__).resolve().parents[2]
DANCER = ROOT / "models" / "winder_line_dancer.toml"


@pytest.fixture(scope="module")
def dancer_line() -> winder.Scene:
    return winder.load_scene(DANCER)


@pytest.fixture(scope="module")
def dancer_run(dancer_line) -> winder.Result:
    """The shipped line's first 4 s (the drums ramp up; the dancer dips by 23 mm)."""
    return winder.simulate(dancer_line, t_end=4.0, output_step=0.01)


def _classical_tangents(a: Circle, b: Circle) -> list[tuple[np.ndarray, np.ndarray]]:
    """The (up to) four common tangents of two circles, each as its contact points: the
    lines n·x = k (|n| = 1) at signed distance σ_a r_a from c_a and σ_b r_b from c_b,
    σ_a = σ_b the outer ones, σ_a = −σ_b the crossed ones: n·D = σ_b r_b − σ_a r_a,
    n = D̂ cos γ ± D̂⊥ sin γ, cos γ = (σ_b r_b − σ_a r_a)/|D|."""
    D = b.c - a.c
    dist = float(np.hypot(*D))
    Dh, Dp = D / dist, np.array([-D[1], D[0]]) / dist
    out = []
    for sa, sb in ((1, 1), (1, -1)):
        cg = (sb * b.r - sa * a.r) / dist
        if abs(cg) > 1:
            continue
        for sign in (1, -1):
            n = Dh * cg + sign * Dp * math.sqrt(1 - cg * cg)
            k = n @ a.c - sa * a.r
            out.append((a.c - (n @ a.c - k) * n, b.c - (n @ b.c - k) * n))
    return out


def _travel(c: Circle, p: np.ndarray) -> np.ndarray:
    """Spec §1: the surface point at angle α moves along s (sin α, −cos α)."""
    al = math.atan2(p[1] - c.z, p[0] - c.x)
    return c.s * np.array([math.sin(al), -math.cos(al)])


def test_span_tangent_is_the_closed_form_tangent_on_the_wrapped_side() -> None:
    """For 200 random pairs of circles and all four sense pairs, span_tangent's contact
    points are those of the one classical common tangent (outer for equal senses,
    crossed for opposite ones) along which both surfaces move towards b: the unit
    direction p_a → p_b equals the travel direction at p_a and at p_b. Measured: 4.4e-16 m."""
    rng = np.random.default_rng(34)
    worst, counts = 0.0, {"outer": 0, "crossed": 0}
    for _ in range(200):
        ra, rb = rng.uniform(0.05, 1.3, 2)
        c = rng.uniform(-4.0, 4.0, 2)
        c *= (ra + rb) * rng.uniform(1.05, 3.0) / np.hypot(*c)  # apart: 4 tangents exist
        for sa, sb in itertools.product((1, -1), repeat=2):
            a, b = Circle(0.3, -0.2, ra, sa), Circle(0.3 + c[0], -0.2 + c[1], rb, sb)
            pa, pb = span_tangent(a, b)
            u = (pb - pa) / np.hypot(*(pb - pa))
            ok = [(qa, qb) for qa, qb in _classical_tangents(a, b)
                  if np.allclose(_travel(a, qa), (qb - qa) / np.hypot(*(qb - qa)), atol=1e-9)
                  and np.allclose(_travel(b, qb), (qb - qa) / np.hypot(*(qb - qa)), atol=1e-9)]
            assert len(ok) == 1  # the side is unique
            worst = max(worst, float(np.max(np.abs(np.concatenate([pa - ok[0][0],
                                                                   pb - ok[0][1]])))))
            np.testing.assert_allclose(_travel(a, pa), u, atol=1e-12)
            counts["outer" if sa == sb else "crossed"] += 1
    assert worst < 1e-13, worst
    assert counts == {"outer": 400, "crossed": 400}


def test_roller_arc_wraps_in_the_direction_of_travel() -> None:
    """Clockwise (s = +1) from the top to the right side is a quarter turn, counter-
    clockwise (s = −1) three quarters; every point on the circle."""
    for s, wrap in ((1, 0.5 * math.pi), (-1, 1.5 * math.pi)):
        c = Circle(1.0, 2.0, 0.3, s)
        arc = roller_arc(c, np.array([1.0, 2.3]), np.array([1.3, 2.0]), n=61)
        np.testing.assert_allclose(np.hypot(*(arc - c.c).T), 0.3, atol=1e-15)
        chords = np.sum(np.hypot(*np.diff(arc, axis=0).T))
        assert abs(chords - 0.3 * wrap) < 0.3 * wrap * 1e-3


def _segments(path: np.ndarray) -> float:
    return float(np.sum(np.hypot(*np.diff(path, axis=0).T)))


def test_dancer_line_draws_tangent_spans_and_the_dancer_at_its_channel(
        dancer_line, dancer_run) -> None:
    """On a real 4 s run of the shipped line, at every 10th sample: the dancer's roller is
    drawn at centre + d·e with d its channel dancer_position (e the travel axis, here
    straight down: both spans lengthen); every straight span of the web touches both of
    its circles (|p − c| = r, (p − c)·(q − p) = 0) with the parent's radius of that
    sample; the readout lists the five span tensions and the dancer's d in mm.
    Measured: position 0, tangency 1.1e-16 m, 1.1e-16 m²."""
    res = dancer_run
    k = np.arange(0, len(res.t), 10)
    m = motion(dancer_line, res, res.t[k])
    b = m.bodies["dancer"]
    e = np.array(b.axis)
    np.testing.assert_allclose(e, [0.0, -1.0], atol=1e-12)
    d = res["dancer_position"][k]
    assert np.ptp(d) > 0.02  # it moves
    drawn = np.column_stack([b.x, b.z]) - np.array([3.3, -2.25])
    np.testing.assert_allclose(drawn @ e, d, rtol=0, atol=1e-15)
    np.testing.assert_allclose(drawn @ np.array([-e[1], e[0]]), 0.0, atol=1e-15)
    names = ["parent", "guide1", "dancer", "guide2", "guide3", "rear"]
    for i, j in enumerate(k):
        path = m.web_paths(i)[0]
        circles = [(np.array([m.bodies[n].x[i], m.bodies[n].z[i]]), m.bodies[n].radius[i])
                   for n in names]
        np.testing.assert_allclose(circles[0][1], res["parent_radius"][j], rtol=1e-12)
        starts = [0, 7, 14, 21, 28]  # the span leaving circle s: path[s] → path[s + 1]
        for s, (c0, r0), (c1, r1) in zip(starts, circles[:-1], circles[1:], strict=True):
            p, q = path[s], path[s + 1]
            np.testing.assert_allclose([np.hypot(*(p - c0)), np.hypot(*(q - c1))],
                                       [r0, r1], atol=1e-12)
            np.testing.assert_allclose([(p - c0) @ (q - p), (q - c1) @ (q - p)], 0.0,
                                       atol=1e-12)
        text = readout_text(m, i).splitlines()
        spans = next(line for line in text if line.startswith("spans")).split()
        assert spans[2:7] == [f"{res[f'span{n}_tension'][j]:.1f}" for n in range(5)]
        assert next(line for line in text if line.startswith("dancer  ")).split()[1:4] \
            == ["d", f"{1e3 * res['dancer_position'][j]:+.1f}", "mm"]


def test_web_lengthens_by_twice_the_dancer_travel(dancer_line, dancer_run) -> None:
    """The shipped dancer's two spans are parallel (its drawn wrap π, as the model
    requires), so the drawn web's length grows by exactly 2·(d − d₀) with the dancer's
    travel (both spans are L + d long, machines spec §11), the bodies that move the web's
    ends (the parent's radius, the set's centre and radius) held at their first sample.
    Measured: 1.6e-15 m over d − d₀ down to −23.8 mm."""
    res = dancer_run
    m = motion(dancer_line, res, res.t)
    np.testing.assert_allclose(m.bodies["dancer"].axis, [0.0, -1.0], atol=1e-15)
    for name, coords in (("parent", ("radius",)), ("set", ("x", "z", "radius"))):
        for c in coords:
            values = getattr(m.bodies[name], c)
            values[:] = values[0]
    lengths = np.array([_segments(m.web_paths(i)[0]) for i in range(len(res.t))])
    d = res["dancer_position"]
    assert np.ptp(d) > 0.02
    np.testing.assert_allclose(lengths - lengths[0], 2.0 * (d - d[0]), rtol=0, atol=1e-12)


def test_web_length_rate_on_a_slanted_dancer_is_its_pulls_resultant() -> None:
    """Spans not parallel (the drawn wrap β on the dancer < π): moving the dancer along
    dancer_axis by ±h changes the web's length (exact arcs: tangents plus R·wrap) at
    the rate 2 sin(β/2) = |sum of the unit pulls| (the belt identity), checked by central
    differences, h = 1e-5 m; moving it across the axis does not change it to first
    order. Measured: 8.2e-11 (rate 1.5441 at β = 1.764 rad), across 4.4e-11."""
    parent, drum = Circle(6.5, 0.8, 1.1, 1), Circle(0.525, 0.0, 0.5, 1)
    g1, g2 = Circle(5.0, -0.9, 0.1, -1), Circle(3.0, -0.9, 0.1, -1)

    def length(dancer: Circle) -> tuple[float, float]:
        circles = [parent, g1, dancer, g2, drum]
        points, meet = line_path(parent, [g1, dancer, g2], drum)
        arcs = points[1:].reshape(3, 7, 2)  # each roller's: arrival ... departure
        ends = [points[0], *arcs[:, [0, -1]].reshape(-1, 2), meet]
        total = sum(float(np.hypot(*(q - p))) for p, q in zip(ends[0::2], ends[1::2],
                                                               strict=True))
        wraps = []
        for c, arc in zip(circles[1:-1], arcs, strict=True):  # exact arcs R·wrap
            a_in = math.atan2(arc[0][1] - c.z, arc[0][0] - c.x)
            a_out = math.atan2(arc[-1][1] - c.z, arc[-1][0] - c.x)
            wraps.append((c.s * (a_in - a_out)) % (2 * math.pi))
            total += c.r * wraps[-1]
        return total, wraps[1]

    home = Circle(4.0, -1.8, 0.1, 1)
    e = dancer_axis(g1, home, g2)
    beta = length(home)[1]
    assert 1.0 < beta < 3.0
    h = 1e-5

    def moved(v: np.ndarray) -> Circle:
        return Circle(home.x + v[0], home.z + v[1], home.r, home.s)
    rate = (length(moved(h * e))[0] - length(moved(-h * e))[0]) / (2 * h)
    assert abs(rate - 2 * math.sin(beta / 2)) < 1e-9, (rate, 2 * math.sin(beta / 2))
    across = np.array([-e[1], e[0]])
    side = (length(moved(h * across))[0] - length(moved(-h * across))[0]) / (2 * h)
    assert abs(side) < 1e-9, side


def test_dancer_line_html_poses_the_dancer_and_joins_the_web(tmp_path: Path, dancer_line,
                                                             dancer_run) -> None:
    """In the HTML animation (2 s playback, 10 fps: 21 frames over 4 s): the dancer node
    sits at (3.3, −2.25 − d(t_k)) with d its channel at the frame times, the carriage block
    moves with it, every roller turns by θ = sense · NAME_angle · spin_gain (guide1 and
    guide2 sense −1: counter-clockwise), the web's 53 segments form one
    path (each starts where the last ended) from the parent's tangent point to the set,
    and the readout of each frame has the spans' tensions. Measured: 1.1e-16 m."""
    res = dancer_run
    plan = plan_animation(res, playback=2.0, fps=10, scene=dancer_line)
    html = export_html(WinderGraph(dancer_line), res, tmp_path / "line.html",
                       playback=2.0, fps=10).read_text()
    tracks = _tracks(html)
    d = np.interp(plan.times, res.t, res["dancer_position"])
    pos = np.array([f["value"] for f in tracks[("/meshcat/winder/dancer", ".position")]])
    np.testing.assert_allclose(pos[:, [0, 2]], np.column_stack([np.full(21, 3.3), -2.25 - d]),
                               atol=1e-12)
    block = np.array([f["value"] for f in tracks[("/meshcat/winder/carriage/dancer",
                                                  ".position")]])
    np.testing.assert_allclose(block[:, [0, 2]], pos[:, [0, 2]], atol=1e-12)
    for name, sense in (("guide1", -1), ("dancer", 1), ("guide2", -1), ("guide3", 1)):
        quats = [f["value"] for f in tracks[(f"/meshcat/winder/{name}", ".quaternion")]]
        theta = sense * np.interp(plan.times, res.t, res[f"{name}_angle"]) * plan.spin_gain
        assert np.ptp(theta) > 1.0  # it turns visibly
        for q, th in zip(quats, theta, strict=True):
            np.testing.assert_allclose(_quat_matrix(q), _rot_y(th), atol=1e-12)
    ends = _web_segments(tracks)
    assert len(ends) == 53
    for (_, b), (a, _) in zip(ends[:-1], ends[1:], strict=True):
        np.testing.assert_allclose(a, b, atol=1e-12)
    r_u = np.interp(plan.times, res.t, res["parent_radius"])
    start = ends[0][0][:, [0, 2]]
    np.testing.assert_allclose(np.hypot(start[:, 0] - 5.0, start[:, 1] - 0.8), r_u,
                               atol=1e-12)
    texts = _embedded_readout(html)
    assert all(any(line.startswith("spans") for line in t.splitlines()) for t in texts)


def test_readout_aggregates_a_long_line() -> None:
    """A line of 9 spans over 8 rollers (one a dancer): the readout has one line for the
    rollers (their count, least and largest speed and surface speed), one for the spans
    (beyond MAX_LISTED_SPANS: their count, least, largest and mean tension, as numpy
    has them) and one for the dancer (d in mm): 3 lines, not 17."""
    from winder.viewer._motion import BodyMotion, Motion, WebMotion
    from winder.viewer._readout import MAX_LISTED_SPANS

    rng = np.random.default_rng(9)
    one = np.ones(1)
    names = [f"r{i}" for i in range(8)]
    speeds = rng.uniform(10.0, 20.0, 8)
    bodies = {n: BodyMotion(n, "drum", 1, 0 * one, 0 * one, 0 * one, 0.1 * one, w * one)
              for n, w in zip(names, speeds, strict=True)}
    bodies["r3"] = BodyMotion("r3", "drum", 1, 0 * one, 0 * one, 0 * one, 0.1 * one,
                              speeds[3] * one, position=np.array([-0.0123]),
                              axis=(0.0, -1.0), home=(0.0, 0.0), travel=(-0.15, 0.2))
    tensions = tuple(np.array([t]) for t in rng.uniform(900.0, 1200.0, 9))
    web = WebMotion("w", ("r0", "r1"), unwind="u", rollers=tuple(names),
                    span_tensions=tensions)
    m = Motion(np.zeros(1), bodies, {}, ("r0", "r1"), webs=(web,))
    lines = readout_text(m, 0).splitlines()
    assert len(tensions) > MAX_LISTED_SPANS
    assert len(lines) == 4  # t, rollers, spans, dancer
    each = np.array([t[0] for t in tensions])
    assert lines[1].split() == ["rollers", "×8", f"{speeds.min():.2f}–{speeds.max():.2f}",
                                "rad/s", f"{0.1 * speeds.min():.2f}–{0.1 * speeds.max():.2f}",
                                "m/s"]
    assert lines[2].split() == ["spans", "T", "×9", f"{each.min():.1f}–{each.max():.1f}",
                                "mean", f"{each.mean():.1f}", "N"]
    assert lines[3].split() == ["r3", "d", "-12.3", "mm", "(travel", "-150", "…", "+200)"]
