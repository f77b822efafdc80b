"""The Gymnasium environments' step rate: steps per second and pin.aba calls per step."""

from __future__ import annotations

from _common import benchmark_result, producer_cli

if __name__ == "__main__":
    producer_cli(__doc__)
    benchmark_result(
        "bench_gym",
        "Gymnasium step rate",
        "bench_gym.py",
        ["--steps", "500"],
        "Process CPU time; the ratio to one `pin.aba` call is the number to compare across machines.",
    )
