"""What Gazebo runs and uvms-pin's loader would refuse: an inertia no mass distribution has
(refused at the import, or balanced on request) and uuv_simulator's fins (their joints set
by the plugin: held fixed)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from uvms_pin.errors import ModelError
from uvms_pin.model.importer.convert import import_model
from uvms_pin.model.urdf.load import load_uvms

REXROV = Path(__file__).parent / "data" / "rexrov_expanded.urdf"
HULL_INERTIA = 'ixx="525.39" ixy="1.44" ixz="33.41" iyy="794.20" iyz="2.6" izz="691.23"'
# principal moments of (0.6, 30, 35) turned about z: I1 + I2 < I3, as uuv_simulator's ECA A9
BAD_INERTIA = 'ixx="15.3" ixy="14.7" ixz="0.0" iyy="15.3" iyz="0.0" izz="35.0"'
FIN = """
  <link name="rexrov/fin0"><inertial><mass value="0.001"/>
    <inertia ixx="1e-9" ixy="0" ixz="0" iyy="1e-9" iyz="0" izz="1e-9"/></inertial></link>
  <joint name="rexrov/fin0_joint" type="revolute"><parent link="rexrov/base_link"/>
    <child link="rexrov/fin0"/><origin xyz="-1.2 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit effort="0" lower="-1.4" upper="1.4" velocity="0"/></joint>
  <gazebo><plugin filename="libuuv_fin_ros_plugin.so" name="fin0_model">
    <liftdrag><type>TwoLines</type><area>0.04155</area><fluid_density>1027.0</fluid_density>
      <a0>0.05</a0><alpha_stall>0.174533</alpha_stall><cla>13.98</cla><cla_stall>0.0</cla_stall>
      <cda>0.0</cda><cda_stall></cda_stall></liftdrag>
    <joint_name>rexrov/fin0_joint</joint_name><link_name>rexrov/fin0</link_name>
  </plugin></gazebo>
</robot>"""


def _source(tmp_path, text: str) -> Path:
    path = tmp_path / "source.urdf"
    path.write_text(text)
    return path


def test_an_inertia_no_body_has_is_refused_at_the_import_saying_how_to_balance_it(tmp_path):
    source = _source(tmp_path, REXROV.read_text().replace(HULL_INERTIA, BAD_INERTIA, 1))
    out = tmp_path / "out.urdf"
    with pytest.raises(
        ModelError, match=r"'rexrov/base_link'.*triangle inequality.*--balance-inertia"
    ):
        import_model(source, out)
    assert not out.exists()  # refused before anything is written (it could not be loaded)


def test_balanced_its_smallest_moment_is_raised_to_the_least_that_makes_it_one(tmp_path):
    source = _source(tmp_path, REXROV.read_text().replace(HULL_INERTIA, BAD_INERTIA, 1))
    out = tmp_path / "out.urdf"
    result = import_model(source, out, balance_inertia=True)
    (note,) = [n for n in result.not_mapped if "balanced" in n]
    assert "(0.6, 30, 35)" in note and "(5, 30, 35)" in note
    uvms = load_uvms(out, water_density_kg_m3=1028.0)
    inertia = uvms.model.inertias[1].inertia
    before = np.array([[15.3, 14.7, 0.0], [14.7, 15.3, 0.0], [0.0, 0.0, 35.0]])
    moments, axes = np.linalg.eigh(inertia)
    np.testing.assert_allclose(moments, [5.0, 30.0, 35.0], atol=1e-9)
    # the same principal axes: each of the source's eigenvectors is one of the balanced's
    _, source_axes = np.linalg.eigh(before)
    np.testing.assert_allclose(np.abs(axes.T @ source_axes), np.eye(3), atol=1e-9)


def test_a_negative_moment_is_refused_even_balanced(tmp_path):
    negative = BAD_INERTIA.replace('izz="35.0"', 'izz="-35.0"')
    source = _source(tmp_path, REXROV.read_text().replace(HULL_INERTIA, negative, 1))
    with pytest.raises(ModelError, match="not positive semi-definite"):
        import_model(source, balance_inertia=True)


def test_a_uuv_fin_joint_is_held_fixed_and_its_lift_reported_not_mapped(tmp_path):
    """The Fin plugin sets its joint's angle itself: a free fin of no inertia would make the
    mass matrix singular; fixed at 0 (a command of 0), the vehicle loads and runs."""
    source = _source(tmp_path, REXROV.read_text().replace("</robot>", FIN, 1))
    out = tmp_path / "out.urdf"
    result = import_model(source, out)
    (note,) = [n for n in result.not_mapped if "fin joint 'rexrov/fin0_joint'" in n]
    assert "written fixed at 0" in note
    uvms = load_uvms(out, water_density_kg_m3=1028.0, allow_dry_links=True)
    assert uvms.nv == 6  # the fin is no degree of freedom
    (fin,) = uvms.fins
    assert fin.name == "rexrov/fin0"


def _uuv_two_lines(v, area, rho, cla, alpha_stall, a0):
    """uuv_simulator's LiftDragTwoLines::compute for a flow in the fin's x-y plane (c_D = 0,
    no slope beyond the stall), its steps as written there."""
    vel = v.copy()
    angle = math.atan2(v[1], v[0])
    if angle > math.pi / 2:
        angle, vel = angle - math.pi, -v
    elif angle < -math.pi / 2:
        angle, vel = angle + math.pi, -v
    alpha = angle + a0
    cl = cla * (alpha if abs(alpha) <= alpha_stall else math.copysign(alpha_stall, alpha))
    lift = cl * 0.5 * rho * float(vel @ vel) * area
    direction = -np.cross([0.0, 0.0, 1.0], v)
    return lift * direction / np.linalg.norm(direction)


def test_a_uuv_two_lines_fin_pushes_as_the_plugin_for_flows_in_its_plane(tmp_path):
    """The fin's <lift_drag> against uuv_simulator's formula, for flows in the fin's x-y
    plane (no sweep) above 0.01 m/s, from ahead and from behind, below and beyond the stall."""
    from uvms_pin.hydro.lift_drag import lift_drag_wrench

    source = _source(tmp_path, REXROV.read_text().replace("</robot>", FIN, 1))
    out = tmp_path / "out.urdf"
    import_model(source, out)
    (fin,) = load_uvms(out, water_density_kg_m3=1028.0, allow_dry_links=True).fins
    rng = np.random.default_rng(4)
    for k in range(200):
        angle = rng.uniform(-0.6, 0.6) + (math.pi if k % 2 else 0.0)
        v = rng.uniform(0.05, 3.0) * np.array([math.cos(angle), math.sin(angle), 0.0])
        ours, _ = lift_drag_wrench(fin.params, np.eye(3), v)
        theirs = _uuv_two_lines(v, 0.04155, 1027.0, 13.98, 0.174533, 0.05)
        np.testing.assert_allclose(ours, theirs, rtol=1e-5, atol=1e-9)


def test_a_uuv_fin_of_the_quadratic_model_is_reported_not_mapped(tmp_path):
    quadratic = FIN.replace("<type>TwoLines</type>", "<type>Quadratic</type>")
    source = _source(tmp_path, REXROV.read_text().replace("</robot>", quadratic, 1))
    result = import_model(source)
    assert any(
        "<liftdrag> type 'Quadratic'; its lift and drag not mapped" in n for n in result.not_mapped
    )
    assert "<lift_drag>" not in result.urdf_text.split("-->", 1)[1]


@pytest.mark.parametrize("balance", [False, True])
def test_an_inertia_entry_that_is_no_number_is_refused_by_name(tmp_path, balance):
    source = _source(tmp_path, REXROV.read_text().replace('ixz="33.41"', 'ixz="nan"', 1))
    with pytest.raises(ModelError, match="ixz"):
        import_model(source, balance_inertia=balance)


@pytest.mark.parametrize(("origin", "cp"), [(None, (0.0, 0.0, 0.0)),
                                             ('<origin xyz="0.05 0 -0.02"/>', (0.05, 0.0, -0.02)),
                                             ("<origin/>", (0.0, 0.0, 0.0))])  # fmt: skip
def test_a_uuv_fins_centre_of_pressure_is_its_links_centre_of_mass(tmp_path, origin, cp):
    """uuv_simulator's fin plugin applies its lift at the link's centre of mass (its
    inertial origin; the link's origin when there is none, or it has no xyz)."""
    fin = FIN if origin is None else FIN.replace("<inertial>", f"<inertial>{origin}", 1)
    source = _source(tmp_path, REXROV.read_text().replace("</robot>", fin, 1))
    out = tmp_path / "out.urdf"
    import_model(source, out)
    (loaded,) = load_uvms(out, water_density_kg_m3=1028.0, allow_dry_links=True).fins
    np.testing.assert_array_equal(loaded.params.cp_m, cp)
