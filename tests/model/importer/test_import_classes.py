"""What a new user met importing vehicles, each as the class it stands for: a joint that
cannot move is a fixed joint (said so), and hydrodynamics the source already carries (a
uvms-pin URDF) are kept, never stripped."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import REFERENCE_URDF

from uvms_pin.model.importer.convert import import_model
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.physics.dynamics import mass_matrix

REXROV = Path(__file__).parent / "data" / "rexrov_expanded.urdf"
#: a sensor as uuv_simulator mounts it: a revolute joint of limits 0 to 0 and a tiny link
SENSOR = """
  <link name="rexrov/dvl_link">
    <inertial><mass value="0.001"/><inertia ixx="1e-9" ixy="0" ixz="0" iyy="1e-9" iyz="0" izz="1e-9"/></inertial>
  </link>
  <joint name="rexrov/dvl_joint" type="revolute">
    <origin xyz="-1.4 0 -0.3" rpy="0 1.57 0"/>
    <parent link="rexrov/base_link"/><child link="rexrov/dvl_link"/>
    <axis xyz="0 0 1"/><limit lower="0" upper="0" effort="0" velocity="0"/>
  </joint>
</robot>"""


def test_a_joint_that_cannot_move_is_imported_fixed_and_said_so(tmp_path):
    source = tmp_path / "with_sensor.urdf"
    source.write_text(REXROV.read_text().replace("</robot>", SENSOR))
    out = tmp_path / "rexrov.urdf"
    result = import_model(source, out)
    assert (
        "joint 'rexrov/dvl_joint': revolute with limits 0 to 0 cannot move; "
        "written as a fixed joint" in result.not_mapped
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        uvms = load_uvms(out, allow_dry_links=True)
    assert uvms.nv == 6  # the vehicle alone: no joint of the sensor
    masses = mass_matrix(uvms, pin.neutral(uvms.model))
    assert np.linalg.eigvalsh(masses).min() > 1.0


def test_a_urdf_with_hydrodynamics_keeps_them(tmp_path):
    out = tmp_path / "again.urdf"
    result = import_model(REFERENCE_URDF, out)
    assert not any("written dry" in note for note in result.not_mapped)
    original, again = load_uvms(REFERENCE_URDF), load_uvms(out)
    assert np.isclose(again.volume_m3, original.volume_m3, rtol=1e-12)
    q = pin.neutral(original.model)
    np.testing.assert_allclose(mass_matrix(again, q), mass_matrix(original, q), rtol=1e-12)


DRY = """<robot name="dry"><link name="hull">
  <inertial><mass value="10"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
</link></robot>"""


def test_a_file_without_hydrodynamics_is_refused_unless_asked_for(tmp_path):
    from uvms_pin.errors import ModelError

    source, out = tmp_path / "dry.urdf", tmp_path / "out.urdf"
    source.write_text(DRY)
    with pytest.raises(ModelError, match=r"dry.urdf: carries no hydrodynamics .* --allow-dry"):
        import_model(source, out)
    assert not out.exists()
    result = import_model(source, out, allow_dry=True)
    assert (
        "link 'hull': no hydrodynamics in the source; written dry (volume 0)" in result.not_mapped
    )


def test_notes_saying_the_same_of_several_names_are_said_once_naming_them_all():
    from uvms_pin.model.importer.result import ImportResult

    notes = [
        "joint 'a/j1': revolute with limits 0 to 0 cannot move; written as a fixed joint",
        "link 'base': <box> not mapped (no uvms-pin counterpart)",
        "joint 'a/j2': revolute with limits 0 to 0 cannot move; written as a fixed joint",
        "plugin 'imu' not mapped",
        "plugin 'gps' not mapped",
        "link 'x': no hydrodynamics in the source; written dry (volume 0)",
        "fluid density stated twice",
    ]
    result = ImportResult("", {}, [], None, notes)
    assert result.grouped_notes() == [
        "joints 'a/j1', 'a/j2': revolute with limits 0 to 0 cannot move; written as a fixed joint",
        "link 'base': <box> not mapped (no uvms-pin counterpart)",
        "plugins 'imu', 'gps': not mapped",
        "link 'x': no hydrodynamics in the source; written dry (volume 0)",
        "fluid density stated twice",
    ]
    assert result.not_mapped == notes  # the URDF keeps each one
