"""A corpus of bad command lines, output paths, scene names and result files for the CLI's
error contract, shared by tests/cli/test_cli_contract.py.

Each :class:`Case` builds its inputs in a fresh folder and gives an argument list. It ends
*cleanly* when ``main`` returns 2 (or 0 where a sane run is allowed) without an exception,
stderr has no traceback and at most a few lines naming what it must name, and no file is
left behind: no temporary, nothing outside the case's folder, no output on an error.
"""

from __future__ import annotations

import contextlib
import io
import os
import pickle
import tempfile
import zipfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
FREE_SPIN = (ROOT / "models" / "free_spin.toml").read_text()
PAPER = ROOT / "models" / "paper_winding.toml"


def quick_scene(folder: Path, name: str | None = None, *, duration: float = 0.5) -> Path:
    """free_spin.toml shortened to ``duration`` [s], optionally renamed (TOML-escaped)."""
    text = FREE_SPIN.replace("duration = 300.0", f"duration = {duration!r}")
    if name is not None:
        escaped = "".join(c if c.isprintable() and c not in '"\\' else f"\\u{ord(c):04x}"
                          for c in name)
        text = text.replace('name = "free_spin"', f'name = "{escaped}"')
    p = folder / "scene.toml"
    p.write_text(text, encoding="utf-8")
    return p


@dataclass
class Case:
    category: str
    label: str
    build: Callable[[Path], list[str]]   # makes inputs in the folder, returns argv
    ok: tuple[int, ...] = (2,)            # exit statuses that are correct
    names: tuple[str, ...] = ()           # what an error message must contain
    keep: tuple[str, ...] = field(default=())  # files (relative) allowed to appear
    absent: tuple[str, ...] = field(default=())  # absolute glob patterns that must not match


@dataclass
class Outcome:
    status: int | None
    stderr: str
    problems: list[str]

    @property
    def clean(self) -> bool:
        return not self.problems


def _files(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*")}


def run_case(main: Callable[[list[str]], int], case: Case, folder: Path) -> Outcome:
    """Run ``case`` in-process in ``folder`` (created) and judge it."""
    folder.mkdir(parents=True)
    outside_before = _files(folder.parent)
    argv = case.build(folder)
    before = _files(folder)
    tmp_root = folder.parent / "_tmp"
    tmp_root.mkdir(exist_ok=True)
    before_tmp = _files(tmp_root)
    err, out = io.StringIO(), io.StringIO()
    status: int | None = None
    problems: list[str] = []
    saved = tempfile.tempdir
    tempfile.tempdir = str(tmp_root)
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
            status = main(argv)
    except SystemExit as exc:  # argparse in older versions
        status = exc.code if isinstance(exc.code, int) else 2
    except BaseException as exc:  # noqa: BLE001 - a traceback is the finding
        problems.append(f"exception {type(exc).__name__}: {str(exc)[:200]}")
    finally:
        tempfile.tempdir = saved
    text = err.getvalue()
    if status is not None and status not in case.ok:
        problems.append(f"exit status {status}, expected {case.ok}")
    if "Traceback" in text:
        problems.append("traceback on stderr")
    if len(text.strip().splitlines()) > 4:
        problems.append(f"{len(text.strip().splitlines())} lines on stderr")
    if status == 2:
        for name in case.names:
            if name not in text:
                problems.append(f"message does not name {name!r}")
    new = _files(folder) - before
    allowed = set(case.keep) if status == 0 else set()
    stray = {f for f in new if f not in allowed and not any(f.startswith(a + "/")
                                                            for a in allowed)}
    if stray:
        problems.append(f"left behind: {sorted(stray)[:5]}")
    escaped = _files(folder.parent) - outside_before - {folder.name, "_tmp"} - \
        {f for f in _files(folder.parent) if f.startswith((folder.name + "/", "_tmp"))}
    if escaped:
        problems.append(f"written outside its folder: {sorted(escaped)[:5]}")
    for pattern in case.absent:
        hits = list(Path("/").glob(pattern.lstrip("/")))
        if hits:
            problems.append(f"written outside its folder: {hits[:3]}")
            for h in hits:
                h.unlink()
    if _files(tmp_root) - before_tmp:
        problems.append(f"left in the temp dir: {sorted(_files(tmp_root) - before_tmp)[:5]}")
    return Outcome(status, text, problems)


# ---- result files ---------------------------------------------------------------------------
def good_result_arrays(n: int = 50) -> dict[str, np.ndarray]:
    """Channels the viewer draws, consistent with a short free spin (with its scene)."""
    t = np.linspace(0.0, 1.0, n)
    r = 0.075 + 0.01 * t
    return {"t": t, "radius": r, "z": 0.5 + r, "roll_angle": 100.0 * t,
            "roll_speed": np.full(n, 100.0), "drum_speed": np.zeros(n),
            "drum_angle": np.zeros(n)}


def scene_dict() -> dict:
    import winder

    return winder.scene_from_dict(
        __import__("tomllib").loads(FREE_SPIN)).to_dict()


def write_npz(path: Path, arrays: dict[str, np.ndarray], meta: object = "scene") -> Path:
    import json

    if meta == "scene":
        meta = {"scene": "free_spin", "scene_dict": scene_dict()}
    extra = {} if meta is None else {"__meta__": np.array(
        meta if isinstance(meta, str) else json.dumps(meta))}
    with open(path, "wb") as fh:
        np.savez_compressed(fh, **arrays, **extra)
    return path


def _result_cases() -> list[Case]:
    cases: list[Case] = []

    def view(label: str, make: Callable[[Path], Path]) -> None:
        def build(d: Path) -> list[str]:
            src = make(d)
            return ["view", str(src), "--html", str(d / "out" / "a.html")]
        cases.append(Case("result file", label, build, names=("src.",)))

    def good(d: Path) -> Path:
        return write_npz(d / "src.npz", good_result_arrays())

    def raw(data: bytes, suffix: str = ".npz") -> Callable[[Path], Path]:
        def make(d: Path) -> Path:
            (d / f"src{suffix}").write_bytes(data)
            return d / f"src{suffix}"
        return make

    view("empty npz", raw(b""))
    view("junk npz", raw(b"hello, this is not a zip file\n" * 20))
    view("random bytes npz", raw(np.random.default_rng(1).bytes(3000)))
    view("pickled object as npz", raw(pickle.dumps({"t": [0, 1], "radius": [1, 2]})))
    view("pickled numpy array as npz", raw(pickle.dumps(np.arange(5.0))))
    view("npy given as npz", lambda d: (np.save(d / "x.npy", np.arange(3.0)),
                                        (d / "x.npy").rename(d / "src.npz"), d / "src.npz")[-1])

    def object_member(d: Path) -> Path:
        arrays = good_result_arrays()
        arrays["radius"] = np.array([object()] * len(arrays["t"]), dtype=object)
        with open(d / "src.npz", "wb") as fh:
            np.savez(fh, **arrays, allow_pickle=True)
        return d / "src.npz"
    view("npz with an object (pickled) member", object_member)
    for frac in (0.1, 0.5, 0.9, 0.99):
        def cut(d: Path, frac: float = frac) -> Path:
            data = good(d).read_bytes()
            (d / "src.npz").write_bytes(data[:int(len(data) * frac)])
            return d / "src.npz"
        view(f"npz truncated at {frac:.0%}", cut)

    def flipped(d: Path) -> Path:
        data = bytearray(good(d).read_bytes())
        data[len(data) // 3] ^= 0xFF
        (d / "src.npz").write_bytes(bytes(data))
        return d / "src.npz"
    view("npz with a flipped byte", flipped)

    def without(channel: str) -> Callable[[Path], Path]:
        def make(d: Path) -> Path:
            a = good_result_arrays()
            del a[channel]
            return write_npz(d / "src.npz", a)
        return make
    for ch in ("t", "radius", "z", "roll_angle"):
        view(f"npz without channel {ch}", without(ch))

    def modified(fn: Callable[[dict], None], meta: object = "scene") -> Callable[[Path], Path]:
        def make(d: Path) -> Path:
            a = good_result_arrays()
            fn(a)
            return write_npz(d / "src.npz", a, meta)
        return make
    view("NaN radius", modified(lambda a: a["radius"].__setitem__(10, np.nan)))
    view("negative radius", modified(lambda a: a["radius"].__setitem__(10, -0.1)))
    view("inf height", modified(lambda a: a["z"].__setitem__(3, np.inf)))
    view("reversed time", modified(lambda a: a.__setitem__("t", a["t"][::-1].copy())))
    view("repeated time", modified(lambda a: a["t"].__setitem__(5, a["t"][4])))
    view("NaN time", modified(lambda a: a["t"].__setitem__(0, np.nan)))
    view("ragged channel", modified(lambda a: a.__setitem__("z", a["z"][:-1])))
    view("2-D channel", modified(lambda a: a.__setitem__("z", np.stack([a["z"], a["z"]]))))
    view("text channel", modified(lambda a: a.__setitem__("z", a["z"].astype(str))))
    view("one sample", modified(lambda a: [a.__setitem__(k, v[:1]) for k, v in a.items()]))
    view("no metadata", modified(lambda a: None, None))
    view("metadata not JSON", modified(lambda a: None, "{not json"))
    view("metadata a JSON list", modified(lambda a: None, [1, 2]))
    view("metadata without scene", modified(lambda a: None, {"scene": "x"}))
    view("stored scene invalid", modified(lambda a: None, {"scene_dict": {"drum": 5}}))
    view("stored scene a string", modified(lambda a: None, {"scene_dict": "drum"}))
    view("missing file", lambda d: d / "src.npz")
    view("directory as result", lambda d: (d / "src.npz").mkdir() or d / "src.npz")
    view("unknown suffix", raw(b"1,2\n", ".txt"))
    view("csv result (no scene)", raw(b"t,radius\n0,1\n1,2\n", ".csv"))
    view("csv junk", raw(b"\xff\xfe\x00junk", ".csv"))

    def zip_with(members: dict[str, bytes]) -> Callable[[Path], Path]:
        def make(d: Path) -> Path:
            with zipfile.ZipFile(d / "src.npz", "w") as zf:
                for k, v in members.items():
                    zf.writestr(k, v)
            return d / "src.npz"
        return make
    view("zip with a text member", zip_with({"readme.txt": b"hello"}))
    view("zip with a junk .npy", zip_with({"t.npy": b"\x93NUMPY junk"}))
    hdr = (b"\x93NUMPY\x01\x00v\x00{'descr': '<f8', 'fortran_order': False, "
           b"'shape': (1000000000000,), }")
    view("npy claiming 10^12 samples", zip_with({"t.npy": hdr.ljust(128, b" ")[:127] + b"\n"}))
    return cases


# ---- options --------------------------------------------------------------------------------
JUNK_NUMBERS = ("0", "-1", "nan", "inf", "-inf", "abc", "", "1e309", "-0", "1e-400", "0x10",
                "1,5", " ")


def _option_cases() -> list[Case]:
    cases: list[Case] = []

    def run_opt(opt: str, value: str) -> Callable[[Path], list[str]]:
        def build(d: Path) -> list[str]:
            return ["run", str(quick_scene(d)), "--out", str(d / "out" / "r.npz"), opt, value]
        return build

    def view_opt(opt: str, value: str) -> Callable[[Path], list[str]]:
        def build(d: Path) -> list[str]:
            src = write_npz(d / "src.npz", good_result_arrays())
            extra = ["--snapshots", str(d / "out")] if opt == "--every" else \
                ["--html", str(d / "out" / "a.html")]
            return ["view", str(src), opt, value, *extra]
        return build

    def modes_opt(opt: str, value: str) -> Callable[[Path], list[str]]:
        def build(d: Path) -> list[str]:
            return ["modes", str(PAPER), "--points", "5", opt, value]
        return build

    for opt in ("--t-end", "--rtol", "--atol", "--max-step"):
        for v in JUNK_NUMBERS:
            cases.append(Case("option", f"run {opt} {v!r}", run_opt(opt, v), names=(opt,)))
    for v in ("1e300", "0.01", "1"):  # atol beyond 1e-3 [state units] means no error control
        cases.append(Case("option", f"run --atol {v}", run_opt("--atol", v),
                          names=("--atol", "0.001")))
    cases.append(Case("option", "run --rtol 2", run_opt("--rtol", "2"), names=("--rtol",)))
    cases.append(Case("option", "run --rtol 1", run_opt("--rtol", "1"), names=("--rtol",)))
    cases.append(Case("option", "run --method junk", run_opt("--method", "junk"),
                      names=("junk",)))
    cases.append(Case("option", "run --backend junk", run_opt("--backend", "junk"),
                      names=("junk",)))
    for opt in ("--every", "--playback"):
        for v in JUNK_NUMBERS:
            cases.append(Case("option", f"view {opt} {v!r}", view_opt(opt, v), names=(opt,)))
    cases.append(Case("option", "view --playback 1e9", view_opt("--playback", "1e9"),
                      names=("--playback",)))
    cases.append(Case("option", "view --every 1e-9", view_opt("--every", "1e-9"),
                      names=("--every",)))

    def scene_every(d: Path) -> list[str]:  # refused before the scene is simulated
        return ["view", str(quick_scene(d)), "--snapshots", str(d / "out"), "--every", "1e-4"]
    cases.append(Case("option", "view scene.toml --every 1e-4", scene_every,
                      names=("--every", "5001 snapshots")))
    for opt in ("--points", "--web-speed"):
        for v in (*JUNK_NUMBERS, "-5", "2.5", "1e12"):
            if opt == "--web-speed" and v == "1e12":
                continue
            sane = opt == "--web-speed" and v == "2.5"
            cases.append(Case("option", f"modes {opt} {v!r}", modes_opt(opt, v),
                              ok=(0,) if sane else (2,), names=(opt,)))
    return cases


def new_option_cases() -> list[Case]:
    """Options new with the budgets (not in the earlier command line)."""
    cases: list[Case] = []
    for opt in ("--max-evals", "--max-wall"):
        for v in (*JUNK_NUMBERS, "2.5" if opt == "--max-evals" else "-3"):
            def build(d: Path, opt: str = opt, v: str = v) -> list[str]:
                return ["run", str(quick_scene(d)), "--out", str(d / "out" / "r.npz"), opt, v]
            cases.append(Case("new option", f"run {opt} {v!r}", build, names=(opt,)))
    # the map's radius range (issue #21): below the core, beyond 10 m, an empty range
    for opt in ("--radius-min", "--radius-max"):
        for v in (*JUNK_NUMBERS, "-5", "0.05", "1e12", "0.3"):
            def modes(d: Path, opt: str = opt, v: str = v) -> list[str]:
                return ["modes", str(PAPER), "--points", "3", "--csv", str(d / "m.csv"), opt, v]
            sane = v == "0.3"
            cases.append(Case("new option", f"modes {opt} {v!r}", modes, ok=(0,) if sane else (2,),
                              names=() if sane else (opt,), keep=("m.csv",) if sane else ()))
    for lo, hi in (("0.4", "0.3"), ("0.3", "0.3"), ("0.9", None)):
        def empty(d: Path, lo: str = lo, hi: str | None = hi) -> list[str]:
            return ["modes", str(PAPER), "--points", "3", "--csv", str(d / "m.csv"),
                    "--radius-min", lo, *(("--radius-max", hi) if hi else ())]
        cases.append(Case("new option", f"modes --radius-min {lo} --radius-max {hi}", empty,
                          names=("--radius-max",) if hi else ("--radius-min", "--radius-max")))
    return cases


# ---- output locations -----------------------------------------------------------------------
def _output_cases() -> list[Case]:
    cases: list[Case] = []
    long_name = "x" * 300

    def bad_paths(d: Path) -> dict[str, str]:
        (d / "file").write_text("a file\n")
        (d / "adir.csv").mkdir()
        (d / "adir.png").mkdir()
        (d / "adir.html").mkdir()
        (d / "adir.fmu").mkdir()
        os.mkfifo(d / "fifo.csv")
        return {"proc": "/proc/winder-test/x", "file-parent": str(d / "file" / "x"),
                "long": str(d / long_name), "long-dir": str(d / long_name / "x"),
                "nul": str(d / "a\0b"), "empty": ""}

    kinds = ("proc", "file-parent", "long", "long-dir", "nul", "empty")

    def add(cmd: str, arg: str, suffix: str, make_argv: Callable[[Path, str], list[str]],
            *, directory: bool = False) -> None:
        for kind in (*kinds, *(() if directory else ("existing dir", "fifo"))):
            def build(d: Path, kind: str = kind) -> list[str]:
                paths = bad_paths(d)
                if kind == "existing dir":
                    return make_argv(d, str(d / f"adir{suffix}"))
                if kind == "fifo":
                    return make_argv(d, str(d / "fifo.csv"))
                p = paths[kind]
                return make_argv(d, p + ("" if directory or not p else suffix))
            names = (arg,)
            cases.append(Case("output path", f"{cmd} {arg} {kind}", build, names=names))
        if directory:
            def file_as_dir(d: Path) -> list[str]:
                bad_paths(d)
                return make_argv(d, str(d / "file"))
            cases.append(Case("output path", f"{cmd} {arg} a file", file_as_dir,
                              names=(arg,)))

    def run_out(d: Path, p: str) -> list[str]:
        return ["run", str(quick_scene(d)), "--out", p]

    def run_plots(d: Path, p: str) -> list[str]:
        return ["run", str(quick_scene(d)), "--out", str(d / "out" / "r.npz"), "--plots", p]

    def view_html(d: Path, p: str) -> list[str]:
        return ["view", str(write_npz(d / "src.npz", good_result_arrays())), "--html", p]

    def view_snaps(d: Path, p: str) -> list[str]:
        return ["view", str(write_npz(d / "src.npz", good_result_arrays())), "--snapshots", p]

    def modes_csv(d: Path, p: str) -> list[str]:
        return ["modes", str(PAPER), "--points", "5", "--csv", p]

    def modes_plot(d: Path, p: str) -> list[str]:
        return ["modes", str(PAPER), "--points", "5", "--no-simulate", "--plot", p]

    def fmu_out(d: Path, p: str) -> list[str]:
        return ["fmu", str(quick_scene(d)), "--no-check", "-o", p]

    add("run", "--out", ".csv", run_out)
    add("run", "--plots", "", run_plots, directory=True)
    add("view", "--html", ".html", view_html)
    add("view", "--snapshots", "", view_snaps, directory=True)
    add("modes", "--csv", ".csv", modes_csv)
    add("modes", "--plot", ".png", modes_plot)
    add("fmu", "-o", ".fmu", fmu_out)

    def long_ok(d: Path) -> list[str]:
        return ["run", str(quick_scene(d)), "--out", str(d / ("y" * 246 + ".csv"))]
    cases.append(Case("output path", "run --out 250-character name", long_ok, ok=(0,),
                      keep=("y" * 246 + ".csv", "y" * 246 + ".npz")))
    return cases


# ---- scene names in file names --------------------------------------------------------------
SCENE_NAMES = ("../escaped", "../../escaped2", "/tmp/winder-abs-escape", "a/b", "a\\b",
               "a\0b", "..", ".", "", "x" * 300, "$\\frac{", "é/ü", "-rf", ".hidden",
               "con", "a\nb", "~/home", "${HOME}")


def _name_cases() -> list[Case]:
    cases = []
    for name in SCENE_NAMES:
        def build(d: Path, name: str = name) -> list[str]:
            (d / "plots").mkdir()
            return ["run", str(quick_scene(d, name)), "--out", str(d / "r.npz"),
                    "--plots", str(d / "plots")]
        cases.append(Case("scene name", f"name {name[:20]!r}", build, ok=(0, 2),
                          keep=("r.npz", "plots"), absent=("/tmp/winder-abs-escape*",)))
    return cases


# ---- sweep keys (tied keys share one axis) ----------------------------------------------------
TWO_DRUM = ROOT / "models" / "two_drum_winder.toml"
_SPEED = "drum.front.drive.web_speed,drum.rear.drive.web_speed"

#: label → (scene, --vary options, what the message names); every one is refused before a
#: cluster starts or anything is written
SWEEP_VARY = {
    "tied: unknown element": (TWO_DRUM, ["drum.front.drive.web_speed,drum.middle.drive."
                                         "web_speed=10:30:5"], ("drum.middle", "front, rear")),
    "tied: empty key": (TWO_DRUM, ["drum.front.drive.web_speed,=10:30:5"], ("empty key",)),
    "tied: trailing comma": (TWO_DRUM, [_SPEED + ",=10:30:5"], ("empty key",)),
    "tied: a key twice": (TWO_DRUM, ["drum.front.drive.web_speed,drum.front.drive.web_speed"
                                     "=10:30:5"], ("drum.front.drive.web_speed", "twice")),
    "tied and alone": (TWO_DRUM, [_SPEED + "=10:30:5", "drum.rear.drive.web_speed=10,20"],
                       ("drum.rear.drive.web_speed", "twice")),
    "tied: bounds of one key": (TWO_DRUM, ["drum.front.drive.web_speed,roll.set.com_offset="
                                           "10:30:5"], ("com_offset", "10")),
    "tied: beyond both bounds": (TWO_DRUM, [_SPEED + "=10:2000:2"], ("web_speed", "2000")),
    "tied: no spec": (TWO_DRUM, [_SPEED], ("KEY=SPEC",)),
    "tied: no key": (TWO_DRUM, ["=10:30:5"], ("KEY=SPEC",)),
    "tied: half a range": (TWO_DRUM, [_SPEED + "=10:30"], ("START:STOP:COUNT",)),
    "tied: empty range": (TWO_DRUM, [_SPEED + "=10:30:0"], ("empty range",)),
    "tied: a table": (TWO_DRUM, ["drum.front.drive,drum.rear.drive=1,2"],
                      ("drum.front.drive", "table")),
    "tied: parts keys on a single-drum scene": (PAPER, [_SPEED + "=10:30:5"],
                                                ("drum.front.drive.web_speed", "drive")),
    "tied: a word for a number": (PAPER, ["drum.drive.web_speed,drum.drive.web_acceleration"
                                          "=fast,slow"], ("web_speed", "fast")),
    "tied: words on the map's axis": (TWO_DRUM, ["nip.front.contact.law,nip.rear.contact.law="
                                                 "linear,hunt_crossley", "--plot"],
                                      ("--plot", "hunt_crossley")),
}


def _sweep_cases() -> list[Case]:
    cases = []
    for label, (scene, vary, names) in SWEEP_VARY.items():
        def build(d: Path, scene: Path = scene, vary: list[str] = vary) -> list[str]:
            argv = ["sweep", str(scene), "--out", str(d / "sweep"), "--no-progress"]
            for item in vary:
                argv += ["--plot"] if item == "--plot" else ["--vary", item]
            return argv
        cases.append(Case("sweep key", label, build, names=names))
    return cases


def corpus() -> list[Case]:
    """Every case (categories: option, output path, scene name, result file, sweep key)."""
    return [*_option_cases(), *_output_cases(), *_name_cases(), *_result_cases(),
            *_sweep_cases()]
