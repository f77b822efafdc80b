"""Cost of a free object: the system of bodies over one control period with a box resting on
the seabed, as a ratio to the same plant without it; and the push_object scenario's speed.

    .venv/bin/python benchmarks/bench_free_objects.py [--repeat N] [--json FILE] [--run]

The robot is scenarios/push_object.toml's (a BlueROV2 Heavy with a Reach Alpha 5, its joint
stops on) at its initial state, 25 cm above the seabed, its world the scenario's. Rows, one
2 ms control period each (RK4 at 0.5 ms: 4 steps, 16 right-hand sides), as a ratio to the
first:

- seabed only: the plant in the scenario's world without its free object (the compiled
  plant's one call);
- + a box resting on the seabed: the scenario's box moved 3 m ahead, resting on its four
  bottom corners, its own floating body: the compiled system's one call (the robot, the box,
  the box's contacts with the seabed, the robot's pairs with the box tested by their bounding
  spheres, every anchor);
- + the box by the jaws: the scenario's box where it starts, within the bounding spheres of
  the jaws, nothing touching yet (each sphere tested against the box's hull box first, coal's
  narrow phase only for those that meet it);
- the same integrated by the Python integrator around the compiled dynamics (the reference
  path: contacts through coal's Python bindings), for scale.

``--run`` also runs the whole scenario (12 s simulated, its Python controller called once
per 2 ms period) and gives its real-time factor, simulated time / wall time of the
simulation loop (machine-dependent, unlike the ratios), as shipped (the jaws on the box by
the compliant law) and with ``[world] moving_contact = "rigid"`` (the jaws' contact a
constraint solved with the box's seabed contacts), side by side in this process.

CPU time of this process, best of interleaved rounds, one BLAS thread (`timing.py`).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

import numpy as np
from timing import best_times, one_blas_thread

import uvms_pin as up
from uvms_pin.physics.world.world import World
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "push_object.toml"
PERIOD_S, STEP_S = 2e-3, 5e-4
BASE = "seabed only"


def _without_free_objects(plant: Plant) -> Plant:
    world = plant.world
    return Plant(
        plant.uvms, world=World(plant.uvms, world.objects, world.law), free_surface=False,
        joint_stops=plant.joint_stops, joint_limits=plant.joint_limits,
    )  # fmt: skip


def _period(plant: Plant, q0: np.ndarray, compiled: bool = True):
    """One control period of the system from its state at t = 0 (each call from the same
    state and anchors: the box at rest on its corners)."""
    system = System(plant, compiled=compiled)
    state = system.initial_state(q0, np.zeros(plant.uvms.nv))
    system.start(state)
    memories = [m for m in system.friction_memories() if m is not None] if system.objects else []
    held = [(dict(m.anchors), set(m.slipping), dict(m.material)) for m in memories]
    integrator, tau = RK4(STEP_S), np.zeros(plant.uvms.nv)

    def call():
        for m, (anchors, slipping, material) in zip(memories, held, strict=True):
            m.anchors, m.slipping, m.material = dict(anchors), set(slipping), dict(material)
        return system.advance(integrator, 0.0, state.q, state.v, tau, PERIOD_S)

    return call, system


def _moved(plant: Plant, offset_m: np.ndarray) -> Plant:
    """The plant with its free objects moved by ``offset_m`` (world) [m]."""
    world = plant.world
    free = [dataclasses.replace(o, q0=o.q0 + np.r_[offset_m, np.zeros(4)]) for o in world.free]
    return Plant(
        plant.uvms, world=World(plant.uvms, world.objects, world.law, free), free_surface=False,
        joint_stops=plant.joint_stops, joint_limits=plant.joint_limits,
    )  # fmt: skip


def cases() -> tuple[dict, dict]:
    scenario = load_scenario(SCENARIO)
    plant, q0 = scenario.plant, scenario.q0
    resting = _moved(plant, np.array([3.0, 0.0, 0.0]))
    with_box, system = _period(resting, q0)
    (box,) = system.objects
    (q_r, v_r), *objects = system.layout.split(*system.initial_state(q0, scenario.v0))
    _, fixed = system.moving.found(q_r, v_r, objects)
    table = {
        BASE: _period(_without_free_objects(plant), q0)[0],
        "+ a box resting on the seabed": with_box,
        "+ the box by the jaws": _period(plant, q0)[0],
        "+ a box resting on the seabed (Python integration)": _period(resting, q0, False)[0],
    }
    return table, {"box": box.name, "box_contacts": len(fixed[0].touch)}


def run_scenario(overrides: dict | None = None) -> dict:
    """The whole scenario (with ``overrides``): simulated time / wall time of its simulation
    loop (the rollout's own record of both)."""
    meta = up.simulate(load_scenario(SCENARIO, overrides or {}), progress=False).metadata
    return {
        "simulated_s": float(meta["simulated_time_s"]),
        "wall_s": float(meta["wall_time_s"]),
        "real_time_factor": float(meta["real_time_factor"]),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--json", type=Path)
    parser.add_argument("--run", action="store_true", help="also run the whole scenario")
    args = parser.parse_args()
    with one_blas_thread():
        table, info = cases()
        best = best_times(table, args.repeat)
    print("| system over one 2 ms period | time [us] | / seabed only |\n|---|---|---|")
    rows = {}
    for name, seconds in best.items():
        rows[name] = {"s": seconds, "ratio": seconds / best[BASE]}
        print(f"| {name} | {seconds * 1e6:.0f} | {seconds / best[BASE]:.2f} |")
    out = {**info, "rows": rows}
    if args.run:
        runs = {"push_object": {}, "push_object (rigid jaws)": {"world.moving_contact": "rigid"}}
        for name, overrides in runs.items():
            out[name] = run_scenario(overrides)
            print(
                f"{name}: "
                "{simulated_s:.1f} s simulated in {wall_s:.2f} s of wall time, "
                "{real_time_factor:.1f}x real time".format(**out[name])
            )
    if args.json:
        args.json.write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
