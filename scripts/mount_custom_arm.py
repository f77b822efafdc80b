"""Mount your own arm URDF on the LBV150 and run the force task with it (headless).

    .venv/bin/python scripts/mount_custom_arm.py                    # a built-in example arm
    .venv/bin/python scripts/mount_custom_arm.py --arm my_arm.urdf --ee-link flange \\
        --mount-rpy 3.1416 0 0 --duration 3 --out out/my_arm

Without ``--arm`` the script writes a small 5-DoF example arm into a temporary directory: two
aluminium tubes (cylinders), a wrist whose collision geometry is an STL mesh referenced by a
relative path (its hydrodynamic coefficients are derived from the mesh), and a roll flange.
It then

1. splits the scenario's model into the vehicle and the reference arm (`split_urdf`),
2. mounts the arm (`mount_arm_detailed`) with automatic trim, prints the model summary
   (derived coefficients are marked with *) and the trim report,
3. runs the scenario's task with the reference arm and with this arm (`compare_arms`: the
   initial configuration is solved so that the probe touches the same contact point) and
   writes comparison.csv / .md / .png into ``--out``.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

# link: (length [m], radius [m], mass [kg]); aluminium tubes with motors, partly foam-filled
_TUBES = {
    "shoulder": (0.06, 0.03, 0.25),
    "upper_arm": (0.25, 0.025, 0.45),
    "forearm": (0.22, 0.022, 0.35),
}
# joint: (parent, child, origin xyz in parent, axis, lower, upper, effort N m, velocity rad/s)
_JOINTS = [
    ("j1_yaw", "base", "shoulder", (0.0, 0.0, 0.0), (0, 0, 1), -1.6, 1.6, 12.0, 1.5),
    ("j2_pitch", "shoulder", "upper_arm", (0.06, 0.0, 0.0), (0, 1, 0), -0.3, 2.2, 12.0, 1.5),
    ("j3_pitch", "upper_arm", "forearm", (0.25, 0.0, 0.0), (0, 1, 0), -2.2, 2.2, 8.0, 2.0),
    ("j4_pitch", "forearm", "wrist", (0.22, 0.0, 0.0), (0, 1, 0), -1.8, 1.8, 4.0, 2.0),
    ("j5_roll", "wrist", "flange", (0.07, 0.0, 0.0), (1, 0, 0), -2.6, 2.6, 3.0, 2.0),
]


def _inertial(mass: float, length: float, radius: float) -> str:
    ixx = 0.5 * mass * radius**2
    iyy = mass * (3 * radius**2 + length**2) / 12
    return (
        f'<inertial><origin xyz="{length / 2} 0 0"/><mass value="{mass}"/>'
        f'<inertia ixx="{ixx:.6g}" iyy="{iyy:.6g}" izz="{iyy:.6g}" ixy="0" ixz="0" iyz="0"/>'
        "</inertial>"
    )


def write_example_arm(directory: Path) -> Path:
    """A 5-DoF arm URDF with a mesh-collision wrist (relative path) in ``directory``."""
    import trimesh

    meshes = directory / "meshes"
    meshes.mkdir(parents=True, exist_ok=True)
    # the wrist housing: a rounded 7 cm box, centred at x = 3.5 cm
    wrist = trimesh.creation.box(extents=(0.07, 0.05, 0.05))
    wrist.apply_translation((0.035, 0.0, 0.0))
    wrist.export(meshes / "wrist.stl")
    parts = ['<robot name="example_arm">', '  <link name="base"/>']
    for name, (length, radius, mass) in _TUBES.items():
        parts.append(
            f'  <link name="{name}">{_inertial(mass, length, radius)}'
            f'<collision><origin xyz="{length / 2} 0 0" rpy="0 {math.pi / 2} 0"/>'
            f'<geometry><cylinder radius="{radius}" length="{length}"/></geometry></collision>'
            "</link>"
        )
    parts.append(
        f'  <link name="wrist">{_inertial(0.2, 0.07, 0.025)}'
        '<collision><geometry><mesh filename="meshes/wrist.stl"/></geometry></collision></link>'
    )
    parts.append(
        f'  <link name="flange">{_inertial(0.05, 0.02, 0.02)}'
        '<collision><origin xyz="0.01 0 0" rpy="0 1.5707963 0"/>'
        '<geometry><cylinder radius="0.02" length="0.02"/></geometry></collision></link>'
    )
    parts.append('  <link name="flange_face"/>')
    for name, parent, child, xyz, axis, lo, hi, effort, vel in _JOINTS:
        parts.append(
            f'  <joint name="{name}" type="revolute"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}"/>'
            f'<axis xyz="{axis[0]} {axis[1]} {axis[2]}"/>'
            f'<limit lower="{lo}" upper="{hi}" effort="{effort}" velocity="{vel}"/></joint>'
        )
    parts.append(
        '  <joint name="flange_face_joint" type="fixed"><parent link="flange"/>'
        '<child link="flange_face"/><origin xyz="0.02 0 0"/></joint>'
    )
    parts.append("</robot>")
    path = directory / "example_arm.urdf"
    path.write_text("\n".join(parts) + "\n")
    return path


def main(argv: list[str] | None = None) -> int:
    from uvms_pin.apps.arms.compare import CompareSettings, compare_arms
    from uvms_pin.errors import UvmsPinError
    from uvms_pin.model.mount.catalog import ArmEntry
    from uvms_pin.model.mount.mount import mount_arm_detailed
    from uvms_pin.model.mount.split import split_urdf
    from uvms_pin.model.summary import model_summary
    from uvms_pin.model.trim import TrimSpec
    from uvms_pin.scenario.load import load_scenario

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--arm", help="your arm URDF (default: a built-in example arm)")
    parser.add_argument("--ee-link", default=None, help="flange link (default: flange_face / auto)")
    parser.add_argument("--mount-rpy", type=float, nargs=3, default=(0.0, 0.0, 0.0))
    parser.add_argument(
        "--scenario", default=str(ROOT / "scenarios" / "realistic_force_tracking.toml")
    )
    parser.add_argument("--duration", type=float, default=2.0, help="simulated time [s]")
    parser.add_argument("--out", default=str(ROOT / "out" / "mount_custom_arm"))
    args = parser.parse_args(argv)

    with tempfile.TemporaryDirectory(prefix="custom_arm_") as tmp:
        tmp = Path(tmp)
        if args.arm is None:
            arm = write_example_arm(tmp / "example_arm")
            ee_link = args.ee_link or "flange_face"
        else:
            arm, ee_link = Path(args.arm), args.ee_link
        try:
            scenario = load_scenario(args.scenario)
            split = split_urdf(scenario.uvms.source, tmp / "split")
            pose = (split.mount_pose.translation, np.asarray(args.mount_rpy))
            result = mount_arm_detailed(
                split.vehicle_urdf, arm, pose, ee_link=ee_link, trim=TrimSpec(bg_m=0.02)
            )
            print(model_summary(result.uvms))
            print(f"\narm joints: {', '.join(result.arm_joints)}; locked: {result.locked_joints}")
            print(f"tool axis in {result.ee_link}: {result.tool_axis_in_ee_link}")
            print("trim (neutral arm configuration):\n" + result.trim.summary())
            # the task: the comparison solves the initial configuration and trims there
            entry = ArmEntry("custom", str(Path(arm).resolve()), ee_link, None, "your arm")
            rows = compare_arms(
                args.scenario,
                ["reference", entry],
                args.out,
                CompareSettings(duration_s=args.duration, mount_rpy=tuple(args.mount_rpy)),
            )
        except UvmsPinError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
    for row in rows:
        rms = row["force_error_rms_N"]
        error = f"force error RMS {rms:.3f} N" if rms is not None and math.isfinite(rms) else ""
        print(f"{row['arm']:<10} {row['status']:<16} {error:<24}  {row['reason']}")
    print(f"wrote {args.out}/comparison.csv, comparison.md, comparison.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
