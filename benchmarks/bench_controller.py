"""Cost of one prescribed-performance ``compute``, as a ratio to one ``pin.aba`` call.

    .venv/bin/python benchmarks/bench_controller.py [--repeat N] [--json FILE] [--breakdown]

Cases, each on a measurement near the scenario's initial state:

- ``paper``: the paper scenario's controller (plain J^+, no null-space task), reference model;
- ``realistic``: the realistic scenario's (generalized pseudo-inverse J^# = W^-1 J^T
  (J W^-1 J^T)^-1 and the joint-limit task in the null space of J), reference model;
- ``7-joint arm``: the Franka Panda of example-robot-data mounted on the reference vehicle,
  realistic-style controller (weights and null-space task), if example-robot-data is
  installed.

Each is timed for the package's controller on its two backends, the compiled law
(``backend="core"``, the default, src/uvms_core/ppc.hpp) and the Python reference
(``backend="python"``), and for the frozen pre-optimization copy kept as the test oracle
(``tests/control/ppc_oracle``), and reported as a ratio to one
rigid-body ``pin.aba`` call on the reference model timed in the same process, so that the
figures compare across machines. Times are this process's CPU time (``time.process_time``),
best of ``--repeat`` interleaved rounds (`timing.py`): on a shared machine the wait for a core
does not count.
Absolute times are printed for information only. ``--breakdown`` also times the stages of
the realistic case's Python ``compute`` separately (where its cost goes), and the compiled
kernel's call alone (what the core's ``compute`` adds in Python: f_d(t), the call, the copy of
tau).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from unittest import mock

import numpy as np
import pinocchio as pin
from timing import best_times, one_blas_thread

import uvms_pin as up
from uvms_pin.control.measurement import Measurement
from uvms_pin.control.ppc import PPCParams, PrescribedPerformanceController
from uvms_pin.model.mount.catalog import CATALOG
from uvms_pin.model.mount.split import split_urdf
from uvms_pin.model.resources import example_robot_data_dir
from uvms_pin.scenario.load import load_scenario

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "control"))
from ppc_oracle import in_place_of_the_package_ppc  # noqa: E402
from ppc_oracle.ppc import PrescribedPerformanceController as OraclePPC  # noqa: E402

#: the compute calls of one case: compiled law, Python reference, pre-optimization oracle
Case = tuple[Callable[[], object], Callable[[], object], Callable[[], object]]


def _measurement(uvms: up.UVMS, q: np.ndarray, time_s: float = 0.3) -> Measurement:
    """Small velocities and a 0.3 N push: inside every funnel of the cases below."""
    v = 0.01 * np.cos(np.arange(uvms.nv))
    return Measurement(time_s, q, v, np.array([0.3, 0.05, -0.05, 0.0, 0.0, 0.0]))


def _calls(measurement: Measurement, *controllers) -> Case:
    def call(controller):
        controller.compute(measurement.time_s, measurement)  # inside the funnels
        return lambda: controller.compute(measurement.time_s, measurement)

    return tuple(call(c) for c in controllers)


def scenario_case(stem: str) -> Case:
    path = ROOT / "scenarios" / f"{stem}.toml"
    scenario = load_scenario(path)
    core = scenario.controller_factory(scenario.uvms)
    python = load_scenario(path, {"controller.backend": "python"}).controller_factory(scenario.uvms)
    assert (core.backend, python.backend) == ("core", "python")
    with mock.patch(
        "uvms_pin.scenario.ppc.PrescribedPerformanceController", in_place_of_the_package_ppc
    ):
        oracle = scenario.controller_factory(scenario.uvms)
    return _calls(_measurement(scenario.uvms, scenario.q0), core, python, oracle)


def mounted_arm_case(arm: str) -> Case | None:
    if example_robot_data_dir() is None:
        return None
    entry = CATALOG[arm]
    with tempfile.TemporaryDirectory() as tmp:
        split = split_urdf(ROOT / "models" / "uvms_lbv150.urdf", tmp)
        uvms = up.mount_arm(
            split.vehicle_urdf,
            entry.urdf,
            (split.mount_pose.translation, (math.pi, 0.0, 0.0)),
            ee_link=entry.ee_link,
            allow_dry_links=True,
        )
    q = uvms.neutral_configuration()
    lower, upper = uvms.model.lowerPositionLimit[7:], uvms.model.upperPositionLimit[7:]
    q[7:] = 0.5 * (lower + upper) + 0.1 * (upper - lower)
    data = uvms.model.createData()
    pin.framesForwardKinematics(uvms.model, data, q)
    rpy = pin.rpy.matrixToRpy(data.oMf[uvms.ee_frame_id].rotation)
    params = PPCParams(
        velocity_weights=[100.0, 300.0, 1000.0, 1e4, 1e4, 100.0] + [1.0] * uvms.n_arm_joints,
        null_space_gain_per_s=3.0,
        desired_rpy=rpy + 0.05,
    )
    frame = uvms.model.frames[uvms.ee_frame_id].name
    force = (0.4, 0.0, 0.0)
    return _calls(
        _measurement(uvms, q),
        PrescribedPerformanceController(uvms.model, frame, params, force),
        PrescribedPerformanceController(uvms.model, frame, params, force, backend="python"),
        OraclePPC(uvms.model, frame, params, force),
    )


def breakdown() -> dict[str, Callable[[], object]]:
    """The stages of the realistic scenario's Python ``compute``, each callable on its own,
    and the compiled kernel's call."""
    from uvms_pin.control import ppc
    from uvms_pin.physics.kinematics import frame_rotation_and_jacobian

    path = ROOT / "scenarios" / "realistic_force_tracking.toml"
    scenario = load_scenario(path, {"controller.backend": "python"})
    c = scenario.controller_factory(scenario.uvms)
    compiled = load_scenario(path).controller_factory(scenario.uvms)
    m = _measurement(scenario.uvms, scenario.q0)
    t, q = m.time_s, m.q
    rotation, jacobian = frame_rotation_and_jacobian(c.model, c.data, q, c.ee_frame_id)
    rpy = pin.rpy.matrixToRpy(rotation)
    force, rpy_desired = c._desired_force(t), c._desired_rpy(t)
    rho = c._performance_both.value(t)
    e_x = ppc._first_level_error(m.wrench_world, force, rpy, rpy_desired)
    xi_x = [e / r for e, r in zip(e_x, rho[:6].tolist(), strict=True)]
    xdot = [k * math.atanh(x) for k, x in zip(c._neg_two_k_x, xi_x, strict=True)]
    zeta_r = c._reference_velocity(q, rpy, jacobian, xdot)
    rho_zeta = rho[6:]

    def second_level():
        e = m.v - zeta_r
        xi = e / rho_zeta
        ppc.max_abs(xi)
        return (c._neg_four_k_zeta * np.arctanh(xi) / (rho_zeta - xi * e)).copy()

    kernel = compiled._kernel
    kernel_args = (t, m.q, m.v, m.wrench_world, force, rpy_desired, False)
    assert kernel.compute(*kernel_args) == 0

    return {
        "core: compute (whole)": lambda: compiled.compute(t, m),
        "core: the kernel's call alone": lambda: kernel.compute(*kernel_args),
        "python: compute (whole)": lambda: c.compute(t, m),
        "measurement check": lambda: c._check_measurement(m),
        "f_d(t), rpy_d(t)": lambda: (c._desired_force(t), c._desired_rpy(t)),
        "Pinocchio pass + rpy": lambda: pin.rpy.matrixToRpy(
            frame_rotation_and_jacobian(c.model, c.data, q, c.ee_frame_id)[0]
        ),
        "funnels rho(t)": lambda: c._performance_both.value(t),
        "first level (e_x .. xdot_r)": lambda: [
            k * math.atanh(e / r)
            for k, e, r in zip(
                c._neg_two_k_x,
                ppc._first_level_error(m.wrench_world, force, rpy, rpy_desired),
                rho[:6].tolist(),
                strict=True,
            )
        ],
        "zeta_r (null space + J^#)": lambda: c._reference_velocity(q, rpy, jacobian, xdot),
        "  of which J^# solve": lambda: c._solver.solve(jacobian, np.ones(6)),
        "second level (.. tau)": second_level,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--repeat", type=int, default=20, help="interleaved rounds; the best is kept"
    )
    parser.add_argument("--json", type=Path, default=None, help="also write the results here")
    parser.add_argument("--breakdown", action="store_true", help="time the stages too")
    args = parser.parse_args()

    reference = up.load_uvms(ROOT / "models" / "uvms_lbv150.urdf")
    model, data = reference.model, reference.model.createData()
    q = reference.neutral_configuration()
    q[7:] = [0.1, 0.6, -0.5, 0.2]
    v = np.random.default_rng(0).normal(scale=0.3, size=model.nv)
    tau = np.ones(model.nv)
    cases = {
        "paper (reference model)": scenario_case("paper_force_tracking"),
        "realistic (reference model)": scenario_case("realistic_force_tracking"),
        "7-joint arm (Panda)": mounted_arm_case("panda"),
    }
    one_blas_thread()
    # every case and the aba floor timed in the same interleaved rounds
    timed_cases = {"aba": lambda: pin.aba(model, data, q, v, tau)}
    for name, case in cases.items():
        for backend, fn in zip(("core", "python", "oracle"), case or (), strict=False):
            timed_cases[name, backend] = fn
    timed = best_times(timed_cases, args.repeat)
    floor = timed["aba"]
    results = {"pin.aba [s]": floor}
    print(f"pin.aba on the reference model: {floor * 1e6:.2f} us")
    print(f"{'':<28}  {'compiled (core)':^18}  {'Python reference':^18}  {'pre-optimization':^16}")
    print(
        f"{'case':<28}  {'x pin.aba':>9}  {'us/call':>7}  {'x pin.aba':>9}  {'us/call':>7}"
        f"  {'x pin.aba':>16}"
    )
    for name, case in cases.items():
        if case is None:
            print(f"{name:<28}  skipped: example-robot-data is not installed")
            continue
        core, python, oracle = (timed[name, b] for b in ("core", "python", "oracle"))
        results[name] = {
            "seconds": core,
            "ratio_to_aba": core / floor,
            "python_seconds": python,
            "python_ratio_to_aba": python / floor,
            "before_seconds": oracle,
        }
        print(
            f"{name:<28}  {core / floor:>9.1f}  {core * 1e6:>7.2f}  {python / floor:>9.1f}"
            f"  {python * 1e6:>7.2f}  {oracle / floor:>16.1f}"
        )
    if args.breakdown:
        print("\nrealistic compute, stage by stage (x pin.aba; 'python' stages: the reference):")
        for name, fn in breakdown().items():
            seconds = best_times({name: fn}, args.repeat)[name]
            results[f"stage: {name}"] = {"seconds": seconds, "ratio_to_aba": seconds / floor}
            print(f"  {name:<30}  {seconds / floor:>6.2f}  {seconds * 1e6:>7.2f} us")
    if args.json is not None:
        args.json.write_text(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
