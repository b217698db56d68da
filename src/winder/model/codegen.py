"""Generated C for a machine: its right-hand side, exact Jacobian, channels and switching
functions, compiled once per structure and cached on disk.

The machine's dynamics (:meth:`~winder.model.machine.Machine.evaluate`) runs once on CasADi
symbols; four functions of ``(t, x, p, m)`` (time, state, parameters, locked modes) are
generated as C, one file each (a large right-hand side in parts, :data:`RHS_PART`), wrapped
with flat entry points ``int NAME(const double* t, const double* x, const double* p, const
double* m, double* out)``. Each file goes to its
own compiler process as soon as it is written (the right-hand side first), at the
optimisation level of its function (:data:`OPTIMISE`). The right-hand side, channels and
switching functions (:data:`MAIN`: all an explicit run needs) are joined into one
relocatable object and the machine's library. The Jacobian (:data:`JACOBIAN`; most of a
large machine's build) is generated and compiled on first use (:meth:`Generated.jacobian`:
implicit methods, linearisation, modes) into a library of its own beside the first,
``SYMBOL_jac.so``, under the same key. It is generated on its structural nonzeros only (in
two column blocks, two files, when it is large); its flat entry point scatters them into
the dense column-major matrix its callers expect (``SYMBOL_jac_nz_flat`` writes the
nonzeros alone, ``SYMBOL_jac_sparsity`` gives their CCS pattern). CasADi's null checks on
each argument read and result written are removed (the flat entry points pass them all):
one branch per element made the compiler's time grow faster than the function. Every build
longer than a moment says so on stderr (what, how big, how long). The cache key is
everything that changes the generated code: the machine's structure
(:meth:`~winder.model.machine.Machine.structure_key`), the source of the physics
(:mod:`winder.model`, :mod:`winder.parts`, :mod:`winder.forces`), the CasADi version, the
layout (:data:`LAYOUT`) and the compiler flags and levels.

The machine's library links that object with the objects the caller brings (the
integrators of :mod:`winder.solve.cint`: ``generate(machine, link=...)``), cached under a
key of both; changing an integrator relinks (about 0.05 s) and recompiles nothing
generated. ``WINDER_SANITIZE=1`` builds everything with AddressSanitizer and UBSan
(:data:`SANITIZE_CFLAGS`, a separate cache key).
Writes are atomic (a temporary file, then ``os.replace``), so processes building the same
model at once all succeed. Parameter values are run-time inputs: changing one compiles
nothing.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from winder.model.c_entry import flat_entry as _flat_entry
from winder.model.c_entry import unguarded as _unguarded
from winder.model.c_split import write_parts
from winder.model.compiler import CompileError, CompilerMissing, Compiles, run_compiler
from winder.model.machine import Machine

__all__ = ["Generated", "generate", "cache_dir", "CompilerMissing", "CompileError", "FUNCTIONS",
           "stats", "Link", "compile_flags", "link_flags", "run_compiler",
           "sanitized", "SANITIZE_CFLAGS", "CFLAGS", "source_hash", "write_source",
           "OPTIMISE", "function_flags", "LAYOUT", "LARGE", "level", "JAC_SPLIT",
           "MAIN", "JACOBIAN", "RHS_PART", "with_level"]

#: The generated functions, in the order of :attr:`Generated.addresses`.
FUNCTIONS = ("rhs", "jac", "out", "sw")
#: ``-fno-semantic-interposition``: the generated helpers (``sq``, ``fmax``, ...) are inlined
#: into the functions that call them rather than called through the PLT (the rhs 1.7×
#: faster; the same operations, so the same results). ``-ffp-contract=off``: no fused
#: multiply–add on any target (x86-64 without ``-march`` has none; aarch64 fuses at -O2 and
#: not at -O1), so the optimisation levels and the rhs in parts change no rounding.
CFLAGS = ("-O3", "-shared", "-fPIC", "-fno-semantic-interposition", "-ffp-contract=off")
#: The optimisation level of each generated function's object (:func:`level`): the
#: right-hand side and the switching functions, called at every stage of every step, at -O3;
#: the Jacobian and the channels, called once per step or per output, at -Og (as fast as
#: -O1 at run time, 30 % cheaper to compile: the flexible two-drum winder's Jacobian, 58,825
#: instructions, 7.8 s CPU against 10.9 s at -O1 and 24.7 s at -O3, 20 µs a call). None
#: changes a result: no fast-math, no FMA contraction on the default target.
OPTIMISE = {"rhs": "-O3", "jac": "-Og", "out": "-Og", "sw": "-O3",
            "part": "-O1 -fstrict-aliasing -finline-small-functions"}
#: A right-hand side of more CasADi instructions than this is cut into parts of about this
#: many (:mod:`winder.model.c_split`: the same operations, bitwise the same results), one
#: file each, compiled at once at ``OPTIMISE["part"]``: -O1 and the two -O2 passes that
#: matter here (CasADi's ``sq``, ``fmax``, ``fabs`` inlined; ``arg[i]`` not reloaded after
#: each store): 0-1 % more instructions per call than -O3 (valgrind), half its compile
#: time. One large function at -O1+ would not do: its register allocation grows faster
#: than it (the flexible drum's rhs at N = 32: 3.1 s against 2.9 s at -O3; 3 parts 1.2 s).
RHS_PART = 4000
#: A channel function of more CasADi instructions than this compiles at -O0 (called once
#: per output row: the flexible two-drum winder's, 8394 instructions, 2.0 s CPU at -O1, 0.7 s
#: at -O0). Not the Jacobian: at -O0 it compiles in half the time of -Og (3.9 s) but runs
#: 2-2.5 times slower (48 against 20 µs; an implicit method calls it every step).
LARGE = 5000
#: A Jacobian of this many nonzeros or more is generated in two column blocks, two files
#: compiled at once (1.08 times the instructions of one for the flexible two-drum winder's
#: 4800 nonzeros; a machine's Jacobian is most of its build).
JAC_SPLIT = 2000
#: A Jacobian's build (on first use) that took longer than this [s] says so again when done.
SAY_AFTER = 5.0
#: The layout of the generated code (in the cache key): one C file per function, the
#: Jacobian on its nonzeros scattered by its flat entry point (beside it its nonzeros' entry
#: point and CCS pattern) in a library of its own built on first use, CasADi's null checks
#: removed; a large right-hand side in parts (:data:`RHS_PART`).
LAYOUT = "lazy-jac-split-sparse-unguarded-rhs-parts-5"
#: ``WINDER_SANITIZE=1`` (``make test-asan``): AddressSanitizer and UBSan on every object
#: and the link (Python then needs libasan preloaded; see the Makefile).
SANITIZE_CFLAGS = ("-fsanitize=address,undefined", "-fno-sanitize-recover=undefined",
                   "-fno-omit-frame-pointer", "-g")
#: Counters of this process: models compiled, libraries linked (the generated object
#: cached), libraries loaded from the cache, and Jacobians compiled (on first use).
stats = {"compiled": 0, "linked": 0, "cached": 0, "jacobians": 0}


def cache_dir() -> Path:
    """``$WINDER_CACHE_DIR`` or ``$XDG_CACHE_HOME/winder`` (``~/.cache/winder``)."""
    env = os.environ.get("WINDER_CACHE_DIR")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "winder"


def sanitized() -> bool:
    """Whether ``$WINDER_SANITIZE`` asks for sanitized builds."""
    return os.environ.get("WINDER_SANITIZE", "") not in ("", "0")


def compile_flags() -> tuple[str, ...]:
    """The flags an object is compiled with (``-c``; :data:`CFLAGS` without ``-shared``;
    where :func:`sanitized`, ``-O1`` and :data:`SANITIZE_CFLAGS`: without fast-math or FMA
    contraction the optimisation level changes no result)."""
    flags = tuple(f for f in CFLAGS if f != "-shared")
    if sanitized():  # -O1: a sanitized build compiles several times faster than -O3
        return (*("-O1" if f == "-O3" else f for f in flags), *SANITIZE_CFLAGS)
    return flags


def level(which: str, size: int) -> str:
    """The optimisation level of one generated function (one of :data:`FUNCTIONS`, or
    ``"part"``: a part of a right-hand side over :data:`RHS_PART`) of ``size`` CasADi
    instructions: :data:`OPTIMISE`, and -O0 for a channel function over :data:`LARGE`."""
    return "-O0" if which == "out" and size > LARGE else OPTIMISE[which]


def with_level(flags: tuple[str, ...] | list[str], lv: str) -> tuple[str, ...]:
    """``flags`` with their ``-O3`` replaced by the level ``lv`` (one or more flags, such as
    ``OPTIMISE["part"]``)."""
    return tuple(g for f in flags for g in (lv.split() if f == "-O3" else (f,)))


def function_flags(which: str, size: int) -> tuple[str, ...]:
    """The flags the object of one generated function is compiled with:
    :func:`compile_flags` at its :func:`level` (sanitized: -O1 throughout)."""
    flags = compile_flags()
    return flags if sanitized() else with_level(flags, level(which, size))


def link_flags() -> tuple[str, ...]:
    """The flags the machine's shared library is linked with."""
    return (*CFLAGS, *SANITIZE_CFLAGS) if sanitized() else CFLAGS


def source_hash() -> str:
    """A hash of the physics' source (:mod:`winder.model`, :mod:`winder.parts`,
    :mod:`winder.forces`; computed once per process)."""
    global _SOURCE
    if _SOURCE is None:
        _SOURCE = _source_hash()
    return _SOURCE


def _source_hash() -> str:
    h = hashlib.sha256()
    root = Path(__file__).resolve().parent.parent
    files: list[Path] = []
    for sub in ("model", "parts", "forces"):  # everything the generated code is built from
        files += sorted([*(root / sub).glob("*.py"), *(root / sub).glob("*.cpp")])
    for f in files:
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()


_SOURCE: str | None = None


def _casadi_version() -> str:
    """CasADi's version, from its package metadata (no import)."""
    import importlib.metadata

    try:
        return importlib.metadata.version("casadi")
    except importlib.metadata.PackageNotFoundError:  # a build without metadata: import it
        import casadi as ca

        return str(ca.__version__)


@dataclass
class Generated:
    """A compiled machine: function addresses and sizes (keep it alive while in use).

    ``addresses`` holds the flat entry points of :data:`FUNCTIONS`; the Jacobian's is 0
    until :meth:`jacobian` builds (or loads) its library, which writes it in place (every
    holder of the array sees it)."""

    key: str
    path: Path
    n_states: int
    n_params: int
    n_modes: int
    n_switches: int
    n_channels: int
    addresses: np.ndarray  # int64 addresses of FUNCTIONS (the Jacobian's 0 until built)
    build_seconds: float = 0.0
    from_cache: bool = False
    route: str = "py"
    #: CasADi instructions of each function (file) built in this process (empty when
    #: loaded from the cache): ``rhs`` (a large one in parts: ``rhs1``, ``rhs2``, ...,
    #: ``rhs``), ``out``, ``sw``, and ``jac`` (``jac1``) once built
    sizes: dict[str, int] = field(default_factory=dict)
    _lib: Any = field(default=None, repr=False)
    _jac_lib: Any = field(default=None, repr=False)
    _make_jac: Callable[[dict[str, int]], Path] | None = field(default=None, repr=False)

    def jacobian(self) -> int:
        """The address of the Jacobian's flat entry point ``SYMBOL_jac_flat`` (dense,
        column-major; beside it ``SYMBOL_jac_nz_flat``, its nonzeros only, and
        ``SYMBOL_jac_sparsity``, their CCS pattern): its library loaded from the cache, or
        generated and compiled on this first use (:func:`generate`). Writes it into
        :attr:`addresses`."""
        if self._jac_lib is None:
            if self._make_jac is None:
                raise CompileError("this machine's Jacobian cannot be built (no builder)")
            self._jac_lib = ctypes.CDLL(str(self._make_jac(self.sizes)))
            self._make_jac = None  # frees the symbols it kept
        address = ctypes.cast(getattr(self._jac_lib, f"{self.symbol}_jac_flat"),
                              ctypes.c_void_p).value
        self.addresses[FUNCTIONS.index("jac")] = address
        return int(address)

    def library(self, which: str) -> Any:
        """The loaded library holding the generated function ``which`` (one of
        :data:`FUNCTIONS`; the Jacobian's built on first use)."""
        if which == "jac":
            self.jacobian()
            return self._jac_lib
        return self._lib

    def jac_sparsity(self) -> tuple[np.ndarray, np.ndarray]:
        """The Jacobian's structural sparsity (CCS): ``colind`` (n_states + 1) and ``row``
        (one per nonzero), the order :meth:`call` ``("jac_nz", ...)`` writes them in."""
        fn = getattr(self.library("jac"), f"{self.symbol}_jac_sparsity")
        fn.restype = ctypes.POINTER(ctypes.c_int64)
        sp = fn()
        n = self.n_states
        colind = np.array(sp[2:3 + n], dtype=np.int64)
        return colind, np.array(sp[3 + n:3 + n + int(colind[-1])], dtype=np.int64)

    def call(self, which: str, t: float, x: np.ndarray, p: np.ndarray,
             m: np.ndarray) -> np.ndarray:
        """Evaluate one generated function from Python (slow path, for tests/outputs);
        ``"jac_nz"``: the Jacobian's nonzeros (:meth:`jac_sparsity`)."""
        lib = self.library("jac" if which == "jac_nz" else which)
        size = {"rhs": self.n_states, "jac": self.n_states ** 2, "out": self.n_channels,
                "sw": self.n_switches}.get(which)
        if size is None:
            size = int(self.jac_sparsity()[0][-1])
        out = np.empty(size)
        tb = np.array([t], float)
        xs, ps, ms = (np.ascontiguousarray(a, dtype=float) for a in (x, p, m))
        fn = getattr(lib, f"{self.symbol}_{which}_flat")
        dp = ctypes.POINTER(ctypes.c_double)
        fn(*(a.ctypes.data_as(dp) for a in (tb, xs, ps, ms, out)))
        if which == "jac":
            return out.reshape(self.n_states, self.n_states, order="F")
        return out

    @property
    def symbol(self) -> str:
        return f"w{self.key}"


class _Symbols:
    """The machine's dynamics on CasADi symbols: ``(t, x, p, m)``, the evaluation and the
    right-hand side ``xdot``; its Jacobian ``∂xdot/∂x`` made on first use (the lazy
    Jacobian's library may never be asked for)."""

    def __init__(self, machine: Machine, route: str) -> None:
        import casadi as ca

        from winder.model.backends import SymbolicBackend

        self.t = ca.SX.sym("t")
        self.x = ca.SX.sym("x", machine.n_states)
        self.p = ca.SX.sym("p", len(machine.param_names))
        self.m = ca.SX.sym("m", len(machine.mode_names))
        self.ev = machine.evaluate(SymbolicBackend(machine.model, route), self.t, self.x,
                                   self.p, self.m)
        self.xdot = ca.vertcat(*[self.ev.rates[n] for n in machine.state_names])
        self._jac: Any = None

    @property
    def jac(self) -> Any:
        if self._jac is None:
            import casadi as ca

            self._jac = ca.jacobian(self.xdot, self.x)
        return self._jac


#: The functions of the machine's first object (everything an explicit run needs) and of
#: its Jacobian's library (built on first use), in the order they are generated.
MAIN, JACOBIAN = ("rhs", "out", "sw"), ("jac",)


def _c_source(machine: Machine, symbol: str, directory: Path, route: str,
              ready: Callable[[str, Path, int], None] | None = None, *,
              pattern: bool = False, which: tuple[str, ...] = ("rhs", "jac", "out", "sw"),
              symbols: _Symbols | None = None
              ) -> tuple[list[tuple[str, Path, int]], dict[str, np.ndarray]]:
    """Write one C file per generated function of ``which`` (default: all of
    :data:`FUNCTIONS`; :data:`MAIN` or :data:`JACOBIAN`), ``SYMBOL_{rhs,jac,out,sw}.c``
    (each with its flat entry point), calling ``ready(which, path, size)`` (``size``:
    CasADi instructions) as soon as each is written (so that its compilation starts while
    the next one is generated). The Jacobian is generated on its structural nonzeros only
    (CCS) and scattered into the dense column-major matrix by its flat entry point; one of
    :data:`JAC_SPLIT` nonzeros or more is generated in two column blocks, the second in
    ``SYMBOL_jac1.c`` (compiled at once with the first). ``pattern``: also the structural
    sparsity of dxdot/dx and dxdot/dp, ``(row, column)`` per nonzero (for an FMU).
    ``symbols``: the machine on CasADi symbols if already made (:class:`_Symbols`).
    Returns ``(which, path, size)`` per file and the patterns."""
    import casadi as ca

    sym = _Symbols(machine, route) if symbols is None else symbols
    t, x, p, m, ev, xdot = sym.t, sym.x, sym.p, sym.m, sym.ev, sym.xdot
    patterns = {}
    if pattern:  # the structural sparsity of dxdot/dx and dxdot/dp: (row, column) per nonzero
        for name, sp in (("x", sym.jac.sparsity()), ("p", ca.jacobian(xdot, p).sparsity())):
            patterns[name] = np.array(sp.get_triplet(), dtype=np.int64).reshape(2, -1).T
    outs: list[tuple[str, str, Any]] = []
    blocks: list[tuple[str, int, Any]] = []
    # the order of generation: the rhs first (its compile is long for its size), the
    # Jacobian's file with the flat entry point last of its blocks
    if "rhs" in which:
        outs.append(("rhs", "rhs", lambda: ca.densify(xdot)))  # cut into parts if large
    if "jac" in which:
        jac = sym.jac
        colind = jac.sparsity().colind()
        cuts = [0, machine.n_states]
        if jac.nnz() >= JAC_SPLIT:  # two column blocks of about half the nonzeros each
            cuts.insert(1, next(c for c in range(machine.n_states + 1)
                                if colind[c] >= jac.nnz() / 2))
        blocks = [(f"jac{i}" if i else "jac", colind[a], jac[:, a:b])
                  for i, (a, b) in enumerate(zip(cuts, cuts[1:], strict=False))]
        outs += [("jac", name, lambda e=e: e) for name, _, e in reversed(blocks)]
    if "out" in which:
        outs.append(("out", "out", lambda: ca.densify(ca.vertcat(
            *[ev.channels[n] for n in machine.channel_names]))))
    if "sw" in which:
        outs.append(("sw", "sw", lambda: ca.densify(ca.vertcat(
            *[ev.switches[n] for n in machine.switch_names]))))
    files: list[tuple[str, Path, int]] = []
    made: dict[str, Any] = {}
    for kind, name, expr in outs:
        f = made[name] = ca.Function(f"{symbol}_{name}", [t, x, p, m], [expr()], {"cse": True})
        if kind == "rhs" and f.n_instructions() > RHS_PART:  # in parts, one file each
            files += write_parts(f, symbol, directory, RHS_PART, ready)
            continue
        cg = ca.CodeGenerator(f"{symbol}_{name}.c", {"with_header": False})
        cg.add(f)
        # dump() rather than generate(): the same code, written here, without loading
        # CasADi's file-system plugin (dlopen with RTLD_DEEPBIND, which AddressSanitizer
        # refuses)
        path = directory / f"{symbol}_{name}.c"
        entry = "" if name.startswith("jac") and name != "jac" else _flat_entry(
            symbol, kind, f, [(f"{symbol}_{n}", made[n], off) for n, off, _ in blocks]
            if name == "jac" else None, sym.jac.sparsity() if name == "jac" else None)
        path.write_text(f"/* {symbol}_{name}: generated by CasADi {ca.__version__} for "
                        "winder */\n" + _unguarded(cg.dump()) + entry)
        files.append((kind, path, f.n_instructions()))
        if ready is not None:
            ready(*files[-1])
    return files, patterns


def _say(line: str) -> None:
    """One line on stderr about a build (a build is never silent: it can take a minute)."""
    print(line, file=sys.stderr, flush=True)


def _key(machine: Machine, route: str, cflags: tuple[str, ...]) -> str:
    """The cache key of a machine's generated code (:func:`generate`): its structure, the
    physics' source, CasADi, the route, the layout and every object's flags."""
    levels = (f"{sorted(OPTIMISE.items())} out -O0 over {LARGE}; jac split at {JAC_SPLIT}; "
              f"rhs parts of {RHS_PART}")
    return hashlib.sha256("|".join((machine.structure_key(), source_hash(), _casadi_version(),
                                    route, LAYOUT, levels, " ".join(cflags))).encode()
                          ).hexdigest()[:20]


def write_source(machine: Machine, directory: Path, *, route: str | None = None
                 ) -> tuple[list[Path], str, dict[str, np.ndarray], list[str]]:
    """Write the machine's generated C (the code :func:`generate` compiles: one file
    ``SYMBOL_K.c`` per function K of :data:`FUNCTIONS`, each with its flat entry point
    ``SYMBOL_K_flat``, and ``SYMBOL_jac1.c`` for a Jacobian in two blocks) into
    ``directory``: the files' paths, ``SYMBOL``, the structural
    sparsity of the right-hand side's Jacobians w.r.t. the states (``"x"``) and the
    parameters (``"p"``), ``(row, column)`` per nonzero (for an FMU's ``sources/`` and
    ``ModelStructure``), and each file's optimisation :func:`level` (imports CasADi)."""
    from winder.model.backends import default_route

    route = default_route() if route is None else route
    symbol = f"w{_key(machine, route, compile_flags())}"
    files, pattern = _c_source(machine, symbol, Path(directory), route, pattern=True)
    return ([f for _, f, _ in files], symbol, pattern,
            [level(which, size) for which, _, size in files])


@dataclass(frozen=True)
class Link:
    """Objects linked into every machine's library, and a key of their sources and
    flags (it names the library beside the generated code's key)."""

    objects: tuple[Path, ...]
    key: str


def generate(machine: Machine, *, directory: Path | None = None,
             route: str | None = None, link: Link | None = None) -> Generated:
    """The compiled functions of ``machine``: from the cache, or generated and compiled
    (and cached). ``route``: how Pinocchio's algorithms reach the symbols (one of
    :data:`~winder.model.backends.ROUTES`; default:
    :func:`~winder.model.backends.default_route`).
    ``link``: objects linked into the machine's library with the generated code (the
    integrators). Raises :class:`CompilerMissing` without a C compiler. A cached machine
    loads without importing CasADi (its version comes from the package metadata).

    The Jacobian is not in this library: it is generated and compiled on first use
    (:meth:`Generated.jacobian`) into its own library beside it, ``SYMBOL_jac.so`` (the
    same key; the symbols of this build kept for it, else made again)."""
    from winder.model.backends import default_route

    route = default_route() if route is None else route
    cflags = compile_flags()
    key = _key(machine, route, cflags)
    symbol = f"w{key}"
    root = Path(directory) if directory is not None else cache_dir() / "generated"
    obj = root / f"{symbol}.o"
    lib = root / (f"{symbol}-{link.key}.so" if link is not None else f"{symbol}.so")
    name = getattr(getattr(machine, "scene", None), "name", "the machine")
    t0 = time.perf_counter()
    from_cache = lib.exists()
    kept: list[_Symbols] = []  # the symbols of this build, for the Jacobian
    sizes: dict[str, int] = {}
    if not from_cache:
        root.mkdir(parents=True, exist_ok=True)
        compiled = not obj.exists()
        with tempfile.TemporaryDirectory(dir=root, prefix=".build-") as tmp:
            if compiled:
                _say(f"winder: building {name}'s code once ({machine.n_states} states, "
                     f"{machine.model.nbodies - 1} bodies; cached in {root})")
                kept.append(_Symbols(machine, route))
                srcs = _compile_sources(machine, symbol, Path(tmp), route, MAIN, kept[0],
                                        sizes)
                tmp_obj = Path(tmp) / obj.name  # one relocatable object of the three
                run_compiler(["-r", "-nostdlib", *(str(s.with_suffix(".o")) for s in srcs),
                              "-o", str(tmp_obj)], "the generated model (-r)")
                os.replace(tmp_obj, obj)
                size = sum(s.stat().st_size for s in srcs)
                _say(f"winder: {name}'s code built in {time.perf_counter() - t0:.1f} s "
                     f"({size / 1024:.0f} kB of C, {sum(sizes.values()):,} CasADi "
                     "instructions; its Jacobian is built on first use)")
            tmp_lib = Path(tmp) / lib.name
            extra = [str(o) for o in link.objects] if link is not None else []
            run_compiler([*link_flags(), str(obj), *extra, "-o", str(tmp_lib), "-lm"],
                         "the machine's library")
            os.replace(tmp_lib, lib)
        stats["compiled" if compiled else "linked"] += 1
    else:
        stats["cached"] += 1
    handle = ctypes.CDLL(str(lib))
    addrs = np.array([0 if k == "jac" else
                      ctypes.cast(getattr(handle, f"{symbol}_{k}_flat"), ctypes.c_void_p).value
                      for k in FUNCTIONS], dtype=np.int64)

    def make_jac(into: dict[str, int]) -> Path:
        return _jacobian_library(machine, symbol, root, route, name,
                                 kept[0] if kept else None, into)

    gen = Generated(key, lib, machine.n_states, len(machine.param_names),
                    len(machine.mode_names), len(machine.switch_names),
                    len(machine.channel_names), addrs, time.perf_counter() - t0, from_cache,
                    route, sizes, handle, None, make_jac)
    if (root / f"{symbol}_jac.so").exists():  # built before: load it now (cheap)
        gen.jacobian()
    return gen


def _compile_sources(machine: Machine, symbol: str, tmp: Path, route: str,
                     which: tuple[str, ...], symbols: _Symbols | None,
                     sizes: dict[str, int]) -> list[Path]:
    """Write the C of the functions ``which`` into ``tmp`` and compile each into an object
    beside it (one compiler process each, started as soon as its file is written); the
    sources' paths. ``sizes``: each file's CasADi instructions, by its function's name."""
    these: dict[str, int] = {}  # this call's files
    with Compiles() as jobs:  # each function compiles while the next is made
        def ready(kind: str, src: Path, size: int) -> None:
            sizes[src.stem.rsplit("_", 1)[1]] = these[src.stem.rsplit("_", 1)[1]] = size
            jobs.start([*function_flags(kind, size), "-c", str(src), "-o",
                        str(src.with_suffix(".o"))], "the generated model")

        srcs = [f for _, f, _ in _c_source(machine, symbol, tmp, route, ready, which=which,
                                           symbols=symbols)[0]]
        if sum(these.values()) > RHS_PART:  # a build of seconds: what it compiles, how big
            kb = sum(s.stat().st_size for s in srcs) / 1024
            _say(f"winder: compiling {_what(these)} ({kb:.0f} kB of C, {len(srcs)} compiler "
                 "processes)")
        jobs.wait()
    return srcs


def _what(sizes: dict[str, int]) -> str:
    """``sizes`` (CasADi instructions by file) in words: each function's and its files."""
    words = []
    for k, label in (("rhs", "rhs"), ("jac", "Jacobian"), ("out", "channels"),
                     ("sw", "switching functions")):
        mine = [v for f, v in sizes.items() if f.rstrip("0123456789") == k]
        if mine:
            words.append(f"{label} {sum(mine):,}"
                         + (f" (in {len(mine)} files)" if len(mine) > 1 else ""))
    return ", ".join(words) + " CasADi instructions"


def _jacobian_library(machine: Machine, symbol: str, root: Path, route: str, name: str,
                      symbols: _Symbols | None, sizes: dict[str, int]) -> Path:
    """The Jacobian's library ``SYMBOL_jac.so`` in ``root``: from the cache, or generated
    (from ``symbols`` if kept, else the machine made on symbols again) and compiled (a
    line on stderr before, with its size, and one after if it took longer than
    :data:`SAY_AFTER`); written atomically."""
    lib = root / f"{symbol}_jac.so"
    if lib.exists():
        return lib
    t0 = time.perf_counter()
    root.mkdir(parents=True, exist_ok=True)
    symbols = _Symbols(machine, route) if symbols is None else symbols
    _say(f"winder: building {name}'s Jacobian once, on first use ({machine.n_states} "
         f"states, {symbols.jac.nnz()} nonzeros; cached in {root})")
    with tempfile.TemporaryDirectory(dir=root, prefix=".build-") as tmp:
        srcs = _compile_sources(machine, symbol, Path(tmp), route, JACOBIAN, symbols, sizes)
        tmp_lib = Path(tmp) / lib.name
        run_compiler([*link_flags(), *(str(s.with_suffix(".o")) for s in srcs), "-o",
                      str(tmp_lib), "-lm"], "the machine's Jacobian")
        os.replace(tmp_lib, lib)
        size = sum(s.stat().st_size for s in srcs)
    stats["jacobians"] += 1
    made = sum(v for k, v in sizes.items() if k.startswith("jac"))
    if time.perf_counter() - t0 > SAY_AFTER:  # a short one said once (before it)
        _say(f"winder: {name}'s Jacobian built in {time.perf_counter() - t0:.1f} s "
             f"({size / 1024:.0f} kB of C, {made:,} CasADi instructions)")
    return lib
