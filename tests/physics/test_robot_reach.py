"""A robot's reach (uvms_pin.physics.world.robot_reach): the sphere about its vehicle holds
every piece in any arm configuration, and bounds every material point's speed."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
from conftest import ROOT

import uvms_pin as up
from uvms_pin.physics.world.robot_reach import reach_sphere, robot_reach_m
from uvms_pin.physics.world.touch import CLEARANCE_M
from uvms_pin.physics.world.world import World


def test_the_reach_holds_every_piece_and_bounds_its_speed():
    uvms = up.load_uvms(ROOT / "models" / "uvms_bluerov2_alpha5.urdf")
    world = World(uvms, [])
    reach = robot_reach_m(uvms.model, world.pieces)
    assert 0.3 < reach < 3.0
    rng = np.random.default_rng(5)
    data = uvms.model.createData()
    for _ in range(50):
        q = pin.randomConfiguration(uvms.model, -np.ones(uvms.nq), np.ones(uvms.nq))
        v = rng.normal(size=uvms.nv)
        pin.forwardKinematics(uvms.model, data, q, v)
        origin = data.oMi[1].translation
        for piece in world.pieces:
            placement = data.oMi[piece.joint_id] * piece.placement_in_joint
            assert np.linalg.norm(placement.translation - origin) + piece.bound_radius_m <= reach
            # the fastest point of the piece's sphere, from its joint's twist
            twist = data.v[piece.joint_id]
            local = piece.placement_in_joint.translation
            fastest = (
                np.linalg.norm(twist.linear + np.cross(twist.angular, local))
                + np.linalg.norm(twist.angular) * piece.bound_radius_m
            )
            for horizon_s in (1.0, 0.01):  # what the points cover grows with the horizon
                centre, radius = reach_sphere(q, v, reach, horizon_s)
                assert np.array_equal(centre, q[:3])
                assert fastest * horizon_s <= (radius - reach - CLEARANCE_M) / 2.0 + 1e-12
            assert reach_sphere(q, v, reach, 0.01)[1] < reach_sphere(q, v, reach, 1.0)[1]


def test_a_robot_without_pieces_reaches_nothing_and_a_prismatic_arm_everywhere():
    model = pin.Model()
    model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
    assert robot_reach_m(model, []) == 0.0
    model.addJoint(1, pin.JointModelPX(), pin.SE3.Identity(), "slide")
    assert robot_reach_m(model, []) == math.inf
    at_rest = reach_sphere(np.zeros(8), np.zeros(7), math.inf, 0.01)  # no 0 x inf = nan
    assert at_rest[1] == math.inf
