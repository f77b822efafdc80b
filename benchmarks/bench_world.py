"""Cost of the world's contacts: the plant over one control period with a seafloor and three
objects, nothing touching and four contacts, as a ratio to the contact-free plant.

    .venv/bin/python benchmarks/bench_world.py [--repeat N] [--json FILE]

The plant advances over one 2 ms control period (RK4 at 0.5 ms: 4 steps, 16 right-hand
sides), compiled core, for the reference UVMS (models/uvms_lbv150.urdf) and its vehicle
alone (models/lbv150.urdf). Rows, each as a ratio to the same model without a world:

- contact-free: no world (the UVMS: joint stops on, inside their range);
- world, nothing near: a seafloor 5 m below and a box, a sphere and a pipe metres away:
  each period costs one compiled bound test, then the same compiled call;
- world, 4 contacts: the vehicle resting on the seafloor on the four bottom corners of its
  hull box: the contacts are compiled too (coal's C++ API), the period one compiled call
  (the UVMS's arm hangs below its hull, so the vehicle alone rests on four corners);
- the same on the Python reference (``backend="python"``: contacts through coal's Python
  bindings, the Python dynamics), for scale.

Each row is also given as a multiple of one ``pin.aba`` on the same model (rigid, no
water), timed in the same rounds.

CPU time of this process, best of interleaved rounds, one BLAS thread (`timing.py`).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pinocchio as pin
from timing import best_times, one_blas_thread

import uvms_pin as up
from uvms_pin.physics.joint_stops import JointStops
from uvms_pin.physics.world.objects import plane, solid
from uvms_pin.physics.world.world import World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

ROOT = Path(__file__).resolve().parents[1]
PERIOD_S, STEP_S = 2e-3, 5e-4
ABA = "pin.aba"


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


def resting_floor_z(uvms: up.UVMS, q: np.ndarray) -> float:
    """A floor 2 mm above the lowest corner of the vehicle's hull at q."""
    probe = World(uvms, objects(-100.0))
    hull = next(p for p in probe.pieces if p.joint_id == 1 and p.corners_m is not None)
    return (
        float(q[2] + (hull.placement_in_joint.translation + hull.corners_m.min(axis=0))[2]) + 2e-3
    )


def cases() -> tuple[dict, dict]:
    """(name -> one control period, what the rows are)."""
    table, info = {}, {}
    for label, model in (("UVMS", "uvms_lbv150.urdf"), ("vehicle", "lbv150.urdf")):
        uvms = up.load_uvms(ROOT / "models" / model)
        stops = JointStops.of_model(uvms.model) if uvms.n_arm_joints else None
        q = uvms.neutral_configuration()
        q[:3] = [0.0, 0.0, -5.0]
        bare = Plant(uvms, joint_stops=stops, free_surface=False)
        far = World(uvms, objects(-10.0))
        rows = {f"{label}: contact-free": bare}
        rows[f"{label}: world, nothing near"] = Plant(
            uvms, joint_stops=stops, free_surface=False, world=far
        )
        if label == "vehicle":  # the UVMS's arm hangs below its hull: it rests on the hull
            resting = Plant(
                uvms, free_surface=False, world=World(uvms, objects(resting_floor_z(uvms, q)))
            )
            contacts = len(resting.world_forces(q, np.zeros(uvms.nv)).touch)
            rows[f"{label}: world, {contacts} contacts"] = resting
            rows[f"{label}: world, {contacts} contacts (Python reference)"] = Plant(
                uvms, free_surface=False, world=resting.world, backend="python"
            )
            info["contacts"] = contacts
        for name, plant in rows.items():
            plant.attach(q)
            table[name] = _period(plant, q)
        table[f"{label}: {ABA}"] = _aba(uvms, q)
    return table, info


def _aba(uvms: up.UVMS, q: np.ndarray):
    model = uvms.model
    data, v = model.createData(), np.zeros(model.nv)
    return lambda: pin.aba(model, data, q, v, v)


def _period(plant: Plant, q: np.ndarray):
    v, tau = np.zeros(plant.uvms.nv), np.zeros(plant.uvms.nv)
    integrator, system = RK4(STEP_S), System(plant)
    return lambda: system.advance(integrator, 0.0, q, v, tau, PERIOD_S)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    with one_blas_thread():
        table, info = cases()
        best = best_times(table, args.repeat)
    print(
        "| plant over one 2 ms period | time [us] | / contact-free | x pin.aba |\n|---|---|---|---|"
    )
    rows = {}
    for name, seconds in best.items():
        model = name.split(":")[0]
        if name == f"{model}: {ABA}":
            continue
        base, aba = best[f"{model}: contact-free"], best[f"{model}: {ABA}"]
        rows[name] = {"s": seconds, "ratio": seconds / base, "aba": seconds / aba}
        print(f"| {name} | {seconds * 1e6:.0f} | {seconds / base:.2f} | {seconds / aba:.0f} |")
    if args.json:
        args.json.write_text(json.dumps({**info, "rows": rows}, indent=2))


if __name__ == "__main__":
    main()
