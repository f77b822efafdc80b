"""Writing an import: ``<hydrodynamics>`` elements in the URDF and the thruster table (TOML,
the scenario's ``[[actuation.thruster]]`` entries)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence

import numpy as np

from uvms_pin.hydro.params import HydroParams
from uvms_pin.model.importer.result import ImportedThruster
from uvms_pin.results.format import numbers_text

__all__ = ["hydro_element", "thruster_table_text", "urdf_text"]


def hydro_element(params: HydroParams) -> ET.Element:
    """The ``<hydrodynamics>`` element of ``params``, every number exact (read back equal)."""
    out = ET.Element("hydrodynamics")
    ET.SubElement(out, "volume", value=repr(params.volume_m3))
    ET.SubElement(out, "center_of_buoyancy", xyz=numbers_text(params.center_of_buoyancy_m))
    ET.SubElement(out, "added_mass", matrix=numbers_text(params.added_mass.ravel()))
    ET.SubElement(out, "linear_damping", matrix=numbers_text(params.linear_damping.ravel()))
    ET.SubElement(out, "quadratic_damping", diagonal=numbers_text(params.quadratic_damping))
    return out


def urdf_text(robot: ET.Element, source: str, not_mapped: Sequence[str]) -> str:
    """The URDF file: a comment naming the source and what was not mapped, then the robot."""
    ET.indent(robot, space="  ")
    lines = [f"Imported by uvms-pin import from {source}."]
    lines += (
        ["Not mapped:"] + [f"  - {n}" for n in not_mapped] if not_mapped else ["Everything mapped."]
    )
    comment = "\n".join(line.replace("--", "- -") for line in lines)
    body = ET.tostring(robot, encoding="unicode")
    return f'<?xml version="1.0"?>\n<!--\n{comment}\n-->\n{body}\n'


def _toml_vector(values: np.ndarray) -> str:
    return "[" + numbers_text(values, sep=", ") + "]"


def thruster_table_text(
    thrusters: Sequence[ImportedThruster], source: str, fluid_density_kg_m3: float | None
) -> str:
    """The thrusters as TOML for a scenario; a limit the source does not give is left as a
    comment (the scenario then refuses to load until it is set)."""
    lines = [f"# Thrusters imported by uvms-pin import from {source}", ""]
    if fluid_density_kg_m3 is not None:
        lines += ["[water]", f"density_kg_m3 = {fluid_density_kg_m3!r}", ""]
    lines.append("[actuation]")
    for thruster in thrusters:
        lines += [
            "",
            "[[actuation.thruster]]",
            f'name = "{thruster.name}"',
            f"position_body_m = {_toml_vector(thruster.position_body_m)}",
            f"direction_body = {_toml_vector(thruster.direction_body)}",
        ]
        for key, value in (
            ("max_forward_N", thruster.max_forward_N),
            ("max_reverse_N", thruster.max_reverse_N),
        ):
            lines.append(
                f"{key} = {value!r}"
                if value is not None
                else f"# {key} = ?  (not in the source: set it)"
            )
        if thruster.time_constant_s is not None:
            lines.append(
                f"time_constant_s = {thruster.time_constant_s!r}  # the source lags the rotor speed"
            )
        if thruster.thrust_coefficient is not None:
            lines.append(
                f"# {thruster.thrust_law} thrust coefficient in the source: {thruster.thrust_coefficient!r}"
            )
    return "\n".join(lines) + "\n"
