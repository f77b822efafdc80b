"""A fixture (`uvms_pin.physics.world.fixture`): a URDF whose root is fixed in the world at
its pose, its joints' limits, damping and friction its URDF's, its links' collision shapes
on the joints that carry them, and the refusals naming the file and the key."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest
from fixture_helpers import RECEPTACLE, VALVE, lever_urdf

from uvms_pin.errors import ParameterError
from uvms_pin.physics.world.fixture import fixture

RHO = 1025.0
POSE = ([1.0, -2.0, -9.0], [0.0, 0.0, np.pi / 2])


def test_the_valve_is_placed_where_its_scenario_puts_it_with_its_urdf_joint():
    valve = fixture("panel", VALVE, POSE, water_density_kg_m3=RHO)
    model = valve.uvms.model
    assert valve.joint_names == ("valve",) and valve.joint_units == ("rad",)
    assert (model.nq, model.nv) == (1, 1)
    np.testing.assert_allclose(model.lowerPositionLimit, [0.0])
    np.testing.assert_allclose(model.upperPositionLimit, [np.pi / 2])
    np.testing.assert_allclose(valve.coulomb, [2.0])
    np.testing.assert_allclose(valve.damping, [0.5])
    data = model.createData()
    pin.forwardKinematics(model, data, np.zeros(1))
    # the joint on the panel's front face, its axis (the panel's x) turned by the yaw
    np.testing.assert_allclose(data.oMi[1].translation, POSE[0], atol=1e-12)
    np.testing.assert_allclose(data.oMi[1].rotation[:, 0], [0.0, 1.0, 0.0], atol=1e-12)
    # the plate on the world (joint 0), the stem and the paddle on the handle's joint
    assert [p.joint_id for p in valve.pieces] == [0, 1, 1]
    assert valve.piece_names == ("panel.panel", "panel.handle", "panel.handle")
    plate = valve.pieces[0]
    np.testing.assert_allclose(plate.placement_in_joint.translation, [1.0, -2.01, -9.0])


def test_joint_positions_by_name_or_in_order_within_the_limits(tmp_path):
    valve = fixture("panel", VALVE, POSE, joint_positions={"valve": 0.4}, water_density_kg_m3=RHO)
    np.testing.assert_allclose(valve.q0, [0.4])
    assert fixture("p", VALVE, POSE, joint_positions=[1.2], water_density_kg_m3=RHO).q0 == 1.2
    assert valve.signal(np.array([0.3])).components == ("valve",)
    assert valve.signal(np.array([0.3])).units == ("rad",)


def test_a_receptacle_is_a_fixture_without_a_moving_joint():
    receptacle = fixture("receptacle", RECEPTACLE, POSE, water_density_kg_m3=RHO)
    assert receptacle.uvms.nq == 0 and receptacle.joint_names == ()
    assert len(receptacle.pieces) == 17 and {p.joint_id for p in receptacle.pieces} == {0}


def test_bad_input_is_refused_naming_the_key_and_the_file(tmp_path):
    with pytest.raises(ParameterError, match="names joint 'gate'") as refused:
        fixture("panel", VALVE, POSE, joint_positions={"gate": 0.1}, water_density_kg_m3=RHO)
    assert refused.value.key == "joint_positions_rad"
    assert str(VALVE) in str(refused.value)
    with pytest.raises(ParameterError, match="outside its limits") as refused:
        fixture("panel", VALVE, POSE, joint_positions={"valve": 2.0}, water_density_kg_m3=RHO)
    assert refused.value.key == "joint_positions_rad"
    with pytest.raises(ParameterError, match="needs 1 values"):
        fixture("panel", VALVE, POSE, joint_positions=[0.1, 0.2], water_density_kg_m3=RHO)
    missing = tmp_path / "nowhere.urdf"
    with pytest.raises(ParameterError, match="no URDF file") as refused:
        fixture("panel", missing, POSE, water_density_kg_m3=RHO)
    assert refused.value.key == "path" and str(missing) in str(refused.value)
    floating = lever_urdf(tmp_path, friction_Nm=0.0, joint_type="floating")
    with pytest.raises(ParameterError, match="'hinge' is floating") as refused:
        fixture("lever", floating, POSE, water_density_kg_m3=RHO)
    assert refused.value.key == "path" and str(floating) in str(refused.value)


def test_the_receptacles_bore_leaves_a_25_mm_stab_its_clearance():
    """A 25 mm stab on the bore's axis clears every wall by 1.5 mm (the flats), a 28.5 mm
    one touches them; the chamfer's mouth takes a stab 10 mm off the axis."""
    receptacle = fixture("receptacle", RECEPTACLE, ([0, 0, 0], [0, 0, 0]), water_density_kg_m3=RHO)

    def clearance_m(radius_m: float, offset_m: float = 0.0, x_m: float = -0.075) -> float:
        stab = coal.Cylinder(radius_m, 0.1)
        along_x = pin.SE3(pin.rpy.rpyToMatrix(0.0, np.pi / 2, 0.0), np.array([x_m, offset_m, 0]))
        request, distances = coal.DistanceRequest(), []
        for piece in receptacle.pieces:
            result = coal.DistanceResult()
            where = piece.placement_in_joint
            coal.distance(
                stab, coal.Transform3s(along_x.rotation, along_x.translation),
                piece.shape, coal.Transform3s(where.rotation, where.translation),
                request, result,
            )  # fmt: skip
            distances.append(result.min_distance)
        return min(distances)

    assert clearance_m(0.0125) == pytest.approx(0.0015, abs=1e-6)
    assert clearance_m(0.01425) < 0.0
    # 10 mm off the axis, just in front of the mouth: the chamfer, not the wall's end, is hit
    assert clearance_m(0.0125, offset_m=0.010, x_m=0.055) < 0.0  # its end 5 mm out
    assert clearance_m(0.0125, offset_m=0.010, x_m=0.08) > 0.0


def test_a_prismatic_joint_is_logged_in_metres(tmp_path):
    latch = fixture(
        "latch", lever_urdf(tmp_path, friction_Nm=1.0, joint_type="prismatic"), POSE,
        joint_positions={"hinge": 0.05}, water_density_kg_m3=RHO,
    )  # fmt: skip
    assert latch.joint_units == ("m",)
    signal = latch.signal(latch.q0)
    assert signal.components == ("hinge",) and signal.units == ("m",) and signal.values[0] == 0.05


def _two_joint_urdf(folder, *, second_mass_kg: float = 0.5):
    """A fixed ``base``, an ``arm`` on ``hinge`` (limits [-0.5, 1.0] rad) and a ``slider`` on
    ``slide`` (prismatic, [0, 0.2] m), the slider's mass ``second_mass_kg``."""
    inertia = 'ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"'
    slider = (
        f'<inertial><mass value="{second_mass_kg!r}"/><inertia {inertia}/></inertial>'
        if second_mass_kg > 0.0
        else ""
    )
    path = folder / "two_joints.urdf"
    path.write_text(f"""<robot name="two">
  <link name="base"><inertial><mass value="1"/><inertia {inertia}/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-0.5" upper="1.0" effort="10" velocity="1"/></joint>
  <link name="arm"><inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia {inertia}/></inertial></link>
  <joint name="slide" type="prismatic"><parent link="arm"/><child link="slider"/>
    <origin xyz="0.2 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0.0" upper="0.2" effort="10" velocity="1"/></joint>
  <link name="slider">{slider}</link>
</robot>""")
    return path


def test_joint_positions_at_their_limits_are_kept_and_beyond_them_refused_by_joint(tmp_path):
    """Each joint's position is checked against its own limits: both joints at their lower
    and at their upper limits are accepted; a position just beyond one limit is refused
    naming that joint, its value and its limits."""
    path = _two_joint_urdf(tmp_path)
    for q0 in ([-0.5, 0.0], [1.0, 0.2]):
        two = fixture("two", path, POSE, joint_positions=q0, water_density_kg_m3=RHO)
        np.testing.assert_array_equal(two.q0, q0)
    for q0, joint, text in (
        ([-0.501, 0.1], "hinge", r"-0\.501, outside its limits \[-0\.5, 1\]"),
        ([1.001, 0.1], "hinge", r"1\.001, outside its limits \[-0\.5, 1\]"),
        ([0.3, -0.001], "slide", r"-0\.001, outside its limits \[0, 0\.2\]"),
        ([0.3, 0.201], "slide", r"0\.201, outside its limits \[0, 0\.2\]"),
    ):
        with pytest.raises(ParameterError, match=f"joint '{joint}' of .* at {text}") as refused:
            fixture("two", path, POSE, joint_positions=q0, water_density_kg_m3=RHO)
        assert refused.value.key == "joint_positions_rad"


def test_a_joint_the_fixture_lacks_is_refused_listing_its_moving_joints(tmp_path):
    path = _two_joint_urdf(tmp_path)
    with pytest.raises(ParameterError, match=r"names joint 'gate', .*\(hinge, slide\)"):
        fixture("two", path, POSE, joint_positions={"gate": 0.1}, water_density_kg_m3=RHO)


def test_a_moving_link_without_inertia_is_refused_naming_its_joint(tmp_path):
    """A slider with no <inertial> makes the fixture's mass matrix singular: refused by the
    joint that carries it (not the one before it), the key ``path``."""
    path = _two_joint_urdf(tmp_path, second_mass_kg=0.0)
    with pytest.raises(ParameterError, match=r"no inertia \(joint 'slide'\)") as refused:
        fixture("two", path, POSE, water_density_kg_m3=RHO)
    assert refused.value.key == "path"


def test_a_shipped_fixture_is_found_from_a_scenario_anywhere(tmp_path):
    """A fixture's ``path`` relative to the scenario's folder, else to the shipped models:
    ``fixtures/subsea_panel_valve.urdf`` from a folder without it is the shipped valve; a
    file beside the scenario wins over it; an absolute path is itself."""
    from uvms_pin.physics.world.fixture import fixture_path

    assert fixture_path("fixtures/subsea_panel_valve.urdf", tmp_path) == VALVE.resolve()
    own = tmp_path / "fixtures" / "subsea_panel_valve.urdf"
    own.parent.mkdir()
    own.write_text(VALVE.read_text())
    assert fixture_path("fixtures/subsea_panel_valve.urdf", tmp_path) == own.resolve()
    assert fixture_path(VALVE, tmp_path / "elsewhere") == VALVE.resolve()
