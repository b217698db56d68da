"""The scene contract under bad input: every key of every shipped scene set missing, of
the wrong type, NaN, ±inf, zero, negative, huge or too long either gives a SceneError that
names the file and the key, or a scene that loads and runs sanely for a moment (finite
state and channels, the roll axis above the drum, positive mass and inertia), or a clean
winder error from the run itself. Nothing else: no other exception, no impossible answer.

``python tests/scene/test_scene_contract.py`` runs the whole corpus (every scene, key and
category) and prints how many cases end cleanly per category.
"""

from __future__ import annotations

import math
import sys
import tomllib
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import winder
from winder.scene.legacy import LEGACY_TABLES

MODELS = Path(__file__).resolve().parents[2] / "models"
#: The shipped scenes in the single-drum format (the keys below are its tables).
SCENES = sorted(p for p in MODELS.glob("*.toml")
                if isinstance(tomllib.loads(p.read_text("utf-8")).get("drum"), dict))
CATEGORIES = ("missing", "wrong_type", "nan", "inf", "-inf", "zero", "negative", "huge",
              "too_long")
#: (table, key, kind) of every scene key; kind "num", "bool" or "str".
KEYS = tuple((table, key.name, key.kind) for table, keys in LEGACY_TABLES.items()
             for key in keys)
LONG = 100_000  # characters of a "too long" string
T_SHORT = 2e-3  # [s] the short run of a scene that loads


def _load(path: Path) -> dict[str, Any]:
    return tomllib.loads(path.read_text(encoding="utf-8"))


def _table(data: dict[str, Any], table: str) -> dict[str, Any]:
    if table == "drum.drive":
        return data.setdefault("drum", {}).setdefault("drive", {})
    return data.setdefault(table, {})


def corpus_value(category: str, kind: str, original: Any) -> Any:
    """The deterministic bad value of a category for a key of ``kind``."""
    if category == "missing":
        return None
    base = abs(float(original)) if kind == "num" and original is not None else 1.0
    return {"wrong_type": {"num": "1.0", "bool": 1, "str": 1}[kind],
            "nan": math.nan, "inf": math.inf, "-inf": -math.inf,
            "zero": {"num": 0.0, "bool": 0, "str": ""}[kind],
            "negative": {"num": -(base or 1.0), "bool": -1, "str": "-"}[kind],
            "huge": 1e300, "too_long": "x" * LONG}[category]


def mutate(path: Path, table: str, key: str, category: str, value: Any = None) -> dict:
    """The shipped scene ``path`` with ``[table] key`` set to ``value`` (deleted for the
    category ``missing``)."""
    data = _load(path)
    t = _table(data, table)
    if category == "missing":
        t.pop(key, None)
    else:
        t[key] = value
    return data


def outcome(path: Path, data: dict, keys: list[str]) -> str:
    """How a mutated scene ends: ``scene_error`` (naming the file and one of the changed
    ``keys``), ``runs`` (loads and runs sanely), ``run_error`` (loads; the short run stops
    with a clean winder error), or ``bad: ...`` (anything else, with the reason)."""
    try:
        scene = winder.scene_from_dict(data, source=str(path))
    except winder.SceneError as exc:
        msg = str(exc)
        if not any(k in msg for k in keys) or str(path) not in msg:
            return f"bad: SceneError not naming file and key: {msg[:200]}"
        if len(msg) > 2000:
            return f"bad: SceneError of {len(msg)} characters"
        return "scene_error"
    except Exception as exc:  # noqa: BLE001 - the contract forbids any other error
        return f"bad: {type(exc).__name__} while loading: {str(exc)[:200]}"
    try:
        from winder.solve.equilibrium import static_state

        machine = winder.Machine(scene)
        y0 = static_state(machine).state
    except winder.WinderError as exc:
        return f"bad: {type(exc).__name__} building the system: {str(exc)[:200]}"
    except Exception as exc:  # noqa: BLE001
        return f"bad: {type(exc).__name__} building the system: {str(exc)[:200]}"
    if not np.all(np.isfinite(y0)):
        return f"bad: non-finite initial state {y0}"
    z = y0[machine.index("roll.z")]
    if z <= scene.drum.radius:
        return f"bad: roll axis at z = {z!r} m inside the drum (R = {scene.drum.radius})"
    try:
        res = winder.simulate(scene, t_end=T_SHORT, output_step=T_SHORT / 2, max_rhs=20_000,
                              max_wall=120.0)
    except winder.WinderError as exc:
        if not str(exc).strip():
            return f"bad: empty {type(exc).__name__}"
        return "run_error"
    except Exception as exc:  # noqa: BLE001
        return f"bad: {type(exc).__name__} in the run: {str(exc)[:200]}"
    for name in winder.CHANNELS:
        if not np.all(np.isfinite(res[name])):
            return f"bad: non-finite channel {name}"
    if not (np.all(res["mass"] > 0) and np.all(res["inertia"] > 0)):
        return "bad: non-positive mass or inertia"
    return "runs"


def run_corpus(scenes=SCENES, categories=CATEGORIES) -> dict[str, Counter]:
    """Every (scene, key, category) of the deterministic corpus; outcomes per category."""
    counts: dict[str, Counter] = {c: Counter() for c in categories}
    for path in scenes:
        base = _load(path)
        for table, key, kind in KEYS:
            original = _table(base, table).get(key)
            for cat in categories:
                data = mutate(path, table, key, cat, corpus_value(cat, kind, original))
                res = outcome(path, data, [key])
                counts[cat][res.split(":")[0]] += 1
                if res.startswith("bad"):
                    print(f"{path.name} [{table}] {key} {cat}: {res}", file=sys.stderr)
    return counts


# ---- Hypothesis: random bad values on random keys of the shipped scenes ---------------

_WRONG = {"num": st.one_of(st.text(max_size=8), st.booleans(), st.lists(st.integers(),
                                                                        max_size=2),
                           st.dictionaries(st.text(max_size=3), st.integers(), max_size=1)),
          "bool": st.one_of(st.integers(), st.floats(), st.text(max_size=8),
                            st.lists(st.booleans(), max_size=2)),
          "str": st.one_of(st.integers(), st.floats(), st.booleans(),
                           st.lists(st.text(max_size=3), max_size=2))}


def _values(category: str, kind: str) -> st.SearchStrategy:
    if category == "missing":
        return st.none()
    if category == "wrong_type":
        return _WRONG[kind]
    if category == "too_long":
        return st.sampled_from("x/é\x00 ").map(lambda c: c * LONG)
    return {"nan": st.just(math.nan), "inf": st.just(math.inf), "-inf": st.just(-math.inf),
            "zero": st.sampled_from([0, 0.0, -0.0]),
            "negative": st.one_of(st.floats(max_value=-1e-300, allow_infinity=False,
                                            allow_nan=False), st.integers(max_value=-1)),
            "huge": st.one_of(st.floats(min_value=1e15, max_value=1e308),
                              st.floats(min_value=-1e308, max_value=-1e15),
                              st.integers(min_value=10**15, max_value=10**400))}[category]


@st.composite
def _cases(draw) -> tuple[Path, str, str, str, Any]:
    path = draw(st.sampled_from(SCENES))
    table, key, kind = draw(st.sampled_from(KEYS))
    category = draw(st.sampled_from(CATEGORIES))
    return path, table, key, category, draw(_values(category, kind))


@settings(max_examples=250, deadline=None, database=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(case=_cases())
def test_bad_scene_key_gives_clean_error_or_sane_run(case) -> None:
    path, table, key, category, value = case
    data = mutate(path, table, key, category, value)
    res = outcome(path, data, [key])
    assert not res.startswith("bad"), f"{path.name} [{table}] {key} = {category}: {res}"


def _in_range(table: str, key: str) -> st.SearchStrategy:
    """Any value a scene accepts for ``[table] key`` on its own (log-uniform in its range)."""
    spec = LEGACY_TABLES[table][key]
    if spec.kind == "bool":
        return st.booleans()
    if spec.kind == "str":
        return st.sampled_from(spec.choices or ("a scene",))
    hi = spec.hi if spec.hi is not None else 1e3
    lo = spec.lo
    exp = st.floats(min_value=math.log10(max(lo or 0.0, 1e-9 * hi)), max_value=math.log10(hi))
    if lo is None:
        values = st.tuples(exp, st.sampled_from((-1.0, 1.0))).map(lambda p: p[1] * 10 ** p[0])
    else:
        values = exp.map(lambda x: min(hi, 10**x))
    return values.map(round) if key == "max_rhs" else values


@st.composite
def _combinations(draw) -> tuple[Path, dict, list[str]]:
    path = draw(st.sampled_from(SCENES))
    data = _load(path)
    keys = draw(st.lists(st.sampled_from(KEYS), min_size=2, max_size=4, unique=True))
    for table, key, _ in keys:
        _table(data, table)[key] = draw(_in_range(table, key))
    return path, data, [key for _, key, _ in keys]


@settings(max_examples=150, deadline=None, database=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(case=_combinations())
def test_combinations_of_valid_values_give_clean_error_or_sane_run(case) -> None:
    """Several keys at once, each within its own range: a combination that makes no
    physical sense is refused naming one of the keys; the others run sanely."""
    path, data, keys = case
    res = outcome(path, data, keys)
    assert not res.startswith("bad"), (keys, res)


@pytest.mark.parametrize("category", CATEGORIES)
def test_corpus_on_paper_scene(category) -> None:
    """The deterministic corpus on the paper scene: every key, one category at a time."""
    counts = run_corpus([MODELS / "paper_winding.toml"], [category])[category]
    assert counts["bad"] == 0, counts


if __name__ == "__main__":
    table = run_corpus()
    print(f"{'category':<12}{'cases':>7}{'clean':>7}  (scene_error / runs / run_error / bad)")
    for cat, c in table.items():
        n = sum(c.values())
        print(f"{cat:<12}{n:>7}{n - c['bad']:>7}  ({c['scene_error']} / {c['runs']} / "
              f"{c['run_error']} / {c['bad']})")
    total = sum(sum(c.values()) for c in table.values())
    bad = sum(c["bad"] for c in table.values())
    print(f"{'total':<12}{total:>7}{total - bad:>7}")
