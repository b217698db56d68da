"""The host side of a winder FMU in FMPy: loading and starting it, written once for the
CLI's run-check, the FMU tests and the real-time benchmark (needs ``winder[fmu]``)."""

from __future__ import annotations

import shutil
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import fmpy
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

from winder._errors import WinderError
from winder.fmu.parameters import FmuError

__all__ = ["loaded_fmu", "start_fmu", "get_reals", "check_fmu"]


@contextmanager
def loaded_fmu(path: str | Path, *, instance_name: str = "winder"
               ) -> Iterator[tuple[Any, dict[str, int], Path]]:
    """FMPy's ``FMU2Slave`` (``FMU3Slave`` for FMI 3.0) of an extracted copy of ``path``,
    the value references by variable name, and the extraction folder (removed on exit).
    The caller instantiates (:func:`start_fmu`) and frees the instance (``freeInstance``),
    as often as it likes."""
    try:
        md = fmpy.read_model_description(str(path))
    except Exception as exc:  # fmpy's ValidationError lists the problems
        raise FmuError(f"{path}: invalid model description: {exc}") from exc
    unzip = fmpy.extract(str(path))
    try:
        slave = FMU3Slave if md.fmiVersion.startswith("3") else FMU2Slave
        fmu = slave(guid=md.guid, unzipDirectory=unzip,
                    modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName=instance_name)
        yield fmu, {v.name: v.valueReference for v in md.modelVariables}, Path(unzip)
    finally:
        shutil.rmtree(unzip, ignore_errors=True)


def start_fmu(fmu: Any, refs: dict[str, int], *, logging: bool = True,
              **parameters: float | bool) -> None:
    """Instantiate at ``t = 0`` and set ``parameters`` (by FMU variable name; booleans
    with ``setBoolean``) during initialisation."""
    fmu.instantiate(loggingOn=logging)
    v3 = isinstance(fmu, FMU3Slave)
    if v3:
        fmu.enterInitializationMode(startTime=0.0)
    else:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
    for name, value in parameters.items():
        if isinstance(value, bool):
            fmu.setBoolean([refs[name]], [value])
        elif v3:
            fmu.setFloat64([refs[name]], [float(value)])
        else:
            fmu.setReal([refs[name]], [float(value)])
    fmu.exitInitializationMode()


def get_reals(fmu: Any, vrs: list[int]) -> list[float]:
    """The values of the Real (FMI 3.0: Float64) variables ``vrs``."""
    return fmu.getFloat64(vrs) if isinstance(fmu, FMU3Slave) else fmu.getReal(vrs)


def check_fmu(path: Path) -> str:
    """Load the FMU in FMPy in this process and run ten 1 ms steps; a one-line report."""
    with loaded_fmu(path, instance_name="check") as (fmu, refs, _):
        try:
            start_fmu(fmu, refs)
            for i in range(10):
                fmu.doStep(currentCommunicationPoint=i * 1e-3, communicationStepSize=1e-3)
            # the roll's radius: ``radius`` (single drum) or the first ``ROLL_radius``
            name = "radius" if "radius" in refs else next(
                (k for k in refs if k.endswith("_radius")), None)
            radius = get_reals(fmu, [refs[name]])[0] if name is not None else None
            fmu.terminate()
        except Exception as exc:  # FMPy raises plain exceptions with the FMI status
            raise WinderError(f"{path} was built but does not run in this Python "
                              f"({sys.executable}): {exc}") from exc
        finally:
            fmu.freeInstance()
    where = f", {name} {radius:.6g} m" if name is not None else ""
    return f"run-checked with FMPy {fmpy.__version__}: 10 steps of 1 ms{where}"
