"""The cases a user tries first, across every shipped model and scenario, run as a user runs
them (the `uvms-pin run` command line, `gymnasium.make`), each classified.

    .venv/bin/python scripts/campaigns/first_tries.py [--only SUBSTRING] [--duration 1] [--jobs 2]
        [--gym-steps 300] [--out out/first_tries] [--no-gym] [--no-cli]
        [--bad-of out/first_tries/first_tries.json]

Every scenario in scenarios/*.toml at its defaults and with the variants tried first (a
larger step, rigid moving contacts, another duration, a changed or added object, another
gripper force, another shipped model, the navigation sensors and the estimator switched on,
the sensors that see (a camera in the loop, an imaging sonar, a multibeam),
no controller), each a short run (``--duration`` simulated seconds); every Gymnasium
environment under uniform random actions, several seeds. Each outcome is one of

- ``ok``: exit 0, the rollout finite and physical (speeds under 10 m/s, no free object
  below a seabed, no energy gained in a passive scene);
- ``refused``: exit 2, an error line naming the cause, no traceback;
- ``stopped``: exit 3, a named cause, no traceback;
- ``BAD``: anything else (a traceback, another exit code, a hang, a NaN, nonsense physics).

The cases are fixed and the seeds given (scenario seeds, ``--seed`` for the Gymnasium
actions): a rerun gives the same table. OUT/first_tries.json keeps every case's command,
outcome and reason.
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import subprocess
import sys
import time
import tomllib
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = sorted((ROOT / "scenarios").glob("*.toml"))
MODELS = sorted(p.stem for p in (ROOT / "models").glob("*.urdf"))
CLI = [str(Path(sys.executable).with_name("uvms-pin"))]
TIMEOUT_S = 120.0
MAX_SPEED_M_S = 10.0
MAX_RATE_RAD_S = 100.0  # what no vehicle or arm joint turns at (divergence.py's "implausible")
ENERGY_GAIN_J = 0.05  # a passive scene in still water may not gain more (integration error)


# ---------------------------------------------------------------- the cases


def _toml(value) -> str:
    """A Python value as the TOML text `--set` reads."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return repr(float(value)) if isinstance(value, float) else str(value)


def _sets(**pairs) -> list[str]:
    return [f"{key.replace('__', '.')}={_toml(value)}" for key, value in pairs.items()]


def _objects(p0: list[float]) -> dict[str, list[dict]]:
    """Object sets placed from the vehicle's start p0: near the arm, touching the vehicle,
    resting on a seabed, on a slope; light and heavy."""
    x, y, z = p0
    seabed_z = z - 0.6
    seabed = {"type": "plane", "name": "seabed", "point_world_m": [x, y, seabed_z]}
    slope = {
        "type": "plane",
        "name": "slope",
        "point_world_m": [x, y, seabed_z],
        "normal_world": [0.3, 0.0, 1.0],
    }
    box = {"type": "box", "name": "box", "size_m": [0.3, 0.3, 0.3]}
    sphere = {"type": "sphere", "name": "ball", "radius_m": 0.1}
    cyl = {"type": "cylinder", "name": "pipe", "radius_m": 0.05, "length_m": 0.6}
    return {
        "box_near_arm_2000": [
            {**box, "position_world_m": [x + 0.8, y, z - 0.2], "density_kg_m3": 2000.0}
        ],
        "sphere_touching_vehicle_1500": [
            {**sphere, "position_world_m": [x, y, z - 0.23], "density_kg_m3": 1500.0}
        ],
        "box_on_seabed_3000": [
            seabed,
            {**box, "position_world_m": [x + 0.7, y, seabed_z + 0.15], "density_kg_m3": 3000.0},
        ],
        "sphere_on_seabed_500": [
            seabed,
            {**sphere, "position_world_m": [x + 0.6, y, seabed_z + 0.1], "density_kg_m3": 500.0},
        ],
        "cylinder_on_slope_2500": [
            slope,
            {
                **cyl,
                "position_world_m": [x + 0.7, y, seabed_z + 0.3 * -0.7 / 1.0 + 0.06],
                "rpy_rad": [1.5707963, 0.0, 0.0],
                "density_kg_m3": 2500.0,
            },
        ],
        "fixed_box_at_arm": [{**box, "position_world_m": [x + 0.75, y, z - 0.1]}],
    }


def _doc(path: Path) -> dict:
    return tomllib.loads(path.read_text())


#: the scenarios every shipped model is tried on (the others: a vehicle alone and an arm)
MODEL_SCENARIOS = (
    "passive_still_water",
    "bluerov_alpha5_ee_circle",
    "gym_station_keeping",
    "paper_force_tracking",
    "push_object",
    "estimator_station_keeping",
)
#: the object sets tried on every scenario (`_objects`); the first two also passive and rigid
OBJECT_SETS = (
    "fixed_box_at_arm",
    "box_on_seabed_3000",
    "box_near_arm_2000",
    "sphere_touching_vehicle_1500",
    "sphere_on_seabed_500",
    "cylinder_on_slope_2500",
)


def _coarse(period: float) -> list[str]:
    """The step, the control period and the log period all ``period``: a coarse run."""
    return _sets(integrator__step_s=period, control__period_s=period, output__log_period_s=period)


def _scenario_cases(path: Path) -> list[tuple[str, list[str], bool]]:
    """(variant, --set arguments, passive) of one scenario."""
    doc = _doc(path)
    step = doc.get("integrator", {}).get("step_s", 0.001)
    still = _still(doc) and "controller" not in doc and "task" not in doc
    cases: list[tuple[str, list[str], bool]] = [("defaults", [], still)]
    cases += [(f"step x{f}", _sets(integrator__step_s=step * f), still) for f in (2, 10)]
    cases += [(f"coarse {h:g}", _coarse(h), still) for h in (0.01, 0.05)]
    cases.append(("semi_implicit_euler", _sets(integrator__method="semi_implicit_euler"), still))
    cases.append(("moving rigid", _sets(world__moving_contact="rigid"), still))
    cases.append(("duration 0.3", _sets(scenario__duration_s=0.3), still))
    if "robots" in doc:
        for model in ("bluerov2_heavy", "uvms_lbv150", "uvms_bluerov2_alpha5_jaws"):
            cases.append((f"robot0 model {model}", _sets(**{"robots[0]__model": model}), False))
        seeing = {"robots[0]__sensors__camera": [EYE], "robots[1]__sensors__sonar": SONARS}
        cases.append(("robots see", _sets(**seeing), False))
        return cases
    passive = _sets(controller={"type": "none"})
    cases.append(("no controller", passive, _still(doc)))
    p0 = doc.get("initial", {}).get("position_world_m", [0.0, 0.0, 0.0])
    sets = _objects(p0)
    for name in OBJECT_SETS:
        world = {"objects": sets[name]}
        fixed = all("density_kg_m3" not in o for o in sets[name])  # the energy is the robot's
        cases.append((f"objects {name}", _sets(world=world), still and fixed))
        if name in OBJECT_SETS[:2]:
            both = _sets(world=world) + passive
            cases.append((f"objects {name}, passive", both, _still(doc) and fixed))
            rigid = {**world, "moving_contact": "rigid"}
            cases.append((f"objects {name}, rigid", _sets(world=rigid), False))
    cases += _free_object_cases(doc)
    if "gripper" in doc:
        for force in (1.0, 50.0, 500.0):
            cases.append((f"gripper {force:g} N", _sets(gripper__max_force_N=force), False))
    models = MODELS if path.stem in MODEL_SCENARIOS else ("bluerov2_heavy", "uvms_lbv150")
    for model in models:
        initial = {"position_world_m": p0}
        cases.append((f"model {model}", _sets(scenario__model=model, initial=initial), False))
    return cases + _sensor_cases()


def _still(doc: dict) -> bool:
    """Nothing drives the scene but gravity and buoyancy (the energy may only fall)."""
    water = doc.get("water", {})
    moving = any(water.get(k) for k in ("waves", "sea", "current")) or any(
        water.get("current_world_m_s", [0.0]) or [0.0]
    )
    driven = any(k in doc for k in ("disturbance", "environment", "gripper"))  # the jaw's servo
    return not moving and not driven


def _free_object_cases(doc: dict) -> list[tuple[str, list[str], bool]]:
    """The scenario's own first free object: denser, lighter, another shape, smaller."""
    objects = doc.get("world", {}).get("objects", [])
    free = [k for k, o in enumerate(objects) if "density_kg_m3" in o or "mass_kg" in o]
    if not free:
        return []
    k, obj = free[0], objects[free[0]]
    key = f"world.objects[{k}]"
    base = {n: obj[n] for n in ("name", "position_world_m", "rpy_rad") if n in obj}
    shapes = {
        "sphere": {"type": "sphere", "radius_m": 0.05},
        "box": {"type": "box", "size_m": [0.1, 0.1, 0.1]},
        "cylinder": {"type": "cylinder", "radius_m": 0.03, "length_m": 0.2},
    }
    cases = [
        (f"own object density {d}", [f"{key}.density_kg_m3={d}.0"], False) for d in (500, 3000)
    ]
    for shape, fields in shapes.items():
        value = {**base, **fields, "density_kg_m3": 1500.0}
        cases.append((f"own object -> {shape}", [f"{key}={_toml(value)}"], False))
    return cases


#: the sensors that see of the "sees" cases: a camera in the loop, an imaging sonar and a
#: multibeam looking down, small and slow (what they cost is not the question)
EYE = {"name": "eye", "width": 32, "height": 24, "rate_hz": 5.0, "in_loop": True}
SONARS = [
    {"name": "fls", "beams": 16, "bins": 32, "rate_hz": 5.0},
    {"name": "mb", "type": "multibeam", "beams": 8, "bins": 32, "rate_hz": 5.0,
     "rpy_rad": [0.0, 1.5708, 0.0]},
]  # fmt: skip


def _sensor_cases() -> list[tuple[str, list[str], bool]]:
    imu = {"gyro_noise_rad_s_rthz": 3e-4, "accel_noise_m_s2_rthz": 2e-3}
    nav = _sets(
        sensors__imu=imu,
        sensors__depth={"noise_Pa": 100.0},
        sensors__dvl={"noise_m_s": 0.01, "seabed_depth_m": 30.0},
        sensors__usbl={"noise_m": 0.1},
    )
    return [
        ("nav sensors", nav, False),
        (
            "estimator in the loop",
            nav + _sets(estimator={"type": "eskf", "controller_input": "estimate"}),
            False,
        ),
        ("noise", _sets(sensors__position_noise_m=0.01, sensors__velocity_noise=0.01), False),
        ("sees", _sets(sensors__camera=[EYE], sensors__sonar=SONARS), False),
    ]


# ---------------------------------------------------------------- running and judging


def _judge_rollouts(out: Path, passive: bool) -> str:
    """ "" if every rollout OUT wrote is finite and physical, else what is not."""
    files = sorted(out.rglob("rollout.npz"))
    if not files:
        return "exit 0 but no rollout.npz"
    for file in files:
        data = np.load(file)
        for key in ("q", "v"):
            if not np.all(np.isfinite(data[key])):
                return f"{file.parent.name}: non-finite {key}"
        speed = np.linalg.norm(data["v"][:, :3], axis=1).max()
        if speed > MAX_SPEED_M_S:
            return f"vehicle speed {speed:.1f} m/s"
        rate = np.abs(data["v"][:, 3:]).max()
        if rate > MAX_RATE_RAD_S:
            return f"an angular or joint rate of {rate:.0f} rad/s"
        problem = _judge_free_objects(file, data) or _judge_images(file)
        if problem:
            return problem
        if passive:
            energy = data["kinetic_energy_J"] + data["potential_energy_J"]
            gain = float(np.max(energy - energy[0]))
            if gain > ENERGY_GAIN_J:
                return f"passive scene gained {gain:.3g} J"
    return ""


def _judge_images(file: Path) -> str:
    """ "" unless the run had cameras or sonars and its images are missing, or not what
    they are (8-bit colour; depths positive or NaN; intensities finite, >= 0)."""
    described = json.loads(file.with_name("rollout.json").read_text()).get("perception") or {}
    if not described:
        return ""
    images = file.with_name("perception.npz")
    if not images.is_file():
        return f"{file.parent.name}: cameras or sonars but no perception.npz"
    with np.load(images) as data:
        for key in data.files:
            values = data[key]
            if key.endswith("__rgb") and values.dtype != np.uint8:
                return f"{key}: {values.dtype}, not 8-bit colour"
            if key.endswith("__depth_m") and np.any(values[np.isfinite(values)] <= 0.0):
                return f"{key}: a depth <= 0"
            if key.endswith("__intensity") and not (
                np.all(np.isfinite(values)) and np.all(values >= 0)
            ):
                return f"{key}: a negative or non-finite echo"
    return ""


def _judge_free_objects(file: Path, data) -> str:
    if "signal__free_objects" not in data.files:
        return ""
    meta = json.loads(file.with_suffix(".json").read_text())
    world = meta.get("world", {}).get("world") or {}
    states = data["signal__free_objects"]
    if not np.all(np.isfinite(states)):
        return "non-finite free object state"
    planes = [o for o in world.get("objects", []) if o.get("type") == "plane"]
    for k, obj in enumerate(world.get("free_objects", [])):
        block = states[:, 13 * k : 13 * (k + 1)]
        speed = np.linalg.norm(block[:, 7:10], axis=1).max()
        if speed > MAX_SPEED_M_S:
            return f"free object {obj['name']} at {speed:.1f} m/s"
        for plane in planes:
            n = np.asarray(plane["normal_world"])
            height = (block[:, :3] - np.asarray(plane["point_world_m"])) @ n
            if height.min() < -0.1:
                return f"free object {obj['name']} {-height.min():.2f} m below {plane['name']}"
    return ""


def _run_cli(scenario: Path, sets: list[str], out: Path, duration: float) -> tuple[int, str, float]:
    argv = [*CLI, "run", str(scenario), "--out", str(out), "--quiet", "--overwrite"]
    for item in sets:
        argv += ["--set", item]
    env = {**os.environ, "UVMS_PIN_MAX_DURATION_S": str(duration), "MPLBACKEND": "Agg"}
    start = time.perf_counter()
    try:
        done = subprocess.run(argv, capture_output=True, text=True, timeout=TIMEOUT_S, env=env)
    except subprocess.TimeoutExpired:
        return -1, f"hang: over {TIMEOUT_S:.0f} s", TIMEOUT_S
    return done.returncode, done.stdout + done.stderr, time.perf_counter() - start


def _raised_on_purpose(text: str) -> bool:
    """The traceback is the one the command line shows of a scenario's own code (a metric,
    a controller: "your code raised") and its last frame is a ``raise`` of that code: the
    code refused on purpose, naming why. Any other traceback is a failure."""
    if "your code raised" not in text and "your controller's code" not in text:
        return False
    lines = text.split("Traceback (most recent call last):", 1)[1].splitlines()
    code = [ln.strip() for ln in lines if ln.startswith("    ") and not ln.strip().startswith("^")]
    return bool(code) and code[-1].startswith("raise ")


def _classify(code: int, text: str, out: Path, passive: bool) -> tuple[str, str]:
    lines = [ln for ln in text.splitlines() if ln.strip() and "warning:" not in ln]
    last = lines[-1] if lines else ""
    if code == -1:
        return "BAD", text
    if "Traceback (most recent call last)" in text and not _raised_on_purpose(text):
        return "BAD", "traceback: " + last
    if code == 0:
        problem = _judge_rollouts(out, passive)
        return ("BAD", problem) if problem else ("ok", "")
    if code in (2, 3):
        named = [ln for ln in lines if "error" in ln.lower() or "stopped" in ln.lower()]
        if not named:
            return "BAD", f"exit {code} without a named cause: {last}"
        if "nan" in " ".join(named).lower().split():
            return "BAD", f"exit {code}, a NaN named as cause: {named[-1]}"
        return ("refused" if code == 2 else "stopped"), named[-1][:200]
    return "BAD", f"exit {code}: {last[:200]}"


def _cli_case(args, index: int, path: Path, variant: str, sets: list[str], passive: bool) -> dict:
    out = args.out / "runs" / f"{index:04d}"
    code, text, wall = _run_cli(path, sets, out, args.duration)
    outcome, reason = _classify(code, text, out, passive)
    words = ["uvms-pin", "run", f"scenarios/{path.name}", "--out", "OUT"]
    command = shlex.join(words + [a for s in sets for a in ("--set", s)])
    label = f"{path.stem}: {variant}"
    print(f"{outcome:8s} {wall:5.1f}s {label}  {reason[:110]}", flush=True)
    return dict(
        case=label,
        kind="cli",
        outcome=outcome,
        reason=reason,
        exit=code,
        wall_s=round(wall, 1),
        command=command,
        env=f"UVMS_PIN_MAX_DURATION_S={args.duration:g}",
    )


def _chosen(args, label: str) -> bool:
    """Whether to run the case ``label``: it contains ``--only``, and was BAD in the
    ``--bad-of`` table when one is given."""
    return (not args.only or args.only in label) and (args.bad_of is None or label in args.bad_of)


def run_cli_cases(args, results: list[dict]) -> None:
    """Every scenario's cases, ``args.jobs`` command lines at a time; in the cases' order."""
    cases = [(path, *case) for path in SCENARIOS for case in _scenario_cases(path)]
    cases = [c for c in cases if _chosen(args, f"{c[0].stem}: {c[1]}")]
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(_cli_case, args, k, *case) for k, case in enumerate(cases)]
        results += [f.result() for f in futures]


# ---------------------------------------------------------------- Gymnasium


def _gym_cases() -> list[tuple[str, str, dict]]:
    """(label, id, make keyword arguments): the defaults, each shipped model, the shipped
    scenarios a user points the environments at."""
    cases = [
        (f"{i} defaults", f"uvms_pin/{i}-v0", {})
        for i in ("ForceTracking", "StationKeeping", "PoseTracking")
    ]
    for model in MODELS:
        for env in ("ForceTracking", "StationKeeping"):
            cases.append((f"{env} model {model}", f"uvms_pin/{env}-v0", {"model": model}))
    for path in SCENARIOS:
        for env in ("ForceTracking", "StationKeeping", "PoseTracking"):
            cases.append(
                (f"{env} scenario {path.stem}", f"uvms_pin/{env}-v0", {"scenario": str(path)})
            )
    return cases


def _gym_episode(env_id: str, kwargs: dict, seed: int, steps: int) -> tuple[str, str]:
    import gymnasium as gym

    import uvms_pin.apps.gym  # noqa: F401  (registers the environments)

    env = gym.make(env_id, **kwargs)
    try:
        env.action_space.seed(seed)
        obs, info = env.reset(seed=seed)
        resets = 0
        for _ in range(steps):
            obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
            if not (np.all(np.isfinite(obs)) and np.isfinite(reward)):
                return "BAD", f"non-finite observation or reward at step {_}"
            if info.get("diverged"):
                return "BAD", f"diverged at step {_}: {info.get('failure', '')}"
            v = np.asarray(env.unwrapped._loop.v)  # the true state, not the observation
            if np.linalg.norm(v[:3]) > MAX_SPEED_M_S or np.abs(v[3:]).max() > MAX_RATE_RAD_S:
                return (
                    "BAD",
                    f"speed {np.linalg.norm(v[:3]):.1f} m/s, rate {np.abs(v[3:]).max():.0f} rad/s at step {_}",
                )
            if terminated or truncated:
                resets += 1
                obs, info = env.reset()
        return "ok", f"{resets} resets"
    finally:
        env.close()


def run_gym_cases(args, results: list[dict]) -> None:
    from uvms_pin.errors import UvmsPinError

    for label, env_id, kwargs in _gym_cases():
        seeds = (args.seed, args.seed + 1, args.seed + 2) if "defaults" in label else (args.seed,)
        for seed in seeds:
            case = f"gym {label} seed {seed}"
            if not _chosen(args, case):
                continue
            start = time.perf_counter()
            try:
                outcome, reason = _gym_episode(env_id, kwargs, seed, args.gym_steps)
            except UvmsPinError as exc:
                outcome, reason = "refused", f"{type(exc).__name__}: {exc}"[:200]
                if not str(exc).strip():
                    outcome = "BAD"
            except Exception as exc:  # what the campaign looks for
                outcome, reason = "BAD", f"{type(exc).__name__}: {exc}"[:300]
            wall = time.perf_counter() - start
            results.append(
                dict(
                    case=case,
                    kind="gym",
                    outcome=outcome,
                    reason=reason,
                    wall_s=round(wall, 1),
                    command=f"gym.make({env_id!r}, **{kwargs!r}), seed {seed}",
                )
            )
            print(f"{outcome:8s} {wall:5.1f}s {case}  {reason[:110]}", flush=True)


# ---------------------------------------------------------------- the table


def summary(results: list[dict]) -> str:
    kinds = sorted({r["kind"] for r in results})
    outcomes = ("ok", "refused", "stopped", "BAD")
    rows = ["| kind | runs | " + " | ".join(outcomes) + " |", "|---" * (len(outcomes) + 2) + "|"]
    for kind in [*kinds, "all"]:
        picked = [r for r in results if kind in ("all", r["kind"])]
        counts = Counter(r["outcome"] for r in picked)
        rows.append(
            f"| {kind} | {len(picked)} | " + " | ".join(str(counts[o]) for o in outcomes) + " |"
        )
    bad = [r for r in results if r["outcome"] == "BAD"]
    rows += ["", f"BAD ({len(bad)}):"] + [f"- {r['case']}: {r['reason'][:160]}" for r in bad]
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", default="", help="run the cases whose label contains this")
    parser.add_argument("--duration", type=float, default=1.0, help="simulated seconds a run")
    parser.add_argument("--jobs", type=int, default=2, help="command lines run at once")
    parser.add_argument("--gym-steps", type=int, default=300)
    parser.add_argument("--seed", type=int, default=0, help="first seed of the random actions")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "first_tries")
    parser.add_argument("--no-gym", action="store_true")
    parser.add_argument("--no-cli", action="store_true")
    parser.add_argument("--bad-of", type=Path, help="rerun the BAD cases of this first_tries.json")
    args = parser.parse_args(argv)
    if args.bad_of is not None:
        args.bad_of = {
            r["case"] for r in json.loads(args.bad_of.read_text()) if r["outcome"] == "BAD"
        }
    args.out.mkdir(parents=True, exist_ok=True)
    results: list[dict] = []
    if not args.no_cli:
        run_cli_cases(args, results)
    if not args.no_gym:
        run_gym_cases(args, results)
    (args.out / "first_tries.json").write_text(json.dumps(results, indent=1))
    table = summary(results)
    (args.out / "first_tries.md").write_text(table + "\n")
    print(table)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
