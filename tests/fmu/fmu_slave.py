"""An FMPy co-simulation slave of a native FMU for the tests (tests/fmu/ is on the path)."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from ctypes import byref
from pathlib import Path

import fmpy
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
