"""What ``uvms-pin info`` says of a model (the frame each body's coefficients are in), and
how a model entry that names no model is explained (a directory, a near-miss of a shipped
name), the same for ``info`` and a scenario's ``model``."""

from __future__ import annotations

import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.model.resources import resolve_model, shipped_path
from uvms_pin.model.summary import model_summary


def test_derived_bodies_are_said_to_be_in_their_collision_shape_frame():
    text = model_summary(up.load_uvms(shipped_path("models/uvms_bluerov2_alpha5.urdf")))
    assert "at the link origin, link frame" not in text
    assert "the collision shape's frame for coefficients derived from geometry, marked *" in text
    lines = text.splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith(" *tool/collision[0]"))
    assert lines[k + 1].strip() == (
        "frame             the collision shape's: origin [0.04 0 0] m, "
        "rpy [0 1.571 0] rad in link tool's frame"
    )
    # a body read from a <hydrodynamics> element has no such line: its frame is its link's
    k = next(i for i, line in enumerate(lines) if line.startswith("  base_link"))
    assert lines[k + 1].strip().startswith("free surface cuts")
    assert lines[k + 2].strip().startswith("added mass diag")


def test_a_model_entry_that_names_no_model_says_why(tmp_path):
    assert resolve_model("uvms_lbv150") == shipped_path("models/uvms_lbv150.urdf")
    (tmp_path / "models").mkdir()
    with pytest.raises(up.ParameterError, match=r"'models' is a directory \(.*\), not a URDF"):
        resolve_model("models", tmp_path)
    with pytest.raises(up.ParameterError) as info:
        resolve_model("bluerov3", tmp_path)
    message = str(info.value)
    assert "'bluerov3' is neither a file" in message and "uvms_lbv150" in message
    assert message.endswith("did you mean 'bluerov2_heavy'?")
    with pytest.raises(up.ParameterError, match="the model is empty"):
        resolve_model(" ")
    with pytest.raises(up.ModelError, match="is a directory, not a URDF file"):
        up.load_uvms(ROOT / "models")


@pytest.mark.parametrize("name", ["uvms_lbv150.urdf", "uvms_bluerov2_alpha5.urdf"])
def test_the_bodies_table_is_each_joints_mass_volume_and_net_weight(name):
    """Each body's row: its mass, the water it displaces and (m - rho V) g; the total row the
    model's, its net weight the sum of the rows (to the table's digits) and -net_buoyancy."""
    uvms = up.load_uvms(shipped_path(f"models/{name}"))
    lines = model_summary(uvms).splitlines()
    first = lines.index(next(line for line in lines if line.startswith("  joint "))) + 1
    rows = [line.split() for line in lines[first : first + uvms.model.njoints]]
    rho, g = uvms.water_density_kg_m3, -uvms.model.gravity.linear[2]
    for j, (joint, mass, volume, net) in enumerate(rows[:-1], start=1):
        assert joint == uvms.model.names[j]
        assert float(mass) == pytest.approx(uvms.model.inertias[j].mass, abs=1e-4)
        assert float(volume) == pytest.approx(uvms.volume_per_joint_m3[j], abs=1e-6)
        expected = (uvms.model.inertias[j].mass - rho * uvms.volume_per_joint_m3[j]) * g
        assert float(net) == pytest.approx(expected, abs=1e-4)
    total = rows[-1]
    assert total[0] == "total"
    assert float(total[1]) == pytest.approx(uvms.mass_kg, abs=1e-4)
    assert float(total[3]) == pytest.approx(-uvms.net_buoyancy_N, abs=1e-4)
    assert float(total[3]) == pytest.approx(sum(float(r[3]) for r in rows[:-1]), abs=1e-3)
