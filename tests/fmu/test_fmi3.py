"""The native FMU behind FMI 3.0 (fmu/c/fmi3.c over the FMI 2.0 core): FMPy validates it,
and its co-simulation and model exchange equal the FMI 2.0 FMU's bit for bit (the FMI 2.0
FMU is checked against winder.simulate in test_native.py), with the run-out, FMU state,
directional derivatives, event indicators and Booleans through the FMI 3.0 calls."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from ctypes import POINTER, byref, c_bool, c_double, c_void_p
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest

import winder

fmpy = pytest.importorskip("fmpy", reason="FMPy is installed with winder[fmu]")
from fmpy.fmi3 import FMU3Model, FMU3Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from winder.fmu.native import build_fmu  # noqa: E402


@pytest.fixture(scope="module")
def fmus(tmp_path_factory, models_dir) -> dict[str, tuple[Path, Path]]:
    """(FMI 2.0, FMI 3.0) FMUs of the two-drum winder and of the winder line with its
    unwind on a torque input; the FMI 3.0 one of the two-drum winder through the CLI."""
    d = tmp_path_factory.mktemp("fmi3")
    out: dict[str, tuple[Path, Path]] = {}
    for key, file in (("two_drum", "two_drum_winder.toml"), ("line", "winder_line_fmu.toml")):
        v2 = build_fmu(models_dir / file, d / f"{key}2.fmu")
        if key == "two_drum":
            v3 = d / f"{key}3.fmu"
            proc = subprocess.run([sys.executable, "-m", "winder", "fmu", str(models_dir / file),
                                   "-o", str(v3), "--fmi-version", "3"],
                                  capture_output=True, text=True, timeout=600)
            assert proc.returncode == 0, proc.stderr
            assert "FMI 3.0" in proc.stdout and "run-checked with FMPy" in proc.stdout
        else:
            v3 = build_fmu(models_dir / file, d / f"{key}3.fmu", fmi_version=3)
        out[key] = (v2, v3)
    return out


@pytest.mark.parametrize("key", ["two_drum", "line"])
def test_validates(key, fmus) -> None:
    path = fmus[key][1]
    assert validate_fmu(str(path)) == []
    md = fmpy.read_model_description(str(path))
    assert md.fmiVersion == "3.0"
    with zipfile.ZipFile(path) as zf:
        names = zf.namelist()
        root = ET.fromstring(zf.read("modelDescription.xml"))
    flags = {"canGetAndSetFMUState", "canSerializeFMUState", "providesDirectionalDerivatives"}
    for kind in ("CoSimulation", "ModelExchange"):
        element = root.find(kind)
        assert element is not None and {k for k in flags if element.get(k) == "true"} == flags
    cs = root.find("CoSimulation")
    assert cs is not None and cs.get("canHandleVariableCommunicationStepSize") == "true"
    assert len(root.findall("ModelStructure/EventIndicator")) > 0
    model = md.coSimulation.modelIdentifier
    assert f"binaries/x86_64-linux/{model}.so" in names
    assert {"sources/fmi3.c", "sources/fmi3Functions.h", "sources/buildDescription.xml",
            "sources/LICENSE-FMI-headers.txt"} <= set(names)
    ldd = subprocess.run(["ldd", str(_binary(path, model, fmus[key][1].parent / "x"))],
                         capture_output=True, text=True).stdout
    assert "python" not in ldd


def _binary(fmu: Path, model: str, where: Path) -> Path:
    with zipfile.ZipFile(fmu) as zf:
        zf.extract(f"binaries/x86_64-linux/{model}.so", where)
    return where / "binaries" / "x86_64-linux" / f"{model}.so"


def _outputs(path: Path) -> list[str]:
    md = fmpy.read_model_description(str(path))
    return [v.name for v in md.modelVariables if v.causality == "output"]


@pytest.mark.parametrize("fmi_type", ["CoSimulation", "ModelExchange"])
def test_equals_fmi2(fmi_type, fmus) -> None:
    """FMPy's simulate_fmu, 1 s of the two-drum winder: every output of the FMI 3.0 FMU
    equals the FMI 2.0 FMU's exactly (measured 0: one core; ME through FMPy's CVode with
    the same event indicators)."""
    v2, v3 = fmus["two_drum"]
    names = _outputs(v3)
    assert names == _outputs(v2)
    kw = {"relative_tolerance": 1e-8, "solver": "CVode"} if fmi_type == "ModelExchange" \
        else {}
    r2, r3 = (fmpy.simulate_fmu(str(p), fmi_type=fmi_type, stop_time=1.0, output_interval=0.01,
                                output=names, **kw) for p in (v2, v3))
    assert len(r3) == len(r2) > 100
    for k in names:
        assert np.array_equal(r3[k], r2[k]), k
    ref = winder.simulate(winder.load_scene(Path(__file__).resolve().parents[2] / "models"
                                            / "two_drum_winder.toml"),
                          t_end=1.0, output_step=0.01, method="DOPRI5", rtol=1e-8, atol=1e-10)
    # and the radius equals simulate's (as the FMI 2.0 FMU's does: test_native.py)
    assert np.max(np.abs(np.interp(ref.t, r3["time"], r3["set_radius"]) - ref["set_radius"])) \
        < 1e-6


class _Slave:
    """An FMPy FMI 3.0 co-simulation slave in step mode, its value references by name and
    its log."""

    def __init__(self, path: Path, **booleans: bool) -> None:
        md = fmpy.read_model_description(str(path))
        self.unzip = fmpy.extract(str(path))
        self.refs = {v.name: v.valueReference for v in md.modelVariables}
        self.log: list[str] = []
        self.fmu = FMU3Slave(guid=md.guid, unzipDirectory=self.unzip,
                             modelIdentifier=md.coSimulation.modelIdentifier,
                             instanceName="t")
        self.fmu.instantiate(logMessage=lambda env, status, cat, msg: self.log.append(
            f"[{cat.decode()}] {msg.decode()}"))
        self.fmu.enterInitializationMode()
        for name, value in booleans.items():
            self.fmu.setBoolean([self.refs[name]], [value])
        self.fmu.exitInitializationMode()

    def get(self, names: list[str]) -> list[float]:
        return self.fmu.getFloat64([self.refs[k] for k in names])

    def close(self) -> None:
        self.fmu.terminate()
        self.fmu.freeInstance()
        shutil.rmtree(self.unzip, ignore_errors=True)


def test_state_round_trips_and_rk4(fmus) -> None:
    """fmi3GetFMUState/SetFMUState and Serialize/Deserialize: back at step 10, the next 20
    steps repeat bit for bit; the Boolean rk4 (its FMI 3.0 value reference) runs the
    fixed-step RK4: other numbers than DOPRI5's, the FMI 2.0 FMU's with rk4 exactly."""
    from fmu_slave import slave

    v2, v3 = fmus["two_drum"]
    names = ["set_speed", "set_radius", "front_nip_normal_force", "rider_z"]
    s = _Slave(v3)
    try:
        for i in range(10):
            s.fmu.doStep(i * 0.01, 0.01)
        state = s.fmu.getFMUState()
        blob = s.fmu.serializeFMUState(state)
        first = []
        for i in range(10, 30):
            s.fmu.doStep(i * 0.01, 0.01)
            first.append(s.get(names))
        for restore in ("state", "bytes"):
            if restore == "state":
                s.fmu.setFMUState(state)
            else:
                s.fmu.setFMUState(s.fmu.deserializeFMUState(blob))
            again = []
            for i in range(10, 30):
                s.fmu.doStep(i * 0.01, 0.01)
                again.append(s.get(names))
            assert again == first, restore
        s.fmu.freeFMUState(state)
        assert s.fmu.getBoolean([s.refs["rk4"]]) == [False]
        dopri = first[-1]
    finally:
        s.close()
    r = _Slave(v3, rk4=True)
    try:
        assert r.fmu.getBoolean([r.refs["rk4"]]) == [True]
        for i in range(30):
            r.fmu.doStep(i * 0.01, 0.01)
        rk4 = r.get(names)
    finally:
        r.close()
    assert rk4 != dopri
    with slave(v2, rk4=True) as (fmu2, refs2, _):
        for i in range(30):
            fmu2.doStep(i * 0.01, 0.01)
        assert fmu2.getReal([refs2[k] for k in names]) == rk4


def test_directional_derivatives_equal_fmi2(fmus) -> None:
    """fmi3GetDirectionalDerivative of every der(STATE) along a random seed of the states
    equals the FMI 2.0 FMU's (the exact generated Jacobian) to round-off, and a central
    difference of fmi3GetContinuousStateDerivatives (model exchange) to 1e-6 of its
    scale."""
    from fmu_slave import slave

    v2, v3 = fmus["two_drum"]
    md = fmpy.read_model_description(str(v3))
    pairs = [(v.derivative.valueReference, v.valueReference) for v in md.modelVariables
             if v.derivative is not None]
    xs, us = [x for x, _ in pairs], [u for _, u in pairs]
    seed = list(np.random.default_rng(3).normal(size=len(xs)))
    s = _Slave(v3)
    try:
        got = s.fmu.getDirectionalDerivative(us, xs, seed)
    finally:
        s.close()
    with slave(v2) as (fmu2, _, _):
        want = fmu2.getDirectionalDerivative(us, xs, seed)
    np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-12)
    # model exchange: a central difference of the derivatives along the seed
    unzip = fmpy.extract(str(v3))
    me = FMU3Model(guid=md.guid, unzipDirectory=unzip,
                   modelIdentifier=md.modelExchange.modelIdentifier, instanceName="m")
    try:
        me.instantiate()
        me.enterInitializationMode()
        me.exitInitializationMode()
        me.enterContinuousTimeMode()
        n = me.getNumberOfContinuousStates()
        x0 = np.zeros(n)
        me.getContinuousStates(x0.ctypes.data_as(fmpy.fmi3.POINTER(fmpy.fmi3.fmi3Float64)), n)
        order = [x - min(xs) for x in xs]
        direction = np.zeros(n)
        direction[order] = seed
        eps = 1e-7 * (1.0 + np.linalg.norm(x0))
        rates = []
        for sign in (1.0, -1.0):
            x = x0 + sign * eps * direction
            me.setContinuousStates(x.ctypes.data_as(fmpy.fmi3.POINTER(fmpy.fmi3.fmi3Float64)), n)
            dx = np.zeros(n)
            me.getContinuousStateDerivatives(
                dx.ctypes.data_as(fmpy.fmi3.POINTER(fmpy.fmi3.fmi3Float64)), n)
            rates.append(dx)
        fd = (rates[0] - rates[1]) / (2 * eps)
        assert np.max(np.abs(fd[[u - min(us) for u in us]] - np.array(got))) < \
            1e-6 * np.max(np.abs(got))
        z = np.zeros(me.getNumberOfEventIndicators())
        me.setContinuousStates(x0.ctypes.data_as(fmpy.fmi3.POINTER(fmpy.fmi3.fmi3Float64)), n)
        me.getEventIndicators(z.ctypes.data_as(fmpy.fmi3.POINTER(fmpy.fmi3.fmi3Float64)),
                              len(z))
        zvars = [v.valueReference for v in md.modelVariables
                 if v.name.startswith("indicator(")]
        assert len(zvars) == len(z) > 0
        assert me.getFloat64(zvars) == list(z)  # the indicators as variables
        me.terminate()
        me.freeInstance()
    finally:
        shutil.rmtree(unzip, ignore_errors=True)


def test_run_out_terminates(fmus, tmp_path, models_dir) -> None:
    """The winder line with 0.2 mm of paper on its parent: fmi3DoStep returns fmi3Discard
    at the run-out, with the outputs and ``time`` there, equal to the in-process Stepper's,
    and the reason logged; a further step returns fmi3Discard with terminateSimulation
    and lastSuccessfulTime at the run-out."""
    import tomli_w
    from fmpy.fmi1 import FMICallException

    scene = winder.load_scene(models_dir / "winder_line_fmu.toml")
    scene = scene.replace(roll={"parent": {"initial_radius": 0.4002}})
    (tmp_path / "runout.toml").write_text(tomli_w.dumps(scene.to_dict()))
    path = build_fmu(tmp_path / "runout.toml", tmp_path / "runout.fmu", fmi_version=3)
    sim = winder.Stepper(scene)
    s = _Slave(path)
    try:
        for i in range(400):
            sim.step(0.01)
            try:
                s.fmu.doStep(i * 0.01, 0.01)
            except FMICallException as exc:
                assert exc.status == 2  # fmi3Discard
                break
        assert sim.ended is not None
        t = s.get(["t"])[0]
        assert t == sim.t and 2.6 < t < 2.75
        assert s.get(["time"])[0] == t
        assert s.get(["parent_radius"])[0] == pytest.approx(0.4, abs=1e-9)
        # the next step, called directly (FMPy raises on fmi3Discard): its outputs say so
        step = s.fmu.dll.fmi3DoStep
        step.argtypes = [c_void_p, c_double, c_double, c_bool, *[POINTER(c_bool)] * 3,
                         POINTER(c_double)]
        event, terminate, early, last = c_bool(True), c_bool(False), c_bool(True), c_double()
        status = step(s.fmu.component, t, 0.01, True, byref(event), byref(terminate),
                      byref(early), byref(last))
        assert (status, terminate.value, event.value, early.value, last.value) == \
            (2, True, False, False, t)
    finally:
        s.close()
    assert any("'parent' ran out of web" in line for line in s.log), s.log


def test_c_host_under_asan(tmp_path, models_dir) -> None:
    """A C host of the FMI 3.0 interface (tests/fmu/native_host3.c: dlopen, no FMPy)
    compiled with -fsanitize=address,undefined instantiates, steps, takes and serialises an
    FMU state, misuses it twice (each refusal logged: through the wrapper's relay and by
    the wrapper) and frees a sanitized build of the two-drum FMU 300 times: exit 0, no
    sanitizer report, the same radius every time, 600 messages."""
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    path = build_fmu(models_dir / "two_drum_winder.toml", tmp_path / "asan3.fmu",
                     fmi_version=3, sanitize=True)
    md = fmpy.read_model_description(str(path))
    so = _binary(path, md.coSimulation.modelIdentifier, tmp_path / "x")
    host = tmp_path / "host3"
    subprocess.run([cc, "-fsanitize=address,undefined", "-fno-sanitize-recover=undefined",
                    "-g", "-I", str(Path(fmpy.__file__).parent / "c-code"),
                    str(Path(__file__).with_name("native_host3.c")), "-o", str(host), "-ldl"],
                   check=True, capture_output=True)
    refs = {v.name: v.valueReference for v in md.modelVariables}
    proc = subprocess.run([str(host), str(so), md.guid, "300", str(refs["set_radius"]),
                           str(refs["time"])],
                          capture_output=True, text=True, timeout=600,
                          env={"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=0"})
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "Sanitizer" not in proc.stderr and "runtime error" not in proc.stderr
    assert "300 cycles, same radius" in proc.stdout and "600 messages" in proc.stdout, \
        proc.stdout


def test_fmpy_compile_rebuilds_it(fmus, tmp_path) -> None:
    """``fmpy compile`` builds the binary of an archive without one from
    sources/buildDescription.xml; the rebuilt FMU gives the same outputs (to 1e-12:
    FMPy's own flags)."""
    from fmu_slave import rebuilt

    v3 = fmus["two_drum"][1]
    copy = rebuilt(v3, tmp_path / "rebuilt.fmu")
    names = ["set_radius", "set_speed", "front_nip_normal_force"]
    got = []
    for path in (v3, copy):
        s = _Slave(path)
        try:
            for i in range(50):
                s.fmu.doStep(i * 0.01, 0.01)
            got.append(s.get(names))
        finally:
            s.close()
    np.testing.assert_allclose(got[1], got[0], rtol=1e-12)
