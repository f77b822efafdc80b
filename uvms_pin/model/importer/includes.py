"""SDF ``<include>`` of a local model, inlined before the import reads the tree.

An ``<include>`` names a model by ``<uri>``: a directory holding ``model.config`` (whose
``<sdf>`` entry names the model file) or ``model.sdf``, or an SDF file. A relative path and a
``model://NAME`` URI are looked up from the including file's folder, then in the folders of
the ``GZ_SIM_RESOURCE_PATH`` environment variable, as gz-sim does; ``file://`` is a plain
path. A remote model (``http(s)://``, Gazebo Fuel) is refused: the importer reads local files
only.

Two ways to include (SDFormat 1.9, ``//model/include/@merge``):

- ``merge="false"`` (the default): the included ``<model>`` takes the ``<include>``'s place,
  renamed by its ``<name>`` and placed by its ``<pose>``.
- ``merge="true"``: the included model's links, joints, plugins and frames go into the
  parent model without a scope of their own; the include's ``<pose>`` (else the included
  model's own) places them in the parent model frame: X_parent_link = X_include X_model_link.

Plugins written inside the ``<include>`` belong to the included model. Relative mesh URIs
of an included model are rewritten relative to the top file, so that they name the same
files as before.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import pinocchio as pin

from uvms_pin.errors import ModelError
from uvms_pin.model.importer.sdf import sdf_pose
from uvms_pin.model.resources import environment_folders
from uvms_pin.model.urdf.read import xml_root
from uvms_pin.results.format import numbers_text

__all__ = ["inline_includes", "resource_folders"]

#: includes within includes deeper than this are refused (a cycle or a runaway tree)
MAX_INCLUDE_DEPTH = 16
_REMOTE_SCHEMES = ("http://", "https://", "fuel://", "ftp://")
_MERGED = ("link", "joint", "plugin", "frame", "gripper")


def inline_includes(root: ET.Element, path: Path, notes: list[str]) -> ET.Element:
    """``root`` (an ``<sdf>`` element read from ``path``) with every ``<include>`` inlined,
    in place; ModelError naming the including file and the URI for a missing, remote or
    malformed model."""
    _inline(root, path, path.parent, (path.resolve(),), notes)
    return root


def _inline(
    element: ET.Element, path: Path, top_dir: Path, chain: tuple[Path, ...], notes: list[str]
) -> None:
    for parent in list(element.iter()):
        for include in parent.findall("include"):
            model, model_path = _included_model(include, path, chain)
            _inline(model, model_path, top_dir, (*chain, model_path.resolve()), notes)
            _rebase_meshes(model, model_path.parent, top_dir)
            model.extend(include.findall("plugin"))
            position = list(parent).index(include)
            parent.remove(include)
            merge = include.get("merge", "false").strip().lower() in ("1", "true")
            if merge and parent.tag == "model":
                _merge(parent, position, model, include, str(path))
            else:
                if merge:
                    notes.append(
                        f"<include merge='true'> of '{include.findtext('uri')}' in a <world>: "
                        "included as a model (merge applies within a <model>)"
                    )
                _nest(parent, position, model, include)


def _included_model(
    include: ET.Element, path: Path, chain: tuple[Path, ...]
) -> tuple[ET.Element, Path]:
    """The ``<model>`` element an ``<include>`` names, and the file it was read from."""
    where = str(path)
    uri = (include.findtext("uri") or "").strip()
    if not uri:
        raise ModelError("an <include> has no <uri>", path=where)
    if uri.lower().startswith(_REMOTE_SCHEMES):
        raise ModelError(
            f"<include> of the remote model '{uri}': uvms-pin import reads local files only; "
            "download the model and include it by its local path",
            path=where,
        )
    if include.find("placement_frame") is not None:
        raise ModelError(f"<include> of '{uri}': <placement_frame> is not supported", path=where)
    model_file = _model_file(uri, path)
    if model_file.resolve() in chain or len(chain) > MAX_INCLUDE_DEPTH:
        raise ModelError(
            f"<include> of '{uri}' includes itself (through {len(chain)} files)", path=where
        )
    root = xml_root(model_file)
    models = root.findall("model") if root.tag == "sdf" else []
    if len(models) != 1:
        raise ModelError(
            f"<include> of '{uri}': {model_file} must hold one <sdf><model>, found {len(models)}",
            path=where,
        )
    return models[0], model_file


def resource_folders(path: Path) -> list[Path]:
    """Where a ``model://`` URI of the file ``path`` is looked for: its folder, then each
    folder of ``GZ_SIM_RESOURCE_PATH``."""
    return [path.parent, *environment_folders("GZ_SIM_RESOURCE_PATH")]


def _model_file(uri: str, path: Path) -> Path:
    """The SDF file of an include URI, searched as the module docstring says."""
    name = uri.removeprefix("model://").removeprefix("file://")
    folders = resource_folders(path)
    tried = []
    for folder in folders:
        candidate = folder / name
        tried.append(str(candidate))
        if candidate.is_file():
            return candidate
        if candidate.is_dir():
            return _model_in_directory(candidate, uri, str(path))
    raise ModelError(
        f"<include> of '{uri}': no such model (looked for {', '.join(tried)}; "
        "model:// URIs are also looked up in GZ_SIM_RESOURCE_PATH)",
        path=str(path),
    )


def _model_in_directory(folder: Path, uri: str, where: str) -> Path:
    """A model directory's SDF: the ``<sdf>`` entry of ``model.config``, else ``model.sdf``."""
    config = folder / "model.config"
    if config.is_file():
        entries = [e.text.strip() for e in xml_root(config).iter("sdf") if (e.text or "").strip()]
        if entries:
            return folder / entries[-1]
    if (folder / "model.sdf").is_file():
        return folder / "model.sdf"
    raise ModelError(
        f"<include> of '{uri}': {folder} has neither a model.config naming its SDF nor a model.sdf",
        path=where,
    )


def _rebase_meshes(model: ET.Element, model_dir: Path, top_dir: Path) -> None:
    for uri in model.iter("uri"):
        text = (uri.text or "").strip()
        if text and "://" not in text and not Path(text).is_absolute():
            uri.text = os.path.relpath(model_dir / text, top_dir)


def _nest(parent: ET.Element, position: int, model: ET.Element, include: ET.Element) -> None:
    name = (include.findtext("name") or "").strip()
    if name:
        model.set("name", name)
    pose = include.find("pose")
    if pose is not None:
        for old in model.findall("pose"):
            model.remove(old)
        model.insert(0, pose)
    parent.insert(position, model)


def _merge(
    parent: ET.Element, position: int, model: ET.Element, include: ET.Element, where: str
) -> None:
    """The included model's contents into ``parent`` at ``position``, links placed by the
    include's pose (else the model's own)."""
    placed = include if include.find("pose") is not None else model
    placement = sdf_pose(placed, where, f"<include> of '{include.findtext('uri')}'")
    for child in [c for c in model if c.tag in _MERGED]:
        if child.tag == "link":
            _place(child, placement, where)
        parent.insert(position, child)
        position += 1


def _place(link: ET.Element, placement: pin.SE3, where: str) -> None:
    """Write ``link``'s pose as ``placement`` times its pose in its own model."""
    pose = placement * sdf_pose(link, where, f"link '{link.get('name')}'")
    for old in link.findall("pose"):
        link.remove(old)
    element = ET.Element("pose")
    element.text = numbers_text([*pose.translation, *pin.rpy.matrixToRpy(pose.rotation)])
    link.insert(0, element)
