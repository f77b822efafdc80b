"""Swapping the arm of the shipped model (issue 11.2): mount_arm replaces the arm a vehicle
file carries, keeps it on request, and takes catalogue names and entries."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import REFERENCE_URDF, ROOT, random_configuration

import uvms_pin as up
from uvms_pin.model.mount.catalog import CATALOG
from uvms_pin.model.mount.mount import mount_arm_detailed
from uvms_pin.model.mount.split import split_urdf

VEHICLE_URDF = ROOT / "models" / "lbv150.urdf"
POSE = ((0.2, 0.0, -0.18), (math.pi, 0.0, 0.0))  # under the hull, upside down
REFERENCE_ARM = [f"arm_joint{k}" for k in range(1, 5)]
REFERENCE_ARM_LINKS = [f"arm_link{k}" for k in range(1, 5)]


def assert_same_dynamics(a: up.UVMS, b: up.UVMS, seed: int = 3) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(5):
        q = random_configuration(a, rng)
        v = rng.normal(size=a.nv)
        current = rng.normal(size=3) * 0.3
        np.testing.assert_allclose(up.mass_matrix(a, q), up.mass_matrix(b, q), atol=1e-12)
        np.testing.assert_allclose(
            up.bias_forces(a, q, v, current), up.bias_forces(b, q, v, current), atol=1e-10
        )


def test_an_erd_arm_on_the_shipped_uvms_replaces_its_arm():
    """uvms_lbv150 + UR5 = lbv150 + UR5: the vehicle plus the new arm only."""
    with pytest.warns(UserWarning, match="replaced the arm") as record:
        on_uvms = mount_arm_detailed(REFERENCE_URDF, "ur5", POSE)
    message = next(str(w.message) for w in record if "replaced the arm" in str(w.message))
    for name in (*REFERENCE_ARM, "ft_sensor", "tool", "ee"):
        assert name in message
    with warnings.catch_warnings(record=True) as quiet:
        warnings.simplefilter("always")  # a vehicle alone: nothing replaced, nothing said
        on_vehicle = mount_arm_detailed(VEHICLE_URDF, "ur5", POSE)
    assert not [w for w in quiet if "replaced the arm" in str(w.message)]
    assert on_uvms.removed_joints == [
        *REFERENCE_ARM,
        "ft_sensor_joint",
        "tool_joint",
        "ee_joint",
    ]
    assert on_uvms.removed_links == [*REFERENCE_ARM_LINKS, "ft_sensor", "tool", "ee"]
    assert on_vehicle.removed_links == [] and on_vehicle.removed_joints == []
    a, b = on_uvms.uvms, on_vehicle.uvms
    assert a.nv == 6 + 6 and b.nv == a.nv
    assert a.arm_joint_names == b.arm_joint_names
    assert not set(a.arm_joint_names) & set(REFERENCE_ARM)
    assert a.mass_kg == pytest.approx(b.mass_kg, rel=1e-14)
    assert_same_dynamics(a, b)


def test_the_reference_arm_mounted_back_on_the_shipped_uvms_is_the_reference(
    tmp_path, reference_uvms
):
    """Replacing the arm by itself gives the reference model: exactly the arm was removed."""
    split = split_urdf(REFERENCE_URDF, tmp_path)
    with pytest.warns(UserWarning, match="replaced the arm"):
        mounted = up.mount_arm(
            REFERENCE_URDF,
            split.arm_urdf,
            split.mount_pose,
            ee_link="ee",
            sensor_link="ft_sensor",
            tool=None,
        )
    assert mounted.arm_joint_names == reference_uvms.arm_joint_names  # no renaming needed
    assert mounted.volume_m3 == pytest.approx(reference_uvms.volume_m3, rel=1e-12)
    assert_same_dynamics(mounted, reference_uvms)


def test_keep_existing_arm_gives_two_arms_with_distinct_names():
    result = mount_arm_detailed(REFERENCE_URDF, CATALOG["ur3"], POSE, keep_existing_arm=True)
    uvms = result.uvms
    assert result.removed_links == []
    assert uvms.nv == 6 + 4 + 6
    names = uvms.arm_joint_names
    assert len(set(names)) == len(names) and set(REFERENCE_ARM) <= set(names)
    model = uvms.model
    frames = {f.name for f in model.frames}
    assert {"ee", "ft_sensor", "arm_ee", "arm_ft_sensor"} <= frames
    # the UVMS's end-effector is the new arm's: it moves with a UR3 joint, not arm_joint1
    assert model.frames[uvms.ee_frame_id].name == "arm_ee"
    q = uvms.neutral_configuration()
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    before = data.oMf[uvms.ee_frame_id].translation.copy()
    old_ee = data.oMf[model.getFrameId("ee")].translation.copy()
    q[model.joints[model.getJointId("arm_joint1")].idx_q] += 0.3
    pin.framesForwardKinematics(model, data, q)
    np.testing.assert_allclose(data.oMf[uvms.ee_frame_id].translation, before, atol=1e-12)
    assert np.linalg.norm(data.oMf[model.getFrameId("ee")].translation - old_ee) > 0.01


def test_catalogue_names_and_entries_are_arms():
    by_name = up.mount_arm(VEHICLE_URDF, "ur3", POSE)
    by_entry = up.mount_arm(VEHICLE_URDF, CATALOG["ur3"], POSE)
    by_path = up.mount_arm(VEHICLE_URDF, CATALOG["ur3"].urdf, POSE, ee_link="tool0")
    by_shipped_name = up.mount_arm("lbv150", "ur3", POSE)
    for other in (by_entry, by_path, by_shipped_name):
        assert other.arm_joint_names == by_name.arm_joint_names
        assert_same_dynamics(other, by_name)


def test_an_unknown_arm_name_lists_the_catalogue():
    with pytest.raises(up.ParameterError, match=r"unknown arm 'ur55'.*ur5"):
        up.mount_arm(VEHICLE_URDF, "ur55", POSE)


TRIMMED_URDF = ROOT / "models" / "uvms_bluerov2_alpha5.urdf"  # its mount trimmed the Alpha 5
TRIM = ["trim_foam", "trim_ballast"]


def _trim_links(uvms: up.UVMS) -> list[str]:
    return sorted(f.name for f in uvms.model.frames if "trim_" in f.name and "joint" not in f.name)


def test_replacing_a_trimmed_arm_removes_its_trim_and_trims_the_new_arm_alone(tmp_path):
    """The Alpha 5's foam and ballast go with it: the UR3 on the BlueROV2 + Alpha 5 is the
    UR3 on the vehicle split from it, trimmed the same way (trim=True: neutral again)."""
    with pytest.warns(UserWarning, match="replaced the arm"):
        replaced = mount_arm_detailed(TRIMMED_URDF, "ur3", POSE, trim=True)
    assert replaced.removed_links[-2:] == TRIM
    assert replaced.removed_joints[-2:] == [f"{name}_joint" for name in TRIM]
    split = split_urdf(TRIMMED_URDF, tmp_path, first_arm_joint="alpha_axis_e")
    assert split.trim_links == tuple(TRIM)
    for path in (split.vehicle_urdf, split.arm_urdf):
        assert "trim_" not in path.read_text()
    on_split = mount_arm_detailed(split.vehicle_urdf, "ur3", POSE, trim=True)
    assert _trim_links(replaced.uvms) == _trim_links(on_split.uvms)
    assert replaced.uvms.mass_kg == pytest.approx(on_split.uvms.mass_kg, rel=1e-12)
    assert replaced.uvms.volume_m3 == pytest.approx(on_split.uvms.volume_m3, rel=1e-12)
    assert replaced.trim.net_buoyancy_after_N == pytest.approx(0.0, abs=1e-6)


def test_a_kept_arm_keeps_its_trim_and_the_new_trim_is_named_apart():
    kept = mount_arm_detailed(TRIMMED_URDF, "ur3", POSE, trim=True, keep_existing_arm=True)
    names = _trim_links(kept.uvms)
    assert set(TRIM) <= set(names) and len(names) == len(set(names)) > len(TRIM)
    assert all(name in TRIM or name.removeprefix("arm_") in TRIM for name in names)
    assert kept.trim.net_buoyancy_after_N == pytest.approx(0.0, abs=1e-6)


def test_a_trimmed_uvms_split_and_its_arm_mounted_back_with_its_trim_is_that_uvms(tmp_path):
    """The BlueROV2 + Alpha 5 split: the arm from the joint that bolted its base (the
    Alpha 5's base link is the arm's), posed in the vehicle's root link through that joint,
    the trim in neither file; mounted back and trimmed as its file was, the same model."""
    split = split_urdf(TRIMMED_URDF, tmp_path, first_arm_joint="alpha_axis_e")
    assert split.vehicle_link == "base_link" and split.trim_links == tuple(TRIM)
    assert "alpha_" not in split.vehicle_urdf.read_text()
    reference = up.load_uvms(TRIMMED_URDF)
    data = reference.model.createData()
    q = reference.neutral_configuration()
    q[:7] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)  # the vehicle frame is the world
    pin.forwardKinematics(reference.model, data, q)
    base = reference.model.frames[reference.model.getFrameId("alpha_base_link")]
    placement = data.oMi[base.parentJoint] * base.placement
    np.testing.assert_allclose(split.mount_pose.homogeneous, placement.homogeneous, atol=1e-15)
    again = mount_arm_detailed(
        split.vehicle_urdf, split.arm_urdf, split.mount_pose, ee_link="ee",
        sensor_link="ft_sensor", tool=None, trim=True,
        trim_joint_positions=(-0.2, 0.8, 2.2, 0.2),  # the force task's, as its file was made
    )  # fmt: skip
    assert again.uvms.arm_joint_names == reference.arm_joint_names
    assert again.uvms.mass_kg == pytest.approx(reference.mass_kg, rel=1e-14)
    assert again.uvms.volume_m3 == pytest.approx(reference.volume_m3, rel=1e-14)
    assert_same_dynamics(again.uvms, reference)


def test_an_arm_on_a_bracket_of_the_vehicle_is_posed_in_the_vehicles_root_link(tmp_path):
    """An arm whose first joint hangs from a fixed bracket of the vehicle (here the Alpha 5's
    base, its joint not named as a mount names it): the bracket stays the vehicle's, and the
    mount pose is the first joint's placement in the root link, through the bracket."""
    text = TRIMMED_URDF.read_text().replace("arm_mount_joint", "bracket_joint")
    (tmp_path / "bracket.urdf").write_text(text)
    split = split_urdf(tmp_path / "bracket.urdf", tmp_path / "split", "alpha_axis_e")
    assert split.vehicle_link == "base_link"
    assert 'link name="alpha_base_link"' in split.vehicle_urdf.read_text()
    reference = up.load_uvms(tmp_path / "bracket.urdf")
    model, data = reference.model, reference.model.createData()
    q = reference.neutral_configuration()
    q[:7] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
    pin.forwardKinematics(model, data, q)
    joint = data.oMi[model.getJointId("alpha_axis_e")]
    np.testing.assert_allclose(split.mount_pose.homogeneous, joint.homogeneous, atol=1e-15)
    assert np.linalg.norm(split.mount_pose.translation) > 0.2  # not the bracket's own frame


def test_split_finds_the_arms_first_joint_and_refuses_a_vehicle_alone(tmp_path):
    found = split_urdf(TRIMMED_URDF, tmp_path / "found")
    named = split_urdf(TRIMMED_URDF, tmp_path / "named", first_arm_joint="alpha_axis_e")
    assert found.arm_urdf.read_text() == named.arm_urdf.read_text()
    assert found.mount_pose.isApprox(named.mount_pose, 0.0)
    with pytest.raises(up.ModelError, match=r"give first_arm_joint.*a vehicle alone"):
        split_urdf(VEHICLE_URDF, tmp_path / "alone")


def test_a_split_makes_relative_mesh_paths_absolute_and_keeps_the_others(tmp_path):
    """The two files are written elsewhere than the source: a relative mesh path is made
    absolute from the source's folder (vehicle and arm alike); an absolute path and a URI
    (package://, file://) are kept as they are."""
    import xml.etree.ElementTree as ET

    def visual(filename: str) -> str:
        return f'<visual><geometry><mesh filename="{filename}"/></geometry></visual>'

    text = REFERENCE_URDF.read_text()
    meshes = {"base_link": "meshes/hull.stl", "arm_link2": "../common/link2.dae",
              "arm_link3": "/opt/meshes/link3.stl", "arm_link4": "package://arm/link4.stl"}  # fmt: skip
    for link, filename in meshes.items():
        opening = f'<link name="{link}">'
        assert text.count(opening) == 1
        text = text.replace(opening, opening + visual(filename))
    source = tmp_path / "src" / "uvms.urdf"
    source.parent.mkdir()
    source.write_text(text)
    split = split_urdf(source, tmp_path / "out")
    written = {}
    for part in (split.vehicle_urdf, split.arm_urdf):
        for link in ET.parse(part).getroot().iter("link"):
            for mesh in link.iter("mesh"):
                written.setdefault(link.get("name"), []).append(mesh.get("filename"))
    assert written["base_link"][0] == str((source.parent / "meshes/hull.stl").resolve())
    assert written["arm_link2"][0] == str((tmp_path / "common" / "link2.dae").resolve())
    assert written["arm_link3"][0] == "/opt/meshes/link3.stl"
    assert written["arm_link4"][0] == "package://arm/link4.stl"
