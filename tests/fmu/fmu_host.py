"""An FMPy host process for the FMU tests: ``python fmu_host.py CASE FMU OUT.json``.

Each case runs in its own process, as a host application would: pythonfmu 0.7's binary
does not survive a copy being unloaded and another instantiated twice in one process
(PythonFMU issue #228), so cases are not mixed.
"""

from __future__ import annotations

import gc
import json
import os
import sys
from pathlib import Path

import fmpy
import numpy as np

from winder.fmu.host import loaded_fmu, start_fmu


def rss_mb() -> float:
    return int(Path("/proc/self/statm").read_text().split()[1]) * 4096 / 1e6


def case_compare(path: str) -> dict:
    chans = ["radius", "roll_speed", "z", "normal_force", "drum_torque", "friction_force"]
    res = fmpy.simulate_fmu(path, stop_time=10.0, output_interval=0.01, output=chans)
    return {"time": res["time"].tolist(), **{k: res[k].tolist() for k in chans}}


def case_torque(path: str) -> dict:
    import winder

    with loaded_fmu(path, instance_name="host") as (fmu, refs, unzip):
        start_fmu(fmu, refs, speed_profile=False, com_offset=0.002)
        scene = winder.load_scene(unzip / "resources" / "scene.toml")
        scene = scene.replace(roll={"com_offset": 0.002},
                              drum={"drive": {"kind": "torque", "web_speed": 0.0}})
        sim = winder.Stepper(scene)
        out = ["drum_speed", "roll_speed", "normal_force", "drum_torque"]
        worst = 0.0
        for i in range(500):
            tau = 400.0 * np.sin(0.01 * i) + 100.0
            fmu.setReal([refs["drum_torque_command"]], [tau])
            fmu.doStep(currentCommunicationPoint=i * 0.01, communicationStepSize=0.01)
            sim.set_input("drum_torque", tau)
            sim.step(0.01)
            got = np.array(fmu.getReal([refs[k] for k in out]))
            want = np.array([sim.output(k) for k in out])
            worst = max(worst, float(np.max(np.abs(got - want) / (1.0 + np.abs(want)))))
        v_ref = fmu.getReal([refs["web_speed_reference"]])[0]
        fmu.terminate()
        fmu.freeInstance()
    return {"worst": worst, "drum_speed": sim.output("drum_speed"), "t": sim.t,
            "web_speed_reference": v_ref}


def case_stepper(path: str, n: int = 100, dt: float = 0.01) -> dict:
    """Every input driven by its own torque signal, every output compared with the
    in-process Stepper of the FMU's scene after each step (same inputs, same steps)."""
    import winder

    md = fmpy.read_model_description(path)
    inputs = [v.name for v in md.modelVariables if v.causality == "input"]
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    with loaded_fmu(path, instance_name="host") as (fmu, refs, unzip):
        start_fmu(fmu, refs)
        sim = winder.Stepper(winder.load_scene(unzip / "resources" / "scene.toml"))
        worst, echo = 0.0, 0.0
        for i in range(n):
            taus = [(300.0 + 100.0 * k) * np.sin(0.05 * (k + 1) * i) + 1500.0 + 500.0 * k
                    for k in range(len(inputs))]
            if inputs:
                fmu.setReal([refs[k] for k in inputs], taus)
            for name, tau in zip(inputs, taus, strict=True):
                sim.set_input(name, tau)
            fmu.doStep(currentCommunicationPoint=i * dt, communicationStepSize=dt)
            sim.step(dt)
            got = np.array(fmu.getReal([refs[k] for k in outputs]))
            want = np.array([sim.output(k) for k in outputs])
            worst = max(worst, float(np.max(np.abs(got - want) / (1.0 + np.abs(want)))))
            # a torque-driven drum's torque channel is its input
            echo = max([echo, *(abs(sim.output(k) - tau) for k, tau in zip(inputs, taus,
                                                                            strict=True))])
        fmu.terminate()
        fmu.freeInstance()
    return {"worst": worst, "echo": echo, "inputs": inputs, "outputs": outputs,
            "t": sim.t, "state": sim.state}


def _line_signal(name: str, i: int) -> float:
    """An input signal of the winder line: a tension set-point about 1000 N [N], or a
    torque about the unwind's braking torque ``−r T`` [N·m]."""
    if name.endswith("_setpoint"):
        return 1000.0 + 200.0 * np.sin(0.05 * i)
    return -450.0 + 100.0 * np.sin(0.07 * i)


def case_line(path: str, n: int = 200, dt: float = 0.01) -> dict:
    """The winder line: its input driven by a signal, every output (and ``t``) compared
    with the in-process Stepper of the FMU's scene after each step."""
    import winder

    md = fmpy.read_model_description(path)
    inputs = [v.name for v in md.modelVariables if v.causality == "input"]
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    with loaded_fmu(path, instance_name="host") as (fmu, refs, unzip):
        start_fmu(fmu, refs)
        sim = winder.Stepper(winder.load_scene(unzip / "resources" / "scene.toml"))
        worst, echo = 0.0, 0.0
        for i in range(n):
            values = [_line_signal(k, i) for k in inputs]
            fmu.setReal([refs[k] for k in inputs], values)
            for name, value in zip(inputs, values, strict=True):
                sim.set_input(name, value)
            fmu.doStep(currentCommunicationPoint=i * dt, communicationStepSize=dt)
            sim.step(dt)
            got = np.array(fmu.getReal([refs[k] for k in outputs]))
            want = np.array([sim.t if k == "t" else sim.output(k) for k in outputs])
            worst = max(worst, float(np.max(np.abs(got - want) / (1.0 + np.abs(want)))))
            echo = max([echo, *(abs(sim.output(k) - v) for k, v in zip(
                inputs, values, strict=True) if k in sim.output_names)])
        fmu.terminate()
        fmu.freeInstance()
    return {"worst": worst, "echo": echo, "inputs": inputs, "outputs": outputs,
            "t": sim.t, "state": sim.state,
            "final": {k: sim.output(k) for k in ("span_tension", "parent_radius",
                                                  "set_radius", "parent_speed")}}


def case_runout(path: str, dt: float = 0.01) -> dict:
    """Steps until the parent roll runs out (the in-process Stepper alongside): where the
    FMU's step fails, the status, the log, the outputs at that time, and the next step."""
    import contextlib
    import io

    import winder

    md = fmpy.read_model_description(path)
    inputs = [v.name for v in md.modelVariables if v.causality == "input"]
    logged = io.StringIO()
    with loaded_fmu(path, instance_name="host") as (fmu, refs, unzip):
        start_fmu(fmu, refs)
        sim = winder.Stepper(winder.load_scene(unzip / "resources" / "scene.toml"))
        failed, i = None, 0
        while failed is None and i < 100_000:
            values = [_line_signal(k, 0) for k in inputs]
            fmu.setReal([refs[k] for k in inputs], values)
            for name, value in zip(inputs, values, strict=True):
                sim.set_input(name, value)
            with contextlib.redirect_stdout(logged):  # FMPy prints the FMU's log
                try:
                    fmu.doStep(currentCommunicationPoint=i * dt, communicationStepSize=dt)
                except Exception as exc:  # FMPy raises on a status above warning
                    failed = str(exc)
            sim.step(dt)
            i += 1
        names = ["t", "parent_radius", "span_tension", "set_radius"]
        after = dict(zip(names, fmu.getReal([refs[k] for k in names]), strict=True))
        with contextlib.redirect_stdout(logged):
            try:
                fmu.doStep(currentCommunicationPoint=i * dt, communicationStepSize=dt)
                again = None
            except Exception as exc:
                again = str(exc)
        fmu.terminate()
        fmu.freeInstance()
    return {"steps": i, "failed": failed, "again": again, "log": logged.getvalue(),
            "after": after, "stepper_t": sim.t, "stepper_ended": sim.ended,
            "stepper": {k: sim.t if k == "t" else sim.output(k) for k in names}}


def case_free_drums(path: str, n: int = 20, dt: float = 0.01) -> dict:
    """Contact off: each drum turns under its own constant input torque alone."""
    md = fmpy.read_model_description(path)
    inputs = sorted(v.name for v in md.modelVariables if v.causality == "input")
    taus = {name: 300.0 - 420.0 * k for k, name in enumerate(inputs)}
    with loaded_fmu(path, instance_name="host") as (fmu, refs, _):
        start_fmu(fmu, refs)
        drums = [name[:-len("_torque")] for name in inputs]
        speeds = []
        speed0 = fmu.getReal([refs[f"{d}_speed"] for d in drums])
        fmu.setReal([refs[k] for k in inputs], [taus[k] for k in inputs])
        accel = []
        for i in range(n):
            fmu.doStep(currentCommunicationPoint=i * dt, communicationStepSize=dt)
            speeds.append(fmu.getReal([refs[f"{d}_speed"] for d in drums]))
            accel.append(fmu.getReal([refs[f"{d}_accel"] for d in drums]))
        fmu.terminate()
        fmu.freeInstance()
    return {"drums": drums, "torques": [taus[k] for k in inputs], "speed0": speed0,
            "speeds": speeds, "accel": accel, "dt": dt}


def case_bad_input(path: str) -> dict:
    with loaded_fmu(path, instance_name="host") as (fmu, refs, _):
        start_fmu(fmu, refs, speed_profile=False)
        fmu.setReal([refs["drum_torque_command"]], [float("inf")])
        try:
            fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)
            message = None
        except Exception as exc:  # FMPy raises on fmi2Error
            message = str(exc)
        fmu.freeInstance()
    return {"error": message}


def case_cycles_instantiate(path: str, n: int = 220) -> dict:
    from winder.fmu.slave import WinderSlave

    mem, radius = [], []
    with loaded_fmu(path, instance_name="host") as (fmu, refs, _):
        name = "radius" if "radius" in refs else "set_radius"  # single drum / two drums
        for i in range(n):
            start_fmu(fmu, refs)
            for k in range(5):
                fmu.doStep(currentCommunicationPoint=k * 1e-3, communicationStepSize=1e-3)
            radius.append(fmu.getReal([refs[name]])[0])
            fmu.terminate()
            fmu.freeInstance()
            if i in (19, n - 1):
                gc.collect()
                mem.append(rss_mb())
        alive = sum(isinstance(o, WinderSlave) for o in gc.get_objects())
    return {"cycles": n, "mem": mem, "alive": alive, "radius": radius}


def case_cycles_simulate(path: str, n: int = 200) -> dict:
    mem = []
    for i in range(n):
        res = fmpy.simulate_fmu(path, stop_time=0.02, output_interval=0.01, output=["radius"])
        if i in (19, n - 1):
            gc.collect()
            mem.append(rss_mb())
    return {"cycles": n, "mem": mem, "radius": float(res["radius"][-1])}


if __name__ == "__main__":
    case, fmu_file, out = sys.argv[1:4]
    result = globals()[f"case_{case}"](fmu_file)
    Path(out).write_text(json.dumps(result))
    # pythonfmu's binary (and libgfortran's finaliser under it) now and then corrupts the
    # heap in the interpreter's exit-time clean-up, after every check above has run; leave
    # without that clean-up once the result is written
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)
