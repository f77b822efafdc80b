"""Write the BlueROV2 Heavy, the Reach Alpha 5 and the Hinsdale-2023 trial vehicle URDFs.

Every number below is an input with its source (models/README.md, sections 7-9, says more):

- vB22: von Benzon, Sorensen, Uth, Jouffroy, Liniger, Pedersen, "An Open-Source Benchmark
  Simulator: Control of a BlueROV2 Underwater Robot", J. Mar. Sci. Eng. 10(12) 1898, 2022,
  Table A1 (coefficients published in NED; the diagonal magnitudes carry over to FLU).
- K23: Hannah Kolano, github.com/hkolano/UVMS-SysID-with-EAs (MIT, (c) 2023 Hannah Kolano),
  commit 18d9b2f5: ``src/julia-sim/ConfigFiles/MagicNumAlpha.jl`` (arm link volumes,
  centres of buoyancy and mass, masses, drag, joint limits),
  ``MagicNumBlueROVHardware.jl`` (the vehicle as configured in the 2023 pool trials:
  buoyancy, centre of buoyancy, ballast, DVL, foam), ``ConstMagicNums.jl`` (rho = 997) and
  ``urdf/blue_rov_hardware_fixedjaw.urdf`` (Alpha 5 kinematics, derived from Reach
  Robotics' public r5m description, link inertia tensors, effort and velocity limits, the
  arm's mount on the vehicle).
- R26: Reach Robotics, github.com/Reach-Robotics/reach_robotics_sdk, commit 935ba1e1,
  ``ROS2/reach_alpha_description/urdf/alpha_5.urdf.xacro`` and
  ``urdf/end_effectors/standard_jaws.urdf.xacro`` (the jaw: its base 99.75 mm along the
  wrist axis, two revolute fingers, their pivots, axes, travel, effort), and the fingers'
  meshes ``meshes/end_effectors/RS1-130.stl``, ``RS1-139.stl``, measured here (the inner
  edge's profile, the width, the volume; no mesh is copied): the collision shapes.
- P25: Evan Palmer, github.com/Robotic-Decision-Making-Lab/reach, commit 5e37b9df,
  ``reach_description/description/alpha_5/standard_jaws/standard_jaws.urdf.xacro`` (the
  fingers' masses). Both files are under Reach Robotics' licence (use with their products
  only): their facts (numbers) are taken over, no text.

Run ``python models/derive_bluerov_alpha5.py --write`` to regenerate the files,
``--check`` to exit 1 if a file differs from what this script writes.
"""

from __future__ import annotations

import argparse
import itertools
import math
import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
G_M_S2 = 9.81
FRESH_WATER_KG_M3 = 997.0  # K23 ConstMagicNums.jl
LEAD_KG_M3 = 11340.0

# ---- BlueROV2 Heavy, vB22 Table A1 (FLU; CoG at the origin, CoB 0.01 m above it) ----
BLUEROV_MASS_KG = 13.5
BLUEROV_VOLUME_M3 = 0.0134
BLUEROV_INERTIA_KG_M2 = (0.26, 0.23, 0.37)
BLUEROV_COB_M = (0.0, 0.0, 0.01)
BLUEROV_ADDED_MASS = (6.36, 7.12, 18.68, 0.189, 0.135, 0.222)
BLUEROV_LINEAR_DAMPING = (13.7, 0.0, 33.0, 0.0, 0.8, 0.0)
BLUEROV_QUADRATIC_DAMPING = (141.0, 217.0, 190.0, 1.19, 0.47, 1.5)
# Blue Robotics BlueROV2 Heavy envelope 457 x 575 x 254 mm (L x W x H), for drawing and trim
BLUEROV_BOX_M = (0.457, 0.575, 0.254)

# ---- the trial vehicle (K23 MagicNumBlueROVHardware.jl), FLU, vehicle frame ----------
TRIAL_MASS_KG = 13.17  # weight 13.17 * 9.81 N applied at the origin
TRIAL_BUOYANCY_KG = 13.082  # buoyancy 13.082 * 9.81 N ...
TRIAL_COB_M = (0.0074, 0.0, 0.02)  # ... at this point
# Identified here, not in K23: shift of the hull's centre of buoyancy fitted on the
# identification trials (families 001, 008) by `python -m uvms_pin.apps.validation.identify
# data/hinsdale2023` run on the file without it (models/README.md section 9)
TRIAL_COB_CORRECTION_M = (0.000306, 0.000546, 0.004211)
# net weights in water [N] of the trim items, at their positions [m]
TRIAL_WEIGHTS = (  # lead: counter-arm weight, bottom-left, bottom-right
    ("ballast_counter_arm", 3.24, (-0.20, 0.165, -0.075)),
    ("ballast_bottom_left", 1.62, (-0.0975, 0.1275, -0.1325)),
    ("ballast_bottom_right", 1.62, (-0.0975, -0.1275, -0.1325)),
)
TRIAL_NET_WEIGHTS = (  # DVL and its bracket: only their net weight is published
    ("dvl", 0.69, (-0.1887, 0.0439, -0.1095 + 0.05)),
    ("dvl_bracket", 1.01, (-0.1887 + 0.0345, 0.0439, -0.1295 + 0.05)),
)
TRIAL_FOAM = (  # net lift [N] of the two foam blocks (the final values of the file)
    ("foam_left", 8.46, (0.0, 0.11, 0.027)),
    ("foam_right", 8.66 + 0.2, (0.0, -0.11, 0.027)),
)

# ---- Reach Alpha 5 (K23): kinematics, masses, CoM, CoB, volumes, drag -----------------
ALPHA_MOUNT_XYZ_M = (0.25, -0.10965, 0.005)  # arm base in the vehicle frame (K23 URDF)
# name, mass [kg], CoM [m], inertia (ixx ixy ixz iyy iyz izz) [kg m^2], volume [L],
# CoB [m], quadratic drag on the CoB velocity per link axis [N/(m/s)^2],
# added mass lumped into the link mass by K23 ("actual + added" - "actual") [kg]
ALPHA_LINKS = (
    (
        "alpha_base_link",
        0.341,
        (-0.075, -0.006, -0.003),
        (0.000099, 0.000139, 0.000115, 0.004334, 0.000003, 0.004348),
        0.202,
        (-0.075, -0.006, -0.003),
        (0.0, 0.0, 0.0),
        0.53 - 0.341,
    ),
    (
        "alpha_shoulder_link",
        0.194,
        (0.005, -0.001, 0.016),
        (0.000196, 0.000005, 0.000054, 0.000220, 0.000003, 0.000067),
        0.018,
        (-0.001, -0.003, 0.032),
        (0.26, 0.26, 0.3),
        0.226 - 0.194,
    ),
    (
        "alpha_upper_arm_link",
        0.429,
        (0.073, 0.0, 0.0),
        (0.000087, -0.000076, -0.000010, 0.004906, 0.0, 0.004929),
        0.203,
        (0.073, 0.0, -0.002),
        (0.3, 1.6, 1.6),
        0.630 - 0.429,
    ),
    (
        "alpha_forearm_link",
        0.115,
        (0.017, -0.026, -0.002),
        (0.000127, -0.000061, -0.000001, 0.000062, 0.0, 0.000163),
        0.025,
        (0.003, 0.001, -0.017),
        (0.26, 0.3, 0.26),
        0.147 - 0.115,
    ),
    (
        "alpha_wrist_link",
        0.333,
        (0.0, 0.0, -0.098),
        (0.006152, -0.000002, -0.000004, 0.006177, 0.0, 0.000079),
        0.155,
        (0.0, 0.0, -0.098),
        (1.8, 1.8, 0.3),
        0.559 - 0.333,
    ),
)
ALPHA_JAW = ("alpha_jaw_link", 0.05, (0.0, 0.0, -0.190), 0.020, (0.05, 0.05, 0.05))
# ---- the Alpha 5's standard jaw (R26, masses P25), in reach_alpha5_jaws.urdf -----------
# The jaw base sits 99.75 mm along the wrist axis from axis B (R26); in K23's wrist frame the
# tool points along -z, so the jaw base frame is turned by pi about x: its +z points out of
# the wrist, as R26's. K23's locked-jaw point mass (ALPHA_JAW: 0.05 kg, 0.020 L) stays as the
# jaw's housing, moved to the jaw base: at K23's 0.19 m it would sit between the fingertips,
# and a link without collision shapes touches the world by a sphere of its volume (17 mm).
ALPHA_JAW_BASE_XYZ_M = (0.0, 0.0, -0.09975)
ALPHA_JAW_BASE_RPY = (math.pi, 0.0, 0.0)
# finger: joint, link, pivot in the jaw base [m], axis, collision box centre in the finger [m]
# Each finger is a revolute joint, 0 (closed) .. 0.5 rad (open), effort 10, velocity 10
# (R26); R26 couples them through <mimic> (finger 139 mimics finger 130, multiplier 1).
ALPHA_FINGERS = (
    (
        "alpha_jaw_finger_130_joint",
        "alpha_jaw_finger_130_link",
        (0.0, 0.0155, 0.0069),
        (-1.0, 0.0, 0.0),
        (0.0, -0.008, 0.045),
    ),
    (
        "alpha_jaw_finger_139_joint",
        "alpha_jaw_finger_139_link",
        (0.0, -0.0155, 0.0069),
        (1.0, 0.0, 0.0),
        (0.0, 0.008, 0.045),
    ),
)
ALPHA_FINGER_BOX_M = (0.012, 0.03, 0.09)  # R26's collision box x y z: mass properties only
ALPHA_FINGER_MASS_KG = 0.055  # P25; at R26's box centre, inertia: the uniform box's
# The fingers' collision shapes: one box per straight piece of the finger's inner edge, as
# measured on R26's mesh RS1-130 (the edge's (y, z) in the finger frame [m], at the mesh's
# mid-plane x = 0; finger 139 is its mirror image in y). From the pivot out: a straight
# palm piece, a piece turned 0.2 rad toward the other finger, a hook turned 0.36 rad, and the
# tip, parallel to the finger. Closed (0 rad) the palm pieces of the two fingers are 2-3 mm
# apart; the hooks and tips cross the jaw's centre line, where the real fingers interleave.
# Opened by about 0.36 rad the two hooks are parallel, 40 mm apart: the pocket where a round
# object of 25-55 mm sits (models/README.md, section 10).
ALPHA_FINGER_EDGE_M = (
    (-0.0144, 0.012),
    (-0.0133, 0.040),
    (-0.0166, 0.056),
    (-0.0211, 0.068),
    (-0.0211, 0.085),
)
# the boxes' width along the pivot axis (RS1-139's 9.8 mm) and depth behind the edge, chosen
# so that the four boxes' volume (6.7 mL) is the mean of the meshes' (6.1 and 7.7 mL)
ALPHA_FINGER_PAD_WIDTH_M = 0.010
ALPHA_FINGER_PAD_DEPTH_M = 0.009
ALPHA_FINGER_LIMITS = (0.0, 0.5, 10.0, 10.0)  # lower, upper [rad], effort, velocity (R26)
HALF_PI = math.pi / 2
# joint, parent, child, xyz, rpy, lower, upper [rad], effort [N m], velocity [rad/s]
# Angles are K23's: raw Reach encoder minus 3.07 rad (axis E) and 2.879 rad (axis B).
ALPHA_JOINTS = (
    (
        "alpha_axis_e",
        "alpha_base_link",
        "alpha_shoulder_link",
        (0.0, 0.0, 0.0),
        (0.0, 0.0, 0.0),
        -math.radians(175),
        math.radians(175),
        9.0,
        0.5,
    ),
    (
        "alpha_axis_d",
        "alpha_shoulder_link",
        "alpha_upper_arm_link",
        (0.020, 0.0, 0.046),
        (HALF_PI, 1.3, 0.0),
        0.0,
        math.radians(200),
        9.0,
        0.5,
    ),
    (
        "alpha_axis_c",
        "alpha_upper_arm_link",
        "alpha_forearm_link",
        (0.15, 0.0, 0.0),
        (math.pi, 0.0, 1.3),
        0.0,
        math.radians(200),
        9.0,
        0.5,
    ),
    (
        "alpha_axis_b",
        "alpha_forearm_link",
        "alpha_wrist_link",
        (0.020, 0.0, 0.0),
        (-HALF_PI, 0.0, 0.0),
        -math.radians(165),
        math.radians(165),
        5.0,
        1.0,
    ),
)
ALPHA_ENCODER_OFFSETS_RAD = {"alpha_axis_e": 3.07, "alpha_axis_b": 2.879}
# The joints' drives (models/README.md, "Joint drives"): each joint's reflected rotor inertia
# J_rotor N^2 [kg m^2], Pinocchio's armature. The gear ratios N are Reach Robotics' (P25's
# reach_hardware/src/alpha_5_hardware.cpp, GEAR_RATIO, device ids 5..2 = axes E..B: 1754.4
# for the three 0.0134 N m/A motors, 340.4 for the wrist's 0.0271 N m/A one); the rotor
# inertias are estimates for motors of those torque constants (no published value): a
# 12-13 mm motor, 2e-8 kg m^2 (0.2 g cm^2), and a 16 mm one, 1e-7 kg m^2 (1 g cm^2).
ALPHA_GEAR_RATIO = {
    "alpha_axis_e": 1754.4,
    "alpha_axis_d": 1754.4,
    "alpha_axis_c": 1754.4,
    "alpha_axis_b": 340.4,
}
ALPHA_ROTOR_INERTIA_KG_M2 = {
    "alpha_axis_e": 2e-8,
    "alpha_axis_d": 2e-8,
    "alpha_axis_c": 2e-8,
    "alpha_axis_b": 1e-7,
}


def alpha_armature_kg_m2(joint: str) -> float:
    """A joint's reflected rotor inertia J_rotor N^2 [kg m^2], to 3 significant digits."""
    return float(f"{ALPHA_ROTOR_INERTIA_KG_M2[joint] * ALPHA_GEAR_RATIO[joint] ** 2:.3g}")


def _f(values) -> str:
    return " ".join(f"{v:.9g}" for v in values)


def _inertial(mass: float, com=(0.0, 0.0, 0.0), inertia=(0, 0, 0, 0, 0, 0)) -> str:
    ixx, ixy, ixz, iyy, iyz, izz = inertia
    return (
        f'    <inertial>\n      <origin xyz="{_f(com)}" rpy="0 0 0"/>\n'
        f'      <mass value="{mass:.9g}"/>\n'
        f'      <inertia ixx="{ixx:.9g}" ixy="{ixy:.9g}" ixz="{ixz:.9g}" iyy="{iyy:.9g}" '
        f'iyz="{iyz:.9g}" izz="{izz:.9g}"/>\n    </inertial>\n'
    )


def _hydro(volume_m3: float, cob=(0.0, 0.0, 0.0), added=None, linear=None, quadratic=None):
    lines = [
        "    <hydrodynamics>",
        f'      <volume value="{volume_m3:.9g}"/>',
        f'      <center_of_buoyancy xyz="{_f(cob)}"/>',
    ]
    if added is not None:
        lines.append(f'      <added_mass diagonal="{_f(added)}"/>')
    if linear is not None:
        lines.append(f'      <linear_damping diagonal="{_f(linear)}"/>')
    if quadratic is not None:
        lines.append(f'      <quadratic_damping diagonal="{_f(quadratic)}"/>')
    lines.append("    </hydrodynamics>")
    return "\n".join(lines) + "\n"


def _fixed(name: str, parent: str, child: str, xyz, rpy=(0.0, 0.0, 0.0)) -> str:
    return (
        f'  <joint name="{name}" type="fixed">\n    <parent link="{parent}"/>\n'
        f'    <child link="{child}"/>\n    <origin xyz="{_f(xyz)}" rpy="{_f(rpy)}"/>\n'
        "  </joint>\n"
    )


def _point_link(name: str, mass: float, hydro: str, comment: str) -> str:
    return f'  <!-- {comment} -->\n  <link name="{name}">\n{_inertial(mass)}{hydro}  </link>\n'


def _header(name: str, what: str) -> str:
    return (
        '<?xml version="1.0"?>\n'
        f"<!-- GENERATED by models/derive_bluerov_alpha5.py: {what}\n"
        "     Sources of every number: models/README.md. Do not edit by hand. -->\n"
        f'<robot name="{name}">\n'
    )


# ---- drawing only (<visual>): no physics number depends on these -------------------------
# Primitives in the URDF's own <visual> elements, laid out after Blue Robotics' BlueROV2
# Heavy (black frame side panels, buoyancy foam on top, the 4" acrylic electronics tube with
# its dome, the 3" battery tube, 8 T200 thrusters where `uvms_pin.model.vehicles.
# bluerov2_heavy.thrusters()` puts them) and the Reach Alpha 5 (40 mm black housings along
# each link). No maker's mesh is shipped: models/README.md section 12 says why.
_BLACK = ("frame_black", "0.06 0.06 0.07 1")
_FOAM = ("foam_blue", "0.10 0.32 0.72 1")
_ACRYLIC = ("acrylic", "0.80 0.90 1.00 0.35")
_ALUMINIUM = ("aluminium", "0.62 0.64 0.68 1")
_THRUSTER = ("t200_grey", "0.18 0.18 0.20 1")
# geometry, xyz [m], rpy [rad], material
BLUEROV_VISUALS = (
    ('<box size="0.457 0.012 0.22"/>', (0.0, 0.16, -0.015), (0.0, 0.0, 0.0), _BLACK),
    ('<box size="0.457 0.012 0.22"/>', (0.0, -0.16, -0.015), (0.0, 0.0, 0.0), _BLACK),
    ('<box size="0.40 0.30 0.010"/>', (0.0, 0.0, -0.122), (0.0, 0.0, 0.0), _BLACK),
    ('<box size="0.16 0.115 0.012"/>', (0.12, 0.2175, -0.01), (0.0, 0.0, 0.0), _BLACK),
    ('<box size="0.16 0.115 0.012"/>', (0.12, -0.2175, -0.01), (0.0, 0.0, 0.0), _BLACK),
    ('<box size="0.16 0.115 0.012"/>', (-0.12, 0.2175, -0.01), (0.0, 0.0, 0.0), _BLACK),
    ('<box size="0.16 0.115 0.012"/>', (-0.12, -0.2175, -0.01), (0.0, 0.0, 0.0), _BLACK),
    ('<box size="0.42 0.12 0.065"/>', (0.0, 0.095, 0.0945), (0.0, 0.0, 0.0), _FOAM),
    ('<box size="0.42 0.12 0.065"/>', (0.0, -0.095, 0.0945), (0.0, 0.0, 0.0), _FOAM),
    ('<cylinder radius="0.0572" length="0.30"/>', (0.0, 0.0, 0.0), (0.0, HALF_PI, 0.0), _ACRYLIC),
    ('<sphere radius="0.0572"/>', (0.15, 0.0, 0.0), (0.0, 0.0, 0.0), _ACRYLIC),
    (
        '<cylinder radius="0.062" length="0.02"/>',
        (-0.16, 0.0, 0.0),
        (0.0, HALF_PI, 0.0),
        _ALUMINIUM,
    ),
    (
        '<cylinder radius="0.0381" length="0.25"/>',
        (-0.02, 0.0, -0.085),
        (0.0, HALF_PI, 0.0),
        _ALUMINIUM,
    ),
)
T200_VISUAL = '<cylinder radius="0.05" length="0.10"/>'  # T200: 100 mm across, 113 mm long
# link: (geometry, xyz [m], rpy [rad]) in K23's link frames (the joint axes are z)
ALPHA_VISUALS = {
    "alpha_base_link": (
        ('<cylinder radius="0.02" length="0.15"/>', (-0.075, 0, 0), (0, HALF_PI, 0)),
    ),
    "alpha_shoulder_link": (
        ('<cylinder radius="0.021" length="0.05"/>', (0.0, 0.0, 0.025), (0.0, 0.0, 0.0)),
        ('<cylinder radius="0.021" length="0.045"/>', (0.02, 0.0, 0.046), (HALF_PI, 0.0, 0.0)),
    ),
    "alpha_upper_arm_link": (
        ('<cylinder radius="0.02" length="0.15"/>', (0.075, 0.0, 0.0), (0.0, HALF_PI, 0.0)),
    ),
    "alpha_forearm_link": (
        ('<cylinder radius="0.021" length="0.045"/>', (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
        ('<cylinder radius="0.02" length="0.03"/>', (0.02, -0.01, 0.0), (HALF_PI, 0.0, 0.0)),
    ),
    "alpha_wrist_link": (
        ('<cylinder radius="0.02" length="0.06"/>', (0.0, 0.0, -0.005), (0.0, 0.0, 0.0)),
    ),
}
_ALPHA_BLACK = ("alpha_black", "0.10 0.10 0.11 1")


def _visual(geometry: str, xyz, rpy, material) -> str:
    name, rgba = material
    return (
        f'    <visual>\n      <origin xyz="{_f(xyz)}" rpy="{_f(rpy)}"/>\n'
        f"      <geometry>{geometry}</geometry>\n"
        f'      <material name="{name}"><color rgba="{rgba}"/></material>\n    </visual>\n'
    )


def _rpy_of_axis(direction) -> tuple[float, float, float]:
    """rpy turning a cylinder's z axis onto a unit ``direction`` (z, or in the x-y plane)."""
    x, y, z = direction
    if abs(z) > 0.5:
        return (0.0, 0.0, 0.0)
    return (0.0, HALF_PI, math.atan2(y, x))


def bluerov_visuals() -> str:
    """The BlueROV2 Heavy's <visual> elements (drawing only)."""
    from uvms_pin.model.vehicles.bluerov2_heavy import thrusters

    out = "".join(_visual(*item) for item in BLUEROV_VISUALS)
    for thruster in thrusters():
        rpy = _rpy_of_axis(thruster.direction_body)
        out += _visual(T200_VISUAL, thruster.position_body_m, rpy, _THRUSTER)
    return out


def _hull_link(mass, inertia, hydro: str) -> str:
    ixx, iyy, izz = inertia
    box = _f(BLUEROV_BOX_M)
    return (
        '  <link name="base_link">\n'
        + _inertial(mass, (0.0, 0.0, 0.0), (ixx, 0, 0, iyy, 0, izz))
        + hydro
        + bluerov_visuals()
        + f'    <collision>\n      <geometry><box size="{box}"/></geometry>\n    </collision>\n'
        "  </link>\n"
    )


def bluerov2_heavy_urdf() -> str:
    """The catalogue vehicle: vB22 Table A1, sea water by default at load time."""
    hydro = _hydro(
        BLUEROV_VOLUME_M3,
        BLUEROV_COB_M,
        BLUEROV_ADDED_MASS,
        BLUEROV_LINEAR_DAMPING,
        BLUEROV_QUADRATIC_DAMPING,
    )
    return (
        _header("bluerov2_heavy", "BlueROV2 Heavy, von Benzon et al. 2022 Table A1")
        + _hull_link(BLUEROV_MASS_KG, BLUEROV_INERTIA_KG_M2, hydro)
        + "</robot>\n"
    )


def lead_for_net_weight(net_weight_N: float, rho: float = FRESH_WATER_KG_M3) -> tuple[float, float]:
    """(mass [kg], volume [m^3]) of lead whose weight in water of density rho is net_weight_N."""
    mass = net_weight_N / (G_M_S2 * (1.0 - rho / LEAD_KG_M3))
    return mass, mass / LEAD_KG_M3


def trial_vehicle_urdf() -> str:
    """The BlueROV2 Heavy as configured in the 2023 pool trials (K23), fresh water."""
    cob = tuple(a + b for a, b in zip(TRIAL_COB_M, TRIAL_COB_CORRECTION_M, strict=True))
    hydro = _hydro(
        TRIAL_BUOYANCY_KG / FRESH_WATER_KG_M3,
        cob,
        BLUEROV_ADDED_MASS,
        BLUEROV_LINEAR_DAMPING,
        BLUEROV_QUADRATIC_DAMPING,
    )
    out = _header(
        "bluerov2_heavy_hinsdale2023",
        "BlueROV2 Heavy as trimmed for the Hinsdale 2023 pool trials (Kolano), rho = 997",
    ) + _hull_link(TRIAL_MASS_KG, BLUEROV_INERTIA_KG_M2, hydro)
    for name, net_N, xyz in TRIAL_WEIGHTS:
        mass, volume = lead_for_net_weight(net_N)
        out += _point_link(name, mass, _hydro(volume), f"lead, {net_N} N in fresh water")
        out += _fixed(f"{name}_joint", "base_link", name, xyz)
    for name, net_N, xyz in TRIAL_NET_WEIGHTS:
        out += _point_link(
            name,
            net_N / G_M_S2,
            _hydro(0.0),
            f"net weight {net_N} N only (mass m = W/g, no volume)",
        )
        out += _fixed(f"{name}_joint", "base_link", name, xyz)
    for name, lift_N, xyz in TRIAL_FOAM:
        volume = lift_N / (FRESH_WATER_KG_M3 * G_M_S2)
        out += _point_link(
            name, 0.0, _hydro(volume), f"foam, net lift {lift_N:.4g} N (massless volume)"
        )
        out += _fixed(f"{name}_joint", "base_link", name, xyz)
    return out + "</robot>\n"


def alpha5_urdf() -> str:
    """Reach Alpha 5, arm only (root alpha_base_link), jaw fixed (K23 kinematics)."""
    out = _header("reach_alpha5", "Reach Alpha 5 (arm only), jaw locked; Kolano's identification")
    for name, mass, com, inertia, volume_L, cob, drag, added in ALPHA_LINKS:
        # volume 0 here: this link's buoyancy, added mass and drag sit on its _cob frame
        out += f'  <link name="{name}">\n{_inertial(mass, com, inertia)}{_hydro(0.0)}'
        out += "".join(_visual(*item, _ALPHA_BLACK) for item in ALPHA_VISUALS[name])
        out += "  </link>\n"
        # the hydrodynamics act at the centre of buoyancy (K23 applies buoyancy and the
        # quadratic drag of the CoB's velocity there): a massless frame at the CoB carries them
        hydro = _hydro(
            volume_L * 1e-3, (0.0, 0.0, 0.0), (added, added, added, 0, 0, 0), None, (*drag, 0, 0, 0)
        )
        out += _point_link(f"{name}_cob", 0.0, hydro, f"{name}: buoyancy, added mass, drag")
        out += _fixed(f"{name}_cob_joint", name, f"{name}_cob", cob)
    for joint, parent, child, xyz, rpy, lower, upper, effort, velocity in ALPHA_JOINTS:
        out += (
            f'  <joint name="{joint}" type="revolute">\n    <parent link="{parent}"/>\n'
            f'    <child link="{child}"/>\n    <origin xyz="{_f(xyz)}" rpy="{_f(rpy)}"/>\n'
            '    <axis xyz="0 0 1"/>\n'
            f'    <limit lower="{lower:.9g}" upper="{upper:.9g}" effort="{effort:.9g}" '
            f'velocity="{velocity:.9g}"/>\n'
            f'    <armature value="{alpha_armature_kg_m2(joint):.9g}"/>\n  </joint>\n'
        )
    name, mass, xyz, volume_L, drag = ALPHA_JAW
    hydro = _hydro(volume_L * 1e-3, quadratic=(*drag, 0, 0, 0))
    out += _point_link(name, mass, hydro, "jaw, locked closed: a point mass with its volume")
    out += _fixed("alpha_jaw_joint", "alpha_wrist_link", name, xyz)
    return out + "</robot>\n"


def _box_inertia(mass: float, size) -> tuple[float, ...]:
    """(ixx 0 0 iyy 0 izz) of a uniform box about its centre [kg m^2]."""
    x, y, z = size
    return (
        mass * (y * y + z * z) / 12,
        0.0,
        0.0,
        mass * (x * x + z * z) / 12,
        0.0,
        mass * (x * x + y * y) / 12,
    )


def _finger_pads(mirror: float) -> list[tuple[tuple, float, tuple]]:
    """(centre, roll [rad], size) of each box along the finger's inner edge, in the finger
    frame: the box's inner face lies on the edge piece, its depth behind it (away from the
    other finger); ``mirror`` -1 for the finger on the -y pivot (y flipped)."""
    pads = []
    edge = ALPHA_FINGER_EDGE_M
    for (y0, z0), (y1, z1) in itertools.pairwise(edge):
        length = math.hypot(y1 - y0, z1 - z0)
        uy, uz = (y1 - y0) / length, (z1 - z0) / length
        half = ALPHA_FINGER_PAD_DEPTH_M / 2  # outward normal (uz, -uy): away from the centre
        cy, cz = (y0 + y1) / 2 + half * uz, (z0 + z1) / 2 - half * uy
        size = (ALPHA_FINGER_PAD_WIDTH_M, ALPHA_FINGER_PAD_DEPTH_M, length)
        pads.append(((0.0, mirror * cy, cz), mirror * math.atan2(-uy, uz) + 0.0, size))
    return pads


def _finger(joint: str, link: str, pivot, axis, centre, mimic: str | None) -> str:
    """One finger of the standard jaw on a revolute joint (R26, P25): R26's mass properties,
    boxes along the inner edge of R26's mesh as its collision and visual shapes; no
    <hydrodynamics>: the loader derives them from the collision boxes."""
    lower, upper, effort, velocity = ALPHA_FINGER_LIMITS
    inertia = _box_inertia(ALPHA_FINGER_MASS_KG, ALPHA_FINGER_BOX_M)
    mimic_line = (
        "" if mimic is None else f'    <mimic joint="{mimic}" multiplier="1" offset="0"/>\n'
    )
    shapes = ""
    for element in ("visual", "collision"):
        for pad_centre, roll, size in _finger_pads(-1.0 if centre[1] > 0 else 1.0):
            material = (
                '      <material name="alpha_grey"><color rgba="0.3 0.3 0.3 1"/></material>\n'
                if element == "visual"
                else ""
            )
            shapes += (
                f'    <{element}>\n      <origin xyz="{_f(pad_centre)}" rpy="{roll:.9g} 0 0"/>\n'
                f'      <geometry><box size="{_f(size)}"/></geometry>\n{material}'
                f"    </{element}>\n"
            )
    return (
        f'  <link name="{link}">\n{_inertial(ALPHA_FINGER_MASS_KG, centre, inertia)}'
        f"{shapes}  </link>\n"
        f'  <joint name="{joint}" type="revolute">\n    <parent link="alpha_jaw_base_link"/>\n'
        f'    <child link="{link}"/>\n    <origin xyz="{_f(pivot)}" rpy="0 0 0"/>\n'
        f'    <axis xyz="{_f(axis)}"/>\n'
        f'    <limit lower="{lower:.9g}" upper="{upper:.9g}" effort="{effort:.9g}" '
        f'velocity="{velocity:.9g}"/>\n{mimic_line}  </joint>\n'
    )


def alpha5_jaws_urdf() -> str:
    """reach_alpha5.urdf with the standard jaw's two fingers moving (R26, P25)."""
    at_base = f'origin xyz="{_f(ALPHA_JAW_BASE_XYZ_M)}" rpy="0 0 0"/>\n  </joint>\n'
    locked = alpha5_urdf().rstrip().removesuffix("</robot>")
    locked = locked.replace('origin xyz="0 0 -0.19" rpy="0 0 0"/>\n  </joint>\n', at_base).replace(
        "jaw, locked closed: a point mass with its volume", "jaw housing: a point mass"
    )
    out = locked.replace(
        "Reach Alpha 5 (arm only), jaw locked; Kolano's identification",
        "Reach Alpha 5 (arm only) with its standard jaw's two fingers (Reach Robotics' "
        "description); Kolano's identification",
    ).replace('<robot name="reach_alpha5">', '<robot name="reach_alpha5_jaws">')
    out += "  <!-- the standard jaw: its base, then two fingers (R26) -->\n"
    out += '  <link name="alpha_jaw_base_link"/>\n'
    out += _fixed(
        "alpha_jaw_base_joint",
        "alpha_wrist_link",
        "alpha_jaw_base_link",
        ALPHA_JAW_BASE_XYZ_M,
        ALPHA_JAW_BASE_RPY,
    )
    first = ALPHA_FINGERS[0][0]
    for k, (joint, link, pivot, axis, centre) in enumerate(ALPHA_FINGERS):
        out += _finger(joint, link, pivot, axis, centre, None if k == 0 else first)
    return out + "</robot>\n"


# the force-task UVMS (scenarios/bluerov_alpha5_force_tracking.toml): the catalogue vehicle
# with the Alpha 5 at K23's mount, uvms-pin's default probe on the wrist, trimmed by
# uvms_pin.model.trim (foam on top, lead below; BG 2 cm) at the scenario's initial arm pose, sea water
FORCE_TASK_ARM_POSE_RAD = (-0.2, 0.8, 2.2, 0.2)


def force_task_urdf() -> str:
    """bluerov2_heavy.urdf + reach_alpha5.urdf + probe, trimmed (needs both files written)."""
    from uvms_pin.model.mount.mount import (
        mount_arm_detailed,  # the installed uvms-pin does the merge
    )

    result = mount_arm_detailed(
        HERE / "bluerov2_heavy.urdf",
        HERE / "reach_alpha5.urdf",
        (ALPHA_MOUNT_XYZ_M, (0.0, 0.0, 0.0)),
        trim=True,
        trim_joint_positions=FORCE_TASK_ARM_POSE_RAD,
    )
    return _with_comment(result, "BlueROV2 Heavy + Reach Alpha 5 + probe")


def _with_comment(result, what: str) -> str:
    """The mounted file's text with a first comment: what it is and its trim."""
    comment = (
        f"<!-- GENERATED by models/derive_bluerov_alpha5.py: {what}"
        ", trimmed with uvms_pin.model.mount.mount (trim: "
        + result.trim.summary().replace("\n", "; ").replace("--", "-")
        + ") -->\n"
    )
    text = result.urdf_text
    if text.startswith("<?xml"):
        declaration, _, rest = text.partition("\n")
        return f"{declaration}\n{comment}{rest}"
    return comment + text


def jaws_uvms_urdf() -> str:
    """bluerov2_heavy.urdf + reach_alpha5_jaws.urdf, fingers moving, no probe (the ``ee``
    frame is the wrist's sensor frame), trimmed as the force-task file with the jaw closed."""
    from uvms_pin.model.mount.mount import mount_arm_detailed

    result = mount_arm_detailed(
        HERE / "bluerov2_heavy.urdf",
        HERE / "reach_alpha5_jaws.urdf",
        (ALPHA_MOUNT_XYZ_M, (0.0, 0.0, 0.0)),
        trim=True,
        trim_joint_positions=(*FORCE_TASK_ARM_POSE_RAD, 0.0, 0.0),
        tool=None,
        moving_jaw=True,
    )
    return _with_comment(result, "BlueROV2 Heavy + Reach Alpha 5 with its moving jaw")


FILES = {
    "bluerov2_heavy.urdf": bluerov2_heavy_urdf,
    "bluerov2_heavy_hinsdale2023.urdf": trial_vehicle_urdf,
    "reach_alpha5.urdf": alpha5_urdf,
    "uvms_bluerov2_alpha5.urdf": force_task_urdf,
    "reach_alpha5_jaws.urdf": alpha5_jaws_urdf,
    "uvms_bluerov2_alpha5_jaws.urdf": jaws_uvms_urdf,
}


_NUMBER = re.compile(r"-?\d+\.?\d*(?:[eE][-+]?\d+)?")


def same_up_to_rounding(written: str, generated: str, rel: float = 1e-12) -> bool:
    """The same text, numbers equal to ``rel``: the trim is a linear solve, whose last digit
    may change with the numpy / LAPACK build, not with the model."""
    if _NUMBER.sub("#", written) != _NUMBER.sub("#", generated):
        return False
    return all(
        math.isclose(float(a), float(b), rel_tol=rel, abs_tol=1e-15)
        for a, b in zip(_NUMBER.findall(written), _NUMBER.findall(generated), strict=True)
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="write the URDF files")
    parser.add_argument("--check", action="store_true", help="exit 1 if a file is out of date")
    args = parser.parse_args(argv)
    stale = []
    for filename, make in FILES.items():
        path = HERE / filename
        text = make()  # in order: the force-task file is made from the files written before
        if args.write:
            path.write_text(text)
            print(f"wrote {path}")
        elif not path.is_file() or not same_up_to_rounding(path.read_text(), text):
            stale.append(filename)
    for filename in stale:
        print(f"{filename} is out of date: run with --write")
    return 1 if (args.check and stale) else 0


if __name__ == "__main__":
    sys.exit(main())
