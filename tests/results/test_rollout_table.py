"""Rollout.to_dataframe: every array component in one named column with its unit."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.results.rollout import Rollout
from uvms_pin.results.table import UNIT_TEXT, column_layout

JOINTS = ["shoulder", "slide", "wrist"]


def _rollout(n: int = 5, kinds=("revolute", "prismatic", "revolute")) -> Rollout:
    nv = 6 + len(JOINTS)
    meta = {"arm_joint_names": JOINTS, "arm_joint_kinds": list(kinds), "scenario": "x"}
    rollout = Rollout.allocate(n, nv + 1, nv, meta)
    rng = np.random.default_rng(3)
    for name in Rollout._BASE:
        setattr(rollout, name, rng.normal(size=getattr(rollout, name).shape))
    rollout.signal("e_x", 6)[:] = rng.normal(size=(n, 6))
    rollout.signal("rho_zeta", nv)[:] = rng.normal(size=(n, nv))
    rollout.signal("tau", nv)[:] = rng.normal(size=(n, nv))
    rollout.signal("my_signal", 2)[:] = rng.normal(size=(n, 2))
    rollout.signal("q", 1)[:] = rng.normal(size=(n, 1))
    return rollout


def test_columns_hold_the_arrays_they_name():
    r = _rollout()
    df = r.to_dataframe()
    np.testing.assert_array_equal(df.index.to_numpy(), r.time_s)
    assert df.index.name == "time_s"
    np.testing.assert_array_equal(df["q.vehicle.x_m"], r.q[:, 0])
    np.testing.assert_array_equal(df["q.vehicle.qw"], r.q[:, 6])
    np.testing.assert_array_equal(df["q.shoulder_rad"], r.q[:, 7])
    np.testing.assert_array_equal(df["v.vehicle.wz_rad_s"], r.v[:, 5])
    np.testing.assert_array_equal(df["v.wrist_rad_s"], r.v[:, 8])
    np.testing.assert_array_equal(df["tau.vehicle.fx_N"], r.tau[:, 0])
    np.testing.assert_array_equal(df["tau.vehicle.mz_Nm"], r.tau[:, 5])
    np.testing.assert_array_equal(df["wrench_contact_world.fz_N"], r.wrench_contact_world[:, 2])
    np.testing.assert_array_equal(
        df["wrench_disturbance_body.my_Nm"], r.wrench_disturbance_body[:, 4]
    )
    np.testing.assert_array_equal(df["kinetic_energy_J"], r.kinetic_energy_J)
    np.testing.assert_array_equal(df["e_x.yaw_rad"], r.signals["e_x"][:, 5])
    np.testing.assert_array_equal(df["rho_zeta.vehicle.vy_m_s"], r.signals["rho_zeta"][:, 1])
    np.testing.assert_array_equal(df["rho_zeta.wrist_rad_s"], r.signals["rho_zeta"][:, 8])


def test_prismatic_joints_get_linear_units():
    df = _rollout().to_dataframe()
    assert {"q.slide_m", "v.slide_m_s", "tau.slide_N"} <= set(df.columns)
    assert {"q.shoulder_rad", "v.shoulder_rad_s", "tau.shoulder_Nm"} <= set(df.columns)


def test_every_column_has_a_unit_matching_its_name_and_nothing_is_lost():
    r = _rollout()
    df = r.to_dataframe()
    units = df.attrs["units"]
    assert list(units) == list(df.columns)
    assert len(set(df.columns)) == len(df.columns)
    widths = sum(getattr(r, name).reshape(len(r), -1).shape[1] for name in Rollout._BASE[1:])
    widths += sum(a.shape[1] for a in r.signals.values())
    assert df.shape == (len(r), widths)
    suffix = {text: code for code, text in UNIT_TEXT.items()}
    for column, unit in units.items():
        if unit:
            assert column.endswith(f"_{suffix.get(unit, unit)}"), column
    assert units["q.vehicle.qx"] == "" and units["e_x.fx_N"] == "N"
    assert units["v.vehicle.vx_m_s"] == "m/s" and units["tau.vehicle.mz_Nm"] == "N m"
    assert units["v.wrist_rad_s"] == "rad/s" and units["q.slide_m"] == "m"
    assert df.attrs["metadata"]["scenario"] == "x"


def test_unknown_and_colliding_signals_are_indexed_and_prefixed():
    df = _rollout().to_dataframe()
    assert {"my_signal.0", "my_signal.1", "signal.q.0"} <= set(df.columns)
    assert "signal.tau.vehicle.fx_N" in df.columns and "signal.tau.wrist_Nm" in df.columns


def test_a_known_signal_of_unexpected_width_falls_back_to_indices():
    r = _rollout()
    r.signals["e_x"] = r.signals["e_x"][:, :3]
    names = [name for name, _, _ in column_layout(r) if name.startswith("e_x")]
    assert names == ["e_x.0", "e_x.1", "e_x.2"]


def test_simulated_rollout_names_the_models_joints():
    scenario = up.load_scenario(
        ROOT / "scenarios" / "passive_still_water.toml", {"scenario.duration_s": 0.04}
    )
    rollout = up.simulate(scenario, progress=False)
    assert rollout.metadata["arm_joint_kinds"] == ["revolute"] * 4
    df = rollout.to_dataframe()
    names = scenario.uvms.arm_joint_names
    for k, name in enumerate(names):
        np.testing.assert_array_equal(df[f"v.{name}_rad_s"], rollout.v[:, 6 + k])
    assert df["q.vehicle.z_m"].iloc[0] == pytest.approx(-2.0)
    assert "tau_commanded.vehicle.fx_N" in df.columns


@pytest.mark.parametrize(
    "meta, expected",
    [
        # one name short: the joints numbered
        ({"arm_joint_names": ["a", "b"]}, ["joint1_rad", "joint2_m", "joint3_rad"]),
        # a kind it does not know, or one kind short: the names kept, revolute units
        ({"arm_joint_kinds": ["revolute", "helical", "revolute"]},
         ["shoulder_rad", "slide_rad", "wrist_rad"]),
        ({"arm_joint_kinds": ["revolute", "prismatic"]},
         ["shoulder_rad", "slide_rad", "wrist_rad"]),
    ],
)  # fmt: skip
def test_metadata_that_does_not_fit_the_arrays_gives_plain_columns(meta, expected):
    """A rollout whose joint names or kinds do not fit its q (a hand-edited rollout.json):
    one column per entry still, named from what fits, nothing dropped or shifted."""
    r = _rollout()
    r.metadata.update(meta)
    columns = [name for name, _, _ in column_layout(r) if name.startswith("q.")]
    assert len(columns) == r.q.shape[1]
    assert columns[7:] == [f"q.{c}" for c in expected]


def test_a_signals_record_that_does_not_fit_its_width_gives_indexed_columns():
    """A signal logged with component names and units (`signal_units`) whose record has
    fewer names or units than the signal's columns: indexed columns, not a misaligned zip."""
    r = _rollout()
    r.metadata["signal_units"] = {
        "my_signal": {"components": ["left"], "units": ["m", "m"]},
    }
    names = [name for name, _, _ in column_layout(r) if name.startswith("my_signal")]
    assert names == ["my_signal.0", "my_signal.1"]
    r.metadata["signal_units"] = {
        "my_signal": {"components": ["left", "right"], "units": ["m", "m"]},
    }
    names = [name for name, _, _ in column_layout(r) if name.startswith("my_signal")]
    assert names == ["my_signal.left_m", "my_signal.right_m"]
