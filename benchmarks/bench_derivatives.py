"""Cost of the derivatives of the underwater forward dynamics, as ratios to ``pin.aba``.

    .venv/bin/python benchmarks/bench_derivatives.py [--repeat N] [--out out/bench/derivatives.md]

On the reference model in a 0.3 m/s current, every figure is a best-of-``repeat`` CPU time
measured in this process (`timing.py`, one BLAS thread) divided by one rigid-body
``pin.aba`` call timed in the same run:

- Pinocchio's own rigid-body derivatives (``pin.computeABADerivatives``, no water);
- ``up.forward_dynamics_derivatives`` (analytical, added mass, C_A, damping, buoyancy and
  the current), compiled and Python reference, and the compiled call alone (the core's
  ``Derivatives`` object without the Python argument checks);
- the same Jacobians by central finite differences of the compiled forward dynamics
  (2 (2 nv) + ... calls; what a user without the derivatives would do);
- MuJoCo's ``mjd_transitionFD`` on the MuJoCo twin (benchmarks/bench_mujoco.py): the
  discrete-transition Jacobians by finite differences, Euler and implicitfast, centred.
  MuJoCo's fluid model has no added-mass acceleration term: the job differs, the cost is
  what a MuJoCo user pays for the Jacobians of one step.
- ``up.forward_dynamics_derivatives`` called with ``current_world=`` (the README's way) as
  with ``flow=``;
- the Jacobians of one 20 ms control period of the plant's RK4 (two substeps, eight
  stages: ``up.step_derivatives(..., integrator="rk4")``), compiled and Python reference.

A second table gives ``up.forward_dynamics_derivatives_batch`` over ``BATCH_STATES`` states
per call, per state, on one and two threads: wall time (``time.perf_counter``, best of the
rounds; threads share the work, so CPU time would hide the gain) over the same ``pin.aba``.

A third table times one re-plan of the MPC controller (`uvms_pin.control.mpc`, station
keeping in the current with the BlueROV2 Heavy's eight bounded thrusters, a 1 s horizon of
50 nodes, 50 Hz and 100 Hz, warm-started BoxFDDP) and gives its real-time factor (the
period over the CPU time of a re-plan; > 1: faster than real time on one core); and of the
force-task MPC of scenarios/mpc_force_tracking.toml (the LBV150's four thrusters, the spring
in every node's dynamics and its derivatives, the same horizon, 50 Hz) from the scenario's
start. Each on the compiled planner (the default: `uvms_pin.ocp.compiled`) and on the
Python one (crocoddyl calling the Python nodes, which call the compiled dynamics).
"""

from __future__ import annotations

import argparse
import itertools
import time
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
from bench_mujoco import CURRENT_WORLD_M_S, reference_system
from timing import best_times, one_blas_thread

import uvms_pin as up
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.dynamics import dynamics_of

ROOT = Path(__file__).resolve().parents[1]


def central_differences(uvms: up.UVMS, q, v, tau, step: float = 1e-6):
    """da/dq, da/dv, da/dtau by central differences of the compiled forward dynamics."""
    fd = dynamics_of(uvms).core.forward_dynamics
    nv, model = uvms.nv, uvms.model
    out = np.empty((nv, 3 * nv))
    for k in range(nv):
        e = np.zeros(nv)
        e[k] = step
        qp, qm = pin.integrate(model, q, e), pin.integrate(model, q, -e)
        out[:, k] = fd(qp, v, tau, CURRENT_WORLD_M_S) - fd(qm, v, tau, CURRENT_WORLD_M_S)
        out[:, nv + k] = fd(q, v + e, tau, CURRENT_WORLD_M_S) - fd(q, v - e, tau, CURRENT_WORLD_M_S)
        out[:, 2 * nv + k] = fd(q, v, tau + e, CURRENT_WORLD_M_S) - fd(
            q, v, tau - e, CURRENT_WORLD_M_S
        )
    return out / (2 * step)


def mujoco_transition_case(system, integrator: int):
    """mjd_transitionFD (centred) of one step of the twin with ``integrator``."""
    model = system.mj_model
    model.opt.integrator = integrator
    data = mujoco.MjData(model)
    from uvms_pin.apps.export.mujoco_state import qpos_from_q, qvel_from_v

    data.qpos[:] = qpos_from_q(system.q0)
    data.qvel[:] = qvel_from_v(system.q0, system.v0)
    mujoco.mj_forward(model, data)
    nx, nu = 2 * model.nv + model.na, model.nu
    a, b = np.zeros((nx, nx)), np.zeros((nx, nu))
    return lambda: mujoco.mjd_transitionFD(model, data, 1e-6, 1, a, b, None, None)


def cases_of(system) -> dict[str, object]:
    uvms, q, v = system.uvms, system.q0, system.v0
    tau = np.random.default_rng(1).normal(size=uvms.nv)
    model, data = uvms.model, uvms.model.createData()
    current = up.flow.UniformCurrent(CURRENT_WORLD_M_S)
    derivatives = core_module().Derivatives(dynamics_of(uvms).core)
    flow_struct = core_module().FlowField()
    flow_struct.current_world_m_s = CURRENT_WORLD_M_S
    cases = {
        "pin.aba (rigid, the unit)": lambda: pin.aba(model, data, q, v, tau),
        "pin.computeABADerivatives (rigid)": lambda: pin.computeABADerivatives(
            model, data, q, v, tau
        ),
        "core forward_dynamics (current)": lambda: up.forward_dynamics(
            uvms, q, v, tau, CURRENT_WORLD_M_S
        ),
        "core forward_dynamics_derivatives (current)": lambda: up.forward_dynamics_derivatives(
            uvms, q, v, tau, flow=current
        ),
        "core forward_dynamics_derivatives (current_world=)": (
            lambda: up.forward_dynamics_derivatives(
                uvms, q, v, tau, current_world=CURRENT_WORLD_M_S
            )
        ),
        "core Derivatives object alone (current)": lambda: derivatives.forward_dynamics_derivatives(
            q, v, tau, flow_struct, 0.0
        ),
        "python forward_dynamics_derivatives (current)": lambda: up.forward_dynamics_derivatives(
            uvms, q, v, tau, flow=current, backend="python"
        ),
        "central differences of core forward_dynamics": lambda: central_differences(
            uvms, q, v, tau
        ),
    }
    # one 20 ms control period of the plant's RK4 (two 10 ms substeps, 8 stages), tau held
    period = {"integrator": "rk4", "step_s": 0.01, "current_world": CURRENT_WORLD_M_S}
    cases["core step_derivatives, RK4 period (2 x 10 ms)"] = lambda: up.step_derivatives(
        uvms, q, v, tau, 0.02, **period
    )
    cases["python step_derivatives, RK4 period (2 x 10 ms)"] = lambda: up.step_derivatives(
        uvms, q, v, tau, 0.02, backend="python", **period
    )
    for name, integrator in (
        ("Euler", mujoco.mjtIntegrator.mjINT_EULER),
        ("implicitfast", mujoco.mjtIntegrator.mjINT_IMPLICITFAST),
    ):
        cases[f"MuJoCo mjd_transitionFD ({name}, centred)"] = mujoco_transition_case(
            system, integrator
        )
    return cases


#: the MPC's planners: "core" (the compiled OCP, crocoddyl's C++ FDDP on the compiled
#: nodes) and "python" (crocoddyl calling uvms_pin.ocp's Python nodes, which call the core)
PLANNERS = ("core", "python")


def mpc_cases(system) -> dict[str, tuple[object, float]]:
    """One warm-started re-plan of a station-keeping MPC per call, at 1 and 3 iterations on
    both planners, and at 100 Hz (the period 10 ms) on the compiled one: name -> (call,
    period [s])."""
    import pinocchio as pin_

    from uvms_pin.control.measurement import Measurement
    from uvms_pin.control.mpc import MpcController
    from uvms_pin.model.vehicles import bluerov2_heavy
    from uvms_pin.ocp.problems import Actuators

    uvms, q0 = system.uvms, system.q0.copy()
    thrusters = bluerov2_heavy.thrusters()
    effort = uvms.model.effortLimit[6:]
    bounds = (
        np.r_[[-t.max_reverse_N for t in thrusters], -effort],
        np.r_[[t.max_forward_N for t in thrusters], effort],
    )
    actuators = Actuators(up.input_matrix(thrusters, uvms.nv), bounds)
    measurement = Measurement(0.0, q0, system.v0, np.zeros(6))
    settings = [(planner, n, 50.0) for planner in PLANNERS for n in (1, 3)]
    settings.append(("core", 1, 100.0))
    cases = {}
    for planner, iterations, rate_hz in settings:
        controller = MpcController(
            uvms,
            task="station",
            target=pin_.SE3(np.eye(3), q0[:3].copy()),
            posture=q0,
            horizon_s=1.0,
            dt_s=0.02,
            rate_hz=rate_hz,
            iterations=iterations,
            actuators=actuators,
            flow=up.flow.UniformCurrent(CURRENT_WORLD_M_S),
            planner=planner,
        )
        clock = itertools.count()
        period = 1.0 / rate_hz
        name = f"station, {iterations} iteration(s), {rate_hz:.0f} Hz, {planner} planner"
        cases[name] = (
            lambda c=controller, k=clock, p=period: c.compute(p * next(k), measurement),
            period,
        )
    return cases


def mpc_force_cases() -> dict[str, tuple[object, float]]:
    """One warm-started re-plan of scenarios/mpc_force_tracking.toml's MPC per call, at 1
    and 3 iterations on both planners, from the scenario's initial state (the desired force
    0.4 N away): name -> (call, period [s])."""
    from uvms_pin.control.measurement import Measurement
    from uvms_pin.scenario.load import load_scenario

    cases = {}
    for planner in PLANNERS:
        for iterations in (1, 3):
            scenario = load_scenario(
                ROOT / "scenarios" / "mpc_force_tracking.toml",
                {"controller.iterations": iterations, "controller.planner": planner},
            )
            controller = scenario.controller_factory(scenario.plant.uvms)
            measurement = Measurement(0.0, scenario.q0, scenario.v0, np.zeros(6))
            clock = itertools.count()
            name = f"force task, {iterations} iteration(s), 50 Hz, {planner} planner"
            cases[name] = (
                lambda c=controller, k=clock, m=measurement: c.compute(0.02 * next(k), m),
                0.02,
            )
    return cases


#: states per batched call (`batch_table`)
BATCH_STATES = 256


def batch_table(system, unit_s: float, repeat: int) -> str:
    """Wall time per state of the batched derivatives on 1 and 2 threads, x pin.aba."""
    uvms = system.uvms
    rng = np.random.default_rng(2)
    q = np.tile(system.q0, (BATCH_STATES, 1))
    q[:, 7:] += rng.uniform(-0.3, 0.3, (BATCH_STATES, uvms.nv - 6))  # the arm's joints
    v = rng.normal(scale=0.2, size=(BATCH_STATES, uvms.nv))
    tau = rng.normal(size=(BATCH_STATES, uvms.nv))
    per_state = {}
    for threads in (1, 2):

        def call(n=threads):
            up.forward_dynamics_derivatives_batch(
                uvms, q, v, tau, current_world=CURRENT_WORLD_M_S, num_threads=n
            )

        call()
        rounds = []
        for _ in range(repeat):
            start = time.perf_counter()
            call()
            rounds.append(time.perf_counter() - start)
        per_state[threads] = min(rounds) / BATCH_STATES
    rows = [
        f"| batched derivatives ({BATCH_STATES} states per call, current) | x pin.aba per state |",
        "|---|---:|",
    ]
    rows += [f"| {n} thread(s) (wall) | {t / unit_s:.1f} |" for n, t in per_state.items()]
    rows.append(f"| speed-up on 2 threads | {per_state[1] / per_state[2]:.2f}x |")
    return "\n".join(rows) + "\n"


def mpc_table(times: dict[str, float], periods: dict[str, float], unit: float) -> str:
    rows = [
        "| MPC re-plan (1 s horizon, 50 nodes, warm) | x pin.aba | real-time factor |",
        "|---|---:|---:|",
    ]
    rows += [f"| {name} | {t / unit:.0f} | {periods[name] / t:.1f} |" for name, t in times.items()]
    return "\n".join(rows) + "\n"


def table(times: dict[str, float]) -> str:
    unit = times["pin.aba (rigid, the unit)"]
    rows = ["| call | x pin.aba |", "|---|---:|"]
    rows += [f"| {name} | {t / unit:.1f} |" for name, t in times.items()]
    return "\n".join(rows) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=30)
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "bench" / "derivatives.md")
    args = parser.parse_args()
    with one_blas_thread():
        system = reference_system()
        times = best_times(cases_of(system), args.repeat)
        cases = {**mpc_cases(system), **mpc_force_cases()}
        # one re-plan per sample (3-80 ms): a third of the rounds, at least 5
        calls = {name: call for name, (call, _) in cases.items()}
        mpc = best_times(calls, max(5, args.repeat // 3), batch_s=0.0)
        unit = times["pin.aba (rigid, the unit)"]
        batch = batch_table(system, unit, args.repeat)
    text = (
        table(times)
        + "\n"
        + batch
        + "\n"
        + mpc_table(mpc, {name: period for name, (_, period) in cases.items()}, unit)
    )
    print(text)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)


if __name__ == "__main__":
    main()
