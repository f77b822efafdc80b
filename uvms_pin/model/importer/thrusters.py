"""Thruster plugins as `ImportedThruster`: where each pushes, along which axis, how hard.

- uuv_simulator (``libuuv_thruster_ros_plugin.so``, ThrusterPlugin.cc): the force acts along
  the x axis of the thruster link (``<linkName>``), at its origin; the command x passes a
  first-order filter (``<dynamics><type>FirstOrder</type><timeConstant>``) and the thrust is
  ``<conversion><type>Basic</type><rotorConstant>`` k: T = k x |x|; ``<thrustMin>``,
  ``<thrustMax>`` clamp the thrust (unbounded by default).
- gz-sim (``gz::sim::systems::Thruster``): the force acts along the axis of ``<joint_name>``
  at the joint; the command is the thrust itself, bounded by ``<min_thrust_cmd>``,
  ``<max_thrust_cmd>`` (default -1000, 1000 N); the propeller turns at omega with
  T = K_T rho D^4 omega^2 (``<thrust_coefficient>``, ``<fluid_density>``,
  ``<propeller_diameter>``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError
from uvms_pin.model.importer.result import ImportedThruster
from uvms_pin.model.importer.tree import axis_of
from uvms_pin.model.importer.xml import child_text

__all__ = ["GZ_DEFAULT_THRUST_LIMIT_N", "gz_thruster", "uuv_thruster"]

#: gz-sim Thruster's default command bounds [N] (cmdMin, cmdMax in Thruster.cc).
GZ_DEFAULT_THRUST_LIMIT_N = 1000.0


def _number(parent: ET.Element, tag: str, where: str, name: str) -> float | None:
    text = child_text(parent, tag)
    if text is None:
        return None
    try:
        value = float(text)
    except ValueError as exc:
        raise ModelError(
            f"thruster '{name}': <{tag}> is not a number: '{text}'", path=where
        ) from exc
    if not np.isfinite(value):
        raise ModelError(f"thruster '{name}': <{tag}> is not finite", path=where)
    return value


def uuv_thruster(
    plugin: ET.Element, placements: dict[str, pin.SE3], where: str, notes: list[str]
) -> ImportedThruster:
    """A uuv_simulator thruster plugin; ``placements`` are the links' in the root frame."""
    link = child_text(plugin, "linkName")
    if link is None or link not in placements:
        raise ModelError(f"thruster plugin names no known <linkName> ({link!r})", path=where)
    placement = placements[link]
    dynamics = plugin.find("dynamics")
    conversion = plugin.find("conversion")
    time_constant = None
    if dynamics is not None and child_text(dynamics, "type") == "FirstOrder":
        time_constant = _number(dynamics, "timeConstant", where, link)
    elif dynamics is not None:
        notes.append(
            f"thruster '{link}': dynamics type {child_text(dynamics, 'type')!r} not mapped"
        )
    law, coefficient = "quadratic", None
    if conversion is not None and child_text(conversion, "type") == "Basic":
        coefficient = _number(conversion, "rotorConstant", where, link)
    elif conversion is not None:
        law = str(child_text(conversion, "type"))
        notes.append(f"thruster '{link}': conversion type {law!r} not mapped (only Basic)")
    thrust_min = _number(plugin, "thrustMin", where, link)
    thrust_max = _number(plugin, "thrustMax", where, link)
    for tag in ("gain", "clampMin", "clampMax", "thrust_efficiency", "propeller_efficiency"):
        if plugin.find(tag) is not None:
            notes.append(f"thruster '{link}': <{tag}> not mapped")
    return ImportedThruster(
        name=link,
        position_body_m=placement.translation.copy(),
        direction_body=placement.rotation[:, 0].copy(),
        time_constant_s=time_constant,
        thrust_law=law,
        thrust_coefficient=coefficient,
        max_forward_N=thrust_max,
        max_reverse_N=None if thrust_min is None else -thrust_min,
    )


def gz_thruster(
    plugin: ET.Element,
    joints: dict[str, ET.Element],
    placements: dict[str, pin.SE3],
    where: str,
    notes: list[str],
) -> ImportedThruster:
    """A gz-sim Thruster system; ``joints`` by name, ``placements`` in the root frame."""
    name = child_text(plugin, "joint_name")
    if name is None or name not in joints:
        raise ModelError(f"Thruster system names no known <joint_name> ({name!r})", path=where)
    child = joints[name].find("child").get("link")
    placement = placements[child]
    k_t = _number(plugin, "thrust_coefficient", where, name)
    rho = _number(plugin, "fluid_density", where, name)
    diameter = _number(plugin, "propeller_diameter", where, name)
    coefficient = None
    if k_t is not None and rho is not None and diameter is not None:
        # in numpy: an overflow is inf (Python's ** raises), refused below by name
        with np.errstate(over="ignore"):
            coefficient = float(np.float64(k_t) * rho * np.float64(diameter) ** 4)
        if not np.isfinite(coefficient):
            raise ModelError(
                f"thruster '{name}': <thrust_coefficient> x <fluid_density> x "
                f"<propeller_diameter>^4 = {k_t:g} x {rho:g} x {diameter:g}^4 is not a finite "
                "number",
                path=where,
            )
    upper = _number(plugin, "max_thrust_cmd", where, name)
    lower = _number(plugin, "min_thrust_cmd", where, name)
    for tag in (
        "use_angvel_cmd",
        "velocity_control",
        "deadband",
        "wake_fraction",
        "alpha_1",
        "alpha_2",
    ):
        if plugin.find(tag) is not None:
            notes.append(f"thruster '{name}': <{tag}> not mapped")
    return ImportedThruster(
        name=name,
        position_body_m=placement.translation.copy(),
        direction_body=placement.rotation @ axis_of(joints[name], where),
        time_constant_s=None,
        thrust_law="commanded thrust",
        thrust_coefficient=coefficient,
        max_forward_N=GZ_DEFAULT_THRUST_LIMIT_N if upper is None else upper,
        max_reverse_N=GZ_DEFAULT_THRUST_LIMIT_N if lower is None else -lower,
    )
