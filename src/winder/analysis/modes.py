"""Resonance map: the bounce modes of a machine against the rotation harmonics as the wound
roll grows (a Campbell chart), for any machine from parts.

At each radius of the wound roll (the roll the web enters, ``[web] entry_nip``) the machine
is linearised with its exact Jacobian (:func:`winder.jacobian`) about its quasi-steady
**operating point** (:mod:`winder.analysis.operating_point`: drums at full speed, rolls
at constant surface speed, free coordinates in balance). Each free coordinate names one
**bounce mode** (:mod:`winder.analysis.mode_labels`): the eigenpair in which that
coordinate carries the largest share of the mode's kinetic energy, an oscillating pair of
the bodies first, each pair used once (``set.x``, ``set.z``, ``rider.z``; ``roll.z`` for a
single-drum scene); the rest are the slip/torsion modes. The roll turns at
``f₁ = v/(2π r)``; where ``k f₁`` (``k = 1, 2, 3``) or a drum's rotation frequency crosses
an oscillating bounce mode, the imbalance (or a drum's runout) drives that mode at
resonance (critical radii). For each radius the web speed at which the 1× line meets the
roll's own vertical bounce mode is ``v_crit = 2π r f_bounce``.

A flexible body (issue #25) has bending and torsion modes in place of its segments'
bounce: labelled by shape, the dominant order ``n`` of the segment displacements' (or
angles') projection onto ``sin(nπ y/L)`` (:mod:`winder.analysis.shapes`):
``front.bend.z1``, ``set.bend.x2``, ``front.torsion1``. Only an oscillating mode of the
bodies whose shape it is carries such a label (issue #32): not a friction state's
relaxation (a real eigenvalue, a slip mode), and no label where no oscillating mode has
that shape (NaN in the map). A harmonic ``k`` meets a bending mode of frequency ``f_b``
where ``k v/(2π r) = f_b``, at ``r = k v/(2π f_b)``.

A web line (machines.md §11) maps against its unwinding roll's radius too (``roll``): its
tension and dancer modes (``dancer.carriage``, ``span0.tension``, …:
:mod:`winder.analysis.line_modes`) against the parent's rotation ``k v/(2π r)``.

A scene without a winding operating point (no wound roll: no ``[web]``, e.g. a drum alone
on its bearings; or ``[effects] contact = false``) has one row: the modes of the machine at
its initial state (``winder run``'s at ``t = 0``, the imbalance off; the free bodies as
they are, a body nothing holds with a zero eigenvalue), ``radius`` the wound roll's initial
radius (none: NaN), the same columns (:attr:`ModeMap.initial_state`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from winder._args import integer, number, show
from winder._errors import ArgumentError, ArgumentTypeError
from winder.analysis.line_modes import line_summary
from winder.analysis.operating_point import (
    WEB_SPEED_MAX,
    Mode,
    _check_type,
    _core_key,
    _entry_drive,
    _Linearisation,
    _linearisation,
    _radius,
    operating_point,
    winding_reason,
)
from winder.parts.roll import KEYS as ROLL_KEYS
from winder.scene.load import Scene
from winder.scene.naming import BY_PARTS, Naming, naming_of

__all__ = ["Mode", "ModeMap", "operating_point", "modes_at", "mode_map", "MAX_POINTS"]

#: Most radii of one resonance map.
MAX_POINTS = 10_000
#: Largest relative change of a mode's frequency between neighbouring radii at a crossing.
_JUMP = 0.25
#: Harmonics of the roll's rotation drawn and searched for crossings.
ORDERS = (1, 2, 3)
#: A flexible body's bending orders a chart draws (and the CLI reports).
SHOWN_ORDERS = 2
#: [Hz] A mode slower than this (a period beyond 1000 s, far longer than any run) is a free
#: coordinate's (nothing holds it: a zero eigenvalue, split by round-off), not overdamped.
FREE_BELOW = 1e-3


def modes_at(scene: Scene, radius: float | None = None, *, web_speed: float | None = None,
             roll: str | None = None) -> list[Mode]:
    """Modes of the linearised machine at ``radius`` [m] of the wound roll and ``web_speed``
    [m/s] (see :func:`operating_point` for the valid range): the bounce modes, one per free
    translational coordinate in the machine's order (a single-drum scene: its one bounce
    mode first; a flexible body's bending orders where an oscillating mode has that shape),
    then the slip and torsion modes (:mod:`winder.analysis.mode_labels`). A scene without a
    winding operating point (no wound roll, or ``[effects] contact = false``:
    :func:`~winder.analysis.operating_point.winding_reason`) has the modes of its initial
    state: give no ``radius`` (``web_speed`` is checked, and unused). ``roll``: the paper
    roll ``radius`` is of (default the wound roll; a web's unwinding roll: the parent's
    radius, the other paper rolls at their initial radius); a web line's modes are kind
    ``line`` (:mod:`winder.analysis.line_modes`)."""
    _check_type(scene, "modes_at")
    reason = winding_reason(scene)
    if reason is not None:
        _no_radius("modes_at", "radius", radius, scene, reason)
        _no_radius("modes_at", "roll", roll, scene, reason)
        lin = _at_rest(scene, "modes_at", web_speed)
        return lin.modes(lin.initial())
    where = "operating_point"
    lin = _linearisation(scene, where, web_speed, lo_open=False, roll=roll)
    if radius is None:
        raise ArgumentError(f"modes_at: radius is required: {scene.source} winds its roll; "
                            f"valid: a finite radius >= {_core_key(lin)} = {lin.rc:g} m")
    r = _radius(where, lin, radius)
    return lin.modes(lin.solve(r, where))


def _no_radius(where: str, name: str, value: object, scene: Scene, reason: str) -> None:
    """An :class:`ArgumentError` where a radius is given for a scene without a winding
    operating point (``reason``)."""
    if value is not None:
        given = f"{name} = {show(value)}{' m' if isinstance(value, int | float) else ''}" \
            if name != "radii" else "radii given"
        raise ArgumentError(f"{where}: {given}: {scene.source} has {reason}, so no map "
                            "over a wound roll's radius: its modes are those of its initial "
                            f"state; valid: no {name}")


def _at_rest(scene: Scene, where: str, web_speed: float | None) -> _Linearisation:
    """The machine of a scene without a winding operating point, for the modes of its
    initial state; ``web_speed`` [m/s] (``>= 0``) checked."""
    v = math.nan
    if web_speed is not None:
        v = number(where, "web_speed", web_speed, lo=0.0, hi=WEB_SPEED_MAX, unit="m/s")
    elif scene.web is not None:
        v = _entry_drive(scene).drive_web_speed()
    return _Linearisation(scene, v, winding=False)


@dataclass(frozen=True)
class ModeMap:
    """Modes against the wound roll's radius (or, :attr:`unwinding`, an unwinding roll's:
    its web line's modes in :attr:`line`; or, :attr:`initial_state`, one row: the
    modes at the initial state). Arrays over ``radius`` [m]; frequencies
    [Hz]; speeds [m/s].

    ``frequencies``/``dampings``: per bounce mode (``coordinates``, e.g. ``set.x``) its
    damped frequency and damping ratio; ``bounce_frequency``/``bounce_damping``: the mode
    of the wound roll's own ``z`` (the single-drum bounce mode); ``slip_*``: the fastest
    slip/torsion mode (``|λ|/2π``); ``rotation_1x`` the roll's rotation frequency
    ``ratio · v/(2π r)`` at no slip (``ratio`` of the drum the web wraps);
    ``drum_rotation`` each drum's rotation frequency; ``critical_web_speed`` the web speed
    at which 1× meets ``bounce_frequency``."""

    radius: np.ndarray
    frequencies: dict[str, np.ndarray]
    dampings: dict[str, np.ndarray]
    slip_frequency: np.ndarray
    slip_damping: np.ndarray
    rotation_1x: np.ndarray
    web_speed: float
    roll: str
    drum_rotation: dict[str, float] = field(default_factory=dict)
    #: the scene's naming: which columns its table has (:meth:`as_columns`,
    #: :meth:`Naming.mode_map_columns <winder.scene.Naming.mode_map_columns>`)
    naming: Naming = BY_PARTS
    #: per bounce mode its natural frequency ``|λ|/2π`` [Hz] (also where it is overdamped)
    natural: dict[str, np.ndarray] = field(default_factory=dict)
    #: per torsion mode of a flexible body (``BODY.torsion{n}``) its natural frequency
    #: ``|λ|/2π`` [Hz] and damping ratio [-] (< 1: only an oscillating mode of that shape
    #: carries the label); NaN at a radius where no mode has that label (the nips'
    #: friction overdamps it)
    torsion: dict[str, np.ndarray] = field(default_factory=dict)
    torsion_damping: dict[str, np.ndarray] = field(default_factory=dict)
    #: True: one row, the modes of the machine at its initial state, where the scene has no
    #: winding operating point (``initial_reason``: no wound roll, or contact off);
    #: ``radius`` the wound roll's initial radius (none: NaN)
    initial_state: bool = False
    initial_reason: str = ""
    #: per line mode of a web line (``dancer.carriage``, ``guide1.roller``,
    #: ``span0.tension``, ``parent.unwind``: :mod:`winder.analysis.line_modes`) its damped
    #: frequency [Hz] (0 where its eigenvalue is real), damping ratio [-] and natural
    #: frequency ``|λ|/2π`` [Hz]; NaN at a radius where no mode has that label
    line: dict[str, np.ndarray] = field(default_factory=dict)
    line_damping: dict[str, np.ndarray] = field(default_factory=dict)
    line_natural: dict[str, np.ndarray] = field(default_factory=dict)
    #: True: ``radius`` is an unwinding roll's (``roll``, the parent), not the wound roll's
    unwinding: bool = False

    @property
    def coordinates(self) -> list[str]:
        """The bounce modes' labels: a rigid body's ``BODY.x``/``BODY.z``, a flexible
        body's bending orders ``BODY.bend.z1`` … (:mod:`winder.analysis.shapes`)."""
        return list(self.frequencies)

    @property
    def flexible(self) -> bool:
        """Whether the machine has a flexible body (bending and torsion modes)."""
        return any(".bend." in c for c in self.frequencies) or bool(self.torsion)

    def shown(self, orders: int = SHOWN_ORDERS) -> list[str]:
        """The modes a chart draws: every rigid bounce mode, a flexible body's bending
        orders ``n <= orders`` and its torsion order 1."""
        def order(c: str) -> int:
            n = re.search(r"(\d+)$", c)
            return int(n.group(1)) if n else 0
        out = [c for c in self.coordinates if ".bend." not in c or order(c) <= orders]
        return out + [c for c in self.torsion if order(c) == 1]

    def frequency(self, mode: str) -> np.ndarray:
        """The damped frequency [Hz] of a bounce, bending or line mode, or the natural
        frequency of a torsion mode, over :attr:`radius`."""
        for table in (self.frequencies, self.line, self.torsion):
            if mode in table:
                return table[mode]
        raise KeyError(mode)

    @property
    def line_shown(self) -> list[str]:
        """The line modes that oscillate at some radius (a chart draws these)."""
        return [c for c, f in self.line.items() if np.any(f > 0)]

    @property
    def main(self) -> str:
        """The wound roll's vertical mode (``ROLL.z``; flexible: ``ROLL.bend.z1``), else
        the first; ``""`` for a machine without free coordinates. A map over an unwinding
        roll's radius: its line's first dancer carriage (else its first line mode)."""
        if self.unwinding:
            return next((c for c in self.line if c.endswith(".carriage")),
                        next(iter(self.line), ""))
        for z in (f"{self.roll}.z", f"{self.roll}.bend.z1"):
            if self.roll and z in self.frequencies:
                return z
        return self.coordinates[0] if self.coordinates else ""

    @property
    def bounce_frequency(self) -> np.ndarray:
        """:attr:`main`'s damped frequency [Hz]."""
        return {**self.frequencies, **self.line}.get(self.main,
                                                    np.full(len(self.radius), np.nan))

    @property
    def bounce_damping(self) -> np.ndarray:
        return {**self.dampings, **self.line_damping}.get(self.main,
                                                          np.full(len(self.radius), np.nan))

    def overdamped(self, mode: str | None = None) -> list[tuple[float, float]]:
        """The radius ranges ``(first, last)`` [m] over which a bounce mode (default
        :attr:`main`) is overdamped: its eigenvalue is real (damping ratio 1, damped
        frequency 0), so it has no oscillation and no crossing there (the nips' damping and
        the friction relaxation couple into it); not where its eigenvalue is zero (a free
        coordinate: nothing holds it; ``|λ|/2π`` below :data:`FREE_BELOW`)."""
        mode = mode or self.main
        over = (self.frequencies[mode] == 0.0) & (self.natural[mode] >= FREE_BELOW) \
            if mode in self.natural else self.frequencies[mode] == 0.0
        out, i = [], 0
        while i < len(over):
            if over[i]:
                j = i
                while j + 1 < len(over) and over[j + 1]:
                    j += 1
                out.append((float(self.radius[i]), float(self.radius[j])))
                i = j
            i += 1
        return out

    @property
    def rotation_2x(self) -> np.ndarray:
        return 2 * self.rotation_1x

    @property
    def critical_web_speed(self) -> np.ndarray:
        return self.web_speed * self.bounce_frequency / self.rotation_1x

    def harmonics(self) -> dict[str, np.ndarray]:
        """The excitation lines [Hz] over ``radius``: ``1x``, ``2x``, ``3x`` of the roll's
        rotation and ``DRUM`` (each drum's rotation, constant; equal drums merged)."""
        out = {f"{k}x": k * self.rotation_1x for k in ORDERS}
        seen: list[float] = []
        for f in self.drum_rotation.values():
            if not any(abs(f - s) <= 1e-12 * abs(s) for s in seen):
                seen.append(f)
                same = [n for n, g in self.drum_rotation.items() if abs(g - f) <= 1e-12 * f]
                key = "drum" if same == ["drum"] else "drum " + "/".join(same)
                out[key] = np.full(len(self.radius), f)
        return out

    def critical_radii(self, order: int | str = 1, mode: str | None = None) -> list[float]:
        """Radii [m] where a harmonic (``order`` ``k`` for ``k × f₁``, or a key of
        :meth:`harmonics`) crosses a bounce mode (``mode``, default :attr:`main`), by
        linear interpolation; only where the mode oscillates on both sides and its
        frequency changes by less than 25 % between the two radii."""
        line = self.harmonics()[f"{order}x" if isinstance(order, int) else order]
        mode = mode or self.main
        if mode in self.frequencies or mode in self.line:
            f = self.frequency(mode)
        else:  # a torsion mode's |λ|/2π: not where it is overdamped (a real root)
            f = np.where(self.torsion_damping[mode] < 1.0, self.torsion[mode], np.nan)
        d = f - line
        out = []
        # a crossing of an oscillating mode whose frequency moves continuously (less than
        # _JUMP between neighbours): not where the mode turns overdamped (f → 0) or where
        # its eigenvalue branch changes
        a, b = f[:-1], f[1:]
        ok = (np.isfinite(d[:-1]) & np.isfinite(d[1:]) & (a > 0) & (b > 0)
              & (np.abs(b - a) <= _JUMP * np.maximum(a, b)))
        for i in np.nonzero(ok & (np.sign(d[:-1]) * np.sign(d[1:]) < 0))[0]:
            s = d[i] / (d[i] - d[i + 1])
            out.append(float(self.radius[i] + s * (self.radius[i + 1] - self.radius[i])))
        return out

    def crossings(self, modes: list[str] | None = None) -> list[tuple[str, str, float]]:
        """Every crossing ``(mode, harmonic, radius [m])`` of the bounce, bending and
        torsion modes (or of ``modes``, e.g. :meth:`shown`) with the harmonics."""
        modes = [*self.coordinates, *self.torsion, *self.line_shown] if modes is None \
            else modes
        return [(c, h, rc) for c in modes for h in self.harmonics()
                for rc in self.critical_radii(h, c)]

    def summary(self) -> list[str]:
        """The lines ``winder modes`` prints: each bounce mode from the first to the last
        radius (where it is overdamped), then where each harmonic meets it; a flexible
        machine: the modes :meth:`shown` and only the crossings found (a bending or torsion
        mode from its first to its last radius where an oscillating mode has its shape); a
        map of the initial state: each mode at it."""
        if self.initial_state:
            return self._initial_summary()
        if self.unwinding:
            return self._line_summary()
        if self.flexible:
            out = []
            for c in self.shown():
                f = self.frequencies.get(c, self.torsion.get(c))
                kind = "torsion" if c in self.torsion else \
                    "bending" if ".bend." in c else "bounce"
                ok = np.nonzero(np.isfinite(f))[0]
                out.append(f"{kind} mode {c} {f[ok[0]]:.1f} -> {f[ok[-1]]:.1f} Hz"
                           + ("" if len(ok) == len(f) else
                              f" (found at {len(ok)} of {len(f)} radii)")
                           if len(ok) else f"{kind} mode {c}: no oscillating mode of this "
                           "shape over the map")
            crossings = self.crossings(self.shown())
            out += [f"{h} rotation meets {c} at r = {rc:.4f} m" for c, h, rc in crossings]
            return out or ["no harmonic meets these modes over the map's radii"]
        one = len(self.coordinates) == 1
        out = []
        for c in self.coordinates:
            f, z = self.frequencies[c], self.dampings[c]
            name = "" if one else " " + c
            out.append(f"bounce mode{name} {f[0]:.1f} -> {f[-1]:.1f} Hz, "
                       f"damping ratio {z[0]:.3f} -> {z[-1]:.3f}")
            out += [f"bounce mode{name} is overdamped (real eigenvalue, no oscillation, no "
                    f"crossing) at r = {lo:.4f}-{hi:.4f} m" for lo, hi in self.overdamped(c)]
        for c in self.coordinates:
            for h in self.harmonics():
                crit = self.critical_radii(h, c)
                out.append(f"{h} rotation meets the bounce mode{'' if one else ' ' + c} at "
                           "r = " + (", ".join(f"{x:.4f} m" for x in crit) if crit
                                     else "(no crossing)"))
        return out

    def _line_summary(self) -> list[str]:
        """The lines of a map over an unwinding roll's radius (:func:`line_summary`)."""
        return line_summary(self)

    def _initial_summary(self) -> list[str]:
        """The lines of a map of the initial state: each bounce or bending mode (a flexible
        body's :meth:`shown` orders) and torsion mode at it, the slowest slip mode, the
        drums' rotation."""
        out = []
        shown = self.shown() if self.flexible else self.coordinates
        for c in shown:
            f = self.frequencies.get(c, self.torsion.get(c))[0]
            z = self.dampings[c][0] if c in self.dampings else self.torsion_damping[c][0]
            kind = "torsion" if c in self.torsion else "bending" if ".bend." in c \
                else "bounce"
            if not np.isfinite(f):
                out.append(f"{kind} mode {c}: no oscillating mode of this shape")
            elif c in self.natural and self.natural[c][0] < FREE_BELOW:
                out.append(f"{kind} mode {c} 0 Hz: free, nothing holds it (|λ|/2π = "
                           f"{self.natural[c][0]:.2g} Hz: a zero eigenvalue)")
            elif c in self.frequencies and f == 0.0:
                out.append(f"{kind} mode {c} overdamped (real eigenvalue, "
                           f"|λ|/2π = {self.natural[c][0]:.1f} Hz)")
            else:
                out.append(f"{kind} mode {c} {f:.1f} Hz, damping ratio {z:.3f}")
        if not shown:
            out.append("no free coordinate and no flexible body: no bounce, bending or "
                       "torsion mode")
        if np.isfinite(self.slip_frequency[0]):
            out.append(f"slowest slip mode |λ|/2π = {self.slip_frequency[0]:.1f} Hz, damping "
                       f"ratio {self.slip_damping[0]:.3f}")
        out += [f"{name} rotation {f:.2f} Hz" for name, f in self.drum_rotation.items()]
        return out

    def as_columns(self) -> dict[str, np.ndarray]:
        """The CSV table: the main bounce mode, every bounce mode (``BODY_x_frequency``,
        ``BODY_x_damping``, ...), the slip mode, the harmonics and the drums' rotation
        frequencies, as the scene's naming has them (a single-drum scene: the historic
        columns)."""
        cols = {"radius": self.radius, "bounce_frequency": self.bounce_frequency,
                "bounce_damping": self.bounce_damping}
        for c in self.coordinates:
            key = c.replace(".", "_")
            cols[f"{key}_frequency"] = self.frequencies[c]
            cols[f"{key}_damping"] = self.dampings[c]
        for c, f in self.torsion.items():
            key = c.replace(".", "_")
            cols[f"{key}_frequency"] = f
            cols[f"{key}_damping"] = self.torsion_damping[c]
        for c, f in self.line.items():
            key = c.replace(".", "_")
            cols[f"{key}_frequency"] = f
            cols[f"{key}_damping"] = self.line_damping[c]
            cols[f"{key}_natural_frequency"] = self.line_natural[c]
        cols.update({"slip_frequency": self.slip_frequency, "slip_damping": self.slip_damping,
                     "rotation_1x": self.rotation_1x, "rotation_2x": self.rotation_2x,
                     "rotation_3x": 3 * self.rotation_1x})
        for name, f in self.drum_rotation.items():
            cols[f"{name}_rotation"] = np.full(len(self.radius), f)
        cols["critical_web_speed"] = self.critical_web_speed
        return self.naming.mode_map_columns(cols)


def wound_length(scene: Scene, v: float) -> float:
    """Paper [m] the web brings in over the scene's duration at web speed ``v`` [m/s]:
    the drum the web wraps ramps at its ``web_acceleration`` to ``v`` (none: ``v`` from
    the start)."""
    return _entry_drive(scene).web_length(scene.scene.duration, v)


def _radius_range(where: str, lin: _Linearisation, scene: Scene, v: float,
                  radius_min: float | None, radius_max: float | None,
                  names: tuple[str, str]) -> tuple[float, float]:
    """``(r_min, r_max)`` [m] of a map: the arguments (``names`` in messages) or the
    roll's initial radius and its radius at the end of the scene's run."""
    roll, rc = lin.roll, lin.rc
    key = _core_key(lin)
    hi = ROLL_KEYS["initial_radius"].hi
    if lin.unwinding and radius_max is None:  # the parent from empty (its core) to full
        radius_max = roll.initial_radius
    if radius_min is None:
        lo = rc if lin.unwinding else roll.initial_radius
    else:
        lo = number(where, names[0], radius_min, lo=rc, hi=hi, unit="m",
                    valid=f"a finite radius >= {key} = {rc:g} m and <= {hi:g} m")
    if radius_max is None:
        end = roll.radius_after(wound_length(scene, v))
        if not end > lo:
            raise ArgumentError(f"{where}: {names[0]} = {lo:g} m is not below the wound "
                                f"roll's radius at the end of the run ({end:g} m, from the "
                                f"scene's duration); valid: a smaller {names[0]}, or give "
                                f"{names[1]} too")
        return lo, end
    below = "the roll's initial radius" if radius_min is None and not lin.unwinding \
        else f"the roll's core radius ({key})" if radius_min is None else names[0]
    up = number(where, names[1], radius_max, lo=lo, lo_open=True, hi=hi, unit="m",
                valid=f"a finite radius > {below} = {lo:g} m and <= {hi:g} m")
    return lo, up


def mode_map(scene: Scene, radii: np.ndarray | None = None, *,
             web_speed: float | None = None, n: int = 200, radius_min: float | None = None,
             radius_max: float | None = None, roll: str | None = None,
             progress: Callable[[int, int], object] | None = None,
             _names: tuple[str, str] = ("radius_min", "radius_max")) -> ModeMap:
    """The resonance map over ``radii`` [m] of the wound roll (each ``>=`` its core
    radius; default: ``n`` points, 2 … 10 000, from ``radius_min`` [m] (default its initial
    radius) to ``radius_max`` [m] (default its radius at the end of the scene's run, winding
    one caliper per revolution at no slip: ``r² = r₀² + h L/π`` with ``L`` the paper brought
    in by the drive's ramp and full speed)) at ``web_speed`` [m/s] (``> 0``; default the
    scene's). Each radius starts from the operating point of the one before (continuation).
    ``progress``: a callable ``(done, total)`` called before the first radius (``done`` 0)
    and after each (a progress bar), or None.
    A scene without a winding operating point (no wound roll, or ``[effects] contact =
    false``) gives one row, the modes of its initial state (:attr:`ModeMap.initial_state`;
    ``n`` checked and unused, ``web_speed`` [m/s] ``>= 0`` only for the drums' rotation,
    default each drum's own).

    ``roll`` names the paper roll whose radius the map follows: the wound roll (default),
    or a web's unwinding roll (the parent): then the map holds its web line's tension and
    dancer modes (:attr:`ModeMap.line`, :mod:`winder.analysis.line_modes`) against the
    parent's radius, from its core radius (empty; default ``radius_min``) to its initial
    radius (full; default ``radius_max``), the wound roll at its initial radius, and the
    harmonics are the parent's rotation ``v/(2π r)``.

    Raises
    ------
    ArgumentError: ``n``, ``radii`` or ``web_speed`` out of range, a scene whose winding
        operating point cannot be found (see :func:`operating_point`), or radii given for
        a scene without one.
    """
    where = "mode_map"
    _check_type(scene, where)
    reason = winding_reason(scene)
    if reason is not None:  # one row: the modes of the initial state
        integer(where, "n", n, lo=2, hi=MAX_POINTS)  # checked, unused
        for name, value in (("radii", radii), (_names[0], radius_min),
                            (_names[1], radius_max), ("roll", roll)):
            _no_radius(where, name, value, scene, reason)
        return _initial_map(scene, where, web_speed, reason)
    lin = _linearisation(scene, where, web_speed, lo_open=True, roll=roll)
    v, rc = lin.v, lin.rc
    if radii is None:
        n = integer(where, "n", n, lo=2, hi=MAX_POINTS)
        radii = np.linspace(*_radius_range(where, lin, scene, v, radius_min, radius_max,
                                           _names), n)
    elif radius_min is not None or radius_max is not None:
        raise ArgumentError(f"{where}: give radii or {_names[0]}/{_names[1]}, not both")
    try:
        radii = np.asarray(radii, dtype=float)
    except (TypeError, ValueError):
        raise ArgumentTypeError(f"{where}: radii must be an array of radii [m], got "
                                f"{show(radii)} ({type(radii).__name__})") from None
    if radii.ndim != 1 or not 1 <= len(radii) <= MAX_POINTS:
        raise ArgumentError(f"{where}: radii must be a 1-D array of 1 … {MAX_POINTS} radii, "
                            f"got shape {radii.shape}")
    bad = ~(np.isfinite(radii) & (radii >= rc))
    if bad.any():
        i = int(np.argmax(bad))
        key = _core_key(lin)
        raise ArgumentError(f"{where}: radii[{i}] = {float(radii[i])!r} is out of range; "
                            f"valid: finite radii >= {key} = {rc:g} m")
    rows = []
    prev = None
    if progress is not None:
        progress(0, len(radii))
    for r in radii:  # continued in radius from the previous point
        if prev is None:
            start, guess = None, None
        else:
            start, guess = lin.continued(float(r), where, prev)
        y = lin.solve(float(r), where, start)
        prev = (y, guess if guess is not None else lin.guess(float(r)))
        rows.append(lin.modes(y))
        if progress is not None:
            progress(len(rows), len(radii))
    drums = {b.segment_of or b.name: b.operating_speed(v) / (2 * math.pi)
             for b in lin.machine.bodies if b.prescribed}  # a flexible drum by its name
    surface = lin.machine.entry.a.surface_speed(v)  # the roll's surface: ratio · v
    return _assembled(lin, scene, radii, rows, surface / (2 * math.pi * radii), drums)


def _assembled(lin: _Linearisation, scene: Scene, radii: np.ndarray, rows: list[list[Mode]],
               rotation_1x: np.ndarray, drums: dict[str, float], reason: str = ""
               ) -> ModeMap:
    """The :class:`ModeMap` of the modes ``rows`` (one list per radius of ``radii``)."""
    nt = len(lin.labels)
    torsion: dict[str, np.ndarray] = {}
    tdamp: dict[str, np.ndarray] = {}
    freq = np.full((nt, len(radii)), np.nan)
    damp = np.full((nt, len(radii)), np.nan)
    natural = np.full((nt, len(radii)), np.nan)
    slip = np.full((2, len(radii)), np.nan)
    line: dict[str, np.ndarray] = {}  # label -> (frequency, damping, natural) rows
    for i, ms in enumerate(rows):
        for m in ms:
            if m.kind == "line":
                row = line.setdefault(m.coordinate, np.full((3, len(radii)), np.nan))
                row[:, i] = m.frequency, m.damping_ratio, m.natural_frequency
            if m.kind in ("bounce", "bending"):
                j = lin.labels.index(m.coordinate)
                freq[j, i], damp[j, i] = m.frequency, m.damping_ratio
                natural[j, i] = m.natural_frequency
            elif m.kind == "torsion":  # each label on one oscillating mode
                f = torsion.setdefault(m.coordinate, np.full(len(radii), np.nan))
                d = tdamp.setdefault(m.coordinate, np.full(len(radii), np.nan))
                f[i], d[i] = m.natural_frequency, m.damping_ratio
        slips = [m for m in ms if m.kind == "slip"]
        if slips:
            slip[:, i] = slips[0].natural_frequency, slips[0].damping_ratio
    order = sorted(torsion, key=lambda c: (c.rsplit(".", 1)[0], int(c.rsplit("n", 1)[1])))
    roll = "" if lin.roll is None else lin.roll.segment_of or lin.roll.name
    return ModeMap(radii, dict(zip(lin.labels, freq, strict=True)),
                   dict(zip(lin.labels, damp, strict=True)), slip[0], slip[1], rotation_1x,
                   lin.v, roll, drums, naming_of(scene),
                   dict(zip(lin.labels, natural, strict=True)),
                   {c: torsion[c] for c in order}, {c: tdamp[c] for c in order},
                   initial_state=bool(reason), initial_reason=reason,
                   line={c: x[0] for c, x in line.items()},
                   line_damping={c: x[1] for c, x in line.items()},
                   line_natural={c: x[2] for c, x in line.items()},
                   unwinding=lin.unwinding)


def _initial_map(scene: Scene, where: str, web_speed: float | None, reason: str) -> ModeMap:
    """The one-row map of a scene without a winding operating point (``reason``): the
    modes of its initial state; ``radius`` the wound roll's initial radius (none: NaN), the
    drums' rotation at ``web_speed`` (default: each drum's own drive ``web_speed``)."""
    lin = _at_rest(scene, where, web_speed)
    y = lin.initial()
    drums = {}
    for b in lin.machine.bodies:
        if b.prescribed:
            v = b.drive_web_speed() if web_speed is None else lin.v
            drums[b.segment_of or b.name] = b.operating_speed(v) / (2 * math.pi)
    r = np.array([y[lin.i_r] if lin.roll is not None else math.nan])
    surface = lin.machine.entry.a.surface_speed(lin.v) if lin.roll is not None else math.nan
    return _assembled(lin, scene, r, [lin.modes(y)], surface / (2 * math.pi * r), drums,
                      reason)
