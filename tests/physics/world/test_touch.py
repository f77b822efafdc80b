"""The world's broad phase (`uvms_pin.physics.world.touch.reach_spheres`, `clear_of`): the
sphere a piece may sweep over a horizon holds every point of the piece over it, and is the
documented bound, no larger."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from conftest import ALPHA5_URDF

import uvms_pin as up
from uvms_pin.physics.world.objects import plane
from uvms_pin.physics.world.touch import CLEARANCE_M, Bounds, clear_of, reach_spheres
from uvms_pin.physics.world.world import World


def _reference_pieces():
    uvms = up.load_uvms(ALPHA5_URDF)
    return uvms, World(uvms, []).pieces


def test_a_pieces_reach_sphere_holds_it_over_the_horizon_and_is_the_documented_bound():
    """For random states of the BlueROV2 + Alpha 5, each piece's sphere over h is centred on
    the piece's bounding sphere and of radius r + 2 (|v_j| + |w_j| (|c| + r)) h + clearance
    (v_j, w_j its joint's twist, c the sphere's centre in the joint's frame: a bound of its
    fastest point's speed |v_j + w_j x c| + |w_j| r), and, the velocity held
    over the horizon, every piece's sphere stays inside (its centre moves by at most the
    first order's distance; 2 x leaves room for the velocity to change)."""
    uvms, pieces = _reference_pieces()
    model, data = uvms.model, uvms.model.createData()
    moved = model.createData()
    rng = np.random.default_rng(21)
    swept = 0.0
    for _ in range(40):
        q = pin.randomConfiguration(model, -np.ones(uvms.nq), np.ones(uvms.nq))
        v = rng.normal(size=uvms.nv) * rng.uniform(0.1, 3.0)
        horizon_s = rng.uniform(0.01, 0.5)
        pin.forwardKinematics(model, data, q, v)
        centres, radii = reach_spheres(data, pieces, horizon_s)
        assert centres.shape == (len(pieces), 3) and radii.shape == (len(pieces),)
        for k, piece in enumerate(pieces):
            local = piece.placement_in_joint.translation
            twist = data.v[piece.joint_id]
            np.testing.assert_allclose(centres[k], data.oMi[piece.joint_id].act(local), atol=1e-12)
            speed = np.linalg.norm(twist.linear) + np.linalg.norm(twist.angular) * (
                np.linalg.norm(local) + piece.bound_radius_m
            )
            expected = piece.bound_radius_m + 2.0 * speed * horizon_s + CLEARANCE_M
            assert abs(radii[k] - expected) <= 1e-12
        # the state moved along v for fractions of the horizon: each piece's bounding sphere
        # stays within its reach sphere (first order: 1x of the 2x margin used)
        for fraction in (0.25, 0.5, 1.0):
            q_t = pin.integrate(model, q, v * fraction * horizon_s)
            pin.forwardKinematics(model, moved, q_t)
            for k, piece in enumerate(pieces):
                centre = moved.oMi[piece.joint_id].act(piece.placement_in_joint.translation)
                offset = np.linalg.norm(centre - centres[k])
                swept = max(swept, offset / (radii[k] - piece.bound_radius_m))
                assert offset + piece.bound_radius_m <= radii[k] - CLEARANCE_M + 1e-9
    assert swept > 0.2  # the motion, not the clearance, set the sizes tried


def test_clear_of_turns_at_the_reach_of_the_lowest_piece_over_a_plane():
    """A plane just below the reach of the lowest piece's sphere: not clear; just beyond it:
    clear, at rest and turning (the reach grows with |w| (|c| + r))."""
    uvms, pieces = _reference_pieces()
    model, data = uvms.model, uvms.model.createData()
    q = pin.neutral(model)
    for v in (np.zeros(uvms.nv), np.r_[0.2, 0.0, 0.1, 0.0, 0.0, 1.5, np.zeros(uvms.nv - 6)]):
        horizon_s = 0.1
        pin.forwardKinematics(model, data, q, v)
        centres, radii = reach_spheres(data, pieces, horizon_s)
        lowest = float(np.min(centres[:, 2] - radii))  # where the first sphere ends
        for gap, expected in ((-1e-6, False), (1e-6, True)):
            floor = plane("seabed", [0.0, 0.0, lowest - gap], [0.0, 0.0, 1.0], 0.5, 0.4)
            assert clear_of(data, pieces, Bounds.of([floor]), horizon_s) is expected
