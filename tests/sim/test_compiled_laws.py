"""The compiled laws of the force baselines (src/uvms_core/law_force_baselines.hpp) and of
resolved acceleration (law_tracking.hpp), built by uvms_pin/sim/compiled/laws.py, in the
compiled sampled loop against their Python controllers in the Python loop: the whole
rollout to 1e-12, the same stop, the law's state handed over when the core declines a tick."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT
from test_compiled_loop import PAPER, PAPER_SAMPLED, REALISTIC, _assert_same

from uvms_pin.apps.compare.runs import controller_scenarios
from uvms_pin.control.base import ZeroController
from uvms_pin.control.baselines.computed_torque import ComputedTorqueController
from uvms_pin.control.baselines.pi_force import PIForceController
from uvms_pin.control.ppc import PrescribedPerformanceController
from uvms_pin.control.pseudo_inverse import MinimumNormSolver
from uvms_pin.errors import ControllerError, SimulationError
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.results.metrics import joint_limit_metrics
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.compiled.laws import law_to_core
from uvms_pin.sim.run import simulate

BASELINES = ("pi_force", "impedance", "computed_torque")
#: the paper's scenario sampled at 500 Hz with RK4 (its own is continuous-time)
PAPER_BASELINE = {k: v for k, v in PAPER_SAMPLED.items() if k != "controller.k_zeta"}


def _scenario(path, kind, overrides):
    return controller_scenarios(path, [kind], {"scenario.duration_s": 1.0, **overrides})[kind]


def _both(scenario, **kwargs):
    """((rollout, the error that stopped it or None) compiled, the same in Python)."""
    out = []
    for compiled in (True, False):
        try:
            out.append((simulate(scenario, progress=False, compiled_loop=compiled, **kwargs), None))
        except SimulationError as exc:
            out.append((exc.rollout, exc))
    return out


def test_a_force_loop_held_at_its_anti_windup_bound_runs_compiled_as_in_python():
    """pi_force's integral clipped at +-integral_limit_Ns (0.01 N s here, which the
    realistic run's force error reaches within 0.5 s; the loop's gains are handed to the
    core by the same code for computed_torque): the compiled law holds it at the same
    bound as the Python controller, tick by tick."""
    limit = [0.01, 0.01, 0.01]
    overrides = {"baselines.pi_force.integral_limit_Ns": limit, "scenario.duration_s": 0.5}
    (compiled, stop_c), (python, stop_p) = _both(_scenario(REALISTIC, "pi_force", overrides))
    assert stop_c is None and stop_p is None
    assert compiled.metadata["closed_loop"]["python_ticks"] == 0
    integral = compiled.signals["force_integral_Ns"]
    assert np.max(np.abs(integral)) == pytest.approx(0.01, abs=1e-15)  # held at the bound
    assert np.mean(np.abs(integral[:, 0]) == 0.01) > 0.2  # for a good part of the run
    _assert_same(compiled, python)


@pytest.mark.parametrize("kind", BASELINES)
@pytest.mark.parametrize(
    "path, overrides",
    [(REALISTIC, {}), (PAPER, PAPER_BASELINE)],
    ids=["realistic", "paper-sampled"],
)
def test_each_baseline_runs_compiled_as_in_python(kind, path, overrides):
    scenario = _scenario(path, kind, overrides)
    (compiled, stop_c), (python, stop_p) = _both(scenario)
    ticks = round(scenario.settings.duration_s / scenario.settings.control_period_s) + 1
    meta = compiled.metadata["closed_loop"]
    if stop_p is None:
        assert stop_c is None
        assert meta == {"path": "compiled", "reason": None, "compiled_ticks": ticks,
                        "python_ticks": 0}  # fmt: skip
        assert python.metadata["closed_loop"]["python_ticks"] == ticks
    else:  # the paper's unlimited vehicle with a default-tuned baseline at 500 Hz: its
        # wrist races at thousands of rad/s between its limits (the sampled loop unstable)
        assert str(stop_c) == str(stop_p)
        python_ticks = python.metadata["closed_loop"]["python_ticks"]
        if "left physics" in str(stop_p):  # found once the run ended: every tick compiled
            assert meta == {"path": "compiled", "reason": None, "compiled_ticks": ticks,
                            "python_ticks": 0}  # fmt: skip
        else:  # diverged: the tick that diverged is handed to Python
            assert "diverged" in str(stop_p)
            assert meta == {"path": "compiled", "reason": None,
                            "compiled_ticks": python_ticks - 1, "python_ticks": 1}  # fmt: skip
    # a joint resting on its limit (the paper's arm under a default-tuned baseline) lands
    # each period at q0 + h (-r / h): its gap r is the rounding of the last landing (~1e-16
    # rad), which v = -r / h turns into ~1e-13 rad/s, not the same in the two loops
    rests = joint_limit_metrics(python).get("time_at_joint_stop_s", 0.0) > 0.0
    _assert_same(compiled, python, rtol=1e-11 if rests else 1e-12)
    assert np.max(np.abs(compiled.v)) > 1e-2  # the run did something
    assert np.max(np.abs(compiled.signals["e_x"][:, :3])) > 1e-2


@pytest.mark.parametrize("kind", BASELINES)
def test_a_declined_tick_raises_in_python_as_in_the_python_loop(kind):
    # the tool's pitch q2 + q3 = pi/2 - 1e-5: the Euler singularity, where the task raises
    singular = {"initial.joint_positions_rad": [-0.2, 1.0, 0.5707863, 0.2]}
    (_, compiled), (_, python) = _both(_scenario(REALISTIC, kind, singular))
    assert isinstance(compiled, ControllerError) and isinstance(python, ControllerError)
    assert str(compiled) == str(python) and "singular" in str(compiled).lower()
    meta = compiled.rollout.metadata["closed_loop"]
    assert meta["reason"] is None and meta["python_ticks"] == 1
    assert meta["compiled_ticks"] == 0


@pytest.mark.parametrize("kind", ["pi_force", "computed_torque"])
def test_ticks_the_solver_declines_hand_the_integral_over(kind):
    # a solver that accepts only the better-conditioned half of the run's Jacobians: the
    # other ticks take the exact SVD route in Python, the integral handed back and forth
    scenario = _scenario(REALISTIC, kind, {"scenario.duration_s": 0.6})
    controller = scenario.controller_factory(scenario.uvms)
    reference = controller.task.reference
    bound = _median_condition_bound(scenario, reference.weights)
    # the solver's largest certified bound is 1 / cutoff^2 (its cutoff is not the SVD's)
    reference.solver = MinimumNormSolver(reference.weights, float(np.sqrt(1.0 / bound)))
    compiled = simulate(scenario, progress=False, controller=controller, compiled_loop=True)
    python = simulate(scenario, progress=False, controller=controller, compiled_loop=False)
    meta = compiled.metadata["closed_loop"]
    assert meta["compiled_ticks"] > 20 and meta["python_ticks"] > 20
    _assert_same(compiled, python)
    assert np.max(np.abs(compiled.signals["e_x"][:, :3])) > 1e-2


def _median_condition_bound(scenario, weights) -> float:
    """The median over a Python run's logged states of the solver's certified bound
    tr G tr G^-1, G = J W^-1 J^T."""
    rollout = simulate(scenario, progress=False, compiled_loop=False)
    task = scenario.controller_factory(scenario.uvms).task
    inverse_weights = 1.0 if weights is None else 1.0 / np.asarray(weights)
    bounds = []
    for q in rollout.q:
        jacobian = task.evaluate(0.0, _Measured(q, rollout.v[0])).jacobian_lwa
        gram = (jacobian * inverse_weights) @ jacobian.T
        bounds.append(np.trace(gram) * np.trace(np.linalg.inv(gram)))
    return float(np.median(bounds))


class _Measured:
    def __init__(self, q, v):
        self.q, self.v, self.wrench_world = q, v, np.zeros(6)


def test_law_to_core_says_why_a_controller_has_no_law():
    core = core_module()
    scenario = _scenario(REALISTIC, "computed_torque", {})
    controller = scenario.controller_factory(scenario.uvms)
    assert not isinstance(law_to_core(controller, core), Fallback)
    model, task = scenario.uvms.model, controller.task
    ee = task.model.frames[task.ee_frame_id].name

    class Mine(PIForceController):
        pass

    mine = law_to_core(Mine(model, ee), core)
    assert isinstance(mine, Fallback) and "Mine is not compiled" in mine.reason
    python = PrescribedPerformanceController(model, ee, backend="python")
    assert law_to_core(python, core).reason == "the controller's Python backend"
    motion = ComputedTorqueController(scenario.uvms, ee, reference=lambda t: (None, None, None))
    assert "motion reference" in law_to_core(motion, core).reason
    nq, nv = model.nq, model.nv
    assert not isinstance(law_to_core(ZeroController(nv, nq), core), Fallback)
    assert "without nq" in law_to_core(ZeroController(nv), core).reason


def test_a_passive_run_takes_the_compiled_loop_and_is_the_python_loops():
    """scenarios/passive_still_water.toml (no input: the zero law) runs in the compiled
    loop, every tick, and gives the Python loop's rollout."""
    path = ROOT / "scenarios" / "passive_still_water.toml"
    scenario = load_scenario(path, {"scenario.duration_s": 0.5})
    rollouts = [simulate(scenario, progress=False, compiled_loop=c) for c in (True, False)]
    compiled, python = (r.metadata["closed_loop"] for r in rollouts)
    assert compiled["path"] == "compiled" and compiled["python_ticks"] == 0
    assert python["path"] == "python"
    _assert_same(*rollouts)


@pytest.mark.parametrize(
    "stem, overrides",
    [
        ("lbv150_ee_circle", {}),
        ("lbv150_ee_circle", {"water.current_world_m_s": [0.1, 0.0, 0.0]}),
        ("bluerov_alpha5_ee_circle", {}),
        # the vehicle's own path (its bias acceleration R (w x v), no arm frame)
        ("lbv150_ee_circle", {"task.target": "vehicle"}),
    ],
    ids=["lbv150", "lbv150-current", "bluerov-alpha5", "lbv150-vehicle"],
)
def test_resolved_acceleration_runs_compiled_as_in_python(stem, overrides):
    path = ROOT / "scenarios" / f"{stem}.toml"
    scenario = controller_scenarios(
        path, ["computed_torque_task"], {"scenario.duration_s": 3.0, **overrides}
    )["computed_torque_task"]
    (compiled, stop_c), (python, stop_p) = _both(scenario)
    assert stop_c is None and stop_p is None
    ticks = round(scenario.settings.duration_s / scenario.settings.control_period_s) + 1
    assert compiled.metadata["closed_loop"] == {
        "path": "compiled", "reason": None, "compiled_ticks": ticks, "python_ticks": 0}  # fmt: skip
    _assert_same(compiled, python)
    assert compiled.metadata["signal_units"]["task_position_error"] == python.metadata[
        "signal_units"]["task_position_error"]  # fmt: skip
    assert np.max(np.abs(compiled.signals["task_position_error"])) > 1e-4


# ---- the MPC (src/uvms_core/law_mpc.hpp) ---------------------------------------------------
MPC_FORCE = ROOT / "scenarios" / "mpc_force_tracking.toml"
MPC_STATION = ROOT / "scenarios" / "mpc_station_keeping.toml"


@pytest.mark.parametrize(
    "path, overrides",
    [
        (MPC_FORCE, {}),
        pytest.param(  # (twenty iterations every re-plan: 5 s)
            MPC_FORCE,
            {"controller.iterations": 2, "controller.warm_start": False},
            marks=pytest.mark.slow,
        ),
        (MPC_STATION, {}),
    ],
    ids=["force", "force-cold", "station"],
)
def test_the_mpc_replans_in_the_compiled_loop_as_in_python(path, overrides):
    """The MPC on its compiled planner, re-planning inside the compiled loop, against the
    same controller ticked by the Python loop: the whole rollout to 1e-9 (the force task's
    spring placed at the tip by the law's first plan, its preview of f_d, the warm starts
    moved on; cold re-plans every time without warm_start). The two loops' plants differ
    by rounding (1e-16, the other laws' rollouts agree to 1e-12); twenty FDDP iterations from
    a cold start turn it into up to 2e-10 of a thrust (1e-10 with warm starts)."""
    pytest.importorskip("crocoddyl")
    scenario = load_scenario(path, {"scenario.duration_s": 0.6, **overrides})
    (compiled, stop_c), (python, stop_p) = _both(scenario)
    assert stop_c is None and stop_p is None
    ticks = round(0.6 / scenario.settings.control_period_s) + 1
    assert compiled.metadata["closed_loop"] == {
        "path": "compiled", "reason": None, "compiled_ticks": ticks, "python_ticks": 0
    }  # fmt: skip
    _assert_same(compiled, python, rtol=1e-9)
    assert np.ptp(compiled.signals["mpc_cost"]) > 0 and np.any(compiled.signals["mpc_u"])
    if "force" in str(path):
        assert np.max(np.abs(compiled.signals["e_x"][:, :3])) > 1e-2
        # the law placed the controller's spring at the tip and handed the point back
        controller = scenario.controller_factory(scenario.uvms)
        simulate(scenario, progress=False, controller=controller, compiled_loop=True)
        data = controller.uvms.model.createData()
        pin.framesForwardKinematics(controller.uvms.model, data, scenario.q0)
        tip = data.oMf[controller.uvms.ee_frame_id].translation
        np.testing.assert_allclose(controller._contact.model.placed_at(), tip, atol=1e-15)


def test_replans_without_their_preview_are_the_python_controllers(monkeypatch):
    """Every other re-plan tick's preview of f_d left NaN: the law declines those ticks, the
    Python controller re-plans them on the same planner and hands its plan back; the rollout
    is the Python loop's all the same."""
    pytest.importorskip("crocoddyl")
    from uvms_pin.sim.compiled import laws

    force_desired = laws._MpcLaw._force_desired
    seen = []

    def every_other(self, time_s):
        out = force_desired(self, time_s)
        if not np.isnan(out[3]):
            seen.append(time_s)
            if len(seen) % 2 == 0:
                out[3:] = np.nan
        return out

    monkeypatch.setattr(laws._MpcLaw, "_force_desired", every_other)
    scenario = load_scenario(MPC_FORCE, {"scenario.duration_s": 0.4})
    (compiled, _), (python, _) = _both(scenario)
    meta = compiled.metadata["closed_loop"]
    assert meta["path"] == "compiled" and 5 <= meta["python_ticks"] <= 15
    _assert_same(compiled, python, rtol=1e-9)


def test_an_mpc_solved_in_python_has_no_law():
    """CSQP (mim_solvers) or the python planner: the MPC ticks in the Python loop, and the
    reason names why its re-plans are not compiled."""
    pytest.importorskip("mim_solvers")
    for overrides, named in (({"controller.solver": "csqp"}, "csqp"),
                             ({"controller.planner": "python"}, "planner 'python'")):  # fmt: skip
        scenario = load_scenario(MPC_FORCE, {"scenario.duration_s": 0.1, **overrides})
        law = law_to_core(scenario.controller_factory(scenario.uvms), core_module())
        assert isinstance(law, Fallback) and named in law.reason
