"""uvms-pin side by side with MuJoCo on the same UVMS, in one process, as ratios only.

    .venv/bin/python benchmarks/bench_mujoco.py [--repeat N] [--out out/bench/mujoco.md]

The MuJoCo model is generated from the uvms-pin one (`uvms_pin.apps.export.mjcf`: same masses,
inertias, joint placements, axes and armature; buoyancy by gravity-compensated carriers;
MuJoCo's ellipsoid fluid model on the collision shapes; the paper's 2 N/m spring as a
tendon), so both simulators move the same rigid bodies. The water differs: uvms-pin puts
the added mass inside M and uses the URDF's damping; MuJoCo's approximate fluid model has
no added-mass acceleration term. Every figure is a ratio of best-of-``repeat`` times
measured here, to one ``pin.aba`` call on the same model or to MuJoCo doing the same job:

1. forward dynamics (with a current), x pin.aba;
2. the plant over one 2 ms control period, RK4 at 0.5 ms (uvms-pin: the simulator's
   per-tick call, ``System.advance`` with the input held (one compiled call on the core);
   MuJoCo: 4 ``mj_step`` with ``opt.integrator = RK4``);
3. one closed-loop tick of scenarios/realistic_force_tracking.toml: the same Python PPC,
   sensors and thruster allocation compute tau from a `Measurement` of each simulator's
   state, then the plant advances 2 ms;
4. the whole 2 s closed loop of that scenario as ``up.simulate`` runs it (measurement with its
   noise, PPC, allocation, plant, log and the rollout's energies), on the compiled loop and on
   the Python loop (`uvms_pin.sim.compiled_loop`), per 2 ms tick, against MuJoCo's plant alone
   (4 RK4 ``mj_step``, no controller);
5. the plant per 2 ms with 4-, 6- and 7-joint arms (reference, UR5, Panda on the
   reference vehicle);
6. the plant per 2 ms in a world (bench_world.py's: a seafloor, a crate, a boulder and a
   pipe), the reference vehicle resting on the seafloor on the four bottom corners of its
   hull box (uvms-pin: Hunt-Crossley and Coulomb contacts, compiled with coal; MuJoCo: the
   same geoms in its twin, its own soft contacts with their default solver settings).

When uvms-pin grows a ``backend=`` keyword (on ``forward_dynamics``, on ``Plant`` or on
``Plant.acceleration``), every uvms-pin row is measured for each backend.
"""

from __future__ import annotations

import argparse
import inspect
import json
import math
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
from bench_world import objects as world_objects
from bench_world import resting_floor_z
from timing import best_times, one_blas_thread

import uvms_pin as up
from uvms_pin.apps.export.mjcf import MjcfOptions, uvms_to_mjcf
from uvms_pin.apps.export.mujoco_state import (
    q_from_qpos,
    qfrc_from_tau,
    qpos_from_q,
    qvel_from_v,
    v_from_qvel,
)
from uvms_pin.model.mount.catalog import resolve_arm
from uvms_pin.model.mount.mount import mount_arm_detailed
from uvms_pin.model.mount.split import split_urdf
from uvms_pin.physics.contact import LinearSpring
from uvms_pin.physics.disturbance import SinusoidalDisturbance
from uvms_pin.physics.world.world import World
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.sensors import SensorSuite
from uvms_pin.sim.system import System as BodySystem

ROOT = Path(__file__).resolve().parents[1]
REFERENCE_URDF = ROOT / "models" / "uvms_lbv150.urdf"
VEHICLE_URDF = ROOT / "models" / "lbv150.urdf"
SCENARIO = ROOT / "scenarios" / "realistic_force_tracking.toml"
CONTROL_PERIOD_S = 2e-3
STEP_S = 5e-4
SPRING_N_M = 2.0
CURRENT_WORLD_M_S = np.array([0.3, 0.1, 0.0])
ARMS = ("reference", "ur5", "panda")  # 4, 6 and 7 arm joints
ABA = "pin.aba (rigid, no water)"
MJ_FORWARD, MJ_PLANT, MJ_LOOP = "MuJoCo mj_forward", "MuJoCo plant", "MuJoCo closed-loop tick"


# ---- backends ---------------------------------------------------------------------------


def backends_of(*functions: Callable) -> list[str | None]:
    """The values of a ``backend`` keyword of any of ``functions`` (its default first, then
    "python"), or [None] when none has one (today's single implementation)."""
    for fn in functions:
        parameter = inspect.signature(fn).parameters.get("backend")
        if parameter is not None:
            default = parameter.default
            found = [default] if isinstance(default, str) else []
            return list(dict.fromkeys([*found, "python"]))
    return [None]


def label(backend: str | None) -> str:
    return "uvms-pin" if backend is None else f"uvms-pin ({backend})"


def keyword(backend: str | None) -> dict:
    return {} if backend is None else {"backend": backend}


def make_plant(uvms: up.UVMS, backend: str | None, **fields) -> Plant:
    """A Plant, given the backend if Plant takes one (else the rhs is given it)."""
    if backend is not None and "backend" in inspect.signature(Plant).parameters:
        fields["backend"] = backend
    return Plant(uvms, **fields)


def plant_backends() -> list[str | None]:
    return backends_of(Plant, Plant.acceleration)


# ---- the two simulators on one system -----------------------------------------------------


@dataclass
class System:
    """One UVMS, its MuJoCo twin and a state to start from."""

    name: str
    uvms: up.UVMS
    mj_model: mujoco.MjModel
    q0: np.ndarray
    v0: np.ndarray

    @property
    def arm_joints(self) -> int:
        return self.uvms.n_arm_joints


def ee_position(uvms: up.UVMS, q: np.ndarray) -> np.ndarray:
    data = uvms.model.createData()
    pin.framesForwardKinematics(uvms.model, data, q)
    return data.oMf[uvms.ee_frame_id].translation.copy()


def build_system(name: str, uvms: up.UVMS, urdf_text: str, q0: np.ndarray) -> System:
    """The MuJoCo twin of ``uvms`` with the spring anchored at the end-effector at q0."""
    q0 = q0.copy()
    q0[2] = -3.0  # deep: the free surface (on by default) cuts no body; the twin has none
    anchor = ee_position(uvms, q0)
    options = MjcfOptions(
        timestep_s=STEP_S,
        integrator="RK4",
        spring_stiffness_N_m=SPRING_N_M,
        spring_anchor_world_m=tuple(anchor),
    )
    mj_model = mujoco.MjModel.from_xml_string(uvms_to_mjcf(uvms, urdf_text, options))
    mj_model.opt.wind[:] = CURRENT_WORLD_M_S
    rng = np.random.default_rng(0)
    return System(name, uvms, mj_model, q0, rng.normal(scale=0.1, size=uvms.nv))


def reference_system() -> System:
    uvms = up.load_uvms(REFERENCE_URDF)
    q0 = uvms.neutral_configuration()
    q0[7:] = [-0.2, 1.0, -0.8, 0.2]  # the realistic scenario's arm
    return build_system("reference", uvms, REFERENCE_URDF.read_text(), q0)


def mounted_system(arm: str, tmp: Path) -> System:
    """An example-robot-data arm on the reference vehicle, mounted as compare-arms does."""
    split = split_urdf(REFERENCE_URDF, tmp)
    entry = resolve_arm(arm)
    pose = (split.mount_pose.translation, np.array([math.pi, 0.0, 0.0]))
    mounted = mount_arm_detailed(
        split.vehicle_urdf, entry.urdf, pose, ee_link=entry.ee_link, allow_dry_links=True
    )
    model = mounted.uvms.model
    q0 = mounted.uvms.neutral_configuration()
    # away from singular straight-arm poses, inside the joint limits
    q0[7:] = np.clip(q0[7:] + 0.3, model.lowerPositionLimit[7:], model.upperPositionLimit[7:])
    return build_system(arm, mounted.uvms, mounted.urdf_text, q0)


def mujoco_data(system: System, q: np.ndarray, v: np.ndarray) -> mujoco.MjData:
    data = mujoco.MjData(system.mj_model)
    data.qpos[:] = qpos_from_q(q)
    data.qvel[:] = qvel_from_v(q, v)
    return data


# ---- the measurements ---------------------------------------------------------------------


def aba_case(system: System) -> Callable[[], object]:
    model = system.uvms.model
    data = model.createData()
    tau = np.zeros(model.nv)
    return lambda: pin.aba(model, data, system.q0, system.v0, tau)


def forward_dynamics_cases(system: System) -> dict[str, Callable[[], object]]:
    """Forward dynamics with the current: pin.aba (rigid), uvms-pin (each backend), MuJoCo."""
    uvms, q, v = system.uvms, system.q0, system.v0
    tau = np.zeros(uvms.nv)
    cases = {}
    for backend in backends_of(up.forward_dynamics):
        kw = keyword(backend)
        cases[f"{label(backend)} forward_dynamics"] = lambda kw=kw: up.forward_dynamics(
            uvms, q, v, tau, CURRENT_WORLD_M_S, **kw
        )
    data = mujoco_data(system, q, v)
    cases[MJ_FORWARD] = lambda: mujoco.mj_forward(system.mj_model, data)
    return cases


def uvms_plant_case(system: System, backend: str | None) -> Callable[[], object]:
    """One 2 ms control period, RK4 at 0.5 ms, input held, current, spring, disturbance."""
    uvms = system.uvms
    plant = make_plant(
        uvms,
        backend,
        current_world_m_s=CURRENT_WORLD_M_S,
        contact=LinearSpring(np.full(3, SPRING_N_M)),
        disturbance=SinusoidalDisturbance(),
    )
    plant.attach(system.q0)
    integrator = RK4(STEP_S)
    q, v, tau = system.q0, system.v0, np.zeros(uvms.nv)
    return lambda: advance(plant, integrator, backend, 0.0, q, v, tau, CONTROL_PERIOD_S)


#: each plant's system of bodies, built on its first period
_BODIES: dict[int, BodySystem] = {}


def advance(plant, integrator, backend, t0, q, v, tau, t1):
    """The simulator's per-tick call: the system of bodies' period step (one compiled call
    for the whole period on the core, the integrator's loop over the right-hand side on the
    Python reference)."""
    stepped = _BODIES.get(id(plant))
    if stepped is None or stepped.plant is not plant:
        stepped = _BODIES[id(plant)] = BodySystem(plant)
    return stepped.advance(integrator, t0, q, v, tau, t1)


def mujoco_plant_case(system: System) -> Callable[[], object]:
    """4 mj_step (RK4, 0.5 ms) from the same state, input held (zero) in qfrc_applied."""
    data = mujoco_data(system, system.q0, system.v0)
    qpos, qvel = data.qpos.copy(), data.qvel.copy()
    model = system.mj_model
    steps = round(CONTROL_PERIOD_S / model.opt.timestep)

    def period():
        data.qpos[:], data.qvel[:] = qpos, qvel  # every call from the same state
        for _ in range(steps):
            mujoco.mj_step(model, data)

    return period


def plant_cases(system: System) -> dict[str, Callable[[], object]]:
    cases = {f"{label(b)} plant": uvms_plant_case(system, b) for b in plant_backends()}
    cases[MJ_PLANT] = mujoco_plant_case(system)
    return cases


# ---- a world with contacts ----------------------------------------------------------------


def robot_touching(mjcf: str) -> ET.Element:
    """The twin's MJCF tree with contacts on, each of the robot's geoms touching what has
    conaffinity 1 (what is added after), not the robot's own others."""
    root = ET.fromstring(mjcf)
    for flag in root.iter("flag"):  # the twin is exported without contacts
        flag.set("contact", "enable")
    for geom in root.iter("geom"):
        geom.set("contype", "1")
        geom.set("conaffinity", "0")
    return root


def _world_geoms(mjcf: str, objects: list) -> str:
    """The MJCF with the world's objects as geoms the robot's geoms collide with (and they
    only with the world: the robot's own pieces do not touch each other here either)."""
    root = robot_touching(mjcf)
    world = root.find("worldbody")
    for obj in objects:
        placement = obj.placement
        mu = f"{obj.friction_static} 0.005 0.0001"
        common = {"contype": "0", "conaffinity": "1", "friction": mu, "name": obj.name}
        position = " ".join(repr(float(x)) for x in placement.translation)
        quat = pin.Quaternion(placement.rotation)
        orientation = " ".join(repr(float(x)) for x in (quat.w, quat.x, quat.y, quat.z))
        size = {
            "plane": "0 0 1",
            "box": " ".join(repr(float(x) / 2) for x in obj.params.get("size_m", [])),
            "sphere": repr(obj.params.get("radius_m")),
            "cylinder": f"{obj.params.get('radius_m')} {obj.params.get('length_m', 0) / 2}",
        }[obj.kind]
        ET.SubElement(
            world, "geom", type=obj.kind, size=size, pos=position, quat=orientation, **common
        )
    return ET.tostring(root, encoding="unicode")


def resting_system() -> tuple[System, World]:
    """The reference vehicle resting on bench_world's seafloor (four corners of its hull box
    2 mm deep), and its MuJoCo twin with the same objects."""
    # the twin needs a frame for its sites: the vehicle's body
    uvms = up.load_uvms(VEHICLE_URDF, ee_frame="base_link", sensor_frame="base_link")
    q0 = uvms.neutral_configuration()
    q0[:3] = [0.0, 0.0, -5.0]
    world = World(uvms, world_objects(resting_floor_z(uvms, q0)))
    options = MjcfOptions(timestep_s=STEP_S, integrator="RK4")
    mjcf = _world_geoms(uvms_to_mjcf(uvms, VEHICLE_URDF.read_text(), options), world.objects)
    mj_model = mujoco.MjModel.from_xml_string(mjcf)
    return System("vehicle", uvms, mj_model, q0, np.zeros(uvms.nv)), world


def contact_cases(system: System, world: World) -> dict[str, Callable[[], object]]:
    """One 2 ms period resting on the seafloor: uvms-pin (each backend), MuJoCo."""
    cases = {}
    q, v, tau = system.q0, system.v0, np.zeros(system.uvms.nv)
    for backend in plant_backends():
        plant = make_plant(system.uvms, backend, world=world, free_surface=False)
        plant.attach(system.q0)
        integrator = RK4(STEP_S)
        cases[f"{label(backend)} plant"] = lambda p=plant, b=backend, i=integrator: advance(
            p, i, b, 0.0, q, v, tau, CONTROL_PERIOD_S
        )
    cases[MJ_PLANT] = mujoco_plant_case(system)
    return cases


def contacts_of(system: System, world: World) -> tuple[int, int]:
    """(uvms-pin's contact points, MuJoCo's contacts) at the resting state."""
    ours = len(Plant(system.uvms, world=world).world_forces(system.q0, system.v0).touch)
    data = mujoco_data(system, system.q0, system.v0)
    mujoco.mj_forward(system.mj_model, data)
    return ours, int(data.ncon)


# ---- the closed loop ----------------------------------------------------------------------


def closed_loop_cases(ticks: int) -> dict[str, Callable[[], object]]:
    """``ticks`` 2 ms ticks of the realistic scenario from its initial state: the same PPC,
    sensors and allocation; the uvms-pin plant (each backend) or MuJoCo's."""
    scenario = up.load_scenario(SCENARIO)
    uvms = scenario.uvms
    system = build_system("reference", uvms, REFERENCE_URDF.read_text(), scenario.q0)
    system.mj_model.opt.wind[:] = scenario.plant.current_world_m_s
    cases = {}
    for backend in plant_backends():
        plant = make_plant(
            uvms,
            backend,
            current_world_m_s=scenario.plant.current_world_m_s,
            contact=scenario.plant.contact,
            disturbance=scenario.plant.disturbance,
            actuation=scenario.plant.actuation,
        )
        cases[f"{label(backend)} closed-loop tick"] = lambda plant=plant, backend=backend: (
            _uvms_loop(scenario, plant, backend, ticks)
        )
    cases[MJ_LOOP] = lambda: _mujoco_loop(scenario, system, ticks)
    return cases


def _controller_tick(plant: Plant, controller, sensors, t, q, v) -> np.ndarray:
    """What the simulator does at a tick: measure, compute, allocate (tau applied)."""
    measurement = sensors.measure(t, q, v, plant.contact_wrench(q, v))
    return plant.actuation.apply(controller.compute(t, measurement))


def _fresh(scenario) -> tuple:
    settings = scenario.settings
    sensors = SensorSuite(scenario.uvms.model, scenario.sensor_config, 1.0, settings.seed)
    controller = scenario.controller_factory(scenario.uvms)
    controller.reset()
    return controller, sensors


def _uvms_loop(scenario, plant: Plant, backend: str | None, ticks: int) -> None:
    controller, sensors = _fresh(scenario)
    plant.attach(scenario.q0)
    integrator = scenario.settings.integrator
    q, v = scenario.q0, scenario.v0
    for k in range(ticks):
        t = k * CONTROL_PERIOD_S
        tau = _controller_tick(plant, controller, sensors, t, q, v)
        q, v = advance(plant, integrator, backend, t, q, v, tau, t + CONTROL_PERIOD_S)


def _mujoco_loop(scenario, system: System, ticks: int) -> None:
    controller, sensors = _fresh(scenario)
    plant = scenario.plant
    plant.attach(scenario.q0)
    model = system.mj_model
    data = mujoco_data(system, scenario.q0, scenario.v0)
    steps = round(CONTROL_PERIOD_S / model.opt.timestep)
    for k in range(ticks):
        t = k * CONTROL_PERIOD_S
        q, v = q_from_qpos(data.qpos), v_from_qvel(data.qpos, data.qvel)
        tau = _controller_tick(plant, controller, sensors, t, q, v)
        tau[:6] -= plant.disturbance_wrench(t)  # held over the tick (uvms-pin: per stage)
        data.qfrc_applied[:] = qfrc_from_tau(q, tau)
        for _ in range(steps):
            mujoco.mj_step(model, data)


def whole_loop_cases(system: System, duration_s: float) -> dict[str, Callable[[], object]]:
    """The realistic scenario's ``duration_s`` closed loop by ``up.simulate`` (each loop
    path), and MuJoCo's plant alone over as many 2 ms periods."""
    scenario = up.load_scenario(SCENARIO, {"scenario.duration_s": duration_s})
    ticks = round(duration_s / CONTROL_PERIOD_S)
    period = mujoco_plant_case(system)

    def run(compiled: bool):
        return lambda: up.simulate(scenario, progress=False, compiled_loop=compiled)

    return {
        "uvms-pin simulate, compiled loop": run(True),
        "uvms-pin simulate, Python loop": run(False),
        "MuJoCo plant alone": lambda: [period() for _ in range(ticks)],
    }


# ---- report -------------------------------------------------------------------------------


def measure_section(
    title: str, system: System, cases: dict[str, Callable], repeat: int, per_call: int = 1
) -> dict:
    """Time ``cases`` with pin.aba on ``system`` in the same rounds; seconds per unit of
    work (a case doing ``per_call`` units per call is divided by it)."""
    times = best_times({ABA: aba_case(system), **cases}, repeat)
    aba = times.pop(ABA)
    return {"title": title, "aba_s": aba, "cases": {n: t / per_call for n, t in times.items()}}


def measure_growth(systems: list[System], repeat: int) -> list[dict]:
    """The plant per 2 ms of every system, all timed in the same rounds (with each one's
    pin.aba), so that the growth with the arm is not blurred by the machine's load."""
    cases = {}
    for system in systems:
        cases[(system.name, ABA)] = aba_case(system)
        for name, fn in plant_cases(system).items():
            cases[(system.name, name)] = fn
    times = best_times(cases, repeat)
    rows = []
    for system in systems:
        mine = {name: t for (owner, name), t in times.items() if owner == system.name}
        aba = mine.pop(ABA)
        rows.append(
            {"system": system.name, "arm_joints": system.arm_joints, "aba_s": aba, "cases": mine}
        )
    return rows


def markdown(sections: list[dict], arms: list[dict]) -> str:
    lines = ["| reference UVMS (4-joint arm) | x pin.aba | x MuJoCo |", "|---|---:|---:|"]
    for section in sections:
        cases = section["cases"]
        mujoco_s = next(t for n, t in cases.items() if n.startswith("MuJoCo"))
        for name, seconds in cases.items():
            lines.append(
                f"| {section['title']}: {name} | {seconds / section['aba_s']:.1f} | "
                f"{seconds / mujoco_s:.2f} |"
            )
    lines += [
        "",
        "| 2 ms plant (RK4 at 0.5 ms, current, spring) | arm joints | x pin.aba (same model) "
        "| x the same on the reference | x MuJoCo |",
        "|---|---:|---:|---:|---:|",
    ]
    for row in arms:
        cases = row["cases"]
        for name, seconds in cases.items():
            lines.append(
                f"| {row['system']}: {name} | {row['arm_joints']} | "
                f"{seconds / row['aba_s']:.1f} | {seconds / arms[0]['cases'][name]:.2f} | "
                f"{seconds / cases[MJ_PLANT]:.2f} |"
            )
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=25, help="rounds; the best is kept")
    parser.add_argument("--ticks", type=int, default=25, help="closed-loop ticks per run")
    parser.add_argument("--loop-s", type=float, default=2.0, help="whole closed loop [s]")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "bench" / "mujoco.md")
    args = parser.parse_args()
    if min(args.repeat, args.ticks) < 1:
        parser.error("--repeat and --ticks must be >= 1")
    one_blas_thread()

    reference = reference_system()
    sections = [
        measure_section(
            "forward dynamics, current 0.3 m/s",
            reference,
            forward_dynamics_cases(reference),
            args.repeat,
        ),
        measure_section(
            "2 ms plant, RK4 at 0.5 ms, current, spring",
            reference,
            plant_cases(reference),
            args.repeat,
        ),
        measure_section(
            "closed-loop tick, realistic scenario (PPC + 2 ms plant)",
            reference,
            closed_loop_cases(args.ticks),
            args.repeat,
            per_call=args.ticks,
        ),
        measure_section(
            f"whole closed loop, realistic scenario, {args.loop_s:g} s, per 2 ms tick",
            reference,
            whole_loop_cases(reference, args.loop_s),
            max(3, args.repeat // 5),
            per_call=round(args.loop_s / CONTROL_PERIOD_S),
        ),
    ]
    resting, world = resting_system()
    points, mj_contacts = contacts_of(resting, world)
    sections.append(
        measure_section(
            f"2 ms plant resting on the seafloor ({points} contacts; MuJoCo {mj_contacts})",
            resting,
            contact_cases(resting, world),
            args.repeat,
        )
    )
    with tempfile.TemporaryDirectory(prefix="uvms_bench_") as tmp:
        systems = [reference] + [mounted_system(arm, Path(tmp) / arm) for arm in ARMS[1:]]
    arms = measure_growth(systems, args.repeat)
    table = markdown(sections, arms)
    print(table, end="")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(table)
    seconds = {"sections": sections, "arms": arms}
    args.out.with_suffix(".json").write_text(json.dumps(seconds, indent=2))
    print(f"written: {args.out} (and .json with the seconds behind the ratios)")


if __name__ == "__main__":
    main()
