"""Cost of one control period of scenarios/cooperative_transport.toml (two UVMS holding a bar),
as a ratio to the same period with the reference's Python around the compiled integration.

    .venv/bin/python benchmarks/bench_transport.py [--repeat N] [--json FILE]

A period is what the robots' loop does every 2 ms (`uvms_pin.sim.robots_loop.RobotsLoop`):
every robot measures (its force/torque sensor's wrench on the bar), commands and actuates,
then the robots and the bar cross the period. As run, the period is one core call
(`RobotsSystem.advance`: the integration, every anchor moved at its end, each robot's joint
limits) and the bound test and the sensors' wrenches are the core's; the reference keeps
the compiled integration (`Robots._integrate`) and does the rest in Python
(`Robots.together_reference`, `RobotContacts.near`, `Robots.object_wrenches_reference`), as
every period was before. Also the parts of the compiled period: the core's integration alone
and one tick (both robots' measure, command, actuate). Both loops run 0.2 s from the
scenario's start (the jaws settled on the bar) before they are timed, and go on along their
runs while timed.

CPU time of this process, best of interleaved rounds, one BLAS thread (`timing.py`).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from timing import bench_arguments, best_times, one_blas_thread

from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.compiled.integrator import integrator_to_core
from uvms_pin.sim.robots_loop import RobotsLoop
from uvms_pin.sim.run import run_parts

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "cooperative_transport.toml"
BASE = "period, the reference's Python around the compiled integration"
SETTLE_S = 0.2


def started_loop(reference: bool = False) -> RobotsLoop:
    """The transport's loop, ``SETTLE_S`` into its run; with ``reference``, every period's
    part but the integration by the Python reference."""
    scenario = load_scenario(SCENARIO)
    parts = [run_parts(r) for r in scenario.robots]
    loop = RobotsLoop(
        [r.plant for r in scenario.robots], scenario.names, scenario.settings, [p[0] for p in parts]
    )
    robots = loop.system
    if reference:  # instance attributes: this loop's robots only
        robots.near = lambda q, v, h: robots.contacts.near(
            robots.sides(q, v), lambda: robots._kinematics(q, v), h
        )
        robots._together = robots.together_reference
        robots.object_wrenches = robots.object_wrenches_reference
    loop.start([(r.q0, r.v0) for r in scenario.robots], [p[1] for p in parts])
    for _ in range(round(SETTLE_S / scenario.settings.control_period_s)):
        loop.step(loop.tick(False))
    return loop


def integration(loop: RobotsLoop):
    """The core's integration of the period alone (`RobotsSystem.integrate`) at the loop's
    state, its inputs held."""
    robots = loop.system
    core, _ = robots.compiled
    step = integrator_to_core(loop.settings.integrator, core_module())
    taus = [np.asarray(t, dtype=float) for t in loop.tick(False)]
    q, v = loop.state
    memories = [s.memory for s in robots.contacts.sets]
    period = loop.settings.control_period_s
    return lambda: core.integrate(0.0, q, v, taus, period, step, robots._memories(), memories)


def rows_of(best: dict[str, float], period_s: float) -> dict[str, dict[str, float]]:
    """Each case's time [s], its ratio to the reference's period and period_s / time."""
    return {
        name: {"s": t, "ratio": t / best[BASE], "real_time_factor": period_s / t}
        for name, t in best.items()
    }


def main() -> None:
    args = bench_arguments(__doc__)
    with one_blas_thread():
        compiled, reference = started_loop(), started_loop(reference=True)
        table = {
            "period, as run (one core call)": lambda: compiled.step(compiled.tick(False)),
            BASE: lambda: reference.step(reference.tick(False)),
            "the core's integration alone": integration(compiled),
            "one tick (both robots measure, command, actuate)": lambda: compiled.tick(False),
        }
        rows = rows_of(best_times(table, args.repeat), compiled.settings.control_period_s)
    lines = [
        "| one 2 ms control period | time [us] | / reference | 2 ms / time |",
        "|---|---|---|---|",
    ]
    lines += [
        f"| {name} | {row['s'] * 1e6:.0f} | {row['ratio']:.2f} | {row['real_time_factor']:.2f} |"
        for name, row in rows.items()
    ]
    print("\n".join(lines))
    if args.json:
        args.json.write_text(json.dumps({"rows": rows}, indent=2))


if __name__ == "__main__":
    main()
