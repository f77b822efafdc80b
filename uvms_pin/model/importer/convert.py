"""`import_model`: a Gazebo vehicle (URDF, xacro-expanded URDF or SDF, with uuv_simulator or
gz-sim plugins) -> a uvms-pin URDF with ``<hydrodynamics>`` and a thruster table.

Per link with mass, the hydrodynamics written are: the uuv_simulator Fossen block that names
it (`uvms_pin.model.importer.fossen`); or gz-sim's Hydrodynamics system for it
(`uvms_pin.model.importer.gz_hydrodynamics`) with the buoyancy gz-sim's Buoyancy system
gives it (its collision primitives' volume); or, with no plugin, that buoyancy alone when
the file has a Buoyancy system, else nothing (a dry link, as in the simulator). Thruster
links (a thruster plugin's propeller) leave the tree and become the thruster table; a
LiftDrag system's link gets a ``<lift_drag>`` (`uvms_pin.model.importer.lift_drag`).
"""

from __future__ import annotations

import copy
import math
import os
import xml.etree.ElementTree as ET
from contextlib import nullcontext
from pathlib import Path

import numpy as np

from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.hydro.params import HydroParams
from uvms_pin.model.importer.collision_volume import collision_volume
from uvms_pin.model.importer.fossen import fossen_hydro
from uvms_pin.model.importer.gz_hydrodynamics import gz_hydrodynamics
from uvms_pin.model.importer.includes import inline_includes, resource_folders
from uvms_pin.model.importer.inertia import check_inertias
from uvms_pin.model.importer.lift_drag import add_fins
from uvms_pin.model.importer.plugins import PluginKind, plugin_kind
from uvms_pin.model.importer.result import ImportedThruster, ImportResult
from uvms_pin.model.importer.sdf import sdf_model, sdf_to_urdf
from uvms_pin.model.importer.thrusters import gz_thruster, uuv_thruster
from uvms_pin.model.importer.tree import fix_immobile_joints, hold_uuv_fins, link_placements
from uvms_pin.model.importer.write import hydro_element, thruster_table_text, urdf_text
from uvms_pin.model.urdf.read import xml_root
from uvms_pin.results.atomic import atomic_path

__all__ = ["import_model"]

_XACRO_NAMESPACE = "{http://www.ros.org/wiki/xacro}"
UUV_DEFAULT_DENSITY_KG_M3 = 1028.0  # UnderwaterObjectPlugin's default fluid_density
GZ_DEFAULT_DENSITY_KG_M3 = 1000.0  # the Buoyancy system's default


def import_model(
    path: str | Path,
    out: str | Path | None = None,
    *,
    thrusters_out: str | Path | None = None,
    allow_dry: bool = False,
    balance_inertia: bool = False,
) -> ImportResult:
    """Read a Gazebo vehicle; with ``out``, write the URDF there and, when it has thrusters,
    the table to ``thrusters_out`` (default: ``out`` with ``.thrusters.toml``).

    ``allow_dry``: import a file that carries no hydrodynamics at all (no plugin uvms-pin
    maps, no ``<hydrodynamics>`` element) with every link dry; refused otherwise (a vehicle
    without water is rarely what was meant). ``balance_inertia``: a link's inertia that no
    mass distribution has (Gazebo does not check it) is balanced (`check_inertias`), not
    refused.

    Raises:
        ModelError: naming the file and what cannot be read or mapped; nothing is written.
    """
    if not isinstance(path, str | Path):
        raise ParameterError(f"path must be a model file's path, got {path!r}")
    path = Path(path)
    where = str(path)
    notes: list[str] = []
    robot, plugins, fmt = _read_source(path, notes)
    links = {link.get("name"): link for link in robot.findall("link")}
    fix_immobile_joints(robot, notes)
    hold_uuv_fins(robot, [p for p in plugins if plugin_kind(p) is PluginKind.UUV_FIN], notes)
    placements = link_placements(robot, where)
    thrusters = _thrusters(robot, plugins, placements, where, notes)
    density, hydro = _hydro(links, plugins, where, notes)
    _drop_thruster_links(robot, plugins, where, notes)
    if not (hydro or allow_dry or any(robot.iter("hydrodynamics"))):
        raise ModelError(
            "carries no hydrodynamics (no uuv_simulator or gz-sim plugin uvms-pin maps, no "
            "<hydrodynamics> element): every link would be dry; pass allow_dry=True "
            "(uvms-pin import --allow-dry) to import it so",
            path=where,
        )
    _finish_links(robot, hydro, where, notes)
    add_fins(robot, plugins, where, notes)
    check_inertias(robot, where, notes, balance=balance_inertia)  # what the loader would refuse
    out = None if out is None else Path(out)
    _place_mesh_files(robot, path, None if out is None else out.parent, notes)
    result = ImportResult(urdf_text(robot, where, notes), hydro, thrusters, density, notes, fmt)
    if out is not None:
        table = None if not thrusters else Path(thrusters_out or out.with_suffix(".thrusters.toml"))
        # both files appear together or neither does
        with (
            atomic_path(out) as urdf_tmp,
            nullcontext() if table is None else atomic_path(table) as table_tmp,
        ):
            urdf_tmp.write_text(result.urdf_text, encoding="utf-8")
            if table_tmp is not None:
                table_tmp.write_text(
                    thruster_table_text(thrusters, where, density), encoding="utf-8"
                )
    return result


def _place_mesh_files(
    robot: ET.Element, source: Path, out_dir: Path | None, notes: list[str]
) -> None:
    """A mesh file the source names relative to its folder (``meshes/hull.stl``) or as a
    ``model://NAME/...`` URI (gz-sim's, looked for beside the source, beside its folder and
    in ``GZ_SIM_RESOURCE_PATH``) named relative to the URDF's own folder ``out_dir`` (the
    loader reads it from there), or absolute when the URDF is not written (None). Another
    URI (``package://``) or an absolute path stays; a ``model://`` mesh not found stays too;
    a mesh not found is noted."""
    for mesh in robot.iter("mesh"):
        filename = (mesh.get("filename") or "").strip()
        if filename.startswith("model://"):
            rest = filename.removeprefix("model://")
            folders = [source.parent.parent, *resource_folders(source)]
            found = next((f / rest for f in folders if (f / rest).is_file()), None)
            if found is None:
                notes.append(
                    f"mesh '{filename}' not found (looked in {', '.join(map(str, folders))}; "
                    "set GZ_SIM_RESOURCE_PATH): left as is, the loader will not find it"
                )
                continue
        elif not filename or "://" in filename or Path(filename).is_absolute():
            continue
        else:
            found = source.parent / filename
            if not found.is_file():
                notes.append(f"mesh '{filename}' not found beside the source ({found})")
        found = found.resolve()
        mesh.set(
            "filename", str(found) if out_dir is None else os.path.relpath(found, out_dir.resolve())
        )


def _read_source(path: Path, notes: list[str]) -> tuple[ET.Element, list[ET.Element], str]:
    """(the URDF robot tree to edit, every <plugin> element, "urdf" or "sdf")."""
    where = str(path)
    root = xml_root(path)
    if root.tag == "sdf":
        inline_includes(root, path, notes)
        for world in root.iter("world"):  # the GUI's plugins are not the vehicle's
            for gui in world.findall("gui"):
                world.remove(gui)
        robot = sdf_to_urdf(sdf_model(root, where), where, notes)
        return robot, list(root.iter("plugin")), "sdf"
    if root.tag != "robot":
        raise ModelError(
            f"root element is <{root.tag}>, expected <robot> (URDF) or <sdf>", path=where
        )
    for element in root.iter():
        if element.tag.startswith(_XACRO_NAMESPACE) or "${" in "".join(element.attrib.values()):
            raise ModelError(
                "is an unexpanded xacro file; expand it first (xacro FILE > FILE.urdf)", path=where
            )
    robot = copy.deepcopy(root)
    plugins = [p for gazebo in robot.findall("gazebo") for p in gazebo.iter("plugin")]
    for gazebo in robot.findall("gazebo"):
        robot.remove(gazebo)
    return robot, plugins, "urdf"


def _thrusters(robot, plugins, placements, where, notes) -> list[ImportedThruster]:
    joints = {j.get("name"): j for j in robot.findall("joint")}
    found = []
    for plugin in plugins:
        kind = plugin_kind(plugin)
        if kind is PluginKind.UUV_THRUSTER:
            found.append(uuv_thruster(plugin, placements, where, notes))
        elif kind is PluginKind.GZ_THRUSTER:
            found.append(gz_thruster(plugin, joints, placements, where, notes))
    return found


def _hydro(links, plugins, where, notes) -> tuple[float | None, dict[str, HydroParams]]:
    """(the fluid density the file states, each link's coefficients)."""
    hydro: dict[str, HydroParams] = {}
    density = None
    kinds = [plugin_kind(p) for p in plugins]
    buoyancy = PluginKind.GZ_BUOYANCY in kinds
    for plugin, kind in zip(plugins, kinds, strict=True):
        if kind is PluginKind.UUV_HYDRO:
            density = _number_or(plugin, "fluid_density", UUV_DEFAULT_DENSITY_KG_M3, where)
            for block in plugin.findall("link"):
                if block.get("name") and block.get("name") not in links:
                    # the plugin warns ("Specified link [...] not found") and goes on
                    notes.append(
                        f"uuv_simulator plugin block of link '{block.get('name')}', which is not "
                        "in the model: skipped, as the plugin skips it (with a warning)"
                    )
                    continue
                name = _known_link(block.get("name"), links, where)
                hydro[name] = fossen_hydro(block, _mass(links[name], where), density, where, notes)
            _note_plugin_extras(plugin, {"link", "fluid_density"}, notes)
        elif kind is PluginKind.GZ_BUOYANCY:
            density = _number_or(plugin, "uniform_fluid_density", GZ_DEFAULT_DENSITY_KG_M3, where)
            _note_plugin_extras(plugin, {"uniform_fluid_density"}, notes)
        elif kind is None:
            notes.append(f"plugin '{plugin.get('name') or plugin.get('filename')}' not mapped")
    for plugin, kind in zip(plugins, kinds, strict=True):
        if kind is PluginKind.GZ_HYDRO:
            name = _known_link((plugin.findtext("link_name") or "").strip(), links, where)
            volume, centre = _gz_buoyancy(links[name], buoyancy, where, notes)
            hydro[name] = gz_hydrodynamics(plugin, volume, centre, where, notes)
    if buoyancy:  # the Buoyancy system floats every link by its collision shapes
        for name, link in links.items():
            if name not in hydro and link.find("inertial") is not None:
                volume, centre = collision_volume(link, where, notes)
                hydro[name] = HydroParams(
                    volume, centre, np.zeros((6, 6)), np.zeros((6, 6)), np.zeros(6)
                )
    return density, hydro


def _gz_buoyancy(link, buoyancy: bool, where: str, notes: list[str]) -> tuple[float, np.ndarray]:
    if buoyancy:
        return collision_volume(link, where, notes)
    notes.append(
        f"link '{link.get('name')}': no Buoyancy system in the file: written without buoyancy"
    )
    return 0.0, np.zeros(3)


def _drop_thruster_links(
    robot: ET.Element, plugins: list[ET.Element], where: str, notes: list[str]
) -> None:
    """The propeller links and their joints leave the tree: a thruster is an actuator of the
    vehicle, not an arm joint. Their mass is reported."""
    joints = {j.get("name"): j for j in robot.findall("joint")}
    by_child = {j.find("child").get("link"): j for j in joints.values()}
    links = {link.get("name"): link for link in robot.findall("link")}
    for plugin in plugins:
        kind = plugin_kind(plugin)
        if kind is PluginKind.UUV_THRUSTER:
            link = (plugin.findtext("linkName") or "").strip()
        elif kind is PluginKind.GZ_THRUSTER:
            link = joints[(plugin.findtext("joint_name") or "").strip()].find("child").get("link")
        else:
            continue
        if any(j.find("parent").get("link") == link for j in joints.values()):
            raise ModelError(
                f"thruster link '{link}' carries other links; cannot remove it", path=where
            )
        if link not in by_child or links.get(link) not in robot:
            raise ModelError(
                f"thruster link '{link}' is no joint's child, or the link of two thruster "
                "plugins: each thruster needs its own propeller link on a joint",
                path=where,
            )
        robot.remove(links[link])
        robot.remove(by_child[link])
        # what was said of the removed joint no longer applies to the written model
        notes[:] = [n for n in notes if not n.startswith(f"joint '{by_child[link].get('name')}':")]
        notes.append(
            f"thruster link '{link}' ({_mass(links[link], where):g} kg) and joint "
            f"'{by_child[link].get('name')}' removed from the tree: the thruster is in the "
            "thruster table"
        )


def _finish_links(
    robot: ET.Element, hydro: dict[str, HydroParams], where: str, notes: list[str]
) -> None:
    """Each link with mass gets its ``<hydrodynamics>`` (zero volume: dry, as in the
    source), unless the source already gives it one (a uvms-pin URDF: kept as it is, never
    stripped); a link without mass loses its collision shapes (uvms-pin needs mass there)."""
    for link in robot.findall("link"):
        name = link.get("name")
        own = link.find("hydrodynamics") is not None and name not in hydro
        if own and link.find("inertial") is not None:
            continue  # the source's own hydrodynamics, kept
        for old in link.findall("hydrodynamics"):
            link.remove(old)
        if link.find("inertial") is None:
            for collision in link.findall("collision"):
                link.remove(collision)
                notes.append(f"link '{name}': collision shape of a massless link dropped")
            continue
        if name not in hydro:
            notes.append(f"link '{name}': no hydrodynamics in the source; written dry (volume 0)")
            hydro[name] = HydroParams.dry()
        link.append(hydro_element(hydro[name]))


def _known_link(name: str | None, links: dict[str, ET.Element], where: str) -> str:
    if name not in links:
        raise ModelError(
            f"a hydrodynamics plugin names link {name!r}, which is not in the model", path=where
        )
    if links[name].find("inertial") is None:
        raise ModelError("has hydrodynamics but no <inertial>", path=where, link=name)
    return name


def _mass(link: ET.Element, where: str) -> float:
    """The link's <mass value> [kg] (0 without one); ModelError naming the link if it is
    not a finite number."""
    mass = link.find("inertial/mass")
    text = "0" if mass is None else mass.get("value", "0")
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise ModelError(
            f"<mass value='{text}'> is not a finite number", path=where, link=link.get("name")
        )
    return value


def _number_or(plugin: ET.Element, tag: str, default: float, where: str) -> float:
    text = plugin.findtext(tag)
    if text is None:
        return default
    try:
        value = float(text)
    except ValueError as exc:
        raise ModelError(f"plugin <{tag}> is not a number: '{text.strip()}'", path=where) from exc
    if not (value > 0.0 and math.isfinite(value)):
        raise ModelError(f"plugin <{tag}> must be positive and finite, got {value}", path=where)
    return value


def _note_plugin_extras(plugin: ET.Element, mapped: set[str], notes: list[str]) -> None:
    for child in plugin:
        if child.tag not in mapped:
            notes.append(f"plugin '{plugin.get('name')}': <{child.tag}> not mapped")
