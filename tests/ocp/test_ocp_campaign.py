"""A user's campaign on `uvms_pin.ocp`: the action model's derivatives on models other than
the reference one, and the bad inputs a user can give the action model, its costs, the
problem builders and the solver.

crocoddyl is in the dev extra (``pip install -e '.[dev]'``); without it these tests skip.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT, continuous_joint_urdf, mount_on_reference_vehicle

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.flow import UniformCurrent
from uvms_pin.model.vehicles import bluerov2_heavy
from uvms_pin.physics.contact import LinearSpring

crocoddyl = pytest.importorskip("crocoddyl")

from uvms_pin.ocp import costs, problems  # noqa: E402
from uvms_pin.ocp.model import UnderwaterActionModel  # noqa: E402
from uvms_pin.physics.derivatives.task_contact import TaskContact  # noqa: E402

ALPHA5 = ROOT / "models" / "uvms_bluerov2_alpha5.urdf"
BARE_VEHICLE = ROOT / "models" / "bluerov2_heavy.urdf"


@pytest.fixture(scope="module")
def alpha5_uvms() -> up.UVMS:
    """The other shipped UVMS: a BlueROV2 Heavy with a Reach Alpha 5."""
    return up.load_uvms(ALPHA5)


@pytest.fixture(scope="module")
def bare_vehicle() -> up.UVMS:
    """A vehicle alone (nq = 7, nv = 6), its body the end-effector frame."""
    return up.load_uvms(BARE_VEHICLE, ee_frame="base_link", sensor_frame="base_link")


@pytest.fixture(scope="module")
def mounted_alpha5(tmp_path_factory) -> up.UVMS:
    """The catalogue's Alpha 5 mounted (upside down) on the reference vehicle."""
    return mount_on_reference_vehicle("alpha5", tmp_path_factory.mktemp("mount"))


@pytest.fixture(scope="module")
def continuous_arm(tmp_path_factory) -> up.UVMS:
    """The reference UVMS with its four arm joints continuous (q: cos and sin each)."""
    return up.load_uvms(continuous_joint_urdf(tmp_path_factory.mktemp("continuous")))


def _state(uvms, rng):
    q = pin.integrate(uvms.model, uvms.neutral_configuration(), rng.uniform(-0.4, 0.4, uvms.nv))
    q[2] = -3.0
    return np.r_[q, rng.normal(scale=0.3, size=uvms.nv)]


def _thrusters(uvms) -> problems.Actuators:
    return problems.Actuators(up.input_matrix(bluerov2_heavy.thrusters(), uvms.nv), None)


def _terms(uvms, nu, contact: bool):
    x_ref = np.r_[uvms.neutral_configuration(), np.zeros(uvms.nv)]
    target = pin.SE3(pin.exp3(np.array([0.1, -0.2, 0.3])), np.array([0.5, 0.1, -2.5]))
    terms = [
        (costs.end_effector_pose(uvms, target, np.ones(6)), 1.0),
        (costs.FramePosition(uvms.ee_frame_id, [0.3, 0.0, -3.0], np.ones(3)), 0.3),
        (costs.vehicle_attitude(uvms, np.eye(3), np.ones(3)), 0.5),
        (costs.StateDeviation(uvms.model, x_ref, np.full(2 * uvms.nv, 0.1)), 1.0),
        (costs.Effort(np.ones(nu)), 1e-3),
    ]
    if contact:
        terms.append((costs.ContactForce([0.4, 0.1, -0.2], [1.0, 0.5, 0.1]), 1.0))
    if uvms.nv > 6:  # a margin the random states cross (a non-zero term)
        terms.append((costs.JointLimitMargin(uvms.model, 1.0, 10.0), 1.0))
    return terms


def _check_against_numdiff(uvms, x, actuators, contact_model=None, flow=None):
    """Fx, Fu, Lx, Lu of the model against crocoddyl's forward differences (~1e-7 relative
    error expected, held to 1e-5 of the largest entry, as tests/ocp/test_ocp.py)."""
    nu = actuators.nu(uvms.nv)
    contact = None if contact_model is None else TaskContact(uvms.ee_frame_id, contact_model)
    model = UnderwaterActionModel(
        uvms,
        _terms(uvms, nu, contact is not None),
        input_matrix_=actuators.input_matrix,
        flow=flow,
        contact=contact,
    )
    numdiff = crocoddyl.DifferentialActionModelNumDiff(model, False)
    data, nd_data = model.createData(), numdiff.createData()
    u = np.random.default_rng(3).normal(scale=5.0, size=model.nu)
    model.calc(data, x, u)
    model.calcDiff(data, x, u)
    numdiff.calc(nd_data, x, u)
    numdiff.calcDiff(nd_data, x, u)
    assert np.all(np.isfinite(data.xout)) and np.isfinite(data.cost)
    for name in ("Fx", "Fu", "Lx", "Lu"):
        got, expected = getattr(data, name), getattr(nd_data, name)
        scale = max(np.abs(expected).max(), 1e-9)
        assert np.abs(got - expected).max() < 1e-5 * scale, name
    return data


def _spring_at_tip(uvms, x):
    data = uvms.model.createData()
    pin.framesForwardKinematics(uvms.model, data, x[: uvms.nq])
    tip = data.oMf[uvms.ee_frame_id].translation
    return LinearSpring(np.array([20.0, 30.0, 50.0]), tip - [0.1, 0.05, -0.05])


@pytest.mark.parametrize("contact", [False, True], ids=["free", "spring"])
@pytest.mark.parametrize(
    "which", ["alpha5_uvms", "bare_vehicle", "mounted_alpha5", "continuous_arm"]
)
def test_calc_diff_matches_numdiff_on_other_models(request, which, contact):
    """The shipped BlueROV2 + Alpha 5, the vehicle alone, an arm mounted by uvms-pin and
    continuous arm joints (NumDiff steps through the state's exact circle difference), in a
    current, with the eight thrusters as the input, with and without the end-effector on a
    spring: the analytic derivatives are crocoddyl's numerical ones."""
    uvms = request.getfixturevalue(which)
    x = _state(uvms, np.random.default_rng(11))
    spring = _spring_at_tip(uvms, x) if contact else None
    data = _check_against_numdiff(
        uvms, x, _thrusters(uvms), spring, UniformCurrent([0.2, -0.1, 0.05])
    )
    if contact:
        assert np.linalg.norm(data.contact.wrench_world[:3]) > 1.0


def _at_rest(uvms):
    q = uvms.neutral_configuration()
    q[2] = -3.0
    return np.r_[q, np.zeros(uvms.nv)]


@pytest.mark.parametrize(
    ("keywords", "message"),
    [
        ({"dt_s": 0.0}, "dt_s"),
        ({"dt_s": -0.02}, "dt_s"),
        ({"dt_s": float("nan")}, "dt_s"),
        ({"horizon_s": 0.0}, "horizon_s"),
        ({"horizon_s": -1.0}, "horizon_s"),
        ({"horizon_s": float("nan")}, "horizon_s"),
        ({"horizon_s": float("inf")}, "horizon_s"),
        ({"horizon_s": 0.005}, "horizon_s"),  # shorter than half a node: no node
        ({"pose_weights": (1.0, 2.0, 3.0)}, "pose_weights"),
        ({"effort_weight": -1e-4}, "effort"),
        ({"effort_weight": float("nan")}, "effort"),
        ({"dt_s": "0.02"}, "dt_s must be a number"),  # was: a comparison's TypeError
        ({"horizon_s": None}, "horizon_s must be a number"),
        ({"pose_weights": "heavy"}, "pose_weights"),  # was: float()'s ValueError
        ({"effort_weight": "1e-4"}, "effort"),
    ],
)
@pytest.mark.parametrize("builder", ["point_to_point", "station_hold"])
def test_problem_builders_refuse_bad_horizons_steps_and_weights(
    reference_uvms, builder, keywords, message
):
    """A horizon or node length that is not a positive finite time, a horizon without a node,
    a weight vector of the wrong size or a negative / NaN effort weight: ParameterError
    naming it (was: ZeroDivisionError, ValueError, OverflowError, or a one-node problem for a
    horizon of 0 or -1 s, or a negative / NaN cost accepted)."""
    build = getattr(problems, builder)
    with pytest.raises(ParameterError, match=message):
        build(reference_uvms, _at_rest(reference_uvms), pin.SE3.Identity(), **keywords)


def test_force_tracking_refuses_a_negative_or_nan_effort_weight(reference_uvms):
    """(a negative or NaN effort weight was dropped silently: no effort cost at all)"""
    uvms = reference_uvms
    contact = TaskContact(uvms.ee_frame_id, LinearSpring(np.full(3, 2.0), np.zeros(3)))
    for weight in (-1.0, float("nan")):
        with pytest.raises(ParameterError, match="effort_weight"):
            problems.force_tracking(
                uvms, _at_rest(uvms), contact, lambda t: np.zeros(3), np.eye(3),
                horizon_s=0.1, effort_weight=weight,
            )  # fmt: skip


def test_the_action_model_refuses_bad_scales_effort_sizes_and_nan_bounds(reference_uvms):
    uvms = reference_uvms
    effort = costs.Effort(np.ones(uvms.nv))
    for scale in (-1.0, float("nan"), float("inf")):
        with pytest.raises(ParameterError, match="effort"):
            UnderwaterActionModel(uvms, [(effort, scale)])
    # an effort term over 3 inputs on a model with nv = 10 inputs (was: a numpy
    # broadcasting error at the first calc)
    with pytest.raises(ParameterError, match="effort"):
        UnderwaterActionModel(uvms, [(costs.Effort(np.ones(3)), 1.0)])
    nan_bounds = (np.full(uvms.nv, np.nan), np.ones(uvms.nv))
    with pytest.raises(ParameterError, match="u_bounds"):  # (was: accepted)
        UnderwaterActionModel(uvms, [], u_bounds=nan_bounds)
    with pytest.raises(ParameterError, match="u_bounds"):
        UnderwaterActionModel(uvms, [], u_bounds=(np.ones(uvms.nv), np.zeros(uvms.nv)))
    # infinite bounds are no bound on that input: allowed
    inf = np.full(uvms.nv, np.inf)
    UnderwaterActionModel(uvms, [], u_bounds=(-inf, inf))


def test_solve_refuses_bad_iterations_and_a_non_finite_start(reference_uvms):
    """A negative iteration count (was: OverflowError from the binding) or zero (the
    solver then reports a cost of 0 for a plan it never evaluated); a NaN start state: the
    node's ParameterError raised inside crocoddyl's C++ loop aborted the whole process
    (SIGABRT, 'terminate called after throwing boost::python::error_already_set'), so it is
    refused before crocoddyl runs. Both also in a subprocess, so an abort fails the test
    instead of killing pytest."""
    uvms = reference_uvms
    problem = problems.point_to_point(uvms, _at_rest(uvms), pin.SE3.Identity(), horizon_s=0.1)
    for iterations in (-1, 0):
        with pytest.raises(ParameterError, match="iterations"):
            problems.solve(problem, iterations=iterations)
    script = (
        "import numpy as np, pinocchio as pin, uvms_pin as up\n"
        "from uvms_pin.errors import ParameterError\n"
        "from uvms_pin.ocp import problems\n"
        f"uvms = up.load_uvms({str(ROOT / 'models' / 'uvms_lbv150.urdf')!r})\n"
        "x0 = np.r_[uvms.neutral_configuration(), np.zeros(uvms.nv)]\n"
        "p = problems.point_to_point(uvms, x0, pin.SE3.Identity(), horizon_s=0.1)\n"
        "p.x0 = np.r_[x0[:-1], np.nan]\n"
        "try:\n"
        "    problems.solve(p, iterations=2)\n"
        "except ParameterError as exc:\n"
        "    print('refused:', exc)\n"
    )
    import subprocess
    import sys

    result = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=120
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert "refused:" in result.stdout and "x0" in result.stdout, result.stdout
    with pytest.raises(ParameterError, match="warm"):
        xs = [problem.x0] * (problem.T + 1)
        us = [np.full(problem.runningModels[0].nu, np.nan)] * problem.T
        problems.solve(problem, iterations=1, warm_start=(xs, us))
