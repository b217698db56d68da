"""Drums (machines spec §1, §6, §8 ``[[drum]]``): bodies with a fixed centre and a
constant radius, driven by a speed profile or a torque."""

from __future__ import annotations

from dataclasses import dataclass

from winder._schema import Key, Table

__all__ = ["DrumPart", "SpeedProfileDrive", "TorqueDrive", "KEYS", "DRIVE_KEYS", "DRIVE_KINDS",
           "NAME", "CENTRE", "MAX_COORD"]

#: Drive kinds of a drum.
DRIVE_KINDS = ("speed_profile", "torque")
#: Largest coordinate of a centre (or of a rider's x) [m].
MAX_COORD = 1e3

#: A part's ``name`` (every part has one; a web's is optional).
NAME = Key(name="name", kind="name", required=True,
           doc="the part's name (unique; names its channels)")
#: A body's ``centre``: its axis position ``[x, z]`` [m].
CENTRE = Key(name="centre", kind="pair", required=True, doc_unit="m",
             doc="axis position [x, z]",
             items=(Key(name="x", doc="x of the axis", unit="m", hi=MAX_COORD),
                    Key(name="z", doc="z of the axis", unit="m", hi=MAX_COORD)))

#: The keys of ``[[drum]]``: one declaration each (units, bounds, meaning).
KEYS = Table((
    NAME,
    Key(name="radius", required=True, unit="m", lo=0.0, lo_open=True, hi=10.0,
        doc="drum radius R"),
    Key(name="inertia", required=True, unit="kg·m²", lo=0.0, lo_open=True, hi=1e7,
        doc="polar moment of inertia J_d about the drum axis"),
    Key(name="mass", required=True, unit="kg", lo=0.0, lo_open=True, hi=1e6,
        doc="drum mass"),
    CENTRE,
    Key(name="sense", kind="sense",
        doc="operation direction: +1 turns the top surface towards +x"),
    Key(name="drive", kind="table", required=True,
        doc="the drive, a sub-table: keys below"),
))

#: The keys of a drum's ``drive``; ``kinds``: the keys each drive kind takes.
DRIVE_KEYS = Table((
    Key(name="kind", kind="str", required=True, choices=DRIVE_KINDS,
        doc="speed_profile: the drum's speed is prescribed, its torque follows from inverse "
            "dynamics; torque: the drum is free and driven by an input torque"),
    Key(name="web_acceleration", unit="m/s²", lo=0.0, hi=1e3,
        doc="ramp of the surface (web) speed a_w; 0: full speed from t = 0"),
    Key(name="web_speed", unit="m/s", lo=0.0, hi=1e3,
        default_text="required (kind speed_profile); 0 (kind torque)",
        doc="speed_profile: the surface speed v_w the ramp reaches; torque: the initial "
            "surface speed"),
    Key(name="ratio", unit="-", lo=0.0, lo_open=True, hi=100.0,
        doc="kind speed_profile: the drum runs at ratio × the profile's surface speed"),
    Key(name="torque", unit="N·m", hi=1e8,
        doc="kind torque: the drive torque (operation sense), constant or an input"),
), kinds={"speed_profile": ("kind", "web_acceleration", "web_speed", "ratio"),
          "torque": ("kind", "torque", "web_speed")})


@dataclass(frozen=True)
class SpeedProfileDrive:
    """``drive = { kind = "speed_profile" }``: the drum's speed is prescribed,
    ``Ω(t) = ratio · min(web_acceleration · t, web_speed) / R`` [rad/s]; keys, units and
    bounds: :data:`DRIVE_KEYS`."""

    kind: str = "speed_profile"
    web_acceleration: float = 0.0
    web_speed: float = 0.0
    ratio: float = 1.0


@dataclass(frozen=True)
class TorqueDrive:
    """``drive = { kind = "torque" }``: the drum turns freely under the input torque
    ``torque`` [N·m] (operation sense); ``web_speed`` [m/s] is its initial surface speed;
    bounds: :data:`DRIVE_KEYS`."""

    kind: str = "torque"
    torque: float = 0.0
    web_speed: float = 0.0


@dataclass(frozen=True)
class DrumPart:
    """``[[drum]]``: name, radius [m], inertia (polar) [kg·m²], mass [kg], centre
    ``(x, z)`` [m] (fixed), sense ±1 (operation direction, spec §1), drive; bounds and
    meanings: :data:`KEYS`."""

    name: str
    radius: float
    inertia: float
    mass: float
    centre: tuple[float, float]
    sense: int = 1
    drive: SpeedProfileDrive | TorqueDrive = SpeedProfileDrive()
