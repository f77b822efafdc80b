"""Dotted overrides of a TOML document: ``environment.stiffness_N_m = [20, 20, 20]``.

One syntax for scenario overrides (``load_scenario(path, overrides)``, ``uvms-pin run
--set KEY=VALUE``) and study parameter paths: a dotted key whose parts may each carry an
element index into a list the document already has, ``initial.joint_positions_rad[3]``,
``actuation.thruster[0].max_forward_N`` (0-based). A key of one part names a whole table,
which a table value replaces: ``controller={type="none"}``. Values are TOML values
(``--set`` parses its text as one).
"""

from __future__ import annotations

import copy
import difflib
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from uvms_pin.errors import ScenarioError

__all__ = [
    "KEY_PATH",
    "KeyPath",
    "apply_overrides",
    "closest",
    "parse_assignment",
    "parse_key_path",
]

_PART = r"[A-Za-z_][\w-]*(?:\[\d+\])?"
#: ``table``, ``table.key``, ``table.key[i]``, ``table.list[i].key`` (also study paths).
KEY_PATH = re.compile(rf"^{_PART}(?:\.{_PART})*$")
_INDEXED = re.compile(r"^(.*)\[(\d+)\]$")


@dataclass(frozen=True)
class KeyPath:
    """A parsed override path: ``key`` (the text without a final index, how errors about
    the value it sets name it) and that final ``index`` (None without one)."""

    text: str
    key: str
    index: int | None

    @property
    def parts(self) -> list[tuple[str, int | None]]:
        """(name, index or None) of every part, the last one's index included."""
        out = []
        for part in self.text.split("."):
            match = _INDEXED.match(part)
            out.append((match.group(1), int(match.group(2))) if match else (part, None))
        return out


def parse_key_path(text: str) -> KeyPath:
    """``"a.b[2]"`` -> KeyPath("a.b[2]", "a.b", 2); ``"a.t[0].k"`` -> KeyPath(.., "a.t[0].k",
    None).

    Raises:
        ScenarioError: not a dotted key like ``environment.stiffness_N_m``,
            ``initial.joint_positions_rad[3]`` or ``actuation.thruster[0].max_forward_N``.
    """
    if not isinstance(text, str) or KEY_PATH.match(text) is None:
        raise ScenarioError(
            f"override '{text}': not a dotted key like 'environment.stiffness_N_m', "
            "'initial.joint_positions_rad[3]' or 'actuation.thruster[0].max_forward_N'"
        )
    match = _INDEXED.match(text)
    if match is None:
        return KeyPath(text, text, None)
    return KeyPath(text, match.group(1), int(match.group(2)))


def _checked(key: str, value: Any) -> KeyPath:
    """The parsed ``key``; a one-part key (a whole table) must be given a table value."""
    path = parse_key_path(key)
    if "." not in key and path.index is None and not isinstance(value, dict):
        raise ScenarioError(
            f"override '{key}': '{key}' is a whole table; give a table value "
            f"({key}={{...}}) or one of its keys ({key}.KEY=VALUE)"
        )
    return path


def parse_assignment(text: str) -> tuple[str, Any]:
    """``"KEY=VALUE"`` -> (KEY, VALUE parsed as a TOML value).

    ``water.current_world_m_s=[0.2, 0, 0]``, ``scenario.duration_s=2``,
    ``integrator.method="Radau"``, ``controller={type="none"}``. A value that is not valid
    TOML is taken as a string (``integrator.method=Radau``), so a shell needs no extra quotes.

    Raises:
        ScenarioError: no ``=``, or a key that is not a dotted path.
    """
    key, sep, value_text = text.partition("=")
    key = key.strip()
    if not sep:
        raise ScenarioError(f"override '{text}': expected KEY=VALUE")
    parse_key_path(key)
    try:
        value = tomllib.loads(f"v = {value_text.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = value_text.strip()
    _checked(key, value)
    return key, value


def closest(word: str, candidates) -> str | None:
    """The candidate closest to ``word`` (difflib), or None if none is close."""
    matches = difflib.get_close_matches(word, sorted(set(candidates)), n=1, cutoff=0.6)
    return matches[0] if matches else None


def flatten_keys(raw: dict[str, Any], prefix: str = "") -> list[str]:
    """Every dotted key of a nested dict (leaves only)."""
    out = []
    for key, value in raw.items():
        dotted = f"{prefix}{key}"
        out += flatten_keys(value, dotted + ".") if isinstance(value, dict) else [dotted]
    return out


def apply_overrides(raw: dict[str, Any], overrides: dict[str, Any] | None) -> dict[str, Any]:
    """A deep copy of ``raw`` with every override set (``{"a.b": 1, "c.d[2]": 0.5,
    "actuation.thruster[0].max_forward_N": 0, "controller": {"type": "none"}}``).

    A plain part creates a missing table (the loader then rejects unknown keys); an indexed
    part goes into a list the document has; a one-part key replaces a whole table and takes
    a table value.

    Raises:
        ScenarioError: naming the override: a bad path, a part that is not a table, an
            index into something that is not a list, or out of range, a table given a value
            that is not a table.
    """
    if overrides is not None and not isinstance(overrides, Mapping):
        raise ScenarioError(
            "overrides must be a mapping of dotted keys to values ({'scenario.duration_s': "
            f"5.0}}), got {type(overrides).__name__}"
        )
    out = copy.deepcopy(raw)
    for text, value in (overrides or {}).items():
        path = _checked(text, value)
        parts = path.parts
        node: Any = out
        for k, (name, index) in enumerate(parts):
            last = k == len(parts) - 1
            where = ".".join(f"{n}" if i is None else f"{n}[{i}]" for n, i in parts[: k + 1])
            if index is None:
                if last:
                    node[name] = copy.deepcopy(value)
                    break
                node = node.setdefault(name, {})
                if not isinstance(node, dict):
                    raise ScenarioError(f"override '{text}': '{where}' is not a table")
                continue
            items = node.get(name)
            if not isinstance(items, list):
                hint = closest(path.key, flatten_keys(raw))
                raise ScenarioError(
                    f"override '{text}': '{where[: where.rindex('[')]}' is not a list in the "
                    "file, so it cannot be indexed (set the whole list)"
                    + (f"; did you mean '{hint}'?" if hint and hint != path.key else "")
                )
            if index >= len(items):
                raise ScenarioError(
                    f"override '{text}': index {index} out of range, "
                    f"'{where[: where.rindex('[')]}' has {len(items)} entries"
                )
            if last:
                items[index] = copy.deepcopy(value)
                break
            node = items[index]
            if not isinstance(node, dict):
                raise ScenarioError(f"override '{text}': '{where}' is not a table")
    return out
