"""The package as a user imports it: the public names, lazy imports, and the compiled
machine built into a fresh cache."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

import winder


def test_every_public_name_resolves() -> None:
    for name in winder.__all__:
        assert getattr(winder, name) is not None, name
    assert set(winder.__all__) <= set(dir(winder))


def test_import_winder_loads_no_heavy_dependency() -> None:
    """``import winder`` alone imports neither scipy nor pinocchio: a command pays only for
    what it uses."""
    code = ("import sys, winder; print(sorted({m.split('.')[0] for m in sys.modules} & "
            "{'scipy', 'pinocchio', 'matplotlib', 'meshcat', 'fmpy'}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"


#: What checking a scene must not import: the solver stack, the plots, the sweeps and
#: NumPy itself (the scene's checks are plain arithmetic).
_SOLVER_STACK = {"numpy", "scipy", "casadi", "pinocchio", "coal",
                 "matplotlib", "dask", "pandas", "pyarrow", "tqdm", "meshcat", "fmpy"}

_CHECK = """
import json, sys
import winder.cli, winder
for path in sys.argv[1:]:
    winder.load_scene(path)
print(json.dumps(sorted({m.split('.')[0] for m in sys.modules})))
"""


def test_checking_a_scene_imports_no_solver_stack(models_dir: Path) -> None:
    """``import winder.cli`` and :func:`winder.load_scene` of every shipped scene import
    none of the solver stack (start-up: a command that stops on its scene stops fast)."""
    scenes = sorted(str(p) for p in models_dir.glob("*.toml"))
    assert len(scenes) >= 5
    out = subprocess.run([sys.executable, "-c", _CHECK, *scenes], capture_output=True,
                         text=True, check=True).stdout
    assert set(json.loads(out)) & _SOLVER_STACK == set()


_BAD_RUN = """
import json, sys
import winder.cli
status = winder.cli.main(["run", sys.argv[1], "--out", sys.argv[2]])
print(json.dumps([status, sorted({m.split('.')[0] for m in sys.modules})]))
"""


def test_run_on_a_bad_scene_exits_2_before_the_solver_is_imported(tmp_path: Path,
                                                                   models_dir: Path) -> None:
    """``winder run`` on a scene that fails its checks exits 2 having imported none of
    the solver stack."""
    text = (models_dir / "paper_winding.toml").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("[paper]", "[paper]\nno_such_key = 1", 1))
    assert bad.read_text() != text
    proc = subprocess.run([sys.executable, "-c", _BAD_RUN, str(bad), str(tmp_path / "r.npz")],
                          capture_output=True, text=True, check=True)
    status, modules = json.loads(proc.stdout)
    assert status == 2 and "no_such_key" in proc.stderr
    assert set(modules) & _SOLVER_STACK == set()
    assert not (tmp_path / "r.npz").exists()



_RUN = """
import json, sys
import winder
from winder.model import codegen
scene = winder.load_scene(sys.argv[1])
res = winder.simulate(scene, t_end=20.0, output_step=5.0)
print(json.dumps({"stats": codegen.stats, "modules": sorted({m.split('.')[0] for m in sys.modules}),
                  "roll_speed": res["roll_speed"].tolist(), "radius": res["radius"].tolist()}))
"""


def test_a_fresh_cache_builds_the_machine_once(tmp_path: Path, models_dir: Path) -> None:
    """In an empty cache the integrators and the machine are compiled and linked into one
    library; a second process loads it and compiles nothing; both give the numbers of
    this process's machine, and neither imports numba or llvmlite (issue #23)."""
    env = {**os.environ, "WINDER_CACHE_DIR": str(tmp_path / "cache")}
    scene = models_dir / "free_spin.toml"
    runs = []
    for _ in range(2):
        proc = subprocess.run([sys.executable, "-c", _RUN, str(scene)], capture_output=True,
                              text=True, env=env, timeout=600)
        assert proc.returncode == 0, proc.stderr
        runs.append(json.loads(proc.stdout.strip().splitlines()[-1]))
    # an explicit run (auto: DOPRI5 on a short probe) builds no Jacobian (issue #33)
    assert runs[0]["stats"] == {"compiled": 1, "linked": 0, "cached": 0, "jacobians": 0}
    assert runs[1]["stats"] == {"compiled": 0, "linked": 0, "cached": 1, "jacobians": 0}
    libs = list((tmp_path / "cache" / "generated").glob("*.so"))
    from winder.solve.cint import SOURCES

    objects = {p.name for p in (tmp_path / "cache" / "integrators").glob("*/*.o")}
    assert len(libs) == 1 and objects == {f"{Path(s).stem}.o" for s in SOURCES}
    ref = winder.simulate(winder.load_scene(scene), t_end=20.0, output_step=5.0)
    for out in runs:
        assert not {"numba", "llvmlite"} & set(out["modules"])
        np.testing.assert_array_equal(out["roll_speed"], ref["roll_speed"])
        np.testing.assert_array_equal(out["radius"], ref["radius"])


def test_every_exception_of_the_package_is_a_winder_error() -> None:
    """Every public exception class the package defines is in the :class:`winder.WinderError`
    tree (warnings and the signal's ``KeyboardInterrupt`` aside), and it raises no bare
    ``RuntimeError``/``Exception`` (an AST scan of src/ and
    viewer/: a new ``class FooError(ValueError)`` or ``raise RuntimeError(...)`` fails
    here)."""
    import ast
    import importlib

    root = Path(__file__).resolve().parents[1]
    bare = {"RuntimeError", "Exception"}
    outside = []
    for path in [*(root / "src" / "winder").rglob("*.py"), *(root / "viewer").glob("*.py")]:
        tree = ast.parse(path.read_text(), str(path))
        rel = path.relative_to(root)
        parts = rel.with_suffix("").parts
        module = ".".join(("winder", "viewer", *parts[1:]) if parts[0] == "viewer"
                          else parts[1:])
        for node in ast.walk(tree):
            if isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call) and \
                    isinstance(node.exc.func, ast.Name) and node.exc.func.id in bare:
                outside.append(f"{rel}:{node.lineno} raises {node.exc.func.id}")
            if isinstance(node, ast.ClassDef) and not node.name.startswith("_") and \
                    node.col_offset == 0:
                cls = getattr(importlib.import_module(module.removesuffix(".__init__")),
                              node.name, None)
                if isinstance(cls, type) and issubclass(cls, Exception) and \
                        not issubclass(cls, Warning | winder.WinderError):
                    outside.append(f"{rel}:{node.lineno} class {node.name}")
    assert not outside, outside


# ---- layout: layers, cycles, module sizes ---------------------------------------------------
ROOT = Path(__file__).resolve().parents[1]
#: Longest module [lines], and the modules over it until their split lands (one each).
MAX_LINES = 600


def _modules() -> dict[str, Path]:
    """Every module of the package by dotted name (viewer/ is ``winder.viewer``)."""
    mods = {}
    for path in [*(ROOT / "src" / "winder").rglob("*.py"), *(ROOT / "viewer").glob("*.py")]:
        parts = path.relative_to(ROOT).with_suffix("").parts
        parts = ("winder", "viewer", *parts[1:]) if parts[0] == "viewer" else parts[1:]
        mods[".".join(parts).removesuffix(".__init__")] = path
    return mods


def _imports(name: str, path: Path, known: set[str]) -> set[str]:
    """The package modules ``name`` imports, anywhere in its file (in functions too)."""
    import ast

    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join([*up, *([base] if base else [])])
            targets = [f"{base}.{a.name}" for a in node.names] + [base]
        else:
            continue
        for t in targets:
            while t and t not in known:
                t = t.rpartition(".")[0]
            if t and t != name and (t != "winder" or targets == ["winder"]):
                found.add(t)
                break
    return found


def _contract() -> tuple[list[set[str]], set[tuple[str, str]]]:
    """The layers (top first, each a set of packages) and ignored imports of pyproject's
    import-linter contract."""
    import tomllib

    data = tomllib.loads((ROOT / "pyproject.toml").read_text())
    (contract,) = data["tool"]["importlinter"]["contracts"]
    layers = [{p.strip() for p in layer.split("|")} for layer in contract["layers"]]
    layers[[i for i, la in enumerate(layers) if "winder.fmu" in la][0]].add("winder.viewer")
    ignored = {tuple(s.strip() for s in i.split("->")) for i in contract.get("ignore_imports", ())}
    return layers, ignored


def _rank(module: str, layers: list[set[str]]) -> int | None:
    for i, layer in enumerate(layers):
        if any(module == p or module.startswith(p + ".") for p in layer):
            return i
    return None


def test_imports_point_down_the_layers_and_never_in_a_circle() -> None:
    """An AST scan (imports inside functions included), independent of import-linter: no
    module imports a layer above its own or a sibling of its layer (``winder.viewer``
    included, which import-linter cannot see), only the contract's ignored imports
    excepted, and the import graph of the package's modules has no cycle (the scan finds
    a planted upward import and a planted cycle)."""
    layers, ignored = _contract()
    mods = _modules()
    graph = {m: _imports(m, p, set(mods)) for m, p in mods.items()}

    def upward(g: dict[str, set[str]]) -> list[str]:
        bad = []
        for m, deps in g.items():
            rm = _rank(m, layers)
            for d in deps:
                rd = _rank(d, layers)
                if rm is None or rd is None or (m, d) in ignored:
                    continue
                top = lambda x: ".".join(x.split(".")[:2])  # noqa: E731
                if rd < rm or (rd == rm and top(d) != top(m)):
                    bad.append(f"{m} -> {d}")
        return bad

    def cycle(g: dict[str, set[str]]) -> list[str] | None:
        colour: dict[str, int] = {}
        stack: list[str] = []

        def visit(m: str) -> list[str] | None:
            colour[m] = 1
            stack.append(m)
            for d in sorted(g.get(m, ())):
                if (m, d) in ignored or d == "winder":
                    continue
                if colour.get(d) == 1:
                    return [*stack[stack.index(d):], d]
                if d not in colour and (found := visit(d)):
                    return found
            stack.pop()
            colour[m] = 2
            return None

        for m in sorted(g):
            if m not in colour and (found := visit(m)):
                return found
        return None

    assert upward(graph) == []
    assert cycle(graph) is None
    # every module is in a layer (the package's entry points aside)
    assert [m for m in mods if _rank(m, layers) is None
            and m not in ("winder", "winder.__main__")] == []
    assert _rank("winder._schema", layers) == _rank("winder._args", layers)
    # the oracle sees what it must: an upward import, a sibling import and a cycle
    planted = {**graph, "winder.io.files": graph["winder.io.files"] | {"winder.solve.simulate"},
               "winder.viewer._motion": graph["winder.viewer._motion"] | {"winder.fmu.parameters"}}
    assert upward(planted) == ["winder.io.files -> winder.solve.simulate",
                               "winder.viewer._motion -> winder.fmu.parameters"]
    looped = {**graph, "winder.solve.budgets": graph["winder.solve.budgets"]
              | {"winder.solve.simulate"}}
    assert cycle(looped) is not None and "winder.solve.budgets" in cycle(looped)
    assert "winder.solve.simulate" in graph["winder.solve.stepper"]  # the scan reads imports
    assert "winder.solve.simulate" in graph["winder.cli"]  # ... inside functions too


def test_no_module_is_over_600_lines() -> None:
    """One concept per module: every module of src/winder and viewer/ has at most 600
    lines."""
    sizes = {str(p.relative_to(ROOT)): len(p.read_text().splitlines())
             for p in _modules().values()}
    assert len(sizes) > 60 and sizes["src/winder/solve/simulate.py"] > 100
    over = {p: n for p, n in sizes.items() if n > MAX_LINES}
    assert over == {}


def test_no_lower_module_imports_the_package_root() -> None:
    """No module of a layer (``src/winder/*/``) nor of ``viewer/`` imports ``winder``
    itself (``from winder import X``, ``import winder``): the root re-exports every layer,
    so such an import points up past every layer and neither import-linter nor the scan
    above sees through it."""
    import re

    pattern = re.compile(r"^\s*(from\s+winder\s+import\b|import\s+winder\s*(#.*)?$)")
    assert pattern.match("    from winder import simulate") and pattern.match("import winder")
    assert not pattern.match("from winder.scene import Scene")
    files = [*(p for p in (ROOT / "src" / "winder").rglob("*.py")
               if p.parent != ROOT / "src" / "winder"), *(ROOT / "viewer").glob("*.py")]
    assert len(files) > 50
    hits = [f"{p.relative_to(ROOT)}:{i}" for p in files
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
            if pattern.match(line)]
    assert hits == []


def test_tests_mirror_the_package() -> None:
    """Each layer package of src/winder (and viewer/) has its test folder tests/NAME, and
    every test folder is such a package (the whole-package tests stay in tests/)."""
    packages = {p.name for p in (ROOT / "src" / "winder").iterdir()
                if p.is_dir() and (p / "__init__.py").exists()} | {"viewer", "cli"}
    folders = {p.name for p in (ROOT / "tests").iterdir()
               if p.is_dir() and any(p.glob("test_*.py"))}
    assert folders == packages
