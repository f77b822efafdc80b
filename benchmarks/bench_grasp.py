"""Cost of a grasp on rigid contacts: one control period of a parallel jaw holding a block by
friction, four contact points solved as constraints with the jaw's joint limits, as a ratio
to the same plant without the block (nothing touching).

    .venv/bin/python benchmarks/bench_grasp.py [--repeat N] [--json FILE]

The jaw is the grasp tests' (tests/jaw_helpers.py: a heavy neutrally buoyant hull, two
prismatic fingers closed by a force-limited servo) with each finger's pad split in two
boxes side by side, so that a block between the pads touches at four points (coal gives one
point a pair of pieces). The block, 3 x 4 x 3 cm, 20 % denser than water, is closed on for
0.4 s from 2 mm off the pads (`[world] moving_contact = "rigid"`), then held: the timed
period starts from that state, its contacts and the jaw's limits solved in the compiled
system's one call. Rows, one 1 ms period each (RK4 at 0.25 ms), as a ratio to the first:

- the jaw alone: the compiled plant without a world;
- + the grasped block (rigid contacts): the compiled system (the jaw, the block, the four
  contacts and the limits in one coupled solve);
- + the grasped block (compliant contacts): the same with the contact law's springs, for
  scale.

- MuJoCo on the same grasp: the jaw's MJCF twin (`uvms_pin.apps.export.mjcf`) with the block
  and its contacts, settled 0.4 s in MuJoCo from uvms-pin's held state, each finger closed
  by a 2 N motor; one 1 ms period as RK4 at 0.25 ms (uvms-pin's steps) and as MuJoCo's usual
  single semi-implicit Euler step. Its soft contacts and pyramidal cones differ from the
  rigid Coulomb cones here; the info line gives the block's slip over 0.5 s held, to show
  both hold it.

CPU time of this process, best of interleaved rounds, one BLAS thread (`timing.py`).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
from bench_mujoco import robot_touching
from timing import best_times, one_blas_thread

import uvms_pin as up
from uvms_pin.apps.export.mjcf import MjcfOptions, uvms_to_mjcf
from uvms_pin.apps.export.mujoco_state import qpos_from_q
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from jaw_helpers import FINGER_Z_M, PAD_M, parallel_jaw_urdf  # noqa: E402

PERIOD_S, STEP_S = 1e-3, 2.5e-4
BASE = "the jaw alone"
RIGID = "+ the grasped block (rigid contacts)"
BLOCK_M = (0.03, 0.04, 0.03)
#: the MuJoCo twins of the grasp: RK4 at uvms-pin's 0.25 ms step, and MuJoCo's own usual
#: setting, one semi-implicit Euler step a 1 ms period
MUJOCO_TWINS = {
    "MuJoCo, the grasp (RK4, 4 x 0.25 ms)": MjcfOptions(timestep_s=STEP_S, integrator="RK4"),
    "MuJoCo, the grasp (Euler, 1 x 1 ms)": MjcfOptions(timestep_s=PERIOD_S, integrator="Euler"),
}
_HELD_BLOCK: list = [None]  # the block's pose in uvms-pin's held grasp (set by `_held`)


def _split_pads(path: Path) -> Path:
    """The jaw with each finger's pad as two boxes side by side along x (four points)."""
    text = path.read_text()
    half = PAD_M[0] / 2
    pad = f'<geometry><box size="{PAD_M[0]} {PAD_M[1]} {PAD_M[2]}"/></geometry>'
    two = f'<geometry><box size="{half} {PAD_M[1]} {PAD_M[2]}"/></geometry>'
    for sign in (1.0, -1.0):
        y, z = sign * PAD_M[1] / 2, -PAD_M[2] / 2
        whole = f'<collision><origin xyz="0 {y} {z}" rpy="0 0 0"/>{pad}</collision>'
        split = "".join(
            f'<collision><origin xyz="{x} {y} {z}" rpy="0 0 0"/>{two}</collision>'
            for x in (-half / 2, half / 2)
        )
        assert whole in text
        text = text.replace(whole, split)
    path.write_text(text)
    return path


def _scenario(folder: Path, contact: str):
    model = _split_pads(parallel_jaw_urdf(folder))
    volume = BLOCK_M[0] * BLOCK_M[1] * BLOCK_M[2]
    data = {
        "scenario": {"name": "grasp", "model": str(model), "duration_s": 0.4},
        "water": {"free_surface": False},
        "initial": {"position_world_m": [0.0, 0.0, -5.0], "joint_positions_rad": [0.012, 0.012]},
        "world": {
            "moving_contact": contact,
            # the stick spring's damper within the step's reach on a finger of 7 g (the
            # law's 200 N s/m is refused at 0.25 ms: its rate leaves RK4's region)
            "contact": {"tangential_damping_N_s_m": 20.0},
            "objects": [
                {
                    "type": "box",
                    "name": "block",
                    "size_m": list(BLOCK_M),
                    "position_world_m": [0.0, 0.0, -5.0 + FINGER_Z_M - 0.04],
                    "mass_kg": 1.2 * 1025.0 * volume,
                    "friction_static": 0.8,
                    "friction_kinetic": 0.8,
                }
            ],
        },
        "gripper": {"max_force_N": 2.0},
        "control": {"period_s": PERIOD_S},
        "integrator": {"method": "rk4", "step_s": STEP_S},
        "output": {"log_period_s": 0.01},
    }
    return up.scenario_from_dict(data, folder / "grasp.toml")


def _held(folder: Path, contact: str):
    """(one period of the grasp from its held state, the number of contact points)."""
    scenario = _scenario(folder, contact)
    rollout = up.simulate(scenario, progress=False)
    system = System(scenario.plant)
    state = system.initial_state(scenario.q0, scenario.v0)
    system.start(state)
    q, v = rollout.q[-1], rollout.v[-1]
    objects = np.asarray(rollout.signals["free_objects"][-1])
    q_s, v_s = np.r_[q, objects[:7]], np.r_[v, objects[7:]]
    tau = np.zeros(scenario.uvms.nv)
    tau[6:] = -2.0  # the servo's grip, each finger closing
    integrator = RK4(STEP_S)
    for k in range(20):  # its friction memories and forces settle
        q_s, v_s = system.advance(integrator, k * PERIOD_S, q_s, v_s, tau, (k + 1) * PERIOD_S)
    _HELD_BLOCK[:] = [q_s[scenario.uvms.nq : scenario.uvms.nq + 7].copy()]
    sets, _ = system.moving.found(*system.robot_state(q_s, v_s), system.layout.split(q_s, v_s)[1:])
    points = sum(len(s) for s in sets)
    memories = [m for m in system.friction_memories() if m is not None]
    held = [(dict(m.anchors), set(m.slipping), dict(m.material)) for m in memories]

    def call():
        for m, (anchors, slipping, material) in zip(memories, held, strict=True):
            m.anchors, m.slipping, m.material = dict(anchors), set(slipping), dict(material)
        return system.advance(integrator, 0.0, q_s, v_s, tau, PERIOD_S)

    return call, points, q_s[: scenario.uvms.nq], v_s[: scenario.uvms.nv], scenario


# ---- the MuJoCo twin of the grasp -----------------------------------------------------------


def _mujoco_grasp(scenario, q: np.ndarray, block_pose: np.ndarray, options: MjcfOptions):
    """The jaw's MJCF twin (`uvms_pin.apps.export.mjcf`: the same bodies, joints and
    collision boxes) with the block: a free box of the same size and mass, friction 0.8, its
    buoyancy a gravity compensation of 1/1.2 of its weight (the twin's fluid model gives it no
    added mass); the robot's boxes touch the block, not one another. Each finger closes with
    a 2 N motor (the servo saturated, as held in uvms-pin). (model, data) at the held state
    of uvms-pin's grasp, then settled 0.4 s in MuJoCo's own contacts."""
    uvms = scenario.uvms
    root = robot_touching(uvms_to_mjcf(uvms, Path(uvms.source).read_text(), options))
    world = root.find("worldbody")
    body = ET.SubElement(
        world, "body", name="block", gravcomp=repr(1.0 / 1.2),
        pos=" ".join(repr(float(x)) for x in block_pose[:3]),
        quat=" ".join(repr(float(x)) for x in (block_pose[6], *block_pose[3:6])),
    )  # fmt: skip
    ET.SubElement(body, "freejoint", name="block")
    mass = 1.2 * 1025.0 * BLOCK_M[0] * BLOCK_M[1] * BLOCK_M[2]
    a, b, c = BLOCK_M
    inertia = [
        mass * (b * b + c * c) / 12,
        mass * (a * a + c * c) / 12,
        mass * (a * a + b * b) / 12,
    ]
    ET.SubElement(body, "inertial", pos="0 0 0", mass=repr(mass),
                  diaginertia=" ".join(repr(x) for x in inertia))  # fmt: skip
    ET.SubElement(
        body, "geom", type="box", size=" ".join(repr(x / 2) for x in BLOCK_M),
        friction="0.8 0.005 0.0001", contype="0", conaffinity="1", condim="3",
    )  # fmt: skip
    actuators = ET.SubElement(root, "actuator")
    for side in ("left", "right"):
        ET.SubElement(actuators, "motor", joint=f"{side}_finger_joint", gear="1")
    model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    data = mujoco.MjData(model)
    data.qpos[: model.nq - 7] = qpos_from_q(q)
    data.qpos[model.nq - 7 :] = block_pose[[0, 1, 2, 6, 3, 4, 5]]
    data.ctrl[:] = -2.0  # each finger closing with 2 N
    mujoco.mj_forward(model, data)
    for _ in range(round(0.4 / model.opt.timestep)):
        mujoco.mj_step(model, data)
    return model, data


def _mujoco_period(model, data) -> tuple:
    """One 1 ms period of the settled MuJoCo grasp from its state (restored at each call),
    and the block's slip against the hull over a further 0.5 s held [m]."""
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    state = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state, spec)
    steps = round(PERIOD_S / model.opt.timestep)

    def call():
        mujoco.mj_setState(model, data, state, spec)
        for _ in range(steps):
            mujoco.mj_step(model, data)

    def offset():
        hull = data.xpos[1].copy()
        return data.qpos[model.nq - 7 : model.nq - 4] - hull

    before = offset()
    for _ in range(round(0.5 / model.opt.timestep)):
        mujoco.mj_step(model, data)
    slip = float(np.linalg.norm(offset() - before))
    mujoco.mj_setState(model, data, state, spec)
    return call, slip


def cases(folder: Path) -> tuple[dict, dict]:
    rigid, points, q, v, scenario = _held(folder, "rigid")
    compliant, compliant_points, *_ = _held(folder, "compliant")
    alone = System(
        Plant(scenario.uvms, free_surface=False, joint_limits=scenario.plant.joint_limits)
    )
    tau = np.zeros(scenario.uvms.nv)
    integrator = RK4(STEP_S)
    table = {
        BASE: lambda: alone.advance(integrator, 0.0, q, v, tau, PERIOD_S),
        RIGID: rigid,
        "+ the grasped block (compliant contacts)": compliant,
    }
    info = {"rigid_points": points, "compliant_points": compliant_points}
    block = np.asarray(_HELD_BLOCK[0])
    for label, options in MUJOCO_TWINS.items():
        model, data = _mujoco_grasp(scenario, q, block, options)
        table[label], info[f"{label}: block slip over 0.5 s [m]"] = _mujoco_period(model, data)
        info[f"{label}: contacts"] = int(data.ncon)
    return table, info


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    with one_blas_thread(), tempfile.TemporaryDirectory() as folder:
        table, info = cases(Path(folder))
        best = best_times(table, args.repeat)
    print(f"contact points: {info}")
    print("| one 1 ms period | time [us] | / the jaw alone | uvms-pin rigid / this |")
    print("|---|---|---|---|")
    rows = {}
    for name, seconds in best.items():
        rows[name] = {"s": seconds, "ratio": seconds / best[BASE]}
        versus = f"{best[RIGID] / seconds:.2f}" if name.startswith("MuJoCo") else ""
        print(f"| {name} | {seconds * 1e6:.0f} | {seconds / best[BASE]:.2f} | {versus} |")
    if args.json:
        args.json.write_text(json.dumps({**info, "rows": rows}, indent=2))


if __name__ == "__main__":
    main()
