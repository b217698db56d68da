"""The order in which force elements run in one evaluation, from what each declares it
``provides`` and ``requires`` (and optionally ``uses``), not from numbers.

A quantity (``"span_rate"``, ``"drive_torque"``, ``"gravity"``, ...) is written by the
elements that provide it and read by those that require it (it must be provided) or use
it (read where some element provides it, else a default). Every provider runs before every
reader; ties keep the given order (the registration order), so the order is
deterministic.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from winder._errors import ModelError

__all__ = ["order_elements", "ElementOrderError"]


class ElementOrderError(ModelError):
    """The force elements' declarations cannot be ordered: a required quantity nobody
    provides, or a cycle."""


def order_elements(elements: Sequence[Any]) -> list[Any]:
    """``elements`` (with ``name``, ``provides``, ``requires``, ``uses``) so that every
    provider of a quantity comes before every element that requires or uses it; among
    the elements free to run, the earliest in ``elements`` first.

    Raises
    ------
    ElementOrderError: a required quantity no element provides (naming both), or a
        cycle (naming its elements).
    """
    providers: dict[str, list[int]] = {}
    for i, el in enumerate(elements):
        for q in getattr(el, "provides", ()):
            providers.setdefault(q, []).append(i)
    after: list[set[int]] = [set() for _ in elements]
    for i, el in enumerate(elements):
        for q in getattr(el, "requires", ()):
            if q not in providers:
                valid = ", ".join(sorted(providers)) or "none"
                raise ElementOrderError(
                    f"force element {el.name!r} requires {q!r}, which no element of this "
                    f"machine provides; provided: {valid}")
            after[i].update(j for j in providers[q] if j != i)
        for q in getattr(el, "uses", ()):
            after[i].update(j for j in providers.get(q, ()) if j != i)
    done: list[int] = []
    left = list(range(len(elements)))
    while left:
        ready = next((i for i in left if after[i] <= set(done)), None)
        if ready is None:
            names = ", ".join(repr(elements[i].name) for i in left)
            raise ElementOrderError(f"the force elements {names} require each other in a "
                                    "cycle (provides/requires); none can run first")
        done.append(ready)
        left.remove(ready)
    return [elements[i] for i in done]
