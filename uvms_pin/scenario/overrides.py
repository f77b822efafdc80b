"""Dotted overrides of a TOML document: ``environment.stiffness_N_m = [20, 20, 20]``.

One syntax for scenario overrides (``load_scenario(path, overrides)``, ``uvms-pin run
--set KEY=VALUE``) and study parameter paths: a dotted key of at least two parts,
optionally followed by an element index, ``initial.joint_positions_rad[3]`` (0-based, into
a list the document already has). Values are TOML values (``--set`` parses its text as one).
"""

from __future__ import annotations

import copy
import difflib
import re
import tomllib
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

#: ``table.key`` or ``table.key[i]`` (also the study files' parameter paths).
KEY_PATH = re.compile(r"^([A-Za-z_][\w-]*(?:\.[A-Za-z_][\w-]*)+)(?:\[(\d+)\])?$")


@dataclass(frozen=True)
class KeyPath:
    """A parsed override path: ``key`` (dotted) and an optional element ``index``."""

    text: str
    key: str
    index: int | None

    @property
    def parts(self) -> list[str]:
        return self.key.split(".")


def parse_key_path(text: str) -> KeyPath:
    """``"a.b[2]"`` -> KeyPath("a.b[2]", "a.b", 2).

    Raises:
        ScenarioError: not a dotted key like ``environment.stiffness_N_m`` or ``a.b[2]``.
    """
    match = KEY_PATH.match(text) if isinstance(text, str) else None
    if match is None:
        raise ScenarioError(
            f"override '{text}': not a dotted key like 'environment.stiffness_N_m' or "
            "'initial.joint_positions_rad[3]'"
        )
    index = match.group(2)
    return KeyPath(text, match.group(1), None if index is None else int(index))


def parse_assignment(text: str) -> tuple[str, Any]:
    """``"KEY=VALUE"`` -> (KEY, VALUE parsed as a TOML value).

    ``water.current_world_m_s=[0.2, 0, 0]``, ``scenario.duration_s=2``,
    ``integrator.method="Radau"``. A value that is not valid TOML is taken as a string
    (``integrator.method=Radau``), so a shell needs no extra quotes.

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
    """A deep copy of ``raw`` with every override set (``{"a.b": 1, "c.d[2]": 0.5}``).

    A plain key creates missing tables (the loader then rejects unknown keys); an indexed
    key replaces one element of a list the document has.

    Raises:
        ScenarioError: naming the override: a bad path, a part that is not a table, an
            index into something that is not a list, or out of range.
    """
    out = copy.deepcopy(raw)
    for text, value in (overrides or {}).items():
        path = parse_key_path(text)
        parts = path.parts
        node = out
        for part in parts[:-1]:
            child = node.setdefault(part, {})
            if not isinstance(child, dict):
                raise ScenarioError(f"override '{text}': '{part}' is not a table")
            node = child
        leaf = parts[-1]
        if path.index is None:
            node[leaf] = copy.deepcopy(value)
            continue
        current = node.get(leaf)
        if not isinstance(current, list):
            hint = closest(path.key, flatten_keys(raw))
            raise ScenarioError(
                f"override '{text}': '{path.key}' is not a list in the file, so it cannot be "
                "indexed (set the whole list)"
                + (f"; did you mean '{hint}'?" if hint and hint != path.key else "")
            )
        if path.index >= len(current):
            raise ScenarioError(
                f"override '{text}': index {path.index} out of range, '{path.key}' has "
                f"{len(current)} entries"
            )
        current[path.index] = copy.deepcopy(value)
    return out
