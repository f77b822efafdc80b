"""Automatic trim (`uvms_pin.model.trim`) on a bare vehicle: one that floats gets ballast
only, one already neutral gets nothing; the trimmed URDF, loaded again, is neutral at the
BG asked and level, by Pinocchio's centre of mass and the bodies' centres of buoyancy."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.model.trim import TrimSpec, mass_properties, plan_trim
from uvms_pin.model.trim_urdf import add_trim_links

BLUEROV = ROOT / "models" / "bluerov2_heavy.urdf"
SEA_KG_M3 = 1025.0  # the BlueROV2 Heavy floats in it (+2.3 N)
#: the slabs' footprint and the hull's top and bottom heights [m], centred under the hull
FOOTPRINT = {"footprint_m": (0.4, 0.3), "top_z_m": 0.1, "bottom_z_m": -0.1}


#: the BlueROV2 Heavy's centre of gravity raised 4 mm above its hull origin (its file's is
#: at the origin, where the BG equation's m z_G term is 0 and its sign goes unseen)
RAISED = ('<origin xyz="0 0 0" rpy="0 0 0"/>\n      <mass value="13.5"/>',
          '<origin xyz="0 0 0.004" rpy="0 0 0"/>\n      <mass value="13.5"/>')  # fmt: skip


def _trimmed(tmp_path, bg_m: float):
    """(the vehicle's report, the trimmed vehicle loaded again): the slabs centred under
    the vehicle's centre of gravity."""
    text = BLUEROV.read_text()
    assert text.count(RAISED[0]) == 1
    source = tmp_path / "raised.urdf"
    source.write_text(text.replace(*RAISED))
    vehicle = up.load_uvms(source, water_density_kg_m3=SEA_KG_M3)
    q = vehicle.neutral_configuration()
    centre = mass_properties(vehicle, q)[1]
    assert centre[2] == pytest.approx(0.004, abs=1e-12)
    spec = TrimSpec(bg_m=bg_m, footprint_center_m=(centre[0], centre[1]), **FOOTPRINT)
    report = plan_trim(vehicle, q, spec)
    root = ET.parse(source).getroot()
    add_trim_links(root, "base_link", report, "trim_")
    out = tmp_path / "trimmed.urdf"
    ET.ElementTree(root).write(out)
    return report, up.load_uvms(out, water_density_kg_m3=SEA_KG_M3)


@pytest.mark.parametrize("bg_m", [0.003, 0.005, 0.007])
def test_a_floating_vehicle_gets_ballast_only_and_is_neutral_and_level(tmp_path, bg_m):
    """Foam cannot help a vehicle that floats: lead only, raised into the frame for a BG
    below the one it gives under the hull (1.2 cm); 0.3 cm would need it above the frame's
    top: it stays at the top, the BG reached said."""
    report, trimmed = _trimmed(tmp_path, bg_m)
    assert report.net_buoyancy_before_N > 1.0
    assert report.foam_volume_m3 == 0.0 and report.ballast_mass_kg > 0.0
    # what the lead must sink: the net buoyancy over its weight in water
    lead = (
        report.net_buoyancy_before_N / 9.81 / (1.0 - SEA_KG_M3 / TrimSpec().ballast_density_kg_m3)
    )
    assert report.ballast_mass_kg == pytest.approx(lead, rel=1e-3)
    assert report.ballast_position_m[2] > FOOTPRINT["bottom_z_m"]  # raised into the frame
    assert any(n.startswith("ballast raised to z =") for n in report.notes)
    assert [b for b in trimmed.model.names if "foam" in b] == []
    mass, com, volume, cob = mass_properties(trimmed, trimmed.neutral_configuration())
    assert mass == pytest.approx(report.mass_after_kg, rel=1e-12)
    assert SEA_KG_M3 * volume - mass == pytest.approx(0.0, abs=1e-9)
    assert cob[2] - com[2] == pytest.approx(report.bg_after_m, abs=1e-9)
    top = FOOTPRINT["top_z_m"] - 0.5 * report.ballast_size_m[2]
    if bg_m > 0.004:
        assert report.bg_after_m == pytest.approx(bg_m, abs=1e-9)
        assert report.ballast_position_m[2] < top
    else:
        assert report.ballast_position_m[2] == pytest.approx(top, abs=1e-12)
        assert bg_m < report.bg_after_m < 0.005
        assert any(n.startswith("BG target 0.30 cm not reachable") for n in report.notes)
    np.testing.assert_allclose(com[:2], cob[:2], atol=1e-9)  # no pitch or roll moment


def test_a_neutral_vehicle_gets_nothing_and_is_told_why_it_tilts():
    """A model neutral already in its water (the BlueROV2 Heavy + Alpha 5 in sea water, to
    rounding) solved to 1e-18 m^3 of foam, with a note on where to put it."""
    uvms = up.load_uvms(ROOT / "models" / "uvms_bluerov2_alpha5.urdf")
    mass, _com, volume, _cob = mass_properties(uvms, uvms.neutral_configuration())
    assert abs(uvms.water_density_kg_m3 * volume - mass) < 1e-12 * mass
    report = plan_trim(uvms, uvms.neutral_configuration(), TrimSpec(bg_m=0.01, **FOOTPRINT))
    assert report.foam_volume_m3 == 0.0 and report.ballast_mass_kg == 0.0
    assert not any("foam centroid" in n or "ballast raised" in n for n in report.notes)
    assert any(n.startswith("neutral without foam or ballast") for n in report.notes)


def test_trim_links_take_the_prefix_while_their_name_or_joints_name_is_taken(tmp_path):
    """A second trim beside the first (an arm's trim a vehicle file keeps) takes the prefix,
    again while its name is taken; so does one whose joint's name alone is taken."""
    vehicle = up.load_uvms(BLUEROV, water_density_kg_m3=SEA_KG_M3)
    q = vehicle.neutral_configuration()
    report = plan_trim(vehicle, q, TrimSpec(bg_m=0.005, **FOOTPRINT))
    assert report.ballast_mass_kg > 0.0 and report.foam_volume_m3 == 0.0
    root = ET.parse(BLUEROV).getroot()
    for _ in range(3):
        add_trim_links(root, "base_link", report, "old_")
    names = [e.get("name") for e in root if e.tag == "link" and "ballast" in e.get("name")]
    assert names == ["trim_ballast", "old_trim_ballast", "old_old_trim_ballast"]
    joints = {e.get("name") for e in root if e.tag == "joint"}
    assert {f"{n}_joint" for n in names} <= joints
    lone = ET.parse(BLUEROV).getroot()
    ET.SubElement(lone, "joint", {"name": "trim_ballast_joint", "type": "fixed"})
    add_trim_links(lone, "base_link", report, "old_")
    assert [e.get("name") for e in lone if e.tag == "link" and "ballast" in e.get("name")] == [
        "old_trim_ballast"
    ]


@pytest.mark.parametrize(
    ("changes", "match"),
    [
        ({"top_z_m": np.nan}, "top_z_m"),
        ({"bottom_z_m": -np.inf}, "bottom_z_m"),
        ({"top_z_m": 0.1, "bottom_z_m": 0.2}, "top_z_m must be above bottom_z_m"),
        ({"footprint_m": (0.3, np.nan)}, "footprint_m"),
        ({"footprint_m": (0.3, 0.0)}, r"footprint_m\[1\]"),
        ({"footprint_m": (0.3,)}, "footprint_m"),
        ({"footprint_center_m": (np.inf, 0.0)}, "footprint_center_m"),
    ],
)
def test_a_trim_spec_refuses_a_non_finite_or_impossible_slab_by_name(changes, match):
    """The slabs' footprint, centre and heights, when given, are finite (a nan was accepted
    and placed the foam and the ballast at nan), the footprint's sides > 0 and the top above
    the bottom."""
    with pytest.raises(up.ParameterError, match=match):
        TrimSpec(**changes)
