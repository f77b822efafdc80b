"""The period step's constraint rows (`uvms_pin.sim.system.period.constrained`): a limit the
smooth step crosses within the period gets its row even when the period starts at rest."""

from __future__ import annotations

import numpy as np
from jaw_helpers import parallel_jaw_urdf

import uvms_pin as up
from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

PERIOD_S = 2e-3


def test_a_limit_crossed_within_a_period_from_rest_is_held(tmp_path):
    """A finger at rest 1.5 mm below its upper limit, pushed so hard that the smooth step
    alone would carry it 4.5 mm in one period: the limit's row is selected by the period's
    own speed (its start's is 0, and 1.5 mm is beyond the 1 mm margin), so the finger ends
    at the limit, not past it; without the limits the same step ends well past it."""
    uvms = up.load_uvms(parallel_jaw_urdf(tmp_path))
    q = uvms.neutral_configuration()
    q[:3] = [0.0, 0.0, -5.0]
    upper = uvms.model.upperPositionLimit[7]
    q[7:] = [upper - 1.5e-3, uvms.model.upperPositionLimit[8] - 0.01]
    push = np.zeros(uvms.nv)
    push[6] = 1.0
    acceleration = up.forward_dynamics(uvms, q, np.zeros(uvms.nv), push)[6]  # per newton
    push[6] = 2.0 * 4.5e-3 / (acceleration * PERIOD_S**2)  # 1/2 a h^2 = 4.5 mm
    plant = Plant(uvms, free_surface=False, joint_limits=JointLimits.of_uvms(uvms))
    free = System(Plant(uvms, free_surface=False))
    limited = System(plant)
    ends = []
    for system in (free, limited):
        state = system.initial_state(q, np.zeros(uvms.nv))
        system.start(state)
        q1, _ = system.advance(RK4(5e-4), 0.0, state.q, state.v, push, PERIOD_S)
        ends.append(q1[7])
    assert ends[0] - upper > 2.5e-3  # the smooth step alone: well past the limit
    assert abs(ends[1] - upper) < 1e-6  # held at it
