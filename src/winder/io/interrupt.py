"""Stopping a command cleanly: SIGINT, SIGTERM and SIGHUP alike.

While :func:`handling_signals` is active (the command line installs it first thing), each of
the three signals raises :class:`Interrupted` (a ``KeyboardInterrupt`` carrying the signal
number; :meth:`Interrupted.describe` says "interrupted (SIGINT)", "terminated (SIGTERM)",
"hung up (SIGHUP)"), so every ``finally`` and ``except BaseException`` runs: temporary files
are removed, child processes stopped. Code that creates something that must not outlive the
process registers its removal with :func:`on_abort`. A second signal while the first is being
cleaned up does not kill the process silently: it runs the registered clean-ups at once,
prints one line and exits with status ``128 + signal``. Inside :func:`deferred` (the few
statements that move finished files into place) a signal is held; :func:`checkpoint` acts on
a held one where the block can still undo its work (a multi-file write rolls back there), the
block's end on one that came after. A write that put its files in place records them with
:func:`committed`: the message of a later signal names them (complete) instead of claiming
that nothing was written.

With ``exiting`` (the command line) the signals are ignored after the block: the command
is over, its output complete and flushed, and one that arrives while Python shuts down
leaves the exit status as it is, instead of Python's default action (killed without a word
by SIGTERM or SIGHUP, a ``KeyboardInterrupt`` traceback from SIGINT). Only ``SIG_IGN``
outlasts Python's finalization, which puts every Python-level handler back to the default.

Outside the command line (``handling_signals`` not active) :func:`on_abort` and
:func:`deferred` do nothing: a library user's own signal handling is left alone.
"""

from __future__ import annotations

import itertools
import os
import signal
import sys
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager

__all__ = ["Interrupted", "SIGNALS", "checkpoint", "committed", "committed_files", "deferred",
           "handling_signals", "on_abort", "run_abort_cleanups"]

#: The signals that stop a command cleanly (SIGHUP where the platform has it).
SIGNALS: tuple[int, ...] = tuple(
    int(s) for s in (getattr(signal, n, None) for n in ("SIGINT", "SIGTERM", "SIGHUP"))
    if s is not None)


#: What a signal did to the command, for its message.
_VERBS = {"SIGINT": "interrupted", "SIGTERM": "terminated", "SIGHUP": "hung up"}


class Interrupted(KeyboardInterrupt):
    """The command was stopped by a signal; :attr:`signo` is its number, :attr:`exit_status`
    ``128 + signo`` (130 for Ctrl-C, 143 for SIGTERM, 129 for SIGHUP)."""

    def __init__(self, signo: int) -> None:
        super().__init__(signal.Signals(signo).name)
        self.signo = int(signo)

    @property
    def name(self) -> str:
        return signal.Signals(self.signo).name

    @property
    def exit_status(self) -> int:
        return 128 + self.signo

    def describe(self) -> str:
        """``interrupted (SIGINT)``, ``terminated (SIGTERM)``, ``hung up (SIGHUP)``."""
        return f"{_VERBS.get(self.name, 'stopped')} ({self.name})"


class _State:
    active = False      # handlers installed
    stopping = False    # a first signal has been turned into Interrupted
    depth = 0           # nesting of deferred()
    pending: int | None = None
    committed: list[str] = []  # files complete and in place (committed())


_CLEANUPS: dict[int, Callable[[], None]] = {}
_IDS = itertools.count()


def run_abort_cleanups() -> None:
    """Run (newest first) and forget every registered clean-up; errors are ignored."""
    while _CLEANUPS:
        key = max(_CLEANUPS)
        fn = _CLEANUPS.pop(key)
        try:
            fn()
        except Exception:  # noqa: S110 - best effort: the process is stopping
            pass


@contextmanager
def on_abort(cleanup: Callable[[], None]) -> Iterator[None]:
    """Register ``cleanup`` (idempotent, fast) while the block runs. It is forgotten when
    the block ends normally and kept when an exception leaves it: the command line runs it
    before exiting, and a second signal runs it at once."""
    if not _State.active:
        yield
        return
    key = next(_IDS)
    _CLEANUPS[key] = cleanup
    yield
    _CLEANUPS.pop(key, None)


@contextmanager
def deferred() -> Iterator[None]:
    """Act on a signal that arrives inside the block only when the block ends (or at a
    :func:`checkpoint` in it)."""
    _State.depth += 1
    try:
        yield
    finally:
        _State.depth -= 1
        if _State.depth == 0 and _State.pending is not None:
            signo, _State.pending = _State.pending, None
            _handle(signo, None)


def checkpoint() -> None:
    """Inside :func:`deferred`: act now on a signal held so far (raise :class:`Interrupted`
    here, where the caller can still undo its work); nothing when none is held."""
    if _State.pending is None:
        return
    signo, _State.pending = _State.pending, None
    depth, _State.depth = _State.depth, 0
    try:
        _handle(signo, None)
    finally:
        _State.depth = depth


def committed(paths: Iterable[str | os.PathLike[str]]) -> None:
    """Record files that a write has just put in place, complete (the command line's
    message on a later signal names them)."""
    if _State.active:
        _State.committed.extend(os.fspath(p) for p in paths)


def committed_files() -> list[str]:
    """The files recorded by :func:`committed` since :func:`handling_signals` began."""
    return list(_State.committed)


def _handle(signo: int, frame: object) -> None:
    if _State.depth > 0:
        if _State.pending is None:
            _State.pending = signo
        return
    if not _State.stopping:
        _State.stopping = True
        raise Interrupted(signo)
    run_abort_cleanups()
    try:
        sys.stderr.write(f"winder: {signal.Signals(signo).name} again during clean-up: "
                         "temporary files removed, stopping now\n")
        sys.stderr.flush()
    finally:
        os._exit(128 + signo)


@contextmanager
def handling_signals(*, exiting: bool = False) -> Iterator[None]:
    """Turn SIGINT, SIGTERM and SIGHUP into :class:`Interrupted` inside the block (main
    thread only; elsewhere the block runs unchanged). Registered clean-ups left over when
    the block ends are run. ``exiting``: the process ends right after the block (the
    command line, with its output flushed); the signals are then ignored, so that one
    arriving while Python shuts down neither kills the process with Python's default action
    nor changes its exit status."""
    try:
        previous = {s: signal.signal(s, _handle) for s in SIGNALS}
    except ValueError:  # not the main thread
        yield
        return
    _State.active, _State.stopping, _State.depth, _State.pending = True, False, 0, None
    _State.committed = []
    try:
        yield
    finally:
        run_abort_cleanups()
        _State.active = False
        for s, h in previous.items():
            signal.signal(s, signal.SIG_IGN if exiting else h)
