"""An imported vehicle runs: the URDF and its thruster table make a scenario as they are."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import uvms_pin as up

LRAUV = Path(__file__).parent / "data" / "lrauv_hydrodynamics.sdf"


def test_imported_lrauv_with_its_thruster_table_runs_and_its_propeller_pushes(tmp_path):
    up.import_model(LRAUV, tmp_path / "lrauv.urdf")
    table = (tmp_path / "lrauv.thrusters.toml").read_text()
    scenario = tmp_path / "run.toml"
    scenario.write_text(
        '[scenario]\nmodel = "lrauv.urdf"\nduration_s = 2.0\n\n'
        "[initial]\nposition_world_m = [0.0, 0.0, -5.0]\n"
        "joint_positions_rad = [0.0, 0.0]\n\n"
        '[controller]\ntype = "none"\n\n[control]\nperiod_s = 0.01\n\n'
        '[integrator]\nmethod = "rk4"\nstep_s = 0.005\n\n[output]\nlog_period_s = 0.05\n\n' + table
    )
    loaded = up.load_scenario(scenario)
    rollout = up.simulate(loaded)
    assert rollout.status.ok
    assert np.all(np.isfinite(rollout.q))
    # no thrust commanded: nothing pushes it forward; it floats, nearly neutral
    assert abs(rollout.v[-1, 0]) < 1e-3
    assert rollout.signals["thrust"].shape[1] == 1
    # the propeller pushes along the body x axis, through the centre line: a pure surge force
    actuation = loaded.plant.actuation
    actuation.start(0.01)
    applied = actuation.apply(np.r_[10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(applied[:6], [10.0, 0.0, 0.0, 0.0, 0.0, 0.0], atol=1e-12)


PASSIVE_LRAUV = (
    '[scenario]\nmodel = "lrauv.urdf"\nduration_s = 60.0\n\n'
    "[initial]\nposition_world_m = [0.0, 0.0, -5.0]\nrpy_rad = [0.2, -0.1, 0.3]\n"
    # the fins swung against their +-0.26 rad limits within the first second
    "velocity = [0.5, 0.0, 0.1, 0.1, 0.1, 0.3, 0.5, -0.5]\n\n"
    '[controller]\ntype = "none"\n\n[integrator]\nmethod = "rk4"\nstep_s = 0.005\n\n'
    "[output]\nlog_period_s = 0.05\n"
)


def test_the_imported_lrauv_with_passive_fins_runs_a_minute_or_is_refused(tmp_path):
    """Its fins (0.2 kg plates, no added mass or damping in gz-sim's model: 5e-5 kg m^2 about
    their hinge) on compliant stops of 1000 N m/rad and 5 N m s/rad diverged at their first
    touch of a stop, at the same time at a 5 ms and a 1 ms step (c / I = 1e5 1/s: RK4 needs
    h <= 28 us); as constraints (the default of a passive run) they hold, and the stops are
    refused before the run, the fin's joint named."""
    from uvms_pin.errors import StiffModeError
    from uvms_pin.results.metrics import joint_limit_metrics

    up.import_model(LRAUV, tmp_path / "lrauv.urdf")
    scenario = tmp_path / "passive.toml"
    scenario.write_text(PASSIVE_LRAUV)
    for step_s in (0.005, 0.001):
        rollout = up.simulate(up.load_scenario(scenario, {"integrator.step_s": step_s}))
        assert rollout.status.ok and rollout.time_s[-1] == 60.0
        limits = joint_limit_metrics(rollout)
        assert limits["time_at_joint_stop_s"] > 0.0  # the fins did reach their limits
        assert limits["joint_limit_excess_max_rad"] < 1e-6
        assert np.abs(rollout.v).max() < 2.0
    compliant = up.load_scenario(scenario, {"joints.stops": "compliant"})
    with pytest.raises(StiffModeError, match=r"the compliant stop of joint '\w+_fins_joint'") as e:
        up.simulate(compliant)
    assert e.value.largest_stable_step_s < 1e-4


def test_the_imported_lrauv_with_lifting_fins_runs_a_minute_and_its_fins_only_take_energy(
    tmp_path,
):
    """With gz-sim's tutorial LiftDrag on both fins (tests/fin_helpers.py) the passive run
    above lasts its minute at its 5 ms step (the compiled loop, its fins in the core),
    and the fins' lift and drag at every logged state take power from the motion, never give
    it (c_Ma = 0: lift normal to the flow, drag against it)."""
    from fin_helpers import import_lrauv

    from uvms_pin.physics.fins import fin_generalized_force, fin_wrenches_world

    import_lrauv(tmp_path)
    scenario = tmp_path / "passive.toml"
    scenario.write_text(PASSIVE_LRAUV)
    rollout = up.simulate(up.load_scenario(scenario), progress=False)
    assert rollout.status.ok and rollout.time_s[-1] == 60.0
    assert rollout.metadata["closed_loop"]["path"] == "compiled"
    assert np.all(np.isfinite(rollout.q)) and np.abs(rollout.v).max() < 2.0
    uvms = up.load_uvms(tmp_path / "lrauv.urdf")
    data = uvms.model.createData()
    power = np.array(
        [
            fin_generalized_force(uvms, data, q, fin_wrenches_world(uvms, data, q, v)) @ v
            for q, v in zip(rollout.q, rollout.v, strict=True)
        ]
    )
    assert power.max() <= 1e-12 and power.min() < -1e-3


STEERED_LRAUV = (
    '[scenario]\nmodel = "lrauv.urdf"\nduration_s = 6.0\n\n[water]\ndensity_kg_m3 = 1000.0\n\n'
    "[initial]\nposition_world_m = [0.0, 0.0, -10.0]\n"
    "velocity = [-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]\n\n"
    '[integrator]\nmethod = "rk4"\nstep_s = 0.005\n\n[control]\nperiod_s = 0.01\n\n'
    # gz-sim's tutorial holds each fin with a JointPositionController of p_gain 0.1
    '[controller]\ntype = "joint_hold"\nstiffness_Nm_rad = 0.1\ndamping_Nms_rad = 0.002\n'
    "vehicle_wrench_body = [-20.0, 0.0, 0.0, 0.0, 0.0, 0.0]\n"
    "positions_rad = {{ vertical_fins_joint = {rudder}, horizontal_fins_joint = 0.0 }}\n"
)


def test_the_imported_lrauv_steers_with_its_rudder_held_as_a_joint(tmp_path):
    """Pushed along its nose (-x) at 20 N with the rudder (the vertical fin, behind) held at
    +-0.2 rad, the LRAUV of gz-sim's tutorial turns one way or the other, by the same amount;
    at 0 it goes straight; without its LiftDrag the rudder turns nothing."""
    from fin_helpers import import_lrauv

    def yaw_rate_end(folder, rudder: float) -> tuple[float, float]:
        (folder / "steer.toml").write_text(STEERED_LRAUV.format(rudder=rudder))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", up.errors.CoreFallbackWarning)
            rollout = up.simulate(up.load_scenario(folder / "steer.toml"), progress=False)
        assert rollout.status.ok
        vertical = up.load_uvms(folder / "lrauv.urdf").model.getJointId("vertical_fins_joint")
        assert rollout.q[-1, 7 + vertical - 2] == pytest.approx(rudder, abs=2e-3)  # held
        return float(rollout.v[-1, 5]), float(rollout.q[-1, 1])

    finned, bare = tmp_path / "finned", tmp_path / "bare"
    finned.mkdir(), bare.mkdir()
    import_lrauv(finned)
    import_lrauv(bare, "")
    left, right, straight = (yaw_rate_end(finned, r) for r in (0.2, -0.2, 0.0))
    assert abs(left[0]) > 0.05 and left[0] == pytest.approx(-right[0], rel=1e-6)
    assert left[1] == pytest.approx(-right[1], rel=1e-6) and abs(left[1]) > 0.3  # sideways
    assert abs(straight[0]) < 1e-9
    assert abs(yaw_rate_end(bare, 0.2)[0]) < 1e-3
