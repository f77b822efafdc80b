"""A parallel jaw on a heavy vehicle, as the grasp tests pose it: two prismatic fingers whose
pads stay parallel, so a block between them is held by exactly 2 mu F; and the shipped
Alpha 5 jaw on the same vehicle."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

#: the hull: a 1 x 1 x 0.5 m box (512 kg of water), heavy so that it hardly moves
HULL_M = (1.0, 1.0, 0.5)
#: each finger: a 2 x 1 x 8 cm pad below the hull, sliding along y, closed 1 cm off the centre
PAD_M = (0.02, 0.01, 0.08)
FINGER_MASS_KG = 0.05
FINGER_Z_M = -0.26  # the pads' top, in the hull frame
CLOSED_Y_M = 0.01  # each pad's inner face at q = 0
TRAVEL_M = 0.03
WATER_KG_M3 = 1025.0


def _finger(side: str, sign: float) -> str:
    y = sign * PAD_M[1] / 2
    box = f'<geometry><box size="{PAD_M[0]} {PAD_M[1]} {PAD_M[2]}"/></geometry>'
    origin = f'<origin xyz="0 {y} {-PAD_M[2] / 2}" rpy="0 0 0"/>'
    return f"""
  <link name="{side}_finger">
    <inertial>{origin}<mass value="{FINGER_MASS_KG}"/>
      <inertia ixx="2.7e-5" iyy="2.8e-5" izz="2e-6" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision>{origin}{box}</collision>
  </link>
  <joint name="{side}_finger_joint" type="prismatic">
    <parent link="base_link"/><child link="{side}_finger"/>
    <origin xyz="0 {sign * CLOSED_Y_M} {FINGER_Z_M}" rpy="0 0 0"/>
    <axis xyz="0 {sign} 0"/>
    <limit lower="0" upper="{TRAVEL_M}" effort="100" velocity="1"/>
  </joint>"""


def _hull_link(jaw_volume_m3: float, jaw_mass_kg: float) -> str:
    """The hull's base_link, heavy enough that the UVMS with a jaw of this volume and mass
    is neutrally buoyant, its CoG 5 cm below the hull's centre."""
    hull_volume = HULL_M[0] * HULL_M[1] * HULL_M[2]
    mass = WATER_KG_M3 * (hull_volume + jaw_volume_m3) - jaw_mass_kg
    ixx = mass * (HULL_M[1] ** 2 + HULL_M[2] ** 2) / 12
    izz = mass * (HULL_M[0] ** 2 + HULL_M[1] ** 2) / 12
    return f"""
  <link name="base_link">
    <inertial><origin xyz="0 0 -0.05" rpy="0 0 0"/><mass value="{mass}"/>
      <inertia ixx="{ixx}" iyy="{ixx}" izz="{izz}" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="{HULL_M[0]} {HULL_M[1]} {HULL_M[2]}"/></geometry></collision>
  </link>"""


def parallel_jaw_urdf(folder: Path) -> Path:
    """Write the vehicle with its parallel jaw to ``folder``; neutrally buoyant, CoG 5 cm
    below the hull's centre (hydrodynamics derived from the collision boxes)."""
    pad_volume = PAD_M[0] * PAD_M[1] * PAD_M[2]
    hull = _hull_link(2 * pad_volume, 2 * FINGER_MASS_KG)
    text = f"""<?xml version="1.0"?>
<robot name="parallel_jaw">{hull}{_finger("left", 1.0)}{_finger("right", -1.0)}
</robot>
"""
    path = Path(folder) / "parallel_jaw.urdf"
    path.write_text(text)
    return path


#: the shipped Alpha 5 jaw (its two fingers as models/reach_alpha5_jaws.urdf has them)
ALPHA5_JAWS_URDF = Path(__file__).resolve().parents[1] / "models" / "reach_alpha5_jaws.urdf"
#: the Alpha 5 jaw's base below the hull's centre, pointing down [m]
ALPHA5_JAW_Z_M = -0.26


def _alpha5_fingers() -> tuple[str, float, float]:
    """(the finger links and joints as URDF text, their mass [kg], their boxes' volume
    [m^3]) taken from the shipped file."""
    root = ET.parse(ALPHA5_JAWS_URDF).getroot()
    text, mass, volume = "", 0.0, 0.0
    for link in root.findall("link"):
        if "finger" in link.get("name"):
            mass += float(link.find("inertial/mass").get("value"))
            for box in link.findall("collision/geometry/box"):
                volume += math.prod(float(s) for s in box.get("size").split())
            text += ET.tostring(link, encoding="unicode")
    for joint in root.findall("joint"):
        if "finger" in joint.get("name"):
            text += ET.tostring(joint, encoding="unicode")
    return text, mass, volume


def alpha5_jaw_urdf(folder: Path) -> Path:
    """Write the heavy hull of `parallel_jaw_urdf` with the shipped Alpha 5 jaw below it,
    pointing down (its fingers close along y, their pivot axes along x); neutrally buoyant."""
    fingers, finger_mass, finger_volume = _alpha5_fingers()
    text = f"""<?xml version="1.0"?>
<robot name="alpha5_jaw_rig">{_hull_link(finger_volume, finger_mass)}
  <link name="alpha_jaw_base_link"/>
  <joint name="alpha_jaw_base_joint" type="fixed">
    <parent link="base_link"/><child link="alpha_jaw_base_link"/>
    <origin xyz="0 0 {ALPHA5_JAW_Z_M}" rpy="{math.pi} 0 0"/>
  </joint>
  {fingers}
</robot>
"""
    path = Path(folder) / "alpha5_jaw.urdf"
    path.write_text(text)
    return path
