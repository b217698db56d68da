"""The native FMU of a scene: the compiled machine behind FMI 2.0 or FMI 3.0, no Python
inside (issue #24).

The archive holds ``binaries/<platform>/MODEL.so`` (``linux64`` for FMI 2.0,
``x86_64-linux`` for FMI 3.0), built with the system C compiler from the machine's
generated C (:func:`winder.model.codegen.write_source`: the same functions
:func:`winder.simulate` calls), winder's C integrators (``solve/c/``: the same DOPRI5 and
RK4 with located events and switched modes) and the wrapper ``fmu/c/fmi2.c`` (FMI 3.0:
also ``fmu/c/fmi3.c``, which translates each fmi3 call into the fmi2 one of the same
core); ``sources/`` with all of them, the machine's data (``winder_model.h``) and the FMI
headers of FMPy's ``c-code/`` (BSD-2, their license beside them), listed in
``<SourceFiles>`` (FMI 2.0) or ``sources/buildDescription.xml`` (FMI 3.0) so that ``fmpy
compile`` rebuilds it for another platform; and ``modelDescription.xml``
(:mod:`winder.fmu.description`). The variables: :mod:`winder.fmu.interface`.

The initial state is the static balance (:meth:`MachineSystem.initial_state
<winder.solve.system.MachineSystem.initial_state>`) of the scene's parameter values,
computed here at build time; where the host sets parameters, the exit of initialisation
mode solves the balance again in C (Newton on the generated force residual and its exact
Jacobian, from the built balance and in its active set: :mod:`winder.fmu.balance`). The
rest of the initial state (speeds, radii) stays the scene's.
"""

from __future__ import annotations

import hashlib
import re
import shutil
import sys
import uuid
import zipfile
from pathlib import Path
from typing import Any

from winder.fmu.balance import Balance, balance_of, write_balance_source
from winder.fmu.description import build_description, model_description
from winder.fmu.interface import NativeInterface, indicators, native_interface, zero_sides
from winder.fmu.parameters import FmuError, scene_with_parameters
from winder.model.codegen import CFLAGS, SANITIZE_CFLAGS, run_compiler, with_level, write_source
from winder.parts import body_elements
from winder.scene.load import Scene, load_scene

__all__ = ["build_fmu", "model_identifier", "FMI_VERSIONS"]

_C = Path(__file__).resolve().parent / "c"
_SOLVE_C = Path(__file__).resolve().parents[1] / "solve" / "c"
#: the integrators' sources copied into the FMU (ros2.c is not used)
_INTEGRATORS = ("dopri5.c", "rk4.c", "machine.c")
#: the FMI versions built: the wrappers, FMPy's headers and the binaries' platform folder
FMI_VERSIONS: dict[int, tuple[tuple[str, ...], tuple[str, ...], str]] = {
    2: (("fmi2.c",), ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
        "linux64"),
    3: (("fmi2.c", "fmi3.c"), ("fmi2Functions.h", "fmi2FunctionTypes.h",
                               "fmi2TypesPlatform.h", "fmi3Functions.h",
                               "fmi3FunctionTypes.h", "fmi3PlatformTypes.h"),
        "x86_64-linux"),
}


# ---- files ---------------------------------------------------------------------------------

def _c_array(ctype: str, name: str, values: Any, fmt: Any = str) -> str:
    """A static C array (a trailing 0 so that none is empty)."""
    items = [fmt(v) for v in values] + ["0"]
    return f"static const {ctype} {name}[] = {{{', '.join(items)}}};\n"


def _model_header(iface: NativeInterface, symbol: str, guid: str, balance: Balance) -> str:
    """``winder_model.h``: the machine's sizes, data and generated functions."""
    sy, m = iface.system, iface.system.machine
    owners = [f'"{mode.owner}"' for mode in m.modes] + ["0"]
    lines = [
        "/* The machine of one scene for fmi2.c (written by winder.fmu.native). */",
        "#ifndef WINDER_MODEL_H", "#define WINDER_MODEL_H", "#include <stdint.h>",
        f'#define W_GUID "{guid}"',
        f"#define W_N {sy.n_states}", f"#define W_NP {len(m.param_names)}",
        f"#define W_NSLOTS {len(sy.table)}", f"#define W_NSW {len(m.switch_names)}",
        f"#define W_NCH {len(m.channel_names)}", f"#define W_NOUT {len(iface.outputs)}",
        f"#define W_NIN {len(iface.inputs)}", f"#define W_NPAR {len(iface.parameters)}",
        f"#define W_NRAMP {len(iface.ramps)}", f"#define W_NZ {len(indicators(sy))}",
    ]
    lines += [f"#define W_NU {len(balance.unknowns)}",
              f"int {symbol}_balance_flat(const double* t, const double* x, const double* p, "
              "const double* m, double* out);", f"#define W_BAL_FN {symbol}_balance_flat"]
    for k in ("rhs", "jac", "out", "sw"):
        lines.append(f"int {symbol}_{k}_flat(const double* t, const double* x, "
                     "const double* p, const double* m, double* out);")
        lines.append(f"#define W_{k.upper()}_FN {symbol}_{k}_flat")
    text = "\n".join(lines) + "\n"
    text += _c_array("double", "W_X0", iface.x0, float.hex)
    text += _c_array("double", "W_P0", sy.params, float.hex)
    text += _c_array("int64_t", "W_TABLE", sy.table.ravel())
    text += _c_array("int", "W_OUT_CH", iface.out_channels)
    text += _c_array("int", "W_IN_P", iface.input_params)
    text += _c_array("int", "W_PAR_P", iface.parameter_params)
    text += _c_array("int", "W_RAMP", [i for r in iface.ramps for i in r])
    text += _c_array("int", "W_Z", indicators(sy))
    text += _c_array("int", "W_Z_ZERO", zero_sides(sy))
    text += _c_array("int", "W_U", balance.unknowns)
    text += _c_array("double", "W_MB", balance.modes, float.hex)
    own = iface.own or ("", False, -1, -1, 0.0, 0.0)
    text += (f"#define W_OWN {int(iface.own is not None)}\n"
             f"#define W_PROFILE {int(own[1])}\n#define W_REF_AP {own[2]}\n"
             f"#define W_REF_VP {own[3]}\n#define W_REF_A {float.hex(own[4])}\n"
             f"#define W_REF_V {float.hex(own[5])}\n")
    text += f"static const char* const W_SLOT_OWNER[] = {{{', '.join(owners)}}};\n"
    return text + "#endif\n"


def _compile(sources: Path, model: str, out: Path, symbol: str, generated: dict[str, str],
             wrappers: tuple[str, ...], sanitize: bool) -> None:
    base = [f for f in CFLAGS if f != "-shared"] + ["-fvisibility=hidden"]
    if sanitize:
        base = ["-O1" if f == "-O3" else f for f in base] + list(SANITIZE_CFLAGS)
    strict = [*base, "-ffp-contract=off", "-std=c99"]  # as solve/cint.py compiles them
    objs = []
    for src in (*generated, f"{symbol}_balance.c", *_INTEGRATORS, *wrappers):
        flags = base if src.startswith(symbol) else strict
        if src in generated and not sanitize:  # each at its level, as codegen compiles it
            flags = list(with_level(flags, generated[src]))
        obj = sources.parent.parent / (Path(src).stem + ".o")
        run_compiler([*flags, "-I", str(sources), "-c", str(sources / src), "-o", str(obj)],
                     src)
        objs.append(str(obj))
    # -Bsymbolic: the wrappers' calls into fmi2.c (FMI 3.0 calls the fmi2 functions) bind
    # inside this library, never to another FMU's fmi2Instantiate loaded before it
    link = ["-shared", "-Wl,-Bsymbolic",
            *(SANITIZE_CFLAGS if sanitize else ["-Wl,--no-undefined"])]
    run_compiler([*link, *objs, "-o", str(out), "-lm"], f"{model}.so")


def _headers_dir() -> Path:
    try:
        import fmpy
    except ImportError as exc:
        raise FmuError("the FMI headers come from FMPy's c-code/: pip install "
                       "'winder[fmu]'") from exc
    return Path(fmpy.__file__).resolve().parent / "c-code"


def _license_text() -> str:
    import importlib.metadata

    dist = importlib.metadata.distribution("fmpy")
    for f in dist.files or ():
        if "LICENSE" in f.name.upper():
            return f.read_text()
    raise FmuError("FMPy's license text is not found in its distribution")


def model_identifier(scene: Scene) -> str:
    """The FMU's model identifier: ``winder_`` and the scene's name as a C identifier."""
    return "winder_" + (re.sub(r"\W", "_", scene.name or "") or "machine")


def build_fmu(scene_path: str | Path, out: str | Path, *, fmi_version: int = 2,
              sanitize: bool = False, speed_profile: bool | None = None) -> Path:
    """Build the native FMU of a scene file at ``out`` (an ``.fmu``), atomically, for
    ``fmi_version`` 2 (FMI 2.0) or 3 (FMI 3.0), co-simulation and model exchange in one
    archive. ``sanitize``: compile with AddressSanitizer and UBSan (for tests; the host must then
    load libasan). ``speed_profile`` (single-drum scenes only): the drum on its speed
    profile (true) or freed on the input ``drum_torque_command`` (false), fixed at build
    time (the two are different machines); None: the scene's drive. Raises
    :class:`FmuError`."""
    from winder.io.files import atomic_write, scratch_dir

    if fmi_version not in FMI_VERSIONS:
        raise FmuError(f"fmi_version: {fmi_version!r} is not an FMI version this FMU is "
                       f"built for; valid: {', '.join(map(str, FMI_VERSIONS))}")
    wrappers, fmi_headers, platform = FMI_VERSIONS[fmi_version]
    scene_path, out = Path(scene_path), Path(out)
    scene = load_scene(scene_path)
    profile = None
    if scene.naming.fmu is not None:
        profile = (float(scene.drum.drive.web_acceleration),
                   float(scene.drum.drive.web_speed))
        if speed_profile is None:
            speed_profile = any(b.prescribed for b in body_elements(scene))
        scene = scene_with_parameters(scene, {}, speed_profile=speed_profile)
    elif speed_profile is not None:
        raise FmuError("speed_profile is a parameter of single-drum scenes only")
    if out.suffix != ".fmu":
        raise FmuError(f"output file must end in .fmu, got {str(out)!r}")
    if len(scene.webs) > 1:
        raise FmuError(f"{scene_path}: [[web]]: {len(scene.webs)} webs "
                       f"({', '.join(w.name for w in scene.webs)}); the FMU takes a scene "
                       "with one web (one winding station); valid: one [web] table (run "
                       "several stations with winder run)")
    iface = native_interface(scene, profile)
    model = model_identifier(scene)
    headers = _headers_dir()
    with scratch_dir("winder_native_fmu_") as d:
        stage, src = d / "fmu", d / "fmu" / "sources"
        (stage / "binaries" / platform).mkdir(parents=True)
        src.mkdir()
        paths, symbol, pattern, levels = write_source(iface.system.machine, src)
        generated = {p.name: lv for p, lv in zip(paths, levels, strict=True)}
        balance = balance_of(iface.system.machine, iface.x0, iface.system.params)
        write_balance_source(iface.system.machine, balance, f"{symbol}_balance", src)
        for f in (*_INTEGRATORS, "events.h"):
            shutil.copyfile(_SOLVE_C / f, src / f)
        for f in (*wrappers, "layout.h"):
            shutil.copyfile(_C / f, src / f)
        for h in fmi_headers:
            shutil.copyfile(headers / h, src / h)
        (src / "LICENSE-FMI-headers.txt").write_text(
            "The FMI headers fmi*.h in this folder come from FMPy's c-code/ "
            "(https://github.com/CATIA-Systems/FMPy):\n\n" + _license_text(),
            encoding="utf-8")
        digest = hashlib.sha256()
        for f in sorted(src.iterdir()):
            digest.update(f.name.encode() + f.read_bytes())
        guid = "{" + str(uuid.UUID(digest.hexdigest()[:32])) + "}"
        (src / "winder_model.h").write_text(_model_header(iface, symbol, guid, balance),
                                            encoding="utf-8")
        kb = sum((src / f).stat().st_size for f in generated) / 1024
        print(f"winder: building the FMU {model}'s binary ({len(generated)} generated C "
              f"files, {kb:.0f} kB, and the integrators; the Jacobian included)",
              file=sys.stderr, flush=True)
        _compile(src, model, stage / "binaries" / platform / f"{model}.so", symbol,
                 generated, wrappers, sanitize)
        sources = [*generated, f"{symbol}_balance.c", *_INTEGRATORS, *wrappers]
        (stage / "modelDescription.xml").write_bytes(model_description(
            iface, model, guid, scene, sources, pattern, fmi_version=fmi_version))
        if fmi_version == 3:
            (src / "buildDescription.xml").write_bytes(build_description(model, sources))
        staged = d / "out.fmu"
        with zipfile.ZipFile(staged, "w", zipfile.ZIP_DEFLATED) as zf:
            for f in sorted(stage.rglob("*")):
                if f.is_file():
                    zf.write(f, f.relative_to(stage).as_posix())
        atomic_write(out, lambda tmp: shutil.copyfile(staged, tmp))
    return out
