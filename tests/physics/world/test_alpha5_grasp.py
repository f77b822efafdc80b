"""Grasping with the shipped Alpha 5 jaw (models/reach_alpha5_jaws.urdf's fingers, boxes along
their measured inner edges).

- Its hooks, parallel when opened 0.36 rad, hold a 40 mm ball by friction up to 2 mu N (N the
  normal force each presses with) and let it slip beyond: held at 0.95 x 2 mu N, out of the
  jaw at 1.05 x 2 mu N. The jaw hangs below the heavy hull of tests/jaw_helpers.py.
- A sample held at rest adds its net weight, (rho - rho_water) V g, to the vertical force
  the vehicle needs (scenarios/object_recovery.toml's UVMS and controller, holding still).
- The water and the contacts never give energy back: while the jaw closes on an object,
  E(t) - E(0) never exceeds the work the servo has done.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from jaw_helpers import ALPHA5_JAW_Z_M, alpha5_jaw_urdf

import uvms_pin as up

GRIP_N, MU, RADIUS_M, G, WATER = 2.0, 0.5, 0.02, 9.81, 1025.0
#: the ball's centre below the jaw's base: on the hooks (72 mm out)
BALL_Z_M = 0.072
RECOVERY = Path(__file__).resolve().parents[3] / "scenarios" / "object_recovery.toml"


def _grasp(folder: Path, net_weight_N: float, open_rad: float = 0.38, log_period_s=0.01):
    """The rollout and its table: the jaw closes from ``open_rad`` on a free ball of net
    weight ``net_weight_N`` below it, the hull free (no controller)."""
    volume = 4.0 / 3.0 * math.pi * RADIUS_M**3
    data = {
        "scenario": {
            "name": "alpha5_grasp",
            "model": str(alpha5_jaw_urdf(folder)),
            "duration_s": 1.0,
        },
        "water": {"free_surface": False},
        "initial": {"position_world_m": [0.0, 0.0, -5.0], "joint_positions_rad": [open_rad] * 2},
        "world": {
            "objects": [
                {
                    "type": "sphere",
                    "name": "ball",
                    "radius_m": RADIUS_M,
                    "position_world_m": [0.0, 0.0, -5.0 + ALPHA5_JAW_Z_M - BALL_Z_M],
                    "density_kg_m3": WATER + net_weight_N / (volume * G),
                    "friction_static": MU,
                    "friction_kinetic": MU,
                }
            ]
        },
        "gripper": {"max_force_N": GRIP_N},
        "control": {"period_s": 0.001},
        "integrator": {"method": "rk4", "step_s": 0.00025},
        "output": {"log_period_s": log_period_s},
    }
    rollout = up.simulate(up.scenario_from_dict(data, folder / "grasp.toml"))
    return rollout, rollout.to_dataframe()


def _below_hull_m(table) -> np.ndarray:
    return (table["q.vehicle.z_m"] - table["free_objects.ball_z_m"]).to_numpy()


def _hook_columns(table, axis: str) -> list[str]:
    """Each finger's hook (its third box) on the ball: the force on the finger along axis."""
    return [c for c in table.columns if c.endswith(f"/collision[2]|ball.f{axis}_N")]


def test_the_hooks_hold_a_ball_below_2_mu_n_and_let_it_slip_beyond(tmp_path):
    # held: the normal force N each hook presses with, measured; the ball's net weight 95 %
    # of what the two hooks' friction can carry
    # about the pivot: F r = 0.091 N m (r = 45.7 mm), the finger's net weight 0.004 N m and
    # the friction 0.003 N m, over the contact's 66 mm arm
    normal_N = 1.49
    weight_N = 0.95 * 2 * MU * normal_N
    _, table = _grasp(tmp_path, weight_N)
    t = np.asarray(table.index, dtype=float)
    below = _below_hull_m(table)
    held = t >= 0.3
    assert abs(below[-1] - below[held][0]) < 1e-4  # less than 0.1 mm in 0.7 s
    normals = [abs(table[c].iloc[-1]) for c in _hook_columns(table, "y")]
    carried = [abs(table[c].iloc[-1]) for c in _hook_columns(table, "z")]
    assert len(normals) == 2 and len(carried) == 2
    limit_N = 2 * MU * float(np.mean(normals))
    assert weight_N / limit_N == pytest.approx(0.95, abs=0.01)  # at 95 % of 2 mu N
    assert sum(carried) == pytest.approx(weight_N, rel=1e-2)  # the hooks carry it all
    # beyond: 1.05 x 2 mu N with the N just measured: out of the jaw
    _, table = _grasp(tmp_path, 1.05 * limit_N)
    assert _below_hull_m(table)[-1] - below[held][0] > 0.05


def test_the_water_and_contacts_never_give_energy_back_as_the_jaw_closes(tmp_path):
    # the fingers close from fully open (0.5 rad), hit the ball at about 0.36 rad and squeeze
    # it; the servo's torque is held over each control period, so its work is exactly
    # sum_k tau_k (q_k+1 - q_k) with the log at the period
    rollout, _ = _grasp(tmp_path, 1.0, open_rad=0.5, log_period_s=0.001)
    tau, q = np.asarray(rollout.tau), np.asarray(rollout.q)
    steps = np.sum(tau[:-1, 6:] * np.diff(q[:, 7:], axis=0), axis=1)
    work_J = np.concatenate([[0.0], np.cumsum(steps)])
    assert np.all(tau[:, :6] == 0.0)  # the hull is passive: only the servo does work
    rest_J = rollout.total_energy_J - rollout.total_energy_J[0] - work_J
    assert work_J[-1] > 0.02  # the servo put in 25 mJ
    assert np.max(rest_J[1:]) < 0.0  # the water and contacts only ever took energy
    assert rest_J[-1] < -0.9 * work_J[-1]  # and took nearly all of it


def _still_with_sample(density_kg_m3: float) -> float:
    """The mean vertical force [N] the controller of object_recovery.toml asks of the
    vehicle over the last second of 8 s holding its jaw still, with the sample (50 mm x
    0.2 m) held in the jaw from the start."""
    overrides = {
        "scenario.duration_s": 8.0,
        "controller.jaw_close_at_s": 0.0,
        "controller.jaw_speed_rad_s": 5.0,  # from 0.5 to 0.45 rad (where they start) in 10 ms
        "initial.joint_positions_rad": [0.0, 0.1, 3.2, 0.0, 0.45, 0.45],
        # 68 mm out from the jaw's base, between the open fingers; the jaw where it starts
        "world.objects[1].position_world_m": [0.3085, -0.1096, -9.7573],
        "world.objects[1].density_kg_m3": density_kg_m3,
        "controller.waypoints_world_m": [[0.3085, -0.1096, -9.6893]],
        "controller.phase_durations_s": [1.0],
    }
    rollout = up.simulate(up.load_scenario(RECOVERY, overrides=overrides))
    assert rollout.metadata["status"] == "ok"
    last = np.asarray(rollout.time_s) > 7.0
    forces = [
        pin.Quaternion(q[3:7]).matrix() @ tau[:3]
        for q, tau in zip(rollout.q, rollout.tau, strict=True)
    ]
    return float(np.mean(np.asarray(forces)[last, 2]))


def test_a_held_sample_adds_its_net_weight_to_the_force_the_vehicle_needs():
    volume_m3 = math.pi * 0.025**2 * 0.2
    net_weight_N = (2000.0 - WATER) * volume_m3 * G  # 3.76 N
    # a sample as dense as the water weighs nothing net: what the vehicle needs without one
    empty_N = _still_with_sample(WATER)
    held_N = _still_with_sample(2000.0)
    assert held_N - empty_N == pytest.approx(net_weight_N, rel=0.02)
