"""Mounting arms on a vehicle (issue 5): equivalence, example-robot-data arms, bad input."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import REFERENCE_URDF, ROOT, random_configuration

import uvms_pin as up
from uvms_pin.apps.arms.compare import CompareSettings, compare_arms
from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.model.mount.catalog import CATALOG, available_arms
from uvms_pin.model.mount.mount import mount_arm, mount_arm_detailed
from uvms_pin.model.mount.split import split_urdf
from uvms_pin.model.mount.tool import ProbeTool
from uvms_pin.model.trim import TrimSpec, mass_properties

SCENARIO = ROOT / "scenarios" / "realistic_force_tracking.toml"
UPSIDE_DOWN = (math.pi, 0.0, 0.0)


@pytest.fixture(scope="module")
def split(tmp_path_factory):
    return split_urdf(REFERENCE_URDF, tmp_path_factory.mktemp("split"))


def _mount_pose(split):
    return (split.mount_pose.translation, UPSIDE_DOWN)


# ---------------------------------------------------------------- reference equivalence


def test_reference_arm_mounted_gives_the_reference_dynamics(split, reference_uvms):
    mounted = mount_arm(
        split.vehicle_urdf,
        split.arm_urdf,
        split.mount_pose,
        ee_link="ee",
        sensor_link="ft_sensor",
        tool=None,
    )
    assert mounted.nq == reference_uvms.nq and mounted.nv == reference_uvms.nv
    assert mounted.arm_joint_names == reference_uvms.arm_joint_names
    assert mounted.mass_kg == pytest.approx(reference_uvms.mass_kg, rel=1e-12)
    assert mounted.volume_m3 == pytest.approx(reference_uvms.volume_m3, rel=1e-12)
    rng = np.random.default_rng(5)
    for _ in range(10):
        q = random_configuration(reference_uvms, rng)
        v = rng.normal(size=reference_uvms.nv)
        current = rng.normal(size=3) * 0.3
        np.testing.assert_allclose(
            up.mass_matrix(mounted, q), up.mass_matrix(reference_uvms, q), atol=1e-10
        )
        np.testing.assert_allclose(
            up.bias_forces(mounted, q, v, current),
            up.bias_forces(reference_uvms, q, v, current),
            atol=1e-9,
        )
        for frame in ("ee", "ft_sensor"):
            a = mounted.model.createData()
            b = reference_uvms.model.createData()
            pin.framesForwardKinematics(mounted.model, a, q)
            pin.framesForwardKinematics(reference_uvms.model, b, q)
            pa = a.oMf[mounted.model.getFrameId(frame)]
            pb = b.oMf[reference_uvms.model.getFrameId(frame)]
            assert pa.isApprox(pb, 1e-12)


def test_added_probe_and_frames_match_the_reference_tool(split, reference_uvms):
    """The default probe is the reference tool: mounting the bare 4-DoF arm with it gives
    the same ee placement and the same mass (hydro of the probe derived, not read)."""
    import xml.etree.ElementTree as ET

    tree = ET.parse(split.arm_urdf)
    root = tree.getroot()
    for link in list(root.findall("link")):
        if link.get("name") in ("ft_sensor", "tool", "ee"):
            root.remove(link)
    for joint in list(root.findall("joint")):
        if joint.get("name") in ("ft_sensor_joint", "tool_joint", "ee_joint"):
            root.remove(joint)
    # the wrist flange: a frame 0.08 m along arm_link4 x, as in the reference model
    ET.SubElement(root, "link", {"name": "flange"})
    joint = ET.SubElement(root, "joint", {"name": "flange_joint", "type": "fixed"})
    ET.SubElement(joint, "parent", {"link": "arm_link4"})
    ET.SubElement(joint, "child", {"link": "flange"})
    ET.SubElement(joint, "origin", {"xyz": "0.08 0 0", "rpy": "0 0 0"})
    bare = split.arm_urdf.parent / "bare_arm.urdf"
    tree.write(bare)
    result = mount_arm_detailed(
        split.vehicle_urdf, bare, split.mount_pose, ee_link="flange", tool=ProbeTool()
    )
    uvms = result.uvms
    np.testing.assert_allclose(result.tool_axis_in_ee_link, [1.0, 0.0, 0.0])
    assert uvms.mass_kg == pytest.approx(reference_uvms.mass_kg, rel=1e-12)
    assert "tool/collision[0]" in result.derived_bodies
    q = random_configuration(reference_uvms, np.random.default_rng(1))
    a, b = uvms.model.createData(), reference_uvms.model.createData()
    pin.framesForwardKinematics(uvms.model, a, q)
    pin.framesForwardKinematics(reference_uvms.model, b, q)
    assert a.oMf[uvms.ee_frame_id].isApprox(b.oMf[reference_uvms.ee_frame_id], 1e-12)
    assert a.oMf[uvms.sensor_frame_id].isApprox(b.oMf[reference_uvms.sensor_frame_id], 1e-12)
    # derived probe volume = the reference tool's written one (both pi r^2 L)
    assert uvms.volume_m3 == pytest.approx(reference_uvms.volume_m3, rel=1e-5)


# ---------------------------------------------------------------- example-robot-data arms

ERD_ARMS = ("z1", "kinova", "ur3", "panda")


@pytest.mark.parametrize("name", ERD_ARMS)
def test_example_robot_data_arm_mounts_with_mesh_hydro(split, name):
    entry = CATALOG[name]
    result = mount_arm_detailed(
        split.vehicle_urdf,
        entry.urdf,
        _mount_pose(split),
        ee_link=entry.ee_link,
        allow_dry_links=True,
    )
    uvms = result.uvms
    assert uvms.n_arm_joints >= 6
    mesh_bodies = [
        b for b in uvms.hydro_bodies if b.params.derived and b.params.origin.startswith("mesh")
    ]
    assert mesh_bodies, "no coefficients derived from a mesh"
    for body in (b for b in uvms.hydro_bodies if b.params.derived):
        p = body.params
        assert p.volume_m3 > 0.0, body.name
        assert np.all(np.linalg.eigvalsh(p.added_mass[:3, :3]) > 0.0), body.name
        assert np.min(np.linalg.eigvalsh(p.added_mass)) >= -1e-12, body.name
    assert uvms.volume_m3 > 0.0
    q = uvms.neutral_configuration()
    m = up.mass_matrix(uvms, q)
    assert np.min(np.linalg.eigvalsh(0.5 * (m + m.T))) > 0.0
    from uvms_pin.model.summary import model_summary

    assert "*" in model_summary(uvms)  # derived bodies are marked


@pytest.mark.parametrize("name", ["ur3", "ur5", "ur10", "panda", "z1", "kinova", "xarm7", "so100"])
def test_every_arm_the_project_uses_passes_the_model_checks(split, name):
    """The inertia, joint-limit and hydrodynamics checks accept every arm compare-arms
    mounts (their massless frame links have zero inertia; point masses are allowed)."""
    entry = CATALOG[name]
    uvms = up.mount_arm(
        split.vehicle_urdf,
        entry.urdf,
        _mount_pose(split),
        ee_link=entry.ee_link,
        arm_base_link=entry.arm_base_link,
        allow_dry_links=True,
    )
    assert uvms.n_arm_joints >= 5
    assert np.all(uvms.model.lowerPositionLimit[7:] <= uvms.model.upperPositionLimit[7:])
    assert np.all(np.linalg.eigvalsh(up.mass_matrix(uvms, uvms.neutral_configuration())) > 0)


def test_available_arms_lists_installed_example_robot_data_arms():
    names = available_arms()
    assert names[0] == "reference"
    assert {"ur5", "panda", "z1", "kinova", "so100"} <= set(names)


def test_trim_makes_a_heavy_arm_neutral_and_stable(split):
    entry = CATALOG["ur3"]
    spec = TrimSpec(bg_m=0.03)
    result = mount_arm_detailed(
        split.vehicle_urdf, entry.urdf, _mount_pose(split), ee_link=entry.ee_link, trim=spec
    )
    report, uvms = result.trim, result.uvms
    assert report.net_buoyancy_before_N < -10.0  # the UR3 sinks the vehicle
    assert report.foam_volume_m3 > 0.0
    assert abs(uvms.net_buoyancy_N) < 1e-6
    assert report.net_buoyancy_after_N == pytest.approx(uvms.net_buoyancy_N, abs=1e-6)
    mass, com, _volume, cob = mass_properties(uvms, uvms.neutral_configuration())
    assert mass == pytest.approx(report.mass_after_kg)
    assert cob[2] - com[2] == pytest.approx(report.bg_after_m, abs=1e-9)
    assert report.bg_after_m > 0.0
    assert "foam" in report.summary()


def test_compare_arms_runs_the_force_task(tmp_path):
    arms = ["reference", "ur3", "z1", "panda", "so100"]
    rows = compare_arms(
        SCENARIO, arms, tmp_path, CompareSettings(duration_s=0.4, ik_starts=8), jobs=1
    )
    assert [r["arm"] for r in rows] == arms
    for path in ("comparison.csv", "comparison.md", "comparison.png"):
        assert (tmp_path / path).is_file()
    assert not list(tmp_path.glob(".*tmp*"))
    by = {r["arm"]: r for r in rows}
    known = {"ok", "FunnelViolation", "SimulationError", "joint limits", "unreachable"}
    for row in rows:
        assert row["status"] in known, (row["arm"], row["status"], row["reason"])
        if row["status"] != "ok":
            assert row["reason"]
    ran = [r for r in rows if r["status"] not in ("unreachable",) and r["arm"] != "reference"]
    assert len(ran) >= 3
    for row in ran:
        assert row["simulated_time_s"] > 0.0
        assert math.isfinite(row["force_error_rms_N"])
        assert abs(row["net_buoyancy_after_N"]) < 1e-6
    assert by["so100"]["status"] == "unreachable"  # 0.5 m from its base: out of reach
    text = (tmp_path / "comparison.md").read_text()
    for arm in arms:
        assert f"| {arm} |" in text


# ---------------------------------------------------------------- bad input


def _arm_text(extra_links: str = "", extra_joints: str = "", collision: str | None = None) -> str:
    geometry = collision or '<cylinder radius="0.02" length="0.1"/>'
    return f"""<robot name="tiny">
  <link name="base"/>
  <link name="l1">
    <inertial><mass value="0.2"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry>{geometry}</geometry></collision>
  </link>
  {extra_links}
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint>
  {extra_joints}
</robot>"""


def test_missing_mesh_is_named(split, write_urdf):
    arm = write_urdf(_arm_text(collision='<mesh filename="meshes/nowhere.stl"/>'), "arm.urdf")
    with pytest.raises(ModelError, match=r"nowhere\.stl.*") as info:
        mount_arm(split.vehicle_urdf, arm, split.mount_pose)
    assert "l1" in str(info.value) and str(arm) in str(info.value)


HYDRO = """<hydrodynamics><volume value="1e-4"/><added_mass diagonal="0.1 0.1 0.1 0 0 0"/>
    <linear_damping diagonal="0 0 0 0 0 0"/><quadratic_damping diagonal="1 1 1 0 0 0"/>
    </hydrodynamics>"""


@pytest.mark.parametrize("where", ["in its link", "at the top level"])
def test_a_link_with_hydrodynamics_needs_no_collision_mesh(split, write_urdf, where):
    """Its coefficients are given: a collision mesh that cannot be found is dropped, not
    refused (it would be read only to derive them), whether the <hydrodynamics> element is
    in the link or at the top level naming it."""
    text = _arm_text(collision='<mesh filename="meshes/nowhere.stl"/>')
    if where == "in its link":
        text = text.replace("</collision>\n  </link>", f"</collision>{HYDRO}</link>", 1)
    else:
        text = text.replace(
            "</robot>", HYDRO.replace("<hydrodynamics>", '<hydrodynamics link="l1">') + "</robot>"
        )
    assert text.count("<hydrodynamics") == 1
    uvms = mount_arm(split.vehicle_urdf, write_urdf(text, "arm.urdf"), split.mount_pose)
    (l1,) = [b for b in uvms.hydro_bodies if b.name == "l1"]
    assert l1.params.volume_m3 == pytest.approx(1e-4)


def test_an_arm_bolted_by_a_link_below_its_root_leaves_what_is_above_behind(split, write_urdf):
    """``arm_base_link`` below the arm file's root (a pedestal the arm stands on in its own
    file): the pedestal and the joint holding the base to it are not mounted."""
    pedestal = """<link name="pedestal">
    <inertial><mass value="3.0"/><inertia ixx="1e-2" iyy="1e-2" izz="1e-2" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>"""
    stand = '<joint name="stand" type="fixed"><parent link="pedestal"/><child link="base"/></joint>'
    arm = write_urdf(_arm_text(pedestal, stand), "arm.urdf")
    alone = mount_arm(split.vehicle_urdf, write_urdf(_arm_text(), "alone.urdf"), split.mount_pose)
    uvms = mount_arm(split.vehicle_urdf, arm, split.mount_pose, arm_base_link="base")
    assert "stand" not in [f.name for f in uvms.model.frames]
    assert "pedestal" not in [f.name for f in uvms.model.frames]
    assert pin.computeTotalMass(uvms.model) == pytest.approx(pin.computeTotalMass(alone.model))


def test_missing_package_mesh_is_named(split, write_urdf):
    arm = write_urdf(
        _arm_text(collision='<mesh filename="package://no_such_pkg/m.stl"/>'), "arm.urdf"
    )
    with pytest.raises(ModelError, match=r"package://no_such_pkg/m\.stl"):
        mount_arm(split.vehicle_urdf, arm, split.mount_pose)


@pytest.mark.parametrize(
    ("pose", "match"),
    [
        (([0.2, 0.0, math.nan], [0, 0, 0]), "non-finite"),
        (([0.2, 0.0, 0.0], [0, math.inf, 0]), "non-finite"),
        (np.diag([1.0, 1.0, 2.0, 1.0]), "not a rotation"),
        (np.diag([1.0, 1.0, -1.0, 1.0]), "not a rotation"),
        (np.ones(5), "shape"),
    ],
)
def test_bad_mount_pose(split, write_urdf, pose, match):
    arm = write_urdf(_arm_text(), "arm.urdf")
    with pytest.raises(ParameterError, match=match):
        mount_arm(split.vehicle_urdf, arm, pose)


def test_unknown_link_names(split, write_urdf):
    arm = write_urdf(_arm_text(), "arm.urdf")
    with pytest.raises(ModelError, match=r"ee_link 'gripper_tip'.*links are: base, l1"):
        mount_arm(split.vehicle_urdf, arm, split.mount_pose, ee_link="gripper_tip")
    with pytest.raises(ModelError, match="arm_base_link 'plate'"):
        mount_arm(split.vehicle_urdf, arm, split.mount_pose, arm_base_link="plate")
    bad_joint = write_urdf(
        _arm_text(
            extra_joints='<joint name="j2" type="fixed"><parent link="l1"/><child link="ghost"/></joint>'
        ),
        "arm2.urdf",
    )
    with pytest.raises(ModelError, match="joint 'j2': unknown child link 'ghost'"):
        mount_arm(split.vehicle_urdf, bad_joint, split.mount_pose)


def test_closed_chain_is_named(split, write_urdf):
    links = """<link name="l2">
    <inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.02"/></geometry></collision></link>"""
    joints = """<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint>
    <joint name="j3" type="revolute"><parent link="base"/><child link="l2"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint>"""
    arm = write_urdf(_arm_text(links, joints), "arm.urdf")
    with pytest.raises(ModelError, match=r"link 'l2': closed chain.*'j2' and 'j3'"):
        mount_arm(split.vehicle_urdf, arm, split.mount_pose)


def test_mass_without_geometry_needs_allow_dry_links(split, write_urdf):
    links = """<link name="l2">
    <inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>"""
    joints = """<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint>"""
    arm = write_urdf(_arm_text(links, joints), "arm.urdf")
    with pytest.raises(ModelError, match=r"link 'l2'.*allow_dry_links"):
        mount_arm(split.vehicle_urdf, arm, split.mount_pose)
    result = mount_arm_detailed(split.vehicle_urdf, arm, split.mount_pose, allow_dry_links=True)
    assert result.dry_links == ["l2"]
    assert result.uvms.n_arm_joints == 2


def test_name_clash_is_renamed_and_nothing_is_left_behind(split, write_urdf, tmp_path):
    text = _arm_text().replace('"base"', '"base_link"')  # the vehicle's root is base_link
    arm = write_urdf(text, "arm.urdf")
    saved = tmp_path / "out" / "merged.urdf"
    result = mount_arm_detailed(split.vehicle_urdf, arm, split.mount_pose, save_urdf=saved)
    assert result.renamed == {"base_link": "arm_base_link"}
    assert saved.is_file() and saved.read_text() == result.urdf_text
    assert sorted(p.name for p in saved.parent.iterdir()) == ["merged.urdf"]
    assert "mount_arm(" in result.uvms.source


def test_relative_mesh_path_of_a_user_arm(split, tmp_path):
    import trimesh

    meshes = tmp_path / "arm" / "meshes"
    meshes.mkdir(parents=True)
    trimesh.creation.box(extents=(0.1, 0.04, 0.04)).export(meshes / "link.stl")
    arm = tmp_path / "arm" / "arm.urdf"
    arm.write_text(_arm_text(collision='<mesh filename="meshes/link.stl"/>'))
    uvms = mount_arm(split.vehicle_urdf, arm, split.mount_pose)
    body = next(b for b in uvms.hydro_bodies if b.name.startswith("l1/"))
    assert body.params.derived
    assert body.params.volume_m3 == pytest.approx(0.1 * 0.04 * 0.04, rel=1e-6)
    assert Path(uvms.source).name != "merged.urdf"


def test_load_uvms_derives_mesh_hydro_with_package_and_relative_paths(tmp_path, load_body):
    import trimesh
    from conftest import body_urdf

    package = tmp_path / "pkgs" / "my_robot" / "meshes"
    package.mkdir(parents=True)
    trimesh.creation.cylinder(radius=0.05, height=0.2, sections=64).export(package / "c.stl")
    rel = body_urdf(collision='<mesh filename="pkgs/my_robot/meshes/c.stl"/>')
    (tmp_path / "rel.urdf").write_text(rel)
    uvms = up.load_uvms(tmp_path / "rel.urdf", ee_frame="body", sensor_frame="body")
    (body,) = uvms.hydro_bodies
    assert body.params.derived and "mesh" in body.params.origin
    assert body.params.volume_m3 == pytest.approx(math.pi * 0.05**2 * 0.2, rel=2e-3)
    assert "cylinder" in body.params.origin  # two equal OBB sides: a cylinder
    pkg = body_urdf(collision='<mesh filename="package://my_robot/meshes/c.stl"/>')
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "pkg.urdf").write_text(pkg)
    uvms2 = up.load_uvms(
        tmp_path / "sub" / "pkg.urdf",
        ee_frame="body",
        sensor_frame="body",
        package_dirs=[tmp_path / "pkgs"],
    )
    assert uvms2.hydro_bodies[0].params == body.params
    with pytest.raises(ModelError, match=r"link 'body'.*package://my_robot/meshes/c\.stl"):
        up.load_uvms(tmp_path / "sub" / "pkg.urdf", ee_frame="body", sensor_frame="body")
