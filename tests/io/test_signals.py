"""Stopping the command line with SIGINT, SIGTERM and SIGHUP at different phases (real
processes, real signals): exit status 128 + signal, one line on stderr naming the signal, no
traceback, no temporary file, no partial output, no child process left, the temp directory
empty. The result and its NPZ twin are written both or neither whenever the signal comes:
at each step of the write, a process signals itself (deterministically, from a wrapped write
step) and the files on disk, the line and the status are checked."""

from __future__ import annotations

import functools
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from cli_corpus import FREE_SPIN, good_result_arrays, quick_scene, write_npz

SIGNALS = [signal.SIGINT, signal.SIGTERM, signal.SIGHUP]
#: The line of a command stopped by each signal.
SAYS = {signal.SIGINT: "interrupted (SIGINT)", signal.SIGTERM: "terminated (SIGTERM)",
        signal.SIGHUP: "hung up (SIGHUP)"}


def _spawn(tmp_path: Path, *args: str) -> subprocess.Popen:
    (tmp_path / "tmp").mkdir(exist_ok=True)
    env = dict(os.environ, TMPDIR=str(tmp_path / "tmp"), PYTHONUNBUFFERED="1")
    return subprocess.Popen([sys.executable, "-m", "winder", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, cwd=tmp_path)


def _wait_for(what: Callable[[], object], proc: subprocess.Popen, timeout: float = 60.0,
              poll: float = 0.002) -> None:
    end = time.monotonic() + timeout
    while not what():
        if proc.poll() is not None:
            raise AssertionError(f"process ended first: {proc.communicate()}")
        if time.monotonic() > end:
            proc.kill()
            raise AssertionError("timed out")
        time.sleep(poll)


def _finish(proc: subprocess.Popen) -> tuple[int, str]:
    _, err = proc.communicate(timeout=60)
    return proc.returncode, err


def _assert_stopped(status: int, err: str, sig: int) -> None:
    assert status == 128 + sig, (status, err)
    assert "Traceback" not in err, err
    assert err.strip() == f"winder: {SAYS[sig]}; no partial file left", err


def _debris(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if p.name.startswith(".winder-")]


def _big_scene(folder: Path) -> Path:
    """A 6 s free spin sampled every 0.1 ms: 60 001 rows, about 2 s of CSV writing."""
    p = folder / "big.toml"
    p.write_text(FREE_SPIN.replace("duration = 300.0", "duration = 6.0")
                 .replace("output_step = 0.05 ", "output_step = 1e-4"))
    return p


@pytest.mark.parametrize(("sig", "previous"), [
    (signal.SIGINT, False), (signal.SIGTERM, False), (signal.SIGHUP, False),
    (signal.SIGTERM, True)], ids=["SIGINT", "SIGTERM", "SIGHUP", "SIGTERM-existing"])
def test_signal_while_writing(sig: int, previous: bool, tmp_path: Path) -> None:
    out = tmp_path / "out" / "r.csv"
    if previous:
        out.parent.mkdir()
        out.write_text("previous\n")
    proc = _spawn(tmp_path, "run", str(_big_scene(tmp_path)), "--out", str(out))
    _wait_for(lambda: out.parent.is_dir() and _debris(out.parent), proc)
    proc.send_signal(sig)
    _assert_stopped(*_finish(proc), sig)
    assert _debris(tmp_path) == []
    assert not out.with_suffix(".npz").exists()  # neither the CSV nor its twin
    if previous:
        assert out.read_text() == "previous\n"  # untouched
    else:
        assert not out.parent.exists()  # the folder it made is gone too
    assert list((tmp_path / "tmp").iterdir()) == []


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP],
                         ids=["SIGTERM", "SIGHUP"])
def test_signal_during_the_run(sig: int, tmp_path: Path) -> None:
    """Sent 0.3 s after ``main`` installed its handlers: while the scene is integrated."""
    scene = tmp_path / "scene.toml"
    scene.write_text(FREE_SPIN)
    out = tmp_path / "r.npz"
    proc = _spawn(tmp_path, "run", str(scene), "--out", str(out), "--plots",
                  str(tmp_path / "plots"))
    _wait_for(lambda: _catches(proc.pid, signal.SIGTERM), proc)
    time.sleep(0.3)
    proc.send_signal(sig)
    _assert_stopped(*_finish(proc), sig)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.toml", "tmp"]
    assert list((tmp_path / "tmp").iterdir()) == []


@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: signal.Signals(s).name)
def test_second_signal_while_writing(sig: int, tmp_path: Path) -> None:
    out = tmp_path / "r.csv"
    proc = _spawn(tmp_path, "run", str(_big_scene(tmp_path)), "--out", str(out))
    _wait_for(lambda: _debris(tmp_path), proc)
    proc.send_signal(sig)
    time.sleep(0.005)
    if proc.poll() is None:
        proc.send_signal(sig)
    status, err = _finish(proc)
    name = signal.Signals(sig).name
    assert status == 128 + sig and name in err and "Traceback" not in err, err
    assert _debris(tmp_path) == [] and not out.exists() and not out.with_suffix(".npz").exists()


_SLOW_CLEANUP = """
import sys, time, pathlib
from winder.io.interrupt import Interrupted, handling_signals, on_abort
tmp = pathlib.Path(sys.argv[1])
with handling_signals():
    tmp.write_text("temporary")
    try:
        with on_abort(lambda: tmp.unlink(missing_ok=True)):
            print("ready", flush=True)
            time.sleep(60)
    except Interrupted:
        print("cleaning up", flush=True)
        time.sleep(60)  # a slow clean-up, interrupted by the second signal
"""


@pytest.mark.parametrize("second", SIGNALS, ids=lambda s: signal.Signals(s).name)
def test_second_signal_during_cleanup_says_so(second: int, tmp_path: Path) -> None:
    tmp = tmp_path / "partial.tmp"
    proc = subprocess.Popen([sys.executable, "-c", _SLOW_CLEANUP, str(tmp)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "ready"
    proc.send_signal(signal.SIGINT)
    assert proc.stdout.readline().strip() == "cleaning up"
    t0 = time.monotonic()
    proc.send_signal(second)
    status, err = _finish(proc)
    assert time.monotonic() - t0 < 10.0  # it stopped, it did not sleep out the clean-up
    assert status == 128 + second
    assert err.strip() == (f"winder: {signal.Signals(second).name} again during clean-up: "
                           "temporary files removed, stopping now")
    assert not tmp.exists()


def _children(pid: int) -> list[tuple[int, str]]:
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            if int(fields[1]) == pid:
                cmd = (stat.parent / "cmdline").read_bytes().replace(b"\0", b" ").decode()
                found.append((int(stat.parent.name), cmd))
        except (OSError, IndexError, ValueError):
            continue
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_live_view_stops_its_meshcat_server(sig: int, tmp_path: Path, paper_scene) -> None:
    arrays = good_result_arrays()
    src = write_npz(tmp_path / "r.npz", arrays,
                    {"scene": "paper", "scene_dict": paper_scene.to_dict()})
    proc = _spawn(tmp_path, "view", str(src))
    try:
        lines = []
        while not (lines and lines[-1].startswith("live view at")):
            lines.append(proc.stdout.readline())  # meshcat prints its URL first
            assert lines[-1], (lines, proc.stderr.read())
        servers = [p for p, cmd in _children(proc.pid) if "meshcat.servers.zmqserver" in cmd]
        assert len(servers) == 1
    except BaseException:
        proc.terminate()  # the live view would run forever
        proc.wait(timeout=30)
        raise
    proc.send_signal(sig)
    status, err = _finish(proc)
    if sig == signal.SIGINT:  # Ctrl-C is how a live view ends
        assert status == 0 and err.strip() == "live view stopped", err
    else:
        _assert_stopped(status, err, sig)
    assert not _alive(servers[0])


def _catches(pid: int, sig: int) -> bool:
    """Whether process ``pid`` has a handler for ``sig`` (``SigCgt`` in /proc/PID/status):
    the command line installs its SIGTERM handler first thing in ``main``."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    mask = int(next(ln.split()[1] for ln in status.splitlines() if ln.startswith("SigCgt")), 16)
    return bool(mask >> (sig - 1) & 1)


@functools.cache
def _winder_imports_lazily() -> bool:
    probe = subprocess.run([sys.executable, "-c", "import sys, winder.cli; "
                            "print('pinocchio' in sys.modules)"], capture_output=True,
                           text=True, timeout=120)
    return probe.stdout.strip() == "False"


@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: signal.Signals(s).name)
def test_signal_during_start_up(sig: int, tmp_path: Path) -> None:
    """Signals as soon as ``main`` has started, while the command imports its modules
    (only where ``import winder.cli`` is light: otherwise everything is imported before
    ``main`` runs, and a signal then is Python's own)."""
    if not _winder_imports_lazily():
        pytest.skip("'import winder.cli' imports all of winder before the command line "
                    "starts; a signal during that import is Python's own")
    proc = _spawn(tmp_path, "run", str(_big_scene(tmp_path)), "--out", str(tmp_path / "r.npz"))
    _wait_for(lambda: _catches(proc.pid, signal.SIGTERM), proc)  # main() has started
    proc.send_signal(sig)
    _assert_stopped(*_finish(proc), sig)
    assert not (tmp_path / "r.npz").exists()


@pytest.mark.parametrize(("sig", "phase"), [(signal.SIGTERM, "build")])
def test_fmu_stopped_leaves_no_build_folder(sig: int, phase: str, tmp_path: Path) -> None:
    pytest.importorskip("fmpy", reason="the FMU's headers come with FMPy (winder[fmu])")
    if shutil.which("cc") is None and shutil.which("gcc") is None:
        pytest.skip("no C compiler: the native FMU is built with one")
    scene = tmp_path / "s.toml"
    scene.write_text(FREE_SPIN)
    out = tmp_path / "out" / "w.fmu"
    proc = _spawn(tmp_path, "fmu", str(scene), "-o", str(out))
    if phase == "build":
        _wait_for(lambda: any((tmp_path / "tmp").iterdir()), proc)
    else:
        _wait_for(out.exists, proc)
    proc.send_signal(sig)
    status, err = _finish(proc)
    if phase == "check" and status == 0:  # it had finished: a complete FMU
        import zipfile
        assert zipfile.ZipFile(out).testzip() is None
    else:
        _assert_stopped(status, err, sig)
    assert list((tmp_path / "tmp").iterdir()) == []
    assert _debris(tmp_path) == []
    if phase == "build":
        assert not out.parent.exists()
    else:
        assert sorted(out.parent.iterdir()) == [out]


def test_partial_npz_never_loads(tmp_path: Path) -> None:
    """What a killed writer of the earlier versions could leave: a prefix of an NPZ."""
    import winder

    full = write_npz(tmp_path / "full.npz", good_result_arrays()).read_bytes()
    for cut in np.linspace(0, len(full) - 1, 7).astype(int):
        (tmp_path / "cut.npz").write_bytes(full[:cut])
        with pytest.raises(winder.WinderError, match="cut.npz"):
            winder.load_result(tmp_path / "cut.npz")


# ---- a signal at each step of writing a result and its twin -------------------------------

#: ``winder run SCENE --out OUT/r.csv`` in a process that signals itself (signal number
#: argv[2]) at one step (argv[1]) of writing r.csv and r.npz, and notes it in argv[3].
_PHASE_RUN = r"""
import atexit, os, sys
from pathlib import Path

phase, signo, note = sys.argv[1], int(sys.argv[2]), Path(sys.argv[3])
scene, out = sys.argv[4], Path(sys.argv[5])
fired = []

def fire(where):
    if where == phase and not fired:
        fired.append(where)
        note.write_text(where)
        os.kill(os.getpid(), signo)  # acted on at the next bytecode: right here

import numpy.lib.format as npy_format
import winder.io.files as files
import winder.io.result as result

writer, write_array, replace = result.Result._writer, npy_format.write_array, os.replace
commit = files.atomic_write_all

def _writer(self, path):
    write, kind = writer(self, path), Path(path).suffix[1:]
    def wrapped(tmp):
        fire(f"{kind}-start")    # its temporary is there, empty
        write(tmp)
        fire(f"{kind}-end")      # its temporary is complete
    return wrapped

arrays = []
def _write_array(*args, **kwargs):
    arrays.append(1)
    if len(arrays) == 3:
        fire("npz-middle")       # inside np.savez: two members of the NPZ written
    return write_array(*args, **kwargs)

def _replace(src, dst, **kwargs):
    replace(src, dst, **kwargs)
    if Path(dst).parent == out.parent:
        fire("renamed-" + Path(dst).suffix[1:])  # that file is in place

def _commit(items):
    done = commit(items)
    fire("committed")            # both in place, the write over
    return done

result.Result._writer = _writer
npy_format.write_array = _write_array
os.replace = _replace
files.atomic_write_all = _commit
atexit.register(fire, "exiting")  # main has returned; Python is shutting down
from winder.cli import main

sys.argv = ["winder", "run", scene, "--out", str(out)]
sys.exit(main())
"""

#: The steps, in the order they happen: all before "committed" leave neither file.
PHASES = ["csv-start", "csv-end", "npz-start", "npz-middle", "npz-end", "renamed-csv",
          "renamed-npz", "committed", "exiting"]
_CASES = [(sig, phase, False) for sig in SIGNALS for phase in PHASES] + [
    (sig, phase, True) for sig in (signal.SIGTERM, signal.SIGHUP)
    for phase in ("npz-middle", "renamed-csv", "renamed-npz")]
_EARLIER = {".csv": "t,x\n0,1\n", ".npz": "an earlier file\n"}


def _run_phase(case: tuple[int, str, bool], folder: Path) -> dict:
    sig, phase, previous = case
    folder.mkdir(parents=True)
    (folder / "tmp").mkdir()
    out = folder / "out" / "r.csv"
    if previous:
        out.parent.mkdir()
        for suffix, text in _EARLIER.items():
            out.with_suffix(suffix).write_text(text)
    env = dict(os.environ, TMPDIR=str(folder / "tmp"), PYTHONUNBUFFERED="1")
    proc = subprocess.run([sys.executable, "-c", _PHASE_RUN, phase, str(int(sig)),
                           str(folder / "fired"), str(quick_scene(folder)), str(out)],
                          capture_output=True, text=True, env=env, cwd=folder, timeout=240)
    return {"status": proc.returncode, "out": proc.stdout, "err": proc.stderr, "csv": out,
            "fired": (folder / "fired").read_text() if (folder / "fired").exists() else None}


@pytest.fixture(scope="module")
def phase_runs(request, tmp_path_factory) -> dict:
    """The cases selected in this session, four processes at a time (each mostly imports)."""
    cases = [item.callspec.params["case"] for item in request.session.items
             if item.originalname == "test_both_or_neither_at_each_step_of_the_write"]
    root = tmp_path_factory.mktemp("phases")
    with ThreadPoolExecutor(4) as pool:
        runs = pool.map(lambda c: _run_phase(c, root / f"{int(c[0])}-{c[1]}-{int(c[2])}"),
                        cases)
        return dict(zip(cases, runs, strict=True))


@pytest.mark.parametrize("case", _CASES, ids=lambda c: f"{signal.Signals(c[0]).name}-{c[1]}"
                         + ("-existing" if c[2] else ""))
def test_both_or_neither_at_each_step_of_the_write(case, phase_runs) -> None:
    """Until both files are in place and the write is over, a signal leaves neither (and
    files that were there before untouched): the line says which signal and that no
    partial file is left. After it, both are complete and the line names them; once the
    command has returned, the process ends with its own status 0, without a word."""
    import winder

    sig, phase, previous = case
    run = phase_runs[case]
    status, err, csv = run["status"], run["err"], run["csv"]
    npz, folder = csv.with_suffix(".npz"), csv.parent.parent
    assert run["fired"] == phase, run  # the signal came at that step
    assert "Traceback" not in err and "Exception ignored" not in err, err
    assert _debris(folder) == [] and list((folder / "tmp").iterdir()) == []
    if PHASES.index(phase) < PHASES.index("committed"):
        _assert_stopped(status, err, sig)
        assert run["out"] == ""
        if previous:  # put back as they were
            assert {p.suffix: p.read_text() for p in csv.parent.iterdir()} == _EARLIER
        else:
            assert not csv.parent.exists()  # neither file, nor the folder made for them
        return
    if phase == "committed":
        assert status == 128 + sig, (status, err)
        assert err.strip() == (f"winder: {SAYS[sig]} after writing {csv}, {npz} (complete); "
                               "no partial file left")
    else:  # "exiting": the run had ended and said so
        assert status == 0 and err == "", (status, err)
        assert run["out"].startswith(f"free_spin: 11 samples to {csv}")
    a, b = winder.load_result(csv), winder.load_result(npz)
    assert list(a) == list(b) and len(a.t) == 11
    for name in a:  # the CSV's 15 digits: within 5e-15 relative (10x margin)
        np.testing.assert_allclose(a[name], b[name], rtol=5e-14, atol=0.0, err_msg=name)


@pytest.mark.parametrize("links", [True, False], ids=["hard-links", "no-hard-links"])
def test_a_failed_move_puts_back_the_files_it_replaced(links: bool, tmp_path: Path,
                                                       monkeypatch) -> None:
    """The second of two moves into place fails (an error, as a signal would act there):
    the first is taken back and both earlier files are as they were, on a file system with
    hard links and on one without (where the earlier file is moved aside, not linked)."""
    import winder.io.files as files

    a, b = tmp_path / "r.csv", tmp_path / "r.npz"
    a.write_text("earlier a\n")
    b.write_text("earlier b\n")
    real_replace, failed = os.replace, []

    def replace(src, dst, **kw):
        if Path(dst) == b and not failed:  # moving the new b into place
            failed.append(src)
            raise OSError(5, "I/O error")
        return real_replace(src, dst, **kw)

    def no_link(*args, **kwargs):
        raise OSError(1, "Operation not permitted")

    monkeypatch.setattr(files.os, "replace", replace)
    if not links:
        monkeypatch.setattr(files.os, "link", no_link)
    with pytest.raises(files.OutputError, match="cannot write .*r.npz: I/O error"):
        files.atomic_write_all([(a, lambda p: p.write_text("new a\n")),
                                (b, lambda p: p.write_text("new b\n"))])
    assert failed and a.read_text() == "earlier a\n" and b.read_text() == "earlier b\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv", "r.npz"]
