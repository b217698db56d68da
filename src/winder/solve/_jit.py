"""numba compilation of winder's kernels, cached on disk where numba can write a cache.

numba keeps compiled machine code next to the source (``__pycache__``) or in the user's
cache directory. A user who can write neither (an installed package and no writable home)
would otherwise fail at ``import winder`` with numba's "cannot cache function"; winder then
compiles in memory for this process only and says so once.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

from numba import njit as _njit

__all__ = ["njit", "CacheFallbackWarning"]

_warned = False


class CacheFallbackWarning(UserWarning):
    """numba cannot write a cache here: kernels are compiled for this process only."""


def njit(func: Callable[..., Any]) -> Any:
    """``numba.njit(cache=True)``, or ``numba.njit`` with a warning where no cache
    location is writable."""
    global _warned
    try:
        return _njit(cache=True)(func)
    except RuntimeError as exc:
        if "cannot cache function" not in str(exc):
            raise
        if not _warned:
            _warned = True
            warnings.warn(f"winder: numba cannot write a compilation cache ({exc}); compiling "
                          "in memory for this process (each run pays the compile time). Set "
                          "NUMBA_CACHE_DIR to a writable directory to cache.",
                          CacheFallbackWarning, stacklevel=2)
        return _njit(func)
