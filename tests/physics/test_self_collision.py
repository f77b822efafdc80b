"""Self-collision on request: an arm link folded into its vehicle's hull is pushed out (the
link jointed to the vehicle never counts); without the key it passes through."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.world import World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

_LINK = """
  <link name="{name}">
    <inertial><origin xyz="{com}"/><mass value="{mass}"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="{com}"/><geometry><box size="{size}"/></geometry></collision>
  </link>"""

_JOINT = """
  <joint name="{name}" type="revolute">
    <parent link="{parent}"/><child link="{child}"/><origin xyz="{xyz}"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="50" velocity="2"/>
  </joint>"""


def _folding_arm(tmp_path) -> up.UVMS:
    """A 1.0 x 0.6 x 0.4 m hull with a two-joint arm on its top (z = 0.2) at x = -0.3: a
    short shoulder (jointed to the hull) and a 0.6 m forearm along its x, which folds down
    into the hull for a positive elbow angle."""
    text = "\n".join(
        [
            '<robot name="folding">',
            _LINK.format(name="hull", com="0 0 0", mass=240.0, size="1.0 0.6 0.4"),
            _LINK.format(name="shoulder", com="0 0 0.025", mass=0.3, size="0.05 0.05 0.05"),
            _LINK.format(name="forearm", com="0.3 0 0", mass=2.0, size="0.6 0.06 0.06"),
            _JOINT.format(
                name="shoulder_joint", parent="hull", child="shoulder", xyz="-0.3 0 0.25"
            ),
            _JOINT.format(name="elbow", parent="shoulder", child="forearm", xyz="0 0 0.1"),
            "</robot>",
        ]
    )
    path = tmp_path / "folding.urdf"
    path.write_text(text)
    uvms = up.load_uvms(path)
    model = pin.Model(uvms.model)
    model.gravity = pin.Motion.Zero()  # weightless: only the contact moves the arm
    return uvms.with_model(model)


def _overlap_m(uvms: up.UVMS, world: World, q: np.ndarray) -> float:
    """The forearm's depth in the hull (coal's signed distance, > 0: inside)."""
    data = uvms.model.createData()
    pin.forwardKinematics(uvms.model, data, q)
    pieces = {world.body_names[p.body].split("/")[0]: p for p in world.pieces}
    shapes = []
    for name in ("forearm", "hull"):
        piece = pieces[name]
        where = data.oMi[piece.joint_id] * piece.placement_in_joint
        shapes.append((piece.shape, coal.Transform3s(where.rotation, where.translation)))
    result = coal.DistanceResult()
    coal.distance(*shapes[0], *shapes[1], coal.DistanceRequest(), result)
    return -float(result.min_distance)


@pytest.mark.parametrize("self_collision", [True, False])
def test_an_arm_folded_into_the_hull_is_pushed_out_only_on_request(tmp_path, self_collision):
    uvms = _folding_arm(tmp_path)
    law = ContactLaw(stiffness_N_m=2e4, dissipation_s_m=1.0)
    world = World(uvms, [], law, self_collision=self_collision)
    plant = Plant(uvms, world=world, free_surface=False)
    q = uvms.neutral_configuration()
    q[:3] = [0.0, 0.0, -5.0]
    q[8] = 0.5  # the elbow folds the forearm 5 cm deep into the hull's top
    depth0 = _overlap_m(uvms, world, q)
    assert depth0 > 0.03
    system = System(plant)
    v, tau = np.zeros(uvms.nv), np.zeros(uvms.nv)
    system.start(system.initial_state(q, v))
    for k in range(200):
        q, v = system.advance(RK4(1e-3), k * 0.01, q, v, tau, (k + 1) * 0.01)
    if self_collision:
        names = system.log.contact_pair_names
        assert names == [
            "forearm/collision[0]|hull/collision[0]"
        ]  # the shoulder (jointed to the hull) is excepted
        assert _overlap_m(uvms, world, q) < 0.02 * depth0  # out (to the last contact)
        assert q[8] < 0.5 - 0.05
    else:
        assert system.moving is None
        assert _overlap_m(uvms, world, q) == pytest.approx(depth0, rel=1e-9)  # through
