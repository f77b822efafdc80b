"""Recompute every number of models/lbv150.urdf (the vehicle alone) and
models/uvms_lbv150.urdf (the same vehicle plus the arm): inertias, hydrodynamics, the trim.

Usage (from the repository root):

    .venv/bin/python models/derive_lbv150.py            # print the derivation, compare the URDFs
    .venv/bin/python models/derive_lbv150.py --write    # regenerate both URDFs
    .venv/bin/python models/derive_lbv150.py --check    # exit 1 if a URDF is out of date

To change the model, edit the constants in the "inputs" section below and run with --write;
models/README.md explains where each input comes from.
"""

from __future__ import annotations

import argparse
import itertools
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from uvms_pin.hydro.geometry import (  # noqa: E402
    box_hydro,
    cylinder_hydro,
    hydro_in_frame,
)
from uvms_pin.hydro.params import HydroParams  # noqa: E402

URDF_PATH = REPO / "models" / "uvms_lbv150.urdf"
VEHICLE_URDF_PATH = REPO / "models" / "lbv150.urdf"

# ----------------------------------------------------------------------------- inputs

WATER_DENSITY_KG_M3 = 1025.0  # sea water
GRAVITY_M_S2 = 9.81

# SeaBotix LBV150-4 published envelope and mass in air (models/README.md, section 1).
HULL_SIZE_M = (0.53, 0.245, 0.254)
HULL_MASS_KG = 11.0
# Mass concentrated low: the hull is modelled as two half-height slabs, the lower one
# (thrusters, electronics, ballast) heavier than the upper one (foam, camera dome).
HULL_UPPER_SLAB_MASS_KG = 4.5
HULL_COB_Z_M = 0.005  # centre of buoyancy above the hull's geometric centre (foam on top)
HULL_DRAG_COEFFICIENT = 1.05  # box face-on (Hoerner 1965; DNV-RP-C205 App. D)
# Roll added inertia of the hull: strip theory with the square-section coefficient
# 0.725 rho a^4 per unit length (a = half side; Newman 1977, Table 4.2). The equal-volume
# ellipsoid of box_hydro gives ~0 for a nearly square section.
SQUARE_SECTION_ROLL_COEFFICIENT = 0.725

# The arm: mounting point of arm_joint1 in base_link (front-bottom, on a bracket).
ARM_MOUNT_XYZ_M = (0.20, 0.0, -0.18)


@dataclass(frozen=True)
class CylinderLink:
    """An arm link modelled as a solid cylinder along +x from its frame origin."""

    name: str
    length_m: float
    radius_m: float
    mass_kg: float


ARM_LINKS = (
    CylinderLink("arm_link1", 0.07, 0.025, 0.16),  # shoulder (yaw) housing
    CylinderLink("arm_link2", 0.18, 0.025, 0.40),  # upper arm with the elbow motor
    CylinderLink("arm_link3", 0.15, 0.022, 0.26),  # forearm with the wrist motor
    CylinderLink("arm_link4", 0.08, 0.020, 0.12),  # wrist (roll) and F/T sensor body
)
TOOL = CylinderLink("tool", 0.08, 0.008, 0.05)  # probe, mounted on the F/T sensor

# ----------------------------------------------------------------------------- derivation


def _rot_y(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def link_hydro(link: CylinderLink) -> HydroParams:
    """cylinder_hydro at the cylinder centre, moved to the link origin (axis z -> link x)."""
    centre = cylinder_hydro(link.radius_m, link.length_m, WATER_DENSITY_KG_M3)
    return hydro_in_frame(centre, _rot_y(math.pi / 2.0), [link.length_m / 2.0, 0.0, 0.0])


def link_inertia(link: CylinderLink) -> np.ndarray:
    """Solid-cylinder inertia about the CoM: (m r^2/2, m(3r^2+L^2)/12, same) with axis x."""
    m, r, length = link.mass_kg, link.radius_m, link.length_m
    transverse = m * (3.0 * r * r + length * length) / 12.0
    return np.array([0.5 * m * r * r, transverse, transverse])


def hull_inertial() -> tuple[float, np.ndarray]:
    """CoM height and principal inertia (about the CoM) of the two-slab hull."""
    lx, ly, lz = HULL_SIZE_M
    m_up = HULL_UPPER_SLAB_MASS_KG
    m_low = HULL_MASS_KG - m_up
    z_up, z_low = lz / 4.0, -lz / 4.0
    z_com = (m_up * z_up + m_low * z_low) / HULL_MASS_KG
    h = lz / 2.0
    inertia = np.zeros(3)
    for m, z in ((m_up, z_up), (m_low, z_low)):
        d2 = (z - z_com) ** 2
        inertia += m * np.array(
            [
                (ly * ly + h * h) / 12.0 + d2,
                (lx * lx + h * h) / 12.0 + d2,
                (lx * lx + ly * ly) / 12.0,
            ]
        )
    return z_com, inertia


def link_origins_in_base() -> dict[str, np.ndarray]:
    """Origin of every arm link and of the tool in base_link, zero arm configuration."""
    origins = {}
    x = np.array(ARM_MOUNT_XYZ_M, dtype=float)
    for link in ARM_LINKS:
        origins[link.name] = x.copy()
        x = x + np.array([link.length_m, 0.0, 0.0])
    origins[TOOL.name] = x.copy()  # ft_sensor and tool sit at the end of arm_link4
    return origins


@dataclass(frozen=True)
class Trim:
    hull_volume_m3: float
    hull_com_x_m: float
    hull_com_z_m: float
    total_mass_kg: float
    total_volume_m3: float
    system_com_m: np.ndarray
    system_cob_m: np.ndarray


def trim() -> Trim:
    """Neutral buoyancy and zero pitch moment in the zero arm configuration.

    Hull volume: rho (V_hull + sum V_i) = m_hull + sum m_i.
    Hull CoM x (ballast position), with the hull CoB at x = 0:
        m_hull x_g,hull = rho sum V_i x_b,i - sum m_i x_g,i.
    """
    rho = WATER_DENSITY_KG_M3
    parts = (*ARM_LINKS, TOOL)
    origins = link_origins_in_base()
    masses = np.array([p.mass_kg for p in parts])
    volumes = np.array([link_hydro(p).volume_m3 for p in parts])
    centres = np.array([origins[p.name] + [p.length_m / 2.0, 0.0, 0.0] for p in parts])
    total_mass = HULL_MASS_KG + masses.sum()
    hull_volume = total_mass / rho - volumes.sum()
    hull_com_x = (rho * volumes @ centres[:, 0] - masses @ centres[:, 0]) / HULL_MASS_KG
    hull_com_z, _ = hull_inertial()
    hull_com = np.array([hull_com_x, 0.0, hull_com_z])
    hull_cob = np.array([0.0, 0.0, HULL_COB_Z_M])
    system_com = (HULL_MASS_KG * hull_com + masses @ centres) / total_mass
    system_cob = (hull_volume * hull_cob + volumes @ centres) / (hull_volume + volumes.sum())
    return Trim(
        hull_volume_m3=hull_volume,
        hull_com_x_m=hull_com_x,
        hull_com_z_m=hull_com_z,
        total_mass_kg=total_mass,
        total_volume_m3=hull_volume + volumes.sum(),
        system_com_m=system_com,
        system_cob_m=system_cob,
    )


def hull_hydro(t: Trim) -> HydroParams:
    """box_hydro of the hull envelope, with the trim volume/CoB and the strip-theory roll."""
    box = box_hydro(HULL_SIZE_M, WATER_DENSITY_KG_M3, drag_coefficient=HULL_DRAG_COEFFICIENT)
    lx, ly, lz = HULL_SIZE_M
    half_side = 0.25 * (ly + lz)
    k_p = SQUARE_SECTION_ROLL_COEFFICIENT * WATER_DENSITY_KG_M3 * half_side**4 * lx
    added = box.added_mass.copy()
    added[3, 3] = k_p
    return HydroParams(
        volume_m3=t.hull_volume_m3,
        center_of_buoyancy_m=np.array([0.0, 0.0, HULL_COB_Z_M]),
        added_mass=added,
        linear_damping=box.linear_damping,
        quadratic_damping=box.quadratic_damping,
        derived=True,
        origin="LBV150 hull envelope (box_hydro) + strip-theory roll added inertia",
    )


# ----------------------------------------------------------------------------- URDF text


def _num(x: float) -> str:
    """Six significant digits, no negative zero."""
    s = f"{x:.6g}"
    return "0" if s in ("-0", "0") else s


def _nums(values) -> str:
    return " ".join(_num(v) for v in np.asarray(values, dtype=float).reshape(-1))


def _is_diagonal(m: np.ndarray) -> bool:
    return bool(np.all(np.abs(m - np.diag(np.diag(m))) <= 1e-12 * max(1.0, np.abs(m).max())))


def _hydro_xml(h: HydroParams, indent: str) -> str:
    def six(tag: str, m: np.ndarray) -> str:
        if _is_diagonal(m):
            return f'{indent}  <{tag} diagonal="{_nums(np.diag(m))}"/>'
        return f'{indent}  <{tag} matrix="{_nums(m)}"/>'

    return "\n".join(
        [
            f"{indent}<hydrodynamics>",
            f'{indent}  <volume value="{_num(h.volume_m3)}"/>',
            f'{indent}  <center_of_buoyancy xyz="{_nums(h.center_of_buoyancy_m)}"/>',
            six("added_mass", h.added_mass),
            six("linear_damping", h.linear_damping),
            f'{indent}  <quadratic_damping diagonal="{_nums(h.quadratic_damping)}"/>',
            f"{indent}</hydrodynamics>",
        ]
    )


def _inertial_xml(mass: float, xyz, inertia_diag, indent: str) -> str:
    ixx, iyy, izz = inertia_diag
    return (
        f"{indent}<inertial>\n"
        f'{indent}  <origin xyz="{_nums(xyz)}" rpy="0 0 0"/>\n'
        f'{indent}  <mass value="{_num(mass)}"/>\n'
        f'{indent}  <inertia ixx="{_num(ixx)}" ixy="0" ixz="0" iyy="{_num(iyy)}" iyz="0" '
        f'izz="{_num(izz)}"/>\n'
        f"{indent}</inertial>"
    )


def _cylinder_link_xml(link: CylinderLink, material: str) -> str:
    half = _num(link.length_m / 2.0)
    geom = (
        f'      <origin xyz="{half} 0 0" rpy="0 1.5707963267949 0"/>\n'
        f"      <geometry>\n"
        f'        <cylinder radius="{_num(link.radius_m)}" length="{_num(link.length_m)}"/>\n'
        f"      </geometry>"
    )
    return (
        f'  <link name="{link.name}">\n'
        + _inertial_xml(link.mass_kg, [link.length_m / 2.0, 0, 0], link_inertia(link), "    ")
        + "\n"
        + f'    <visual>\n{geom}\n      <material name="{material}"/>\n    </visual>\n'
        + f"    <collision>\n{geom}\n    </collision>\n"
        + _hydro_xml(link_hydro(link), "    ")
        + "\n  </link>\n"
    )


# (name, parent, child, axis, lower, upper, effort N m, velocity rad/s, armature kg m^2)
# armature = reflected rotor inertia J_rotor N^2 of a geared joint motor: a small DC motor
# rotor of ~1e-6 kg m^2 behind a ~100:1 gearbox gives ~0.01 kg m^2 (shoulder, elbow);
# the wrist's smaller motor (~2e-7 kg m^2, 100:1) ~0.002 kg m^2. Estimates: replace with
# the data of the actual drives.
_ARM_JOINTS = (
    ("arm_joint1", "base_link", "arm_link1", "0 0 1", -1.6, 1.6, 10.0, 1.5, 0.01),
    ("arm_joint2", "arm_link1", "arm_link2", "0 1 0", -0.3, 2.0, 10.0, 1.5, 0.01),
    ("arm_joint3", "arm_link2", "arm_link3", "0 1 0", -1.5, 1.5, 6.0, 2.0, 0.005),
    ("arm_joint4", "arm_link3", "arm_link4", "1 0 0", -2.6, 2.6, 3.0, 2.0, 0.002),
)


_MATERIALS = (
    '  <material name="hull_yellow"><color rgba="1.0 0.78 0.05 1"/></material>',
    '  <material name="thruster_black"><color rgba="0.08 0.08 0.08 1"/></material>',
    '  <material name="dome_clear"><color rgba="0.55 0.75 0.95 0.5"/></material>',
    '  <material name="arm_gray"><color rgba="0.25 0.25 0.27 1"/></material>',
)
_ARM_MATERIALS = ('  <material name="probe_silver"><color rgba="0.78 0.78 0.80 1"/></material>',)


def render_vehicle_urdf() -> str:
    """models/lbv150.urdf: the vehicle alone (hull and arm bracket), the same base_link."""
    t = trim()
    arm_net_N = (
        t.total_mass_kg
        - HULL_MASS_KG
        - WATER_DENSITY_KG_M3 * (t.total_volume_m3 - t.hull_volume_m3)
    ) * GRAVITY_M_S2
    out = [
        '<?xml version="1.0"?>',
        "<!-- GENERATED by models/derive_lbv150.py: edit its inputs and rerun it with the",
        "     write option. SeaBotix LBV150 ROV (floating base) alone: hull and arm bracket,",
        "     primitive geometry only, no end-effector or sensor frame. models/uvms_lbv150.urdf",
        "     is this vehicle plus the 4-DoF arm, from the same numbers. The hull's volume is",
        "     trimmed for the vehicle CARRYING that arm: alone it floats up with",
        f"     {arm_net_N:.4f} N (the arm's weight in water) and pitches. -->",
        '<robot name="lbv150">',
        *_MATERIALS,
        "",
        *_base_link_lines(t),
        "</robot>",
        "",
    ]
    return "\n".join(out)


def render_urdf() -> str:
    """models/uvms_lbv150.urdf: the vehicle of `render_vehicle_urdf` plus the arm and tool."""
    t = trim()
    out = [
        '<?xml version="1.0"?>',
        "<!-- GENERATED by models/derive_lbv150.py: edit its inputs and rerun it with the",
        "     write option. SeaBotix LBV150 ROV (floating base) with a 4-DoF arm, a wrist",
        "     force/torque sensor frame, a probe tool and an end-effector frame; primitive",
        "     geometry only. <hydrodynamics>: coefficients at the LINK ORIGIN, in the LINK",
        "     FRAME, SI units; derivation and sources in models/README.md. Trimmed neutrally",
        f"     buoyant in sea water (rho = {_num(WATER_DENSITY_KG_M3)} kg/m^3): total mass "
        f"{t.total_mass_kg:.4f} kg, total volume {t.total_volume_m3:.7f} m^3. -->",
        '<robot name="uvms_lbv150">',
        *_MATERIALS,
        *_ARM_MATERIALS,
        "",
        *_base_link_lines(t),
        *_arm_lines(),
        "</robot>",
        "",
    ]
    return "\n".join(out)


def _base_link_lines(t: Trim) -> list[str]:
    """The hull link (trimmed for the arm), with its visual-only cosmetic parts."""
    hull = hull_hydro(t)
    z_com, hull_inertia = hull_inertial()
    lx, ly, lz = HULL_SIZE_M
    bracket_top = -lz / 2.0
    bracket_len = bracket_top - ARM_MOUNT_XYZ_M[2]
    bracket_xyz = [ARM_MOUNT_XYZ_M[0], 0.0, ARM_MOUNT_XYZ_M[2] + bracket_len / 2.0]
    out = [
        '  <link name="base_link">',
        _inertial_xml(HULL_MASS_KG, [t.hull_com_x_m, 0, z_com], hull_inertia, "    "),
        "    <visual>",
        '      <origin xyz="0 0 0" rpy="0 0 0"/>',
        f'      <geometry><box size="{_nums(HULL_SIZE_M)}"/></geometry>',
        '      <material name="hull_yellow"/>',
        "    </visual>",
    ]
    # cosmetic parts, visual only: two aft thrusters, lateral thruster, camera dome, bracket
    along_x, along_y = "0 1.5707963267949 0", "1.5707963267949 0 0"
    thruster = '<cylinder radius="0.035" length="0.08"/>'
    cosmetic = [
        ("-0.29 0.09 0", along_x, thruster, "thruster_black"),
        ("-0.29 -0.09 0", along_x, thruster, "thruster_black"),
        ("0 0 0.137", "0 0 0", '<cylinder radius="0.035" length="0.02"/>', "thruster_black"),
        (
            "-0.05 0 -0.05",
            along_y,
            f'<cylinder radius="0.03" length="{_num(ly + 0.01)}"/>',
            "thruster_black",
        ),
        (f"{_num(lx / 2.0)} 0 0.03", "0 0 0", '<sphere radius="0.07"/>', "dome_clear"),
        (_nums(bracket_xyz), "0 0 0", f'<box size="0.04 0.04 {_num(bracket_len)}"/>', "arm_gray"),
    ]
    for xyz, rpy, shape, material in cosmetic:
        out += [
            "    <visual>",
            f'      <origin xyz="{xyz}" rpy="{rpy}"/>',
            f"      <geometry>{shape}</geometry>",
            f'      <material name="{material}"/>',
            "    </visual>",
        ]
    out += [
        "    <collision>",
        '      <origin xyz="0 0 0" rpy="0 0 0"/>',
        f'      <geometry><box size="{_nums(HULL_SIZE_M)}"/></geometry>',
        "    </collision>",
        _hydro_xml(hull, "    "),
        "  </link>",
        "",
    ]
    return out


def _arm_lines() -> list[str]:
    """The arm links and joints, the F/T sensor frame, the probe and the ee frame."""
    origins = {ARM_LINKS[0].name: np.array(ARM_MOUNT_XYZ_M)}
    for prev, link in itertools.pairwise(ARM_LINKS):
        origins[link.name] = np.array([prev.length_m, 0.0, 0.0])
    out = [_cylinder_link_xml(link, "arm_gray") for link in ARM_LINKS]
    for name, parent, child, axis, lower, upper, effort, velocity, armature in _ARM_JOINTS:
        out += [
            f'  <joint name="{name}" type="revolute">',
            f'    <parent link="{parent}"/>',
            f'    <child link="{child}"/>',
            f'    <origin xyz="{_nums(origins[child])}" rpy="0 0 0"/>',
            f'    <axis xyz="{axis}"/>',
            f'    <limit lower="{_num(lower)}" upper="{_num(upper)}" effort="{_num(effort)}" '
            f'velocity="{_num(velocity)}"/>',
            f'    <armature value="{_num(armature)}"/>',
            "  </joint>",
        ]
    out += [
        "",
        "  <!-- wrist force/torque sensor frame: frame only (no inertial, geometry, hydro) -->",
        '  <link name="ft_sensor"/>',
        '  <joint name="ft_sensor_joint" type="fixed">',
        '    <parent link="arm_link4"/>',
        '    <child link="ft_sensor"/>',
        f'    <origin xyz="{_num(ARM_LINKS[-1].length_m)} 0 0" rpy="0 0 0"/>',
        "  </joint>",
        "",
        "  <!-- probe tool, rigidly mounted on the sensor: merged into arm_joint4's body -->",
        _cylinder_link_xml(TOOL, "probe_silver").rstrip("\n"),
        '  <joint name="tool_joint" type="fixed">',
        '    <parent link="ft_sensor"/>',
        '    <child link="tool"/>',
        '    <origin xyz="0 0 0" rpy="0 0 0"/>',
        "  </joint>",
        "",
        "  <!-- end-effector frame at the probe tip, x forward along the arm -->",
        '  <link name="ee"/>',
        '  <joint name="ee_joint" type="fixed">',
        '    <parent link="tool"/>',
        '    <child link="ee"/>',
        f'    <origin xyz="{_num(TOOL.length_m)} 0 0" rpy="0 0 0"/>',
        "  </joint>",
    ]
    return out


# ----------------------------------------------------------------------------- report


def report() -> None:
    rho, g = WATER_DENSITY_KG_M3, GRAVITY_M_S2
    t = trim()
    z_com, hull_inertia = hull_inertial()
    print(f"water density {rho:g} kg/m^3, g = {g:g} m/s^2\n")
    print("Hull (base_link)")
    lower = HULL_MASS_KG - HULL_UPPER_SLAB_MASS_KG
    print(
        f"  envelope {HULL_SIZE_M} m, mass {HULL_MASS_KG:g} kg (upper slab "
        f"{HULL_UPPER_SLAB_MASS_KG:g} kg, lower {lower:g} kg)"
    )
    print(
        f"  CoM ({t.hull_com_x_m:.5f}, 0, {z_com:.5f}) m, CoB (0, 0, {HULL_COB_Z_M:g}) m, "
        f"BG = {HULL_COB_Z_M - z_com:.4f} m"
    )
    print(f"  inertia about CoM (Ixx, Iyy, Izz) = {np.array2string(hull_inertia, precision=5)}")
    h = hull_hydro(t)
    print(f"  added mass diag   {np.array2string(np.diag(h.added_mass), precision=5)}")
    print(f"  linear damping    {np.array2string(np.diag(h.linear_damping), precision=5)}")
    print(f"  quadratic damping {np.array2string(h.quadratic_damping, precision=5)}\n")

    for link in (*ARM_LINKS, TOOL):
        hl = link_hydro(link)
        print(
            f"{link.name}: L = {link.length_m:g} m, r = {link.radius_m:g} m, "
            f"m = {link.mass_kg:g} kg, V = {hl.volume_m3:.6e} m^3, "
            f"rho V = {rho * hl.volume_m3:.4f} kg"
        )
        print(f"  inertia about CoM   {np.array2string(link_inertia(link), precision=6)}")
        print(f"  CoB at origin       {hl.center_of_buoyancy_m}")
        with np.printoptions(precision=6, suppress=False, linewidth=110):
            print("  added mass at origin (6x6):")
            print("   " + str(hl.added_mass).replace("\n", "\n   "))
            print(f"  linear damping diag {np.diag(hl.linear_damping)} (+ coupling, see URDF)")
            print(f"  quadratic damping   {hl.quadratic_damping}")

    print("\nTrim (zero arm configuration, positions in base_link)")
    print(
        f"  {'body':10s} {'mass kg':>9s} {'volume m^3':>12s} {'rho V kg':>9s} "
        f"{'net kg':>8s} {'x_G m':>8s} {'x_B m':>8s}"
    )
    origins = link_origins_in_base()
    rows = [("base_link", HULL_MASS_KG, t.hull_volume_m3, t.hull_com_x_m, 0.0)]
    for p in (*ARM_LINKS, TOOL):
        xc = origins[p.name][0] + p.length_m / 2.0
        rows.append((p.name, p.mass_kg, link_hydro(p).volume_m3, xc, xc))
    for name, m, v, xg, xb in rows:
        print(
            f"  {name:10s} {m:9.4f} {v:12.7f} {rho * v:9.4f} {m - rho * v:8.4f} {xg:8.4f} {xb:8.4f}"
        )
    weight = t.total_mass_kg * g
    buoyancy = rho * g * t.total_volume_m3
    print(
        f"  {'total':10s} {t.total_mass_kg:9.4f} {t.total_volume_m3:12.7f} "
        f"{rho * t.total_volume_m3:9.4f}"
    )
    print(
        f"  weight {weight:.4f} N, buoyancy {buoyancy:.4f} N, "
        f"relative difference {(buoyancy - weight) / weight:.2e}"
    )
    print(
        f"  system CoM {np.array2string(t.system_com_m, precision=5)} m, "
        f"CoB {np.array2string(t.system_cob_m, precision=5)} m, "
        f"BG (z) = {t.system_cob_m[2] - t.system_com_m[2]:.4f} m"
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="regenerate the URDF")
    parser.add_argument("--check", action="store_true", help="exit 1 if the URDF is stale")
    args = parser.parse_args(argv)
    report()
    stale = []
    for path, text in ((VEHICLE_URDF_PATH, render_vehicle_urdf()), (URDF_PATH, render_urdf())):
        if args.write:
            path.write_text(text)
            print(f"\nwrote {path}")
            continue
        up_to_date = path.exists() and path.read_text() == text
        print(f"\n{path.name}: {'up to date' if up_to_date else 'OUT OF DATE (run --write)'}")
        stale += [] if up_to_date else [path]
    return 1 if (stale and args.check) else 0


if __name__ == "__main__":
    sys.exit(main())
