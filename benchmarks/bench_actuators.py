"""Cost per control tick of the actuators and sensors that run in Python, as a ratio to the
compiled plant's advance over one control period (the realistic scenario: 2 ms, RK4).

    .venv/bin/python benchmarks/bench_actuators.py [--repeat N]

Cases, each the `Actuation.apply` (or the navigation sensors' update) of one tick:
``direct`` (the default linear thrusters: allocation and limits), ``quadratic + lag + rate``
and ``T200 + lag`` (four thruster drives), ``joint lag`` (four joint torque lags), and
``navigation`` (IMU, depth, DVL, USBL). CPU time, best of ``--repeat`` rounds (`timing.py`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from timing import best_times, one_blas_thread

from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.navigation.dvl import DvlSpec
from uvms_pin.sim.navigation.imu import ImuSpec
from uvms_pin.sim.navigation.suite import NavigationSpec, NavigationSuite
from uvms_pin.sim.navigation.usbl import UsblSpec
from uvms_pin.sim.system import System

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "realistic_force_tracking.toml"
POSITIONS = [[-0.29, 0.09, -0.03], [-0.29, -0.09, -0.03], [0.03, 0.0, -0.03], [0.03, 0.0, 0.0]]
DIRECTIONS = [[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]


def _thrusters(**keys) -> list[dict]:
    return [
        {"position_body_m": p, "direction_body": d, **keys}
        for p, d in zip(POSITIONS, DIRECTIONS, strict=True)
    ]


CASES = {
    "direct": {},
    "quadratic + lag + rate": {
        "actuation.thruster": _thrusters(
            curve="quadratic", max_forward_N=21.6, max_reverse_N=15.0, deadband=0.05,
            time_constant_s=0.05, rate_limit_N_s=200.0,
        )
    },
    "T200 + lag": {"actuation.thruster": _thrusters(curve="t200_16v", time_constant_s=0.05)},
    "joint lag": {"joints.torque_time_constant_s": [0.01] * 4},
}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=20)
    args = parser.parse_args()
    one_blas_thread()
    tau = np.r_[5.0, 2.0, 3.0, 0.0, 0.0, 1.0, np.zeros(4)]
    calls = {}
    for name, overrides in CASES.items():
        actuation = load_scenario(
            SCENARIO, {"scenario.duration_s": 1.0, **overrides}
        ).plant.actuation
        actuation.start(0.002)
        calls[name] = lambda a=actuation: a.apply(tau)
    scenario = load_scenario(SCENARIO, {"scenario.duration_s": 1.0})
    nav = NavigationSuite(
        NavigationSpec(ImuSpec(1e-3, 1e-5, 1e-2, 1e-4), 50.0, DvlSpec(0.01), UsblSpec(0.1), 30.0), 1
    )
    nav.start(0.002)
    clock = iter(range(10**9))
    q, v = scenario.q0, np.full(scenario.plant.uvms.nv, 0.1)
    calls["navigation"] = lambda: nav.update(next(clock) * 0.002, q, v)
    plant, integrator = scenario.plant, scenario.settings.integrator
    system = System(plant)
    system.start(system.initial_state(scenario.q0, scenario.v0))
    calls["plant advance"] = lambda: system.advance(integrator, 0.0, q, scenario.v0, tau, 0.002)
    best = best_times(calls, args.repeat)
    for name, seconds in best.items():
        ratio = seconds / best["plant advance"]
        print(f"{name:24s} {seconds * 1e6:8.1f} us  {ratio:5.2f} x the plant's period")


if __name__ == "__main__":
    main()
