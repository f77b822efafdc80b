"""An SDF model's sphere, cylinder and mesh collisions and a joint axis given in the model
frame (``<use_parent_model_frame>``), imported: gz-sim's LRAUV with its fins' boxes made a
sphere and a cylinder, its horizontal fins' link turned a quarter turn about z and a mesh
beside the hull's box."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from uvms_pin.model.importer.convert import import_model
from uvms_pin.model.urdf.load import load_uvms

LRAUV = Path(__file__).parent / "data" / "lrauv_hydrodynamics.sdf"
FIN_BOX = "<box>\n            <size>0.1 0.1 0.02</size>\n          </box>"
SPHERE_CENTRE_M = (0.01, -0.02, 0.03)


def _replace_in_link(text: str, link: str, old: str, new: str) -> str:
    start = text.index(old, text.index(f'<link name="{link}">'))
    return text[:start] + new + text[start + len(old) :]


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    text = LRAUV.read_text()
    assert text.count(FIN_BOX) == 2
    text = text.replace(
        '<link name="horizontal_fins">\n      <pose>1.05 0 0 0 0 0</pose>',
        '<link name="horizontal_fins">\n      <pose>1.05 0 0 0 0 1.5707963267948966</pose>',
    )
    text = _replace_in_link(
        text, "horizontal_fins", FIN_BOX, "<sphere><radius>0.05</radius></sphere>"
    )
    text = _replace_in_link(
        text,
        "horizontal_fins",
        '<collision name="collision">',
        '<collision name="collision"><pose>{} {} {} 0 0 0</pose>'.format(*SPHERE_CENTRE_M),
    )
    text = _replace_in_link(
        text,
        "vertical_fins",
        FIN_BOX,
        "<cylinder><radius>0.04</radius><length>0.1</length></cylinder>",
    )
    # the horizontal fins' axis, y of the model frame: x of their link, turned about z
    text = text.replace(
        "<xyz>0 1 0</xyz>",
        "<xyz>0 1 0</xyz><use_parent_model_frame>true</use_parent_model_frame>",
    )
    text = text.replace(
        '<collision name="main_body_buoyancy">',
        '<collision name="dome"><geometry><mesh><uri>dome.stl</uri><scale>2 2 2</scale>'
        '</mesh></geometry></collision>\n      <collision name="main_body_buoyancy">',
    )
    folder = tmp_path_factory.mktemp("shapes")
    source = folder / "shapes.sdf"
    source.write_text(text)
    return import_model(source, folder / "shapes.urdf"), folder / "shapes.urdf"


def test_a_sphere_and_a_cylinder_displace_their_closed_form_volumes(imported):
    result, _ = imported
    sphere = result.hydro["horizontal_fins"]
    assert sphere.volume_m3 == pytest.approx(4.0 / 3.0 * math.pi * 0.05**3, rel=1e-15)
    np.testing.assert_allclose(sphere.center_of_buoyancy_m, SPHERE_CENTRE_M, atol=1e-15)
    cylinder = result.hydro["vertical_fins"]
    assert cylinder.volume_m3 == pytest.approx(math.pi * 0.04**2 * 0.1, rel=1e-15)


def test_a_mesh_is_left_out_of_the_buoyancy_and_said_so(imported):
    result, _ = imported
    assert result.hydro["base_link"].volume_m3 == pytest.approx(2 * 0.3 * 0.2464451666666667)
    assert any(
        n == "link 'base_link': a collision shape without a primitive volume left out of its "
        "buoyancy"
        for n in result.not_mapped
    )
    # the mesh is kept as the link's collision, its scale with it; its file is not there
    assert '<mesh filename="dome.stl" scale="2 2 2" />' in result.urdf_text
    assert any(
        n.startswith("mesh 'dome.stl' not found beside the source") for n in result.not_mapped
    )


def test_an_axis_in_the_model_frame_is_written_in_the_child_links(imported):
    _, out = imported
    with pytest.warns(UserWarning, match="dome.stl"):  # the mesh file is not there
        uvms = load_uvms(out, water_density_kg_m3=1000.0)
    joint = uvms.model.getJointId("horizontal_fins_joint")
    placement = uvms.model.jointPlacements[joint]
    np.testing.assert_allclose(placement.rotation[:, 0], [0.0, 1.0, 0.0], atol=1e-15)
    # a revolute joint about its link's x: Pinocchio's RX (or a unit axis along x)
    motion = uvms.model.joints[joint].shortname()
    if motion == "JointModelRX":
        return
    assert motion == "JointModelRevoluteUnaligned"
    np.testing.assert_allclose(uvms.model.joints[joint].extract().axis, [1.0, 0.0, 0.0], atol=1e-15)


def test_a_mesh_named_relative_to_the_source_is_found_from_the_urdf_written_elsewhere(tmp_path):
    """``<uri>meshes/hull.stl</uri>`` beside the SDF: the URDF written in another folder
    names it from there (it named it as the SDF did, and the loader, reading it from the
    URDF's folder, did not find it: the link's hull fell back to a sphere); the URDF text
    returned without writing names it by its absolute path."""
    import trimesh

    source_dir, out_dir = tmp_path / "models" / "lrauv", tmp_path / "out"
    (source_dir / "meshes").mkdir(parents=True)
    out_dir.mkdir()
    trimesh.creation.box(extents=(0.4, 0.3, 0.2)).export(source_dir / "meshes" / "hull.stl")
    text = LRAUV.read_text().replace(
        '<collision name="main_body_buoyancy">',
        '<collision name="dome"><geometry><mesh><uri>meshes/hull.stl</uri></mesh></geometry>'
        '</collision>\n      <collision name="main_body_buoyancy">',
    )
    source = source_dir / "lrauv.sdf"
    source.write_text(text)
    result = import_model(source, out_dir / "lrauv.urdf")
    assert '<mesh filename="../models/lrauv/meshes/hull.stl" />' in result.urdf_text
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the file is found: no fallback warned of
        load_uvms(out_dir / "lrauv.urdf", water_density_kg_m3=1000.0)
    unwritten = import_model(source)
    mesh = str((source_dir / "meshes" / "hull.stl").resolve())
    assert f'<mesh filename="{mesh}" />' in unwritten.urdf_text


def test_a_model_uri_mesh_is_found_beside_the_model_or_on_the_resource_path(tmp_path, monkeypatch):
    """gz-sim's ``model://NAME/meshes/x.stl``: the model's own folder (models/NAME beside
    the source's) or a folder of GZ_SIM_RESOURCE_PATH holds it; the URDF names it from its
    own folder. One found nowhere is left as it was and noted."""
    import trimesh

    models, out_dir, common = tmp_path / "models", tmp_path / "out", tmp_path / "common"
    for folder in (models / "lrauv" / "meshes", common / "props" / "meshes", out_dir):
        folder.mkdir(parents=True)
    trimesh.creation.box(extents=(0.4, 0.3, 0.2)).export(models / "lrauv" / "meshes" / "h.stl")
    trimesh.creation.box(extents=(0.1, 0.1, 0.1)).export(common / "props" / "meshes" / "p.stl")

    def meshes(*uris: str) -> str:
        collisions = "".join(
            f'<collision name="c{k}"><geometry><mesh><uri>{uri}</uri></mesh></geometry></collision>'
            for k, uri in enumerate(uris)
        )
        return LRAUV.read_text().replace(
            '<collision name="main_body_buoyancy">',
            f'{collisions}\n      <collision name="main_body_buoyancy">',
        )

    source = models / "lrauv" / "model.sdf"
    source.write_text(meshes("model://lrauv/meshes/h.stl", "model://props/meshes/p.stl"))
    result = import_model(source, out_dir / "lrauv.urdf")
    assert '<mesh filename="../models/lrauv/meshes/h.stl" />' in result.urdf_text
    assert '<mesh filename="model://props/meshes/p.stl" />' in result.urdf_text
    assert any(
        n.startswith("mesh 'model://props/meshes/p.stl' not found") for n in result.not_mapped
    )
    monkeypatch.setenv("GZ_SIM_RESOURCE_PATH", str(common))
    result = import_model(source, out_dir / "lrauv.urdf", thrusters_out=out_dir / "t.toml")
    assert '<mesh filename="../common/props/meshes/p.stl" />' in result.urdf_text
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # both found from the URDF's folder
        load_uvms(out_dir / "lrauv.urdf", water_density_kg_m3=1000.0)


def test_a_limit_without_lower_or_upper_takes_minus_and_plus_pi(tmp_path):
    """SDF's defaults for a revolute joint's limits not given: lower -pi, upper pi (their
    absence is not 0)."""
    text = LRAUV.read_text()
    assert text.count("<lower>-0.261799</lower>") == 2
    text = text.replace("<lower>-0.261799</lower>", "", 1).replace("<upper>0.261799</upper>", "", 2)
    source = tmp_path / "limits.sdf"
    source.write_text(text)
    import_model(source, tmp_path / "limits.urdf")
    uvms = load_uvms(tmp_path / "limits.urdf", water_density_kg_m3=1000.0)
    joint = uvms.model.getJointId("horizontal_fins_joint")
    q = uvms.model.joints[joint].idx_q
    assert uvms.model.lowerPositionLimit[q] == pytest.approx(-math.pi, abs=1e-12)
    assert uvms.model.upperPositionLimit[q] == pytest.approx(math.pi, abs=1e-12)
    other = uvms.model.joints[uvms.model.getJointId("vertical_fins_joint")].idx_q
    assert uvms.model.lowerPositionLimit[other] == pytest.approx(-0.261799, abs=1e-12)
    assert uvms.model.upperPositionLimit[other] == pytest.approx(math.pi, abs=1e-12)


def test_a_links_centre_of_buoyancy_is_its_primitives_volume_centroid():
    """A box and a sphere: the centroid weighted by their closed-form volumes; a link with a
    mesh alone displaces nothing, its centre the link's origin (3,), and is said so."""
    import xml.etree.ElementTree as ET

    from uvms_pin.model.importer.collision_volume import collision_volume

    both = ET.fromstring(
        '<link name="two"><collision><origin xyz="1 0 0"/><geometry><box size="0.2 0.1 0.5"/>'
        '</geometry></collision><collision><origin xyz="0 2 -1"/><geometry>'
        '<sphere radius="0.3"/></geometry></collision></link>'
    )
    notes: list[str] = []
    volume, centre = collision_volume(both, "test.urdf", notes)
    box, sphere = 0.2 * 0.1 * 0.5, 4.0 / 3.0 * math.pi * 0.3**3
    assert volume == pytest.approx(box + sphere, rel=1e-15)
    np.testing.assert_allclose(
        centre, (box * np.array([1, 0, 0]) + sphere * np.array([0, 2, -1])) / (box + sphere),
        rtol=0, atol=1e-15,
    )  # fmt: skip
    assert notes == []
    mesh = ET.fromstring(
        '<link name="hull"><collision><geometry><mesh filename="hull.stl"/></geometry>'
        "</collision></link>"
    )
    volume, centre = collision_volume(mesh, "test.urdf", notes)
    assert volume == 0.0
    assert centre.shape == (3,) and not centre.any()
    assert notes == [
        "link 'hull': a collision shape without a primitive volume left out of its buoyancy"
    ]
