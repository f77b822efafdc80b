"""What a scenario file makes uvms-pin import or read beyond itself, and the refusal of
``uvms-pin run --no-code`` (docs/security.md).

A scenario file is code when it names code: ``[controller] type = "module:Class"`` and
``[metrics] extra = ["module:function"]`` import (run) a module with the user's rights, from
the scenario's folder or anywhere on ``sys.path``. It also names files uvms-pin reads:
``[scenario] model`` (a URDF) and the ``path`` of a ``[[world.objects]]`` mesh or fixture; each
``[[robots]]`` entry its controller and model likewise; and a URDF it names (the model, a
fixture) names files in turn: its ``<mesh filename>`` (visual and collision) and any other
``filename`` attribute, read by the loader and by the replay's drawing. With
``--no-code`` (`check_no_code`), a scenario is refused, before anything is imported or read,
when it names any module, or a file outside its own folder (and the folders below it) and the
shipped models; the names are judged as the reader will resolve them (symbolic links
followed), on the table after the ``--set`` overrides.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from uvms_pin.errors import ParameterError, ScenarioError
from uvms_pin.model.resources import find_model, resolve_resource, shipped_path
from uvms_pin.physics.world.fixture import FIXTURE_TYPE, fixture_path
from uvms_pin.physics.world.objects import kind_names, object_kind


@dataclass(frozen=True)
class Reach:
    """One thing a scenario makes uvms-pin import or read.

    Attributes:
        key: its dotted key in the file (``"world.objects[1].path"``).
        module: the ``module:name`` it imports, or "" for a file.
        path: the file it reads (resolved), or None for a module.
    """

    key: str
    module: str = ""
    path: Path | None = None


def reaches(raw: Mapping[str, Any], scenario_dir: Path) -> Iterator[Reach]:
    """Every module and file the scenario ``raw`` (the TOML as a dict) names; entries of the
    wrong type are left to the reader, which refuses them."""
    controller = raw.get("controller")
    kind = controller.get("type") if isinstance(controller, Mapping) else None
    if isinstance(kind, str) and ":" in kind:
        yield Reach("controller.type", module=kind)
    metrics = raw.get("metrics")
    extra = metrics.get("extra") if isinstance(metrics, Mapping) else None
    for k, reference in enumerate(extra if isinstance(extra, list) else []):
        yield Reach(f"metrics.extra[{k}]", module=str(reference))
    scenario = raw.get("scenario")
    model = scenario.get("model") if isinstance(scenario, Mapping) else None
    if isinstance(model, str) and model.strip():
        found = find_model(model, scenario_dir)
        yield Reach("scenario.model", path=found or (scenario_dir / model).resolve())
        yield from _urdf_reaches("scenario.model", found)
    yield from _robot_reaches(raw, scenario_dir)
    world = raw.get("world")
    objects = world.get("objects") if isinstance(world, Mapping) else None
    for k, table in enumerate(objects if isinstance(objects, list) else []):
        if isinstance(table, Mapping) and table.get("type") == FIXTURE_TYPE:
            fixture = _fixture_reach(f"world.objects[{k}].path", table.get("path"), scenario_dir)
            yield fixture
            yield from _urdf_reaches(fixture.key, fixture.path)
            continue
        if not isinstance(table, Mapping) or table.get("type") not in kind_names():
            continue
        for key in object_kind(table["type"]).keys:
            entry = table.get(key.name, key.default)
            if key.holds == "path" and isinstance(entry, str):
                yield Reach(f"world.objects[{k}].{key.name}", path=(scenario_dir / entry).resolve())


def _urdf_reaches(key: str, urdf: Path | None) -> Iterator[Reach]:
    """The files a URDF names in ``filename`` attributes (meshes, visual and collision), as
    its readers resolve them (`resolve_resource`: relative to the URDF's folder, ``file://``,
    ``package://``); after the URDF's own `Reach`, so that a caller stopping at a URDF
    outside reads nothing of it. A URDF that cannot be read, or a name that resolves to no
    file through ``package://``, is left to the reader, which refuses it."""
    if urdf is None or not urdf.is_file():
        return
    try:
        root = ET.parse(urdf).getroot()
    except (OSError, ET.ParseError):
        return
    for element in root.iter():
        filename = element.get("filename")
        if not filename:
            continue
        found = resolve_resource(filename, urdf.parent)
        if found is None and filename.startswith("package://"):
            continue
        named = Path(filename.removeprefix("file://"))
        path = found if found is not None else urdf.parent / named
        yield Reach(
            f"{key} ({urdf.name}) <{element.tag} filename='{filename}'>", path=path.resolve()
        )


def _fixture_reach(key: str, entry: Any, scenario_dir: Path) -> Reach:
    """The file a fixture's ``path`` names, as its reader resolves it (`fixture_path`)."""
    if not isinstance(entry, str):
        return Reach(key)
    try:
        return Reach(key, path=fixture_path(entry, scenario_dir).resolve())
    except ParameterError:  # no such file: the reader refuses it
        return Reach(key, path=(scenario_dir / entry).resolve())


def _robot_reaches(raw: Mapping[str, Any], scenario_dir: Path) -> Iterator[Reach]:
    """What each ``[[robots]]`` entry names: its controller's module, its model."""
    entries = raw.get("robots")
    for k, entry in enumerate(entries if isinstance(entries, list) else []):
        if not isinstance(entry, Mapping):
            continue
        for reach in reaches(
            {"controller": entry.get("controller"), "scenario": entry}, scenario_dir
        ):
            yield Reach(
                f"robots[{k}].{reach.key.removeprefix('scenario.')}", reach.module, reach.path
            )


def _inside(path: Path, folder: Path) -> bool:
    return path.is_relative_to(folder.resolve())


def check_no_code(raw: Mapping[str, Any], scenario_path: str | Path) -> None:
    """Refuse (ScenarioError naming the file and the key) a scenario that would import a
    module, or read a file outside its folder and the shipped models (``--no-code``)."""
    scenario_path = Path(scenario_path)
    folders = [scenario_path.parent]
    try:
        folders.append(shipped_path("models"))
    except FileNotFoundError:  # an install without its models: the scenario's folder only
        pass
    for reach in reaches(raw, scenario_path.parent):
        if reach.module:
            raise ScenarioError(
                f"{scenario_path}: {reach.key}: '{reach.module}' would import and run a module "
                "(refused by --no-code: run the file without it only if you trust it as code)"
            )
        if reach.path is not None and not any(_inside(reach.path, f) for f in folders):
            raise ScenarioError(
                f"{scenario_path}: {reach.key}: reads {reach.path}, outside the scenario's "
                "folder and the shipped models (refused by --no-code)"
            )
