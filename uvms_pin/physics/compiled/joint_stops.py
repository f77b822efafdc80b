"""Joint stops as the core's (src/uvms_core/joint_stops.hpp): `JointStops`."""

from __future__ import annotations

from types import ModuleType

from uvms_pin.physics.joint_stops import JointStops


def joint_stops_to_core(stops: JointStops | None, core: ModuleType):
    """The core's stops (None: none)."""
    if stops is None:
        return None
    out = core.JointStops()
    out.q_index = [int(i) for i in stops.q_index]
    out.v_index = [int(i) for i in stops.v_index]
    out.lower_rad = stops.lower_rad
    out.upper_rad = stops.upper_rad
    out.stiffness_Nm_rad = float(stops.stiffness_Nm_rad)
    out.damping_Nm_s_rad = float(stops.damping_Nm_s_rad)
    return out
