"""The package as a user imports it: the public names, lazy imports, and compiled kernels
where numba can write no cache."""

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
    """``import winder`` alone imports neither numba, scipy nor pinocchio: a command pays
    only for what it uses."""
    code = ("import sys, winder; print(sorted({m.split('.')[0] for m in sys.modules} & "
            "{'numba', 'scipy', 'pinocchio', 'matplotlib', 'meshcat', 'pythonfmu'}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"


_RUN = """
import json, sys, warnings
warnings.simplefilter("always")
with warnings.catch_warnings(record=True) as caught:
    import winder
    scene = winder.load_scene(sys.argv[1])
    res = winder.simulate(scene, t_end=20.0, output_step=5.0)
print(json.dumps({"warnings": [f"{w.category.__name__}: {w.message}" for w in caught],
                  "roll_speed": res["roll_speed"].tolist(), "radius": res["radius"].tolist()}))
"""


def test_no_writable_numba_cache_falls_back_to_memory(tmp_path: Path, models_dir: Path) -> None:
    """Where numba finds no cache location (read-only package, no home directory), winder
    still imports and runs — compiled in memory, with one warning — and gives the same
    numbers as the cached kernels."""
    (tmp_path / "nolocator.py").write_text(
        "class Never:\n"
        "    @classmethod\n"
        "    def from_function(cls, py_func, py_file):\n"
        "        return None\n")
    env = {**os.environ, "NUMBA_CACHE_LOCATOR_CLASSES": "nolocator.Never",
           "PYTHONPATH": os.pathsep.join(filter(None, [str(tmp_path),
                                                       os.environ.get("PYTHONPATH")]))}
    scene = models_dir / "free_spin.toml"
    proc = subprocess.run([sys.executable, "-c", _RUN, str(scene)], capture_output=True,
                          text=True, env=env, timeout=300)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    fallback = [w for w in out["warnings"] if w.startswith("CacheFallbackWarning")]
    assert len(fallback) == 1 and "NUMBA_CACHE_DIR" in fallback[0]
    ref = winder.simulate(winder.load_scene(scene), t_end=20.0, output_step=5.0)
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
