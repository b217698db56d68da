"""Keys every kind of part declares alike: its ``name``, a body's ``centre`` and the bound
of a coordinate (each part's own keys are in its module, ``KEYS``)."""

from __future__ import annotations

from winder._schema import Key

__all__ = ["NAME", "CENTRE", "MAX_COORD"]

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
