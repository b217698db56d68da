"""The figures' size rule: every figure at most :data:`MAX_HEIGHT_PX` tall at
:data:`DPI`, by choosing its layout from the count of what it draws (rows packed onto pages,
a flexible body's segments drawn as one heat map), never by shrinking a figure afterwards;
and line styles that stay distinct when a panel draws many lines."""

from __future__ import annotations

import itertools

__all__ = ["DPI", "MAX_HEIGHT_PX", "MAX_HEIGHT", "HEADER", "ROW", "rows_per_page", "pages",
           "page_suffix", "line_styles", "LEGEND_INSIDE"]

#: Resolution of every PNG the figures write [dot/inch].
DPI = 110
#: The tallest figure [px].
MAX_HEIGHT_PX = 4000
#: The tallest figure [in] at :data:`DPI`.
MAX_HEIGHT = MAX_HEIGHT_PX / DPI
#: Height of a figure's title and time axis [in].
HEADER = 1.6
#: Height of one row of a stacked figure [in].
ROW = 2.0
#: At most this many lines keep their legend inside a panel; more go beside it.
LEGEND_INSIDE = 6


def rows_per_page(row: float = ROW, header: float = HEADER) -> int:
    """How many rows of ``row`` [in] fit under :data:`MAX_HEIGHT` with a ``header`` [in]."""
    return max(1, int((MAX_HEIGHT - header) // row))


def pages(groups: list[int], row: float = ROW, header: float = HEADER) -> list[list[int]]:
    """The groups of rows (``groups[i]`` rows each, kept on one page: a body's panels)
    packed in order onto pages of at most :func:`rows_per_page` rows: the group indices of
    each page. A group larger than a page gets a page of its own (the caller keeps groups
    smaller than a page)."""
    limit = rows_per_page(row, header)
    out: list[list[int]] = []
    used = limit
    for i, n in enumerate(groups):
        if not out or used + n > limit:
            out.append([])
            used = 0
        out[-1].append(i)
        used += n
    return out


def page_suffix(page: int) -> str:
    """The file-name suffix of page ``page`` (0-based) of a figure: none for the first,
    ``_2``, ``_3``, ... after it."""
    return "" if page == 0 else f"_{page + 1}"


_COLOURS = ("C0", "C1", "C2", "C3", "C4", "C5", "C6", "C7", "C8", "C9")
_DASHES = ("-", "--", "-.", ":")
_MARKERS = ("", "o", "s", "^", "v", "D", "x", "+", "*", "P")


def line_styles(n: int, colours: tuple[str, ...] = _COLOURS
                ) -> list[tuple[str, str, str]]:
    """``n`` distinct ``(colour, linestyle, marker)`` combinations: the colours first
    (solid lines), then each colour dashed, dash-dotted, dotted, then with markers; no two
    alike for any ``n``."""
    combos = itertools.product(_MARKERS, _DASHES, colours)
    return [(c, ls, m) for m, ls, c in itertools.islice(combos, n)] if n <= len(
        _MARKERS) * len(_DASHES) * len(colours) else _many(n, colours)


def _many(n: int, colours: tuple[str, ...]) -> list[tuple[str, str, str]]:
    """More combinations than the named ones: colours from a continuous map."""
    import matplotlib

    cmap = matplotlib.colormaps["turbo"]
    return [(matplotlib.colors.to_hex(cmap(i / max(n - 1, 1))), _DASHES[i % len(_DASHES)],
             _MARKERS[i % len(_MARKERS)]) for i in range(n)]
