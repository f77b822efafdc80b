"""An imported vehicle runs: the URDF and its thruster table make a scenario as they are."""

from __future__ import annotations

from pathlib import Path

import numpy as np

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
