"""A parallel jaw on a heavy vehicle, as the grasp tests pose it: two prismatic fingers whose
pads stay parallel, so a block between them is held by exactly 2 mu F."""

from __future__ import annotations

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


def parallel_jaw_urdf(folder: Path) -> Path:
    """Write the vehicle with its parallel jaw to ``folder``; neutrally buoyant, CoG 5 cm
    below the hull's centre (hydrodynamics derived from the collision boxes)."""
    hull_volume = HULL_M[0] * HULL_M[1] * HULL_M[2]
    pad_volume = PAD_M[0] * PAD_M[1] * PAD_M[2]
    mass = WATER_KG_M3 * (hull_volume + 2 * pad_volume) - 2 * FINGER_MASS_KG
    ixx = mass * (HULL_M[1] ** 2 + HULL_M[2] ** 2) / 12
    izz = mass * (HULL_M[0] ** 2 + HULL_M[1] ** 2) / 12
    text = f"""<?xml version="1.0"?>
<robot name="parallel_jaw">
  <link name="base_link">
    <inertial><origin xyz="0 0 -0.05" rpy="0 0 0"/><mass value="{mass}"/>
      <inertia ixx="{ixx}" iyy="{ixx}" izz="{izz}" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="{HULL_M[0]} {HULL_M[1]} {HULL_M[2]}"/></geometry></collision>
  </link>{_finger("left", 1.0)}{_finger("right", -1.0)}
</robot>
"""
    path = Path(folder) / "parallel_jaw.urdf"
    path.write_text(text)
    return path
