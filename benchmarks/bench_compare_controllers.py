"""Cost of each row of ``uvms-pin compare-controllers``, as a ratio to the PPC's row (the
first controller's).

    .venv/bin/python benchmarks/bench_compare_controllers.py [SCENARIO] [--repeat N]
        [--duration S] [--controllers ppc,pi_force,...] [--json FILE]

Each controller's run of the scenario (default scenarios/realistic_force_tracking.toml,
shortened to ``--duration``) is simulated as compare-controllers simulates it (its
[baselines.<name>] tuning, `controller_scenarios`), and reported as a ratio of its time to
the first row's (the PPC's by default; on a tracking scenario name its controllers, e.g.
``--controllers task_priority,computed_torque_task``), timed in the same process: the figures compare across machines. Times are this
process's CPU time, best of ``--repeat`` interleaved rounds (`timing.py`). The path each run
took (the compiled sampled loop, or the Python loop and why) is printed with it, and, with
``--python-loop``, each row's time on the Python loop too (``compiled_loop=False``: what a
controller without a compiled law costs), as a ratio to the same PPC row, and the row's
compiled loop as a ratio to its own Python loop (the column "compiled / python"). The
compiled task-priority loop against its Python loop, on the LBV150 circle:

    .venv/bin/python benchmarks/bench_compare_controllers.py scenarios/lbv150_ee_circle.toml \
        --controllers task_priority,task_priority_ppc,computed_torque_task --python-loop
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from timing import best_times, one_blas_thread

from uvms_pin.apps.compare.runs import controller_scenarios
from uvms_pin.sim.run import simulate

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SCENARIO = ROOT / "scenarios" / "realistic_force_tracking.toml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", nargs="?", default=str(DEFAULT_SCENARIO))
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--duration", type=float, default=2.0, help="simulated seconds per run")
    parser.add_argument("--controllers", default="ppc,pi_force,impedance,computed_torque")
    parser.add_argument("--python-loop", action="store_true", help="also time the Python loop")
    parser.add_argument("--json", type=Path, default=None, help="write the ratios here")
    args = parser.parse_args()
    one_blas_thread()
    names = args.controllers.split(",")
    scenarios = controller_scenarios(args.scenario, names, {"scenario.duration_s": args.duration})
    paths = {}
    for name, scenario in scenarios.items():
        meta = simulate(scenario, progress=False).metadata["closed_loop"]
        paths[name] = meta["path"] if meta["reason"] is None else f"python ({meta['reason']})"
    cases = {(name, True): s for name, s in scenarios.items()}
    if args.python_loop:
        cases.update({(name, False): s for name, s in scenarios.items()})
    seconds = best_times(
        {
            key: (lambda s=s, c=key[1]: simulate(s, progress=False, compiled_loop=c))
            for key, s in cases.items()
        },
        args.repeat,
        batch_s=0.0,
    )
    first = names[0]
    base = seconds[first, True]
    print(f"{Path(args.scenario).name}, {args.duration:g} s simulated per run, "
          f"best of {args.repeat}; ratios to the {first} row ({base:.3f} s)")  # fmt: skip
    print(f"{'controller':<22}{'ratio':>8}{'python loop':>13}{'compiled / python':>19}  loop")
    ratios = {}
    for name in names:
        ratio = seconds[name, True] / base
        python = seconds.get((name, False), float("nan")) / base
        ratios[name] = {
            f"ratio_to_{first}": ratio,
            "python_loop_ratio": python,
            "compiled_to_python": ratio / python,
            "loop": paths[name],
        }
        print(f"{name:<22}{ratio:>8.2f}{python:>13.2f}{ratio / python:>19.3f}  {paths[name]}")
    if args.json is not None:
        args.json.write_text(json.dumps(ratios, indent=1))


if __name__ == "__main__":
    main()
