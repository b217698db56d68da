"""Units in an FMU's modelDescription.xml: pythonfmu 0.7 writes no ``unit`` attribute and
no ``<UnitDefinitions>``; :class:`UnitReal` and :func:`with_unit_definitions` add them
(the units of :mod:`winder.model.units`, by their FMI names)."""

from __future__ import annotations

from typing import Any
from xml.etree.ElementTree import Element, SubElement

from pythonfmu import Real

from winder.model.units import BASE_UNITS, dimensions, fmi_name

__all__ = ["UnitReal", "with_unit_definitions"]


class UnitReal(Real):
    """A pythonfmu ``Real`` with a ``unit`` (a unit text of :mod:`winder.model.units`,
    written as its FMI name; None for none)."""

    def __init__(self, name: str, *, unit: str | None = None, **kwargs: Any) -> None:
        super().__init__(name, **kwargs)
        self.unit = None if unit is None else fmi_name(unit)
        self.winder_unit = unit

    def to_xml(self) -> Element:
        parent = super().to_xml()
        if self.unit is not None:
            parent.find("Real").set("unit", self.unit)
        return parent


def with_unit_definitions(root: Element, variables: Any) -> Element:
    """``root`` (pythonfmu's ``fmiModelDescription``) with a ``<UnitDefinitions>`` of every
    unit of ``variables`` (the slave's :class:`UnitReal` among them) after
    ``<CoSimulation>``, where FMI 2.0 puts it: ``<Unit name="N.m"><BaseUnit kg="1" m="2"
    s="-2"/></Unit>`` each."""
    units = sorted({v.winder_unit for v in variables if getattr(v, "winder_unit", None)},
                   key=fmi_name)
    if not units:
        return root
    defs = Element("UnitDefinitions")
    for unit in units:
        node = SubElement(defs, "Unit", name=fmi_name(unit))
        exps = dimensions(unit)
        SubElement(node, "BaseUnit", {b: str(exps[b]) for b in BASE_UNITS if exps.get(b)})
    at = next((i for i, child in enumerate(root) if child.tag == "CoSimulation"), -1)
    root.insert(at + 1, defs)
    return root
