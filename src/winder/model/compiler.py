"""The C compiler of the generated code: which one (``$CC``, else ``cc`` or ``gcc``), one
run of it, and several at once (:class:`Compiles`: one process per generated file, started as
soon as the file is written)."""

from __future__ import annotations

import os
import shutil
import subprocess

from winder._errors import WinderError

__all__ = ["CompilerMissing", "CompileError", "compiler", "run_compiler", "Compiles"]


class CompilerMissing(WinderError, RuntimeError):
    """No C compiler: the generated path is unavailable (the numeric path remains)."""


class CompileError(WinderError, RuntimeError):
    """The C compiler failed on the generated model: the message holds its output."""


def compiler() -> str:
    """The C compiler: ``$CC``, else ``cc`` or ``gcc`` on the PATH."""
    env = os.environ.get("CC")
    if env:
        cc = shutil.which(env)
        if cc is None:
            raise CompilerMissing(f"the C compiler CC={env!r} is not found")
        return cc
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        raise CompilerMissing("no C compiler (cc or gcc) on the PATH")
    return cc


def run_compiler(args: list[str], what: str) -> None:
    """Run the C compiler with ``args``; :class:`CompileError` with its output if it
    fails."""
    cc = compiler()
    proc = subprocess.run([cc, *args], capture_output=True, text=True)
    if proc.returncode != 0:
        raise CompileError(f"compiling {what} failed ({cc}):\n" + proc.stderr[-2000:])


class Compiles:
    """The generated functions' objects compiled at once (one compiler process each,
    started as soon as its source is written); :meth:`wait` raises :class:`CompileError`
    on the first failure; leaving the ``with`` block ends any still running."""

    def __init__(self) -> None:
        self.running: list[tuple[subprocess.Popen[str], str]] = []

    def start(self, args: list[str], what: str) -> None:
        self.running.append((subprocess.Popen([compiler(), *args], stdout=subprocess.DEVNULL,
                                              stderr=subprocess.PIPE, text=True), what))

    def wait(self) -> None:
        for proc, what in self.running:
            _, err = proc.communicate()
            if proc.returncode != 0:
                raise CompileError(f"compiling {what} failed ({proc.args[0]}):\n"
                                   + err[-2000:])

    def __enter__(self) -> Compiles:
        return self

    def __exit__(self, *exc: object) -> None:
        for proc, _ in self.running:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
