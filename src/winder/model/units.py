"""The units winder writes (result channels, scene keys), as exponents of the SI base units
and the radian: one table for FMI's ``<UnitDefinitions>`` and for dimension checks.

A unit is written as text in SI with ``·`` for a product and superscripts for powers
(``N·m``, ``kg·m²/s``, ``m/s²``); ``-`` is a dimensionless number. :func:`fmi_name` gives
its plain-ASCII name for an FMU (``N.m``, ``kg.m2/s``, ``m/s2``, Modelica's spelling).
"""

from __future__ import annotations

from types import MappingProxyType

from winder._errors import ModelError

__all__ = ["BASE_UNITS", "DIMENSIONS", "dimensions", "fmi_name"]

#: FMI 2.0's base units (``<BaseUnit>`` attributes), in its order.
BASE_UNITS = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")

#: Each unit text → its exponents of :data:`BASE_UNITS` (absent: 0).
DIMENSIONS = MappingProxyType({
    "-": {},
    "s": {"s": 1},
    "m": {"m": 1},
    "m/s": {"m": 1, "s": -1},
    "m/s²": {"m": 1, "s": -2},
    "rad": {"rad": 1},
    "rad/s": {"rad": 1, "s": -1},
    "rad/s²": {"rad": 1, "s": -2},
    "kg": {"kg": 1},
    "kg/s": {"kg": 1, "s": -1},
    "kg/m³": {"kg": 1, "m": -3},
    "kg·m²": {"kg": 1, "m": 2},
    "kg·m²/s": {"kg": 1, "m": 2, "s": -1},
    "N": {"kg": 1, "m": 1, "s": -2},
    "N·s": {"kg": 1, "m": 1, "s": -1},
    "N/m": {"kg": 1, "s": -2},
    "N·s/m": {"kg": 1, "s": -1},
    "N·m": {"kg": 1, "m": 2, "s": -2},
    "s/m": {"s": 1, "m": -1},
})


def dimensions(unit: str) -> dict[str, int]:
    """Exponents of :data:`BASE_UNITS` of ``unit`` (``"N·m"``: ``{"kg": 1, "m": 2, "s":
    -2}``); :class:`~winder.ModelError` naming the valid units for an unknown one."""
    try:
        return dict(DIMENSIONS[unit])
    except (KeyError, TypeError):
        raise ModelError(f"unit {unit!r} is unknown; valid: {', '.join(DIMENSIONS)}") from None


def fmi_name(unit: str) -> str:
    """The plain-ASCII name of ``unit`` in an FMU (``kg·m²/s`` → ``kg.m2/s``, ``-`` →
    ``1``)."""
    dimensions(unit)
    return "1" if unit == "-" else \
        unit.replace("·", ".").replace("²", "2").replace("³", "3")
