"""Grasping by contact: a ball between the closed pads of a parallel jaw is held by friction
up to 2 mu F (two pads, each pressing with F) and slips beyond it.

The jaw (tests/jaw_helpers.py) hangs below a heavy, neutrally buoyant hull; its two
prismatic fingers close on a ball with F = 2 N each (`[gripper]`, the force-limited servo);
the ball is denser than water by what makes its net weight W. A ball, not a block: one
contact point per pad on the line through its centre, so the pads' friction makes no moment
about that line (a block gets one deepest point per pad, off its centre, and swings about
the line through them).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from jaw_helpers import FINGER_Z_M, parallel_jaw_urdf

import uvms_pin as up

GRIP_N, MU, RADIUS_M, G = 2.0, 0.5, 0.02, 9.81


def _held_ball(
    folder: Path, net_weight_N: float, contact: str = "compliant"
) -> tuple[np.ndarray, np.ndarray, object]:
    """(t [s], the ball's height below the hull [m], the rollout's table), the pads
    touching the ball by ``contact`` (`[world] moving_contact`)."""
    volume = 4.0 / 3.0 * math.pi * RADIUS_M**3
    data = {
        "scenario": {"name": "grasp", "model": str(parallel_jaw_urdf(folder)), "duration_s": 1.0},
        "water": {"free_surface": False},
        # the pads 2 mm off the ball, closing from the start
        "initial": {"position_world_m": [0.0, 0.0, -5.0], "joint_positions_rad": [0.012, 0.012]},
        "world": {
            "moving_contact": contact,
            "objects": [
                {
                    "type": "sphere",
                    "name": "ball",
                    "radius_m": RADIUS_M,
                    "position_world_m": [0.0, 0.0, -5.0 + FINGER_Z_M - 0.04],
                    "density_kg_m3": 1025.0 + net_weight_N / (volume * G),
                    "friction_static": MU,
                    "friction_kinetic": MU,
                }
            ],
        },
        "gripper": {"max_force_N": GRIP_N},
        "control": {"period_s": 0.001},
        "integrator": {"method": "rk4", "step_s": 0.00025},
        "output": {"log_period_s": 0.01},
    }
    rollout = up.simulate(up.scenario_from_dict(data, folder / "grasp.toml"))
    table = rollout.to_dataframe()
    below = table["q.vehicle.z_m"] - table["free_objects.ball_z_m"]
    return np.asarray(table.index, dtype=float), below.to_numpy(), table


@pytest.mark.parametrize(
    ("contact", "fraction"),
    # the rigid contacts' stiction holds to within 2 % of the limit, and without creep
    [("compliant", 0.95), ("compliant", 1.05), ("rigid", 0.98), ("rigid", 1.02)],
)
def test_a_ball_is_held_below_2_mu_f_and_slips_beyond(tmp_path, contact, fraction):
    limit_N = 2.0 * MU * GRIP_N
    t, below, table = _held_ball(tmp_path, fraction * limit_N, contact)
    gripped = t >= 0.3
    slip_m = below[-1] - below[gripped][0]
    if fraction < 1.0:
        # held: less than 0.1 mm in 0.7 s (the compliant friction's spring creeps a little,
        # the rigid contact's stiction not at all: to its solver's tolerance)
        assert abs(slip_m) < (1e-4 if contact == "compliant" else 1e-7)
        # each pad presses with F and carries half the net weight by friction
        pads = [c for c in table.columns if c.endswith("finger/collision[0]|ball.fz_N")]
        assert len(pads) == 2
        carried = sum(table[c].iloc[-1] for c in pads)
        assert abs(carried) == pytest.approx(fraction * limit_N, rel=1e-2)
        grip = table["jaw.left_finger_joint_grip_N"].iloc[-1]
        assert grip == pytest.approx(GRIP_N, rel=1e-9)  # the servo saturated on the ball
    else:
        assert slip_m > 0.05  # slipped out: more than 5 cm in 0.7 s
