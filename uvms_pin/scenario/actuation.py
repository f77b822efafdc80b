"""``[actuation]``: the vehicle's thrusters (``[[actuation.thruster]]``) and the arm's joint
torque limits; without the table every DoF is actuated without limit.

``thruster_curve`` (one of `CURVES`, default "linear") is every thruster's ``curve`` unless
its entry names its own: one key switches a vehicle's thrusters to the T200 table.

A thruster entry: ``name``, ``position_body_m``, ``direction_body``, ``max_forward_N``,
``max_reverse_N`` (the allocation's limits); its drive: ``curve`` ("linear", "quadratic",
"t200_16v"), ``deadband`` (quadratic: the command fraction giving no thrust),
``time_constant_s`` (first-order lag, 0: none) and ``rate_limit_N_s`` (absent: none).
"""

from __future__ import annotations

import math

from uvms_pin.errors import ParameterError
from uvms_pin.model.thrust_curve import QuadraticThrustCurve, ThrustCurve
from uvms_pin.model.thruster import Thruster
from uvms_pin.model.uvms import UVMS
from uvms_pin.model.vehicles.t200 import t200_16v_curve
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.actuation import Actuation, ThrustersAndJointLimits, Unlimited, linear_curve
from uvms_pin.sim.thruster_drive import ThrusterDrives

CURVES = ("linear", "quadratic", "t200_16v")


def build_actuation(t: Table | None, uvms: UVMS) -> Actuation:
    if t is None:
        return Unlimited()
    limit_joints = t.boolean("limit_joint_torques", True)
    entries = t.tables("thruster")
    if not entries:
        raise t.fail("needs at least one [[actuation.thruster]]")
    default_curve = t.string("thruster_curve", "linear", CURVES)
    parts = [_thruster(e, k, default_curve) for k, e in enumerate(entries)]
    parts = _shared_curves(parts)
    thrusters = [p[0] for p in parts]
    drives = ThrusterDrives([p[1] for p in parts], [p[2] for p in parts], [p[3] for p in parts])
    if all(c.name == "linear" for c in drives.curves) and not drives.has_dynamics:
        drives = None  # the allocated thrust at once: the actuation's direct path
    components = t.vector("allocated_components", None, [0, 1, 2, 3, 4, 5])
    t.finish()
    limits = uvms.model.effortLimit[6:].copy() if limit_joints else None
    try:
        return ThrustersAndJointLimits(thrusters, limits, components.astype(int).tolist(), drives)
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc


def _thruster(t: Table, k: int, default_curve: str) -> tuple[Thruster, ThrustCurve, float, float]:
    """(the thruster, its curve (``default_curve`` unless it names one), its time constant
    [s], its rate limit [N/s])."""
    name = t.string("name", f"thruster{k}")
    position = t.vector("position_body_m", 3)
    direction = t.vector("direction_body", 3)
    kind = t.string("curve", default_curve, CURVES)
    table_curve = t200_16v_curve() if kind == "t200_16v" else None
    # a tabulated curve brings its own limits; lower ones may be given
    forward = t.number(
        "max_forward_N", table_curve.max_forward_N if table_curve else None, nonneg=True
    )
    reverse = t.number(
        "max_reverse_N", table_curve.max_reverse_N if table_curve else None, nonneg=True
    )
    if table_curve is not None:
        for key, value, most in (
            ("max_forward_N", forward, table_curve.max_forward_N),
            ("max_reverse_N", reverse, table_curve.max_reverse_N),
        ):
            if value > most:
                raise t.error(key, f"{value} N is more than the {kind} curve gives ({most:.6g} N)")
    try:
        thruster = Thruster(
            name=name,
            position_body_m=position,
            direction_body=direction,
            max_forward_N=forward,
            max_reverse_N=reverse,
        )
        deadband = t.number("deadband", 0.0, nonneg=True)
        if deadband and kind != "quadratic":
            raise t.error(
                "deadband", f'applies to curve = "quadratic" (curve "{kind}" has its own)'
            )
        if kind == "quadratic":
            curve: ThrustCurve = QuadraticThrustCurve(forward, reverse, deadband)
        else:
            curve = table_curve if table_curve is not None else linear_curve(thruster)
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc
    time_constant = t.number("time_constant_s", 0.0, nonneg=True)
    rate = t.optional_number("rate_limit_N_s", positive=True)
    t.finish()
    return thruster, curve, time_constant, math.inf if rate is None else rate


def _shared_curves(parts: list) -> list:
    """Equal quadratic curves as one object: the drives evaluate a shared curve at once."""
    shared: dict[tuple[float, float, float], ThrustCurve] = {}
    out = []
    for thruster, curve, tau, rate in parts:
        if isinstance(curve, QuadraticThrustCurve):
            key = (curve.forward_N, curve.reverse_N, curve.deadband)
            curve = shared.setdefault(key, curve)
        out.append((thruster, curve, tau, rate))
    return out
