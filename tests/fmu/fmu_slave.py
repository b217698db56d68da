"""Host helpers of the native FMU's tests (tests/fmu/ is on the path): an FMPy
co-simulation slave, and an archive rebuilt by ``fmpy compile``."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import zipfile
from collections.abc import Iterator
from contextlib import contextmanager
from ctypes import byref
from pathlib import Path

import fmpy
import pytest
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.logging import addLoggerProxy


@contextmanager
def slave(path: Path, *, rk4: bool = False, **params: float
          ) -> Iterator[tuple[FMU2Slave, dict[str, int], list[str]]]:
    """An FMPy slave of ``path`` in stepping mode (``params`` set during initialisation),
    its value references by name, and the messages it logged."""
    md = fmpy.read_model_description(str(path))
    unzip = fmpy.extract(str(path))
    log: list[str] = []

    def logger(env, name, status, category, message) -> None:  # noqa: ANN001
        log.append(f"[{category.decode()}] {message.decode()}")

    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip,
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="t")
    refs = {v.name: v.valueReference for v in md.modelVariables}
    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(logger)
    addLoggerProxy(byref(callbacks))  # FMPy's C proxy formats the variadic arguments
    try:
        fmu.instantiate(callbacks=callbacks)
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        if rk4:
            fmu.setBoolean([refs["rk4"]], [True])
        for name, value in params.items():
            fmu.setReal([refs[name]], [value])
        fmu.exitInitializationMode()
        yield fmu, refs, log
    finally:
        fmu.terminate()
        fmu.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)


def rebuilt(fmu: Path, out: Path) -> Path:
    """``out``: the archive ``fmu`` without its binaries/, rebuilt by ``fmpy compile`` from
    its sources/ (FMPy's CMake project, as for another platform); skips without cmake."""
    bindir = Path(sys.executable).parent
    if shutil.which("cmake", path=str(bindir)) is None and shutil.which("cmake") is None:
        pytest.skip("no cmake")
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(out, "w") as dst:
        for item in src.infolist():
            if not item.filename.startswith("binaries/"):
                dst.writestr(item, src.read(item.filename))
    env = {**os.environ, "PATH": f"{bindir}{os.pathsep}{os.environ.get('PATH', '')}"}
    proc = subprocess.run([str(bindir / "fmpy"), "compile", str(out)], capture_output=True,
                          text=True, timeout=600, env=env)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    return out
