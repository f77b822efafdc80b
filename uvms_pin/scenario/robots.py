"""``[[robots]]``: several robots in one scenario, each its own document.

Each entry has a ``name`` (letters, digits, ``_`` and ``-``: it names the robot's columns
and its results' directory), a ``model`` (as ``[scenario] model``) and any of a robot's own
tables (`ROBOT_TABLES`). The run's tables (`SHARED_TABLES`: ``[scenario]`` without its
``model``, ``[water]``, ``[world]``, the timing and the metrics) are every robot's. A robot
becomes the single-robot document of its model, its tables and the shared ones
(`robot_documents`), read as any scenario is; its sensors' seed is its own
(`uvms_pin.sim.robots_run.robot_seed`). A scenario without ``[[robots]]`` is a single-robot
scenario, read as always.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

from uvms_pin.scenario.schema import Table

__all__ = ["ROBOT_TABLES", "SHARED_TABLES", "robot_documents", "robot_overrides"]

#: the tables a [[robots]] entry may hold: a robot's own
ROBOT_TABLES = (
    "initial", "actuation", "sensors", "joints", "gripper", "controller", "task", "estimator",
    "environment", "disturbance",
)  # fmt: skip
#: a robot's own names of its model's frames, as ``[scenario]``'s (its end-effector's, its F/T
#: sensor's)
ROBOT_FRAMES = ("ee_frame", "sensor_frame")
#: the tables every robot shares
SHARED_TABLES = ("scenario", "water", "world", "integrator", "control", "output", "metrics")
_NAME = re.compile(r"[A-Za-z0-9_-]+")


def robot_documents(
    raw: Mapping[str, Any], source: str, overridden: dict[str, str]
) -> list[tuple[str, dict[str, Any]]] | None:
    """(name, the robot's single-robot document) of each ``[[robots]]`` entry of ``raw``,
    in order; None when ``raw`` has no ``[[robots]]``.

    Raises:
        ScenarioError: naming the key: an entry without a name or model, two robots of one
            name, a robot's table at the top level (or ``[scenario] model``) beside
            ``[[robots]]``, an unknown key.
    """
    if "robots" not in raw:
        return None
    top = Table(raw, "", source, overridden)
    entries = top.tables("robots")
    if not entries:
        raise top.error("robots", "must hold at least one robot ([[robots]] entries)")
    head = top.table_or_empty("scenario")
    if head.has("model"):
        raise head.error("model", "with [[robots]], each robot names its model ([[robots]] model)")
    for key in (*ROBOT_TABLES, "baselines"):
        if top.has(key):
            raise top.error(key, "with [[robots]], a robot's table belongs in its [[robots]] entry")
    shared = {key: raw[key] for key in SHARED_TABLES if key in raw}
    for key in SHARED_TABLES:
        top.pop_raw(key)
    top.finish()  # what is left is unknown
    out: list[tuple[str, dict[str, Any]]] = []
    for entry in entries:
        name = entry.string("name")
        if not _NAME.fullmatch(name):
            raise entry.error("name", f"letters, digits, '_' and '-' only, got '{name}'")
        if name in (n for n, _ in out):
            raise entry.error("name", f"'{name}' names two robots")
        model = entry.string("model")
        frames = {key: entry.string(key) for key in ROBOT_FRAMES if entry.has(key)}
        own = {key: entry.pop_raw(key) for key in ROBOT_TABLES if entry.has(key)}
        entry.finish()
        scenario = {**shared.get("scenario", {}), "model": model, **frames}
        out.append((name, {**shared, "scenario": scenario, **own}))
    return out


def robot_overrides(overridden: dict[str, str], index: int) -> dict[str, str]:
    """The overridden keys as robot ``index``'s document names them (``robots[1].initial.x``
    -> ``initial.x``; a shared table's as they are), so that an error about a value an
    override set names the override."""
    prefix = f"robots[{index}]."
    return {
        key.removeprefix(prefix): text
        for key, text in overridden.items()
        if key.startswith(prefix) or not key.startswith("robots")
    }
