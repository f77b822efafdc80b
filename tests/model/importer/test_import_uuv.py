"""Importing uuv_simulator's RexROV: the Fossen plugin's matrices, its frame, its thrusters."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.errors import ModelError
from uvms_pin.hydro.added_mass import kirchhoff_wrench
from uvms_pin.hydro.damping import damping_wrench
from uvms_pin.model.importer.convert import import_model
from uvms_pin.model.importer.fossen import LINK_FROM_SNAME
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.physics.dynamics import mass_matrix

DATA = Path(__file__).parent / "data"
REXROV = DATA / "rexrov_expanded.urdf"

# the published plugin block (rexrov.gazebo.xacro), SNAME frame
A_SNAME = np.array(
    [
        [779.79, -6.8773, -103.32, 8.5426, -165.54, -7.8033],
        [-6.8773, 1222, 51.29, 409.44, -5.8488, 62.726],
        [-103.32, 51.29, 3659.9, 6.1112, -386.42, 10.774],
        [8.5426, 409.44, 6.1112, 534.9, -10.027, 21.019],
        [-165.54, -5.8488, -386.42, -10.027, 842.69, -1.1162],
        [-7.8033, 62.726, 10.775, 21.019, -1.1162, 224.32],
    ]
)
L_SNAME = np.array([-74.82, -69.48, -728.4, -268.8, -309.77, -105])
Q_SNAME = np.array([-748.22, -992.53, -1821.01, -672, -774.44, -523.27])
T = LINK_FROM_SNAME


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    out = tmp_path_factory.mktemp("rexrov") / "rexrov.urdf"
    result = import_model(REXROV, out)
    return result, out


def test_mass_matrix_is_rigid_body_plus_the_plugins_added_mass(imported):
    result, out = imported
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the import is a complete model: nothing to warn of
        uvms = load_uvms(out, water_density_kg_m3=result.fluid_density_kg_m3)
    assert uvms.nv == 6  # the thruster joints are not arm joints
    m = 1862.87
    inertia = np.array([[525.39, 1.44, 33.41], [1.44, 794.20, 2.6], [33.41, 2.6, 691.23]])
    m_rb = np.zeros((6, 6))
    m_rb[:3, :3] = m * np.eye(3)
    m_rb[3:, 3:] = inertia
    expected = m_rb + T @ (0.5 * (A_SNAME + A_SNAME.T)) @ T
    got = mass_matrix(uvms, uvms.neutral_configuration())
    assert np.max(np.abs(got - expected)) <= 1e-12 * np.max(np.abs(expected))
    # every entry the plugin states symmetrically is carried exactly
    symmetric = A_SNAME == A_SNAME.T
    m_a = result.hydro["rexrov/base_link"].added_mass
    np.testing.assert_array_equal(m_a[symmetric], (T @ A_SNAME @ T)[symmetric])


def test_the_one_asymmetric_entry_is_reported(imported):
    result, _ = imported
    (note,) = [n for n in result.not_mapped if "not symmetric" in n]
    assert "0.001" in note  # |10.774 - 10.775|


def test_buoyancy_and_density_are_the_plugins(imported):
    result, _out = imported
    params = result.hydro["rexrov/base_link"]
    assert params.volume_m3 == 1.83826
    np.testing.assert_array_equal(params.center_of_buoyancy_m, [0.0, 0.0, 0.3])
    assert result.fluid_density_kg_m3 == 1028.0


def test_fluid_wrench_equals_the_plugins_in_the_link_frame(imported):
    """The plugin: nu_s = T nu, tau_s = -C_A(nu_s) nu_s - D(nu_s) nu_s with
    D = -L - diag(Q)|nu_s|, back by T. uvms-pin: -C_A nu - D_lin nu - D_quad |nu| nu."""
    result, _ = imported
    params = result.hydro["rexrov/base_link"]
    a_sym = 0.5 * (A_SNAME + A_SNAME.T)
    rng = np.random.default_rng(3)
    for nu in rng.normal(size=(20, 6)):
        nu_s = T @ nu
        d = -np.diag(L_SNAME) - np.diag(Q_SNAME * np.abs(nu_s))
        ab = a_sym @ nu_s
        sa = -pin.skew(ab[:3])
        c_a = np.block([[np.zeros((3, 3)), sa], [sa, -pin.skew(ab[3:])]])
        plugin = T @ (-d @ nu_s - c_a @ nu_s)
        ours = damping_wrench(
            params.linear_damping, params.quadratic_damping, nu
        ) - kirchhoff_wrench(params.added_mass, nu)
        np.testing.assert_allclose(ours, plugin, rtol=1e-12, atol=1e-9)


def test_damping_dissipates(imported):
    params = imported[0].hydro["rexrov/base_link"]
    assert np.all(np.linalg.eigvalsh(params.linear_damping) > 0.0)
    assert np.all(params.quadratic_damping > 0.0)


def test_thrusters_sit_where_the_joints_put_them(imported):
    result, out = imported
    assert [t.name for t in result.thrusters] == [f"rexrov/thruster_{i}" for i in range(8)]
    first = result.thrusters[0]
    np.testing.assert_array_equal(first.position_body_m, [-0.890895, 0.334385, 0.528822])
    rotation = pin.rpy.rpyToMatrix(0.0, np.radians(-74.53), np.radians(-53.21))
    np.testing.assert_allclose(first.direction_body, rotation[:, 0], atol=1e-15)
    assert first.time_constant_s == 0.05 and first.thrust_coefficient == 0.00031
    assert first.max_forward_N is None  # the plugin's thrust is unbounded by default
    # the horizontal thrusters push in the horizontal plane, 45 degrees off the axes
    for t in result.thrusters[4:]:
        assert abs(t.direction_body[2]) < 1e-15
        assert abs(abs(t.direction_body[0]) - np.sqrt(0.5)) < 1e-15
    table = out.with_suffix(".thrusters.toml").read_text()
    assert table.count("[[actuation.thruster]]") == 8
    assert "density_kg_m3 = 1028.0" in table
    assert any("thruster link 'rexrov/thruster_0'" in n for n in result.not_mapped)


def test_the_written_urdf_reads_back_the_same_coefficients(imported):
    result, out = imported
    uvms = load_uvms(out, water_density_kg_m3=1028.0)
    (body,) = uvms.hydro_bodies
    assert body.params == result.hydro["rexrov/base_link"]


def test_the_writer_says_what_it_did_not_map(imported):
    _result, out = imported
    text = out.read_text()
    assert "<flow_velocity_topic> not mapped" in text
    assert "<box> not mapped" in text


def test_unexpanded_xacro_is_refused(tmp_path):
    source = tmp_path / "v.xacro"
    source.write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:property name="a" value="1"/></robot>'
    )
    out = tmp_path / "out.urdf"
    with pytest.raises(ModelError, match="unexpanded xacro"):
        import_model(source, out)
    assert not out.exists()


@pytest.mark.parametrize(
    ("old", "new", "match"),
    [
        ("<type>fossen</type>", "<type>box</type>", 'type "box" cannot be imported'),
        ("-74.82 -69.48", "74.82 -69.48", "positive semi-definite"),
        ("<volume>1.83826</volume>", "<volume>x</volume>", "non-numeric"),
    ],
)
def test_bad_plugin_blocks_are_named(tmp_path, old, new, match):
    text = REXROV.read_text()
    assert old in text
    source = tmp_path / "bad.urdf"
    source.write_text(text.replace(old, new, 1))
    out = tmp_path / "out.urdf"
    with pytest.raises(ModelError, match=match):
        import_model(source, out)
    assert not out.exists()


def test_neutrally_buoyant_gives_volume_m_over_rho(tmp_path):
    source = tmp_path / "n.urdf"
    source.write_text(REXROV.read_text().replace("<neutrally_buoyant>0<", "<neutrally_buoyant>1<"))
    result = import_model(source)
    assert result.hydro["rexrov/base_link"].volume_m3 == pytest.approx(1862.87 / 1028.0, rel=1e-15)


def test_unexpanded_xacro_without_its_namespace_declared_is_refused_as_xacro(tmp_path):
    source = tmp_path / "v.urdf.xacro"
    source.write_text('<robot name="v"><xacro:property name="a" value="1"/></robot>')
    with pytest.raises(ModelError, match="unexpanded xacro"):
        import_model(source, tmp_path / "out.urdf")


def test_a_plugin_block_of_a_link_the_model_lacks_is_skipped_as_the_plugin_skips_it(tmp_path):
    """uuv_simulator warns ("Specified link [...] not found") and goes on; so does the
    import, saying so (DAVE's RexROV + Predator names the Oberon 7's links so)."""
    text = REXROV.read_text()
    block = '<link name="rexrov/base_link">\n        <neutrally'
    assert block in text
    extra = '<link name="oberon7/base"><volume>0.01</volume><hydrodynamic_model><type>fossen</type></hydrodynamic_model></link>\n      '
    source = tmp_path / "extra.urdf"
    source.write_text(text.replace(block, extra + block, 1))
    result = import_model(source)
    assert list(result.hydro) == ["rexrov/base_link"]
    (note,) = [n for n in result.not_mapped if "oberon7/base" in n]
    assert "not in the model: skipped" in note
