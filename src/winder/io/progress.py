"""Progress bars on stderr (tqdm): a simulation's time, a sweep's runs, a count of steps.

On a terminal a bar is redrawn in place at most every 0.2 s; when stderr is a log file or a
pipe each update is one whole line (no carriage returns), at most every 5 s.
"""

from __future__ import annotations

import os
import sys
import time
from typing import TextIO

from tqdm import tqdm

__all__ = ["Progress", "SweepProgress", "CountProgress"]

_TTY_INTERVAL = 0.2  # [s] between redraws on a terminal
_LOG_INTERVAL = 5.0  # [s] between lines on a log or pipe


class _Lines:
    """A stream for tqdm on a log or pipe: every status it draws becomes one whole line."""

    def __init__(self, stream: TextIO) -> None:
        self.stream = stream

    def write(self, text: str) -> int:
        line = text.replace("\r", "").rstrip()
        if line:
            self.stream.write(line + "\n")
            self.stream.flush()
        return len(text)

    def flush(self) -> None:
        self.stream.flush()


def _is_terminal(stream: TextIO) -> bool:
    """A terminal with a width (a pseudo-terminal of width 0 gets whole lines too)."""
    try:
        return stream.isatty() and os.get_terminal_size(stream.fileno()).columns > 0
    except (AttributeError, OSError, ValueError):
        return False


def _bar(stream: TextIO | None, **kw) -> tqdm:
    stream = sys.stderr if stream is None else stream
    tty = _is_terminal(stream)
    return tqdm(file=stream if tty else _Lines(stream),
                mininterval=_TTY_INTERVAL if tty else _LOG_INTERVAL,
                dynamic_ncols=tty, leave=True, **kw)


class Progress:
    """Progress of one simulation: ``update(t)`` with the simulated time [s] reached,
    ``close()`` at the end (draws the bar as last updated: at ``t_end`` for a finished run,
    at the time reached for a run a budget stopped). ``t_end`` [s] is the run's end time."""

    def __init__(self, t_end: float, label: str, *, stream: TextIO | None = None) -> None:
        self.t_end = float(t_end)
        self.bar = _bar(stream, total=self.t_end, desc=label,
                        bar_format="{desc} {percentage:5.1f}%|{bar:30}| t = {n:8.2f} s  "
                                   "{elapsed} wall, {remaining} left")

    def update(self, t: float) -> None:
        t = min(max(float(t), 0.0), self.t_end)
        if t > self.bar.n:
            self.bar.update(t - self.bar.n)

    def close(self) -> None:
        self.bar.close()


class SweepProgress:
    """Progress of a sweep: runs done out of ``total`` (``done`` already at the start, e.g.
    from an earlier interrupted sweep), failures, and the estimated finish time."""

    def __init__(self, total: int, *, done: int = 0, label: str = "sweep",
                 stream: TextIO | None = None) -> None:
        self.total, self.failed = int(total), 0
        self._start, self._initial = time.time(), int(done)
        self.bar = _bar(stream, total=self.total, initial=self._initial, desc=label,
                        unit="run", postfix="0 failed",
                        bar_format="{desc}: {n}/{total} runs |{bar:30}| {elapsed}{postfix}")

    def _postfix(self) -> None:
        parts = [f"{self.failed} failed"]
        new = self.bar.n - self._initial
        left = self.total - self.bar.n
        if new > 0 and left > 0:
            remaining = (time.time() - self._start) / new * left
            finish = time.strftime("%H:%M:%S", time.localtime(time.time() + remaining))
            parts.append(f"ETA {finish} ({remaining:.0f} s left)")
        self.bar.set_postfix_str(", ".join(parts), refresh=False)

    def update(self, *, failed: bool = False) -> None:
        """One more run done (``failed``: it ended with an error recorded in its row)."""
        self.failed += bool(failed)
        self.bar.n += 1
        self._postfix()
        if self.bar.n < self.total:  # the last state is drawn by close()
            self.bar.update(0)

    def close(self) -> None:
        self._postfix()
        self.bar.close()


class CountProgress:
    """Progress of ``total`` steps of one computation (e.g. a resonance map's radii;
    ``units``: what they are, plural):
    ``update()`` after each, ``close()`` at the end."""

    def __init__(self, total: int, label: str, *, units: str = "steps",
                 stream: TextIO | None = None) -> None:
        self.bar = _bar(stream, total=int(total), desc=label,
                        bar_format="{desc}: {n}/{total} " + units + " |{bar:30}| {elapsed} "
                                   "wall, {remaining} left")

    def update(self) -> None:
        self.bar.update(1)

    def close(self) -> None:
        self.bar.close()
