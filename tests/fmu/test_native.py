"""The native FMU (winder.fmu.native, issue #24 phase 1): no Python inside; checked by
FMPy (validation, co-simulation against winder.simulate and the in-process Stepper, FMU
state round trips, directional derivatives) and by a C host under AddressSanitizer."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

import winder

fmpy = pytest.importorskip("fmpy", reason="FMPy is installed with winder[fmu]")
from ctypes import byref  # noqa: E402

from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.fmi2 import (  # noqa: E402
    fmi2Discard,
    fmi2LastSuccessfulTime,
    fmi2Real,
)
from fmpy.validation import validate_fmu  # noqa: E402
from fmu_slave import rebuilt, slave  # noqa: E402

from winder.fmu.native import build_fmu, model_identifier  # noqa: E402

HOST_C = Path(__file__).with_name("native_host.c")


def _cli_native(scene: Path, out: Path, *options: str) -> Path:
    """``winder fmu`` (the native FMU is the default)."""
    proc = subprocess.run([sys.executable, "-m", "winder", "fmu", str(scene), "-o", str(out),
                           *options], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "native" in proc.stdout and "run-checked with FMPy" in proc.stdout, proc.stdout
    return out


@pytest.fixture(scope="module")
def paper_fmu(tmp_path_factory, models_dir) -> Path:
    return _cli_native(models_dir / "paper_winding.toml",
                       tmp_path_factory.mktemp("native") / "paper.fmu")


@pytest.fixture(scope="module")
def two_drum_fmu(tmp_path_factory, models_dir) -> Path:
    return build_fmu(models_dir / "two_drum_winder.toml",
                     tmp_path_factory.mktemp("native2") / "two_drum.fmu")


@pytest.fixture(scope="module")
def line_fmu(tmp_path_factory, models_dir) -> Path:
    """The winder line with its unwind on a torque input."""
    return build_fmu(models_dir / "winder_line_fmu.toml",
                     tmp_path_factory.mktemp("native3") / "line.fmu")


def _outputs(path: Path) -> list[str]:
    md = fmpy.read_model_description(str(path))
    return [v.name for v in md.modelVariables if v.causality == "output"]


# ---- the archive ----------------------------------------------------------------------

@pytest.mark.parametrize("which", ["paper_fmu", "two_drum_fmu", "line_fmu"])
def test_validates(which, request) -> None:
    path = request.getfixturevalue(which)
    assert validate_fmu(str(path)) == []
    proc = subprocess.run([str(Path(sys.executable).with_name("fmpy")), "validate",
                           str(path)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and "No problems found" in proc.stdout, proc.stdout


def test_archive_has_no_python(paper_fmu, tmp_path, paper_scene) -> None:
    """binaries/linux64/MODEL.so needs libc and libm only and exports only fmi2*; the
    sources, the FMI headers and their license travel in sources/; the flags FMI wants."""
    model = model_identifier(paper_scene)
    with zipfile.ZipFile(paper_fmu) as zf:
        names = set(zf.namelist())
        zf.extractall(tmp_path)
    so = tmp_path / "binaries" / "linux64" / f"{model}.so"
    assert so.is_file()
    assert {"sources/fmi2.c", "sources/dopri5.c", "sources/rk4.c", "sources/events.h",
            "sources/winder_model.h", "sources/fmi2Functions.h",
            "sources/LICENSE-FMI-headers.txt"} <= names
    assert "BSD" in (tmp_path / "sources" / "LICENSE-FMI-headers.txt").read_text()
    ldd = subprocess.run(["ldd", str(so)], capture_output=True, text=True).stdout
    assert "python" not in ldd.lower()
    libs = {line.split()[0] for line in ldd.splitlines() if "=>" in line}
    assert libs <= {"libm.so.6", "libc.so.6"}, libs
    undefined = subprocess.run(["nm", "-D", "--undefined-only", str(so)], capture_output=True,
                               text=True).stdout
    assert "Py" not in undefined
    defined = subprocess.run(["nm", "-D", "--defined-only", str(so)], capture_output=True,
                             text=True).stdout.split()
    exported = [s for s in defined[2::3]]
    assert exported and all(s.startswith("fmi2") for s in exported), exported
    md = fmpy.read_model_description(str(paper_fmu))
    cs = md.coSimulation
    assert not cs.needsExecutionTool and cs.canHandleVariableCommunicationStepSize
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate
    assert cs.providesDirectionalDerivative


def test_fmpy_compile_rebuilds_it(paper_fmu, tmp_path) -> None:
    """``fmpy compile`` (FMPy's CMake project on sources/, as for another platform)
    rebuilds the binary of an archive without one; the rebuilt FMU gives the same
    outputs (to 1e-12: other flags)."""
    copy = rebuilt(paper_fmu, tmp_path / "rebuilt.fmu")
    with zipfile.ZipFile(copy) as zf:
        assert any(n.startswith("binaries/linux64/") for n in zf.namelist())
    outs = ["radius", "roll_speed", "normal_force"]
    got = {}
    for path in (paper_fmu, copy):
        with slave(path) as (fmu, refs, _):
            for i in range(50):
                fmu.doStep(i * 0.01, 0.01)
            got[path] = fmu.getReal([refs[k] for k in outs])
    np.testing.assert_allclose(got[copy], got[paper_fmu], rtol=1e-12)


def test_interface(two_drum_fmu, line_fmu, models_dir) -> None:
    """Inputs, parameters and outputs are the Stepper's and the scene's, by name, with
    the scene's values and the declared units; the states and derivatives are locals."""
    from winder.fmu.parameters import fmu_parameters, parameter_units, parameter_value
    from winder.model.units import fmi_name

    for path, file in ((two_drum_fmu, "two_drum_winder.toml"),
                       (line_fmu, "winder_line_fmu.toml")):
        scene = winder.load_scene(models_dir / file)
        sim = winder.Stepper(scene)
        md = fmpy.read_model_description(str(path))
        by = {v.name: v for v in md.modelVariables}
        kinds: dict[str, set[str]] = {}
        for v in md.modelVariables:
            kinds.setdefault(v.causality, set()).add(v.name)
        inputs = set(sim.inputs) if file.startswith("winder_line") else set()
        assert kinds.pop("input", set()) == inputs
        clock = {"t"} if scene.rolls and any(r.name == "parent" for r in scene.rolls) else set()
        assert kinds.pop("output") == (set(sim.output_names) - inputs) | clock
        params = fmu_parameters(scene)
        assert kinds.pop("parameter") == {*params, "rtol", "atol", "rk4_step", "rk4"}
        locals_ = kinds.pop("local")
        assert locals_ == {*sim.system.state_names,
                           *(f"der({n})" for n in sim.system.state_names)}
        assert kinds == {}
        units = parameter_units(scene)
        for name, (place, _) in params.items():
            assert float(by[name].start) == parameter_value(scene, place), name
            assert by[name].unit == fmi_name(units[name]), name
        for name in set(sim.output_names) - inputs:
            assert by[name].unit == fmi_name(sim.system.channel_units[name]), name
        for name in inputs:
            assert by[name].unit == "N.m" and by[name].description == "drive torque [N·m]"


# ---- co-simulation against simulate and the Stepper -------------------------------------

def _run(path: Path, names: list[str], t_end: float, dt: float, **kw: object
         ) -> dict[str, np.ndarray]:
    out: dict[str, list[float]] = {k: [] for k in names}
    with slave(path, **kw) as (fmu, refs, _):  # type: ignore[arg-type]
        vrs = [refs[k] for k in names]
        for i in range(int(round(t_end / dt))):
            fmu.doStep(i * dt, dt)
            for k, v in zip(names, fmu.getReal(vrs), strict=True):
                out[k].append(v)
    return {k: np.array(v) for k, v in out.items()}


@pytest.mark.parametrize("which,file,t_end", [("paper_fmu", "paper_winding.toml", 5.0),
                                              ("two_drum_fmu", "two_drum_winder.toml", 2.0)])
def test_matches_simulate(which, file, t_end, request, models_dir) -> None:
    """Co-simulation at 10 ms steps against winder.simulate (DOPRI5, rtol 1e-8, atol
    1e-10) sampled at the same times: every radius to 1e-6 m, every speed and force to
    1e-5 of its largest magnitude (the FMU restarts its DOPRI5 at every step: the two
    differ by the local error level)."""
    path = request.getfixturevalue(which)
    scene = winder.load_scene(models_dir / file)
    ref = winder.simulate(scene, t_end=t_end, output_step=0.01, method="DOPRI5", rtol=1e-8,
                          atol=1e-10)
    names = _outputs(path)
    got = _run(path, names, t_end, 0.01)
    radii = [k for k in names if k == "radius" or k.endswith("_radius")]
    kinetic = [k for k in names if k.endswith(("speed", "force")) or k == "roll_speed"]
    assert radii and len(kinetic) >= 3
    worst = {}
    for k in radii:
        worst[k] = float(np.max(np.abs(got[k] - ref[k][1:])))
        assert worst[k] < 1e-6, (k, worst[k])
    for k in kinetic:
        scale = max(float(np.max(np.abs(ref[k]))), 1e-9)
        worst[k] = float(np.max(np.abs(got[k] - ref[k][1:]))) / scale
        assert worst[k] < 1e-5, (k, worst[k])
    print(which, "worst", max(worst.items(), key=lambda kv: kv[1]))


def test_equals_the_stepper_bit_for_bit(line_fmu, models_dir) -> None:
    """The winder line with its unwind torque driven by a signal, 100 steps of 10 ms:
    every output equals the in-process Stepper's exactly (the same generated code and
    the same integrator, the same steps)."""
    scene = winder.load_scene(models_dir / "winder_line_fmu.toml")
    sim = winder.Stepper(scene)
    names = [k for k in _outputs(line_fmu) if k != "t"]
    with slave(line_fmu) as (fmu, refs, _):
        for i in range(100):
            tau = 2000.0 * np.sin(0.05 * i)
            fmu.setReal([refs["parent_torque"]], [tau])
            sim.set_input("parent_torque", tau)
            fmu.doStep(i * 0.01, 0.01)
            sim.step(0.01)
            got = fmu.getReal([refs[k] for k in names])
            want = [sim.output(k) for k in names]
            assert got == want, i
        assert fmu.getReal([refs["t"]])[0] == sim.t
        state = fmu.getReal([refs[n] for n in sim.system.state_names])
        assert state == list(sim.y)


def test_rk4_option(paper_fmu, paper_scene) -> None:
    """rk4 = true: fixed steps of rk4_step; 2 s at 1 ms communication steps agree with
    simulate's RK4 at max_step 1 ms (same method on the same grid, restarted at every
    step: the grid's times differ by round-off, which the stiff nip amplifies) to 1e-7
    of each channel's largest magnitude (measured 1.5e-8 on the normal force)."""
    names = ["radius", "roll_speed", "normal_force"]
    got = _run(paper_fmu, names, 2.0, 1e-3, rk4=True, rk4_step=1e-3)
    rk4 = winder.simulate(paper_scene, t_end=2.0, output_step=1e-3, method="RK4",
                          max_step=1e-3)
    for k in names:
        scale = float(np.max(np.abs(rk4[k])))
        assert np.max(np.abs(got[k] - rk4[k][1:])) / scale < 1e-7, k


# ---- FMU state ----------------------------------------------------------------------------

def test_fmu_state_round_trips(two_drum_fmu) -> None:
    """Get the state after 20 steps, run 30 more; set it back (and deserialize its
    serialization into a fresh instance): the 30 steps repeat bit for bit."""
    names = _outputs(two_drum_fmu)

    def steps(fmu, refs, start: int) -> list[list[float]]:  # noqa: ANN001
        rows = []
        for i in range(start, start + 30):
            fmu.doStep(i * 0.01, 0.01)
            rows.append(fmu.getReal([refs[k] for k in names]))
        return rows

    with slave(two_drum_fmu) as (fmu, refs, _):
        for i in range(20):
            fmu.doStep(i * 0.01, 0.01)
        state = fmu.getFMUState()
        blob = fmu.serializeFMUState(state)
        first = steps(fmu, refs, 20)
        fmu.setFMUState(state)
        again = steps(fmu, refs, 20)
        fmu.freeFMUState(state)
    assert again == first
    with slave(two_drum_fmu) as (fmu, refs, _):
        state = fmu.deSerializeFMUstate(blob)
        fmu.setFMUState(state)
        fmu.freeFMUState(state)
        fresh = steps(fmu, refs, 20)
    assert fresh == first


# ---- directional derivatives --------------------------------------------------------------

def test_directional_derivatives(two_drum_fmu, models_dir) -> None:
    """After 0.3 s: the derivatives' directional derivative w.r.t. the states (the exact
    Jacobian) against central differences of the generated right-hand side in the same
    modes, column by column and along a random direction; the der() values equal it."""
    scene = winder.load_scene(models_dir / "two_drum_winder.toml")
    sy = winder.Stepper(scene).system
    states = list(sy.state_names)
    ders = [f"der({n})" for n in states]
    with slave(two_drum_fmu) as (fmu, refs, _):
        for i in range(30):
            fmu.doStep(i * 0.01, 0.01)
        y = np.array(fmu.getReal([refs[n] for n in states]))
        dy = np.array(fmu.getReal([refs[n] for n in ders]))
        J = np.column_stack([fmu.getDirectionalDerivative([refs[d] for d in ders],
                                                          [refs[n]], [1.0])
                             for n in states])
        rng = np.random.default_rng(7)
        v = rng.standard_normal(len(states))
        Jv = np.array(fmu.getDirectionalDerivative([refs[d] for d in ders],
                                                   [refs[n] for n in states], list(v)))
        out_vr = [refs["set_speed"], refs["front_nip_normal_force"]]
        dout = np.array(fmu.getDirectionalDerivative(out_vr, [refs[n] for n in states],
                                                     list(v)))
    t = 0.0
    for _ in range(30):
        t += 0.01  # the FMU's time, summed as it sums it
    sy.kernels.modes(sy.fns, sy.table, t, y, sy.params, sy.modes, contact_auto=False)
    np.testing.assert_array_equal(sy.rhs(t, y), dy)
    fd = np.empty_like(J)
    for k in range(len(states)):
        h = 1e-6 * max(1.0, abs(y[k]))
        a, b = y.copy(), y.copy()
        a[k] += h
        b[k] -= h
        fd[:, k] = (sy.rhs(t, a) - sy.rhs(t, b)) / (2 * h)
    scale = np.maximum(np.abs(J).max(axis=1, keepdims=True), 1.0)
    assert np.max(np.abs(J - fd) / scale) < 1e-5
    np.testing.assert_allclose(Jv, J @ v, rtol=1e-12, atol=1e-12 * np.abs(J).max())
    # outputs along v: central differences of the channels (the FMU's own)
    eps = 1e-6 * (1 + np.linalg.norm(y)) / np.linalg.norm(v)
    ch = [sy.channels(np.array([t]), (y + s * eps * v)[:, None]) for s in (1, -1)]
    want = [(ch[0][k][0] - ch[1][k][0]) / (2 * eps) for k in ("set_speed",
                                                             "front_nip_normal_force")]
    np.testing.assert_allclose(dout, want, rtol=1e-9)


# ---- the run-out of an unwinding roll -----------------------------------------------------

def test_run_out_discards(tmp_path, models_dir) -> None:
    """A parent with 0.2 mm of paper runs out near 2.686 s: the
    step returns fmi2Discard with the reason logged, the outputs at the run-out time,
    fmi2LastSuccessfulTime there, and every later step discards too."""
    import tomli_w

    scene = winder.load_scene(models_dir / "winder_line_fmu.toml")
    scene = scene.replace(roll={"parent": {"initial_radius": 0.4002}})
    (tmp_path / "runout.toml").write_text(tomli_w.dumps(scene.to_dict()))
    fmu_path = build_fmu(tmp_path / "runout.toml", tmp_path / "runout.fmu")
    sim = winder.Stepper(scene)
    with slave(fmu_path) as (fmu, refs, log):
        status = None
        for i in range(400):
            sim.step(0.01)
            try:
                fmu.doStep(i * 0.01, 0.01)
            except FMICallException as exc:
                status = exc.status
                break
        assert status == fmi2Discard and sim.ended is not None
        t = fmu.getReal([refs["t"]])[0]
        assert t == sim.t and 2.6 < t < 2.75
        last = fmi2Real()
        fmu.fmi2GetRealStatus(fmu.component, fmi2LastSuccessfulTime, byref(last))
        assert last.value == t
        assert fmu.getReal([refs["parent_radius"]])[0] == pytest.approx(0.4, abs=1e-9)
        assert fmu.getReal([refs["span_tension"]])[0] == sim.output("span_tension")
        with pytest.raises(FMICallException) as again:
            fmu.doStep(t, 0.01)
        assert again.value.status == fmi2Discard
    text = "\n".join(log)
    assert "[logStatusDiscard]" in text and "'parent' ran out of web" in text
    assert sim.ended.split(" at t")[0] in text and "the run has ended" in text
    # model exchange: the end's event indicator stops the run there (terminateSimulation)
    res = fmpy.simulate_fmu(str(fmu_path), fmi_type="ModelExchange", stop_time=4.0,
                            output_interval=0.01, relative_tolerance=1e-8,
                            output=["parent_radius"])
    assert res["time"][-1] == pytest.approx(t, abs=1e-3)
    assert res["parent_radius"][-1] == pytest.approx(0.4, abs=1e-6)


# ---- a plain C host under AddressSanitizer ------------------------------------------------

def test_c_host_under_asan(tmp_path, models_dir) -> None:
    """A C host (dlopen, no FMPy) compiled with -fsanitize=address,undefined instantiates,
    steps and frees a sanitized build of the two-drum FMU 1000 times: exit 0, no
    sanitizer report, the same radius every time."""
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    fmu_path = build_fmu(models_dir / "two_drum_winder.toml", tmp_path / "asan.fmu",
                         sanitize=True)
    with zipfile.ZipFile(fmu_path) as zf:
        zf.extractall(tmp_path / "x")
    md = fmpy.read_model_description(str(fmu_path))
    so = tmp_path / "x" / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    host = tmp_path / "host"
    headers = Path(fmpy.__file__).parent / "c-code"
    subprocess.run([cc, "-fsanitize=address,undefined", "-fno-sanitize-recover=undefined",
                    "-g", "-I", str(headers), str(HOST_C), "-o", str(host), "-ldl"],
                   check=True, capture_output=True)
    radius = {v.name: v.valueReference for v in md.modelVariables}["set_radius"]
    proc = subprocess.run([str(host), str(so), md.guid, "1000", str(radius)],
                          capture_output=True, text=True, timeout=600,
                          env={"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=0"})
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "Sanitizer" not in proc.stderr and "runtime error" not in proc.stderr
    assert "1000 cycles" in proc.stdout and "same radius" in proc.stdout, proc.stdout


# ---- model exchange --------------------------------------------------------------------------

@pytest.mark.parametrize("which,file", [("paper_fmu", "paper_winding.toml"),
                                        ("two_drum_fmu", "two_drum_winder.toml"),
                                        ("line_fmu", "winder_line_fmu.toml")])
def test_model_exchange_matches_simulate(which, file, request, models_dir) -> None:
    """FMPy's CVode (rtol 1e-8) on the model-exchange interface, 2 s, against
    winder.simulate (DOPRI5, rtol 1e-8) sampled every 10 ms: radii to 1e-6 m (measured
    4e-13), speeds and forces to 1e-3 of their largest magnitude (measured at most 8e-5,
    z_dot of the paper scene, with the generated code's route cpp and 1.05e-4 with route
    py: two integrators through the bounce's contact events, which switch the modes in
    fmi2NewDiscreteStates)."""
    path = request.getfixturevalue(which)
    ref = winder.simulate(winder.load_scene(models_dir / file), t_end=2.0, output_step=0.01,
                          method="DOPRI5", rtol=1e-8, atol=1e-10)
    names = [k for k in _outputs(path) if k != "t"]
    res = fmpy.simulate_fmu(str(path), fmi_type="ModelExchange", solver="CVode",
                            stop_time=2.0, output_interval=0.01, relative_tolerance=1e-8,
                            output=names)
    assert res["time"][-1] == pytest.approx(2.0)
    checked = 0
    for k in names:
        got = np.interp(ref.t, res["time"], res[k])
        if k == "radius" or k.endswith("_radius"):
            assert np.max(np.abs(got - ref[k])) < 1e-6, k
            checked += 1
        elif k.endswith(("speed", "force", "_dot")):
            scale = max(float(np.max(np.abs(ref[k]))), 1e-9)
            assert np.max(np.abs(got - ref[k])) / scale < 1e-3, k
            checked += 1
    assert checked >= 5


def test_model_exchange_leaves_the_core_at_rest(free_drum_fmu, paper_scene) -> None:
    """The free drum from rest under a constant 30 N·m: the roll starts at rest on its core,
    both core switching functions exactly 0, so the core mode starts at the core. Model
    exchange (FMPy's CVode, rtol 1e-8) must see the roll leave it: radius and speeds
    against winder.simulate (DOPRI5, rtol 1e-8) over 2 s (measured: radius 1.2e-13 m,
    speeds 7e-8 relative). Reporting a zero indicator as zero instead, CVode saw no sign
    change and the radius stayed at the core, 0.0750000 against 0.0750219 m."""
    from winder.fmu.parameters import scene_with_parameters

    scene = scene_with_parameters(paper_scene, {}, speed_profile=False).replace(
        drum={"drive": {"torque": 30.0}})
    ref = winder.simulate(scene, t_end=2.0, output_step=0.01, method="DOPRI5", rtol=1e-8,
                          atol=1e-10)
    names = ["radius", "roll_speed", "drum_speed"]
    res = fmpy.simulate_fmu(str(free_drum_fmu), fmi_type="ModelExchange", solver="CVode",
                            stop_time=2.0, output_interval=0.01, relative_tolerance=1e-8,
                            start_values={"drum_torque_command": 30.0}, output=names)
    assert ref["radius"][-1] - ref["radius"][0] > 2e-5
    got = {k: np.interp(ref.t, res["time"], res[k]) for k in names}
    assert np.max(np.abs(got["radius"] - ref["radius"])) < 1e-11
    for k in names[1:]:
        assert np.max(np.abs(got[k] - ref[k])) < 1e-6 * np.max(np.abs(ref[k])), k


def test_model_structure_from_the_jacobian(two_drum_fmu, models_dir) -> None:
    """numberOfEventIndicators: the switching functions the mode table refers to; each
    derivative's dependencies are the structural nonzeros of the generated Jacobian:
    they contain every numerical nonzero at a state of the run, and an angle's rate
    depends on its speed alone."""
    from winder.fmu.interface import indicators

    scene = winder.load_scene(models_dir / "two_drum_winder.toml")
    sy = winder.Stepper(scene).system
    md = fmpy.read_model_description(str(two_drum_fmu))
    assert md.numberOfEventIndicators == len(indicators(sy)) == 5  # core 2, 3 nips
    deps = {u.variable.name: {d.name for d in u.dependencies}
            for u in md.derivatives}
    assert list(deps) == [f"der({n})" for n in sy.state_names]
    assert deps["der(set.theta)"] == {"set.theta_dot"}
    y = sy.initial_state() * (1 + 1e-3)
    J = sy.jac(0.5, y)
    for i, name in enumerate(sy.state_names):
        numeric = {sy.state_names[j] for j in np.nonzero(J[i])[0]}
        assert numeric <= deps[f"der({name})"], name


def test_c_host_under_valgrind(paper_fmu, tmp_path) -> None:
    """The plain C host (no sanitizer) under valgrind's memcheck: 50 instantiate, step,
    free cycles of the paper FMU as shipped: no memory error, no leak."""
    valgrind, cc = shutil.which("valgrind"), shutil.which("cc") or shutil.which("gcc")
    if valgrind is None or cc is None:
        pytest.skip("valgrind or a C compiler is not installed")
    with zipfile.ZipFile(paper_fmu) as zf:
        zf.extractall(tmp_path / "x")
    md = fmpy.read_model_description(str(paper_fmu))
    so = tmp_path / "x" / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    host = tmp_path / "host"
    subprocess.run([cc, "-O1", "-g", "-I", str(Path(fmpy.__file__).parent / "c-code"),
                    str(HOST_C), "-o", str(host), "-ldl"], check=True, capture_output=True)
    radius = {v.name: v.valueReference for v in md.modelVariables}["radius"]
    proc = subprocess.run([valgrind, "--leak-check=full", "--error-exitcode=3",
                           "--errors-for-leak-kinds=definite,indirect,possible",
                           str(host), str(so), md.guid, "50", str(radius)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "ERROR SUMMARY: 0 errors" in proc.stderr, proc.stderr[-3000:]
    assert "50 cycles" in proc.stdout and "same radius" in proc.stdout


@pytest.mark.parametrize("fmi_type", ["CoSimulation", "ModelExchange"])
def test_parameters_act_at_run_time(fmi_type, paper_fmu, paper_scene) -> None:
    """Parameters set by the host act without compiling: the paper scene's profile at
    5 m/s reached at 2 m/s² (its ramp end, a breakpoint and a time event, moves from
    40 s to 2.5 s) and twice the caliper, 4 s, equal winder.simulate of the scene with
    those values (whose initial balance is the scene's: none of them enters it) within
    the tolerances above."""
    from winder.fmu.parameters import scene_with_parameters

    values = {"profile_web_speed": 5.0, "web_acceleration": 2.0, "caliper": 3.2e-4}
    scene = scene_with_parameters(paper_scene, values, speed_profile=True)
    ref = winder.simulate(scene, t_end=4.0, output_step=0.01, method="DOPRI5", rtol=1e-8,
                          atol=1e-10)
    names = ["radius", "drum_speed", "roll_speed", "normal_force"]
    res = fmpy.simulate_fmu(str(paper_fmu), fmi_type=fmi_type, stop_time=4.0,
                            output_interval=0.01, relative_tolerance=1e-8,
                            start_values=values, output=names)
    tol = 1e-5 if fmi_type == "CoSimulation" else 1e-4
    for k in names:
        got = np.interp(ref.t, res["time"], res[k])
        err = np.max(np.abs(got - ref[k]))
        assert err < (1e-6 if k == "radius" else tol * np.max(np.abs(ref[k]))), (k, err)
    # the drum follows the new profile: ratio · min(2 t, 5) / R
    assert ref["drum_speed"][-1] == pytest.approx(5.0 / 0.5, rel=1e-9)


def _ecospy():  # noqa: ANN202 - the module
    try:
        import ecospy
    except ImportError:
        pytest.skip("ecospy is installed with winder[fmu]")
    except OSError as exc:  # its libecos needs libtbb.so.12 (make libtbb)
        pytest.skip(f"ecospy cannot load its library: {exc}")
    return ecospy


def test_second_host_ecospy(two_drum_fmu, line_fmu) -> None:
    """ecospy (libecos, an independent C++ FMI host from PyPI) steps both FMUs 100 times
    at 10 ms, the line with its unwind torque set through it: every output equals FMPy's
    run of the same steps, bit for bit."""
    ecospy = _ecospy()
    for path, inputs in ((two_drum_fmu, {}), (line_fmu, {"parent_torque": 1500.0})):
        names = [k for k in _outputs(path)]
        structure = ecospy.EcosSimulationStructure()
        structure.add_model("w", str(path))
        with ecospy.EcosSimulation(structure=structure, step_size=0.01) as sim:
            sim.init()
            for name, value in inputs.items():
                sim.set_real(f"w::{name}", value)
            sim.step(100)
            assert sim.get_time() == pytest.approx(1.0, abs=1e-12)
            got = [sim.get_real(f"w::{k}") for k in names]
            sim.terminate()
        with slave(path) as (fmu, refs, _):
            for name, value in inputs.items():
                fmu.setReal([refs[name]], [value])
            for i in range(100):
                fmu.doStep(i * 0.01, 0.01)
            want = fmu.getReal([refs[k] for k in names])
        assert got == want, path.name


@pytest.mark.parametrize("which,file,values", [
    ("two_drum_fmu", "two_drum_winder.toml",
     {"web_tension": 1500.0, "rear_nip_contact_stiffness": 3e7, "set_density": 700.0}),
    ("paper_fmu", "paper_winding.toml", {"contact_stiffness": 3e7, "density": 900.0})])
def test_static_balance_of_the_hosts_parameters(which, file, values, request,
                                                models_dir) -> None:
    """Parameters set during initialisation that move the static balance (the two-drum
    winder's set and rider by 0.55 mm): fmi2ExitInitializationMode solves it in C (Newton
    on the generated residual), and the states equal winder's balance of the scene with
    those values (scipy's root) to 1e-15 m (measured 7e-17); unchanged parameters keep the
    built state bit for bit."""
    from winder.fmu.parameters import scene_with_parameters
    from winder.solve.system import MachineSystem

    path = request.getfixturevalue(which)
    scene = winder.load_scene(models_dir / file)
    profile = True if scene.naming.fmu is not None else None
    system = MachineSystem(scene_with_parameters(scene, values, speed_profile=profile))
    want = system.initial_state()
    base = MachineSystem(scene).initial_state()
    assert np.max(np.abs(want - base)) > 1e-6
    names = list(system.state_names)
    with slave(path, **values) as (fmu, refs, _):
        got = np.array(fmu.getReal([refs[n] for n in names]))
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-15)
    with slave(path) as (fmu, refs, _):
        assert fmu.getReal([refs[n] for n in names]) == list(base)


def test_misuse_is_refused_with_a_reason(line_fmu) -> None:
    """A step from a time the FMU is not at, a fixed parameter set after initialisation,
    a non-finite input: fmi2Error, each with its reason logged; the FMU stays usable."""
    from fmpy.fmi2 import fmi2Error

    with slave(line_fmu) as (fmu, refs, log):
        fmu.doStep(0.0, 0.01)
        for call in (lambda: fmu.doStep(0.5, 0.01),
                     lambda: fmu.setReal([refs["span_EA"]], [2e6]),
                     lambda: fmu.setReal([refs["parent_torque"]], [float("nan")]),
                     lambda: fmu.setBoolean([refs["rk4"]], [True])):
            with pytest.raises(FMICallException) as exc:
                call()
            assert exc.value.status == fmi2Error
        fmu.doStep(0.01, 0.01)
        assert fmu.getReal([refs["t"]])[0] == pytest.approx(0.02, abs=1e-15)
    text = "\n".join(log)
    assert "steps must be contiguous" in text and "fixed parameter" in text
    assert "is not finite" in text and "rk4 is a fixed parameter" in text


# ---- the single-drum interface (the old format's) -----------------------------------------

@pytest.fixture(scope="module")
def free_drum_fmu(tmp_path_factory, models_dir) -> Path:
    """The paper scene's drum freed on ``drum_torque_command`` (speed_profile = false)."""
    return build_fmu(models_dir / "paper_winding.toml",
                     tmp_path_factory.mktemp("native4") / "free.fmu", speed_profile=False)


def test_single_drum_interface(free_drum_fmu, paper_fmu) -> None:
    """The single-drum format's own variables (Naming.fmu): the Boolean
    parameter ``speed_profile`` (fixed; its built value; the other is refused with the
    build option that gives it), the input ``drum_torque_command`` [N.m] (start 0) and
    the output ``web_speed_reference`` [m/s]; ``drum_torque`` stays an output."""
    for path, profile in ((free_drum_fmu, False), (paper_fmu, True)):
        md = fmpy.read_model_description(str(path))
        by = {v.name: v for v in md.modelVariables}
        sw = by["speed_profile"]
        assert (sw.type, sw.causality, sw.variability) == ("Boolean", "parameter", "fixed")
        assert sw.start == str(profile).lower()
        ref = by["web_speed_reference"]
        assert (ref.causality, ref.variability, ref.unit) == ("output", "continuous", "m/s")
        assert by["drum_torque"].causality == "output"
        if not profile:
            cmd = by["drum_torque_command"]
            assert (cmd.causality, cmd.variability, cmd.unit, float(cmd.start)) == \
                ("input", "continuous", "N.m", 0.0)
        else:
            assert "drum_torque_command" not in by
        with slave(path) as (fmu, refs, log):
            vr = refs["speed_profile"]
            assert fmu.getBoolean([vr]) == [profile]
            fmu.setBoolean([vr], [profile])  # its own value: accepted
            with pytest.raises(FMICallException):
                fmu.setBoolean([vr], [not profile])
            assert "speed-profile" in log[-1], log


def test_free_drum_equals_the_stepper_bit_for_bit(free_drum_fmu, paper_scene) -> None:
    """speed_profile = false, the drum torque driven by a signal, 200 steps of 10 ms:
    every output equals the in-process Stepper's of the same scene (the drum freed as
    winder.fmu.parameters.scene_with_parameters frees it) exactly, and
    web_speed_reference is min(a_w t, v_w) of the scene's profile."""
    from winder.fmu.parameters import scene_with_parameters

    sim = winder.Stepper(scene_with_parameters(paper_scene, {}, speed_profile=False))
    names = [k for k in _outputs(free_drum_fmu) if k != "web_speed_reference"]
    d = paper_scene.drum.drive
    with slave(free_drum_fmu) as (fmu, refs, _):
        for i in range(200):
            tau = 30.0 + 20.0 * np.sin(0.1 * i)
            fmu.setReal([refs["drum_torque_command"]], [tau])
            sim.set_input("drum_torque", tau)
            fmu.doStep(i * 0.01, 0.01)
            sim.step(0.01)
            got = fmu.getReal([refs[k] for k in names])
            want = [sim.output(k) for k in names]
            assert got == want, i
            ref = fmu.getReal([refs["web_speed_reference"]])[0]
            assert ref == pytest.approx(min(d.web_acceleration * sim.t, d.web_speed),
                                        rel=1e-12)


def test_tension_example_runs_a_built_fmu(line_fmu, tmp_path) -> None:
    """examples/tension_control_fmu.py --fmu (make demo's way): the native FMU given is
    run, none built; its figure and log written to --out."""
    example = Path(__file__).resolve().parents[2] / "examples" / "tension_control_fmu.py"
    proc = subprocess.run([sys.executable, str(example), "--t-end", "1", "--fmu",
                           str(line_fmu), "--out", str(tmp_path)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert f"native FMU {line_fmu})" in proc.stdout, proc.stdout
    assert not (tmp_path / "winder_line_fmu.fmu").exists()
    assert len(np.load(tmp_path / "tension_control_fmu.npz")["t"]) == 501
    assert (tmp_path / "tension_control_fmu.png").stat().st_size > 10_000


def test_cli_builds_either_single_drum_machine(tmp_path, models_dir) -> None:
    """winder fmu --no-speed-profile: the free drum (the native FMU, by default);
    --speed-profile is refused for a machine from parts (exit 2, naming the option's
    parameter), with nothing written."""
    path = _cli_native(models_dir / "paper_winding.toml", tmp_path / "free.fmu",
                       "--no-speed-profile")
    md = fmpy.read_model_description(str(path))
    by = {v.name: v for v in md.modelVariables}
    assert by["speed_profile"].start == "false" and "drum_torque_command" in by
    proc = subprocess.run([sys.executable, "-m", "winder", "fmu",
                           str(models_dir / "two_drum_winder.toml"), "-o",
                           str(tmp_path / "parts.fmu"), "--speed-profile"],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 2 and "speed_profile" in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr
    assert not (tmp_path / "parts.fmu").exists()


def test_tension_example_reports_the_planned_run_out(line_fmu, tmp_path) -> None:
    """examples/tension_control_fmu.py to the parent's run-out (about 56.2 s): the FMU's
    refused step (fmi2Discard, terminated) is reported once, as the planned end it is
    ("run-out at t = ... (planned ...)"), its time that of the log's last outputs; no
    "[DISCARD]" log line, no "failed with status" (it printed "fmi2DoStep failed with
    status 2")."""
    example = Path(__file__).resolve().parents[2] / "examples" / "tension_control_fmu.py"
    proc = subprocess.run([sys.executable, str(example), "--fmu", str(line_fmu), "--out",
                           str(tmp_path)], capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = proc.stdout + proc.stderr
    assert "[DISCARD]" not in out and "failed with status" not in out, out
    lines = [s for s in out.splitlines() if "run-out" in s]
    assert len(lines) == 1 and lines[0].endswith("(planned: the parent reached its core)")
    t_out = float(lines[0].split("t = ")[1].split()[0])
    t = np.load(tmp_path / "tension_control_fmu.npz")["t"]
    assert t_out == pytest.approx(t[-1], abs=1e-4) and 56.0 < t_out < 56.5
