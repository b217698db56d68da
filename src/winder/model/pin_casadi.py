"""Pinocchio's own ABA, RNEA and kinematics as CasADi Functions (route "cpp").

The ``pin`` wheel has no ``pinocchio.casadi`` bindings, but it ships Pinocchio's templated
C++ headers. A small model-independent C++ program, ``_pin_casadi.cpp`` beside this file,
is compiled once from the ``pin``, ``casadi`` and ``cmeel-eigen`` wheels (about 160 s of g++
CPU time and 4 GB of memory). It reads a model written by ``model.saveToText`` and saves three
``casadi.Function`` objects:

- ``pin_vel(q[nq], v[nv]) -> V[6*nj]``: each joint's spatial velocity in its LOCAL frame,
  ``[linear [m/s]; angular [rad/s]]`` (``data.v[1:]`` after ``forwardKinematics``);
- ``pin_aba(q, v, tau[nv], dyn[10*nj], fext[6*nj], g[3]) -> ddq[nv]``: ``pinocchio::aba``,
  LOCAL convention;
- ``pin_rnea(q, v, a[nv], dyn, fext, g) -> tau[nv]``: ``pinocchio::rnea``.

``nj = model.njoints - 1``. Joint i's inertia is ``Inertia.FromDynamicParameters(
dyn[10*(i-1):10*i])`` (order of ``pin.Inertia.toDynamicParameters()``: mass [kg], first
moment [kg·m], rotational inertia at the joint origin [kg·m²]); ``fext[6*(i-1):6*i]`` is the
force on joint i in its LOCAL frame ``[force [N]; torque [N·m]]``; ``g`` is the gravity
vector [m/s²] (the model's own gravity is ignored). Called with SX arguments the functions
inline into a larger expression graph.

The generator binary lives under the virtual environment (``sys.prefix``), or the user cache
directory when that is read-only, in a folder keyed by the pin, casadi and cmeel-eigen
versions and the source, so it is rebuilt only when one of them changes. Generated functions
are cached per model text on disk (same folder) and in memory. Every file is written under a
temporary name in its final directory and renamed, so concurrent processes both succeed.

``python -m winder.model.pin_casadi`` builds the generator (``make venv``/``make test`` run it).
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

from winder._errors import ArgumentTypeError, WinderError

if TYPE_CHECKING:
    import casadi as ca
    import pinocchio as pin

__all__ = ["PinFunctions", "PinCasadiError", "generator_path", "unavailable_reason",
           "functions", "SOURCE", "FUNCTION_NAMES"]

#: The generator's C++ source.
SOURCE = Path(__file__).with_name("_pin_casadi.cpp")
#: The three functions the generator saves, in the order of :class:`PinFunctions`.
FUNCTION_NAMES = ("pin_vel", "pin_aba", "pin_rnea")
#: Boost configuration Pinocchio's headers are built with (from ``pinocchioTargets.cmake``);
#: without it the joint variant fails to compile ("wrong number of template arguments").
BOOST_DEFINES = ("-DBOOST_MPL_LIMIT_LIST_SIZE=30", "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
                 "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", "-DBOOST_FUSION_INVOKE_MAX_ARITY=12")
#: Compiler flags; -O1 costs no more build time than -O0 and the generator runs in 0.01 s.
CXXFLAGS = ("-std=c++17", "-O1", "-Wno-deprecated-declarations", *BOOST_DEFINES)
_BINARY = "_pin_casadi"
_ENV_DIR = "WINDER_PIN_CASADI_DIR"  # overrides where the generator and the cache live


class PinCasadiError(WinderError, RuntimeError):
    """The generator cannot be built or run here (the message says why and what to do)."""


class PinFunctions(NamedTuple):
    """The three CasADi functions of one Pinocchio model (see the module docstring)."""

    vel: ca.Function
    aba: ca.Function
    rnea: ca.Function


_reason: str | None = None          # why generator_path() last returned None
_loaded: dict[str, PinFunctions] = {}  # model-text hash -> functions (this process)


def unavailable_reason() -> str | None:
    """Why the last :func:`generator_path` call returned None (None when it did not)."""
    return _reason


def _wheel_dirs() -> tuple[Path, Path]:
    """``(cmeel.prefix, casadi package dir)`` of the installed wheels."""
    try:
        prefix = Path(importlib.metadata.distribution("pin").locate_file("cmeel.prefix"))
        casadi_dir = Path(importlib.metadata.distribution("casadi").locate_file("casadi"))
    except importlib.metadata.PackageNotFoundError as exc:
        raise PinCasadiError(f"pin_casadi: the Python package {exc.name!r} is not installed; "
                             "pip install pin casadi cmeel-eigen") from exc
    return Path(prefix), Path(casadi_dir)


def _key() -> str:
    """Folder name: the versions the binary depends on, a hash of the source and the flags."""
    versions = []
    for dist in ("pin", "casadi", "cmeel-eigen"):
        try:
            versions.append(f"{dist}{importlib.metadata.version(dist)}")
        except importlib.metadata.PackageNotFoundError:
            versions.append(f"{dist}-none")
    digest = hashlib.sha256(SOURCE.read_bytes() + " ".join(CXXFLAGS).encode())
    return "-".join(versions) + "-" + digest.hexdigest()[:12]


def _writable(path: Path) -> bool:
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return False
    return os.access(path, os.W_OK)


def _root() -> Path:
    """The folder for this generator version and its model cache."""
    key = _key()
    env = os.environ.get(_ENV_DIR)
    # the user's cache first: every clone and venv with the same pin, casadi and eigen
    # (the key) shares one build of the generator
    candidates = [Path(env)] if env else [
        Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "winder" / "pin-casadi",
        Path(sys.prefix) / "winder-pin-casadi"]
    for base in candidates:
        if _writable(base / key):
            return base / key
    raise PinCasadiError(f"pin_casadi: no writable folder for the generator (tried "
                         f"{', '.join(str(c) for c in candidates)}); set {_ENV_DIR}")


def compile_command(output: Path) -> list[str]:
    """The g++ command that builds the generator into ``output``."""
    prefix, casadi_dir = _wheel_dirs()
    include, lib = prefix / "include", prefix / "lib"
    for needed, package in ((include / "pinocchio" / "autodiff" / "casadi.hpp", "pin"),
                            (include / "eigen3" / "Eigen" / "Core", "cmeel-eigen"),
                            (casadi_dir / "include" / "casadi" / "casadi.hpp", "casadi")):
        if not needed.exists():
            raise PinCasadiError(f"pin_casadi: {needed} is missing; pip install {package}")
    return ["g++", *CXXFLAGS,
            f"-I{include}", f"-I{include / 'eigen3'}", f"-I{casadi_dir / 'include'}",
            str(SOURCE), "-o", str(output),
            f"-L{casadi_dir}", "-lcasadi", f"-L{lib}", "-lboost_serialization",
            f"-Wl,-rpath,{casadi_dir}", f"-Wl,-rpath,{lib}"]


class _Lock:
    """An exclusive ``flock`` on ``path`` (a no-op where fcntl does not exist)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.fd: int | None = None

    def __enter__(self) -> _Lock:
        try:
            import fcntl
        except ImportError:  # pragma: no cover - not POSIX
            return self
        self.fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        fcntl.flock(self.fd, fcntl.LOCK_EX)
        return self

    def __exit__(self, *exc: object) -> None:
        if self.fd is not None:
            os.close(self.fd)  # closing releases the lock


def _run_group(command: list[str]) -> tuple[int, str]:
    """Run ``command`` in its own process group; (exit status, stdout + stderr).

    If this process is interrupted, the whole group is ended: killing only g++ would leave
    its cc1plus (4 GB) running.
    """
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, start_new_session=True)
    try:
        output, _ = proc.communicate()
    except BaseException:
        os.killpg(proc.pid, signal.SIGTERM)
        proc.wait()
        raise
    return proc.returncode, output


def generator_path(build: bool = True) -> Path | None:
    """The generator binary, built first if it is missing and ``build`` is true.

    Returns None (and :func:`unavailable_reason` says why) where g++ is missing or, with
    ``build=False``, where the binary has not been built. Raises :class:`PinCasadiError`
    when the wheels are incomplete or g++ fails (with its last lines of output).
    """
    global _reason
    _reason = None
    root = _root()
    binary = root / _BINARY
    if binary.exists():
        return binary
    if not build:
        _reason = f"the pin_casadi generator is not built yet ({binary})"
        return None
    if shutil.which("g++") is None:
        _reason = ("g++ is not on PATH: the pin_casadi generator (Pinocchio's C++ headers on "
                   "casadi::SX) cannot be built; install g++ (Debian: apt-get install g++)")
        return None
    with _Lock(root / ".build.lock"):  # one 4 GB compile at a time; others wait and reuse it
        if binary.exists():
            return binary
        fd, tmp_name = tempfile.mkstemp(prefix=f".{_BINARY}.", dir=root)
        os.close(fd)
        tmp = Path(tmp_name)
        try:
            command = compile_command(tmp)
            print(f"winder: building the pin_casadi generator ({binary}); about 2-3 min and "
                  "4 GB of memory, once per pin/casadi version", file=sys.stderr, flush=True)
            returncode, output = _run_group(command)
            if returncode != 0:
                tail = "\n".join(output.splitlines()[-25:])
                raise PinCasadiError(f"pin_casadi: g++ failed (exit {returncode}) building "
                                     f"{SOURCE}:\n{tail}\ncommand: {' '.join(command)}")
            os.replace(tmp, binary)
        finally:
            tmp.unlink(missing_ok=True)
    return binary


def _model_text(model: pin.Model) -> str:
    with tempfile.TemporaryDirectory(prefix="winder-pin-casadi-") as tmp:
        path = Path(tmp) / "model.txt"
        model.saveToText(str(path))
        return path.read_text()


def _generate(binary: Path, text: str, final: Path) -> None:
    """Run the generator on ``text`` into ``final`` (renamed in whole from a temporary dir)."""
    final.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{final.name}.", dir=final.parent))
    try:
        (tmp / "model.txt").write_text(text)
        run = subprocess.run([str(binary), str(tmp / "model.txt"), str(tmp)],
                             capture_output=True, text=True, check=False)
        if run.returncode != 0:
            raise PinCasadiError(f"pin_casadi: the generator {binary} failed (exit "
                                 f"{run.returncode}): {run.stderr.strip() or run.stdout.strip()}")
        missing = [n for n in FUNCTION_NAMES if not (tmp / f"{n}.casadi").exists()]
        if missing:
            raise PinCasadiError(f"pin_casadi: the generator {binary} wrote no "
                                 f"{', '.join(missing)}")
        try:
            os.rename(tmp, final)  # atomic; fails if another process got there first
        except OSError:
            if not _complete(final):
                raise
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)


def _complete(folder: Path) -> bool:
    return all((folder / f"{n}.casadi").exists() for n in FUNCTION_NAMES)


def functions(model: pin.Model) -> PinFunctions:
    """The CasADi functions ``pin_vel``, ``pin_aba`` and ``pin_rnea`` of ``model``.

    Cached by the model's text (``saveToText``) in memory and on disk; the first call for a
    model runs the generator (about 0.01 s), building it first if needed (about 160 s of CPU).
    Raises :class:`PinCasadiError` where g++ is missing or the generator fails.
    """
    import casadi as ca
    import pinocchio as pin

    if not isinstance(model, pin.Model):
        raise ArgumentTypeError(f"functions: model must be a pinocchio.Model, got "
                                f"{type(model).__name__}")
    text = _model_text(model)
    root = _root()
    digest = hashlib.sha256(text.encode()).hexdigest()[:20]
    key = f"{root.name}/{digest}"
    if key in _loaded:
        return _loaded[key]
    folder = root / "models" / digest
    if not _complete(folder):
        binary = generator_path(build=True)
        if binary is None:
            raise PinCasadiError(f"pin_casadi: {unavailable_reason()}")
        _generate(binary, text, folder)
    loaded = PinFunctions(*(ca.Function.load(str(folder / f"{n}.casadi"))
                            for n in FUNCTION_NAMES))
    _loaded[key] = loaded
    return loaded


def main() -> int:
    """``python -m winder.model.pin_casadi``: build the generator if needed, print its path.

    Exits 0 with a warning where g++ is missing (the features that need it say so when used),
    1 when the build fails.
    """
    start = time.perf_counter()
    try:
        path = generator_path(build=True)
    except PinCasadiError as exc:
        print(f"winder: {exc}", file=sys.stderr)
        return 1
    if path is None:
        print(f"winder: warning: {unavailable_reason()}", file=sys.stderr)
        return 0
    print(f"pin_casadi generator: {path} ({time.perf_counter() - start:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
