"""Importing gz-sim's LRAUV tutorial vehicle: Hydrodynamics coefficients, Buoyancy from the
collision shapes, the Thruster system, an SDF model as a URDF tree."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from uvms_pin.errors import ModelError
from uvms_pin.model.importer.convert import import_model
from uvms_pin.model.importer.gz_hydrodynamics import gz_hydrodynamics
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.physics.dynamics import mass_matrix

LRAUV = Path(__file__).parent / "data" / "lrauv_hydrodynamics.sdf"


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    out = tmp_path_factory.mktemp("lrauv") / "lrauv.urdf"
    return import_model(LRAUV, out), out


def test_coefficients_are_the_negated_stability_derivatives(imported):
    result, _ = imported
    params = result.hydro["base_link"]
    np.testing.assert_array_equal(
        np.diag(params.added_mass), [4.876161, 126.324739, 126.324739, 0.0, 33.46, 33.46]
    )
    np.testing.assert_array_equal(
        params.quadratic_damping, [6.2282, 601.27, 601.27, 0.1916, 632.698957, 632.698957]
    )
    assert not np.any(params.linear_damping)
    assert not np.any(params.added_mass - np.diag(np.diag(params.added_mass)))


def test_buoyancy_is_the_collision_boxs_volume_in_the_worlds_density(imported):
    result, _ = imported
    assert result.fluid_density_kg_m3 == 1000.0
    volume = 2 * 0.3 * 0.2464451666666667
    assert result.hydro["base_link"].volume_m3 == pytest.approx(volume, rel=1e-15)
    # the tutorial sizes the box for neutral buoyancy of the hull: rho V = m
    assert 1000.0 * volume == pytest.approx(147.8671, rel=1e-6)
    assert result.hydro["horizontal_fins"].volume_m3 == pytest.approx(0.1 * 0.1 * 0.02)


def test_the_model_loads_and_its_mass_matrix_has_the_added_mass(imported):
    _result, out = imported
    uvms = load_uvms(out, water_density_kg_m3=1000.0)
    # the propeller joint became the thruster; the two fin joints stay
    assert uvms.nv == 8
    assert [uvms.model.names[j] for j in range(2, uvms.model.njoints)] == [
        "horizontal_fins_joint",
        "vertical_fins_joint",
    ]
    m = mass_matrix(uvms, uvms.neutral_configuration())
    fins = 0.4  # two 0.2 kg fin links ride on the vehicle; boxes add their own added mass
    surge = 147.8671 + fins + 4.876161
    assert m[0, 0] == pytest.approx(surge, rel=1e-3)  # + the fins' geometry-free added mass: none
    assert m[0, 0] - surge == pytest.approx(0.0, abs=1e-9)


def test_thruster_along_the_propeller_axis(imported):
    result, _ = imported
    (thruster,) = result.thrusters
    assert thruster.name == "propeller_joint"
    np.testing.assert_allclose(thruster.position_body_m, [1.43162, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(thruster.direction_body, [1.0, 0.0, 0.0], atol=1e-15)
    assert thruster.thrust_coefficient == pytest.approx(0.004422 * 1000 * 0.2**4, rel=1e-15)
    assert (thruster.max_forward_N, thruster.max_reverse_N) == (1000.0, 1000.0)
    assert any("<use_angvel_cmd> not mapped" in n for n in result.not_mapped)


def test_sdf_link_poses_become_joint_origins(imported):
    _, out = imported
    text = out.read_text()
    assert 'name="horizontal_fins_joint"' in text
    assert 'xyz="1.05 0.0 0.0"' in text


def test_cross_terms_are_reported_not_dropped_silently():
    import xml.etree.ElementTree as ET

    plugin = ET.fromstring(
        "<plugin><link_name>b</link_name><xUabsU>-2</xUabsU><xUabsV>-3</xUabsV>"
        "<nRR>-1</nRR><xDotU>-2</xDotU><nDotR>-1</nDotR><xDotR>-0.5</xDotR><foo>1</foo></plugin>"
    )
    notes: list[str] = []
    params = gz_hydrodynamics(plugin, 0.0, np.zeros(3), "f.sdf", notes)
    assert params.quadratic_damping[0] == 2.0
    assert any("<xUabsV> = -3" in n for n in notes)
    assert any("<nRR> = -1" in n for n in notes)
    assert any("<foo> not mapped" in n for n in notes)
    # the cross added mass is carried (symmetrized) and its Coriolis difference reported
    assert params.added_mass[0, 5] == 0.25
    assert any("off-diagonal added mass" in n for n in notes)


def test_a_joint_with_its_own_pose_is_refused(tmp_path):
    text = LRAUV.read_text().replace(
        '<joint name="horizontal_fins_joint" type="revolute">\n      <pose>0 0 0 0 0 0</pose>',
        '<joint name="horizontal_fins_joint" type="revolute">\n      <pose>0 0.1 0 0 0 0</pose>',
    )
    assert "0 0.1 0 0 0 0" in text
    source = tmp_path / "bad.sdf"
    source.write_text(text)
    with pytest.raises(ModelError, match="horizontal_fins_joint"):
        import_model(source)


def test_notes_about_the_removed_propeller_joint_are_dropped(imported):
    result, _ = imported
    assert not any(n.startswith("joint 'propeller_joint':") for n in result.not_mapped)
    assert any(
        n.startswith("joint 'vertical_fins_joint': effort limit -1") for n in result.not_mapped
    )


def test_prefixes_gz_sim_reads_without_a_declaration_do_not_stop_the_import(imported, tmp_path):
    """MBARI's LRAUV files carry ``<experimental:params>`` and ``gz:type`` without declaring
    ``xmlns:experimental`` or ``xmlns:gz`` (SDFormat's parser does not ask for it): the
    vehicle imports as without them."""
    text = LRAUV.read_text().replace(
        '<link name="base_link">',
        '<link name="base_link">\n      <experimental:params><sensor gz:type="salinity"/>'
        "</experimental:params>",
        1,
    )
    assert "xmlns:gz" not in text and "<experimental:params>" in text
    source = tmp_path / "undeclared.sdf"
    source.write_text(text)
    result = import_model(source)
    assert result.hydro == imported[0].hydro
    assert [t.name for t in result.thrusters] == [t.name for t in imported[0].thrusters]


def test_xml_that_is_not_well_formed_for_another_reason_is_still_refused(tmp_path):
    source = tmp_path / "bad.sdf"
    source.write_text('<sdf version="1.9"><model name="m"><gz:x></model></sdf>')
    with pytest.raises(ModelError, match="not well-formed XML"):
        import_model(source)


def _notes_of(inner: str) -> list[str]:
    import xml.etree.ElementTree as ET

    notes: list[str] = []
    plugin = ET.fromstring(f"<plugin><link_name>b</link_name>{inner}</plugin>")
    gz_hydrodynamics(plugin, 0.0, np.zeros(3), "f.sdf", notes)
    return notes


def test_a_diagonal_added_mass_is_no_coriolis_difference():
    """Diagonal added mass alone: gz-sim's Coriolis and uvms-pin's agree, nothing to say."""
    notes = _notes_of("<xDotU>-2</xDotU><yDotV>-3</yDotV><nDotR>-1</nDotR><xU>-5</xU>")
    assert not notes, notes


@pytest.mark.parametrize(
    ("flags", "said"),
    [
        ("<disable_coriolis>true</disable_coriolis>", ["disable_coriolis"]),
        ("<disable_added_mass> 1 </disable_added_mass>", ["disable_added_mass"]),
        (
            "<disable_coriolis>false</disable_coriolis><disable_added_mass>0</disable_added_mass>",
            [],
        ),
        ("<namespace>true</namespace>", []),
    ],
)
def test_a_disabled_term_is_said_to_be_kept_and_other_flags_pass_quietly(flags, said):
    """uvms-pin always has the added mass and its Coriolis term: a source that turns either off
    is told so; the flags off, and the plugin's other settings, say nothing."""
    notes = _notes_of(flags)
    assert len(notes) == len(said), notes
    for note, tag in zip(notes, said, strict=True):
        assert f"<{tag}> is true in the source" in note
