"""The web (machines spec §3, §8 ``[web]``): where the paper enters the wound roll and
under which tension."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["WebPart"]


@dataclass(frozen=True)
class WebPart:
    """``[web]``: entry_nip (the name of the nip where the web enters its wound roll: ``a``
    a drum, ``b`` a wound roll), tension [0, 1e7] [N] (constant)."""

    entry_nip: str
    tension: float = 0.0
