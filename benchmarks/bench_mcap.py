"""Speed of the ROS 2 bag export (`Rollout.to_mcap`): wall time per simulated minute.

    .venv/bin/python benchmarks/bench_mcap.py [--scenario FILE] [--duration S] [--repeat N]

Simulates the scenario for ``--duration`` seconds (default 10; the realistic force-tracking
scenario, logged at its own rate: every link's transform, the joints, odometry, wrenches,
thrusters and the navigation sensors it has), writes it to MCAP ``--repeat`` times and
prints the best wall and CPU times (the CPU time: what a busy machine does not change), the samples and messages, and the seconds per simulated minute
(the target: at most 1 s).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--scenario", default=str(ROOT / "scenarios" / "realistic_force_tracking.toml")
    )
    parser.add_argument("--duration", type=float, default=10.0)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    rollout = simulate(
        load_scenario(args.scenario, {"scenario.duration_s": args.duration}), progress=False
    )
    simulated_s = float(rollout.time_s[-1] - rollout.time_s[0])
    best, best_cpu = float("inf"), float("inf")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "run.mcap"
        for _ in range(args.repeat):
            start, start_cpu = time.perf_counter(), time.process_time()
            rollout.to_mcap(path)
            best = min(best, time.perf_counter() - start)
            best_cpu = min(best_cpu, time.process_time() - start_cpu)
        size_mb = path.stat().st_size / 1e6
    per_minute = best / simulated_s * 60.0
    print(
        f"{Path(args.scenario).name}: {len(rollout)} samples over {simulated_s:g} s simulated, "
        f"{size_mb:.1f} MB; export {best:.3f} s wall, {best_cpu:.3f} s CPU (best of "
        f"{args.repeat}) = {per_minute:.2f} s wall per simulated minute (target <= 1)"
    )


if __name__ == "__main__":
    main()
