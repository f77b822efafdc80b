"""Fixtures (articulated bodies with a fixed root) as the tests pose them: a lever on a
horizontal axis, whose weight is a known torque on its joint."""

from __future__ import annotations

from pathlib import Path

from conftest import ROOT

VALVE = ROOT / "models" / "fixtures" / "subsea_panel_valve.urdf"
RECEPTACLE = ROOT / "models" / "fixtures" / "hot_stab_receptacle.urdf"

#: the lever's mass [kg] at LEVER_ARM_M along its x from the axis, the axis along y
LEVER_MASS_KG, LEVER_ARM_M, LEVER_OWN_IYY = 1.0, 0.1, 1.0e-4


def lever_urdf(
    folder: Path,
    *,
    friction_Nm: float,
    damping: float = 0.0,
    limits: tuple[float, float] = (-1.0, 1.0),
    joint_type: str = "revolute",
    name: str = "lever",
    volume_m3: float = 0.0,
) -> Path:
    """A URDF: a fixed ``base`` and a ``lever`` on the revolute joint ``hinge`` about y,
    its mass LEVER_MASS_KG at LEVER_ARM_M along x: at q = 0 its weight is a torque
    m g d about +y (q grows as it falls), its inertia about the axis m d^2 + LEVER_OWN_IYY.
    Dry (no <hydrodynamics>): its weight alone acts; with ``volume_m3`` > 0 its lever has a
    <hydrodynamics> element of that volume, buoyant at its mass."""
    m, d, iyy = LEVER_MASS_KG, LEVER_ARM_M, LEVER_OWN_IYY
    limit = (
        f'<limit lower="{limits[0]!r}" upper="{limits[1]!r}" effort="100" velocity="10"/>'
        if joint_type != "floating"
        else ""
    )
    text = f"""<robot name="{name}">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision>
  </link>
  <joint name="hinge" type="{joint_type}">
    <parent link="base"/><child link="lever"/>
    <origin xyz="0 0 0"/><axis xyz="0 1 0"/>
    {limit}
    <dynamics damping="{damping!r}" friction="{friction_Nm!r}"/>
  </joint>
  <link name="lever">
    <inertial><origin xyz="{d!r} 0 0"/><mass value="{m!r}"/>
      <inertia ixx="1e-4" iyy="{iyy!r}" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="{d!r} 0 0"/><geometry><box size="0.02 0.02 0.02"/></geometry></collision>
  </link>
</robot>
"""
    if volume_m3 > 0.0:
        hydro = (
            f'<hydrodynamics><volume value="{volume_m3!r}"/>'
            f'<center_of_buoyancy xyz="{d!r} 0 0"/></hydrodynamics>'
        )
        text = text.replace("</link>\n</robot>", f"  {hydro}\n  </link>\n</robot>")
    path = folder / f"{name}.urdf"
    path.write_text(text)
    return path


def double_lever_urdf(folder: Path, *, friction_Nm: float) -> Path:
    """``lever_urdf``'s lever with a second lever on its end (joint ``elbow``, about y, at
    LEVER_ARM_M), both with the Coulomb friction ``friction_Nm``: two coupled joints."""
    path = lever_urdf(folder, friction_Nm=friction_Nm, name="double")
    d, m = LEVER_ARM_M, LEVER_MASS_KG
    second = f"""  <joint name="elbow" type="revolute">
    <parent link="lever"/><child link="tip"/>
    <origin xyz="{d!r} 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1.0" upper="1.0" effort="100" velocity="10"/>
    <dynamics damping="0.0" friction="{friction_Nm!r}"/>
  </joint>
  <link name="tip">
    <inertial><origin xyz="{d!r} 0 0"/><mass value="{m!r}"/>
      <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
</robot>
"""
    path.write_text(path.read_text().replace("</robot>\n", second))
    return path
