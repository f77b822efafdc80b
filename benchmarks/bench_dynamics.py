"""Cost of the underwater dynamics, the plant and the closed loop: compiled core vs Python.

    .venv/bin/python benchmarks/bench_dynamics.py [--repeat N] [--loop-s T] [--json FILE]

Every figure is measured in this process, on the reference model, and reported as a ratio
to one rigid-body ``pin.aba`` call (the floor: Pinocchio's forward dynamics with no water)
timed in the same run, so the numbers compare across machines. Times are the CPU time of
this process (``time.process_time``), best of interleaved rounds, with one BLAS thread
(`timing.py`): on a machine shared with other jobs, wall-clock time measures the neighbours. Absolute times are printed for information only. "core" is the compiled backend (the default), "python" the reference.

The plant rows advance the plant of the realistic scenario (2 N/m spring, sinusoidal
disturbance, a 0.3 m/s current) over one 2 ms control period with RK4 at 0.5 ms (4 steps, 16
right-hand sides). The closed-loop rows run the shipped scenarios for ``--loop-s`` simulated
seconds and report the real-time factor (simulated / wall time) and the cost per control tick.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import pinocchio as pin
from timing import best_times, one_blas_thread

import uvms_pin as up
from uvms_pin.physics.contact import LinearSpring
from uvms_pin.physics.disturbance import SinusoidalDisturbance
from uvms_pin.physics.dynamics import dynamics_of
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

ROOT = Path(__file__).resolve().parents[1]
BACKENDS = ("core", "python")


#: the vehicle's depth for the deep-water rows [m] (its origin; the arm hangs below)
DEEP_Z_M = -3.0


def call_rows(uvms: up.UVMS, repeat: int) -> dict[str, float]:
    """Seconds per call of each dynamics function and of the plant over a control period."""
    model, data = uvms.model, uvms.model.createData()
    rng = np.random.default_rng(0)
    q = uvms.neutral_configuration()
    q[2] = DEEP_Z_M  # every body under water: the free surface (on by default) cuts none
    q[7:] = [0.1, 0.6, -0.5, 0.2]
    v = rng.normal(scale=0.3, size=model.nv)
    tau = rng.normal(size=model.nv)
    current = np.array([0.3, 0.1, 0.0])
    compiled = dynamics_of(uvms).core
    cases = {
        "pin.aba (rigid floor)": lambda: pin.aba(model, data, q, v, tau),
        "core Dynamics.forward_dynamics (direct)": lambda: compiled.forward_dynamics(
            q, v, tau, current
        ),
    }
    for b in BACKENDS:
        cases[f"{b}: mass_matrix"] = lambda b=b: up.mass_matrix(uvms, q, backend=b)
        cases[f"{b}: bias_forces (current)"] = lambda b=b: up.bias_forces(
            uvms, q, v, current, backend=b
        )
        cases[f"{b}: forward_dynamics (current)"] = lambda b=b: up.forward_dynamics(
            uvms, q, v, tau, current, backend=b
        )
    rk4 = RK4(5e-4)
    for b in BACKENDS:
        plant = Plant(
            uvms, current, LinearSpring(np.full(3, 2.0)), SinusoidalDisturbance(), backend=b
        )
        plant.attach(q)
        system = System(plant)  # the simulator's period step (Plant itself steps nothing)
        cases[f"{b}: plant over 2 ms (RK4 0.5 ms)"] = lambda s=system: s.advance(
            rk4, 0.0, q, v, tau, 0.002
        )
    # the marginal cost of hydrodynamic bodies: the same plant with the arm links dry (only
    # the vehicle in water), against every body in water as above
    dry_arm = uvms.with_hydro(lambda b: b.params if b.joint_id == 1 else up.HydroParams.dry())
    plant = Plant(dry_arm, current, LinearSpring(np.full(3, 2.0)), SinusoidalDisturbance())
    plant.attach(q)
    system = System(plant)
    cases["core: plant over 2 ms, arm links dry"] = lambda s=system: s.advance(
        rk4, 0.0, q, v, tau, 0.002
    )
    return best_times(cases, repeat)


def surface_rows(uvms: up.UVMS, repeat: int) -> dict[str, float]:
    """Seconds per control period of the compiled plant with and without a free surface,
    every body deep (the vehicle 3 m down) and the vehicle at the surface (its origin at
    z = 0: the hull and the arm's first links cut by it)."""
    rng = np.random.default_rng(0)
    q = uvms.neutral_configuration()
    q[7:] = [0.1, 0.6, -0.5, 0.2]
    v = rng.normal(scale=0.3, size=uvms.nv)
    tau = rng.normal(size=uvms.nv)
    current = np.array([0.3, 0.1, 0.0])
    rk4 = RK4(5e-4)
    cases = {}
    for where, z in (("deep", DEEP_Z_M), ("at the surface", 0.0)):
        at = q.copy()
        at[2] = z
        for surface in (False, True):
            plant = Plant(
                uvms,
                current,
                LinearSpring(np.full(3, 2.0)),
                SinusoidalDisturbance(),
                free_surface=surface,
            )
            plant.attach(at)
            label = "free surface" if surface else "no surface"
            system = System(plant)
            cases[f"core: plant over 2 ms, {where}, {label}"] = lambda s=system, a=at: s.advance(
                rk4, 0.0, a, v, tau, 0.002
            )
    return best_times(cases, repeat)


def closed_loop_rows(duration_s: float) -> dict[str, dict[str, float]]:
    """Real-time factor and wall time per control tick of the shipped scenarios."""
    out = {}
    for name in ("realistic_force_tracking", "paper_force_tracking"):
        for b in BACKENDS:
            path = ROOT / "scenarios" / f"{name}.toml"
            # a short run first: what happens once per process (imports, building the
            # compiled model) is not part of a loop's cost
            warm_up = {"scenario.duration_s": 0.02, "output.log_period_s": 0.01}
            up.simulate(up.load_scenario(path, {**warm_up, "integrator.backend": b}))
            scenario = up.load_scenario(
                path, {"scenario.duration_s": duration_s, "integrator.backend": b}
            )
            start = time.process_time()
            rollout = up.simulate(scenario)
            wall = time.process_time() - start
            period = scenario.settings.control_period_s
            ticks = duration_s / period if period else float("nan")
            out[f"{name} [{b}]"] = {
                "real_time_factor": duration_s / wall,
                "wall_s": wall,
                "seconds_per_tick": wall / ticks,
                "status": rollout.metadata["status"],
            }
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--repeat", type=int, default=20, help="interleaved rounds; the best is kept"
    )
    parser.add_argument("--loop-s", type=float, default=2.0, help="simulated seconds per loop")
    parser.add_argument("--json", type=Path, default=None, help="also write the results here")
    args = parser.parse_args()
    one_blas_thread()

    uvms = up.load_uvms(ROOT / "models" / "uvms_lbv150.urdf")
    calls = {**call_rows(uvms, args.repeat), **surface_rows(uvms, args.repeat)}
    floor = calls["pin.aba (rigid floor)"]
    width = max(len(n) for n in calls)
    print(f"{'case':<{width}}  {'x pin.aba':>10}  {'us/call':>10}")
    for name, seconds in calls.items():
        print(f"{name:<{width}}  {seconds / floor:>10.1f}  {seconds * 1e6:>10.2f}")
    for what in ("forward_dynamics (current)", "plant over 2 ms (RK4 0.5 ms)"):
        speedup = calls[f"python: {what}"] / calls[f"core: {what}"]
        print(f"speed-up core / python, {what}: {speedup:.1f}x")
    wet = (
        calls["core: plant over 2 ms (RK4 0.5 ms)"] / calls["core: plant over 2 ms, arm links dry"]
    )
    print(f"core plant, every body in water / only the vehicle in water: {wet:.2f}x")
    for where in ("deep", "at the surface"):
        ratio = (
            calls[f"core: plant over 2 ms, {where}, free surface"]
            / calls[f"core: plant over 2 ms, {where}, no surface"]
        )
        print(f"core plant {where}, with a free surface / without: {ratio:.2f}x")

    loops = closed_loop_rows(args.loop_s)
    width = max(len(n) for n in loops)
    print(f"\n{'closed loop (' + str(args.loop_s) + ' s)':<{width}}  {'RTF':>7}  {'us/tick':>9}")
    for name, r in loops.items():
        print(
            f"{name:<{width}}  {r['real_time_factor']:>7.2f}  "
            f"{r['seconds_per_tick'] * 1e6:>9.0f}  {r['status']}"
        )
    for name in ("realistic_force_tracking", "paper_force_tracking"):
        speedup = loops[f"{name} [python]"]["wall_s"] / loops[f"{name} [core]"]["wall_s"]
        print(f"speed-up core / python, {name} closed loop: {speedup:.1f}x")
    if args.json is not None:
        results = {
            "calls": {n: {"seconds": s, "ratio_to_aba": s / floor} for n, s in calls.items()},
            "closed_loop": loops,
        }
        args.json.write_text(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
