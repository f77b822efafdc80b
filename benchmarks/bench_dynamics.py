"""Cost of the underwater dynamics and of one integrator step, as ratios to pin.aba.

    .venv/bin/python benchmarks/bench_dynamics.py [--repeat N] [--json FILE]

Every figure is measured in this process, on the reference model, and reported as a ratio
to one rigid-body ``pin.aba`` call (the floor: Pinocchio's forward dynamics with no water)
timed in the same run, so the numbers compare across machines. Absolute times are printed
for information only.
"""

from __future__ import annotations

import argparse
import json
import timeit
from pathlib import Path

import numpy as np
import pinocchio as pin

import uvms_pin as up
from uvms_pin.integrators import RK4, SemiImplicitEuler

ROOT = Path(__file__).resolve().parents[1]


def best_time(fn, number: int, repeat: int) -> float:
    """Best mean time per call over ``repeat`` batches of ``number`` calls [s]."""
    return min(timeit.repeat(fn, number=number, repeat=repeat)) / number


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--number", type=int, default=2000)
    parser.add_argument("--json", type=Path, default=None, help="also write the results here")
    args = parser.parse_args()

    uvms = up.load_uvms(ROOT / "models" / "uvms_lbv150.urdf")
    model = uvms.model
    data = model.createData()
    rng = np.random.default_rng(0)
    q = uvms.neutral_configuration()
    q[7:] = [0.1, 0.6, -0.5, 0.2]
    v = rng.normal(scale=0.3, size=model.nv)
    tau = rng.normal(size=model.nv)
    current = np.array([0.3, 0.1, 0.0])

    def rhs(t, qq, vv):
        return up.forward_dynamics(uvms, qq, vv, tau, current)

    rk4, euler = RK4(1e-3), SemiImplicitEuler(1e-3)
    cases = {
        "pin.aba (rigid floor)": lambda: pin.aba(model, data, q, v, tau),
        "mass_matrix": lambda: up.mass_matrix(uvms, q),
        "bias_forces (with current)": lambda: up.bias_forces(uvms, q, v, current),
        "forward_dynamics (with current)": lambda: up.forward_dynamics(uvms, q, v, tau, current),
        "RK4 step (4 forward_dynamics)": lambda: rk4.advance(model, rhs, 0.0, q, v, 1e-3),
        "semi-implicit Euler step": lambda: euler.advance(model, rhs, 0.0, q, v, 1e-3),
    }
    results = {}
    floor = None
    for name, fn in cases.items():
        number = args.number if "step" not in name else max(1, args.number // 4)
        seconds = best_time(fn, number, args.repeat)
        floor = seconds if floor is None else floor
        results[name] = {"seconds": seconds, "ratio_to_aba": seconds / floor}
    width = max(len(n) for n in results)
    print(f"{'case':<{width}}  {'x pin.aba':>10}  {'us/call':>10}")
    for name, r in results.items():
        print(f"{name:<{width}}  {r['ratio_to_aba']:>10.1f}  {r['seconds'] * 1e6:>10.2f}")
    if args.json is not None:
        args.json.write_text(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
