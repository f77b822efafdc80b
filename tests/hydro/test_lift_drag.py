"""A fin's lift and drag (gz-sim's LiftDrag, `uvms_pin.hydro.lift_drag`): the formula on
analytic cases, the stall, the sweep, the control joint, and a force that never does positive
work (none at all with the flow along the chord)."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.hydro.lift_drag import LiftDragParams, angle_of_attack, lift_drag_wrench

# the LRAUV tutorial's fins (gz-sim tutorials/files/underwater_vehicles/buoyant_lrauv.sdf)
FIN = LiftDragParams(
    area_m2=0.0244,
    fluid_density_kg_m3=1000.0,
    cla=4.13,
    cda=0.2,
    alpha_stall_rad=0.17,
    cla_stall=-1.1,
    cda_stall=0.03,
)
F, U = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])  # forward x, upward z
S = np.cross(F, U)  # the span, -y
SPEED = 1.5


def _flow(alpha: float, speed: float = SPEED) -> np.ndarray:
    """A flow meeting the chord at ``alpha`` from below its upward side."""
    return speed * (math.cos(alpha) * F - math.sin(alpha) * U)


def _expected(alpha: float, params: LiftDragParams = FIN, span_speed: float = 0.0) -> np.ndarray:
    """gz-sim's formula written out for this fin: lift along cos(a) u + sin(a) f, drag along
    -v_ld, dynamic pressure of the in-plane speed, the sweep's cos^2."""
    p, stall = params, params.alpha_stall_rad
    if alpha > stall:
        cl = max(0.0, p.cla * stall + p.cla_stall * (alpha - stall))
        cd = abs(p.cda * stall + p.cda_stall * (alpha - stall))
    elif alpha < -stall:
        cl = min(0.0, -p.cla * stall + p.cla_stall * (alpha + stall))
        cd = abs(-p.cda * stall + p.cda_stall * (alpha + stall))
    else:
        cl, cd = p.cla * alpha, abs(p.cda * alpha)
    cos2 = SPEED**2 / (SPEED**2 + span_speed**2)
    q_area = 0.5 * p.fluid_density_kg_m3 * SPEED**2 * p.area_m2
    lift = math.cos(alpha) * U + math.sin(alpha) * F
    drag = -_flow(alpha) / SPEED
    return q_area * cos2 * (cl * lift + cd * drag)


@pytest.mark.parametrize("alpha", [-1.2, -0.4, -0.17, -0.05, 0.0, 0.01, 0.1, 0.17, 0.3, 1.0, 1.5])
def test_the_force_against_the_angle_of_attack_is_gz_sims_formula(alpha):
    attack = angle_of_attack(FIN, np.eye(3), _flow(alpha))
    assert attack[0] == pytest.approx(alpha, abs=1e-12)
    force, moment = lift_drag_wrench(FIN, np.eye(3), _flow(alpha))
    np.testing.assert_allclose(force, _expected(alpha), rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(moment, np.zeros(3))  # c_Ma = 0


def test_lift_grows_with_the_angle_up_to_the_stall_and_falls_after():
    lift = [lift_drag_wrench(FIN, np.eye(3), _flow(a))[0] @ U for a in (0.05, 0.1, 0.17, 0.3)]
    assert lift[0] < lift[1] < lift[2] and lift[3] < lift[2]
    # below the stall: L = c_La alpha q S along the lift's direction (the drag is normal to it)
    # (gz-sim's alpha is an arc cosine: near 0 it carries eps / sin(alpha) of error)
    for a, rel in ((1e-4, 1e-7), (0.05, 1e-12), (0.16, 1e-12)):
        lift_direction = math.cos(a) * U + math.sin(a) * F
        expected = FIN.cla * a * 0.5 * 1000.0 * SPEED**2 * FIN.area_m2
        force, _ = lift_drag_wrench(FIN, np.eye(3), _flow(a))
        assert force @ lift_direction == pytest.approx(expected, rel=rel)


def test_a_flow_along_the_span_is_swept_out():
    alpha, span_speed = 0.1, 0.8
    flow = _flow(alpha) + span_speed * S
    force, _ = lift_drag_wrench(FIN, np.eye(3), flow)
    np.testing.assert_allclose(force, _expected(alpha, span_speed=span_speed), rtol=1e-12)


def test_no_force_along_the_chord_below_the_threshold_speed_or_from_behind():
    for flow in (SPEED * F, 0.007 * (F - U), -SPEED * F + 0.3 * U):  # |0.007 (1, 0, -1)| < 0.01
        force, moment = lift_drag_wrench(FIN, np.eye(3), flow)
        assert not force.any() and not moment.any()
    reversible = LiftDragParams(**{**FIN.__dict__, "reversible": True})
    assert np.any(lift_drag_wrench(reversible, np.eye(3), -SPEED * F + 0.3 * U)[0])


def test_the_force_never_does_positive_work_and_turns_with_the_fin():
    rng = np.random.default_rng(41)
    fins = [FIN, LiftDragParams(area_m2=0.1, fluid_density_kg_m3=1025.0, forward=[1, 1, 0],
            upward=[0, 0.2, 1], radial_symmetry=True, reversible=True, cla_stall=0.5)]  # fmt: skip
    for _ in range(400):
        params = fins[rng.integers(2)]
        rotation = pin.exp3(rng.normal(size=3))
        flow = rng.normal(size=3) * rng.uniform(0.0, 3.0)
        force, _ = lift_drag_wrench(params, rotation, flow)
        assert force @ flow <= 1e-12 * max(1.0, np.linalg.norm(force) * np.linalg.norm(flow))
        # the same fin and flow turned together: the same force, turned
        turn = pin.exp3(rng.normal(size=3))
        turned, _ = lift_drag_wrench(params, turn @ rotation, turn @ flow)
        np.testing.assert_allclose(turned, turn @ force, atol=1e-10)


def test_the_control_joint_adds_its_lift_and_moment():
    params = LiftDragParams(**{**FIN.__dict__, "control_joint_rad_to_cl": 2.0, "cm_delta": 0.5})
    alpha, delta = 0.05, 0.1
    force, moment = lift_drag_wrench(params, np.eye(3), _flow(alpha), control_rad=delta)
    base, _ = lift_drag_wrench(params, np.eye(3), _flow(alpha))
    q_area = 0.5 * 1000.0 * SPEED**2 * FIN.area_m2
    lift = math.cos(alpha) * U + math.sin(alpha) * F
    np.testing.assert_allclose(force - base, 2.0 * delta * q_area * lift, atol=1e-12)
    np.testing.assert_allclose(moment, 0.5 * delta * q_area * S, atol=1e-12)


def test_bad_parameters_are_refused_by_name():
    for kwargs, word in (
        ({"area_m2": -1.0}, "area"),
        ({"area_m2": 1.0, "fluid_density_kg_m3": 0.0}, "fluid density"),
        ({"area_m2": 1.0, "forward": [0, 0, 0]}, "forward"),
        ({"area_m2": 1.0, "upward": [2, 0, 0]}, "upward must not be along forward"),
        ({"area_m2": 1.0, "cla": math.nan}, "cla"),
    ):
        with pytest.raises(ParameterError, match=word):
            LiftDragParams(**kwargs)


@pytest.mark.parametrize("alpha", [-1.2, -0.3, -0.1, 0.1, 0.3, 1.2])
def test_the_moment_about_the_span_follows_its_own_slopes(alpha):
    """M = c_M q S along the span, c_M = c_Ma alpha below the stall and c_Ma alpha_s +
    c_Ma,stall (alpha - alpha_s) beyond it (mirrored below -alpha_s), kept of the sign it
    had at the stall: with c_Ma = 0.8 and c_Ma,stall = -0.3 (a lift of c_La as FIN's)."""
    params = LiftDragParams(**{**FIN.__dict__, "cma": 0.8, "cma_stall": -0.3})
    stall = params.alpha_stall_rad
    if alpha > stall:
        cm = max(0.0, 0.8 * stall - 0.3 * (alpha - stall))
    elif alpha < -stall:
        cm = min(0.0, -0.8 * stall - 0.3 * (alpha + stall))
    else:
        cm = 0.8 * alpha
    q_area = 0.5 * 1000.0 * SPEED**2 * FIN.area_m2
    force, moment = lift_drag_wrench(params, np.eye(3), _flow(alpha))
    np.testing.assert_allclose(moment, cm * q_area * S, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(force, _expected(alpha), rtol=1e-12, atol=1e-12)


def test_a_flow_across_the_chord_or_along_the_span_gives_nothing():
    """A flow normal to the chord (f . v = 0, straight up or down at the fin) meets a
    one-way fin from neither side: no force. A reversible fin in a flow along its span has
    no flow in its lift-drag plane (v_ld = 0, the sweep's cos^2 = 0): no force, no moment."""
    for flow in (SPEED * U, -SPEED * U, SPEED * S):
        force, moment = lift_drag_wrench(FIN, np.eye(3), flow)
        assert not force.any() and not moment.any()
    reversible = LiftDragParams(**{**FIN.__dict__, "reversible": True, "cma": 0.8})
    force, moment = lift_drag_wrench(reversible, np.eye(3), SPEED * S)
    np.testing.assert_array_equal(force, np.zeros(3))
    np.testing.assert_array_equal(moment, np.zeros(3))
