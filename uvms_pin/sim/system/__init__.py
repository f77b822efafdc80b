"""The system of bodies: everything that moves in a run, stepped together.

`System` holds the robot (a `uvms_pin.sim.plant.Plant`: a UVMS or a bare vehicle in its
water, with its environment, joint stops and fixed world) and the world's free objects; one
state (`SystemState`: q and v of every body, `Layout` says where each sits), one right-hand
side, one period step and the contacts between any two bodies and between a body and the
fixed world.
"""

from uvms_pin.sim.system.state import Layout, SystemState
from uvms_pin.sim.system.system import System

__all__ = ["Layout", "System", "SystemState"]
