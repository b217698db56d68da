"""Output files: safe names from scene text, checks of every output location before a run,
and atomic writes that leave the complete file or nothing.

- :func:`safe_stem` turns any text (a scene's ``name``) into a short file-name stem: no
  scene text decides the directory a file is written to.
- :func:`check_output_file` and :func:`check_output_dir` are called before a run starts:
  an output that cannot be written (read-only place, a directory given as a file, a parent
  that is a file, a name too long for the file system) is an error naming the argument and
  the path, and nothing is created.
- :func:`scratch_dir` is a temporary directory that is removed even when a signal arrives
  while it is being created.
- :func:`atomic_write` and :func:`atomic_write_all` write into hidden temporary files
  (``.winder-XXXXXXXX.tmp``, short whatever the target's name) beside the targets and move
  them into place when all are complete; on an error, Ctrl-C, SIGTERM or SIGHUP the
  temporaries are removed and the files already moved are taken back (the files they
  replaced put back), so a set of files is written whole or not at all (see
  :mod:`winder.io.interrupt`).
"""

from __future__ import annotations

import errno
import os
import re
import shutil
import tempfile
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Any

from winder._errors import WinderError
from winder.io.interrupt import checkpoint, committed, deferred, on_abort

__all__ = ["OutputError", "atomic_write", "atomic_write_all", "check_output_dir", "csv_writer",
           "check_output_file", "safe_stem", "scratch_dir"]

Writer = Callable[[Path], object]
_TMP_PREFIX = ".winder-"
_TMP_SUFFIX = ".tmp"
#: Longest stem :func:`safe_stem` returns [bytes]; derived names stay far below 255.
STEM_MAX = 80


class OutputError(WinderError, OSError):
    """An output file or directory cannot be written (the message names it and why)."""


def safe_stem(text: object, *, default: str = "result", max_bytes: int = STEM_MAX) -> str:
    """A file-name stem from ``text``: ASCII letters, digits, ``-``, ``_`` and inner ``.``
    only (everything else, including ``/``, ``\\`` and NUL, becomes ``_``), no leading dot,
    at most ``max_bytes`` bytes; ``default`` when nothing is left."""
    stem = re.sub(r"[^A-Za-z0-9._-]+", "_", str(text))
    stem = stem.lstrip(".-_")[:max_bytes].rstrip("._-")
    return stem or default


def _name_max(directory: Path) -> int:
    try:
        return int(os.pathconf(directory, "PC_NAME_MAX"))
    except (OSError, ValueError, AttributeError):
        return 255


def _fail(arg: str, path: object, problem: str) -> OutputError:
    return OutputError(f"{arg} {path}: {problem}")


def _check_text(arg: str, text: str) -> Path:
    if not text:
        raise _fail(arg, repr(text), "empty path")
    if "\0" in text:
        raise _fail(arg, repr(text), "the path contains a NUL byte")
    try:
        os.fsencode(text)
    except UnicodeError:
        raise _fail(arg, repr(text), "the path cannot be encoded for this file system") \
            from None
    return Path(text)


def _existing_ancestor(arg: str, path: Path) -> tuple[Path, list[str]]:
    """The nearest existing ancestor of ``path`` and the names below it (to be created)."""
    absolute = Path(os.path.abspath(path))
    missing: list[str] = []
    here = absolute
    while True:
        try:
            here.lstat()
            break
        except (FileNotFoundError, NotADirectoryError):
            missing.append(here.name)
            here = here.parent
        except OSError as exc:
            if exc.errno == errno.ENAMETOOLONG:
                missing.append(here.name)
                here = here.parent
                continue
            raise _fail(arg, path, f"cannot be checked ({exc.strerror})") from None
    missing.reverse()
    if missing and not here.is_dir():
        raise _fail(arg, path, f"its parent {here} is a file, not a directory")
    limit = _name_max(here)
    for name in missing:
        size = len(os.fsencode(name))
        if size > limit:
            raise _fail(arg, path, f"the name {name[:40]!r}... is {size} bytes long; the file "
                        f"system allows {limit}")
    return here, missing


def _check_writable(arg: str, path: Path, directory: Path) -> None:
    """Create and remove a probe file in ``directory`` (permission bits do not tell the
    truth for root or on read-only mounts)."""
    with deferred():  # a signal here would leave the probe behind: acted on after it
        try:
            fd, probe = tempfile.mkstemp(prefix=_TMP_PREFIX, suffix=_TMP_SUFFIX,
                                         dir=directory)
        except OSError as exc:
            raise _fail(arg, path, f"cannot write in {directory} ({exc.strerror})") from None
        os.close(fd)
        os.unlink(probe)


def check_output_file(path: str | os.PathLike[str], arg: str, *,
                      suffixes: Sequence[str] | None = None) -> Path:
    """Check, without creating anything, that the file ``path`` can be written; returns it.

    Raises :class:`OutputError` naming ``arg`` (the option, e.g. ``--out``) and the path
    when the path is empty or has a NUL byte, names an existing directory or a special file,
    has a file as a parent, a name longer than the file system allows, lies in a directory
    that cannot be written, or (``suffixes``) does not end in one of ``suffixes``."""
    text = os.fspath(path)
    p = _check_text(arg, text)
    if text.endswith(("/", os.sep)):
        raise _fail(arg, p, "is a directory; give a file name")
    here, missing = _existing_ancestor(arg, p)
    if not missing and here.is_dir():
        raise _fail(arg, p, "is a directory; give a file name")
    if suffixes is not None and p.suffix.lower() not in suffixes:
        raise _fail(arg, p, f"unknown file type {p.suffix!r}; valid: {', '.join(suffixes)}")
    if not missing and not here.is_file():
        raise _fail(arg, p, "exists and is not a regular file")
    _check_writable(arg, p, here if missing else here.parent)
    return p


def check_output_dir(path: str | os.PathLike[str], arg: str) -> Path:
    """Check, without creating anything, that files can be written in the directory
    ``path`` (existing or to be created); returns it. Errors as :func:`check_output_file`."""
    p = _check_text(arg, os.fspath(path))
    here, missing = _existing_ancestor(arg, p)
    if not missing and not here.is_dir():
        raise _fail(arg, p, "is a file, not a directory")
    _check_writable(arg, p, here)
    return p


def _make_parents(directory: Path) -> list[Path]:
    """``mkdir -p``; returns the directories created (outermost first)."""
    created: list[Path] = []
    for d in reversed([directory, *directory.parents]):
        if not d.exists():
            try:
                d.mkdir()
            except FileExistsError:
                continue
            created.append(d)
    return created


def _remove_dirs(created: Iterable[Path]) -> None:
    for d in reversed(list(created)):
        try:
            d.rmdir()
        except OSError:
            pass


def _unlink(path: Path) -> None:
    try:
        path.unlink()
    except FileNotFoundError:
        pass


_UMASK = os.umask(0)
os.umask(_UMASK)


def csv_writer(columns: Mapping[str, Any], *, fmt: str) -> Writer:
    """A writer (for :func:`atomic_write`) of a CSV of equal-length numeric ``columns``:
    a header of their names, then one row per sample in ``fmt``. -0.0 is written 0 (``+
    0.0`` turns it into 0.0 and leaves every other value, NaN and ±inf included, as it
    is)."""
    import numpy as np

    header = ",".join(columns)
    table = np.column_stack(list(columns.values())) + 0.0
    return lambda tmp: np.savetxt(tmp, table, delimiter=",", header=header, comments="",
                                  fmt=fmt)


def _set_aside(target: Path) -> Path | None:
    """A hidden hard link (a renamed copy where the file system has no hard links) of the
    file ``target`` beside it, to put back if the write that replaces it is undone; None
    when there is no file there."""
    if not os.path.lexists(target):
        return None
    fd, name = tempfile.mkstemp(prefix=_TMP_PREFIX, suffix=_TMP_SUFFIX, dir=target.parent)
    os.close(fd)
    aside = Path(name)
    try:
        os.unlink(aside)
        os.link(target, aside, follow_symlinks=False)
    except OSError:
        os.replace(target, aside)  # no hard links here: the target is absent until replaced
    return aside


def atomic_write_all(items: Sequence[tuple[str | os.PathLike[str], Writer]]) -> list[Path]:
    """Call each ``write(tmp_path)``, then move all the files into place together: the
    targets are all written or none is (no partial file, no temporary left; a file that
    was there before stays as it was) on an error, Ctrl-C, SIGTERM or SIGHUP, whenever it
    comes: while the temporaries are written, and while they are moved into place (a
    signal that arrives then undoes the moves: the files that were there are put back).
    Missing parent directories are created (and removed again on failure). Errors of the
    file system raise :class:`OutputError` naming the file."""
    targets = [Path(p) for p, _ in items]
    temps: list[Path] = []
    asides: list[Path] = []
    created: list[Path] = []
    current = targets[0] if targets else Path()

    def cleanup() -> None:
        for tmp in (*temps, *asides):
            _unlink(tmp)
        _remove_dirs(created)

    with on_abort(cleanup):
        try:
            for target, (_, write) in zip(targets, items, strict=True):
                current = target
                created += _make_parents(target.parent)
                with deferred():  # no signal between creating and recording the temporary
                    fd, name = tempfile.mkstemp(prefix=_TMP_PREFIX, suffix=_TMP_SUFFIX,
                                                dir=target.parent)
                    os.close(fd)
                    temps.append(Path(name))
                write(temps[-1])
                os.chmod(temps[-1], 0o666 & ~_UMASK)  # mkstemp makes 0600
            done: list[tuple[Path, Path | None]] = []  # (target, the file it replaces)
            with deferred():  # a signal is acted on at the checkpoint: all or nothing
                try:
                    for tmp, target in zip(temps, targets, strict=True):
                        current = target
                        aside = _set_aside(target)
                        if aside is not None:
                            asides.append(aside)
                        done.append((target, aside))  # undone below, moved or not
                        os.replace(tmp, target)
                    checkpoint()  # a signal so far: undo the moves (below)
                except BaseException:
                    for target, aside in reversed(done):
                        if aside is None:
                            _unlink(target)
                            continue
                        try:
                            os.replace(aside, target)
                        except OSError:  # keep the earlier file (hidden) rather than lose it
                            asides.remove(aside)
                    raise
                for aside in asides:
                    _unlink(aside)
                committed(targets)
        except BaseException as exc:
            cleanup()
            if isinstance(exc, OSError) and not isinstance(exc, WinderError):
                raise OutputError(f"cannot write {current}: {exc.strerror or exc}") from exc
            raise
    return targets


def atomic_write(path: str | os.PathLike[str], write: Writer) -> Path:
    """Call ``write(tmp_path)`` then move the file into place: the complete ``path`` or
    nothing (see :func:`atomic_write_all`)."""
    return atomic_write_all([(path, write)])[0]


@contextmanager
def scratch_dir(prefix: str = "winder-", *, dir: str | Path | None = None) -> Iterator[Path]:
    """A temporary directory, removed with its contents when the block ends, on an error,
    and on a signal (also one that arrives while it is being created)."""
    with ExitStack() as stack:
        with deferred():  # no signal between creating the directory and recording it
            path = Path(tempfile.mkdtemp(prefix=prefix, dir=dir))
            stack.callback(shutil.rmtree, path, ignore_errors=True)
            stack.enter_context(on_abort(lambda: shutil.rmtree(path, ignore_errors=True)))
        yield path
