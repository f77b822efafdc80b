"""Cost of several robots: one control period of N = 1, 2, 4 robots in one sea, as a ratio to
one robot in the same loop (target: at most 1.2 N).

    .venv/bin/python benchmarks/bench_robots.py [--repeat N] [--json FILE]

Every robot is scenarios/two_robots.toml's "bravo" (a BlueROV2 Heavy + Reach Alpha 5 drawing
its end-effector circle with the task-priority controller, its eight thrusters allocated,
its sensors' noise), the robots 3 m apart in a row. A period is what the robots' loop does
each 10 ms tick (`uvms_pin.sim.robots_loop.RobotsLoop`): every robot measures, commands and
actuates, then the robots' system crosses the period (RK4 at 2.5 ms, each robot's compiled
period step while no two robots can touch, the bound test of every pair first). For scale,
the single robot's own sampled loop in Python (`ClosedLoop`, ``compiled_loop=False``) over
the same period.

CPU time of this process, best of interleaved rounds, one BLAS thread (`timing.py`).
"""

from __future__ import annotations

import argparse
import copy
import json
from pathlib import Path

from timing import best_times, one_blas_thread

from uvms_pin.errors import ScenarioError
from uvms_pin.scenario.load import scenario_from_dict
from uvms_pin.scenario.toml import read_toml
from uvms_pin.sim.closed_loop import ClosedLoop
from uvms_pin.sim.robots_loop import RobotsLoop
from uvms_pin.sim.run import run_parts

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "two_robots.toml"
COUNTS = (1, 2, 4)
BASE = "1 robot"


def robots(n: int):
    """The scenario of ``n`` copies of "bravo", 3 m apart along y."""
    doc = read_toml(SCENARIO, ScenarioError)
    bravo = doc["robots"][1]
    doc["robots"] = []
    for k in range(n):
        entry = copy.deepcopy(bravo)
        entry["name"] = f"bravo{k}"
        entry["initial"]["position_world_m"] = [0.0, 3.0 * k, -2.0]
        doc["robots"].append(entry)
    return scenario_from_dict(doc, SCENARIO)


def robots_period(n: int):
    """One period of ``n`` robots' loop, called again and again along its run."""
    scenario = robots(n)
    parts = [run_parts(r) for r in scenario.robots]
    loop = RobotsLoop(
        [r.plant for r in scenario.robots], scenario.names, scenario.settings, [p[0] for p in parts]
    )
    loop.start([(r.q0, r.v0) for r in scenario.robots], [p[1] for p in parts])
    return lambda: loop.step(loop.tick(False))


def single_period():
    """One period of the single robot's own sampled loop in Python."""
    robot = robots(1).robots[0]
    controller, sensors, _ = run_parts(robot)
    loop = ClosedLoop(robot.plant, robot.settings, controller, compiled=False)
    loop.start(robot.q0, robot.v0, sensors)

    def call():
        measurement, _ = loop.observe()
        loop.step(loop.actuate(loop.command(measurement)))

    return call


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    with one_blas_thread():
        table = {f"{n} robot{'s' if n > 1 else ''}": robots_period(n) for n in COUNTS}
        table["1 robot, its own loop (ClosedLoop, Python)"] = single_period()
        best = best_times(table, args.repeat)
    print("| one 10 ms control period | time [us] | / 1 robot | / (1 robot x N) |")
    print("|---|---|---|---|")
    rows = {}
    for (name, seconds), n in zip(best.items(), [*COUNTS, 1], strict=True):
        ratio = seconds / best[BASE]
        rows[name] = {"s": seconds, "ratio": ratio, "ratio_per_robot": ratio / n}
        print(f"| {name} | {seconds * 1e6:.0f} | {ratio:.2f} | {ratio / n:.2f} |")
    if args.json:
        args.json.write_text(json.dumps({"rows": rows}, indent=2))


if __name__ == "__main__":
    main()
