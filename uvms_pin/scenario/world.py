"""``[environment]`` (what the end-effector touches) and ``[disturbance]`` (what pushes the
vehicle)."""

from __future__ import annotations

from collections.abc import Callable

from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.contact import CompliantPlane, ContactModel, LinearSpring
from uvms_pin.physics.disturbance import SinusoidalDisturbance
from uvms_pin.scenario.schema import Table


def build_environment(t: Table | None, uvms: UVMS) -> ContactModel | None:
    """The contact model of [environment] (type "spring" or "plane"), None without one."""
    if t is None:
        return None
    uvms.require_ee_frame("[environment] (a contact at the end-effector)")
    kind = t.string("type", choices=tuple(CONTACTS))
    model = CONTACTS[kind](t)
    t.finish()
    return model


def _spring(t: Table) -> LinearSpring:
    anchor = t.vector("anchor_world_m", 3) if t.has("anchor_world_m") else None
    return LinearSpring(t.vector("stiffness_N_m", 3, nonneg=True), anchor)


def _plane(t: Table) -> CompliantPlane:
    point = t.vector("anchor_world_m", 3) if t.has("anchor_world_m") else None
    return CompliantPlane(
        normal_world=t.vector("normal_world", 3, [-1.0, 0.0, 0.0]),
        stiffness_N_m=t.number("stiffness_N_m", positive=True),
        damping_N_s_m=t.number("damping_N_s_m", 0.0, nonneg=True),
        point_world_m=point,
    )


#: [environment] type -> how the contact model is built from the table
CONTACTS: dict[str, Callable[[Table], ContactModel]] = {"spring": _spring, "plane": _plane}


def build_disturbance(t: Table | None) -> SinusoidalDisturbance | None:
    """[disturbance]: a sinusoidal body wrench on the vehicle, None without one."""
    if t is None:
        return None
    out = SinusoidalDisturbance(
        amplitude=t.vector("amplitude", 6),
        period_s=t.number("period_s", positive=True),
        phase_rad=t.number("phase_rad", 0.0),
    )
    t.finish()
    return out
