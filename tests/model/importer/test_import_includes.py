"""SDF ``<include>``: gz-sim's tutorial world includes its vehicle with ``merge="true"`` from a
local model directory; the importer inlines local includes (merged or nested) and refuses a
missing or remote model by name."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from uvms_pin.errors import ModelError
from uvms_pin.model.importer.convert import import_model
from uvms_pin.model.urdf.load import load_uvms

_MODEL = """<?xml version="1.0"?>
<sdf version="1.6">
  <model name="tiny_auv">
    <link name="hull">
      <inertial><mass>10</mass>
        <inertia><ixx>0.1</ixx><iyy>0.5</iyy><izz>0.5</izz></inertia></inertial>
      <collision name="c"><geometry><box><size>0.5 0.2 0.1</size></box></geometry></collision>
    </link>
    <link name="fin">
      <pose>0.3 0 0 0 0 0</pose>
      <inertial><mass>0.1</mass>
        <inertia><ixx>1e-4</ixx><iyy>1e-4</iyy><izz>1e-4</izz></inertia></inertial>
      <collision name="c"><geometry><box><size>0.1 0.1 0.01</size></box></geometry></collision>
    </link>
    <joint name="fin_joint" type="revolute">
      <parent>hull</parent><child>fin</child>
      <axis><xyz>0 1 0</xyz><limit><lower>-0.3</lower><upper>0.3</upper></limit></axis>
    </joint>
  </model>
</sdf>
"""

_CONFIG = """<?xml version="1.0"?>
<model><name>tiny</name><sdf version="1.6">tiny.sdf</sdf></model>
"""


def _world(body: str) -> str:
    return f"""<?xml version="1.0"?>
<sdf version="1.9">
  <world name="w">
    <plugin filename="gz-sim-buoyancy-system" name="gz::sim::systems::Buoyancy">
      <uniform_fluid_density>1000</uniform_fluid_density>
    </plugin>
    {body}
  </world>
</sdf>
"""


@pytest.fixture
def model_dir(tmp_path: Path) -> Path:
    folder = tmp_path / "tiny_auv"
    folder.mkdir()
    (folder / "model.config").write_text(_CONFIG)
    (folder / "tiny.sdf").write_text(_MODEL)
    return folder


def _import(tmp_path: Path, body: str):
    world = tmp_path / "world.sdf"
    world.write_text(_world(body))
    out = tmp_path / "out" / "auv.urdf"
    out.parent.mkdir(exist_ok=True)
    return import_model(world, out), out


def test_a_merged_include_is_the_models_links_in_the_parent_model(tmp_path, model_dir):
    # as in gz-sim's tutorials/files/underwater_vehicles/buoyant_lrauv.sdf: a <model> whose
    # only content is <include merge="true"> of a local model directory, turned by a pose,
    # with plugins written inside the include
    body = """<model name="auv"><include merge="true">
        <pose degrees="true">0 0 0 0 0 -180</pose><uri>tiny_auv</uri>
        <plugin filename="gz-sim-odometry-publisher-system"
                name="gz::sim::systems::OdometryPublisher"/>
      </include></model>"""
    result, out = _import(tmp_path, body)
    assert result.source_format == "sdf"
    assert result.hydro["hull"].volume_m3 == pytest.approx(0.5 * 0.2 * 0.1)
    assert any("OdometryPublisher" in note for note in result.not_mapped)
    uvms = load_uvms(out, water_density_kg_m3=1000.0)
    assert uvms.nv == 7
    # the fin sits 0.3 m ahead of the hull whatever the common turn of the include
    joint = uvms.model.getJointId("fin_joint")
    np.testing.assert_allclose(
        uvms.model.jointPlacements[joint].translation, [0.3, 0, 0], atol=1e-12
    )


def test_a_nested_include_in_a_world_is_the_model(tmp_path, model_dir):
    body = "<include><uri>model://tiny_auv</uri><name>renamed</name></include>"
    merged, _ = _import(tmp_path, body)
    assert set(merged.hydro) == {"hull", "fin"}
    assert 'name="renamed"' in merged.urdf_text


def test_the_same_vehicle_merged_or_nested_or_inlined(tmp_path, model_dir):
    nested, _ = _import(tmp_path, "<include><uri>tiny_auv</uri></include>")
    merged, _ = _import(
        tmp_path,
        '<model name="tiny_auv"><include merge="true"><uri>tiny_auv</uri></include></model>',
    )
    inline_world = tmp_path / "inline.sdf"
    inline_world.write_text(_world(_MODEL.split('<sdf version="1.6">')[1].split("</sdf>")[0]))
    inlined = import_model(inline_world)
    assert nested.urdf_text.split("-->")[1] == inlined.urdf_text.split("-->")[1]
    assert merged.urdf_text.split("-->")[1] == inlined.urdf_text.split("-->")[1]


def test_a_model_sdf_file_can_be_included_directly(tmp_path, model_dir):
    result, _ = _import(tmp_path, "<include><uri>tiny_auv/tiny.sdf</uri></include>")
    assert set(result.hydro) == {"hull", "fin"}


def test_model_uris_are_looked_up_in_the_resource_path(tmp_path, model_dir, monkeypatch):
    elsewhere = tmp_path / "worlds"
    elsewhere.mkdir()
    monkeypatch.setenv("GZ_SIM_RESOURCE_PATH", str(tmp_path))
    result, _ = _import(elsewhere, "<include><uri>model://tiny_auv</uri></include>")
    assert set(result.hydro) == {"hull", "fin"}


def test_a_missing_model_is_named(tmp_path, model_dir, monkeypatch):
    monkeypatch.delenv("GZ_SIM_RESOURCE_PATH", raising=False)
    with pytest.raises(ModelError, match=r"world\.sdf: <include> of 'no_such_auv': no such model"):
        _import(tmp_path, "<include><uri>no_such_auv</uri></include>")
    assert not (tmp_path / "out" / "auv.urdf").exists()


def test_a_remote_model_is_refused_by_name(tmp_path):
    uri = "https://fuel.gazebosim.org/1.0/OpenRobotics/models/Tethys"
    with pytest.raises(ModelError, match=r"remote model .*Tethys.*local files only"):
        _import(tmp_path, f"<include><uri>{uri}</uri></include>")


def test_a_directory_without_a_model_file_is_named(tmp_path):
    (tmp_path / "empty_model").mkdir()
    with pytest.raises(
        ModelError, match=r"neither a model\.config naming its SDF nor a model\.sdf"
    ):
        _import(tmp_path, "<include><uri>empty_model</uri></include>")


def test_an_include_of_itself_is_refused(tmp_path):
    folder = tmp_path / "loop"
    folder.mkdir()
    (folder / "model.sdf").write_text(
        '<sdf version="1.9"><model name="loop"><include merge="true"><uri>../loop</uri>'
        "</include></model></sdf>"
    )
    with pytest.raises(ModelError, match="includes itself"):
        _import(tmp_path, "<include><uri>loop</uri></include>")


def test_a_nested_model_beside_links_is_refused_with_the_way_out(tmp_path, model_dir):
    body = """<model name="auv"><link name="base"><inertial><mass>1</mass></inertial></link>
      <include><uri>tiny_auv</uri></include></model>"""
    with pytest.raises(ModelError, match='merge="true"'):
        _import(tmp_path, body)
