"""The tool on the wrist: the F/T sensor frame with its x axis along the tool axis, a probe
(a solid cylinder) and the end-effector frame ``ee`` at its tip, x forward along the probe."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from uvms_pin.checks import positive
from uvms_pin.errors import ParameterError
from uvms_pin.model.mount.origin import add_fixed_joint, origin_of, vector_attribute
from uvms_pin.model.mount.tree import URDFTree
from uvms_pin.results.format import numbers_text

__all__ = [
    "AXES",
    "REFERENCE_PROBE",
    "ProbeTool",
    "add_tool_frames",
    "probe_link",
    "rotation_with_x",
    "tool_axis_in_link",
]

#: The tool axes that can be named, in the wrist link's frame.
AXES = {
    "x": (1.0, 0.0, 0.0),
    "y": (0.0, 1.0, 0.0),
    "z": (0.0, 0.0, 1.0),
    "-x": (-1.0, 0.0, 0.0),
    "-y": (0.0, -1.0, 0.0),
    "-z": (0.0, 0.0, -1.0),
}


@dataclass(frozen=True)
class ProbeTool:
    """A rigid probe on the wrist: a solid cylinder along the tool axis, tip = ``ee``.

    Defaults are the reference arm's probe (models/README.md section 3): 0.08 m long,
    radius 8 mm, 50 g (steel-tipped, slightly heavier than the water it displaces).
    """

    length_m: float = 0.08
    radius_m: float = 0.008
    mass_kg: float = 0.05

    def __post_init__(self) -> None:
        for name in ("length_m", "radius_m", "mass_kg"):
            positive(f"ProbeTool.{name}", getattr(self, name))


#: The default tool of a mount: the reference arm's probe.
REFERENCE_PROBE = ProbeTool()


def tool_axis_in_link(
    arm: URDFTree, tool_axis: str | Sequence[float], chain: list[str], ee: str, path: Path
) -> np.ndarray:
    """The unit tool axis in link ``ee``'s frame: a named axis (`AXES`), a 3-vector, or
    "auto" (the last joint of ``chain``'s axis, pointing away from the arm)."""
    if isinstance(tool_axis, str):
        if tool_axis in AXES:
            return np.array(AXES[tool_axis])
        if tool_axis != "auto":
            raise ParameterError(
                f"tool_axis must be 'auto', one of {', '.join(AXES)} or a 3-vector, got {tool_axis!r}"
            )
        return _auto_tool_axis(arm, chain, ee, path)
    axis = np.asarray(tool_axis, dtype=float).reshape(-1)
    norm = float(np.linalg.norm(axis)) if axis.shape == (3,) else 0.0
    if axis.shape != (3,) or not np.all(np.isfinite(axis)) or norm == 0.0:
        raise ParameterError(f"tool_axis must be a non-zero finite 3-vector, got {tool_axis!r}")
    return axis / norm


def _auto_tool_axis(arm: URDFTree, chain: list[str], ee: str, path: Path) -> np.ndarray:
    """The last chain joint's axis in ``ee``'s frame, pointing away from the arm (from the
    joint before it, or the base, towards ``ee``), all at the zero configuration."""
    last = chain[-1]
    base = arm.parent_of(chain[0])
    placements = _placements_along(arm, arm.path_joints(base, ee), path)
    joint_frame = placements[arm.child_of(last)]  # the last joint's frame (zero position)
    ee_frame = placements[ee]
    axis_joint = vector_attribute(arm.joints[last].find("axis"), "xyz", "1 0 0", path, last)
    axis_base = joint_frame.rotation @ (axis_joint / np.linalg.norm(axis_joint))
    if len(chain) > 1:
        prev = placements[arm.child_of(chain[-2])].translation
    else:
        prev = np.zeros(3)
    away = ee_frame.translation - prev
    if float(axis_base @ away) < 0.0:
        axis_base = -axis_base
    axis = ee_frame.rotation.T @ axis_base
    return axis / np.linalg.norm(axis)


def _placements_along(arm: URDFTree, joints: list[str], path: Path) -> dict[str, pin.SE3]:
    """Placements (zero configuration) of every link on the path, relative to its start."""
    out = {}
    current = pin.SE3.Identity()
    for joint in joints:
        current = current * origin_of(arm.joints[joint], path)
        out[arm.child_of(joint)] = current
    return out


def rotation_with_x(axis: np.ndarray) -> np.ndarray:
    """A rotation whose x column is ``axis`` (the y column as close to the link's y as it can)."""
    x = axis / np.linalg.norm(axis)
    helper = np.array([0.0, 1.0, 0.0]) if abs(x[1]) < 0.9 else np.array([0.0, 0.0, 1.0])
    y = helper - (helper @ x) * x
    y /= np.linalg.norm(y)
    return np.column_stack([x, y, np.cross(x, y)])


def probe_link(name: str, tool: ProbeTool) -> ET.Element:
    """A solid cylinder along x from the origin: inertial and collision (hydro derived).

    Inertia at its centre: I_xx = m r^2 / 2 about its axis, I_yy = I_zz = m (3 r^2 + L^2) / 12.
    """
    r, length, m = tool.radius_m, tool.length_m, tool.mass_kg
    ixx = 0.5 * m * r * r
    iyy = m * (3.0 * r * r + length * length) / 12.0
    link = ET.Element("link", {"name": name})
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "origin", {"xyz": numbers_text([length / 2, 0, 0]), "rpy": "0 0 0"})
    ET.SubElement(inertial, "mass", {"value": repr(m)})
    ET.SubElement(
        inertial,
        "inertia",
        {"ixx": repr(ixx), "iyy": repr(iyy), "izz": repr(iyy), "ixy": "0", "ixz": "0", "iyz": "0"},
    )
    for tag in ("visual", "collision"):
        el = ET.SubElement(link, tag)
        # URDF cylinders lie along z: turned about y onto x, centred half-way to the tip
        ET.SubElement(
            el,
            "origin",
            {"xyz": numbers_text([length / 2, 0, 0]), "rpy": numbers_text([0, math.pi / 2, 0])},
        )
        geom = ET.SubElement(el, "geometry")
        ET.SubElement(geom, "cylinder", {"radius": repr(r), "length": repr(length)})
    return link


def add_tool_frames(
    out: ET.Element,
    frames: dict[str, str],
    wrist_link: str,
    sensor_link: str | None,
    tool: ProbeTool | None,
    axis: np.ndarray,
) -> tuple[str, str]:
    """Append the sensor frame (unless the arm's ``sensor_link`` is used), the tool and the
    ``ee`` frame to ``out``; returns (sensor frame, ee frame).

    Args:
        frames: the names of the added frames (`names.unique_frame_names`).
        wrist_link: the link carrying the sensor (``ee_link``, merged-file name).
        sensor_link: an arm link to use as the sensor frame (merged-file name), or None.
        tool: the probe, or None (``ee`` is the sensor frame, or ``wrist_link`` itself when
            it is named as the ee frame).
        axis: the unit tool axis in ``wrist_link``'s frame: the sensor frame's x.
    """
    rot_tool = rotation_with_x(axis)
    if sensor_link is None:
        sensor_frame = frames["ft_sensor"]
        out.append(ET.Element("link", {"name": sensor_frame}))
        sensor_placement = pin.SE3(rot_tool, np.zeros(3))
        add_fixed_joint(out, frames["ft_sensor_joint"], wrist_link, sensor_frame, sensor_placement)
    else:
        sensor_frame = sensor_link
    ee_frame = frames["ee"]
    if tool is not None:
        out.append(probe_link(frames["tool"], tool))
        add_fixed_joint(out, frames["tool_joint"], sensor_frame, frames["tool"], pin.SE3.Identity())
        out.append(ET.Element("link", {"name": ee_frame}))
        tip = pin.SE3(np.eye(3), np.array([tool.length_m, 0, 0]))
        add_fixed_joint(out, frames["ee_joint"], frames["tool"], ee_frame, tip)
    elif wrist_link != ee_frame:
        out.append(ET.Element("link", {"name": ee_frame}))
        add_fixed_joint(out, frames["ee_joint"], sensor_frame, ee_frame, pin.SE3.Identity())
    return sensor_frame, ee_frame
