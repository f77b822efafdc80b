"""gz-sim's LiftDrag system imported: a ``<lift_drag>`` in the fin's link with the plugin's
parameters (gz-sim's defaults for the rest), its control joint, and the links and joints it
names checked."""

from __future__ import annotations

import pytest
from fin_helpers import TUTORIAL_FINS, import_lrauv, lift_drag_plugin

import uvms_pin as up
from uvms_pin.errors import ModelError
from uvms_pin.hydro.lift_drag import LiftDragParams


def test_the_tutorials_fins_become_lift_drag_elements_and_nothing_is_left_unmapped(tmp_path):
    result = import_lrauv(tmp_path)
    assert not [n for n in result.not_mapped if "LiftDrag" in n]
    assert result.urdf_text.count("<lift_drag>") == 2
    uvms = up.load_uvms(tmp_path / "lrauv.urdf", water_density_kg_m3=1000.0)
    horizontal = next(f for f in uvms.fins if f.name == "horizontal_fins")
    defaults = LiftDragParams(area_m2=1.0)
    assert horizontal.params.cma == defaults.cma and horizontal.params.reversible is False
    assert horizontal.params.control_joint_rad_to_cl == defaults.control_joint_rad_to_cl
    assert horizontal.control_q_index is None  # the fin's own link turns with its joint


def test_a_control_joint_and_its_gain_are_carried(tmp_path):
    extra = (
        "<control_joint_name>vertical_fins_joint</control_joint_name>"
        "<control_joint_rad_to_cl>2.5</control_joint_rad_to_cl><cm_delta>-0.3</cm_delta>"
        "<radial_symmetry>true</radial_symmetry>"
    )
    import_lrauv(tmp_path, lift_drag_plugin("base_link", "-1 0 0", "0 0 1", extra))
    uvms = up.load_uvms(tmp_path / "lrauv.urdf", water_density_kg_m3=1000.0)
    (fin,) = uvms.fins
    joint = uvms.model.joints[uvms.model.getJointId("vertical_fins_joint")]
    assert fin.control_q_index == joint.idx_q
    assert (fin.params.control_joint_rad_to_cl, fin.params.cm_delta) == (2.5, -0.3)
    assert fin.params.radial_symmetry is True


def test_what_the_importer_cannot_carry_is_said(tmp_path):
    no_density = lift_drag_plugin("vertical_fins", "-1 0 0", "0 1 0").replace(
        "<air_density>1000</air_density>", ""
    )
    advanced = '<plugin filename="gz-sim-advanced-lift-drag-system" name="gz::sim::systems::AdvancedLiftDrag"/>'
    result = import_lrauv(tmp_path, no_density + advanced)
    assert any("without <air_density>: gz-sim's 1.2041" in n for n in result.not_mapped)
    assert "plugin 'gz::sim::systems::AdvancedLiftDrag' not mapped" in result.not_mapped
    odd = lift_drag_plugin("vertical_fins", "-1 0 0", "0 1 0", "<wind>1</wind>")
    assert any("LiftDrag <wind> not mapped" in n for n in import_lrauv(tmp_path, odd).not_mapped)


@pytest.mark.parametrize(
    ("plugin", "message"),
    [
        (lift_drag_plugin("no_such_fin", "1 0 0", "0 0 1"), "names link 'no_such_fin'"),
        (lift_drag_plugin("propeller", "1 0 0", "0 0 1"), "thruster's propeller"),
        (
            lift_drag_plugin(
                "vertical_fins", "1 0 0", "0 0 1", "<control_joint_name>x</control_joint_name>"
            ),
            "<control_joint_name> 'x' is not a moving joint",
        ),
        (lift_drag_plugin("vertical_fins", "1 0 0", "1 0 0"), "upward must not be along forward"),
        (TUTORIAL_FINS.replace("<area>0.0244</area>", "<area>-1</area>", 1), "area must be >= 0"),
    ],
)
def test_a_bad_lift_drag_is_refused_by_name(tmp_path, plugin, message):
    with pytest.raises(ModelError, match=message):
        import_lrauv(tmp_path, plugin)
        up.load_uvms(tmp_path / "lrauv.urdf", water_density_kg_m3=1000.0)
