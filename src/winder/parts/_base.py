"""The part protocol: what one body of the machine brings to it.

A scene's part (the frozen dataclass read from its table, e.g. :class:`DrumPart`) is data;
its behaviour is a :class:`BodyElement` beside it in the same module (``DrumBody`` for
``[[drum]]``). The element class is also the body type's registration record: its
table (:attr:`~BodyElement.table`), keys (:attr:`~BodyElement.KEYS`, sub-tables
:attr:`~BodyElement.SUB_TABLES`), part dataclass (:attr:`~BodyElement.part_cls`) and
parser (:meth:`~BodyElement.parse`). :class:`~winder.model.machine.Machine` assembles
the body elements and the force elements of :mod:`winder.forces` without knowing which
kinds there are, and the scene (its tables, parsing, checks, ``to_dict``, the generated
reference) and the viewer read the registry :data:`winder.parts.PARTS`: a new body type is
its module plus one line there.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, Protocol

from winder._schema import Channel, Table
from winder.model.roles import NIP_ROLES, WEB_ROLES, Roles, Segment

if TYPE_CHECKING:
    from winder.model.machine import BodyState, Evaluation, Machine

__all__ = ["BodyElement", "RigidDisc", "SubTable", "TableReader", "Drawing", "Roles", "Segment",
           "WEB_ROLES", "NIP_ROLES", "segment_count"]


def segment_count(part: Any) -> int | None:
    """The number of segments of a part with a ``flex`` sub-table (None: rigid)."""
    flex = getattr(part, "flex", None)
    return None if flex is None else int(flex.segments)

@dataclass(frozen=True)
class SubTable:
    """A sub-table of a body's table (a drum's ``drive``): its keys, the dataclasses whose
    field defaults the reference shows for keys that declare none, and its heading in the
    reference after ``[[TABLE]]`` (None: the key's name)."""

    keys: Table
    defaults: tuple[type, ...] = ()
    heading: str | None = None


class TableReader(Protocol):
    """What :meth:`BodyElement.parse` reads a scene table with (the scene's parser,
    :mod:`winder.scene.parts`): every error names the file, the table and the key."""

    #: the scene file (messages)
    source: str
    #: the scene's ``[paper]`` (:class:`~winder.scene.tables.Paper`) or None
    paper: Any
    #: the scene's ``[effects]`` (:class:`~winder.scene.tables.Effects`)
    effects: Any

    def keys(self, label: str, raw: Any, table: Table) -> dict[str, Any]:
        """The keys of ``raw`` checked against ``table`` (sub-tables left out)."""

    def kinds(self, label: str, parsed: Mapping[str, Any], table: Table) -> None:
        """Every key of ``parsed`` belongs to its ``kind`` (``table.kinds``)."""

    def fail(self, label: str, key: str, message: str) -> Exception:
        """The error of ``key`` of ``[label]``."""


@dataclass(frozen=True)
class Drawing:
    """How the viewer draws a body, whatever its type: a cylinder along ``y`` with a radial
    mark.

    colour: a colour key of the viewer (``drum``, ``rider``, ...; an unknown one: the
    drum's). width: its own length along ``y`` [m] (None: the machine's, 1.05 × the widest
    body's width). width_of: the name of a body whose width it takes (a rider: the roll
    it rides). core_radius: a paper roll's core [m] (then a core, a paper cylinder scaled
    by its radius state, and a centre-of-mass marker at com_offset [m]). y: its centre
    along the axis [m] from the machine's mid-width (a segment of a flexible body)."""

    colour: str = "drum"
    width: float | None = None
    width_of: str | None = None
    core_radius: float | None = None
    com_offset: float = 0.0
    y: float = 0.0


class BodyElement(ABC):
    """Base class of the bodies of a machine (drums, paper rolls, riders, ...).

    A body is a disc in the ``x``–``z`` plane turning about ``+y`` (machines.md §1). The
    machine gives it its joints (prismatic ``x``/``z`` where :attr:`free`, then a revolute
    ``θ``), its joint-coordinate states ``NAME.x``, ``NAME.z``, ``NAME.theta`` and their
    rates ``NAME.x_dot``, ..., the generic channels (``NAME_speed`` [rad/s],
    ``NAME_angle`` [rad], ``NAME_torque`` [N·m], ``NAME_accel`` [rad/s²], ``NAME_x``
    [m], ...) and the dynamics (Pinocchio's ABA). The element says everything else.

    To add a body type: the machine, the solvers, the generated code, the static balance,
    the scene (its tables, parsing, checks, ``to_dict``), the generated reference, the FMU's
    parameters and the viewer's scene graph read it from here. The scene's checks and the
    effects ask its declared roles (:meth:`roles_of`, :class:`~winder.model.roles.Roles`:
    how it carries a web, bears on a nip, whether it is a paper roll or a flexible body of
    segments), never its table's name; the figures draw a body by :attr:`role`.

    1. Subclass :class:`BodyElement` (or :class:`RigidDisc` for a body of constant radius,
       mass and inertia) in the part's module under ``winder/parts/``; set the class
       variables :attr:`table` (the scene's array of tables: messages name its keys as
       ``[[drum]] 'front' centre``), :attr:`KEYS` (its keys, :class:`~winder._schema.Table`;
       sub-tables :attr:`SUB_TABLES`), :attr:`part_cls` (its frozen dataclass),
       :attr:`role` (how the figures draw it: ``"drum"``, ``"roll"`` or ``"rider"``),
       :attr:`place_key` (the key that places it) and, where they apply,
       :attr:`radius_state` (its radius is a state and a ``NAME_radius`` channel) and
       :attr:`variable_mass` (its mass properties change: the ``variable_mass`` effect
       adds ``−Ẏv``).
    2. In ``__init__(part, placed)`` (``placed``: the bodies built before it, by name)
       call ``super().__init__(part)`` and set :attr:`free` (the translational axes
       among ``("x", "z")``, in that order), :attr:`centre` [m] (the fixed coordinates,
       and the initial guess of the free ones), :attr:`parent` (the name of an earlier
       body it hangs off, whose joint frame its centre is then given in; ``None``: the
       world) and :attr:`prescribed` (its rotation is a function of time: no ``θ``
       state). :attr:`drives` names the force elements its drive calls for
       (``("tension_control",)``); :attr:`torque_inputs` and :attr:`setpoint_inputs`
       its run-time parameters that are inputs of a co-simulation (``NAME.torque``,
       ``NAME.tension_setpoint``); :attr:`com_offset` [m] its centre-of-mass offset for
       the ``imbalance`` effect (None: none).
    3. :meth:`declare`: its run-time parameters (``machine.parameter(name, value)``),
       the states beyond its joint coordinates with their initial values (spec §7,
       ``machine.state``), its locked modes (``machine.mode(name, switches,
       ModeKind..., owner=NAME)``); :attr:`CHANNELS` its own channels (declared once, with
       their units; the machine registers them); :meth:`initial_rate` the initial rate of a
       joint coordinate (spec §7).
    4. :meth:`kinematics`: over the math namespace ``ev.mathns`` (floats or CasADi
       symbols: branch on states only with ``if_else``/``fmax``) its radius ``r`` [m]
       and rate ``r_dot`` [m/s], ``mass`` [kg], ``inertia`` [kg·m²] and their
       derivatives ``dm_dr`` [kg/m], ``dJ_dr`` [kg·m]; with :attr:`prescribed` also
       ``theta`` [rad], ``omega`` [rad/s] and ``alpha_prescribed`` [rad/s²]; the rates
       of its own states (``ev.set_rate``) and its switching functions
       (``ev.switches[name]``).
    5. Optional: :meth:`transverse_inertia` (default ``J/2``, a thin disc),
       :meth:`drive_torque` (an input torque [N·m], operation sense),
       :meth:`outputs` (its channels, ``ev.set_channel``), :meth:`fixed_at_rest`
       (coordinates the static balance does not solve for), :attr:`bearing_axes` (those
       it solves for even without contact), :meth:`breakpoints` (times
       [s] where its prescribed motion has a kink), :meth:`operating_speed` and
       :meth:`hold_operating_speed` (a prescribed drive at a given web speed, for the
       resonance map), :meth:`structure_tag`
       (what changes its generated code beyond its names); for the analyses
       :attr:`least_radius`, :meth:`radius_after` (its growth law integrated),
       :meth:`drive_web_speed`, :meth:`surface_speed` and :meth:`web_length`.
    6. Scene side, where the defaults do not do: :meth:`parse` (its part from its raw
       table: the default checks :attr:`KEYS` and builds :attr:`part_cls`; sub-tables and
       checks across keys need their own), :meth:`roles_of` (its roles:
       the scene's reference, nip and web checks and the effects read them) and
       :meth:`initial_circle` (the overlap check), :meth:`drawing` (the viewer's shape and
       colour).
    7. Register it: one line in :data:`winder.parts.PARTS` (scene attribute → class);
       the scene then reads ``[[TABLE]]`` and lists its parts as ``scene.ATTRIBUTE``.

    Example: a disc of constant radius on a fixed axis under a constant torque, a scene's
    ``[[disc]]`` (in ``winder/parts/disc.py``, plus ``PARTS["discs"] = DiscBody``)::

        @dataclass(frozen=True)
        class DiscPart:               # keys, units and bounds: KEYS
            name: str
            radius: float
            inertia: float
            mass: float
            centre: tuple[float, float]
            torque: float = 0.0

        class DiscBody(RigidDisc):
            table, role, part_cls = "disc", "drum", DiscPart
            KEYS = Table((NAME, Key(name="radius", ...), ..., CENTRE, Key(name="torque",
                          unit="N·m", doc="the drive torque")))

            def __init__(self, part, placed):
                super().__init__(part)
                self.free, self.centre = (), tuple(part.centre)
                self.torque_inputs = (f"{self.name}.torque",)

            def declare(self, machine):
                super().declare(machine)          # radius, inertia, mass
                machine.parameter(f"{self.name}.torque", self.part.torque)

            def initial_rate(self, coord):
                return 0.0

            def drive_torque(self, ev):
                return ev.p(f"{self.name}.torque")

    It then runs in every solver and in the generated code:
    ``θ̇(t) = τ t / J`` [rad/s] (``tests/test_part_protocol.py``).
    """

    #: the scene's array of tables (``[[drum]]``): error messages name keys by it
    table: ClassVar[str]
    #: the keys of ``[[TABLE]]``, each declared once (parser, messages, reference, FMU)
    KEYS: ClassVar[Table]
    #: its sub-tables by key (a drum's ``drive``), in the reference after its table
    SUB_TABLES: ClassVar[Mapping[str, SubTable]] = {}
    #: the frozen dataclass of its part (the scene's data)
    part_cls: ClassVar[type]
    #: how the figures draw it: ``"drum"``, ``"roll"`` or ``"rider"`` (the viewer reads
    #: :meth:`drawing`)
    role: ClassVar[str]
    #: the scene key that places it (``centre``; a rider: ``x``)
    place_key: ClassVar[str] = "centre"
    #: its own result channels (after the generic ones of every body), each
    #: ``BODY``/``ROLL``/``RIDER``-named: the machine registers them for it
    CHANNELS: ClassVar[tuple[Channel, ...]] = ()
    #: its radius is the state ``NAME.radius`` and the channel ``NAME_radius`` [m]
    radius_state: ClassVar[bool] = False
    #: its mass properties change in time (the ``variable_mass`` effect applies)
    variable_mass: ClassVar[bool] = False
    #: the free axes an elastic support holds it along (a flexible body's bearings, a
    #: roll's chucks, a rider's arms): the static balance solves them whether or not
    #: anything rests on it (:func:`~winder.solve.equilibrium.balance_unknowns`)
    bearing_axes: tuple[str, ...] = ()

    #: the axes its bearings hold against a beam's deflection (a flexible body's segment;
    #: rigid bodies: none)
    bearing_axes: tuple[str, ...] = ()

    def __init__(self, part: Any) -> None:
        self.part = part
        self.name: str = part.name
        #: what it is to the rest of the machine (:meth:`roles_of` its part)
        self.roles: Roles = type(self).roles_of(part)
        self.sense: int = int(getattr(part, "sense", 1))
        self.free: tuple[str, ...] = ()
        self.centre: tuple[float, float] = (0.0, 0.0)
        self.parent: str | None = None
        self.prescribed = False
        self.drives: tuple[str, ...] = ()
        self.torque_inputs: tuple[str, ...] = ()
        self.setpoint_inputs: tuple[str, ...] = ()
        #: paper winds onto it: its radius grows with its web (a wound roll)
        self.winds = False
        #: its centre of mass offset [m] for the ``imbalance`` effect (None: no imbalance)
        self.com_offset: float | None = None
        #: a segment of a flexible body: that body's name (its nips are sliced), else None
        self.segment_of: str | None = None
        #: a segment: the axes its whole body's rigid self is free along, whose ``x``, ``z``
        #: channels the whole body keeps (:mod:`winder.model.whole_body`); None: :attr:`free`
        self.whole_free: tuple[str, ...] | None = None
        #: Pinocchio joint ids by coordinate (``x``, ``z``, ``theta``), set by the machine
        self.joints: dict[str, int] = {}

    # ---- scene ------------------------------------------------------------------------
    @classmethod
    def parse(cls, reader: TableReader, label: str, raw: Any) -> Any:
        """Its part from the raw table ``raw`` of ``[label]`` (``disc 'd1'``): each key
        checked against :attr:`KEYS`, then :attr:`part_cls` of them (override for
        sub-tables, defaults from ``[paper]`` and checks across keys)."""
        return cls.part_cls(**reader.keys(label, raw, cls.KEYS))

    @classmethod
    def elements(cls, part: Any, placed: Mapping[str, BodyElement]) -> list[BodyElement]:
        """The body elements of its part ``part`` (``placed``: those built before, by
        name): default one, ``cls(part, placed)``; a flexible body its segments."""
        return [cls(part, placed)]

    @classmethod
    def roles_of(cls, part: Any) -> Roles:
        """Its roles for the part ``part`` (:class:`Roles`): default none beyond a fixed
        centre (a body that carries no web, bears on a nip with a fixed centre, is rigid
        and no paper roll)."""
        return Roles()

    @classmethod
    def fixed_centre(cls, part: Any) -> bool:
        """Whether its centre is fixed (a nip needs one body free to move): its roles'
        ``nip == "fixed"``."""
        return cls.roles_of(part).fixed

    @property
    def segment(self) -> Segment | None:
        """Itself as a segment of a flexible body (:class:`Segment`), or None (rigid)."""
        return self if self.segment_of is not None else None  # type: ignore[return-value]

    @classmethod
    def initial_circle(cls, part: Any) -> tuple[tuple[float, float], float] | None:
        """Its centre ``(x, z)`` [m] and radius [m] at the start, for the scene's overlap
        check (None: left out); default from the part's ``centre`` and ``radius``."""
        centre, radius = getattr(part, "centre", None), getattr(part, "radius", None)
        return None if centre is None or radius is None else (tuple(centre), radius)

    def drawing(self) -> Drawing:
        """How the viewer draws it (default: a cylinder as long as the machine, in the
        drum's colour)."""
        return Drawing()

    # ---- structure ----------------------------------------------------------------------
    @property
    @abstractmethod
    def initial_radius(self) -> float:
        """Its radius [m] at ``t = 0`` (placing the bodies that rest on it)."""

    @abstractmethod
    def declare(self, machine: Machine) -> None:
        """Register its parameters, its own states and its modes (once)."""

    @abstractmethod
    def initial_rate(self, coord: str) -> float:
        """Initial rate of joint coordinate ``coord`` (``x``, ``z`` [m/s], ``theta``
        [rad/s], the joint's sense), spec §7."""

    def fixed_at_rest(self) -> Mapping[str, float]:
        """Free coordinates held at a given value [m] in the static balance (default:
        none, the balance solves for every free coordinate)."""
        return {}

    def breakpoints(self) -> tuple[float, ...]:
        """Times [s] where its prescribed motion has a kink (the integrators stop there)."""
        return ()

    def operating_speed(self, web_speed: float) -> float:
        """Its speed [rad/s] (operation sense) once a prescribed drive runs at
        ``web_speed`` [m/s] (the operating point of the resonance map); only where
        :attr:`prescribed`."""
        raise NotImplementedError(f"{self!r} has no prescribed operating speed")

    def hold_operating_speed(  # noqa: B027 - optional hook
            self, machine: Machine, params: Any, web_speed: float) -> None:
        """Set its run-time parameters in ``params`` so that a prescribed drive runs at
        ``web_speed`` [m/s] from ``t = 0`` (default: nothing to set)."""

    def radius_of(self, y: Any, machine: Machine) -> float:
        """Its radius [m] in state ``y``."""
        if self.radius_state:
            return float(y[machine.index(f"{self.name}.radius")])
        return float(self.part.radius)

    def structure_tag(self) -> str:
        """Everything about it that changes the generated code, beyond its names."""
        return f"{type(self).__name__}:{self.sense}:{self.prescribed}:{','.join(self.drives)}" \
            f":{','.join(self.torque_inputs)}:{self.parent}"

    # ---- per evaluation -----------------------------------------------------------------
    @abstractmethod
    def kinematics(self, ev: Evaluation, bs: BodyState) -> None:
        """Its radius, mass properties (and prescribed rotation), own rates, switches."""

    def transverse_inertia(self, ev: Evaluation, mass: Any, inertia: Any) -> Any:
        """Its inertia [kg·m²] about a diameter through the centre, from its ``mass``
        [kg] and polar ``inertia`` [kg·m²] (or their rates): a thin disc ``J/2``."""
        return 0.5 * inertia

    def drive_torque(self, ev: Evaluation) -> Any:
        """Its input torque [N·m] (operation sense), or None (not torque-driven)."""
        return None

    def outputs(self, ev: Evaluation, bs: BodyState) -> None:  # noqa: B027 - optional
        """Write its own channels (``ev.set_channel``)."""

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"

    # ---- for the analyses (operating point, resonance map, sweep bands) ----------------
    #: the scene key of its smallest radius (:attr:`least_radius`), for messages
    least_radius_key: ClassVar[str] = "radius"

    @property
    def least_radius(self) -> float:
        """Its smallest radius [m] (a wound roll's core; default: its initial radius)."""
        return self.initial_radius

    def radius_after(self, length: float) -> float:
        """Its radius [m] once ``length`` [m] of web has wound onto it at no slip (default:
        constant, :attr:`initial_radius`)."""
        return self.initial_radius

    def drive_web_speed(self) -> float | None:
        """The surface (web) speed [m/s] its drive names (a speed profile's full speed, a
        torque drive's initial one), or None (no drive speed)."""
        return None

    def surface_speed(self, web_speed: float) -> float:
        """Its surface speed [m/s] when its prescribed drive runs at ``web_speed`` [m/s]
        (:meth:`operating_speed` times its radius); only where it has a drive speed."""
        raise NotImplementedError(f"{self!r} has no drive speed")

    def web_length(self, duration: float, web_speed: float) -> float:
        """Web [m] its drive brings in over ``duration`` [s] at ``web_speed`` [m/s]; only
        where it has a drive speed."""
        raise NotImplementedError(f"{self!r} has no drive speed")


class RigidDisc(BodyElement):
    """A body of constant radius, mass and inertia: parameters ``NAME.radius`` [m],
    ``NAME.inertia`` [kg·m²], ``NAME.mass`` [kg] from its part's keys."""

    @property
    def initial_radius(self) -> float:
        return float(self.part.radius)

    def declare(self, machine: Machine) -> None:
        n, part = self.name, self.part
        machine.parameter(f"{n}.radius", part.radius)
        machine.parameter(f"{n}.inertia", part.inertia)
        machine.parameter(f"{n}.mass", part.mass)

    def initial_rate(self, coord: str) -> float:
        return 0.0

    def kinematics(self, ev: Evaluation, bs: BodyState) -> None:
        n = self.name
        bs.r = ev.p(f"{n}.radius")
        bs.r_dot = 0.0
        bs.mass = ev.p(f"{n}.mass")
        bs.inertia = ev.p(f"{n}.inertia")
        bs.dm_dr = bs.dJ_dr = 0.0
