"""Reading a scene file (TOML, UTF-8; spec section 7; machines spec §8) into a
:class:`~winder.scene.scene.Scene`.

Two formats load: the single-drum format (tables ``[drum]``, ``[roll]``, ``[contact]``,
``[friction]``; :attr:`Scene.legacy`, :mod:`winder.scene.legacy`) and scenes of parts
(arrays of tables ``[[drum]]``, ``[[roll]]``, ``[[rider]]``, ``[[nip]]``, and ``[web]``
(or ``[[web]]``, one per wound roll) with its optional ``[web.span]`` from an unwinding
roll). A single-drum scene is also converted to parts (drum "drum", roll "roll", nip
"nip", web entering at "nip"), so code written for parts reads both.

Every error names the file, the table (an element of an array by its name, ``[drum
'front']``) and the key, and the offending value.
"""

from __future__ import annotations

import os
import tomllib
from pathlib import Path

from winder._args import show
from winder._errors import ArgumentTypeError, SceneError
from winder.scene.scene import Scene, scene_from_dict

__all__ = ["Scene", "load_scene", "scene_from_dict", "MAX_SCENE_BYTES"]


#: Largest scene file read [bytes] (scenes are a few kB; this stops a device or a huge
#: file given by mistake from being read into memory).
MAX_SCENE_BYTES = 1 << 20


def _scene_text(p: Path) -> str:
    """The text of a scene file, or a :class:`SceneError` saying why it is not one."""
    try:
        with p.open("rb") as fh:
            raw = fh.read(MAX_SCENE_BYTES + 1)
    except IsADirectoryError:
        raise SceneError(f"{p}: is a directory, not a scene file (give a .toml file)") from None
    except OSError as exc:
        raise SceneError(f"{p}: cannot read scene file: {exc.strerror or exc}") from None
    if len(raw) > MAX_SCENE_BYTES:
        raise SceneError(f"{p}: larger than {MAX_SCENE_BYTES} bytes: not a scene file "
                         "(a scene is a small TOML text file)")
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise SceneError(f"{p}: UTF-16 text; a scene file must be UTF-8 (save it as UTF-8)")
    if raw.startswith(b"PK\x03\x04"):
        raise SceneError(f"{p}: a zip archive (a .npz result?), not a TOML scene file")
    if b"\x00" in raw:
        raise SceneError(f"{p}: a binary file (NUL byte at offset {raw.index(0)}), not a "
                         "TOML scene file")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise SceneError(f"{p}: not UTF-8 text: byte 0x{raw[exc.start]:02x} at line {line} "
                         f"(offset {exc.start}); a scene file must be UTF-8 (save it as "
                         "UTF-8)") from None


def load_scene(path: str | os.PathLike[str]) -> Scene:
    """Read and validate a scene file (TOML, UTF-8, spec section 7).

    Raises
    ------
    SceneError
        If the file is missing, a directory, not UTF-8 text, not TOML, or any key is
        unknown, missing, of the wrong type, non-finite or out of range (the message names
        the key and the file).
    ArgumentTypeError
        If ``path`` is not a string or path.
    """
    if not isinstance(path, str | os.PathLike):
        raise ArgumentTypeError(f"load_scene: path must be a str or os.PathLike naming a "
                                f"scene file, got {show(path)} ({type(path).__name__})")
    name = os.fspath(path)
    if not isinstance(name, str):
        raise ArgumentTypeError(f"load_scene: path must name the file as text, got "
                                f"{show(name)} ({type(name).__name__})")
    if "\x00" in name:
        raise SceneError(f"{show(name)}: a file name cannot contain a NUL byte")
    p = Path(path)
    text = _scene_text(p)
    try:
        data = tomllib.loads(text)
    except (tomllib.TOMLDecodeError, ValueError) as exc:  # ValueError: 5000-digit integers
        raise SceneError(f"{p}: not valid TOML: {show(str(exc), 200)[1:-1]}") from None
    except RecursionError:
        raise SceneError(f"{p}: not a scene: arrays or tables nested too deeply for TOML "
                         "parsing (a scene is a few flat tables)") from None
    return scene_from_dict(data, source=str(p))
