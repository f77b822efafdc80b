"""A model's numbers against what any vehicle has: a body's mean density (mass over the water
it displaces) that no body can have is refused, one far from usual warned; the water's
density likewise; a hydrodynamic or inertial element given twice is refused (a reader
taking the first silently dropped the second)."""

from __future__ import annotations

import warnings

import pytest
from conftest import REFERENCE_URDF, body_urdf, hydro_xml

import uvms_pin as up
from uvms_pin.errors import PlausibilityWarning


def _load(write_urdf, text, **kw):
    return up.load_uvms(write_urdf(text), ee_frame="body", sensor_frame="body", **kw)


@pytest.mark.parametrize(
    ("mass", "volume", "message"),
    [
        (31.0, 30.0, "mean density of 1.03333 kg/m^3 cannot be physical"),  # litres as m^3
        (31000.0, 0.03, "mean density of 1.03333e+06 kg/m^3 cannot be physical"),  # grams
    ],
)
def test_a_body_no_material_makes_is_refused(write_urdf, mass, volume, message):
    with pytest.raises(up.ModelError) as info:
        _load(write_urdf, body_urdf(mass=mass, hydro=hydro_xml(volume)))
    text = str(info.value)
    assert "the body on joint 'root_joint' (links body)" in text and message in text
    assert ("litres" if volume > 1 else "grams") in text


@pytest.mark.parametrize(("mass", "volume"), [(31.0, 1.0), (31.0, 0.0016)])
def test_a_body_far_from_usual_is_warned_and_loads(write_urdf, mass, volume):
    with pytest.warns(up.ModelWarning, match="is far outside what vehicles and arms are made of"):
        uvms = _load(write_urdf, body_urdf(mass=mass, hydro=hydro_xml(volume)))
    assert uvms.mass_kg == mass


def test_every_shipped_model_is_plausible():
    from uvms_pin.model.resources import shipped_models, shipped_path

    for name in shipped_models():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", up.ModelWarning)  # dry links of the arm file
            warnings.simplefilter("error", PlausibilityWarning)
            up.load_uvms(shipped_path(f"models/{name}.urdf"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        up.load_uvms(REFERENCE_URDF)
    assert not caught


def test_water_no_liquid_is_refused_and_unusual_water_warned():
    with pytest.raises(
        up.ParameterError, match=r"water_density_kg_m3 = 1\.025e\+06 kg/m\^3 cannot"
    ):
        up.load_uvms(REFERENCE_URDF, water_density_kg_m3=1025000.0)
    with pytest.warns(PlausibilityWarning, match="1240 kg/m.3 is far outside fresh to sea water"):
        up.load_uvms(REFERENCE_URDF, water_density_kg_m3=1240.0)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ('<volume value="0.01"/>', '<volume value="0.01"/><volume value="0.02"/>', "<hydrodynamics> has 2 <volume> elements"),
        ('<mass value="10.0"/>', '<mass value="10.0"/><mass value="12.0"/>', "<inertial> has 2 <mass> elements"),
        ("<hydrodynamics>", '<hydrodynamics><center_of_buoyancy xyz="0 0 0.1"/>', "2 <center_of_buoyancy> elements"),
    ],
)  # fmt: skip
def test_an_element_given_twice_is_refused(write_urdf, old, new, message):
    text = body_urdf(mass=10.0, hydro=hydro_xml(1e-2))
    assert old in text, text
    with pytest.raises(up.ModelError, match=message):
        _load(write_urdf, text.replace(old, new, 1))


def test_a_body_whose_mass_sits_on_dry_links_beside_a_probe_is_refused_naming_them(write_urdf):
    """An imported wrist the source gives no hydrodynamics (7.5 kg, volume 0) and a probe of
    16 mL fixed to it make one body denser than osmium: refused, the refusal naming the dry
    link rather than only suspecting grams."""
    text = body_urdf(mass=10.0, hydro=hydro_xml(0.01)).replace(
        "</robot>",
        '<link name="wrist"><inertial><mass value="7.5"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
        f"<hydrodynamics>{hydro_xml(0.0)}</hydrodynamics></link>"
        '<joint name="wrist_joint" type="revolute"><parent link="body"/><child link="wrist"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        '<link name="probe"><inertial><mass value="0.01"/>'
        '<inertia ixx="1e-6" iyy="1e-6" izz="1e-6" ixy="0" ixz="0" iyz="0"/></inertial>'
        f"<hydrodynamics>{hydro_xml(1.6e-5)}</hydrodynamics></link>"
        '<joint name="probe_joint" type="fixed"><parent link="wrist"/><child link="probe"/>'
        "</joint></robot>",
    )
    with pytest.raises(up.ModelError, match="cannot be physical") as info:
        _load(write_urdf, text)
    assert "of its links, wrist displace no water (volume 0)" in str(info.value)
    with pytest.raises(up.ModelError) as info:  # a wet body in grams: no dry link to name
        _load(write_urdf, body_urdf(mass=31000.0, hydro=hydro_xml(0.03)))
    assert "displace no water" not in str(info.value)
