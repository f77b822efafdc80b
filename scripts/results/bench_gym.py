"""The Gymnasium environments' step rate: steps per second and pin.aba calls per step; the
native vector environment against mujoco.rollout at 1 and 2 threads."""

from __future__ import annotations

from _common import benchmark_result, producer_cli

if __name__ == "__main__":
    producer_cli(__doc__)
    benchmark_result(
        "bench_gym",
        "Gymnasium step rate",
        "bench_gym.py",
        ["--steps", "500"],
        "Single environments: process CPU time; the ratio to one `pin.aba` call is the number to "
        "compare across machines. Vector environment: wall-clock time (threads), as ratios to "
        "MuJoCo's `rollout` of its twin's plant alone, measured in the same process.",
    )
