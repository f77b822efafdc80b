"""Documents built from the documented keys, for the generated-input tests: the shipped
scenarios and studies (every key they use, [[robots]] entries' too), the tables the docs show
(sensors.md's cameras and sonars), the documented keys and tables no shipped scenario
uses (`UNSHIPPED_KEYS`, `UNSHIPPED_TABLES`) and one ``[[world.objects]]`` of every
registered kind and a fixture, mutated by a few edits each
(a value of any type, size and sign, NaN and infinities; a key removed or added; a table
grafted from another document; a list resized; an element of an array of tables twice).

The strategies edit plain dicts (cheap): nothing heavy is built to draw an input."""

from __future__ import annotations

import copy
import datetime
import json
import math
import re
import tomllib
from pathlib import Path
from typing import Any

from fuzz_bounds import ROOT
from hypothesis import strategies as st

from uvms_pin.physics.world.objects import registered_kinds
from uvms_pin.scenario.robots import ROBOT_TABLES


def _toml_blocks(doc: Path) -> list[dict[str, Any]]:
    return [tomllib.loads(b) for b in re.findall(r"```toml\n(.*?)```", doc.read_text(), re.S)]


def _object_tables() -> list[dict[str, Any]]:
    """One [[world.objects]] table of each kind, every key of the kind given a value."""
    values = {"number": 0.2, "vector": [0.1, 0.2, -5.0], "path": "meshes/rock.obj"}
    tables = []
    for kind in registered_kinds():
        table = {"type": kind.name}
        table.update(
            {
                k.name: list(k.default or ()) or values[k.holds]
                if k.holds == "vector"
                else k.default or values[k.holds]
                for k in kind.keys
            }
        )
        tables.append(table)
    # a fixture (type = "urdf", uvms_pin.scenario.fixtures): its joints by name or in order
    fixture = {"type": "urdf", "name": "panel", "position_world_m": [0.8, 0.0, -2.0],
               "path": "../models/fixtures/subsea_panel_valve.urdf", "rpy_rad": [0.0, 0.0, 3.1]}  # fmt: skip
    tables += [{**fixture, "joint_positions_rad": {"valve": 0.2}},
               {**fixture, "joint_positions_rad": [0.2]}]  # fmt: skip
    return tables


def _table(value: Any) -> dict[str, Any]:
    """A top-level entry's keys: a table's own; an array of tables' ([[robots]]): none."""
    return value if isinstance(value, dict) else {}


def _robot_entries(doc: dict[str, Any]) -> list[dict[str, Any]]:
    """The [[robots]] entries of ``doc`` (none for a single-robot document)."""
    entries = doc.get("robots")
    return [e for e in entries if isinstance(e, dict)] if isinstance(entries, list) else []


def _scenarios() -> dict[str, dict[str, Any]]:
    # the cheap ones first: hypothesis shrinks towards the first
    paths = sorted((ROOT / "scenarios").glob("*.toml"), key=lambda p: ("mpc" in p.name, p.name))
    return {p.name: tomllib.loads(p.read_text()) for p in paths}


SCENARIOS = _scenarios()
#: (dotted table, its value): the tables a document can be given from another
DONORS: list[tuple[tuple[str, ...], Any]] = [
    (path, json.loads(text))
    for path, text in sorted(
        {
            (key,) if sub is None else (key, sub): json.dumps(
                doc[key] if sub is None else doc[key][sub], sort_keys=True
            )
            for doc in [*SCENARIOS.values(), *_toml_blocks(ROOT / "docs" / "sensors.md")]
            for key in doc
            for sub in [
                None,
                *(k for k, v in _table(doc[key]).items() if isinstance(v, dict | list)),
            ]
        }.items()
    )
]
DONORS += [(("world", "objects"), [table]) for table in _object_tables()]
#: documented keys no shipped scenario uses: (table, key, a valid value, a document holding
#: the table), each grafted as that document's table with the key set
UNSHIPPED_KEYS = (
    ("actuation", "thruster_curve", "t200_16v", "bluerov_alpha5_force_tracking.toml"),
)
DONORS += [
    ((table,), {**SCENARIOS[doc][table], key: value}) for table, key, value, doc in UNSHIPPED_KEYS
]
#: documented tables no shipped scenario holds, grafted whole
UNSHIPPED_TABLES = (
    (
        ("controller",),
        {"type": "joint_hold", "positions_rad": {"arm_joint1": 0.2}, "stiffness_Nm_rad": 2.0,
         "damping_Nms_rad": 0.1, "vehicle_wrench_body": [5.0, 0.0, 0.0, 0.0, 0.0, 0.0]},
    ),
)  # fmt: skip
DONORS += list(UNSHIPPED_TABLES)

EDGE_NUMBERS = (0, -0.0, -1, 1e-300, 1e300, math.nan, math.inf, -math.inf, 2**63, -(2**63) - 1,
                10**30, 1e-9, 1e9, 0.5, -0.5, 3)  # fmt: skip
KEY_NAMES = sorted(
    {k for doc in SCENARIOS.values() for t in doc.values() if isinstance(t, dict) for k in t}
    | {k for doc in SCENARIOS.values() for entry in _robot_entries(doc) for k in entry}
    | {key for _, key, _, _ in UNSHIPPED_KEYS}
    | {key for _, table in UNSHIPPED_TABLES for key in table}
)
#: the tables a [[robots]] entry holds, from every document: what `_graft_robot` gives one
ROBOT_DONORS = [(p[0], value) for p, value in DONORS if len(p) == 1 and p[0] in ROBOT_TABLES]

scalars = st.one_of(
    st.sampled_from(EDGE_NUMBERS),
    st.booleans(),
    st.integers(),
    st.floats(),
    st.text(max_size=12),
    st.sampled_from(["uvms_lbv150", "ppc", "none", "rk4", "nan", "", "a:b", "os:system"]),
    st.just(datetime.date(2026, 12, 4)),
)
values = st.recursive(
    scalars,
    lambda inner: (
        st.lists(inner, max_size=8) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=10,
)
#: a key of any table: a documented one (in the wrong place), a typo of one, or any text
key_names = st.one_of(
    st.sampled_from(KEY_NAMES),
    st.sampled_from(KEY_NAMES).map(lambda k: k[:-1]),
    st.text(max_size=10),
)


def paths_in(doc: Any, prefix: tuple = ()) -> list[tuple]:
    """Every path into ``doc`` (keys and list indices), tables and lists included."""
    out = []
    items = (
        doc.items() if isinstance(doc, dict) else enumerate(doc) if isinstance(doc, list) else ()
    )
    for key, value in items:
        out.append((*prefix, key))
        out.extend(paths_in(value, (*prefix, key)))
    return out


def _parent(doc: Any, path: tuple) -> Any:
    for key in path[:-1]:
        doc = doc[key]
    return doc


def _set(draw, doc: dict) -> None:
    path = draw(st.sampled_from(paths_in(doc)))
    _parent(doc, path)[path[-1]] = draw(values)


def _edge(draw, doc: dict) -> None:
    numeric = [p for p in paths_in(doc) if isinstance(_parent(doc, p)[p[-1]], int | float)]
    if numeric:
        path = draw(st.sampled_from(numeric))
        _parent(doc, path)[path[-1]] = draw(st.sampled_from(EDGE_NUMBERS))


def _delete(draw, doc: dict) -> None:
    path = draw(st.sampled_from(paths_in(doc)))
    del _parent(doc, path)[path[-1]]


def _extra(draw, doc: dict) -> None:
    tables = [(), *(p for p in paths_in(doc) if isinstance(_parent(doc, p)[p[-1]], dict))]
    path = draw(st.sampled_from(tables))
    table = _parent(doc, path)[path[-1]] if path else doc
    table[draw(key_names)] = draw(values)


def _graft(draw, doc: dict) -> None:
    path, value = draw(st.sampled_from(DONORS))
    table = doc.setdefault(path[0], {}) if len(path) == 2 else doc
    if not isinstance(table, dict):
        return
    held = table.get(path[-1])
    if isinstance(held, list) and isinstance(value, list) and draw(st.booleans()):
        held.extend(copy.deepcopy(value))  # one more camera, thruster, object
    else:
        table[path[-1]] = copy.deepcopy(value)


def _resize(draw, doc: dict) -> None:
    lists = [p for p in paths_in(doc) if isinstance(_parent(doc, p)[p[-1]], list)]
    if lists:
        path = draw(st.sampled_from(lists))
        items = _parent(doc, path)[path[-1]]
        size = draw(st.sampled_from([0, 1, 2, len(items) - 1, len(items) + 1, 2 * len(items)]))
        _parent(doc, path)[path[-1]] = (
            [copy.deepcopy(items[k % len(items)]) for k in range(max(size, 0))]
            if items
            else [draw(values)]
        )


def _graft_robot(draw, doc: dict) -> None:
    """A robot's table from another document into a [[robots]] entry (a robot's table into
    a single-robot document is `_graft`'s)."""
    entries = _robot_entries(doc)
    if entries and ROBOT_DONORS:
        key, value = draw(st.sampled_from(ROBOT_DONORS))
        draw(st.sampled_from(entries))[key] = copy.deepcopy(value)


EDITS = (_set, _edge, _delete, _extra, _graft, _resize, _graft_robot)


@st.composite
def edited(draw, documents: dict[str, dict[str, Any]], max_edits: int = 3):
    """(the name of a document of ``documents``, a copy of it with 1 to ``max_edits`` edits)."""
    name = draw(st.sampled_from(sorted(documents, key=list(documents).index)))
    doc = copy.deepcopy(documents[name])
    for _ in range(draw(st.integers(1, max_edits))):
        if not doc:
            break
        draw(st.sampled_from(EDITS))(draw, doc)
    return name, doc


def toml_text(doc: dict[str, Any]) -> str:
    """``doc`` as TOML: each top-level entry one line (tables inline), None left out."""
    return "".join(f"{_key(k)} = {_value(v)}\n" for k, v in doc.items() if v is not None)


def _key(key: Any) -> str:
    return _string(str(key))


def _string(text: str) -> str:
    """A TOML basic string: quotes, backslashes and control characters escaped."""
    escaped = (c if 0x20 <= ord(c) != 0x7F and c not in '"\\' else f"\\u{ord(c):04x}" for c in text)
    return '"' + "".join(escaped) + '"'


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return (
            "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
        )
    if isinstance(v, str):
        return _string(v)
    if isinstance(v, datetime.date):
        return v.isoformat()
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_value(x) for x in v if x is not None) + "]"
    if isinstance(v, dict):
        return (
            "{" + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items() if x is not None) + "}"
        )
    raise TypeError(type(v))
