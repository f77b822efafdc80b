"""The Gymnasium environments' step rate: steps per second and pin.aba calls per step."""

from __future__ import annotations

from _common import benchmark_result

if __name__ == "__main__":
    benchmark_result(
        "bench_gym",
        "Gymnasium step rate",
        "bench_gym.py",
        ["--steps", "500"],
        "Process CPU time; the ratio to one `pin.aba` call is the number to compare across machines.",
    )
