"""Cost of the world's contacts: the plant over one control period with a seafloor and three
objects, nothing touching and four contacts, as a ratio to the contact-free plant.

    .venv/bin/python benchmarks/bench_world.py [--repeat N] [--json FILE]

The reference UVMS (models/uvms_lbv150.urdf) advances over one 2 ms control period (RK4 at
0.5 ms: 4 steps, 16 right-hand sides), compiled core. Rows:

- contact-free: no world (joint stops on, inside their range);
- world, far: a seafloor 5 m below and a box, a sphere and a rock-sized cylinder metres
  away: each period costs one bound test, then the same compiled call;
- world, four contacts: the vehicle resting on the seafloor on the four bottom corners of
  its hull box (the period is integrated in Python around the compiled dynamics).

CPU time of this process, best of interleaved rounds, one BLAS thread (`timing.py`).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from timing import best_times, one_blas_thread

import uvms_pin as up
from uvms_pin.physics.joint_stops import JointStops
from uvms_pin.physics.world.objects import plane, solid
from uvms_pin.physics.world.world import World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
PERIOD_S, STEP_S = 2e-3, 5e-4


def objects(floor_z: float) -> list:
    return [
        plane("seafloor", [0.0, 0.0, floor_z], [0.0, 0.0, 1.0], 0.6, 0.5),
        solid(
            "crate", "box", {"size_m": [1, 1, 1]}, [4.0, 0.0, floor_z + 0.5], [0, 0, 0], 0.6, 0.5
        ),
        solid("boulder", "sphere", {"radius_m": 0.6}, [-4.0, 2.0, floor_z], [0, 0, 0], 0.6, 0.5),
        solid(
            "pipe",
            "cylinder",
            {"radius_m": 0.3, "length_m": 6.0},
            [0.0, 4.0, floor_z + 0.3],
            [0.0, 1.5708, 0.0],
            0.6,
            0.5,
        ),
    ]


def cases() -> tuple[dict, dict]:
    uvms = up.load_uvms(ROOT / "models" / "uvms_lbv150.urdf")
    stops = JointStops.of_model(uvms.model)
    q = uvms.neutral_configuration()
    q[:3] = [0.0, 0.0, -5.0]
    tau = np.zeros(uvms.nv)
    integrator = RK4(STEP_S)
    bare = Plant(uvms, joint_stops=stops, free_surface=False)
    far = Plant(uvms, joint_stops=stops, free_surface=False, world=World(uvms, objects(-10.0)))
    # resting: the hull's bottom face 2 mm into a floor just under it
    probe = World(uvms, objects(-100.0))
    lowest = min(
        float(q[2] + (p.placement_in_joint.translation + p.corners_m.min(axis=0))[2])
        for p in probe.pieces
        if p.joint_id == 1 and p.corners_m is not None
    )
    touching = Plant(
        uvms, joint_stops=stops, free_surface=False, world=World(uvms, objects(lowest + 0.002))
    )
    contacts = len(touching.world_forces(q, np.zeros(uvms.nv)).touch)
    plants = {"contact-free": bare, "world, far": far, f"world, {contacts} contacts": touching}
    for plant in plants.values():
        plant.attach(q)
    v = np.zeros(uvms.nv)

    def period(plant):
        return lambda: plant.advance(integrator, 0.0, q, v, tau, PERIOD_S)

    return {name: period(p) for name, p in plants.items()}, {"contacts": contacts}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    with one_blas_thread():
        table, info = cases()
        best = best_times(table, args.repeat)
    base = best["contact-free"]
    print("| plant over one 2 ms period | time [us] | / contact-free |\n|---|---|---|")
    for name, seconds in best.items():
        print(f"| {name} | {seconds * 1e6:.0f} | {seconds / base:.2f} |")
    if args.json:
        rows = {name: {"s": s, "ratio": s / base} for name, s in best.items()}
        args.json.write_text(json.dumps({**info, "rows": rows}, indent=2))


if __name__ == "__main__":
    main()
