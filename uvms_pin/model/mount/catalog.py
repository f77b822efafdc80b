"""Arms that ``compare-arms`` knows by name: the reference arm and example-robot-data's.

example-robot-data ships URDFs and meshes (no Python loader); :func:`available_arms` lists
the catalogue entries whose files are installed. Any other name is taken as a URDF path.
Each entry says which link carries the F/T sensor and probe (the flange or tool frame of the
arm's own description); the tool axis is found from the last joint (``tool_axis="auto"`` of
`uvms_pin.model.mount.mount`). Gripper joints are locked by the mount.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from uvms_pin.errors import ParameterError
from uvms_pin.model.resources import example_robot_data_dir, shipped_path

__all__ = ["CATALOG", "REFERENCE", "ArmEntry", "available_arms", "resolve_arm"]

REFERENCE = "reference"


#: a table-top arm's base under a vehicle: turned over, its z axis down
UPSIDE_DOWN = (math.pi, 0.0, 0.0)


@dataclass(frozen=True)
class ArmEntry:
    """One arm: where its URDF is and how to mount it.

    Attributes:
        name: short name used on the command line.
        relative_path: URDF path under example-robot-data's ``robots/`` (or absolute for a
            user file).
        ee_link: the link carrying the sensor and probe (None: chosen by the mount).
        arm_base_link: the link bolted to the vehicle (None: the URDF's root).
        description: a few words for the report.
        shipped: the URDF ships with uvms-pin (``relative_path`` under its ``models/``).
        mount_rpy_rad: how its base is bolted under a vehicle, roll, pitch, yaw of the base
            frame in the vehicle's [rad]: a table-top arm upside down, (pi, 0, 0), its base's
            z axis down so that it hangs under the hull (the default); an arm built for
            vehicles as its maker mounts it.
    """

    name: str
    relative_path: str
    ee_link: str | None = None
    arm_base_link: str | None = None
    description: str = ""
    shipped: bool = False
    mount_rpy_rad: tuple[float, float, float] = UPSIDE_DOWN

    @property
    def urdf(self) -> Path:
        path = Path(self.relative_path)
        if path.is_absolute():
            return path
        if self.shipped:
            return shipped_path(Path("models") / path)
        root = example_robot_data_dir()
        if root is None:
            raise ParameterError(
                f"arm '{self.name}' needs example-robot-data, which is not installed"
            )
        return root / "robots" / path


CATALOG: dict[str, ArmEntry] = {
    e.name: e
    for e in (
        ArmEntry("so100", "so_arm_description/urdf/so100.urdf", "gripper", None, "SO-100, 5 DoF"),
        ArmEntry(
            "so101", "so_arm_description/urdf/so101.urdf", "gripper_link", None, "SO-101, 5 DoF"
        ),
        ArmEntry("z1", "z1_description/urdf/z1.urdf", "link06", None, "Unitree Z1, 6 DoF"),
        ArmEntry(
            "kinova",
            "kinova_description/robots/kinova.urdf",
            "j2s6s200_end_effector",
            None,
            "Kinova Jaco2 j2s6s200, 6 DoF",
        ),
        ArmEntry("ur3", "ur_description/urdf/ur3_robot.urdf", "tool0", None, "UR3, 6 DoF"),
        ArmEntry("ur5", "ur_description/urdf/ur5_robot.urdf", "tool0", None, "UR5, 6 DoF"),
        ArmEntry("ur10", "ur_description/urdf/ur10_robot.urdf", "tool0", None, "UR10, 6 DoF"),
        ArmEntry(
            "panda",
            "panda_description/urdf/panda.urdf",
            "panda_hand_tcp",
            None,
            "Franka Panda, 7 DoF",
        ),
        ArmEntry(
            "xarm7", "xarm_description/urdf/xarm7.urdf", "link_eef", None, "UFactory xArm7, 7 DoF"
        ),
        ArmEntry(
            "alpha5",
            "reach_alpha5.urdf",
            "alpha_wrist_link",
            None,
            "Reach Alpha 5, 4 DoF + locked jaw (shipped)",
            shipped=True,
            # as Reach mounts it on the BlueROV2 (and models/uvms_bluerov2_alpha5.urdf does):
            # its base frame the vehicle's, the arm reaching forward
            mount_rpy_rad=(0.0, 0.0, 0.0),
        ),
    )
}


def available_arms() -> list[str]:
    """Names accepted by ``compare-arms`` whose files are installed (reference first)."""
    names = [REFERENCE] + [n for n, e in CATALOG.items() if e.shipped]
    if example_robot_data_dir() is not None:
        names += [n for n, e in CATALOG.items() if not e.shipped and e.urdf.is_file()]
    return names


def resolve_arm(name: str | ArmEntry) -> ArmEntry:
    """A catalogue entry, or an entry for a URDF path (an ArmEntry is returned as it is).

    Raises:
        ParameterError: neither a known name nor an existing file.
    """
    if isinstance(name, ArmEntry):
        if not name.urdf.is_file():
            raise ParameterError(f"arm '{name.name}': URDF '{name.urdf}' not found")
        return name
    if name in CATALOG:
        return CATALOG[name]
    path = Path(name)
    if path.suffix.lower() == ".urdf" or path.is_file():
        if not path.is_file():
            raise ParameterError(f"arm URDF '{name}' not found")
        return ArmEntry(path.stem, str(path.resolve()), description=f"user URDF {path.name}")
    raise ParameterError(
        f"unknown arm '{name}': give a URDF path or one of {', '.join(available_arms())}"
    )
