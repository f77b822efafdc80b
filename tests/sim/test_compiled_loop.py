"""The compiled sampled loop (uvms_pin/sim/compiled_loop.py, src/uvms_core/sampled_loop.hpp)
against the Python loop, tick by tick: same rollout to 1e-12, same stop, same partial run."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.control.base import Controller
from uvms_pin.errors import ActuationWarning, FunnelViolation
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.closed_loop import ClosedLoop
from uvms_pin.sim.log import RolloutLog
from uvms_pin.sim.run import simulate
from uvms_pin.sim.sensors import SensorSuite

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"
PAPER = ROOT / "scenarios" / "paper_force_tracking.toml"
#: the paper's scenario with a 500 Hz sampled PPC and RK4 (its own is continuous-time); its
#: k_zeta = 5 breaks a funnel within 2 ticks at 500 Hz, 0.2 holds until t = 0.186 s
PAPER_SAMPLED = {
    "controller.k_zeta": 0.2,
    "control.period_s": 0.002,
    "integrator": {"method": "rk4", "step_s": 0.0005},
    "output.log_period_s": 0.01,
}


def _run(path, overrides, compiled, **kwargs):
    scenario = load_scenario(path, {"scenario.duration_s": 1.0, **overrides})
    _run.ticks = round(scenario.settings.duration_s / scenario.settings.control_period_s) + 1
    try:
        rollout = simulate(scenario, progress=False, compiled_loop=compiled, **kwargs)
        return rollout, None
    except FunnelViolation as exc:
        return exc.rollout, exc


def _assert_same(a, b, rtol=1e-12):
    """Every array of two rollouts equal to ``rtol`` relative to each array's scale."""
    assert len(a) == len(b) > 0
    for name in ("time_s", "q", "v", "tau", "wrench_contact_world", "wrench_measured_world",
                 "wrench_disturbance_body", "kinetic_energy_J", "potential_energy_J"):  # fmt: skip
        x, y = getattr(a, name), getattr(b, name)
        scale = max(1.0, float(np.max(np.abs(y))))
        np.testing.assert_allclose(x, y, rtol=0, atol=rtol * scale, err_msg=name)
    assert list(a.signals) == list(b.signals)  # same signals, same order
    for name, values in b.signals.items():
        scale = max(1.0, float(np.max(np.abs(values))))
        np.testing.assert_allclose(a.signals[name], values, rtol=0, atol=rtol * scale, err_msg=name)


def _paths(compiled, python):
    return compiled.metadata["closed_loop"], python.metadata["closed_loop"]


@pytest.mark.parametrize(
    "path, overrides",
    [
        (REALISTIC, {}),
        (PAPER, {**PAPER_SAMPLED, "scenario.duration_s": 0.18}),
        (REALISTIC, {"water.current_world_m_s": [0.2, -0.1, 0.0],
                     "water.waves": {"amplitude_m": 0.3, "period_s": 4.0}}),
        # every noise channel: the measured state goes through the manifold (integrate)
        (REALISTIC, {"sensors.position_noise_m": 0.002, "sensors.orientation_noise_rad": 0.002,
                     "sensors.joint_noise_rad": 0.001, "sensors.velocity_noise": 0.002,
                     "sensors.torque_noise_Nm": 0.01, "sensors.sample_period_s": 0.0015}),
    ],
    ids=["realistic", "paper-sampled", "waves-current", "state-noise"],
)  # fmt: skip
def test_compiled_loop_matches_the_python_loop(path, overrides):
    compiled, stop_c = _run(path, overrides, True)
    python, stop_p = _run(path, overrides, False)
    assert stop_c is None and stop_p is None
    meta_c, meta_p = _paths(compiled, python)
    assert meta_c["path"] == "compiled" and meta_c["reason"] is None
    assert meta_c["python_ticks"] == 0 and meta_c["compiled_ticks"] == _run.ticks
    assert meta_p == {"path": "python", "reason": "the Python loop was asked for",
                      "compiled_ticks": 0, "python_ticks": _run.ticks}  # fmt: skip
    _assert_same(compiled, python)
    assert np.max(np.abs(compiled.v)) > 1e-2  # the run did something


@pytest.mark.parametrize(
    "path, overrides, tick",
    [(PAPER, PAPER_SAMPLED, 93), (REALISTIC, {"controller.k_zeta": 5.0}, 141)],
    ids=["paper-sampled", "realistic-paper-gains"],
)
def test_a_funnel_violation_stops_both_loops_at_the_same_tick(path, overrides, tick):
    compiled, stop_c = _run(path, overrides, True)
    python, stop_p = _run(path, overrides, False)
    assert stop_c is not None and stop_p is not None
    assert (stop_c.level, stop_c.component, stop_c.time_s) == (
        stop_p.level, stop_p.component, stop_p.time_s)  # fmt: skip
    assert stop_c.time_s == pytest.approx(tick * 0.002, abs=1e-12)
    assert compiled.status.kind == "FunnelViolation" == python.status.kind
    _assert_same(compiled, python)
    # the core ran the ticks before the violation and handed the violating one to Python
    assert compiled.metadata["closed_loop"] == {
        "path": "compiled", "reason": None, "compiled_ticks": tick, "python_ticks": 1}  # fmt: skip


def test_an_interrupted_compiled_run_keeps_its_rows():
    def interrupt(time_s, duration_s):
        if time_s >= 0.5:
            raise KeyboardInterrupt

    scenario = load_scenario(REALISTIC, {"scenario.duration_s": 1.0})
    with pytest.raises(KeyboardInterrupt) as info:
        simulate(scenario, progress=interrupt)
    partial = info.value.rollout
    assert partial.status.kind == "interrupted"
    assert partial.metadata["closed_loop"]["path"] == "compiled"
    assert 0.5 <= partial.time_s[-1] < 1.0
    full, _ = _run(REALISTIC, {}, True)
    n = len(partial)
    np.testing.assert_array_equal(partial.q, full.q[:n])
    np.testing.assert_array_equal(partial.signals["xi_zeta"], full.signals["xi_zeta"][:n])


class _Damping(Controller):
    def compute(self, time_s, measurement):
        return -np.asarray(measurement.v)


def test_a_python_part_makes_the_loop_take_the_python_path():
    scenario = load_scenario(REALISTIC, {"scenario.duration_s": 0.1})
    rollout = simulate(scenario, progress=False, controller=_Damping())
    meta = rollout.metadata["closed_loop"]
    assert meta["path"] == "python" and "_Damping" in meta["reason"]
    assert meta["python_ticks"] == 51
    continuous = simulate(load_scenario(PAPER, {"scenario.duration_s": 0.05}), progress=False)
    assert continuous.metadata["closed_loop"]["reason"] == "continuous-time control"


def test_what_the_thrusters_cannot_produce_is_warned_alike():
    # all six components asked of 4 thrusters that cannot roll or pitch: the allocation
    # drops a part of every command, tracked tick by tick in the core as in Python
    overrides = {"actuation.allocated_components": [0, 1, 2, 3, 4, 5], "scenario.duration_s": 0.3}
    warned = {}
    for compiled in (True, False):
        with pytest.warns(ActuationWarning) as record:
            rollout, _ = _run(REALISTIC, overrides, compiled)
        warned[compiled] = [str(w.message) for w in record if w.category is ActuationWarning]
        assert rollout.metadata["closed_loop"]["path"] == ("compiled" if compiled else "python")
    assert warned[True] == warned[False] and "roll moment" in warned[True][0]


def test_after_either_loop_the_controller_holds_the_last_ticks_signals():
    """The PPC given to a run ends with the signals of its last tick, whichever loop ran it:
    the compiled loop hands its kernel's last call to the controller (its f_d and rpy_d,
    `adopt_kernel_call`), the Python loop computed it; both the rollout's last logged row."""
    scenario = load_scenario(REALISTIC, {"scenario.duration_s": 0.2})
    held = []
    for compiled in (True, False):
        controller = scenario.controller_factory(scenario.uvms)
        rollout = simulate(scenario, progress=False, controller=controller, compiled_loop=compiled)
        assert rollout.metadata["closed_loop"]["path"] == ("compiled" if compiled else "python")
        held.append(controller.last_signals)
    core, python = held
    assert core.time_s == python.time_s == pytest.approx(0.2, abs=1e-12)
    for name in ("force_desired_world_N", "rpy_desired", "e_x", "xi_zeta", "eps_x", "tau"):
        np.testing.assert_allclose(
            getattr(core, name), getattr(python, name), rtol=0, atol=1e-9, err_msg=name
        )
    # a desired force and attitude that differ, so that swapping them shows
    assert np.max(np.abs(core.force_desired_world_N - core.rpy_desired)) > 0.1
    last = {k: v[-1] for k, v in rollout.signals.items()}
    np.testing.assert_allclose(
        core.force_desired_world_N, last["force_desired_world_N"], atol=1e-12
    )
    np.testing.assert_allclose(core.rpy_desired, last["rpy_desired"], atol=1e-12)


def _loop_after(path, overrides, compiled):
    """The `ClosedLoop` after running ``path`` (compiled or in Python): (loop, rollout)."""
    scenario = load_scenario(path, {"scenario.duration_s": 1.0, **overrides})
    settings = scenario.settings
    loop = ClosedLoop(
        scenario.plant, settings, scenario.controller_factory(scenario.uvms), compiled=compiled
    )
    sensors = SensorSuite(
        scenario.uvms.model, scenario.sensor_config, settings.duration_s, settings.seed
    )
    try:
        rollout = loop.run(scenario.q0, scenario.v0, sensors, RolloutLog(scenario.uvms, 8, {}))
    except FunnelViolation as exc:
        rollout = exc.rollout
    assert rollout.metadata["closed_loop"]["path"] == ("compiled" if compiled else "python")
    return loop, rollout


@pytest.mark.parametrize(
    "path, overrides, time_s",
    [(REALISTIC, {"scenario.duration_s": 0.3}, 0.3), (PAPER, PAPER_SAMPLED, 93 * 0.002)],
    ids=["whole-run", "funnel-stop"],
)
def test_after_either_loop_its_time_and_state_are_the_last_ticks(path, overrides, time_s):
    """The loop's clock and state after a run (what a script driving `ClosedLoop` reads
    next): the last tick's, the compiled loop's as the Python loop's; after a whole run the
    rollout's last row (no step after the last tick), after a stop the violating tick's."""
    (core, core_rollout), (python, _) = (_loop_after(path, overrides, c) for c in (True, False))
    assert core.time_s == python.time_s == pytest.approx(time_s, abs=1e-12)
    for name in ("q", "v"):
        scale = max(1.0, float(np.max(np.abs(getattr(python, name)))))
        np.testing.assert_allclose(
            getattr(core, name), getattr(python, name), rtol=0, atol=1e-12 * scale
        )
    if core_rollout.status.ok:
        assert core_rollout.time_s[-1] == pytest.approx(core.time_s, abs=1e-12)
        np.testing.assert_array_equal(core_rollout.q[-1], core.q)
